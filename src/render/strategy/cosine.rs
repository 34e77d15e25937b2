//! Cosine-weighted hemisphere sampling: `p(ω) = (ω·n)/π`, so the estimator is `f_r L_i π`.

use super::{DirectionSample, Target};
use crate::math::{Frame, SampleRng};
use crate::render::ShadingPoint;
use crate::sampling::{cosine_hemisphere_pdf, sample_cosine_hemisphere};

pub const DESCRIPTION: &str = "cosine-weighted directions on the hemisphere (importance-samples ω·n)";
pub const PDF: &str = "p(ω) = (ω·n)/π";

#[inline]
pub fn sample(sp: &ShadingPoint, rng: &mut SampleRng) -> Option<DirectionSample> {
    let local = sample_cosine_hemisphere(rng.uniform_2d());
    let wi = Frame::from_z(sp.n).to_world(local);
    Some(DirectionSample { wi, pdf: cosine_hemisphere_pdf(local.z), target: Target::Trace })
}
