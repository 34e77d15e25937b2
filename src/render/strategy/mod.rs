//! The sampling strategies: each is one small unit that draws a direction ω_k and knows its density p(ω_k), so
//! that `f_r L_i (ω_k·n) / p(ω_k)` estimates the scattering integral. All of them estimate the same integral.

mod brdf;
mod cosine;
mod emitter;
pub mod light;
pub mod mis;
mod projected_solid_angle;
mod solid_angle;
mod uniform;

pub use light::LightTechnique;
pub use mis::{Heuristic, MisSettings};

use super::ShadingPoint;
use crate::math::SampleRng;
use crate::scene::{EmitterSampler, Scene};
use glam::Vec3;

/// A sampled incident direction and how to find the radiance arriving along it.
#[derive(Clone, Copy, Debug)]
pub struct DirectionSample {
    /// Unit direction towards the light (ω_k).
    pub wi: Vec3,
    /// Its density w.r.t. solid angle.
    pub pdf: f32,
    pub target: Target,
}

/// How L_i(ω_k) is found.
#[derive(Clone, Copy, Debug)]
pub enum Target {
    /// Trace a ray along ω_k; L_i is the radiance emitted by whatever it hits first.
    Trace,
    /// The direction was aimed at a point on an emitter triangle: L_i is its emission if a shadow ray gets
    /// through.
    Emitter { triangle: u32, point: Vec3 },
}

/// A strategy by its command-line name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Strategy {
    Uniform,
    Cosine,
    Brdf,
    Emitter,
    SolidAngle,
    ProjectedSolidAngle,
    Mis,
}

impl Strategy {
    pub const ALL: [Strategy; 7] = [
        Strategy::Uniform,
        Strategy::Cosine,
        Strategy::Brdf,
        Strategy::Emitter,
        Strategy::SolidAngle,
        Strategy::ProjectedSolidAngle,
        Strategy::Mis,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Strategy::Uniform => "uniform",
            Strategy::Cosine => "cosine",
            Strategy::Brdf => "brdf",
            Strategy::Emitter => "emitter",
            Strategy::SolidAngle => "solid-angle",
            Strategy::ProjectedSolidAngle => "projected-solid-angle",
            Strategy::Mis => "mis",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.name() == name)
    }

    /// One line: what the strategy samples.
    pub fn description(self) -> &'static str {
        match self {
            Strategy::Uniform => uniform::DESCRIPTION,
            Strategy::Cosine => cosine::DESCRIPTION,
            Strategy::Brdf => brdf::DESCRIPTION,
            Strategy::Emitter => emitter::DESCRIPTION,
            Strategy::SolidAngle => solid_angle::DESCRIPTION,
            Strategy::ProjectedSolidAngle => projected_solid_angle::DESCRIPTION,
            Strategy::Mis => mis::DESCRIPTION,
        }
    }

    /// The density in the lecture's notation.
    pub fn pdf_formula(self) -> &'static str {
        match self {
            Strategy::Uniform => uniform::PDF,
            Strategy::Cosine => cosine::PDF,
            Strategy::Brdf => brdf::PDF,
            Strategy::Emitter => emitter::PDF,
            Strategy::SolidAngle => solid_angle::PDF,
            Strategy::ProjectedSolidAngle => projected_solid_angle::PDF,
            Strategy::Mis => mis::PDF,
        }
    }

    /// The light technique of a light strategy.
    pub fn light_technique(self) -> Option<LightTechnique> {
        match self {
            Strategy::Emitter => Some(LightTechnique::Area),
            Strategy::SolidAngle => Some(LightTechnique::SolidAngle),
            Strategy::ProjectedSolidAngle => Some(LightTechnique::ProjectedSolidAngle),
            _ => None,
        }
    }

    /// Draws ω_k. `None`: no sample could be taken (it counts as zero). MIS draws several directions and is
    /// evaluated by the estimator instead.
    #[inline]
    pub fn sample(
        self,
        sp: &ShadingPoint,
        scene: &Scene,
        emitters: Option<&EmitterSampler>,
        rng: &mut SampleRng,
    ) -> Option<DirectionSample> {
        match self {
            Strategy::Uniform => uniform::sample(sp, rng),
            Strategy::Cosine => cosine::sample(sp, rng),
            Strategy::Brdf => brdf::sample(sp, rng),
            Strategy::Emitter | Strategy::SolidAngle | Strategy::ProjectedSolidAngle => {
                self.light_technique()?.sample(sp, scene, emitters?, rng)
            }
            Strategy::Mis => None,
        }
    }
}
