//! Traversal of the 8-wide BVH with a fixed-size stack. The closest-hit query visits the children a ray enters
//! nearest first and skips any entered beyond the best hit so far; the any-hit query stops at the first triangle
//! in range. Eight any-hit rays can also walk the tree together (`shadow_bundle`).

use super::build::MAX_DEPTH;
use super::node::{Child, SKIP_NOTHING};
use super::packet::NearestLanes;
use super::ray::{RayLanes, WideRay};
use super::shadow_bundle::SET_ASIDE;
use super::{Accel, Hit, HitLanes};
use crate::math::{Vec3x8, for_each_lane, lane_mask};
use arrayvec::ArrayVec;
use glam::Vec3;
use wide::{CmpLt, f32x8};

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
                let (mask, t_enter) = node.intersect(&ray, best_t);
                if mask != 0 {
                    current = enter_nearest(node, mask, t_enter.to_array(), &mut stack);
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

    /// [`Accel::closest_hit`] for up to eight rays, one per lane of `active` (bit l for `rays[l]`), each walking
    /// the tree alone but interleaved with the others, one step of each in turn: their dependent chains (load a
    /// node, test its boxes, take a child) overlap instead of waiting on one another. Each ray takes the steps it
    /// takes alone, so its hit is [`Accel::closest_hit`]'s, bit for bit.
    #[inline]
    pub fn closest_hits(&self, rays: &[(Vec3, Vec3); 8], active: u32, t_max: f32) -> [Option<Hit>; 8] {
        let [origins, dirs] = [rays.map(|r| r.0), rays.map(|r| r.1)].map(|v| Vec3x8::from_lanes(&v));
        self.closest_hits_lanes(&origins, &dirs, active, t_max)
    }

    /// [`Accel::closest_hits`] for rays given as lanes: ray l is `origins + t·dirs` in lane l.
    #[inline]
    pub fn closest_hits_lanes(&self, origins: &Vec3x8, dirs: &Vec3x8, active: u32, t_max: f32) -> [Option<Hit>; 8] {
        let Some(root) = self.root.filter(|_| active != 0) else { return [None; 8] };
        let active = if root.is_leaf() { active } else { self.entering_root(root, origins, dirs, active, t_max) };
        if active == 0 {
            return [None; 8];
        }
        // A walk holds its stack (a kilobyte): the eight are kept per thread and reset in place, where building
        // them per call copied ten kilobytes (a tenth of MIS's time on a small scene).
        WALKS.with_borrow_mut(|walks| {
            for_each_lane(active, |l| walks[l].reset(root, origins.lane(l), dirs.lane(l), t_max));
            let mut walking = active;
            while walking != 0 {
                for_each_lane(walking, |l| {
                    if !self.closest_hit_step(&mut walks[l]) {
                        walking &= !(1 << l);
                    }
                });
            }
            std::array::from_fn(|l| if active & (1 << l) != 0 { walks[l].best } else { None })
        })
    }

    /// [`Accel::closest_hit`] for up to eight rays from one `origin` along `dirs` (those in `active`, bit l for
    /// lane l), walking the tree as one packet (Wald et al., "Interactive Rendering with Coherent Ray Tracing",
    /// 2001): rays that start together and point nearly alike, as a pixel's camera rays, enter nearly the same
    /// subtrees, and each node and leaf is then loaded once for all of them. A child is entered by the rays whose
    /// slab test admits it within their own nearest hit so far, nearest first (by the distance at which the first
    /// of them enters it); a ray leaves the walk of a pending subtree it enters beyond its nearest hit. Each ray
    /// meets every triangle its lone walk meets nearer than its nearest hit, through the same arithmetic, so each
    /// finds the nearest distance its lone walk finds, bit for bit; where two triangles tie at it (a ray through
    /// their common edge), the walks may keep different ones, as through a pixel's cone.
    #[inline]
    pub fn closest_hits_from(&self, origin: Vec3, dirs: &Vec3x8, active: u32, t_max: f32) -> HitLanes {
        let mut nearest = NearestLanes::new(t_max);
        let Some(root) = self.root.filter(|_| active != 0) else { return nearest.hits() };
        let rays = RayLanes::new(&Vec3x8::splat(origin), dirs);
        // The pending subtrees with the rays that enter them, and apart (a vector aligned in its own array, where
        // in one tuple each push and pop copied it through unaligned temporaries) the distances they enter at.
        let (mut stack, mut stack_t) = (ArrayVec::<(Child, u32), STACK>::new(), ArrayVec::<f32x8, STACK>::new());
        let (mut current, mut lanes) = (root, active);
        loop {
            if current.is_leaf() {
                let entered: f32x8 = bytemuck::cast(lane_mask(lanes));
                for packet in &self.packets[current.first as usize..(current.first + current.packets) as usize] {
                    packet.nearer_of_rays(&rays.o, &rays.d, entered, &mut nearest);
                }
            } else {
                // The children entered, nearest on top (an insertion sort of (key, child) pairs: at most eight;
                // each child's rays and distances kept by child, not moved by the sort).
                let node = &self.nodes[current.first as usize];
                let (mut order, mut n) = ([(0.0f32, 0usize); 8], 0);
                let (mut entered_by, mut t_enter_by) = ([0u32; 8], [f32x8::ZERO; 8]);
                let mut children = node.used();
                while children != 0 {
                    let k = children.trailing_zeros() as usize;
                    children &= children - 1;
                    let (entered, t_enter) = node.enter_lanes(k, &rays, nearest.t);
                    let entered = entered & lanes;
                    if entered == 0 {
                        continue;
                    }
                    (entered_by[k], t_enter_by[k]) = (entered, t_enter);
                    let key = t_enter.as_array_ref()[entered.trailing_zeros() as usize];
                    let mut i = n;
                    while i > 0 && order[i - 1].0 < key {
                        order[i] = order[i - 1];
                        i -= 1;
                    }
                    order[i] = (key, k);
                    n += 1;
                }
                if n > 0 {
                    for &(_, k) in &order[..n - 1] {
                        stack.push((node.children[k], entered_by[k]));
                        stack_t.push(t_enter_by[k]);
                    }
                    let k = order[n - 1].1;
                    (current, lanes) = (node.children[k], entered_by[k]);
                    continue;
                }
            }
            // Next: the nearest pending subtree, with the rays that may still find something nearer in it.
            loop {
                let (Some((child, entered)), Some(t_enter)) = (stack.pop(), stack_t.pop()) else {
                    return nearest.hits();
                };
                let entered = entered & t_enter.cmp_lt(nearest.t).move_mask() as u32;
                if entered != 0 {
                    (current, lanes) = (child, entered);
                    break;
                }
            }
        }
    }

    /// The rays of `active` that enter some child of the root node `root`, found for all of them at once, a child at a
    /// time (as many box tests as one ray's walk makes at the root): a ray that enters none would find nothing
    /// (e.g. most traced directions, in the lights' small tree), and need not walk.
    #[inline(always)]
    fn entering_root(&self, root: Child, origins: &Vec3x8, dirs: &Vec3x8, active: u32, t_max: f32) -> u32 {
        let node = &self.nodes[root.first as usize];
        let lanes = RayLanes::new(origins, dirs);
        let (mut entering, mut children) = (0, node.used());
        while children != 0 && entering != active {
            let k = children.trailing_zeros() as usize;
            children &= children - 1;
            entering |= node.intersect_lanes(k, &lanes, t_max) & active;
        }
        entering
    }

    /// One step of a closest-hit walk: tests the current leaf's triangles, or enters the current node's nearest
    /// child entered (the others pending, nearest on top); after a leaf or a node no child of which is entered,
    /// takes the nearest pending child that may still hold something nearer than the best hit. False when none is
    /// left: the walk is over.
    #[inline(always)]
    fn closest_hit_step(&self, walk: &mut ClosestHitWalk) -> bool {
        let current = walk.current;
        if current.is_leaf() {
            for p in current.first..current.first + current.packets {
                let packet = &self.packets[p as usize];
                if let Some(h) = packet.closest(&walk.ray, walk.best_t) {
                    walk.best_t = h.t;
                    walk.best = Some(Hit { triangle: packet.ids[h.lane], t: h.t, u: h.u, v: h.v });
                }
            }
        } else {
            let node = &self.nodes[current.first as usize];
            let (mask, t_enter) = node.intersect(&walk.ray, walk.best_t);
            if mask != 0 {
                walk.current = enter_nearest(node, mask, t_enter.to_array(), &mut walk.stack);
                return true;
            }
        }
        // Next: the nearest pending child that may still hold something nearer than the best hit.
        loop {
            let Some((child, t_enter)) = walk.stack.pop() else { return false };
            if t_enter < walk.best_t {
                walk.current = child;
                return true;
            }
        }
    }

    /// True when something lies on `origin + t·dir` for 0 < t < t_max (`dir` need not be a unit vector: t
    /// counts in its lengths), leaving out the triangles of group `skip` (see [`Accel::build`]) where the tree
    /// holds them apart; stops at the first hit found.
    #[inline(always)]
    pub fn occluded(&self, origin: Vec3, dir: Vec3, t_max: f32, skip: Option<u32>) -> bool {
        let Some(root) = self.root else { return false };
        self.occluded_below(root, &WideRay::new(origin, dir), t_max, skip_code(skip))
    }

    /// [`Accel::occluded`] within the subtree `start`.
    #[inline]
    fn occluded_below(&self, start: Child, ray: &WideRay, t_max: f32, skip: i32) -> bool {
        let mut stack = AnyHitStack::new();
        stack.push(start);
        while !stack.is_empty() {
            if self.occlusion_step(&mut stack, ray, t_max, skip) {
                return true;
            }
        }
        false
    }

    /// One step of an any-hit walk: takes the subtree on top of `stack` and tests a leaf's triangles, or takes the
    /// children of a node the ray enters (but those wholly in group `skip`); the order does not matter for any hit.
    /// In a deep tree ([`Accel::walks_alone`]) they all go on the stack in one step ([`push_entered`]); in a
    /// smaller one, where a ray enters one or two children of a node and their leaves are mostly a wall's, the
    /// nodes go on one by one and the leaves are tested at once (measured: 0.6% fewer instructions on the Cornell
    /// box). True when a triangle in range was found; false also for an empty stack.
    #[inline(always)]
    pub(super) fn occlusion_step(&self, stack: &mut AnyHitStack, ray: &WideRay, t_max: f32, skip: i32) -> bool {
        let leaf_hit = |leaf: Child| {
            self.packets[leaf.first as usize..(leaf.first + leaf.packets) as usize].iter().any(|p| p.any(ray, t_max))
        };
        let Some(current) = stack.pop() else { return false };
        if current.is_leaf() {
            return leaf_hit(current);
        }
        let node = &self.nodes[current.first as usize];
        let mut mask = node.intersect(ray, t_max).0;
        if skip != SKIP_NOTHING {
            mask &= !self.groups[current.first as usize].in_group(skip);
        }
        if self.walks_alone() {
            push_entered(stack, &node.children, mask);
            return false;
        }
        while mask != 0 {
            let child = node.children[mask.trailing_zeros() as usize];
            mask &= mask - 1;
            if !child.is_leaf() {
                stack.push(child);
            } else if leaf_hit(child) {
                return true;
            }
        }
        false
    }
}

/// For each mask of eight bits, the positions of its set bits in increasing order, then zeros: where
/// [`push_entered`] takes a node's entered children from.
const COMPACT: [[u8; 8]; 256] = {
    let mut table = [[0u8; 8]; 256];
    let mut mask = 0;
    while mask < 256 {
        let (mut bit, mut n) = (0, 0);
        while bit < 8 {
            if mask & (1 << bit) != 0 {
                table[mask][n] = bit as u8;
                n += 1;
            }
            bit += 1;
        }
        mask += 1;
    }
    table
};

/// `children[k]` for each bit k of `mask`, in increasing k, then copies of child 0.
#[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
#[inline(always)]
fn compacted(children: &[Child; 8], mask: u32) -> [Child; 8] {
    let order = &COMPACT[mask as usize & 0xff];
    std::array::from_fn(|i| children[order[i] as usize])
}

/// [`COMPACT`] as the 32-bit lanes of two AVX2 vectors of four children each (a child is two lanes): byte 2i and
/// 2i + 1 of a mask's row are the lanes of its i-th entered child, its sign bit set where that child is one of
/// children 4–7, the second vector.
#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
const COMPACT_LANES: [[i8; 16]; 256] = {
    let mut table = [[0i8; 16]; 256];
    let mut mask = 0;
    while mask < 256 {
        let mut i = 0;
        while i < 8 {
            let k = COMPACT[mask][i] as i8;
            let lane = (2 * k) & 7 | if k >= 4 { i8::MIN } else { 0 };
            table[mask][2 * i] = lane;
            table[mask][2 * i + 1] = lane + 1;
            i += 1;
        }
        mask += 1;
    }
    table
};

/// `children[k]` for each bit k of `mask`, in increasing k, then copies of child 0: four permutes of the
/// children's 32-bit lanes and two blends (`vpermd`, `vblendvps`), where gathering them one by one took 16 loads
/// and 8 shuffles (callgrind, knot `emitter`, 128², 16 spp: the shadow rays' walks 119.9 M → 112.3 M instructions).
#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
#[inline(always)]
fn compacted(children: &[Child; 8], mask: u32) -> [Child; 8] {
    use safe_arch::*;
    let [low, high]: [m256i; 2] = bytemuck::cast(*children);
    let lanes: m128i = bytemuck::cast(COMPACT_LANES[mask as usize & 0xff]);
    let half = |lanes: m128i| {
        let lanes = convert_to_i32_m256i_from_lower8_i8_m128i(lanes);
        let (from_low, from_high) = (shuffle_av_i32_all_m256i(low, lanes), shuffle_av_i32_all_m256i(high, lanes));
        let [from_low, from_high, lanes]: [m256; 3] = bytemuck::cast([from_low, from_high, lanes]);
        blend_varying_m256(from_low, from_high, lanes)
    };
    bytemuck::cast([half(lanes), half(byte_shr_imm_u128_m128i::<8>(lanes))])
}

/// The room of an [`AnyHitStack`]: the subtrees set aside (`shadow_bundle`), a walk's (each node it opens
/// replaces itself with at most eight children: at most seven more a level), and the eight slots
/// [`push_entered`] fills whatever the number of children.
const ANY_HIT_ROOM: usize = SET_ASIDE + STACK + 8;

/// The stack of a ray's any-hit walk.
pub(super) type AnyHitStack = ArrayVec<Child, ANY_HIT_ROOM>;

/// Pushes `children[k]` for each bit k of `mask` (in increasing k: the last one is popped first) in one step:
/// eight children copied in [`COMPACT`]'s order (`compacted`), then the length cut to their number, with no
/// branch that depends on which children a ray enters (what a CPU mispredicts most in a walk, since every ray
/// enters others). With leaves pushed like nodes and tested when popped, the knot's shadow rays walking alone took
/// 18% less time than with the children pushed one by one and the leaves tested at once (see
/// `shadow_bundle::SHARED_WALK_DEPTH`).
#[inline(always)]
pub(super) fn push_entered(stack: &mut AnyHitStack, children: &[Child; 8], mask: u32) {
    let len = stack.len();
    let entered = compacted(children, mask);
    // One room check and one length update for the eight: pushed one by one, each checked the room and updated
    // the length (callgrind, knot `emitter`, 128², 16 spp: 679.0 M instructions → 657.9 M with one copy).
    stack.try_extend_from_slice(&entered).expect("an any-hit stack has room for a node's eight children");
    stack.truncate(len + (mask & 0xff).count_ones() as usize);
}

/// The child of `node` to enter next among those the ray enters (`mask`, at distances `t_enter`): the nearest;
/// the others are pushed on `stack`, the nearest on top (an insertion sort: at most eight).
#[inline(always)]
fn enter_nearest(
    node: &super::node::Node8,
    mut mask: u32,
    t_enter: [f32; 8],
    stack: &mut ArrayVec<(Child, f32), STACK>,
) -> Child {
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
    node.children[order[0].1]
}

/// Where a closest-hit walk stands: the subtree it is in, the children pending (with the distance at which the ray
/// enters them), and the best hit so far.
struct ClosestHitWalk {
    ray: WideRay,
    current: Child,
    stack: ArrayVec<(Child, f32), STACK>,
    best_t: f32,
    best: Option<Hit>,
}

impl ClosestHitWalk {
    #[inline(always)]
    fn new(root: Child, origin: Vec3, dir: Vec3, t_max: f32) -> Self {
        Self { ray: WideRay::new(origin, dir), current: root, stack: ArrayVec::new(), best_t: t_max, best: None }
    }

    /// A new walk in place of this one (its stack's room kept).
    #[inline(always)]
    fn reset(&mut self, root: Child, origin: Vec3, dir: Vec3, t_max: f32) {
        self.ray = WideRay::new(origin, dir);
        self.current = root;
        self.stack.clear();
        self.best_t = t_max;
        self.best = None;
    }
}

thread_local! {
    /// Each thread's eight walks for [`Accel::closest_hits`].
    static WALKS: std::cell::RefCell<Box<[ClosestHitWalk; 8]>> = std::cell::RefCell::new(Box::new(
        std::array::from_fn(|_| ClosestHitWalk::new(Child { first: 0, packets: 0 }, Vec3::ZERO, Vec3::Z, 0.0)),
    ));
}

/// A group to skip as the nodes store groups: its id, or [`SKIP_NOTHING`].
#[inline(always)]
fn skip_code(skip: Option<u32>) -> i32 {
    skip.map_or(SKIP_NOTHING, |g| g as i32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// For every mask, `push_entered` pushes exactly the children of its set bits, in increasing order, above what
    /// the stack held, and pops them last first.
    #[test]
    fn push_entered_pushes_the_entered_children_in_order() {
        let children: [Child; 8] = std::array::from_fn(|k| Child { first: 10 + k as u32, packets: k as u32 % 2 });
        for mask in 0..256u32 {
            let mut stack = AnyHitStack::new();
            stack.push(Child { first: 99, packets: 1 });
            push_entered(&mut stack, &children, mask);
            assert_eq!(stack.len(), 1 + mask.count_ones() as usize, "mask {mask:#010b}");
            let mut popped = Vec::new();
            while let Some(child) = stack.pop() {
                popped.push(child);
            }
            let mut expected: Vec<Child> = (0..8).filter(|k| mask & (1 << k) != 0).map(|k| children[k]).collect();
            expected.reverse();
            expected.push(Child { first: 99, packets: 1 });
            assert_eq!(popped, expected, "mask {mask:#010b}");
        }
    }
}
