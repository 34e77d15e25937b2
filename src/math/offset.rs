//! Robust ray origins: Wächter & Binder, "A Fast and Robust Method for Avoiding Self-Intersection",
//! Ray Tracing Gems (2019), ch. 6.
//!
//! The hit point is moved off the surface along the geometric normal by a few float ULPs of its own
//! coordinates (an integer offset on the bit pattern), and by a small absolute amount near the origin, where
//! ULPs are tiny. The offset therefore scales with the magnitude of the coordinates: no shadow acne or light
//! leaks near the origin, and none 10⁴ units away from it either.

use glam::Vec3;

const ORIGIN: f32 = 1.0 / 32.0;
const FLOAT_SCALE: f32 = 1.0 / 65536.0;
const INT_SCALE: f32 = 256.0;

/// Offsets `p` off its surface towards the side of `n` (the unit geometric normal, pointing to the side the new
/// ray leaves on).
#[inline]
pub fn offset_ray_origin(p: Vec3, n: Vec3) -> Vec3 {
    let of_i = [(INT_SCALE * n.x) as i32, (INT_SCALE * n.y) as i32, (INT_SCALE * n.z) as i32];
    let pa = p.to_array();
    let na = n.to_array();
    let mut out = [0.0f32; 3];
    for k in 0..3 {
        let shift = if pa[k] < 0.0 { -of_i[k] } else { of_i[k] };
        let p_i = f32::from_bits((pa[k].to_bits() as i32).wrapping_add(shift) as u32);
        out[k] = if pa[k].abs() < ORIGIN { pa[k] + FLOAT_SCALE * na[k] } else { p_i };
    }
    Vec3::from_array(out)
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
}
