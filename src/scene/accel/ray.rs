//! A ray broadcast to eight SIMD lanes, or eight rays one per lane, with what the slab test needs precomputed
//! once per ray; and the tests eight rays walking together run ([`BundleTests`]).

use super::node::Node8;
use super::packet::TrianglePacket;
use crate::math::{Vec3x8, for_each_lane};
use glam::{Vec3, Vec3A};
use wide::{CmpLt, f32x8};

/// Directions components smaller than this are replaced by it (with their sign), so 1/d stays finite and the
/// slab test never computes 0·∞.
const MIN_COMPONENT: f32 = 1e-30;

pub(super) struct WideRay {
    pub o: [f32x8; 3],
    pub d: [f32x8; 3],
    pub inv_d: [f32x8; 3],
}

impl WideRay {
    #[inline]
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        let d = Vec3A::from(dir);
        let tiny = d.abs().cmplt(Vec3A::splat(MIN_COMPONENT));
        let inv_d =
            Vec3A::select(tiny, Vec3A::splat(MIN_COMPONENT).copysign(d), d).recip().to_array().map(f32x8::splat);
        Self { o: origin.to_array().map(f32x8::splat), d: dir.to_array().map(f32x8::splat), inv_d }
    }
}

/// Eight rays, one per lane, with [`WideRay`]'s precomputation done lane by lane (the same values bit for bit).
pub(super) struct RayLanes {
    pub o: [f32x8; 3],
    pub d: [f32x8; 3],
    pub inv_d: [f32x8; 3],
}

impl RayLanes {
    #[inline]
    pub fn new(origins: &Vec3x8, dirs: &Vec3x8) -> Self {
        let d = [dirs.x, dirs.y, dirs.z];
        let inv_d = d.map(|d| {
            let tiny = d.abs().cmp_lt(f32x8::splat(MIN_COMPONENT));
            f32x8::ONE / tiny.blend(f32x8::splat(MIN_COMPONENT).copysign(d), d)
        });
        Self { o: [origins.x, origins.y, origins.z], d, inv_d }
    }
}

/// The tests the eight rays of a shared walk (`Accel::occluded_lanes`) run at its nodes and leaves: in eight
/// lanes ([`RayLanes`]) or in sixteen (`super::avx512`), with the same answers bit for bit.
pub(super) trait BundleTests {
    /// The vector instructions these tests run with.
    const PATH: super::vectors::VectorPath;

    /// Which of the rays enter each used child of `node` within `t_max`: child k's in bits 8k to 8k + 7 (bit
    /// 8k + i for ray i), as [`Node8::intersect_lanes`] gives them.
    fn entered(&self, node: &Node8, t_max: f32) -> u64;

    /// [`TrianglePacket::any_of_rays`]: the rays that hit one of the packet's triangles at `0 < t < t_max`.
    fn any_of_rays(&self, packet: &TrianglePacket, t_max: f32) -> u32;
}

impl BundleTests for RayLanes {
    const PATH: super::vectors::VectorPath = super::vectors::VectorPath::Avx2;

    #[inline(always)]
    fn entered(&self, node: &Node8, t_max: f32) -> u64 {
        let mut entered = 0;
        for_each_lane(node.used(), |k| entered |= (node.intersect_lanes(k, self, t_max) as u64) << (8 * k));
        entered
    }

    #[inline(always)]
    fn any_of_rays(&self, packet: &TrianglePacket, t_max: f32) -> u32 {
        packet.any_of_rays(self, t_max)
    }
}
