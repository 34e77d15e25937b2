//! One image being refined: its settings, its film and what it took.

use crate::render::{Film, PassStats, RenderSettings};
use crate::scene::Camera;
use std::time::Duration;

/// One image being refined.
pub(super) struct Lane {
    pub(super) settings: RenderSettings,
    pub(super) film: Film,
    pub(super) spp: u32,
    pub(super) passes: u32,
    pub(super) stats: PassStats,
    pub(super) elapsed: Duration,
    /// The generation this film belongs to.
    pub(super) generation: u64,
    /// Whether the preview of this generation was published.
    pub(super) previewed: bool,
}

impl Lane {
    pub(super) fn new(settings: RenderSettings, camera: &Camera) -> Self {
        Self {
            settings,
            film: Film::new(camera.width, camera.height),
            spp: 0,
            passes: 0,
            stats: PassStats::default(),
            elapsed: Duration::ZERO,
            generation: 0,
            previewed: false,
        }
    }

    pub(super) fn reset(&mut self, camera: &Camera, generation: u64) {
        if (self.film.width, self.film.height) == (camera.width, camera.height) {
            self.film.clear();
        } else {
            self.film = Film::new(camera.width, camera.height);
        }
        self.spp = 0;
        self.passes = 0;
        self.stats = PassStats::default();
        self.elapsed = Duration::ZERO;
        self.generation = generation;
        self.previewed = false;
    }
}
