//! Uniform hemisphere sampling: `p(ω) = 1/(2π)`, so the estimator is `f_r L_i (ω_k·n) 2π`.

use super::{DirectionSample, DirectionStrategy, Domain, Reached, SampleContext, Target};
use crate::math::{Frame, SampleRng};
use crate::render::ShadingPoint;
use crate::sampling::{sample_uniform_hemisphere, uniform_hemisphere_pdf};
use glam::Vec3;

pub struct Uniform;

impl DirectionStrategy for Uniform {
    const NAME: &'static str = "uniform";
    const DESCRIPTION: &'static str = "uniform directions on the hemisphere around n";
    const PDF: &'static str = "p(ω) = 1/(2π)";
    const DOMAIN: Domain = Domain::Hemisphere;

    #[inline]
    fn sample(&self, _: &SampleContext, sp: &ShadingPoint, rng: &mut SampleRng) -> Option<DirectionSample> {
        let wi = Frame::from_z(sp.n).to_world(sample_uniform_hemisphere(rng.uniform_2d()));
        Some(DirectionSample { wi, pdf: uniform_hemisphere_pdf(), target: Target::Trace })
    }

    /// `1/(2π)` above the surface, 0 below.
    #[inline]
    fn pdf(&self, _: &SampleContext, sp: &ShadingPoint, wi: Vec3, _: Option<Reached>) -> f32 {
        if sp.n.dot(wi) > 0.0 { uniform_hemisphere_pdf() } else { 0.0 }
    }
}
