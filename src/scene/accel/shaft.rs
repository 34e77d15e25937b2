//! Shaft culling (Haines & Wallace, "Shaft Culling for Efficient Ray-Traced Radiosity", 1994): whether anything
//! can stop a segment from one flat patch A (a pixel's footprint on the surface it sees) to another, B (an
//! emitter triangle), found once for every segment between them.
//!
//! Every such segment lies in the convex hull of A ∪ B, and the hull lies in the half-space `n·x ≤ h(n)` for
//! every direction n, `h(n) = max n·c` over the patches' corners c (the support function). The shaft keeps the
//! half-spaces whose planes touch the hull along three corners (its faces: through an edge of one patch and a
//! corner of the other, or a patch's own plane), each moved out by a margin that covers the segments' ends
//! moved off their surfaces and the rounding of the tests. A triangle whose three vertices all lie beyond one
//! of them meets no segment; so does a box whose every point does. The faces alone cannot set apart a large
//! triangle that wraps around the hull (a wall beside a thin shaft: separating them may take an axis of
//! neither), so the shaft keeps the six half-spaces of the hull's bounding box as well (Haines and Wallace's
//! shaft is the box's, cut by planes through the patches' edges).
//!
//! Two more half-spaces hold every segment but are not faces: the fronts of A's and of B's planes, when each
//! patch lies wholly in front of the other's plane. A shadow ray leaves A's surface on its front and ends, moved
//! off B, in front of B's plane (`math::offset`), so it meets no triangle lying on or behind either plane, the
//! way a ray to a convex emitter skips the rest of its group (`scene::convex`).

use super::node::Child;
use super::traverse::STACK;
use super::{Accel, TrianglePacket};
use arrayvec::ArrayVec;
use glam::Vec3;
use wide::{CmpGt, CmpLe, f32x8};

/// At most this many half-spaces are kept: the six of the hull's bounding box, and its faces (two quads' hull has
/// at most 4 + 4 + 2 = 10 distinct ones; a quad and a triangle's, 9).
const MAX_FACES: usize = 22;

/// The region every segment between two flat patches lies in, as half-spaces.
#[derive(Clone, Debug)]
pub struct Shaft {
    /// `(n, d)`: the hull lies in `n·x ≤ d`, margin included.
    faces: ArrayVec<(Vec3, f32), MAX_FACES>,
    /// `(n, d)`: every segment lies in `n·x > d`; a triangle with `n·v ≤ d` at every vertex meets none.
    fronts: ArrayVec<(Vec3, f32), 2>,
}

impl Shaft {
    /// The shaft between the convex polygons `a` and `b` (their corners in order, three or four each) in the
    /// planes `n·x = d` given as `(n, d)` (unit n towards the side the segments leave or reach the patch on);
    /// its faces are moved out by `margin`.
    pub fn between(a: &[Vec3], plane_a: (Vec3, f32), b: &[Vec3], plane_b: (Vec3, f32), margin: f32) -> Self {
        let corners: ArrayVec<Vec3, 8> = a.iter().chain(b).copied().collect();
        let mut faces = ArrayVec::new();
        let (lo, hi) =
            corners.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), c| (lo.min(*c), hi.max(*c)));
        for axis in [Vec3::X, Vec3::Y, Vec3::Z] {
            faces.push((axis, axis.dot(hi) + margin));
            faces.push((-axis, -axis.dot(lo) + margin));
        }
        let mut face = |n: Vec3, on: [Vec3; 3]| {
            let Some(n) = n.try_normalize() else { return };
            let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
            for c in &corners {
                let s = n.dot(*c);
                (lo, hi) = (lo.min(s), hi.max(s));
            }
            let touch = |h: f32, n: Vec3| on.iter().all(|c| (n.dot(*c) - h).abs() <= margin);
            for (n, h) in [(n, hi), (-n, -lo)] {
                // A face touches the hull along three corners; a plane already kept is not kept twice. That test
                // (a dot product with each kept face) comes last: run for every candidate plane it was 43% of
                // this function's instructions on the knot's tiles.
                let new = || !faces.iter().any(|&(m, _): &(Vec3, f32)| m.dot(n) > 1.0 - 1e-6);
                if touch(h, n) && !faces.is_full() && new() {
                    faces.push((n, h + margin));
                }
            }
        };
        for (p, q) in [(a, b), (b, a)] {
            for i in 0..p.len() {
                let (u, v) = (p[i], p[(i + 1) % p.len()]);
                for &w in q {
                    face((v - u).cross(w - u), [u, v, w]);
                }
            }
            face((p[1] - p[0]).cross(p[2] - p[0]), [p[0], p[1], p[2]]);
        }
        // Each patch's front, where the other lies wholly in front of it.
        let mut fronts = ArrayVec::new();
        for ((n, d), q) in [(plane_a, b), (plane_b, a)] {
            if q.iter().all(|c| n.dot(*c) - d > margin) {
                fronts.push((n, d));
            }
        }
        Self { faces, fronts }
    }

    /// Whether a triangle with these vertices meets no segment: beyond a face, or on or behind a front (what
    /// `TrianglePacket::cleared_by` finds for eight at once), or found outside the hull when clipped by every
    /// face in turn (Sutherland–Hodgman): nothing of it is left.
    fn clears(&self, v: [Vec3; 3]) -> bool {
        if self.faces.iter().any(|&(n, d)| v.iter().all(|p| n.dot(*p) > d))
            || self.fronts.iter().any(|&(n, d)| v.iter().all(|p| n.dot(*p) <= d))
        {
            return true;
        }
        // Each clip adds at most one corner to the polygon.
        let mut polygon: ArrayVec<Vec3, { 3 + MAX_FACES }> = v.into_iter().collect();
        for &(n, d) in &self.faces {
            let mut kept = ArrayVec::<Vec3, { 3 + MAX_FACES }>::new();
            for (i, &p) in polygon.iter().enumerate() {
                let q = polygon[(i + 1) % polygon.len()];
                let (sp, sq) = (n.dot(p) - d, n.dot(q) - d);
                if sp <= 0.0 {
                    kept.push(p);
                }
                if (sp <= 0.0) != (sq <= 0.0) && !kept.is_full() {
                    kept.push(p + (q - p) * (sp / (sp - sq)));
                }
            }
            if kept.is_empty() {
                return true;
            }
            polygon = kept;
        }
        false
    }
}

impl TrianglePacket {
    /// The lanes whose triangle [`Shaft::clears`] (unused lanes included).
    fn cleared_by(&self, shaft: &Shaft) -> u32 {
        let (v0, e1, e2) = self.edges();
        let mut cleared = f32x8::ZERO;
        let dot = |n: Vec3, v: [f32x8; 3]| v[0] * n.x + v[1] * n.y + v[2] * n.z;
        let (v1, v2) = ([0, 1, 2].map(|a| v0[a] + e1[a]), [0, 1, 2].map(|a| v0[a] + e2[a]));
        for &(n, d) in &shaft.faces {
            let d = f32x8::splat(d);
            cleared |= dot(n, *v0).cmp_gt(d) & dot(n, v1).cmp_gt(d) & dot(n, v2).cmp_gt(d);
        }
        for &(n, d) in &shaft.fronts {
            let d = f32x8::splat(d);
            cleared |= dot(n, *v0).cmp_le(d) & dot(n, v1).cmp_le(d) & dot(n, v2).cmp_le(d);
        }
        let unused = crate::math::lanes_equal(&self.ids, u32::MAX);
        cleared.move_mask() as u32 | unused
    }
}

impl Accel {
    /// The ids of the triangles that may meet a segment in `shaft`, but for those `left_out` names: every
    /// triangle that can stop such a segment. `None` where there are more than eight (more than sixteen before
    /// clipping), or the walk would look at more than `budget` nodes and leaves.
    pub fn shaft_blockers(
        &self,
        shaft: &Shaft,
        left_out: impl Fn(u32) -> bool,
        budget: u32,
    ) -> Option<ArrayVec<u32, 8>> {
        // The triangles no face or front clears at once, clipped once the walk is over: a shaft through a dense
        // mesh gives up on its seventeenth, where clipping each as it came cost the knot's tiles more than their
        // shadow rays saved.
        let mut open_ones = ArrayVec::<(u32, [Vec3; 3]), 16>::new();
        let Some(root) = self.root else { return Some(ArrayVec::new()) };
        let mut stack = ArrayVec::<Child, STACK>::new();
        stack.push(root);
        let mut visits = 0;
        while let Some(child) = stack.pop() {
            visits += 1;
            if visits > budget {
                return None;
            }
            if child.is_leaf() {
                for packet in &self.packets[child.first as usize..(child.first + child.packets) as usize] {
                    let mut open = !packet.cleared_by(shaft) & 0xff;
                    while open != 0 {
                        let lane = open.trailing_zeros() as usize;
                        let id = packet.ids[lane];
                        if let (false, Some(v)) = (left_out(id), packet.vertices(lane)) {
                            open_ones.try_push((id, v)).ok()?;
                        }
                        open &= open - 1;
                    }
                }
            } else {
                let node = &self.nodes[child.first as usize];
                let mut mask = node.used() & !node.cleared_by(shaft);
                while mask != 0 {
                    stack.push(node.children[mask.trailing_zeros() as usize]);
                    mask &= mask - 1;
                }
            }
        }
        let mut found = ArrayVec::new();
        for (id, v) in open_ones {
            if !shaft.clears(v) {
                found.try_push(id).ok()?;
            }
        }
        Some(found)
    }
}

impl super::node::Node8 {
    /// The children whose box lies wholly beyond one of the shaft's faces or on or behind one of its fronts.
    fn cleared_by(&self, shaft: &Shaft) -> u32 {
        let bounds = self.bounds();
        // The box corner least (most) along n: its dot product is the box's least (greatest).
        let extreme = |n: Vec3, least: bool| {
            let mut s = f32x8::ZERO;
            for axis in 0..3 {
                let lo = (n[axis] >= 0.0) == least;
                s += bounds[if lo { axis } else { axis + 3 }] * f32x8::splat(n[axis]);
            }
            s
        };
        let mut cleared = f32x8::ZERO;
        for &(n, d) in &shaft.faces {
            cleared |= extreme(n, true).cmp_gt(f32x8::splat(d));
        }
        for &(n, d) in &shaft.fronts {
            cleared |= extreme(n, false).cmp_le(f32x8::splat(d));
        }
        cleared.move_mask() as u32
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::SampleRng;

    fn square(centre: Vec3, half: f32) -> [Vec3; 4] {
        [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].map(|(x, z)| centre + Vec3::new(x, 0.0, z) * half)
    }

    /// Every point of every segment between the patches lies in every face's half-space; a point beyond the
    /// hull (pushed out from a point of it along a face's normal) lies outside that face's.
    #[test]
    fn the_shaft_holds_every_segment_and_no_more() {
        let floor = square(Vec3::new(0.3, 0.0, -0.2), 0.01);
        let light = [Vec3::new(-0.2, 1.9, -0.1), Vec3::new(0.25, 1.9, -0.1), Vec3::new(0.0, 1.95, 0.3)];
        let n_light = (light[1] - light[0]).cross(light[2] - light[0]).normalize();
        let n_light = if n_light.y > 0.0 { -n_light } else { n_light };
        let shaft = Shaft::between(&floor, (Vec3::Y, 0.0), &light, (n_light, n_light.dot(light[0])), 1e-5);
        assert!(shaft.faces.len() >= 7, "{} faces", shaft.faces.len());
        assert_eq!(shaft.fronts.len(), 2, "each patch lies in front of the other");
        let mut rng = SampleRng::new(3, 0, 0);
        for _ in 0..10_000 {
            let (u, v) = (rng.uniform(), rng.uniform());
            let a = floor[0] + (floor[1] - floor[0]) * u + (floor[3] - floor[0]) * v;
            let (su, w) = (rng.uniform().sqrt(), rng.uniform());
            let b = light[0] * (1.0 - su) + light[1] * su * (1.0 - w) + light[2] * su * w;
            let x = a.lerp(b, rng.uniform());
            for &(n, d) in &shaft.faces {
                assert!(n.dot(x) <= d, "{x} beyond the face {n}, {d}");
                // A triangle just beyond this face, around x's projection on it, is cleared.
                let beyond = x + n * (d - n.dot(x) + 1e-3);
                let t = n.any_orthonormal_vector() * 1e-3;
                assert!(shaft.clears([beyond, beyond + t, beyond + n.cross(t)]));
            }
        }
        // A triangle across the middle of the shaft is not cleared; one under the floor is (the floor's front).
        let middle = (floor[0] + light[0]) * 0.5;
        assert!(!shaft.clears([middle - Vec3::X, middle + Vec3::X, middle + Vec3::Z]));
        assert!(shaft.clears([Vec3::new(-5.0, 0.0, -5.0), Vec3::new(5.0, 0.0, -5.0), Vec3::new(0.0, -1.0, 5.0)]));
    }
}
