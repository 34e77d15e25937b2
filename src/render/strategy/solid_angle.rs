//! Solid-angle light sampling: pick a triangle with p_Δ, then a direction uniformly in the spherical triangle it
//! subtends (Arvo 1995): `p(ω) = p_Δ / Ω_Δ`. No 1/r² in the estimator, so a light touching the surface is no
//! harder than a far one. Where Ω_Δ < 3·10⁻⁴ sr or > 6.22 sr (float precision; pbrt-v4's limits) it samples the
//! area instead, with that density.

use super::emitter::Emitter;
use super::light::{LightStrategy, TriangleSampler, area_pdf_solid_angle, hit_plane};
use crate::math::SampleRng;
use crate::render::ShadingPoint;
use crate::sampling::{
    MAX_SPHERICAL_SAMPLE_AREA, MIN_SPHERICAL_SAMPLE_AREA, sample_spherical_triangle, spherical_triangle_area,
    spherical_triangle_pdf,
};
use crate::scene::Triangle;
use glam::Vec3;

pub struct SolidAngle;

impl SolidAngle {
    /// Ω_Δ seen from p, and whether Arvo's construction samples it there (else the area is sampled).
    #[inline(always)]
    pub fn solid_angle_at(p: Vec3, tri: &Triangle) -> (f32, bool) {
        let [a, b, c] = tri.v;
        let omega = spherical_triangle_area(p, a, b, c);
        (omega, (MIN_SPHERICAL_SAMPLE_AREA..=MAX_SPHERICAL_SAMPLE_AREA).contains(&omega))
    }

    /// What `sample_triangle` gives for the direction `wi` drawn by Arvo's construction (`None`: none was), with
    /// Ω_Δ = `omega` in the spherical range: ω, `1/Ω_Δ` and the point ω aims at on Δ.
    #[inline(always)]
    pub fn spherical_sample(p: Vec3, tri: &Triangle, omega: f32, wi: Option<Vec3>) -> Option<(Vec3, f32, Vec3)> {
        let wi = wi?;
        let x = hit_plane(p, wi, tri)?;
        Some((wi, spherical_triangle_pdf(omega), x))
    }
}

impl TriangleSampler for SolidAngle {
    #[inline]
    fn sample_triangle(sp: &ShadingPoint, tri: &Triangle, rng: &mut SampleRng) -> Option<(Vec3, f32, Vec3)> {
        let (omega, spherical) = Self::solid_angle_at(sp.p, tri);
        if !spherical {
            return Emitter::sample_triangle(sp, tri, rng);
        }
        let [a, b, c] = tri.v;
        Self::spherical_sample(sp.p, tri, omega, sample_spherical_triangle(rng.uniform_2d(), sp.p, a, b, c))
    }

    #[inline]
    fn triangle_pdf(sp: &ShadingPoint, tri: &Triangle, x: Vec3, wi: Vec3) -> f32 {
        let (omega, spherical) = Self::solid_angle_at(sp.p, tri);
        if spherical { spherical_triangle_pdf(omega) } else { area_pdf_solid_angle(sp.p, tri, x, wi) }
    }
}

impl LightStrategy for SolidAngle {
    const NAME: &'static str = "solid-angle";
    const DESCRIPTION: &'static str = "uniform directions in the spherical triangle of a light triangle (Arvo 1995)";
    const PDF: &'static str = "p(ω) = p_Δ / Ω_Δ   (area sampling where Ω_Δ < 3e-4 or > 6.22 sr)";
}
