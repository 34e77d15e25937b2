//! Single-ray traversal of the 8-wide BVH with a fixed-size stack. The closest-hit query visits the children a
//! ray enters nearest first and skips any entered beyond the best hit so far; the any-hit query stops at the
//! first triangle in range.

use super::build::MAX_DEPTH;
use super::node::Child;
use super::ray::WideRay;
use super::{Accel, Hit};
use arrayvec::ArrayVec;
use glam::Vec3;

/// Each level pushes at most seven children (the eighth is visited at once).
pub(super) const STACK: usize = 7 * MAX_DEPTH + 8;

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
        let Some(root) = self.root else { return false };
        let ray = WideRay::new(origin, dir);
        let mut stack = ArrayVec::<Child, STACK>::new();
        stack.push(root);
        let leaf_hit = |leaf: Child| {
            self.packets[leaf.first as usize..(leaf.first + leaf.packets) as usize].iter().any(|p| p.any(&ray, t_max))
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
            let mut mask = node.intersect(&ray, t_max).0;
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
}
