//! The lecture's Phong material: `f_r(ω, ω_o) = k_d/π + k_s (α+1)/(2π) max(0, ω·ω_r)^α`, ω_r the mirror of ω_o
//! about n, plus an emitted radiance for area lights.

use crate::math::{Frame, ONE_MINUS_EPSILON, reflect};
use crate::sampling::{cosine_hemisphere_pdf, phong_lobe_pdf_from_gap, sample_cosine_hemisphere, sample_phong_lobe};
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Diffuse albedo k_d (RGB).
    pub kd: Vec3,
    /// Specular coefficient k_s (RGB).
    pub ks: Vec3,
    /// Phong exponent α ≥ 0.
    pub alpha: f32,
    /// Emitted radiance L_e (RGB), on the side the triangle's normal faces.
    pub emission: Vec3,
}

impl Default for Material {
    fn default() -> Self {
        Self { kd: Vec3::splat(0.5), ks: Vec3::ZERO, alpha: 1.0, emission: Vec3::ZERO }
    }
}

impl Material {
    pub fn is_emissive(&self) -> bool {
        self.emission.max_element() > 0.0
    }

    /// True where k_d + k_s > 1 in some channel: the BRDF then reflects more than it receives.
    pub fn exceeds_energy_conservation(&self) -> bool {
        (self.kd + self.ks).max_element() > 1.0
    }

    /// Probability of choosing the diffuse lobe in BRDF sampling: `Pr(diffuse) = k_d/(k_d + k_s)` on the RGB
    /// averages (the lecture's Bernoulli lobe choice). `None` for a black material (k_d = k_s = 0).
    #[inline]
    pub fn diffuse_probability(&self) -> Option<f32> {
        let (d, s) = (self.kd.element_sum(), self.ks.element_sum());
        (d + s > 0.0).then(|| d / (d + s))
    }

    /// `f_r(ω_i, ω_o)` with unit vectors on the side of the unit normal `n`; 0 when either lies below.
    #[inline]
    pub fn eval_brdf(&self, n: Vec3, wo: Vec3, wi: Vec3) -> Vec3 {
        if n.dot(wi) <= 0.0 || n.dot(wo) <= 0.0 {
            return Vec3::ZERO;
        }
        let mut f = self.kd * FRAC_1_PI;
        if self.ks != Vec3::ZERO {
            let lobe = phong_lobe_pdf_from_gap(mirror_gap(n, wo, wi), self.alpha);
            f += self.ks * lobe;
        }
        f
    }

    /// Samples ω_i from the mixture `Pr(diffuse) · cos θ/π + Pr(specular) · (α+1)/(2π) cos^α θ_r`, with two
    /// uniforms: u₀ chooses the lobe and is then rescaled and reused (the lecture's "technical detail").
    /// Directions below the surface are returned; they carry f_r = 0.
    #[inline]
    pub fn sample_brdf(&self, n: Vec3, wo: Vec3, u: Vec2) -> Option<Vec3> {
        let p_d = self.diffuse_probability()?;
        if u.x < p_d {
            let u0 = (u.x / p_d).min(ONE_MINUS_EPSILON);
            Some(Frame::from_z(n).to_world(sample_cosine_hemisphere(Vec2::new(u0, u.y))))
        } else {
            let u0 = ((u.x - p_d) / (1.0 - p_d)).clamp(0.0, ONE_MINUS_EPSILON);
            let wr = reflect(wo, n);
            Some(Frame::from_z(wr).to_world(sample_phong_lobe(Vec2::new(u0, u.y), self.alpha)))
        }
    }

    /// Solid-angle density of [`Material::sample_brdf`] (the mixture, as the estimator must divide by it).
    #[inline]
    pub fn pdf_brdf(&self, n: Vec3, wo: Vec3, wi: Vec3) -> f32 {
        let Some(p_d) = self.diffuse_probability() else { return 0.0 };
        let mut p = p_d * cosine_hemisphere_pdf(n.dot(wi));
        if p_d < 1.0 {
            p += (1.0 - p_d) * phong_lobe_pdf_from_gap(mirror_gap(n, wo, wi), self.alpha);
        }
        p
    }
}

/// `1 − ω_i·ω_r = |ω_i − ω_r|²/2`, exact where the dot product would round to 1.
#[inline]
fn mirror_gap(n: Vec3, wo: Vec3, wi: Vec3) -> f32 {
    let wr = reflect(wo, n);
    0.5 * (wi - wr).length_squared()
}

/// Rejects values the BRDF is not defined for; the error names the material and the field.
pub(crate) fn validate(m: &Material, name: &str) -> Result<(), super::SceneError> {
    let check = |what: &str, ok: bool| {
        if ok { Ok(()) } else { Err(super::SceneError::Invalid(format!("material '{name}': {what}"))) }
    };
    let non_negative = |v: Vec3| v.is_finite() && v.min_element() >= 0.0;
    check("k_d (Kd) must be finite and ≥ 0", non_negative(m.kd))?;
    check("k_s (Ks) must be finite and ≥ 0", non_negative(m.ks))?;
    check("emitted radiance (Ke) must be finite and ≥ 0", non_negative(m.emission))?;
    check("Phong exponent α (Ns) must be finite and ≥ 0", m.alpha.is_finite() && m.alpha >= 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::PI;

    #[test]
    fn black_material_samples_nothing() {
        let m = Material { kd: Vec3::ZERO, ks: Vec3::ZERO, ..Default::default() };
        assert!(m.sample_brdf(Vec3::Z, Vec3::Z, Vec2::splat(0.5)).is_none());
        assert_eq!(m.pdf_brdf(Vec3::Z, Vec3::Z, Vec3::Z), 0.0);
        assert_eq!(m.eval_brdf(Vec3::Z, Vec3::Z, Vec3::Z), Vec3::ZERO);
    }

    #[test]
    fn lambertian_value() {
        let m = Material { kd: Vec3::splat(0.6), ..Default::default() };
        let f = m.eval_brdf(Vec3::Z, Vec3::Z, Vec3::new(0.6, 0.0, 0.8));
        assert!((f - Vec3::splat(0.6 / PI)).length() < 1e-7);
        assert_eq!(m.eval_brdf(Vec3::Z, Vec3::Z, -Vec3::Z), Vec3::ZERO);
    }

    #[test]
    fn phong_peak_is_alpha_plus_one_over_two_pi() {
        let m = Material { kd: Vec3::ZERO, ks: Vec3::ONE, alpha: 1e6, ..Default::default() };
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let wr = reflect(wo, Vec3::Z);
        let f = m.eval_brdf(Vec3::Z, wo, wr);
        assert!((f.x / ((1e6 + 1.0) / (2.0 * PI)) - 1.0).abs() < 1e-5);
        assert!((m.pdf_brdf(Vec3::Z, wo, wr) / f.x - 1.0).abs() < 1e-5);
    }
}
