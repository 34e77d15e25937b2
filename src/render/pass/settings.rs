//! What a render is a function of besides the scene ([`RenderSettings`]), and what its passes count
//! ([`PassStats`]).

use crate::guiding::GuideSettings;
use crate::render::strategy::MisSettings;
use crate::render::{Footprint, Strategy};
use crate::scene::LightSelection;
use std::time::Duration;

/// What a render is a function of, besides the scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct RenderSettings {
    pub strategy: Strategy,
    pub light_selection: LightSelection,
    pub seed: u64,
    /// Used by [`Strategy::Mis`].
    pub mis: MisSettings,
    /// Where camera rays go in their pixels.
    pub footprint: Footprint,
    /// How `guided` learns its guide.
    pub guiding: GuideSettings,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            strategy: Strategy::Emitter,
            light_selection: LightSelection::Power,
            seed: 0,
            mis: MisSettings::default(),
            footprint: Footprint::Jittered,
            guiding: GuideSettings::default(),
        }
    }
}

/// Counts from one or more passes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PassStats {
    /// Pixel samples taken (accepted + dropped).
    pub samples: u64,
    /// Rays traced: camera, BRDF and shadow rays.
    pub rays: u64,
    /// Non-finite samples dropped.
    pub non_finite: u64,
    /// CPU time spent on the samples, summed over threads (each row's thread CPU clock).
    pub cpu: Duration,
}

impl std::ops::AddAssign for PassStats {
    fn add_assign(&mut self, o: Self) {
        self.samples += o.samples;
        self.rays += o.rays;
        self.non_finite += o.non_finite;
        self.cpu += o.cpu;
    }
}
