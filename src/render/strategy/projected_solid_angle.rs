//! Projected-solid-angle light sampling: pick a triangle with p_Δ, then a direction with density ∝ (ω·n) over
//! it: `p(ω) = p_Δ (ω·n)⁺ / Ω⊥_Δ`. On a diffuse surface under one unoccluded triangle the estimate is the
//! constant `(k_d/π) L Ω⊥`: its only variance is visibility and the choice of triangle. Exact by rejection from
//! spherical-triangle samples; area sampling where that would be inefficient (see [`ProjectedPlan`]).

use super::emitter::Emitter;
use super::light::{LightStrategy, TriangleSampler, area_pdf_solid_angle, hit_plane};
use crate::math::SampleRng;
use crate::render::ShadingPoint;
use crate::sampling::{ProjectedPlan, projected_triangle_pdf, sample_projected_triangle};
use crate::scene::Triangle;
use glam::Vec3;

pub struct ProjectedSolidAngle;

impl ProjectedSolidAngle {
    /// How Δ is sampled from `sp` (see [`ProjectedPlan`]).
    #[inline(always)]
    pub fn plan(sp: &ShadingPoint, tri: &Triangle) -> ProjectedPlan {
        let [a, b, c] = tri.v;
        ProjectedPlan::new(sp.p, sp.n, a, b, c)
    }

    /// What `sample_triangle` gives for the direction `wi` drawn by rejection (`None`: none was), Ω⊥ being
    /// `projected`: ω, `(ω·n)⁺/Ω⊥` and the point ω aims at on Δ.
    #[inline(always)]
    pub fn rejection_sample(
        sp: &ShadingPoint,
        tri: &Triangle,
        projected: f32,
        wi: Option<Vec3>,
    ) -> Option<(Vec3, f32, Vec3)> {
        let wi = wi?;
        let x = hit_plane(sp.p, wi, tri)?;
        Some((wi, projected_triangle_pdf(wi.dot(sp.n), projected), x))
    }
}

impl TriangleSampler for ProjectedSolidAngle {
    #[inline]
    fn sample_triangle(sp: &ShadingPoint, tri: &Triangle, rng: &mut SampleRng) -> Option<(Vec3, f32, Vec3)> {
        match Self::plan(sp, tri) {
            ProjectedPlan::Invisible => None,
            ProjectedPlan::Area => Emitter::sample_triangle(sp, tri, rng),
            ProjectedPlan::Rejection { projected, cos_max, .. } => {
                let wi = sample_projected_triangle(rng, sp.p, sp.n, tri.v, cos_max);
                Self::rejection_sample(sp, tri, projected, wi)
            }
        }
    }

    #[inline]
    fn triangle_pdf(sp: &ShadingPoint, tri: &Triangle, x: Vec3, wi: Vec3) -> f32 {
        match Self::plan(sp, tri) {
            ProjectedPlan::Invisible => 0.0,
            ProjectedPlan::Area => area_pdf_solid_angle(sp.p, tri, x, wi),
            ProjectedPlan::Rejection { projected, .. } => projected_triangle_pdf(wi.dot(sp.n), projected),
        }
    }
}

impl LightStrategy for ProjectedSolidAngle {
    const NAME: &'static str = "projected-solid-angle";
    const DESCRIPTION: &'static str =
        "directions proportional to cos θ over a light triangle (exact): ideal for diffuse";
    const PDF: &'static str = "p(ω) = p_Δ (ω·n) / Ω_proj,  Ω_proj = ½ Σ Θ_i (n·γ_i)";
}
