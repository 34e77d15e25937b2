//! Error-bounded ray origins (Pharr, Jakob & Humphreys, *Physically Based Rendering*, 4th ed., §6.8: the
//! rounding error of computed intersections and `OffsetRayOrigin`), adapted to this renderer's Möller–Trumbore
//! test.
//!
//! A computed point x̃ on a triangle Δ lies off Δ's plane by at most `δ_x`; a ray leaving from x̃ must start on the
//! right side of the plane *as the intersection test computes it*, whose sign of `t` is itself rounded. The ray
//! origin is moved along the normal by the sum of both bounds and then one float further in each coordinate, so
//! that rounding the sum cannot undo the move:
//!
//! ```text
//! o = x̃ + δ n,   o_k ← next float after o_k away from x̃_k        (pbrt-v4's OffsetRayOrigin)
//! δ = γ₇ (|v₀| + |e₁| + |e₂|)·|n|                                 the point v₀ + u e₁ + v e₂ (0 in a coordinate
//!                                                                  where e₁ and e₂ are 0: it is copied exactly)
//!   + γ₁₀ |e₂|·(|T| ×| |e₁|) / ‖e₁ × e₂‖                           the sign of t = e₂·(T × e₁)/det, T = o − v₀
//! ```
//!
//! with `γₙ = nε/(1 − nε)`, ε = 2⁻²⁴ (Higham's bound on n roundings), absolute values taken per coordinate, and
//! `a ×| b = (a_y b_z + a_z b_y, a_z b_x + a_x b_z, a_x b_y + a_y b_x)` the bound of a computed cross product's
//! terms. Per coordinate, the bounds vanish where the geometry makes the arithmetic exact: for a floor in the plane
//! y = 0, δ is zero and the origin moves by one float. For a ray leaving Δ itself, `|T| ≤` Δ's extent from v₀
//! ([`SurfaceError::at_point`]); at the far end of a shadow ray, Δ is tested from the ray's origin, so |T| grows
//! with the segment `x − p` ([`SurfaceError::far_end`]). The bound grows with the coordinates only as the rounding
//! does, not as a fixed count of ULPs of every coordinate (Ray Tracing Gems ch. 6, what this replaced), which at
//! 10⁵ m from the origin jumped metres.

use super::Vec3x8;
use bytemuck::cast;
use glam::Vec3;
use wide::{CmpEq, CmpGt, CmpLt, f32x8, i32x8};

/// `γₙ = nε/(1 − nε)`, ε = 2⁻²⁴: bounds the relative error of n floating-point roundings.
pub const fn gamma(n: u32) -> f32 {
    let e = n as f32 * f32::EPSILON * 0.5;
    e / (1.0 - e)
}

/// The side term is capped at this many γ₁₀ per unit of |T|: slivers get the bound of a triangle with a 1° angle
/// rather than offsets that jump over nearby geometry.
const MAX_SHAPE: f32 = 64.0;

/// `a ×| b`: per coordinate, the sum of the absolute terms of the cross product a × b.
#[inline]
fn abs_cross(a: Vec3, b: Vec3) -> Vec3 {
    let (a, b) = (a.abs(), b.abs());
    Vec3::new(a.y * b.z + a.z * b.y, a.z * b.x + a.x * b.z, a.x * b.y + a.y * b.x)
}

/// How far a computed point on one triangle may be off its plane, as the intersection test sees it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SurfaceError {
    /// δ for a ray leaving a point of the triangle computed from its barycentrics.
    pub at_point: f32,
    /// `γ₁₀ (|e₁| ×| |e₂|) / ‖e₁ × e₂‖`: δ grows by `|d|·per_distance` when the triangle is tested from
    /// `x + d`, x a point of it.
    pub per_distance: Vec3,
}

impl SurfaceError {
    /// The bounds of the triangle (v₀, v₁, v₂) with unit normal n.
    pub fn of_triangle([v0, v1, v2]: [Vec3; 3], n: Vec3) -> Self {
        let (e1, e2) = (v1 - v0, v2 - v0);
        let area2 = e1.cross(e2).length();
        let per_distance = (gamma(10) * abs_cross(e1, e2) / area2).min(Vec3::splat(gamma(10) * MAX_SHAPE));
        let per_distance = if per_distance.is_finite() { per_distance } else { Vec3::splat(gamma(10) * MAX_SHAPE) };
        // A coordinate in which the triangle does not vary is copied exactly: v₀ + u·0 + v·0 = v₀.
        let varies = e1.cmpne(Vec3::ZERO) | e2.cmpne(Vec3::ZERO);
        let point = Vec3::select(varies, gamma(7) * (v0.abs() + e1.abs() + e2.abs()), Vec3::ZERO).dot(n.abs());
        // From a point of the triangle, |T| ≤ its extent from v₀, coordinate by coordinate.
        let extent = e1.abs().max(e2.abs());
        Self { at_point: point + extent.dot(per_distance), per_distance }
    }

    /// δ for the far end x of a shadow ray from p that ends on this triangle: the test of this triangle from the
    /// ray's origin has `|T| ≤ |x − p| +` its extent, and x may be a ray–plane intersection from p
    /// (`γ₈ |p|·|n_x|`).
    #[inline]
    pub fn far_end(&self, p: Vec3, x: Vec3, n_x: Vec3) -> f32 {
        let (d, w) = ((x - p).abs(), self.per_distance);
        let segment = d.x * w.x + d.y * w.y + d.z * w.z;
        let from = p.x.abs() * n_x.x.abs() + p.y.abs() * n_x.y.abs() + p.z.abs() * n_x.z.abs();
        self.at_point + segment + gamma(8) * from
    }
}

/// Eight lanes' [`SurfaceError`]s, one vector per field.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceErrorLanes {
    pub at_point: f32x8,
    pub per_distance: Vec3x8,
}

impl SurfaceErrorLanes {
    /// Lane l holds `errors[l]`.
    #[inline]
    pub fn from_lanes(errors: &[SurfaceError; 8]) -> Self {
        let at_point = f32x8::new(errors.map(|e| e.at_point));
        Self { at_point, per_distance: Vec3x8::from_lanes(&errors.map(|e| e.per_distance)) }
    }

    /// [`SurfaceError::far_end`] for eight rays at once, the same values bit for bit.
    #[inline]
    pub fn far_end(&self, p: Vec3x8, x: Vec3x8, n_x: Vec3x8) -> f32x8 {
        let (d, w) = (x - p, self.per_distance);
        let segment = d.x.abs() * w.x + d.y.abs() * w.y + d.z.abs() * w.z;
        let from = p.x.abs() * n_x.x.abs() + p.y.abs() * n_x.y.abs() + p.z.abs() * n_x.z.abs();
        self.at_point + segment + f32x8::splat(gamma(8)) * from
    }
}

/// The next float after `o` in the direction of the sign of `dir` (`o` itself where dir is 0).
#[inline]
fn round_away(o: f32, dir: f32) -> f32 {
    if dir == 0.0 {
        o
    } else if o == 0.0 {
        f32::from_bits(1).copysign(dir)
    } else if (o > 0.0) == (dir > 0.0) {
        f32::from_bits(o.to_bits() + 1)
    } else {
        f32::from_bits(o.to_bits() - 1)
    }
}

/// Moves `p`, a computed point of a surface whose unit normal `n` points to the side the new ray leaves on, off
/// the surface by `error` (its bound δ, see the module) and one float more in each coordinate where n is not 0
/// (so also where δ is 0).
#[inline]
pub fn offset_ray_origin(p: Vec3, n: Vec3, error: f32) -> Vec3 {
    let o = p + n * error;
    Vec3::new(round_away(o.x, n.x), round_away(o.y, n.y), round_away(o.z, n.z))
}

/// [`round_away`] in eight lanes.
#[inline(always)]
fn round_away_lanes(o: f32x8, dir: f32x8) -> f32x8 {
    let bits: i32x8 = cast(o);
    // −1 where o and dir have opposite signs, 0 where the same (a comparison's true is all bits set).
    let opposite = cast::<f32x8, i32x8>(o.cmp_gt(f32x8::ZERO)) ^ cast::<f32x8, i32x8>(dir.cmp_gt(f32x8::ZERO));
    // ±1 on the bit pattern: away from 0 where the signs agree, towards it where they differ.
    let next: f32x8 = cast(bits + (i32x8::splat(1) + opposite * i32x8::splat(2)));
    let tiny: f32x8 = cast(i32x8::splat(1));
    let at_zero = dir.cmp_lt(f32x8::ZERO).blend(-tiny, tiny);
    let moved = o.cmp_eq(f32x8::ZERO).blend(at_zero, next);
    dir.cmp_eq(f32x8::ZERO).blend(o, moved)
}

/// [`offset_ray_origin`] for eight points at once, one per lane; the same values bit for bit.
#[inline]
pub fn offset_ray_origins(p: Vec3x8, n: Vec3x8, error: f32x8) -> Vec3x8 {
    let e = error;
    Vec3x8 {
        x: round_away_lanes(p.x + n.x * e, n.x),
        y: round_away_lanes(p.y + n.y * e, n.y),
        z: round_away_lanes(p.z + n.z * e, n.z),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::SampleRng;

    #[test]
    fn gamma_is_higham_bound() {
        assert_eq!(gamma(0), 0.0);
        assert!((gamma(1) - 2f32.powi(-24)).abs() < 1e-14);
        assert!(gamma(16) > 16.0 * 2f32.powi(-24));
    }

    #[test]
    fn offset_moves_to_the_normal_side_by_at_least_the_bound() {
        let n = Vec3::new(0.3, -0.5, 0.8).normalize();
        for scale in [0.0, 1e-3, 1.0, 1e2, 1e4, 1e6] {
            let p = Vec3::new(1.0, -2.0, 3.0) * scale;
            let error = gamma(7) * p.abs().dot(n.abs()) + 1e-7;
            let q = offset_ray_origin(p, n, error);
            assert!(q.is_finite());
            assert!((q - p).dot(n) >= error * 0.999, "scale {scale}: {}", (q - p).dot(n));
            assert!((q - p).length() <= 2.0 * error + 4.0 * f32::EPSILON * p.abs().max_element(), "scale {scale}");
        }
    }

    /// Points drawn on random triangles at scales 10⁻³ to 10⁶, offset by their bound, are on the side of the
    /// normal by the triangle's own plane test in f64; rays leaving them into the upper hemisphere never meet
    /// their own triangle in the renderer's intersection test (f32 Möller–Trumbore), and shadow rays from points
    /// in front of the triangle to them, their far ends offset, stop short of it.
    #[test]
    fn offset_points_never_see_their_own_triangle() {
        use crate::scene::test_ray_triangle;
        let mut rng = SampleRng::new(11, 0, 0);
        let mut tested = 0;
        for k in 0..200_000 {
            let scale = [1e-3, 1.0, 1e2, 1e4, 1e6][k % 5];
            let mut v = || (rng.uniform() - 0.5) * 2.0;
            let centre = Vec3::new(v(), v(), v()) * scale;
            let size = scale.max(1.0) * 10f32.powf(-2.0 * (v() + 1.0));
            let mut tri = [0, 1, 2].map(|_| centre + Vec3::new(v(), v(), v()) * size);
            if k % 3 == 0 {
                tri.iter_mut().for_each(|t| t.y = centre.y); // in a plane y = c, where δ is 0
            }
            let cross = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
            if !(cross.length() > 0.0) {
                continue;
            }
            let n = cross.normalize();
            let error = SurfaceError::of_triangle(tri, n);
            let (a, b) = (v().abs(), v().abs());
            let (u, w) = if a + b > 1.0 { (1.0 - a, 1.0 - b) } else { (a, b) };
            let x = tri[0] + (tri[1] - tri[0]) * u + (tri[2] - tri[0]) * w;
            let side = if v() > 0.0 { n } else { -n };
            let o = offset_ray_origin(x, side, error.at_point);
            let d = (side + Vec3::new(v(), v(), v()) * 0.999).normalize_or(side);
            if d.dot(side) <= 1e-3 {
                continue;
            }
            let height = (o.as_dvec3() - tri[0].as_dvec3()).dot(cross.as_dvec3()) * side.dot(n) as f64;
            assert!(height > 0.0, "case {k}: the origin is behind the plane");
            assert!(test_ray_triangle(tri, o, d).is_none(), "case {k}: the ray meets its own triangle");
            // A shadow ray from a point p in front of the triangle (up to 10⁴ sizes away) to x ends before it.
            let p = x + (side * 1.5 + Vec3::new(v(), v(), v())) * size * 10f32.powf(2.0 * (v() + 1.0));
            let n_p = (x - p).normalize();
            let from = offset_ray_origin(p, n_p, gamma(8) * p.abs().dot(n_p.abs()));
            if (from - x).dot(side) > 0.0 {
                let to = offset_ray_origin(x, side, error.far_end(p, x, side));
                let t = test_ray_triangle(tri, from, to - from);
                assert!(t.is_none_or(|t| t >= crate::render::SEGMENT_END), "case {k}: the shadow ray ends at {t:?}");
            }
            tested += 1;
        }
        assert!(tested > 150_000, "{tested}");
    }

    #[test]
    fn far_end_lanes_equal_the_scalar_bound_bit_for_bit() {
        let mut rng = SampleRng::new(4, 0, 0);
        for i in 0..20_000 {
            let scale = [1e-6, 1e-2, 1.0, 1e3, 1e6][i % 5];
            let mut v = || (rng.uniform() - 0.5) * 2.0;
            let (p, x) = (Vec3::new(v(), v(), v()) * scale, Vec3::new(v(), v(), v()) * scale);
            let n = Vec3::new(v(), v(), v()).normalize_or(Vec3::Z);
            let e = SurfaceError { at_point: v().abs() * 1e-6, per_distance: Vec3::new(v(), v(), v()).abs() * 1e-6 };
            let errors =
                SurfaceErrorLanes { at_point: f32x8::splat(e.at_point), per_distance: Vec3x8::splat(e.per_distance) };
            let lanes = errors.far_end(Vec3x8::splat(p), Vec3x8::splat(x), Vec3x8::splat(n));
            assert_eq!(lanes.as_array_ref()[i % 8].to_bits(), e.far_end(p, x, n).to_bits());
        }
    }

    #[test]
    fn simd_offsets_equal_the_scalar_ones_bit_for_bit() {
        let mut rng = SampleRng::new(3, 0, 0);
        for i in 0..100_000 {
            let scale = [0.0, 1e-6, 1e-2, 1.0, 1e3, 1e6][i % 6];
            let mut v = || (rng.uniform() - 0.5) * 2.0;
            let p = Vec3::new(v(), v(), v()) * scale;
            let n = match i % 7 {
                0 => Vec3::X,
                1 => -Vec3::Z,
                _ => Vec3::new(v(), v(), v()).normalize_or(Vec3::Z),
            };
            let error = [0.0, 1e-30, 1e-7, 1e-3][i % 4] * v().abs();
            let expected = offset_ray_origin(p, n, error).to_array().map(f32::to_bits);
            let lanes = offset_ray_origins(Vec3x8::splat(p), Vec3x8::splat(n), f32x8::splat(error));
            assert_eq!(lanes.lane(i % 8).to_array().map(f32::to_bits), expected, "p {p}, n {n}, error {error}");
        }
    }
}
