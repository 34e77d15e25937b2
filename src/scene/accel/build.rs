//! Building the 8-wide BVH: obvhs builds a binary BVH (PLOC clustering, reinsertion and SAH leaf collapse,
//! Meister & Bittner 2018), which is collapsed top-down into nodes of up to eight children by repeatedly opening
//! the child with the largest surface area (Wald et al., "Getting Rid of Packets", 2008). Each binary leaf (at
//! most eight triangles) becomes one packet: testing eight triangles at once costs what testing one does.

use super::node::{Child, ChildGroups, NO_GROUP, Node8};
use super::packet::TrianglePacket;
use arrayvec::ArrayVec;
use glam::Vec3;
use obvhs::{
    BvhBuildParams,
    bvh2::{Bvh2, builder::build_bvh2_from_tris},
    triangle::Triangle as ObvhsTriangle,
};
use std::time::Duration;

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
    let input: Vec<ObvhsTriangle> =
        positions.iter().map(|[a, b, c]| ObvhsTriangle { v0: (*a).into(), v1: (*b).into(), v2: (*c).into() }).collect();
    // obvhs's fast preset: on a 1M-triangle mesh it builds in about two thirds of the medium preset's time, and its
    // trees cost no more to trace (callgrind, instructions per render: 1–2% fewer on the knot, as many on the
    // Cornell box).
    let bvh = build_bvh2_from_tris(&input, BvhBuildParams::fast_build(), &mut Duration::default());
    // Group ids are non-negative as i32; NO_GROUP and SKIP_NOTHING are negative.
    let groups = groups.iter().map(|g| g.map_or(NO_GROUP, |g| i32::try_from(g).expect("group id below 2³¹"))).collect();
    // Reserved ahead (a binary tree of n leaves collapses to about a seventh as many wide nodes; a packet holds
    // up to eight triangles): growing these by doubling took 7% of a 1M-triangle load in copies and page faults.
    let wide = bvh.nodes.len() / 7 + 1;
    let mut builder = Builder {
        bvh: &bvh,
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

struct Builder<'a> {
    bvh: &'a Bvh2,
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

    /// Whether binary node `id` becomes a wide node rather than a leaf: obvhs's leaves (at most eight triangles,
    /// sized by its SAH collapse) become packets as they are. Merging small subtrees into one packet would save
    /// node tests but grow boxes: shadow rays leaving one wall would then enter the box it shares with the next,
    /// and on the Cornell box they tested 2.24 packets per ray instead of 1.43.
    fn splits(&self, id: usize) -> bool {
        !self.bvh.nodes[id].is_leaf()
    }

    fn half_area(&self, id: usize) -> f32 {
        self.bvh.nodes[id].aabb.half_area()
    }

    /// Every triangle under binary node `id`, eight to a packet.
    fn leaf(&mut self, id: usize) -> (Child, i32) {
        // A leaf of obvhs (the usual case) is read in place; a subtree cut off at MAX_DEPTH is gathered first.
        let bvh = self.bvh;
        let node = &bvh.nodes[id];
        let mut gathered = Vec::new();
        let triangles = if node.is_leaf() {
            let first = node.first_index as usize;
            &bvh.primitive_indices[first..first + node.prim_count as usize]
        } else {
            let mut stack = vec![id];
            while let Some(n) = stack.pop() {
                let node = &bvh.nodes[n];
                let first = node.first_index as usize;
                if node.is_leaf() {
                    gathered.extend_from_slice(&bvh.primitive_indices[first..first + node.prim_count as usize]);
                } else {
                    stack.extend([first + 1, first]);
                }
            }
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
        (Child { first: first_packet, packets: self.packets.len() as u32 - first_packet }, group)
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
