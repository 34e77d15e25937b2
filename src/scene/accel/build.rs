//! Building the 8-wide BVH: obvhs builds a binary BVH (PLOC clustering and reinsertion, Meister & Bittner 2018)
//! whose small subtrees are chosen as leaves by the SAH ([`sah_leaves`]); the tree is collapsed top-down into
//! nodes of up to eight children by repeatedly opening the child with the largest surface area (Wald et al.,
//! "Getting Rid of Packets", 2008). Each leaf (at most eight triangles) becomes one packet: testing eight
//! triangles at once costs what testing one does.

use super::node::{Child, ChildGroups, NO_GROUP, Node8};
use super::packet::TrianglePacket;
use arrayvec::ArrayVec;
use glam::Vec3;
use obvhs::{
    BvhBuildParams,
    bvh2::{Bvh2, reinsertion::ReinsertionOptimizer},
    ploc::PlocBuilder,
    triangle::Triangle as ObvhsTriangle,
};

/// Below this many node levels a subtree becomes one leaf, whatever its size; it bounds the traversal stack
/// (at most seven entries per level) on pathological input.
pub(super) const MAX_DEPTH: usize = 16;

const WIDTH: usize = 8;

pub(super) struct Built {
    pub nodes: Vec<Node8>,
    /// The groups of each node's children.
    pub groups: Vec<ChildGroups>,
    pub packets: Vec<TrianglePacket>,
    pub root: Child,
    /// `order[i]` = input index of the i-th stored triangle; packets refer to stored indices.
    pub order: Vec<u32>,
}

/// Builds the tree over a non-empty triangle list, with each triangle's group (see [`super::Accel::build`]).
pub(super) fn build(positions: &[[Vec3; 3]], groups: &[Option<u32>]) -> Built {
    let (bvh, leaf_sizes) = binary_tree(positions);
    // Group ids are non-negative as i32; NO_GROUP and SKIP_NOTHING are negative.
    let groups = groups.iter().map(|g| g.map_or(NO_GROUP, |g| i32::try_from(g).expect("group id below 2³¹"))).collect();
    // Reserved ahead (a binary tree of n leaves collapses to about a seventh as many wide nodes; a packet holds
    // up to eight triangles): growing these by doubling took 7% of a 1M-triangle load in copies and page faults.
    let wide = bvh.nodes.len() / 7 + 1;
    let mut builder = Builder {
        bvh: &bvh,
        leaf_sizes,
        gathered: Vec::new(),
        stack: Vec::new(),
        positions,
        groups,
        nodes: Vec::with_capacity(wide),
        child_groups: Vec::with_capacity(wide),
        packets: Vec::with_capacity(positions.len() / 4 + 1),
        order: Vec::with_capacity(positions.len()),
    };
    let (root, _) = builder.child(0, 0);
    let (nodes, groups, packets, order) = (builder.nodes, builder.child_groups, builder.packets, builder.order);
    Built { nodes, groups, packets, root, order }
}

/// obvhs's binary tree over the triangles, and per node its triangle count if it is a leaf (see [`sah_leaves`]).
fn binary_tree(positions: &[[Vec3; 3]]) -> (Bvh2, Vec<u32>) {
    let input = obvhs_triangles(positions);
    // obvhs's fast preset: on a 1M-triangle mesh it builds in about two thirds of the medium preset's time, and its
    // trees cost no more to trace (callgrind, instructions per render: 1–2% fewer on the knot, as many on the
    // Cornell box). Its steps are those of `obvhs::bvh2::builder::build_bvh2_from_tris` but the last: the preset
    // neither pre-splits nor reinserts after the leaf collapse, and the collapse itself (which copies the whole
    // tree: on a 1M-triangle mesh, about 200 of obvhs's 600 ms) is replaced by `sah_leaves`, which only marks the
    // same leaves.
    let config = BvhBuildParams::fast_build();
    debug_assert!(!config.pre_split && config.post_collapse_reinsertion_batch_ratio_multiplier == 0.0);
    let mut bvh = PlocBuilder::with_capacity(input.len()).build(
        config.ploc_search_distance,
        &input,
        (0..input.len() as u32).collect(),
        config.sort_precision,
        config.search_depth_threshold,
    );
    drop(input);
    ReinsertionOptimizer::default().run(&mut bvh, config.reinsertion_batch_ratio, None);
    let leaf_sizes = sah_leaves(&bvh, config.max_prims_per_leaf, config.collapse_traversal_cost);
    (bvh, leaf_sizes)
}

fn obvhs_triangles(positions: &[[Vec3; 3]]) -> Vec<ObvhsTriangle> {
    positions.iter().map(|[a, b, c]| ObvhsTriangle { v0: (*a).into(), v1: (*b).into(), v2: (*c).into() }).collect()
}

/// Appends the triangles under binary node `id` to `out`, in the order of a depth-first walk (left first);
/// `stack` is scratch.
fn subtree_triangles(bvh: &Bvh2, id: usize, out: &mut Vec<u32>, stack: &mut Vec<usize>) {
    stack.clear();
    stack.push(id);
    while let Some(n) = stack.pop() {
        let node = &bvh.nodes[n];
        let first = node.first_index as usize;
        if node.is_leaf() {
            out.extend_from_slice(&bvh.primitive_indices[first..first + node.prim_count as usize]);
        } else {
            stack.extend([first + 1, first]);
        }
    }
}

struct Builder<'a> {
    bvh: &'a Bvh2,
    /// Per binary node, its triangle count if it is a leaf of the wide tree (see [`sah_leaves`]), else 0.
    leaf_sizes: Vec<u32>,
    /// Scratch of [`Builder::leaf`]: the triangles of a subtree, and the nodes still to visit.
    gathered: Vec<u32>,
    stack: Vec<usize>,
    positions: &'a [[Vec3; 3]],
    /// Per input triangle, its group or [`NO_GROUP`].
    groups: Vec<i32>,
    nodes: Vec<Node8>,
    child_groups: Vec<ChildGroups>,
    packets: Vec<TrianglePacket>,
    order: Vec<u32>,
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
        self.leaf_sizes[id] == 0
    }

    fn half_area(&self, id: usize) -> f32 {
        self.bvh.nodes[id].aabb.half_area()
    }

    /// Every triangle under binary node `id`, eight to a packet, in the order of a depth-first walk (left first).
    fn leaf(&mut self, id: usize) -> (Child, i32) {
        // A leaf of obvhs is read in place; a subtree (an SAH leaf, or one cut off at MAX_DEPTH) is gathered first.
        let bvh = self.bvh;
        let node = &bvh.nodes[id];
        let mut gathered = std::mem::take(&mut self.gathered);
        gathered.clear();
        let triangles = if node.is_leaf() {
            let first = node.first_index as usize;
            &bvh.primitive_indices[first..first + node.prim_count as usize]
        } else {
            subtree_triangles(bvh, id, &mut gathered, &mut self.stack);
            &gathered[..]
        };
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
        self.gathered = gathered;
        (Child { first: first_packet, packets: self.packets.len() as u32 - first_packet }, group)
    }
}

/// The leaves of obvhs's SAH leaf collapse (`obvhs::bvh2::leaf_collapser::collapse`), marked without rewriting the
/// tree: per binary node, its triangle count n if it is a leaf of the collapsed tree, else 0. Bottom up, an inner
/// node whose two children are leaves becomes one when n = n_l + n_r ≤ `max_prims` and the SAH says testing its
/// triangles costs no more than entering its children: A·(n − c_t) ≤ A_l·n_l + A_r·n_r (A: half surface areas,
/// c_t: `traversal_cost`). Like obvhs, a tree of at most 2·`max_prims` + 1 nodes or `max_prims` triangles is kept
/// as it is; the unit test checks that the leaves are obvhs's, triangle for triangle.
fn sah_leaves(bvh: &Bvh2, max_prims: u32, traversal_cost: f32) -> Vec<u32> {
    let nodes = &bvh.nodes;
    let mut sizes: Vec<u32> = nodes.iter().map(|n| if n.is_leaf() { n.prim_count } else { 0 }).collect();
    let max_prims = max_prims.clamp(1, 255);
    if max_prims <= 1 || nodes.len() as u32 <= 2 * max_prims + 1 || bvh.primitive_indices.len() as u32 <= max_prims {
        return sizes;
    }
    // Post-order, with an explicit stack (a degenerate tree may be as deep as it has triangles): a node is
    // pushed again, marked, below its children, and decided when it comes up the second time.
    let mut stack = vec![(0usize, false)];
    while let Some((id, children_done)) = stack.pop() {
        let node = &nodes[id];
        if node.is_leaf() {
            continue;
        }
        let first = node.first_index as usize;
        if !children_done {
            stack.extend([(id, true), (first + 1, false), (first, false)]);
            continue;
        }
        let (left, right) = (&nodes[first], &nodes[first + 1]);
        let (n_l, n_r) = (sizes[first], sizes[first + 1]);
        let n = n_l + n_r;
        if n_l > 0 && n_r > 0 && n <= max_prims {
            let collapse_cost = node.aabb().half_area() * (n as f32 - traversal_cost);
            let base_cost = left.aabb().half_area() * n_l as f32 + right.aabb().half_area() * n_r as f32;
            let same_triangle = left.first_index == right.first_index && n == 2;
            if collapse_cost <= base_cost || same_triangle {
                sizes[id] = n;
            }
        }
    }
    sizes
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

    /// A tree, depth first (left first): per node its box and, for a leaf, its triangles in order.
    type Walk = Vec<([[u32; 3]; 2], Option<Vec<u32>>)>;

    fn walk(bvh: &Bvh2, is_leaf: impl Fn(usize) -> bool) -> Walk {
        let mut out = Walk::new();
        let mut stack = vec![0];
        while let Some(id) = stack.pop() {
            let node = &bvh.nodes[id];
            let bits = |v: glam::Vec3A| v.to_array().map(f32::to_bits);
            let first = node.first_index as usize;
            if is_leaf(id) {
                let mut triangles = Vec::new();
                subtree_triangles(bvh, id, &mut triangles, &mut Vec::new());
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
            let (ours, sizes) = binary_tree(tris);
            let expected = walk(&theirs, |id| theirs.nodes[id].is_leaf());
            assert_eq!(walk(&ours, |id| sizes[id] > 0), expected, "{} triangles", tris.len());
            collapsed_anywhere += expected.iter().filter(|(_, t)| t.as_ref().is_some_and(|t| t.len() > 1)).count();
        }
        assert!(collapsed_anywhere > 1000, "the soups exercise the collapse: {collapsed_anywhere} leaves of 2–8");
    }
}
