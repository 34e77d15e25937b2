//! Traversal of the 8-wide BVH with a fixed-size stack. The closest-hit query visits the children a ray enters
//! nearest first and skips any entered beyond the best hit so far; the any-hit query stops at the first triangle
//! in range. Eight any-hit rays can also walk the tree together, one per lane (e.g. the shadow rays of eight
//! samples of one pixel): each node's children are tested against all of them at once, and a ray drops out
//! when it is found occluded.

use super::build::MAX_DEPTH;
use super::node::Child;
use super::ray::{RayLanes, WideRay};
use super::{Accel, Hit};
use crate::math::Vec3x8;
use arrayvec::ArrayVec;
use glam::Vec3;

/// Each level pushes at most seven children (the eighth is visited at once).
pub(super) const STACK: usize = 7 * MAX_DEPTH + 8;

/// Rays walk a subtree together while at least this many of them enter it; fewer go on one by one, since a
/// node costs the bundle eight box tests whatever the number of rays still in it (Benthin et al., "Combining
/// Single and Packet-Ray Tracing for Arbitrary Ray Distributions on the Intel MIC Architecture", 2012).
const PACKET_MIN_RAYS: u32 = 5;

impl Accel {
    /// Nearest intersection along `origin + t·dir`, 0 < t < t_max.
    #[inline]
    pub fn closest_hit(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<Hit> {
        let mut current = self.root?;
        let ray = WideRay::new(origin, dir);
        let mut best_t = t_max;
        let mut best = None;
        let mut stack = ArrayVec::<(Child, f32), STACK>::new();
        loop {
            if current.is_leaf() {
                for p in current.first..current.first + current.packets {
                    let packet = &self.packets[p as usize];
                    if let Some(h) = packet.closest(&ray, best_t) {
                        best_t = h.t;
                        best = Some(Hit { triangle: packet.ids[h.lane], t: h.t, u: h.u, v: h.v });
                    }
                }
            } else {
                let node = &self.nodes[current.first as usize];
                let (mut mask, t_enter) = node.intersect(&ray, best_t);
                if mask != 0 {
                    let t_enter = t_enter.to_array();
                    // Sort the entered children by distance, nearest first (insertion sort: at most eight).
                    let mut order = [(0.0f32, 0usize); 8];
                    let mut n = 0;
                    while mask != 0 {
                        let lane = mask.trailing_zeros() as usize;
                        mask &= mask - 1;
                        let mut k = n;
                        while k > 0 && order[k - 1].0 > t_enter[lane] {
                            order[k] = order[k - 1];
                            k -= 1;
                        }
                        order[k] = (t_enter[lane], lane);
                        n += 1;
                    }
                    for &(t, lane) in order[1..n].iter().rev() {
                        stack.push((node.children[lane], t));
                    }
                    current = node.children[order[0].1];
                    continue;
                }
            }
            // Next: the nearest pending child that may still hold something nearer than the best hit.
            loop {
                let Some((child, t_enter)) = stack.pop() else { return best };
                if t_enter < best_t {
                    current = child;
                    break;
                }
            }
        }
    }

    /// True when something lies on `origin + t·dir` for 0 < t < t_max (`dir` need not be a unit vector: t
    /// counts in its lengths); stops at the first hit found.
    #[inline]
    pub fn occluded(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        self.root.is_some_and(|root| self.occluded_below(root, &WideRay::new(origin, dir), t_max))
    }

    /// [`Accel::occluded`] within the subtree `start`.
    #[inline]
    fn occluded_below(&self, start: Child, ray: &WideRay, t_max: f32) -> bool {
        let mut stack = ArrayVec::<Child, STACK>::new();
        stack.push(start);
        let leaf_hit = |leaf: Child| {
            self.packets[leaf.first as usize..(leaf.first + leaf.packets) as usize].iter().any(|p| p.any(ray, t_max))
        };
        while let Some(current) = stack.pop() {
            if current.is_leaf() {
                if leaf_hit(current) {
                    return true;
                }
                continue;
            }
            // Leaves are tested at once, nodes wait on the stack: the order does not matter for any hit.
            let node = &self.nodes[current.first as usize];
            let mut mask = node.intersect(ray, t_max).0;
            while mask != 0 {
                let child = node.children[mask.trailing_zeros() as usize];
                mask &= mask - 1;
                if !child.is_leaf() {
                    stack.push(child);
                } else if leaf_hit(child) {
                    return true;
                }
            }
        }
        false
    }

    /// [`Accel::occluded`] for eight rays `origins + t·dirs`, one per lane, those in `active` (bit i for lane i);
    /// returns the occluded ones. Ray i visits the leaves its own slab tests admit and meets their triangles
    /// through the same arithmetic as alone, so its answer is [`Accel::occluded`]'s, bit for bit. The rays
    /// share the walk, so the tests of a node's children for all of them are independent and overlap, until
    /// fewer than [`PACKET_MIN_RAYS`] remain in a subtree.
    #[inline]
    pub fn occluded_lanes(&self, origins: &Vec3x8, dirs: &Vec3x8, t_max: f32, active: u32) -> u32 {
        let Some(root) = self.root else { return 0 };
        let rays = RayLanes::new(origins, dirs);
        let mut occluded = 0;
        let mut stack = ArrayVec::<(Child, u32), { STACK + MAX_DEPTH }>::new();
        stack.push((root, active));
        while let Some((current, lanes)) = stack.pop() {
            let mut lanes = lanes & !occluded;
            if lanes == 0 {
                continue;
            }
            if current.is_leaf() {
                for packet in &self.packets[current.first as usize..(current.first + current.packets) as usize] {
                    let hit = packet.any_of_rays(&rays, t_max) & lanes;
                    occluded |= hit;
                    lanes &= !hit;
                    if lanes == 0 {
                        break;
                    }
                }
                if occluded == active {
                    break;
                }
                continue;
            }
            if lanes.count_ones() < PACKET_MIN_RAYS {
                // Too few rays left here to fill the lanes: each goes on alone.
                while lanes != 0 {
                    let l = lanes.trailing_zeros() as usize;
                    lanes &= lanes - 1;
                    let ray = WideRay::new(origins.lane(l), dirs.lane(l));
                    occluded |= (self.occluded_below(current, &ray, t_max) as u32) << l;
                }
                continue;
            }
            let node = &self.nodes[current.first as usize];
            let mut children = node.used();
            while children != 0 {
                let k = children.trailing_zeros() as usize;
                children &= children - 1;
                let entered = node.intersect_lanes(k, &rays, t_max) & lanes;
                if entered != 0 {
                    stack.push((node.children[k], entered));
                }
            }
        }
        occluded
    }
}
