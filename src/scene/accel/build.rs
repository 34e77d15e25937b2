//! Building the 8-wide BVH: obvhs builds a binary BVH (PLOC clustering and reinsertion, Meister & Bittner 2018)
//! whose small subtrees are chosen as leaves by the SAH ([`SahLeaves`]); the tree is collapsed top-down into
//! nodes of up to eight children by repeatedly opening the child with the largest surface area (Wald et al.,
//! "Getting Rid of Packets", 2008). Each leaf (at most eight triangles) becomes one packet: testing eight
//! triangles at once costs what testing one does.

use super::node::{Child, ChildGroups, NO_GROUP, Node8};
use super::packet::TrianglePacket;
use arrayvec::ArrayVec;
use glam::{Vec3, Vec3A};
use obvhs::{
    Boundable, BvhBuildParams,
    aabb::Aabb,
    bvh2::{Bvh2, reinsertion::ReinsertionOptimizer},
    ploc::PlocBuilder,
};

/// Below this many node levels a subtree becomes one leaf, whatever its size; it bounds the traversal stack
/// (at most seven entries per level) on pathological input.
pub(super) const MAX_DEPTH: usize = 16;

const WIDTH: usize = 8;

/// A would-be leaf whose box's half surface area is at least this share of the scene's is judged by the SAH with
/// [`LARGE_LEAF_TRAVERSAL_COST`] instead of the preset's cost. The SAH counts rays as lines that cross a box from
/// outside, but shadow and reflected rays start on the scene's surfaces, and a box that spans a room holds
/// surfaces from all over it: every ray starting there enters the box, which the SAH does not count (the
/// end-point overlap of Aila, Karras & Laine, "On Quality Metrics of Bounding Volume Hierarchies", 2013). Measured:
/// 10⁻⁴ already changed the knot's leaves; 10⁻³ changes only the rooms' (walls merged with blocks).
const LARGE_LEAF_SHARE: f32 = 1e-3;

/// The SAH's traversal cost (against 1 per triangle) for leaves of [`LARGE_LEAF_SHARE`] or more: the preset's 3
/// made a leaf of the Cornell box's back wall and two faces of the tall block, and one of seven triangles of
/// occluded-light's room; 2 splits them (the walls' flat boxes are rarely entered). For every leaf, 2 made the
/// knot's leaves smaller and its renders about 3% slower.
const LARGE_LEAF_TRAVERSAL_COST: f32 = 2.0;

pub(super) struct Built {
    pub nodes: Vec<Node8>,
    /// The groups of each node's children.
    pub groups: Vec<ChildGroups>,
    pub packets: Vec<TrianglePacket>,
    pub root: Child,
    /// The wide levels on the longest path from the root to a leaf (0 when the root is a leaf).
    pub depth: usize,
    /// `order[i]` = input index of the i-th stored triangle; packets refer to stored indices.
    pub order: Vec<u32>,
}

/// Builds the tree over a non-empty triangle list, with each triangle's group (see [`super::Accel::build`]).
pub(super) fn build(positions: &[[Vec3; 3]], groups: &[Option<u32>]) -> Built {
    let (bvh, sah) = binary_tree(positions, LARGE_LEAF_SHARE);
    // Group ids are non-negative as i32; NO_GROUP and SKIP_NOTHING are negative.
    let groups = groups.iter().map(|g| g.map_or(NO_GROUP, |g| i32::try_from(g).expect("group id below 2³¹"))).collect();
    // Reserved ahead (a binary tree of n leaves collapses to about a seventh as many wide nodes; a packet holds
    // up to eight triangles): growing these by doubling took 7% of a 1M-triangle load in copies and page faults.
    let wide = bvh.nodes.len() / 7 + 1;
    let mut builder = Builder {
        bvh: &bvh,
        sah,
        positions,
        groups,
        nodes: Vec::with_capacity(wide),
        child_groups: Vec::with_capacity(wide),
        packets: Vec::with_capacity(positions.len() / 4 + 1),
        order: Vec::with_capacity(positions.len()),
        depth: 0,
    };
    let (root, _) = builder.child(0, 0);
    let (nodes, groups, packets, order) = (builder.nodes, builder.child_groups, builder.packets, builder.order);
    Built { nodes, groups, packets, root, depth: builder.depth, order }
}

/// obvhs's binary tree over the triangles, and the leaves the SAH chooses in it (with the traversal cost of
/// large leaves for those of `large_share` of the scene or more, see [`LARGE_LEAF_SHARE`]).
fn binary_tree(positions: &[[Vec3; 3]], large_share: f32) -> (Bvh2, SahLeaves) {
    let input: &[Corners] = bytemuck::cast_slice(positions);
    // obvhs's fast preset: on a 1M-triangle mesh it builds in about two thirds of the medium preset's time, and its
    // trees cost no more to trace (callgrind, instructions per render: 1–2% fewer on the knot, as many on the
    // Cornell box). Its steps are those of `obvhs::bvh2::builder::build_bvh2_from_tris` but the last: the preset
    // neither pre-splits nor reinserts after the leaf collapse, and the collapse itself (which copies the whole
    // tree: on a 1M-triangle mesh, about 200 of obvhs's 600 ms) is replaced by `SahLeaves`, which only marks the
    // same leaves.
    let config = BvhBuildParams::fast_build();
    debug_assert!(!config.pre_split && config.post_collapse_reinsertion_batch_ratio_multiplier == 0.0);
    let mut bvh = PlocBuilder::with_capacity(input.len()).build(
        config.ploc_search_distance,
        input,
        (0..input.len() as u32).collect(),
        config.sort_precision,
        config.search_depth_threshold,
    );
    ReinsertionOptimizer::default().run(&mut bvh, config.reinsertion_batch_ratio, None);
    let costs = [config.collapse_traversal_cost, LARGE_LEAF_TRAVERSAL_COST];
    let sah = SahLeaves::new(&bvh, config.max_prims_per_leaf, costs, large_share);
    (bvh, sah)
}

/// A triangle's corners as obvhs bounds them, read in place: copying a 1M-triangle mesh into obvhs's own
/// triangle type (48 bytes each) took 48 MB of fresh memory. The box is the one obvhs's triangle gives (a min and
/// max of the same values), so the tree is the same.
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(transparent)]
struct Corners([Vec3; 3]);

impl Boundable for Corners {
    #[inline(always)]
    fn aabb(&self) -> Aabb {
        Aabb::from_points(&self.0.map(Vec3A::from))
    }
}

struct Builder<'a> {
    bvh: &'a Bvh2,
    /// The leaves of the wide tree, and each node's triangles.
    sah: SahLeaves,
    positions: &'a [[Vec3; 3]],
    /// Per input triangle, its group or [`NO_GROUP`].
    groups: Vec<i32>,
    nodes: Vec<Node8>,
    child_groups: Vec<ChildGroups>,
    packets: Vec<TrianglePacket>,
    order: Vec<u32>,
    /// The deepest wide level made so far.
    depth: usize,
}

impl Builder<'_> {
    /// The wide child standing for binary node `id`, at `depth` wide levels below the root, and the group all
    /// its triangles belong to (or [`NO_GROUP`]).
    fn child(&mut self, id: usize, depth: usize) -> (Child, i32) {
        if !self.splits(id) || depth >= MAX_DEPTH {
            return self.leaf(id);
        }
        let first = self.bvh.nodes[id].first_index as usize;
        let mut open = ArrayVec::<usize, WIDTH>::from_iter([first, first + 1]);
        while !open.is_full() {
            let widest = (0..open.len())
                .filter(|&i| self.splits(open[i]))
                .max_by(|&i, &j| self.half_area(open[i]).total_cmp(&self.half_area(open[j])));
            let Some(i) = widest else { break };
            let node = open.swap_remove(i);
            let first = self.bvh.nodes[node].first_index as usize;
            open.extend([first, first + 1]);
        }
        self.depth = self.depth.max(depth + 1);
        let slot = self.nodes.len();
        self.nodes.push(Node8::new(&[]));
        self.child_groups.push(ChildGroups::new(&[]));
        let (mut children, mut groups) = (ArrayVec::<_, WIDTH>::new(), ArrayVec::<_, WIDTH>::new());
        for c in open {
            let aabb = self.bvh.nodes[c].aabb;
            let (child, group) = self.child(c, depth + 1);
            children.push(([aabb.min.into(), aabb.max.into()], child));
            groups.push(group);
        }
        self.nodes[slot] = Node8::new(&children);
        self.child_groups[slot] = ChildGroups::new(&groups);
        (Child { first: slot as u32, packets: 0 }, common_group(groups))
    }

    /// Whether binary node `id` becomes a wide node rather than a leaf: the SAH's leaves (at most eight
    /// triangles) become packets as they are. Merging small subtrees into one packet would save node tests but
    /// grow boxes: shadow rays leaving one wall would then enter the box it shares with the next, and on the
    /// Cornell box they tested 2.24 packets per ray instead of 1.43.
    fn splits(&self, id: usize) -> bool {
        !self.sah.leaf[id]
    }

    fn half_area(&self, id: usize) -> f32 {
        self.bvh.nodes[id].aabb.half_area()
    }

    /// Every triangle under binary node `id`, eight to a packet, in the order of a depth-first walk (left first).
    fn leaf(&mut self, id: usize) -> (Child, i32) {
        let triangles = self.sah.triangles(id);
        let first_packet = self.packets.len() as u32;
        for chunk in triangles.chunks(WIDTH) {
            let first_stored = self.order.len() as u32;
            self.order.extend_from_slice(chunk);
            let positions = self.positions;
            let packet =
                TrianglePacket::from_fn(chunk.len(), |i| (positions[chunk[i] as usize], first_stored + i as u32));
            self.packets.push(packet);
        }
        let group = common_group(triangles.iter().map(|&t| self.groups[t as usize]));
        (Child { first: first_packet, packets: self.packets.len() as u32 - first_packet }, group)
    }
}

/// The leaves of obvhs's SAH leaf collapse (`obvhs::bvh2::leaf_collapser::collapse`), marked without rewriting the
/// tree, and every node's triangles found without walking its subtree again.
struct SahLeaves {
    /// Per binary node, whether it is a leaf of the collapsed tree (at most `max_prims` triangles).
    leaf: Vec<bool>,
    /// Per binary node, where its subtree's triangles start and end in `triangles`.
    spans: Vec<(u32, u32)>,
    /// Every triangle, in the order of a depth-first walk (left first): each subtree's are consecutive.
    triangles: Vec<u32>,
}

impl SahLeaves {
    /// Bottom up, an inner node whose two children are leaves becomes one when n = n_l + n_r ≤ `max_prims` and the
    /// SAH says testing its triangles costs no more than entering its children: A·(n − c_t) ≤ A_l·n_l + A_r·n_r
    /// (A: half surface areas, c_t: `traversal_costs[0]`, or `traversal_costs[1]` where A is at least
    /// `large_share` of the root's). Like obvhs, a tree of at most 2·`max_prims` + 1 nodes or `max_prims` triangles
    /// is kept as it is; with `large_share` = ∞ the leaves are obvhs's, triangle for triangle (a unit test).
    ///
    /// One walk, depth first and post-order, decides the leaves and lays out the triangles: the tree's nodes lie
    /// scattered in memory after the reinsertion, so each walk of it costs a cache miss per node (on a
    /// 1M-triangle mesh, about 100 ms), and the wide tree then reads a subtree's triangles in place.
    fn new(bvh: &Bvh2, max_prims: u32, traversal_costs: [f32; 2], large_share: f32) -> Self {
        let nodes = &bvh.nodes;
        let large = large_share * nodes[0].aabb().half_area();
        let mut leaf = vec![false; nodes.len()];
        let mut spans = vec![(0, 0); nodes.len()];
        let mut triangles = Vec::with_capacity(bvh.primitive_indices.len());
        let max_prims = max_prims.clamp(1, 255);
        let collapse =
            max_prims > 1 && nodes.len() as u32 > 2 * max_prims + 1 && bvh.primitive_indices.len() as u32 > max_prims;
        // An explicit stack (a degenerate tree may be as deep as it has triangles): an inner node is pushed again,
        // marked, below its children, and decided when it comes up the second time.
        let mut stack = vec![(0usize, false)];
        while let Some((id, children_done)) = stack.pop() {
            let node = &nodes[id];
            let at = node.first_index as usize;
            let start = triangles.len() as u32;
            if node.is_leaf() {
                triangles.extend_from_slice(&bvh.primitive_indices[at..at + node.prim_count as usize]);
                spans[id] = (start, triangles.len() as u32);
                leaf[id] = true;
                continue;
            }
            if !children_done {
                stack.extend([(id, true), (at + 1, false), (at, false)]);
                continue;
            }
            let ((first, middle), (_, end)) = (spans[at], spans[at + 1]);
            spans[id] = (first, end);
            let (n_l, n_r) = (middle - first, end - middle);
            let n = n_l + n_r;
            if collapse && leaf[at] && leaf[at + 1] && n <= max_prims {
                let (left, right) = (&nodes[at], &nodes[at + 1]);
                let area = node.aabb().half_area();
                let traversal_cost = traversal_costs[usize::from(area >= large)];
                let collapse_cost = area * (n as f32 - traversal_cost);
                let base_cost = left.aabb().half_area() * n_l as f32 + right.aabb().half_area() * n_r as f32;
                let same_triangle = left.first_index == right.first_index && n == 2;
                leaf[id] = collapse_cost <= base_cost || same_triangle;
            }
        }
        Self { leaf, spans, triangles }
    }

    /// The triangles under binary node `id`, in the order of a depth-first walk (left first).
    fn triangles(&self, id: usize) -> &[u32] {
        let (first, end) = self.spans[id];
        &self.triangles[first as usize..end as usize]
    }
}

/// The group shared by all of `groups`, or [`NO_GROUP`].
fn common_group(groups: impl IntoIterator<Item = i32>) -> i32 {
    let mut groups = groups.into_iter();
    match groups.next() {
        Some(first) if groups.all(|g| g == first) => first,
        _ => NO_GROUP,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::accel::tests::random_soup;
    use obvhs::bvh2::builder::build_bvh2_from_tris;
    use obvhs::triangle::Triangle as ObvhsTriangle;

    fn obvhs_triangles(positions: &[[Vec3; 3]]) -> Vec<ObvhsTriangle> {
        positions.iter().map(|[a, b, c]| ObvhsTriangle { v0: (*a).into(), v1: (*b).into(), v2: (*c).into() }).collect()
    }

    /// A tree, depth first (left first): per node its box and, for a leaf, its triangles in order.
    type Walk = Vec<([[u32; 3]; 2], Option<Vec<u32>>)>;

    /// `leaf_triangles(id)`: the triangles of node `id` if it is a leaf.
    fn walk(bvh: &Bvh2, leaf_triangles: impl Fn(usize) -> Option<Vec<u32>>) -> Walk {
        let mut out = Walk::new();
        let mut stack = vec![0];
        while let Some(id) = stack.pop() {
            let node = &bvh.nodes[id];
            let bits = |v: glam::Vec3A| v.to_array().map(f32::to_bits);
            let first = node.first_index as usize;
            if let Some(triangles) = leaf_triangles(id) {
                out.push(([bits(node.aabb.min), bits(node.aabb.max)], Some(triangles)));
            } else {
                out.push(([bits(node.aabb.min), bits(node.aabb.max)], None));
                stack.extend([first + 1, first]);
            }
        }
        out
    }

    #[test]
    fn the_leaves_marked_by_the_sah_are_those_of_obvhs_collapse() {
        let mut soups: Vec<Vec<[Vec3; 3]>> = [1, 2, 5, 8, 9, 10, 17, 40, 100, 3000, 20000]
            .iter()
            .flat_map(|&n| [(n, 0.5), (n, 4.0)])
            .enumerate()
            .map(|(i, (n, size))| random_soup(n, size, 7 + i as u64))
            .collect();
        soups.push(vec![[Vec3::new(-5.0, -5.0, 0.0), Vec3::new(5.0, -5.0, 0.0), Vec3::new(0.0, 5.0, 0.0)]; 300]);
        let knot = crate::scene::load_scene("assets/knot-box/knot-box.toml").expect("the knot loads");
        let scenes = crate::scene::every_bundled_scene(8, 8).map(|(_, scene, _)| scene).chain([knot]);
        soups.extend(scenes.map(|scene| scene.triangles.iter().map(|t| t.v).collect()));
        let mut collapsed_anywhere = 0;
        for tris in &soups {
            let theirs =
                build_bvh2_from_tris(&obvhs_triangles(tris), BvhBuildParams::fast_build(), &mut Default::default());
            let (ours, sah) = binary_tree(tris, f32::INFINITY);
            let expected = walk(&theirs, |id| {
                let node = &theirs.nodes[id];
                let first = node.first_index as usize;
                node.is_leaf().then(|| theirs.primitive_indices[first..first + node.prim_count as usize].to_vec())
            });
            assert_eq!(
                walk(&ours, |id| sah.leaf[id].then(|| sah.triangles(id).to_vec())),
                expected,
                "{} triangles",
                tris.len()
            );
            // Every node's triangles (those a subtree cut off at MAX_DEPTH reads) are its children's, left first.
            for (id, node) in ours.nodes.iter().enumerate().filter(|(_, n)| !n.is_leaf()) {
                let first = node.first_index as usize;
                assert_eq!(sah.triangles(id), [sah.triangles(first), sah.triangles(first + 1)].concat());
            }
            assert_eq!(sah.triangles(0).len(), tris.len());
            collapsed_anywhere += expected.iter().filter(|(_, t)| t.as_ref().is_some_and(|t| t.len() > 1)).count();
        }
        assert!(collapsed_anywhere > 1000, "the soups exercise the collapse: {collapsed_anywhere} leaves of 2–8");
    }

    /// The leaves of a tree: per leaf its box's half area and its triangles.
    fn leaves(bvh: &Bvh2, sah: &SahLeaves) -> Vec<(f32, Vec<u32>)> {
        let mut out = Vec::new();
        let mut stack = vec![0];
        while let Some(id) = stack.pop() {
            let node = &bvh.nodes[id];
            if sah.leaf[id] {
                out.push((node.aabb().half_area(), sah.triangles(id).to_vec()));
            } else {
                stack.extend([node.first_index as usize + 1, node.first_index as usize]);
            }
        }
        out
    }

    /// The SAH with the large leaves' traversal cost splits the Cornell box's leaf of its back wall and two faces
    /// of the tall block (a box of 71% of the room's half area, which nearly every shadow ray from the back half
    /// of the room enters), and leaves the knot's fine mesh as the preset has it, leaf for leaf.
    #[test]
    fn large_leaves_are_split_where_small_ones_are_not() {
        let scene = |path| crate::scene::load_scene(path).expect("a bundled scene loads");
        let positions = |scene: &crate::scene::Scene| scene.triangles.iter().map(|t| t.v).collect::<Vec<_>>();
        let cornell = positions(&scene("assets/cornell-box/cornell-box.toml"));
        // The largest box of a leaf of more than two triangles, as a share of the room's.
        let largest = |share| {
            let (bvh, sah) = binary_tree(&cornell, share);
            let root = bvh.nodes[0].aabb().half_area();
            leaves(&bvh, &sah).iter().filter(|(_, t)| t.len() > 2).map(|(a, _)| a / root).fold(0.0, f32::max)
        };
        let (preset, split) = (largest(f32::INFINITY), largest(LARGE_LEAF_SHARE));
        assert!(preset > 0.6, "the preset's largest leaf holds {preset} of the room");
        assert!(split < 0.2, "with large leaves split, the largest holds {split} of the room");
        let knot = positions(&scene("assets/knot-box/knot-box.toml"));
        let [preset, split] = [f32::INFINITY, LARGE_LEAF_SHARE].map(|share| {
            let (bvh, sah) = binary_tree(&knot, share);
            leaves(&bvh, &sah)
        });
        assert_eq!(preset, split, "the knot's leaves");
        assert!(preset.len() > 10_000);
    }
}
