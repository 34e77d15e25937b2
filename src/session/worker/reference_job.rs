//! The reference as the worker renders it: from a file, from the cache, or pass by pass between the lanes' passes,
//! then stored in the cache.

use super::state::State;
use super::{A, ReferenceStatus};
use crate::measure::{Reference, ReferenceOrigin, load_cached, reference_settings, store_cached};
use crate::render::{Film, Renderer};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

/// The reference being rendered.
pub(super) struct ReferenceJob {
    target: u32,
    cache: Option<PathBuf>,
    film: Film,
    /// `film` and one more pass's samples, added sample by sample as a one-shot render adds them (so the
    /// reference does not depend on how its passes were sized); it replaces `film` when the pass completes.
    scratch: Film,
    spp: u32,
    elapsed: Duration,
    /// Kept from pass to pass: a new scene starts a new job.
    renderer: Renderer,
}

impl State {
    /// Sets up the reference for the current scene: from a file, from the cache, or a render job.
    pub(super) fn start_reference(&mut self) {
        self.job = None;
        let (w, h) = (self.scene.camera.width, self.scene.camera.height);
        if let Some(path) = &self.reference_file {
            let status = match Reference::load_exr(path).and_then(|r| r.check_size(w, h).map(|()| r)) {
                Ok(r) => ReferenceStatus::Ready { reference: Arc::new(r), note: format!("from {}", path.display()) },
                Err(e) => ReferenceStatus::Failed(e.to_string()),
            };
            // A file matches one camera: later scene or camera changes fall back to rendering.
            self.reference_file = None;
            self.publish_reference(status);
            return;
        }
        // The reference converges to what the lanes do: the box-filtered image or the pixel centres' values.
        let footprint = self.lanes[A].settings.footprint;
        self.reference_footprint = footprint;
        let Some(target) = self.reference_spp else {
            self.publish_reference(ReferenceStatus::Off);
            return;
        };
        if let Some(folder) = &self.reference_cache
            && let Some(r) = load_cached(folder, &self.scene, target, footprint)
        {
            let note = match &r.origin {
                ReferenceOrigin::Cache(p) => format!("cached in {}", p.display()),
                _ => String::new(),
            };
            self.publish_reference(ReferenceStatus::Ready { reference: Arc::new(r), note });
            return;
        }
        let target = target.max(1);
        self.job = Some(ReferenceJob {
            target,
            cache: self.reference_cache.clone(),
            film: Film::new(w, h),
            scratch: Film::new(w, h),
            spp: 0,
            elapsed: Duration::ZERO,
            renderer: Renderer::new(self.scene.clone(), reference_settings(footprint)),
        });
        self.publish_reference(ReferenceStatus::Rendering { spp: 0, target, elapsed: Duration::ZERO });
    }

    /// A pass sized as the lanes' are ([`super::PassSize`]) onto a copy of the reference, kept only if no command
    /// arrived meanwhile (so a reference pass never delays a new setting by more than a row).
    pub(super) fn reference_pass(&mut self, pool: &rayon::ThreadPool) {
        let Some(job) = &mut self.job else { return };
        let generation = self.shared.generation.load(Ordering::SeqCst);
        let current = &self.shared.generation;
        let cancelled = move || current.load(Ordering::Relaxed) != generation;
        job.scratch.pixels.clone_from(&job.film.pixels);
        let count = self.pass_size.count(job.spp.min(1), job.spp, job.elapsed).min(job.target - job.spp);
        let start = Instant::now();
        pool.install(|| job.renderer.render_pass(&mut job.scratch, job.spp, count, &cancelled));
        if cancelled() {
            return;
        }
        job.elapsed += start.elapsed();
        job.spp += count;
        std::mem::swap(&mut job.film, &mut job.scratch);
        if job.spp < job.target {
            let status = ReferenceStatus::Rendering { spp: job.spp, target: job.target, elapsed: job.elapsed };
            self.publish_reference(status);
            return;
        }
        let Some(job) = self.job.take() else { return };
        let reference = Reference::from_film(&job.film, job.elapsed.as_secs_f64());
        let note = match &job.cache {
            Some(folder) => match store_cached(folder, &self.scene, &reference, job.renderer.settings().footprint) {
                Ok(p) => format!("rendered in {:.1} s, cached in {}", job.elapsed.as_secs_f64(), p.display()),
                Err(e) => format!("rendered in {:.1} s, not cached: {e}", job.elapsed.as_secs_f64()),
            },
            None => format!("rendered in {:.1} s", job.elapsed.as_secs_f64()),
        };
        self.publish_reference(ReferenceStatus::Ready { reference: Arc::new(reference), note });
    }

    fn publish_reference(&self, status: ReferenceStatus) {
        if let Ok(mut slot) = self.latest.reference.lock() {
            *slot = Some(status);
        }
        (self.notify)();
    }
}
