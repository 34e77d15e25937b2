//! Robust ray origins: Wächter & Binder, "A Fast and Robust Method for Avoiding Self-Intersection",
//! Ray Tracing Gems (2019), ch. 6.
//!
//! The hit point is moved off the surface along the geometric normal by a few float ULPs of its own
//! coordinates (an integer offset on the bit pattern), and by a small absolute amount near the origin, where
//! ULPs are tiny. The offset therefore scales with the magnitude of the coordinates: no shadow acne or light
//! leaks near the origin, and none 10⁴ units away from it either.

use super::Vec3x8;
use bytemuck::cast;
use glam::Vec3;
use wide::{CmpLt, f32x4, f32x8, i32x4, i32x8};

const ORIGIN: f32 = 1.0 / 32.0;
const FLOAT_SCALE: f32 = 1.0 / 65536.0;
const INT_SCALE: f32 = 256.0;

/// One coordinate per lane: `p` moved by an integer number of ULPs (or, near 0, by a small absolute amount)
/// towards the sign of the normal's component `n`.
macro_rules! offset_lanes {
    ($p:expr, $n:expr, $f:ty, $i:ty) => {{
        let (p, n): ($f, $f) = ($p, $n);
        let of_i = (n * <$f>::splat(INT_SCALE)).trunc_int();
        // Negate the integer offset where p < 0: (x ⊕ m) − m with m = −1 there, 0 elsewhere.
        let negative: $i = cast(p.cmp_lt(<$f>::ZERO));
        let shift = (of_i ^ negative) - negative;
        let p_i: $f = cast(cast::<$f, $i>(p) + shift);
        let near_origin = p.abs().cmp_lt(<$f>::splat(ORIGIN));
        near_origin.blend(p + n * <$f>::splat(FLOAT_SCALE), p_i)
    }};
}

/// Offsets `p` off its surface towards the side of `n` (the unit geometric normal, pointing to the side the new
/// ray leaves on). The three coordinates are handled at once (SIMD, four lanes).
#[inline]
pub fn offset_ray_origin(p: Vec3, n: Vec3) -> Vec3 {
    let out = offset_lanes!(f32x4::new([p.x, p.y, p.z, 0.0]), f32x4::new([n.x, n.y, n.z, 0.0]), f32x4, i32x4);
    let out = out.to_array();
    Vec3::new(out[0], out[1], out[2])
}

/// [`offset_ray_origin`] for eight points at once, one per lane; the same values bit for bit.
#[inline]
pub fn offset_ray_origins(p: Vec3x8, n: Vec3x8) -> Vec3x8 {
    Vec3x8 {
        x: offset_lanes!(p.x, n.x, f32x8, i32x8),
        y: offset_lanes!(p.y, n.y, f32x8, i32x8),
        z: offset_lanes!(p.z, n.z, f32x8, i32x8),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offset_moves_to_the_normal_side_at_every_scale() {
        let n = Vec3::new(0.3, -0.5, 0.8).normalize();
        for scale in [0.0, 1e-3, 1.0, 1e2, 1e4, 1e6] {
            let p = Vec3::new(1.0, -2.0, 3.0) * scale;
            let q = offset_ray_origin(p, n);
            assert!(q.is_finite());
            assert!((q - p).dot(n) > 0.0, "scale {scale}");
            // Small relative to the coordinates.
            assert!((q - p).length() <= 1e-3 * (1.0 + p.abs().max_element()));
        }
    }

    /// The formula of Ray Tracing Gems ch. 6, one coordinate at a time.
    fn offset_scalar(p: Vec3, n: Vec3) -> Vec3 {
        let mut out = [0.0f32; 3];
        for k in 0..3 {
            let of_i = (INT_SCALE * n[k]) as i32;
            let shift = if p[k] < 0.0 { -of_i } else { of_i };
            let p_i = f32::from_bits((p[k].to_bits() as i32).wrapping_add(shift) as u32);
            out[k] = if p[k].abs() < ORIGIN { p[k] + FLOAT_SCALE * n[k] } else { p_i };
        }
        Vec3::from_array(out)
    }

    #[test]
    fn simd_offsets_equal_the_scalar_formula_bit_for_bit() {
        let mut rng = crate::math::SampleRng::new(3, 0, 0);
        for i in 0..100_000 {
            let scale = [1e-6, 1e-2, 1.0, 1e3, 1e6][i % 5];
            let mut v = || (rng.uniform() - 0.5) * 2.0;
            let p = Vec3::new(v(), v(), v()) * scale;
            let n = Vec3::new(v(), v(), v()).normalize_or(Vec3::Z);
            let expected = offset_scalar(p, n).to_array().map(f32::to_bits);
            assert_eq!(offset_ray_origin(p, n).to_array().map(f32::to_bits), expected);
            let lanes = offset_ray_origins(Vec3x8::splat(p), Vec3x8::splat(n));
            assert_eq!(lanes.lane(i % 8).to_array().map(f32::to_bits), expected);
        }
    }
}
