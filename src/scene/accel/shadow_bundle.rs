//! Eight any-hit rays walking the BVH together, one per lane (e.g. the shadow rays of eight samples of one
//! pixel): each node's children are tested against all of them at once, and a ray drops out when it is found
//! occluded; where too few of them enter a subtree, they walk on alone but interleaved. The shared walk's tests
//! run in eight lanes, or in sixteen where the CPU has AVX-512 (`super::avx512`). In a deep tree (a real mesh) the
//! rays part within a few levels, and each walks alone, interleaved, from the root ([`SHARED_WALK_DEPTH`]).

use super::Accel;
#[cfg(all(target_arch = "x86_64", target_feature = "fma"))]
use super::avx512;
use super::build::MAX_DEPTH;
use super::node::{Child, SKIP_NOTHING};
use super::ray::{BundleTests, RayLanes, WideRay};
use super::traverse::{AnyHitStack, STACK};
use super::vectors::{VectorPath, vector_path};
use crate::math::{Vec3x8, for_each_lane};
use arrayvec::ArrayVec;
use wide::{CmpEq, i32x8};

/// Subtrees set aside per ray in [`Accel::occluded_lanes`] before the rays walk alone.
pub(super) const SET_ASIDE: usize = 8;

/// The deepest tree (in wide levels) in which [`Accel::occluded_lanes`]'s rays walk together; in a deeper one each
/// walks alone from the root. Eight shadow rays of one pixel part where the boxes grow small beside the spread of
/// their points on the lights. In the small scenes' trees (one to four levels: the bundled rooms and veach-mis)
/// that is at the leaves, and walking together pays: alone from the root, `occluded-light`'s `emitter` took 0.63 s
/// instead of 0.39 s and the Cornell box's 0.29 s instead of 0.26 s. In the knot's tree (seven levels, 67 200
/// triangles) they part a few levels down: the shared walk tested boxes for 3.5 rays on average, through about ten
/// nodes a bundle, and walking alone from the root (with `traverse::push_entered`) made the knot's whole
/// `emitter` render 18% faster, 0.82 s → 0.67 s (256², 256 spp, AMD EPYC Zen 4, 2026-12-06).
pub(super) const SHARED_WALK_DEPTH: usize = 4;

impl Accel {
    /// Whether this tree is deeper than [`SHARED_WALK_DEPTH`]: [`Accel::occluded_lanes`]'s rays each walk alone
    /// from the root, and the any-hit step pushes a node's children in one step (`traverse::push_entered`).
    #[inline(always)]
    pub(super) fn walks_alone(&self) -> bool {
        self.depth > SHARED_WALK_DEPTH
    }

    /// How [`Accel::occluded_lanes`]'s rays walk this tree, for `render`, `bench` and the status bar: together, in
    /// the vectors [`vector_path`] chose, or each alone, in a tree deeper than [`SHARED_WALK_DEPTH`].
    pub fn shadow_walk(&self) -> String {
        if self.walks_alone() {
            format!("single-ray walks ({}-level tree)", self.depth)
        } else {
            vector_path().name().to_string()
        }
    }

    /// [`Accel::occluded`] for eight rays `origins + t·dirs`, one per lane, those in `active` (bit i for lane i),
    /// ray i skipping group `skips[i]` (or none: [`super::SKIP_NONE`]); returns the occluded ones. Ray i visits
    /// the leaves its own slab tests admit and meets their triangles through the same arithmetic as alone, so
    /// its answer is [`Accel::occluded`]'s, bit for bit.
    ///
    /// The rays share the walk while at least [`VectorPath::packet_min_rays`] of them enter a subtree: the tests
    /// of a node's children for all of them are independent and overlap. A subtree fewer rays enter is set aside
    /// on the stack of each of them, and the rays with subtrees set aside walk them alone but interleaved
    /// (`Accel::walk_alone`): before the shared walk goes on with one of them (it may be occluded by then), when
    /// one has `SET_ASIDE` subtrees set aside, and at the end. Where the rays part at the root (lights in
    /// different places), they all walk alone together.
    #[inline]
    pub fn occluded_lanes(&self, origins: &Vec3x8, dirs: &Vec3x8, t_max: f32, active: u32, skips: [u32; 8]) -> u32 {
        self.occluded_lanes_on(vector_path(), origins, dirs, t_max, active, skips)
    }

    /// [`Accel::occluded_lanes`] with the shared walk's tests in `path`'s vectors (the same answers on every
    /// path; [`VectorPath::Avx512`] only where the CPU has it, or this panics).
    #[inline]
    pub fn occluded_lanes_on(
        &self,
        path: VectorPath,
        origins: &Vec3x8,
        dirs: &Vec3x8,
        t_max: f32,
        active: u32,
        skips: [u32; 8],
    ) -> u32 {
        let Some(root) = self.root else { return 0 };
        let skips = skips.map(|s| s as i32);
        let mut alone: [AnyHitStack; 8] = Default::default();
        if active.count_ones() < path.packet_min_rays() || self.walks_alone() {
            for_each_lane(active, |l| alone[l].push(root));
            return self.walk_alone(&mut alone, active, origins, dirs, t_max, &skips);
        }
        let rays = RayLanes::new(origins, dirs);
        #[cfg(all(target_arch = "x86_64", target_feature = "fma"))]
        if path == VectorPath::Avx512 {
            let walk = |tests: &_| self.walk_shared(root, active, tests, t_max, &skips, &mut alone, origins, dirs);
            return avx512::occluded_lanes(walk, &rays);
        }
        let _ = path; // one path only in builds without the 16-lane code
        self.walk_shared(root, active, &rays, t_max, &skips, &mut alone, origins, dirs)
    }

    /// The shared walk of [`Accel::occluded_lanes`], its nodes and leaves tested by `tests`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn walk_shared(
        &self,
        root: Child,
        active: u32,
        tests: &impl BundleTests,
        t_max: f32,
        skips: &[i32; 8],
        alone: &mut [AnyHitStack; 8],
        origins: &Vec3x8,
        dirs: &Vec3x8,
    ) -> u32 {
        if skips.iter().any(|&s| s != SKIP_NOTHING) {
            self.walk_together::<true, _>(root, active, tests, t_max, skips, alone, origins, dirs)
        } else {
            self.walk_together::<false, _>(root, active, tests, t_max, skips, alone, origins, dirs)
        }
    }

    /// The shared walk of [`Accel::occluded_lanes`], with the rays' groups to skip tested only if `SKIPS`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn walk_together<const SKIPS: bool, T: BundleTests>(
        &self,
        root: Child,
        active: u32,
        tests: &T,
        t_max: f32,
        skips: &[i32; 8],
        alone: &mut [AnyHitStack; 8],
        origins: &Vec3x8,
        dirs: &Vec3x8,
    ) -> u32 {
        let skip_lanes = i32x8::new(*skips);
        // The lanes with subtrees set aside, and those with no room left to set one more aside.
        let (mut occluded, mut set_aside, mut full) = (0, 0, 0);
        let mut stack = ArrayVec::<(Child, u32), { STACK + MAX_DEPTH }>::new();
        stack.push((root, active));
        while let Some((current, lanes)) = stack.pop() {
            let mut lanes = lanes & !occluded;
            let few = lanes.count_ones() < T::PATH.packet_min_rays();
            // Rays about to go on together, or to set one more subtree aside, first walk alone.
            let walk_first = if few { full } else { set_aside };
            if lanes & walk_first != 0 {
                occluded |= self.walk_alone(alone, set_aside, origins, dirs, t_max, skips);
                (set_aside, full) = (0, 0);
                lanes &= !occluded;
            }
            if lanes == 0 {
                continue;
            }
            if few {
                for_each_lane(lanes, |l| {
                    alone[l].push(current);
                    full |= ((alone[l].len() == SET_ASIDE) as u32) << l;
                });
                set_aside |= lanes;
                continue;
            }
            if current.is_leaf() {
                for packet in &self.packets[current.first as usize..(current.first + current.packets) as usize] {
                    let hit = tests.any_of_rays(packet, t_max) & lanes;
                    occluded |= hit;
                    lanes &= !hit;
                    if lanes == 0 {
                        break;
                    }
                }
                if occluded == active {
                    return occluded;
                }
                continue;
            }
            let node = &self.nodes[current.first as usize];
            let entered_children = tests.entered(node, t_max);
            let mut children = node.used();
            while children != 0 {
                let k = children.trailing_zeros() as usize;
                children &= children - 1;
                let mut entered = (entered_children >> (8 * k)) as u32 & 0xff & lanes;
                if SKIPS {
                    let group = self.groups[current.first as usize].group(k);
                    entered &= !(skip_lanes.cmp_eq(i32x8::splat(group)).move_mask() as u32);
                }
                if entered != 0 {
                    stack.push((node.children[k], entered));
                }
            }
        }
        occluded | self.walk_alone(alone, set_aside, origins, dirs, t_max, skips)
    }

    /// The rays of `lanes` (bit i for lane i) walk the subtrees on their stacks in `stacks`, each alone, one step
    /// of each in turn, ray i skipping group code `skips[i]`: the walks are independent, so the dependent chain of
    /// each (node, box test, child) overlaps the others' instead of waiting alone. Returns the occluded ones;
    /// leaves their stacks empty.
    #[inline]
    fn walk_alone(
        &self,
        stacks: &mut [AnyHitStack; 8],
        lanes: u32,
        origins: &Vec3x8,
        dirs: &Vec3x8,
        t_max: f32,
        skips: &[i32; 8],
    ) -> u32 {
        if lanes == 0 {
            return 0; // nothing set aside: the common end of a coherent bundle's walk
        }
        let mut rays: [Option<WideRay>; 8] = Default::default();
        for_each_lane(lanes, |l| rays[l] = Some(WideRay::new(origins.lane(l), dirs.lane(l))));
        let (mut walking, mut occluded) = (lanes, 0);
        while walking != 0 {
            for_each_lane(walking, |l| {
                let Some(ray) = &rays[l] else { return };
                if self.occlusion_step(&mut stacks[l], ray, t_max, skips[l]) {
                    occluded |= 1 << l;
                    stacks[l].clear();
                }
                if stacks[l].is_empty() {
                    walking &= !(1 << l);
                }
            });
        }
        occluded
    }
}
