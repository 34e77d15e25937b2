//! One image being refined: its settings, its film and what it took.

use crate::guiding::{Guide, GuideSettings};
use crate::render::{Film, PassStats, PixelCones, RenderSettings, Renderer};
use crate::scene::{Camera, Scene};
use std::sync::Arc;
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
    /// The renderer of its passes, kept while the scene and the settings are the same (it owns the state built
    /// per scene and settings).
    renderer: Option<Renderer>,
    /// The guide the last renderer that learned one finished learning, with the guide settings it learned
    /// with: a new renderer with those settings samples from it if it is of the same light (camera, material and
    /// other setting changes keep it).
    pub(super) guide: Option<(GuideSettings, Arc<Guide>)>,
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
            renderer: None,
            guide: None,
        }
    }

    /// The renderer for `scene` and this lane's settings, to be given back with [`Lane::keep`]: the kept one if
    /// it is for both, else a new one, which takes `cones` if they are for its camera.
    pub(super) fn take_renderer(&mut self, scene: &Arc<Scene>, cones: Option<&Arc<PixelCones>>) -> Renderer {
        let settings = self.settings;
        match self.renderer.take() {
            Some(r) if Arc::ptr_eq(r.scene(), scene) && *r.settings() == settings => r,
            _ => {
                let mut renderer = Renderer::new(scene.clone(), settings);
                if let Some(guide) = self.kept_guide() {
                    renderer = renderer.with_guide(guide);
                }
                match cones {
                    Some(cones) => renderer.with_cones(cones.clone()),
                    None => renderer,
                }
            }
        }
    }

    pub(super) fn keep(&mut self, renderer: Renderer) {
        if let Some(t) = renderer.training().filter(|t| t.is_frozen()) {
            self.guide = Some((*t.settings(), t.guide().clone()));
        }
        self.renderer = Some(renderer);
    }

    /// The kept guide, if it was learned with this lane's guide settings.
    pub(super) fn kept_guide(&self) -> Option<Arc<Guide>> {
        self.guide.as_ref().filter(|(s, _)| *s == self.settings.guiding).map(|(_, g)| g.clone())
    }

    /// Forgets the learned guide and the renderer that holds it.
    pub(super) fn forget_guide(&mut self) {
        self.guide = None;
        self.renderer = None;
    }

    pub(super) fn reset(&mut self, camera: &Camera, generation: u64) {
        if (self.film.width, self.film.height) == (camera.width, camera.height) {
            self.film.clear();
        } else {
            self.film = Film::new(camera.width, camera.height);
        }
        // A guide still learning is learned again from the first sample: the image is then what a fresh render
        // gives (a finished one is kept, see `guide`).
        if self.renderer.as_ref().and_then(Renderer::training).is_some_and(|t| !t.is_frozen()) {
            self.renderer = None;
        }
        self.spp = 0;
        self.passes = 0;
        self.stats = PassStats::default();
        self.elapsed = Duration::ZERO;
        self.generation = generation;
        self.previewed = false;
    }
}
