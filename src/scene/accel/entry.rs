//! Where the shadow rays of a shaft (`Shaft`: from a tile's footprints to one emitter triangle) start their walk
//! in a deep tree: a node of its own whose children are the deepest subtrees that, at most eight of them, hold
//! everything in the shaft (a cut of the tree, grown from the root by opening the largest box while the cut
//! fits; the subtrees wholly outside every shaft are left out). A ray tests the cut's boxes in one step where
//! from the root it would step down through every node above them; it meets the same triangles the shaft can
//! hold, so its answer is the walk's from the root. Haines and Wallace's shaft culling keeps a candidate list
//! per shaft; this keeps the top of that list, the part that saves the rays' steps.

use super::Accel;
use super::node::{ChildGroups, NO_GROUP, Node8};
use super::shaft::Shaft;
use arrayvec::ArrayVec;

/// The cut a shaft's rays start from: its subtrees as the children of one node, with their groups.
#[derive(Clone, Debug)]
pub struct ShaftEntry {
    pub(super) node: Node8,
    pub(super) groups: ChildGroups,
}

/// A member of a cut: child `lane` of node `parent`, with its box's half surface area.
#[derive(Clone, Copy)]
struct Member {
    parent: u32,
    lane: u8,
    area: f32,
    /// A leaf, or a node whose opening would make the cut more than eight.
    closed: bool,
}

impl Accel {
    /// The cut the rays in `shafts` (their union) start from, in a tree whose rays walk alone
    /// (`Accel::walks_alone`); `None` where it would be the root's own children.
    pub fn shaft_entry(&self, shafts: &[Shaft]) -> Option<ShaftEntry> {
        let root = self.root.filter(|r| !r.is_leaf() && self.walks_alone())?;
        // The children of a node some shaft does not clear.
        let kept = |node: u32| {
            let node = &self.nodes[node as usize];
            shafts.iter().fold(0, |m, s| m | (node.used() & !node.cleared_by(s)))
        };
        let open = |node: u32, mut lanes: u32, cut: &mut ArrayVec<Member, 8>| {
            let (bounds, children) = (self.nodes[node as usize].bounds(), &self.nodes[node as usize].children);
            while lanes != 0 {
                let k = lanes.trailing_zeros() as usize;
                lanes &= lanes - 1;
                let e = [0, 1, 2].map(|a| bounds[a + 3].as_array_ref()[k] - bounds[a].as_array_ref()[k]);
                let area = e[0] * e[1] + e[1] * e[2] + e[2] * e[0];
                cut.push(Member { parent: node, lane: k as u8, area, closed: children[k].is_leaf() });
            }
        };
        let mut cut = ArrayVec::<Member, 8>::new();
        open(root.first, kept(root.first), &mut cut);
        let mut opened = false;
        // The largest box first: the most rays enter it.
        while let Some(i) =
            (0..cut.len()).filter(|&i| !cut[i].closed).max_by(|&i, &j| cut[i].area.total_cmp(&cut[j].area))
        {
            let node = self.nodes[cut[i].parent as usize].children[cut[i].lane as usize].first;
            let lanes = kept(node);
            if cut.len() - 1 + lanes.count_ones() as usize > 8 {
                cut[i].closed = true;
                continue;
            }
            cut.remove(i);
            open(node, lanes, &mut cut);
            opened = true;
        }
        if !opened {
            return None;
        }
        let members: ArrayVec<(&Node8, usize), 8> =
            cut.iter().map(|m| (&self.nodes[m.parent as usize], m.lane as usize)).collect();
        let groups: ArrayVec<i32, 8> =
            cut.iter().map(|m| self.groups[m.parent as usize].group(m.lane as usize)).collect();
        debug_assert!(groups.iter().all(|&g| g >= NO_GROUP));
        Some(ShaftEntry { node: Node8::gathered(&members), groups: ChildGroups::new(&groups) })
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::random_soup;
    use super::*;
    use crate::math::{SampleRng, Vec3x8};
    use crate::scene::SKIP_NONE;
    use glam::Vec3;

    /// Shadow rays through a shaft (from points of a square to points of a triangle) answer from the shaft's
    /// entry as from the root, each skipping a group or none, in a tree deep enough for its rays to walk alone;
    /// and the entries open below the root's children (most of them), so the test walks real cuts.
    #[test]
    fn rays_in_a_shaft_answer_from_its_entry_as_from_the_root() {
        let tris = random_soup(40_000, 0.25, 11);
        // Triangles with centroid x > 2 in group 0, x < −2 in group 1: subtrees the tree holds apart.
        let side = |[a, b, c]: &[Vec3; 3]| match (a.x + b.x + c.x) / 3.0 {
            x if x > 2.0 => Some(0),
            x if x < -2.0 => Some(1),
            _ => None,
        };
        let (accel, _) = Accel::build(&tris, &tris.iter().map(side).collect::<Vec<_>>());
        assert!(accel.walks_alone(), "a tree of {} levels", accel.depth);
        let (mut entries, mut occluded, mut clear) = (0, 0, 0);
        for case in 0..300u64 {
            let mut rng = SampleRng::new(23, case, 0);
            let mut point =
                |scale: f32| Vec3::new(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5) * scale;
            // A square of side 0.02–1 and a triangle about 1 across, on opposite sides of the soup's middle.
            let (centre_a, centre_b) = (point(12.0), point(12.0));
            let (u, v) = (point(1.0).normalize_or(Vec3::X), point(1.0).normalize_or(Vec3::Y));
            let n_a = u.cross(v).normalize_or(Vec3::Z);
            let (u, v) = (u, n_a.cross(u));
            let half = 0.01 + 0.49 * (case % 7) as f32 / 6.0;
            let a =
                [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].map(|(s, t)| centre_a + (u * s + v * t) * half);
            let b = [centre_b + point(1.0), centre_b + point(1.0), centre_b + point(1.0)];
            let Some(n_b) = (b[1] - b[0]).cross(b[2] - b[0]).try_normalize() else { continue };
            let towards = |n: Vec3, from: Vec3, to: Vec3| if n.dot(to - from) >= 0.0 { n } else { -n };
            let (n_a, n_b) = (towards(n_a, centre_a, centre_b), towards(n_b, centre_b, centre_a));
            let shaft = Shaft::between(&a, (n_a, n_a.dot(a[0])), &b, (n_b, n_b.dot(b[0])), 1e-4);
            let Some(entry) = accel.shaft_entry(std::slice::from_ref(&shaft)) else { continue };
            entries += 1;
            for bundle in 0..8 {
                let rays: [(Vec3, Vec3); 8] = std::array::from_fn(|_| {
                    let (s, t) = (rng.uniform() * 2.0 - 1.0, rng.uniform() * 2.0 - 1.0);
                    let p = centre_a + (u * s + v * t) * half;
                    let (r1, r2) = (rng.uniform().sqrt(), rng.uniform());
                    let x = b[0] * (1.0 - r1) + b[1] * (r1 * (1.0 - r2)) + b[2] * (r1 * r2);
                    (p, x - p)
                });
                let skips: [u32; 8] = std::array::from_fn(|l| [SKIP_NONE, 0, 1][(bundle + l) % 3]);
                let [origins, dirs] = [rays.map(|r| r.0), rays.map(|r| r.1)].map(|v| Vec3x8::from_lanes(&v));
                let t_max = 1.0 - 1e-6;
                let bits = accel.occluded_lanes(&origins, &dirs, t_max, 0xff, skips, &[Some(&entry); 8]);
                for (l, &(o, d)) in rays.iter().enumerate() {
                    let skip = Some(skips[l]).filter(|&s| s != SKIP_NONE);
                    let from_root = accel.occluded(o, d, t_max, skip);
                    assert_eq!(bits & (1 << l) != 0, from_root, "case {case}, bundle {bundle}, ray {l}");
                    (occluded, clear) = if from_root { (occluded + 1, clear) } else { (occluded, clear + 1) };
                }
            }
        }
        assert!(entries > 150, "only {entries} of 300 shafts had an entry below the root's children");
        assert!(occluded > 1000 && clear > 1000, "{occluded} rays occluded, {clear} clear: the test checks too little");
    }
}
