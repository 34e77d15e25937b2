//! The specular lobe of the lecture's Phong BRDF, sampled around the mirror direction ω_r.

use crate::math::sin_cos;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// Direction in the lobe's frame (z = ω_r) with density `p(ω) = (α+1)/(2π) cos^α θ_r` w.r.t. solid angle, where
/// cos θ_r = ω·ω_r (the lecture's Phong lobe; Lafortune & Willems 1994). cos θ_r = u₀^{1/(α+1)}, φ = 2π u₁.
///
/// `1 − cos θ_r = −expm1(ln u₀ / (α+1))` keeps the sine accurate for α up to 10⁶ and beyond, where cos θ_r is
/// within a few float ULPs of 1.
#[inline]
pub fn sample_phong_lobe(u: Vec2, alpha: f32) -> Vec3 {
    let gap = (-(u.x.ln() / (alpha + 1.0)).exp_m1()).clamp(0.0, 1.0); // 1 − cos θ_r
    let cos_theta = 1.0 - gap;
    let sin_theta = (gap * (2.0 - gap)).max(0.0).sqrt();
    let (sin_phi, cos_phi) = sin_cos(2.0 * PI * u.y);
    Vec3::new(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta)
}

/// Density of [`sample_phong_lobe`] at cos θ_r: `(α+1)/(2π) max(0, cos θ_r)^α` (solid angle).
#[inline]
pub fn phong_lobe_pdf(cos_theta_r: f32, alpha: f32) -> f32 {
    if cos_theta_r <= 0.0 {
        return 0.0;
    }
    (alpha + 1.0) * (0.5 / PI) * cos_theta_r.powf(alpha)
}

/// Same density from the gap `g = 1 − cos θ_r` (pass `|ω − ω_r|²/2`, which is exact for unit vectors and does not
/// cancel): `cos^α θ_r = exp(α ln(1 − g))`. Accurate where ω·ω_r rounds to 1 (α ≳ 10⁵).
#[inline]
pub fn phong_lobe_pdf_from_gap(gap: f32, alpha: f32) -> f32 {
    // ln(1 − g) ≤ −g, so α g > 110 puts α ln(1 − g) below −110, rounding errors and all, where exp is 0 in f32
    // (below −103.98): the same 0 without the two calls, for most directions off a narrow lobe.
    if gap >= 1.0 || alpha * gap > 110.0 {
        return 0.0;
    }
    let log_cos = (-gap).ln_1p();
    (alpha + 1.0) * (0.5 / PI) * (alpha * log_cos).exp()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extreme_exponents_stay_finite_and_unit() {
        for alpha in [0.0, 1e-3, 1.0, 1e3, 1e6, 1e9] {
            for u in [Vec2::ZERO, Vec2::splat(0.5), Vec2::splat(0.99999994), Vec2::new(1e-30, 0.3)] {
                let w = sample_phong_lobe(u, alpha);
                assert!(w.is_finite() && (w.length() - 1.0).abs() < 1e-5, "{alpha} {u:?} {w:?}");
                let gap = (w - Vec3::Z).length_squared() * 0.5;
                let p = phong_lobe_pdf_from_gap(gap, alpha);
                assert!(p.is_finite() && p >= 0.0);
            }
        }
    }

    /// The shortcut for α g > 110 returns what the formula gives, bit for bit, on both sides of it.
    #[test]
    fn narrow_lobe_shortcut_changes_nothing() {
        for alpha in [1.0f32, 111.0, 1e3, 1e4, 1e6] {
            for k in 0..=4000 {
                let gap = (110.0 / alpha) * (0.5 + k as f32 / 2000.0);
                let formula = (alpha + 1.0) * (0.5 / PI) * (alpha * (-gap).ln_1p()).exp();
                let value = if gap >= 1.0 { 0.0 } else { formula };
                assert_eq!(phong_lobe_pdf_from_gap(gap, alpha).to_bits(), value.to_bits(), "α {alpha}, g {gap}");
            }
        }
    }

    #[test]
    fn gap_form_agrees_with_cosine_form() {
        for alpha in [0.0, 1.0, 50.0, 1e4] {
            for c in [0.2f32, 0.9, 0.999] {
                let a = phong_lobe_pdf(c, alpha);
                let b = phong_lobe_pdf_from_gap(1.0 - c, alpha);
                assert!((a - b).abs() <= 1e-3 * a.max(1e-30), "{alpha} {c}: {a} vs {b}");
            }
        }
    }
}
