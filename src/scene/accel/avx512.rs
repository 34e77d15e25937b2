//! The shadow rays' shared walk with 512-bit vectors, chosen at run time: where the CPU has AVX-512 (F, DQ, VL,
//! BW), [`super::Accel::occluded_lanes`] runs its walk compiled for it, and tests a node's children, or a leaf's
//! triangles, two at a time against the eight rays: child (or triangle) k in the low eight lanes of a 512-bit
//! vector, k + 1 in the high eight, each lane's arithmetic the eight-lane code's (the same fused operations in the
//! same order, the same comparisons, min and max with the same operand first), so the answers are the same bit for
//! bit. Elsewhere, or with `ILLUMLAB_VECTORS=avx2` in the environment, the eight-lane walk runs
//! (`super::vector_path` says which).
//!
//! Calling code compiled for instructions the build does not assume takes `unsafe`: this module's `unsafe` blocks
//! do, each only where the CPU was found to have them. The crate's only other `unsafe` sets and restores the
//! floating-point control register (`math::without_denormals`).
#![allow(unsafe_code)]

use super::node::{Node8, ROBUST_EXIT};
use super::packet::TrianglePacket;
use super::ray::{BundleTests, RayLanes};
use super::vectors::has_avx512;
use std::arch::x86_64::*;
use wide::f32x8;

/// [`super::Accel::walk_shared`] compiled for AVX-512, its leaves tested by [`RayLanes512`].
pub(super) fn occluded_lanes(walk: impl FnOnce(&RayLanes512) -> u32, rays: &RayLanes) -> u32 {
    assert!(has_avx512(), "the 16-lane path runs only where the CPU has AVX-512");
    // SAFETY: the CPU has every feature `with_avx512` is compiled for (asserted above; one cached load).
    unsafe { with_avx512(walk, rays) }
}

#[target_feature(enable = "avx512f,avx512dq,avx512vl,avx512bw")]
fn with_avx512(walk: impl FnOnce(&RayLanes512) -> u32, rays: &RayLanes) -> u32 {
    walk(&RayLanes512::new(rays))
}

/// Eight rays ([`RayLanes`]), each in lane i and lane i + 8 of 512-bit vectors: what two boxes or two triangles
/// are tested against at once.
pub(super) struct RayLanes512 {
    o: [__m512; 3],
    d: [__m512; 3],
    inv_d: [__m512; 3],
    /// Per axis, the lanes whose ray travels towards −axis (the sign bits of 1/d).
    negative: [__mmask16; 3],
}

impl RayLanes512 {
    #[target_feature(enable = "avx512f,avx512dq,avx512vl,avx512bw")]
    fn new(rays: &RayLanes) -> Self {
        let negative = rays.inv_d.map(|v| _mm512_movepi32_mask(_mm512_castps_si512(twice(v))));
        Self { o: rays.o.map(|v| twice(v)), d: rays.d.map(|v| twice(v)), inv_d: rays.inv_d.map(|v| twice(v)), negative }
    }
}

impl BundleTests for RayLanes512 {
    const PATH: super::vectors::VectorPath = super::vectors::VectorPath::Avx512;

    #[inline(always)]
    fn entered(&self, node: &Node8, t_max: f32) -> u64 {
        // SAFETY: a `RayLanes512` is made only inside `with_avx512`, which runs only where the CPU has AVX-512.
        unsafe { entered(self, node, t_max) }
    }

    #[inline(always)]
    fn any_of_rays(&self, packet: &TrianglePacket, t_max: f32) -> u32 {
        // SAFETY: as above.
        unsafe { any_of_rays(self, packet, t_max) }
    }
}

/// Lane i reads lane k of a vector (i < 8) or lane k + 1 (i ≥ 8).
#[target_feature(enable = "avx512f,avx512dq,avx512vl,avx512bw")]
fn pair_index(k: i32) -> __m512i {
    let halves = _mm512_set_epi32(1, 1, 1, 1, 1, 1, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0);
    _mm512_add_epi32(halves, _mm512_set1_epi32(k))
}

/// Lane k of `v` in the low eight lanes, lane k + 1 in the high eight (`index` from [`pair_index`]).
#[target_feature(enable = "avx512f,avx512dq,avx512vl,avx512bw")]
fn pair(index: __m512i, v: f32x8) -> __m512 {
    _mm512_permutexvar_ps(index, _mm512_castps256_ps512(bytemuck::cast::<f32x8, __m256>(v)))
}

/// [`BundleTests::entered`]: [`Node8::enter_lanes`]'s slab test, two children per test, the same operations on
/// the same values lane by lane.
#[target_feature(enable = "avx512f,avx512dq,avx512vl,avx512bw")]
fn entered(rays: &RayLanes512, node: &Node8, t_max: f32) -> u64 {
    let bounds = node.bounds();
    let used = node.used().count_ones() as i32;
    let (t_max, robust, zero) = (_mm512_set1_ps(t_max), _mm512_set1_ps(ROBUST_EXIT), _mm512_setzero_ps());
    let mut entered = 0u64;
    let mut k = 0;
    while k < used {
        let index = pair_index(k);
        let slab = |a: usize, near: bool| {
            let (lo, hi) = (pair(index, bounds[a]), pair(index, bounds[a + 3]));
            let plane = if near {
                _mm512_mask_blend_ps(rays.negative[a], lo, hi)
            } else {
                _mm512_mask_blend_ps(rays.negative[a], hi, lo)
            };
            _mm512_mul_ps(_mm512_sub_ps(plane, rays.o[a]), rays.inv_d[a])
        };
        let t_enter = _mm512_max_ps(_mm512_max_ps(slab(0, true), slab(1, true)), _mm512_max_ps(slab(2, true), zero));
        let t_exit = _mm512_min_ps(_mm512_min_ps(slab(0, false), slab(1, false)), slab(2, false));
        let t_exit = _mm512_min_ps(_mm512_mul_ps(t_exit, robust), t_max);
        entered |= (_mm512_cmp_ps_mask::<_CMP_LE_OQ>(t_enter, t_exit) as u64) << (8 * k);
        k += 2;
    }
    entered // an unused lane's bits (a pair's second child) are read by no one
}

/// `v` in the low and in the high eight lanes.
#[target_feature(enable = "avx512f,avx512dq,avx512vl,avx512bw")]
fn twice(v: f32x8) -> __m512 {
    let v: __m256 = bytemuck::cast(v);
    _mm512_broadcast_f32x8(v)
}

/// [`TrianglePacket::any_of_rays`], two triangles per test.
#[target_feature(enable = "avx512f,avx512dq,avx512vl,avx512bw")]
fn any_of_rays(rays: &RayLanes512, packet: &TrianglePacket, t_max: f32) -> u32 {
    let (v0, e1, e2) = packet.edges();
    let used = packet.ids.iter().take_while(|&&id| id != u32::MAX).count() as i32;
    let t_max = _mm512_set1_ps(t_max);
    let mut hit = 0u32;
    let mut k = 0;
    while k < used {
        let index = pair_index(k);
        let pairs = |v: &[f32x8; 3]| v.map(|axis| pair(index, axis));
        // Unused slots hold points (det = 0): their lanes never hit.
        let both = moller_trumbore_any(&pairs(v0), &pairs(e1), &pairs(e2), &rays.o, &rays.d, t_max) as u32;
        hit |= (both | (both >> 8)) & 0xff;
        k += 2;
    }
    hit
}

/// The hit test of the packet's `moller_trumbore` on sixteen (triangle, ray) pairs: the same operations lane by
/// lane, so the same answers.
#[target_feature(enable = "avx512f,avx512dq,avx512vl,avx512bw")]
fn moller_trumbore_any(
    v0: &[__m512; 3],
    e1: &[__m512; 3],
    e2: &[__m512; 3],
    o: &[__m512; 3],
    d: &[__m512; 3],
    t_max: __m512,
) -> __mmask16 {
    let [dx, dy, dz] = *d;
    let [e1x, e1y, e1z] = *e1;
    let [e2x, e2y, e2z] = *e2;
    // a.mul_sub(b, c) = a b − c and a.mul_add(b, c) = a b + c, each rounded once, as the eight-lane code has them.
    let mul_sub = |a, b, c| _mm512_fmsub_ps(a, b, c);
    let mul_add = |a, b, c| _mm512_fmadd_ps(a, b, c);
    let mul = |a, b| _mm512_mul_ps(a, b);
    let (px, py, pz) = (mul_sub(dy, e2z, mul(dz, e2y)), mul_sub(dz, e2x, mul(dx, e2z)), mul_sub(dx, e2y, mul(dy, e2x)));
    let det = mul_add(e1x, px, mul_add(e1y, py, mul(e1z, pz)));
    let (tx, ty, tz) = (_mm512_sub_ps(o[0], v0[0]), _mm512_sub_ps(o[1], v0[1]), _mm512_sub_ps(o[2], v0[2]));
    let (qx, qy, qz) = (mul_sub(ty, e1z, mul(tz, e1y)), mul_sub(tz, e1x, mul(tx, e1z)), mul_sub(tx, e1y, mul(ty, e1x)));
    let u = mul_add(tx, px, mul_add(ty, py, mul(tz, pz)));
    let v = mul_add(dx, qx, mul_add(dy, qy, mul(dz, qz)));
    let t = mul_add(e2x, qx, mul_add(e2y, qy, mul(e2z, qz)));
    let abs_det = _mm512_abs_ps(det);
    let sign = _mm512_and_ps(det, _mm512_set1_ps(-0.0));
    let (su, sv, st) = (_mm512_xor_ps(u, sign), _mm512_xor_ps(v, sign), _mm512_xor_ps(t, sign));
    let zero = _mm512_setzero_ps();
    let inside = _mm512_cmp_ps_mask::<_CMP_GE_OQ>(su, zero)
        & _mm512_cmp_ps_mask::<_CMP_GE_OQ>(sv, zero)
        & _mm512_cmp_ps_mask::<_CMP_LE_OQ>(_mm512_add_ps(su, sv), abs_det);
    let ahead = _mm512_cmp_ps_mask::<_CMP_GT_OQ>(st, zero) & _mm512_cmp_ps_mask::<_CMP_LT_OQ>(st, mul(t_max, abs_det));
    inside & ahead & _mm512_cmp_ps_mask::<_CMP_GT_OQ>(abs_det, zero)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{SampleRng, Vec3x8};
    use crate::scene::accel::node::Child;
    use glam::Vec3;

    /// Rays that decide by a rounding: aimed at a vertex, at a point of an edge or of a box face, or lying in a
    /// face's plane, with zero direction components among them; and ordinary ones.
    fn borderline_rays(rng: &mut SampleRng, targets: &[Vec3]) -> (Vec3x8, Vec3x8) {
        let mut point = |scale: f32| Vec3::new(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5) * scale;
        let mut origins = [Vec3::ZERO; 8];
        let mut dirs = [Vec3::ZERO; 8];
        for l in 0..8 {
            let target = targets[(l * 7 + (point(1.0).x.to_bits() as usize)) % targets.len()];
            origins[l] = point(12.0);
            dirs[l] = match l % 4 {
                0 => target - origins[l],
                1 => (target - origins[l]) * 0.5, // t = 2 at the target: beyond a t_max of 1
                2 => {
                    origins[l].y = target.y; // in the plane y = target.y: a zero component
                    Vec3::new(target.x - origins[l].x, 0.0, target.z - origins[l].z)
                }
                _ => point(8.0),
            };
        }
        (Vec3x8::from_lanes(&origins), Vec3x8::from_lanes(&dirs))
    }

    /// The 16-lane tests give the eight-lane tests' answers bit for bit: masks of 8 rays against packets of 1 to 8
    /// triangles (and needles and points among them) and against nodes of 1 to 8 boxes (flat ones among them),
    /// with rays aimed at vertices, edges and faces, where one rounding more or less flips the answer. Runs where
    /// the CPU has AVX-512; elsewhere it says SKIPPED (the eight-lane path is then the only one).
    #[test]
    fn sixteen_lanes_answer_as_eight_bit_for_bit() {
        if !has_avx512() {
            eprintln!("SKIPPED: this CPU has no AVX-512, so the 16-lane path cannot run here");
            return;
        }
        let (mut hits, mut entered, mut cases) = (0u32, 0u32, 0u32);
        for case in 0..4000u64 {
            let mut rng = SampleRng::new(91, case, 0);
            let mut point =
                |scale: f32| Vec3::new(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5) * scale;
            let n = 1 + case as usize % 8;
            let tris: Vec<([Vec3; 3], u32)> = (0..n)
                .map(|i| {
                    let (a, b) = (point(6.0), point(6.0));
                    let tri = match i % 5 {
                        3 => [a, b, (a + b) * 0.5], // a needle: three points on a line
                        4 => [a, a, a],             // a point
                        _ => [a, b, a + point(3.0)],
                    };
                    (tri, i as u32)
                })
                .collect();
            let boxes: Vec<([Vec3; 2], Child)> = (0..n)
                .map(|i| {
                    let (a, b) = (point(6.0), point(6.0));
                    let (mut lo, hi) = (a.min(b), a.max(b));
                    if i % 4 == 3 {
                        lo.z = hi.z; // flat
                    }
                    ([lo, hi], Child { first: i as u32, packets: 1 })
                })
                .collect();
            let packet = TrianglePacket::new(&tris);
            let node = Node8::new(&boxes);
            let mut targets: Vec<Vec3> =
                tris.iter().flat_map(|(t, _)| [t[0], t[1], t[2], (t[0] + t[1]) * 0.5]).collect();
            targets
                .extend(boxes.iter().flat_map(|([lo, hi], _)| [*lo, *hi, Vec3::new(lo.x, hi.y, (lo.z + hi.z) * 0.5)]));
            for t_max in [1.0, f32::INFINITY] {
                let (origins, dirs) =
                    borderline_rays(&mut SampleRng::new(92, case, t_max.is_finite() as u64), &targets);
                let rays = RayLanes::new(&origins, &dirs);
                let (eight_hits, eight_entered) = (rays.any_of_rays(&packet, t_max), rays.entered(&node, t_max));
                let mut sixteen = (0, 0);
                occluded_lanes(
                    |wide| {
                        sixteen = (wide.any_of_rays(&packet, t_max), wide.entered(&node, t_max));
                        0
                    },
                    &rays,
                );
                assert_eq!(sixteen.0, eight_hits, "case {case}, t_max {t_max}: triangle hits differ");
                assert_eq!(sixteen.1, eight_entered, "case {case}, t_max {t_max}: boxes entered differ");
                hits += eight_hits.count_ones();
                entered += eight_entered.count_ones();
                cases += 1;
            }
        }
        assert!(hits > cases / 4 && entered > 4 * cases, "too few hits ({hits}) or boxes entered ({entered}) to check");
    }
}
