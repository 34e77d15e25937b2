//! Uniform hemisphere sampling: `p(ω) = 1/(2π)`, so the estimator is `f_r L_i (ω_k·n) 2π`.

use super::{DirectionSample, Target};
use crate::math::{Frame, SampleRng};
use crate::render::ShadingPoint;
use crate::sampling::{sample_uniform_hemisphere, uniform_hemisphere_pdf};

pub const DESCRIPTION: &str = "uniform directions on the hemisphere around n";
pub const PDF: &str = "p(ω) = 1/(2π)";

#[inline]
pub fn sample(sp: &ShadingPoint, rng: &mut SampleRng) -> Option<DirectionSample> {
    let wi = Frame::from_z(sp.n).to_world(sample_uniform_hemisphere(rng.uniform_2d()));
    Some(DirectionSample { wi, pdf: uniform_hemisphere_pdf(), target: Target::Trace })
}
