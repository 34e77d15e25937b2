//! Phong BRDF sampling: choose the diffuse lobe with Pr = k_d/(k_d+k_s), else the cos^α lobe around ω_r; divide
//! by the mixture density. Two uniforms per sample: the lobe-choosing one is rescaled and reused.

use super::{DirectionSample, DirectionStrategy, Domain, Reached, SampleContext, Target};
use crate::math::SampleRng;
use crate::render::ShadingPoint;
use glam::Vec3;

pub struct Brdf;

impl DirectionStrategy for Brdf {
    const NAME: &'static str = "brdf";
    const DESCRIPTION: &'static str = "Phong BRDF sampling: Bernoulli choice of diffuse or cos^α lobe, mixture pdf";
    const PDF: &'static str = "p(ω) = Pr_d (ω·n)/π + (1−Pr_d) (α+1)/(2π) (ω·ω_r)^α,  Pr_d = k_d/(k_d+k_s)";
    const DOMAIN: Domain = Domain::Hemisphere;

    #[inline]
    fn sample(&self, _: &SampleContext, sp: &ShadingPoint, rng: &mut SampleRng) -> Option<DirectionSample> {
        let m = sp.material;
        let wi = m.sample_brdf(sp.n, sp.wo, rng.uniform_2d())?;
        let pdf = m.pdf_brdf(sp.n, sp.wo, wi);
        Some(DirectionSample { wi, pdf, target: Target::Trace })
    }

    /// The mixture's density; the specular lobe reaches below the surface, where f_r = 0.
    #[inline]
    fn pdf(&self, _: &SampleContext, sp: &ShadingPoint, wi: Vec3, _: Option<Reached>) -> f32 {
        sp.material.pdf_brdf(sp.n, sp.wo, wi)
    }
}
