//! Cosine-weighted hemisphere sampling: `p(ω) = (ω·n)/π`, so the estimator is `f_r L_i π`.

use super::{DirectionSample, DirectionStrategy, Domain, Reached, SampleContext, Target};
use crate::math::{Frame, SampleRng};
use crate::render::ShadingPoint;
use crate::sampling::{cosine_hemisphere_pdf, sample_cosine_hemisphere};
use glam::Vec3;

pub struct Cosine;

impl DirectionStrategy for Cosine {
    const NAME: &'static str = "cosine";
    const DESCRIPTION: &'static str = "cosine-weighted directions on the hemisphere (importance-samples ω·n)";
    const PDF: &'static str = "p(ω) = (ω·n)/π";
    const DOMAIN: Domain = Domain::Hemisphere;

    #[inline]
    fn sample(&self, _: &SampleContext, sp: &ShadingPoint, rng: &mut SampleRng) -> Option<DirectionSample> {
        let local = sample_cosine_hemisphere(rng.uniform_2d());
        let wi = Frame::from_z(sp.n).to_world(local);
        Some(DirectionSample { wi, pdf: cosine_hemisphere_pdf(local.z), target: Target::Trace })
    }

    #[inline]
    fn pdf(&self, _: &SampleContext, sp: &ShadingPoint, wi: Vec3, _: Option<Reached>) -> f32 {
        cosine_hemisphere_pdf(sp.n.dot(wi))
    }
}
