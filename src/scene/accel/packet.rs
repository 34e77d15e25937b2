//! Eight triangles in structure-of-arrays form, intersected with one ray at once by Möller & Trumbore's test
//! ("Fast, Minimum Storage Ray/Triangle Intersection", 1997): with `e₁ = v₁ − v₀`, `e₂ = v₂ − v₀`,
//! `P = d × e₂`, `T = o − v₀`, `Q = T × e₁` and `det = e₁·P`, the ray meets the plane at
//! `t = (e₂·Q)/det` with barycentrics `u = (T·P)/det`, `v = (d·Q)/det`, inside the triangle when
//! `u ≥ 0, v ≥ 0, u + v ≤ 1`. Both faces are hit.

use super::HitLanes;
use super::ray::{RayLanes, WideRay};
use crate::math::Vec3x8;
use glam::Vec3;
use wide::{CmpGe, CmpGt, CmpLe, CmpLt, f32x8};

/// A hit inside a packet: the lane, the distance and the barycentrics of v₁ and v₂.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct LaneHit {
    pub lane: usize,
    pub t: f32,
    pub u: f32,
    pub v: f32,
}

impl LaneHit {
    /// The nearest of the lanes of `mask` (bit i for lane i) hit at `0 < t < t_max`, from Möller–Trumbore's
    /// numerators and det.
    #[inline(always)]
    pub fn nearest(mask: u32, [t, u, v, det]: [f32x8; 4], t_max: f32) -> Option<Self> {
        if mask == 0 {
            return None;
        }
        let inv = f32x8::ONE / det;
        let t = (t * inv).to_array();
        let mut best: Option<usize> = None;
        let mut bits = mask;
        while bits != 0 {
            let i = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            if t[i] < t_max && best.is_none_or(|b| t[i] < t[b]) {
                best = Some(i);
            }
        }
        let lane = best?;
        let (u, v) = ((u * inv).to_array()[lane], (v * inv).to_array()[lane]);
        Some(Self { lane, t: t[lane], u, v })
    }
}

/// Eight rays' nearest hits so far, one per lane, as vectors: the distance (the ray's limit before any hit), the
/// barycentrics and the triangle id (as f32 bits, for the blends; `u32::MAX` for none).
#[derive(Clone, Copy, Debug)]
pub(super) struct NearestLanes {
    pub t: f32x8,
    u: f32x8,
    v: f32x8,
    id: f32x8,
}

impl NearestLanes {
    /// No hit yet, below `t_max`.
    #[inline(always)]
    pub fn new(t_max: f32) -> Self {
        Self { t: f32x8::splat(t_max), u: f32x8::ZERO, v: f32x8::ZERO, id: f32x8::splat(f32::from_bits(u32::MAX)) }
    }

    /// Keeps triangle `id`'s hits in the lanes of `hit` (all bits set) that are nearer than the lane's hit so far,
    /// from Möller–Trumbore's numerators and det.
    #[inline(always)]
    pub fn keep_nearer(&mut self, hit: f32x8, [t, u, v, det]: [f32x8; 4], id: u32) {
        if hit.none() {
            return;
        }
        let inv = f32x8::ONE / det;
        let t = t * inv;
        let nearer = hit & t.cmp_lt(self.t);
        self.t = nearer.blend(t, self.t);
        self.u = nearer.blend(u * inv, self.u);
        self.v = nearer.blend(v * inv, self.v);
        self.id = nearer.blend(f32x8::splat(f32::from_bits(id)), self.id);
    }

    /// The hits found.
    #[inline(always)]
    pub fn hits(&self) -> HitLanes {
        let triangle = self.id.to_array().map(f32::to_bits);
        let mask = !crate::math::lanes_equal(&triangle, u32::MAX) & 0xff;
        HitLanes { mask, triangle, t: self.t, u: self.u, v: self.v }
    }
}

#[derive(Clone, Debug)]
pub(super) struct TrianglePacket {
    v0: [f32x8; 3],
    e1: [f32x8; 3],
    e2: [f32x8; 3],
    /// The triangle in each lane (an index into the stored order); unused lanes hold a point (e₁ = e₂ = 0,
    /// det = 0), which no ray hits.
    pub ids: [u32; 8],
}

impl TrianglePacket {
    /// Up to eight triangles, with their ids.
    #[cfg(test)]
    pub fn new(triangles: &[([Vec3; 3], u32)]) -> Self {
        Self::from_fn(triangles.len(), |i| triangles[i])
    }

    /// The `n` triangles `triangle(i)` = (vertices, id), i < n ≤ 8. Each triangle's first eight coordinates go in
    /// as a row, which one transposition turns into a vector per coordinate.
    #[inline]
    pub fn from_fn(n: usize, triangle: impl Fn(usize) -> ([Vec3; 3], u32)) -> Self {
        assert!(n <= 8, "a packet holds at most eight triangles");
        let (mut rows, mut last) = ([f32x8::ZERO; 8], [0.0; 8]);
        let mut ids = [u32::MAX; 8];
        for lane in 0..n {
            let ([a, b, c], id) = triangle(lane);
            rows[lane] = Vec3x8::triangle_row([a, b, c]);
            (last[lane], ids[lane]) = (c.z, id);
        }
        let [a, b, c] = Vec3x8::triangles(rows, f32x8::new(last));
        let [e1, e2] = [b - a, c - a].map(|e| [e.x, e.y, e.z]);
        Self { v0: [a.x, a.y, a.z], e1, e2, ids }
    }

    /// The vertices of the triangle in `lane`, or `None` for an unused lane.
    pub fn vertices(&self, lane: usize) -> Option<[Vec3; 3]> {
        if self.ids[lane] == u32::MAX {
            return None;
        }
        let at = |v: &[f32x8; 3]| Vec3::from_array([0, 1, 2].map(|axis| v[axis].as_array_ref()[lane]));
        let v0 = at(&self.v0);
        Some([v0, v0 + at(&self.e1), v0 + at(&self.e2)])
    }

    #[inline(always)]
    fn test(&self, ray: &WideRay, t_max: f32) -> (u32, [f32x8; 4]) {
        let (hit, tuvd) = moller_trumbore(&self.v0, &self.e1, &self.e2, &ray.o, &ray.d, f32x8::splat(t_max));
        (hit.move_mask() as u32, tuvd)
    }

    /// The nearest hit at `0 < t < t_max`.
    #[inline(always)]
    pub fn closest(&self, ray: &WideRay, t_max: f32) -> Option<LaneHit> {
        let (mask, tuvd) = self.test(ray, t_max);
        LaneHit::nearest(mask, tuvd, t_max)
    }

    /// The triangle in lane `k` against eight rays `o + t·d`, one per lane: [`moller_trumbore`] with the roles of
    /// the lanes swapped.
    #[inline(always)]
    fn test_rays(&self, k: usize, o: &[f32x8; 3], d: &[f32x8; 3], t_max: f32x8) -> (f32x8, [f32x8; 4]) {
        moller_trumbore(&lane_splat(&self.v0, k), &lane_splat(&self.e1, k), &lane_splat(&self.e2, k), o, d, t_max)
    }

    /// Each of eight rays `o + t·d` (one per lane; those in `active`, all bits set) keeps in `nearest` the nearer
    /// of its hit there and the packet's nearest hit at `0 < t <` that distance, as [`TrianglePacket::closest`]
    /// finds it for the ray with that limit (the triangles are tested against the limit the ray came in with,
    /// as there). The best hits stay in vectors, updated by blends: no branch or store per lane.
    #[inline(always)]
    pub fn nearer_of_rays(&self, o: &[f32x8; 3], d: &[f32x8; 3], active: f32x8, nearest: &mut NearestLanes) {
        let limit = nearest.t;
        for k in (0..8).filter(|&k| self.ids[k] != u32::MAX) {
            let (hit, tuvd) = self.test_rays(k, o, d, limit);
            nearest.keep_nearer(hit & active, tuvd, self.ids[k]);
        }
    }

    /// The rays of `rays` (bit i for lane i) that hit one of the packet's triangles at `0 < t < t_max`: bit i is
    /// [`TrianglePacket::any`] for ray i, bit for bit.
    #[inline(always)]
    pub fn any_of_rays(&self, rays: &RayLanes, t_max: f32) -> u32 {
        let mut hit = 0;
        for k in (0..8).filter(|&k| self.ids[k] != u32::MAX) {
            hit |= self.rays_hitting(k, rays, t_max);
        }
        hit
    }

    /// The rays of `rays` that hit the triangle in lane `k` at `0 < t < t_max` (bit i for ray i): what
    /// [`TrianglePacket::any_of_rays`] finds for that triangle alone.
    #[inline(always)]
    pub fn rays_hitting(&self, k: usize, rays: &RayLanes, t_max: f32) -> u32 {
        self.test_rays(k, &rays.o, &rays.d, f32x8::splat(t_max)).0.move_mask() as u32
    }

    /// v₀, e₁ and e₂ of the eight lanes.
    #[inline(always)]
    pub fn edges(&self) -> (&[f32x8; 3], &[f32x8; 3], &[f32x8; 3]) {
        (&self.v0, &self.e1, &self.e2)
    }

    /// Whether any triangle is hit at `0 < t < t_max`.
    #[inline(always)]
    pub fn any(&self, ray: &WideRay, t_max: f32) -> bool {
        self.test(ray, t_max).0 != 0
    }
}

/// Lane `k` of each of three vectors, in every lane: three broadcasts (through `map`, the compiler built the
/// arrays on the stack and copied them).
#[inline(always)]
pub(super) fn lane_splat(v: &[f32x8; 3], k: usize) -> [f32x8; 3] {
    let [x, y, z] = v;
    let one = |v: &f32x8| f32x8::splat(v.as_array_ref()[k]);
    [one(x), one(y), one(z)]
}

/// What Möller–Trumbore computes from a triangle and a ray's origin alone, per lane: `T = o − v₀`, `Q = T × e₁`
/// and `e₂·Q` (det times the distance).
#[derive(Clone, Copy, Debug)]
pub(super) struct OriginTerms {
    t: [f32x8; 3],
    q: [f32x8; 3],
    e2q: f32x8,
}

impl OriginTerms {
    #[inline(always)]
    pub fn new(v0: &[f32x8; 3], e1: &[f32x8; 3], e2: &[f32x8; 3], o: &[f32x8; 3]) -> Self {
        let [e1x, e1y, e1z] = *e1;
        let [e2x, e2y, e2z] = *e2;
        let (tx, ty, tz) = (o[0] - v0[0], o[1] - v0[1], o[2] - v0[2]);
        let (qx, qy, qz) = (ty.mul_sub(e1z, tz * e1y), tz.mul_sub(e1x, tx * e1z), tx.mul_sub(e1y, ty * e1x));
        let e2q = e2x.mul_add(qx, e2y.mul_add(qy, e2z * qz));
        Self { t: [tx, ty, tz], q: [qx, qy, qz], e2q }
    }

    /// Lane `k`'s terms in every lane.
    #[inline(always)]
    pub fn splat(&self, k: usize) -> Self {
        let e2q = f32x8::splat(self.e2q.as_array_ref()[k]);
        Self { t: lane_splat(&self.t, k), q: lane_splat(&self.q, k), e2q }
    }
}

/// Möller–Trumbore on eight (triangle, ray) pairs, one per lane. Returns the lanes hit at `0 < t < t_max` (each
/// lane's own limit; all bits set), with `(T·P, d·Q, e₂·Q)` and det in every lane.
#[inline(always)]
fn moller_trumbore(
    v0: &[f32x8; 3],
    e1: &[f32x8; 3],
    e2: &[f32x8; 3],
    o: &[f32x8; 3],
    d: &[f32x8; 3],
    t_max: f32x8,
) -> (f32x8, [f32x8; 4]) {
    moller_trumbore_from(&OriginTerms::new(v0, e1, e2, o), e1, e2, d, t_max)
}

/// [`moller_trumbore`] with the terms of the triangles and the rays' origins worked out: the same operations on
/// the same values, so the same answers bit for bit. The tests run on the numerators with det's sign folded in
/// (`u ≥ 0` ⇔ `(T·P)·sgn(det) ≥ 0`, and so on), so no lane is divided until one is hit.
#[inline(always)]
pub(super) fn moller_trumbore_from(
    origin: &OriginTerms,
    e1: &[f32x8; 3],
    e2: &[f32x8; 3],
    d: &[f32x8; 3],
    t_max: f32x8,
) -> (f32x8, [f32x8; 4]) {
    let [dx, dy, dz] = *d;
    let [e1x, e1y, e1z] = *e1;
    let [e2x, e2y, e2z] = *e2;
    let (px, py, pz) = (dy.mul_sub(e2z, dz * e2y), dz.mul_sub(e2x, dx * e2z), dx.mul_sub(e2y, dy * e2x));
    let det = e1x.mul_add(px, e1y.mul_add(py, e1z * pz));
    let ([tx, ty, tz], [qx, qy, qz], t) = (origin.t, origin.q, origin.e2q);
    let u = tx.mul_add(px, ty.mul_add(py, tz * pz));
    let v = dx.mul_add(qx, dy.mul_add(qy, dz * qz));
    let abs_det = det.abs();
    let (su, sv, st) = (u.flip_signs(det), v.flip_signs(det), t.flip_signs(det));
    let zero = f32x8::ZERO;
    let inside = su.cmp_ge(zero) & sv.cmp_ge(zero) & (su + sv).cmp_le(abs_det);
    let ahead = st.cmp_gt(zero) & st.cmp_lt(t_max * abs_det);
    (inside & ahead & abs_det.cmp_gt(zero), [t, u, v, det])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Triangle i lies in the plane z = i + 1, so a ray up the z axis meets them in lane order.
    fn stack(n: usize) -> TrianglePacket {
        let tris: Vec<([Vec3; 3], u32)> = (0..n)
            .map(|i| {
                let z = i as f32 + 1.0;
                ([Vec3::new(-1.0, -1.0, z), Vec3::new(3.0, -1.0, z), Vec3::new(-1.0, 3.0, z)], 10 + i as u32)
            })
            .collect();
        TrianglePacket::new(&tris)
    }

    #[test]
    fn the_nearest_lane_is_reported_with_its_barycentrics() {
        let packet = stack(8);
        let ray = WideRay::new(Vec3::new(0.0, 0.0, 2.5), Vec3::Z);
        let hit = packet.closest(&ray, f32::INFINITY).unwrap();
        assert_eq!((hit.lane, packet.ids[hit.lane]), (2, 12));
        assert!((hit.t - 0.5).abs() < 1e-6);
        // (0, 0) = v₀ + u e₁ + v e₂ with e₁ = (4, 0), e₂ = (0, 4) from v₀ = (−1, −1): u = v = 1/4.
        assert!((hit.u - 0.25).abs() < 1e-6 && (hit.v - 0.25).abs() < 1e-6);
        assert!(packet.closest(&ray, 0.5).is_none(), "t_max is exclusive");
        assert!(packet.any(&ray, 0.6));
        let down = WideRay::new(Vec3::new(0.0, 0.0, 2.5), -Vec3::Z);
        assert_eq!(packet.closest(&down, f32::INFINITY).unwrap().lane, 1, "back faces are hit too");
    }

    #[test]
    fn misses_unused_lanes_parallel_rays_and_the_outside() {
        let packet = stack(3);
        let up = WideRay::new(Vec3::new(0.0, 0.0, 3.5), Vec3::Z);
        assert!(packet.closest(&up, f32::INFINITY).is_none(), "lanes 3..8 are unused");
        let parallel = WideRay::new(Vec3::new(-5.0, 0.0, 1.0), Vec3::X);
        assert!(!packet.any(&parallel, f32::INFINITY));
        let outside = WideRay::new(Vec3::new(2.0, 2.0, 0.0), Vec3::Z);
        assert!(!packet.any(&outside, f32::INFINITY));
    }
}
