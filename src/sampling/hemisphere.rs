//! Hemisphere warps in the local frame (z = n).

use crate::math::sin_cos;
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, FRAC_PI_2, FRAC_PI_4, PI};

/// Uniform direction on the hemisphere z ≥ 0: `p(ω) = 1/(2π)` w.r.t. solid angle (the lecture's uniform sampling).
/// cos θ = u₀, φ = 2π u₁.
#[inline]
pub fn sample_uniform_hemisphere(u: Vec2) -> Vec3 {
    let z = u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (sin_phi, cos_phi) = sin_cos(2.0 * PI * u.y);
    Vec3::new(r * cos_phi, r * sin_phi, z)
}

/// Density of [`sample_uniform_hemisphere`]: `1/(2π)` on z ≥ 0 (solid angle).
#[inline]
pub fn uniform_hemisphere_pdf() -> f32 {
    0.5 * FRAC_1_PI
}

/// Cosine-weighted direction on the hemisphere: `p(ω) = cos θ / π` w.r.t. solid angle (the lecture's cosine
/// sampling). Malley's method: Shirley–Chiu's concentric map of `u` to the unit disc, lifted to the hemisphere
/// (pbrt-v4, `SampleCosineHemisphere`).
#[inline]
pub fn sample_cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = sample_concentric_disc(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    Vec3::new(d.x, d.y, z)
}

/// Density of [`sample_cosine_hemisphere`]: `cos θ / π` for cos θ ≥ 0, else 0 (solid angle).
#[inline]
pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cos_theta.max(0.0) * FRAC_1_PI
}

/// Shirley & Chiu 1997, "A low distortion map between disk and square": uniform on the unit disc.
#[inline]
fn sample_concentric_disc(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return Vec2::ZERO;
    }
    let (r, theta) =
        if o.x.abs() > o.y.abs() { (o.x, FRAC_PI_4 * (o.y / o.x)) } else { (o.y, FRAC_PI_2 - FRAC_PI_4 * (o.x / o.y)) };
    let (sin, cos) = sin_cos(theta);
    r * Vec2::new(cos, sin)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_are_unit_and_upper() {
        for i in 0..64 {
            for j in 0..64 {
                let u = Vec2::new(i as f32 / 63.0 * 0.9999999, j as f32 / 63.0 * 0.9999999);
                for w in [sample_uniform_hemisphere(u), sample_cosine_hemisphere(u)] {
                    assert!((w.length() - 1.0).abs() < 1e-5);
                    assert!(w.z >= 0.0);
                }
            }
        }
    }
}
