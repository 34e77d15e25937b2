//! The integrator thread's side of the [`super::Worker`]: the films it owns, the commands it applies, and the
//! loop that picks the next pass (lane A, lane B or the reference) and publishes its frame.

use super::lane::Lane;
use super::reference_job::ReferenceJob;
use super::{A, B, Budget, Command, Frame, PassSize, R, Shared, Slots};
use crate::render::{Film, Footprint, PixelCones, RenderSettings, Renderer};
use crate::scene::{Camera, Scene};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::sync::mpsc::{Receiver, TryRecvError};
use std::time::{Duration, Instant};

/// Everything the worker thread owns.
pub(super) struct State {
    pub(super) scene: Arc<Scene>,
    /// The pixel cones the lanes' passes found for this scene's geometry (and its camera, which each renderer
    /// checks), kept from pass to pass.
    pub(super) cones: Option<Arc<PixelCones>>,
    pub(super) lanes: [Lane; 2],
    pub(super) comparing: bool,
    pub(super) budget: Budget,
    /// Equal time with a target: the CPU time the first lane needed to reach it.
    pub(super) time_budget: Option<Duration>,
    pub(super) pass_size: PassSize,
    pub(super) target: Option<u32>,
    pub(super) paused: bool,
    /// What the reference should be: the spp to render and where to cache it, or a file.
    pub(super) reference_spp: Option<u32>,
    pub(super) reference_cache: Option<PathBuf>,
    pub(super) reference_file: Option<PathBuf>,
    pub(super) job: Option<ReferenceJob>,
    /// The reference's generation, to discard a pass cancelled by a scene change.
    pub(super) reference_generation: u64,
    /// The footprint of the reference set up last: a lane with another restarts it.
    pub(super) reference_footprint: Footprint,
    /// Passes run: the reference gets every other one while lanes are busy.
    pub(super) turn: u64,
    /// Per lane and reference: the generation of the last command received that restarts it.
    pub(super) received: [u64; 3],
    pub(super) latest: Arc<Slots>,
    pub(super) shared: Arc<Shared>,
    pub(super) notify: Box<dyn Fn() + Send>,
    /// A pass panicked: nothing renders until a command restarts an image.
    pub(super) stalled: bool,
    /// Tests: make the next pass panic.
    #[cfg(test)]
    pub(super) panic_in_next_pass: bool,
}

/// The text of a panic's payload.
fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "(no message)".into())
}

impl State {
    pub(super) fn new(
        scene: Arc<Scene>,
        settings: RenderSettings,
        latest: Arc<Slots>,
        shared: Arc<Shared>,
        notify: Box<dyn Fn() + Send>,
    ) -> Self {
        let lanes = [Lane::new(settings, &scene.camera), Lane::new(settings, &scene.camera)];
        Self {
            scene,
            cones: None,
            lanes,
            comparing: false,
            budget: Budget::EqualSamples,
            time_budget: None,
            pass_size: PassSize::Auto,
            target: None,
            paused: false,
            reference_spp: None,
            reference_cache: None,
            reference_file: None,
            job: None,
            reference_generation: 0,
            reference_footprint: Footprint::Jittered,
            turn: 0,
            received: [0; 3],
            latest,
            shared,
            notify,
            stalled: false,
            #[cfg(test)]
            panic_in_next_pass: false,
        }
    }

    /// Tells the UI why the integrator stopped.
    fn report_failure(&self, message: String) {
        if let Ok(mut slot) = self.latest.failure.lock() {
            *slot = Some(message);
        }
        (self.notify)();
    }

    fn lane_count(&self) -> usize {
        if self.comparing { 2 } else { 1 }
    }

    fn lane_idle(&self, i: usize) -> bool {
        let lane = &self.lanes[i];
        if self.paused {
            return true;
        }
        match (self.comparing, self.budget) {
            (true, Budget::EqualTime) => self.time_budget.is_some_and(|t| lane.stats.cpu >= t),
            _ => self.target.is_some_and(|t| lane.spp >= t),
        }
    }

    /// The lane to refine next, by the budget: fewer spp, or less CPU time (A on ties).
    fn next_lane(&self) -> Option<usize> {
        let busy = (0..self.lane_count()).filter(|&i| !self.lane_idle(i));
        match self.budget {
            Budget::EqualSamples => busy.min_by_key(|&i| self.lanes[i].spp),
            Budget::EqualTime => busy.min_by_key(|&i| self.lanes[i].stats.cpu),
        }
    }

    fn reference_pending(&self) -> bool {
        !self.paused && self.job.is_some()
    }

    /// `threads` run the passes; the first pass after a restart uses every core, so that a new setting shows as
    /// soon as possible (the UI is idle then).
    pub(super) fn run(mut self, rx: Receiver<(u64, Command)>, threads: usize) {
        let all = std::thread::available_parallelism().map_or(threads, |n| n.get().max(threads));
        let pools = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .and_then(|pool| Ok((pool, rayon::ThreadPoolBuilder::new().num_threads(all).build()?)));
        let (pool, first_pool) = match pools {
            Ok(pools) => pools,
            Err(e) => {
                self.report_failure(format!("cannot start the integrator's {all} threads: {e}"));
                return;
            }
        };
        loop {
            // Apply every pending command; block only when there is nothing to render.
            let mut changed = false;
            loop {
                let nothing_to_do = self.stalled || (self.next_lane().is_none() && !self.reference_pending());
                let (generation, command) = if nothing_to_do && !changed {
                    match rx.recv() {
                        Ok(c) => c,
                        Err(_) => return,
                    }
                } else {
                    match rx.try_recv() {
                        Ok(c) => c,
                        Err(TryRecvError::Empty) => break,
                        Err(TryRecvError::Disconnected) => return,
                    }
                };
                for &i in command.resets() {
                    self.received[i] = generation;
                    changed = true;
                }
                if !self.apply(command) {
                    return;
                }
            }
            if changed {
                self.stalled = false;
                self.reset_what_changed();
            }
            if self.stalled {
                continue;
            }
            // A pass that panics (a bug) stops rendering, not the thread: the UI is told, and the next command
            // that restarts an image starts again.
            let step = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| self.step(&pool, &first_pool)));
            if let Err(payload) = step {
                self.stalled = true;
                self.report_failure(format!(
                    "rendering stopped: a pass panicked ({}); change a setting to try again",
                    panic_message(payload.as_ref())
                ));
            }
        }
    }

    /// One preview or pass: the lane or reference whose turn it is.
    fn step(&mut self, pool: &rayon::ThreadPool, first_pool: &rayon::ThreadPool) {
        #[cfg(test)]
        if std::mem::take(&mut self.panic_in_next_pass) {
            panic!("a fault injected by a test");
        }
        if let Some(i) = (0..self.lane_count()).find(|&i| !self.lanes[i].previewed && !self.lane_idle(i)) {
            self.preview(i, first_pool);
            return;
        }
        let lane = self.next_lane();
        let reference_turn = self.reference_pending() && (lane.is_none() || self.turn % 2 == 1);
        self.turn += 1;
        match lane {
            _ if reference_turn => self.reference_pass(if lane.is_none() { first_pool } else { pool }),
            Some(i) => self.pass(i, if self.lanes[i].passes == 0 { first_pool } else { pool }),
            None => {}
        }
    }

    /// Returns false on `Quit`.
    fn apply(&mut self, command: Command) -> bool {
        match command {
            Command::SetScene(scene) => {
                self.scene = scene;
                self.cones = None;
            }
            Command::SetSettings(s) => self.lanes[A].settings = s,
            Command::SetCompare(b) => {
                self.comparing = b.is_some();
                if let Some(s) = b {
                    self.lanes[B].settings = s;
                }
            }
            Command::SetBudget(b) => self.budget = b,
            Command::SetCamera(camera) => {
                Arc::make_mut(&mut self.scene).camera = camera;
                self.cones = None;
            }
            Command::SetMaterial { index, material } => {
                if let Some(m) = Arc::make_mut(&mut self.scene).materials.get_mut(index) {
                    *m = material;
                }
            }
            Command::SetPassSize(size) => self.pass_size = size,
            Command::SetTargetSpp(t) => {
                self.target = t;
                self.time_budget = None;
            }
            Command::Pause(p) => self.paused = p,
            Command::Restart => {}
            Command::ResetGuide => self.lanes.iter_mut().for_each(Lane::forget_guide),
            Command::SetReference { spp, cache } => {
                self.reference_spp = spp;
                self.reference_cache = cache;
                self.reference_file = None;
            }
            Command::LoadReference(path) => self.reference_file = Some(path),
            Command::Quit => return false,
            #[cfg(test)]
            Command::PanicInNextPass => self.panic_in_next_pass = true,
        }
        true
    }

    /// Resets every lane (and the reference) that a command received since the last pass changed.
    fn reset_what_changed(&mut self) {
        let camera = self.scene.camera;
        for i in [A, B] {
            let g = self.received[i];
            if g != self.lanes[i].generation {
                self.lanes[i].reset(&camera, g);
                self.time_budget = None;
            }
        }
        let g = self.received[R];
        if g != self.reference_generation || self.reference_footprint != self.lanes[A].settings.footprint {
            self.reference_generation = g;
            self.start_reference();
        }
    }

    /// Publishes a quick look at a new setting: one sample per pixel at half resolution (a quarter of a full
    /// pass), upsampled. It goes to a separate film: the accumulated image is not touched.
    fn preview(&mut self, i: usize, pool: &rayon::ThreadPool) {
        self.lanes[i].previewed = true;
        let camera = self.scene.camera;
        if camera.width * camera.height < 128 * 128 {
            return; // a full pass is quick enough
        }
        let small = Camera { width: camera.width.div_ceil(2), height: camera.height.div_ceil(2), ..camera };
        let lane = &self.lanes[i];
        let generation = lane.generation;
        let current = &self.shared.resets[i];
        let cancelled = move || current.load(Ordering::Relaxed) != generation;
        let mut renderer = Renderer::with_camera(self.scene.clone(), lane.settings, &small);
        if let Some(guide) = lane.kept_guide() {
            renderer = renderer.with_guide(guide);
        }
        let mut film = Film::new(small.width, small.height);
        let stats = pool.install(|| renderer.render_pass(&mut film, 0, 1, &cancelled));
        if cancelled() {
            return;
        }
        let means = film.means();
        let radiance = (0..camera.height)
            .flat_map(|y| (0..camera.width).map(move |x| (x / 2, y / 2)))
            .map(|(x, y)| means[(y * small.width + x) as usize])
            .collect();
        self.publish(Frame {
            lane: i,
            generation,
            width: camera.width,
            height: camera.height,
            radiance,
            std_error: Vec::new(),
            relative_variance: Vec::new(),
            largest_share: Vec::new(),
            spp: 0,
            passes: 0,
            elapsed: Duration::ZERO,
            stats,
            settings: lane.settings,
            scene_name: self.scene.name.clone(),
            camera,
            preview: true,
            guide: None,
        });
    }

    fn publish(&self, frame: Frame) {
        if let Ok(mut slot) = self.latest.frames[frame.lane].lock() {
            *slot = Some(Arc::new(frame));
        }
        (self.notify)();
    }

    fn pass(&mut self, i: usize, pool: &rayon::ThreadPool) {
        let equal_time = self.comparing && self.budget == Budget::EqualTime;
        let lane = &mut self.lanes[i];
        let count = self.pass_size.count(lane.passes, lane.spp, lane.elapsed);
        let count = match self.target {
            Some(t) if !equal_time => count.min(t.saturating_sub(lane.spp)).max(1),
            _ => count,
        };
        let generation = lane.generation;
        let current = &self.shared.resets[i];
        let cancelled = move || current.load(Ordering::Relaxed) != generation;
        let start = Instant::now();
        let mut renderer = lane.take_renderer(&self.scene, self.cones.as_ref());
        let stats = pool.install(|| renderer.render_pass(&mut lane.film, lane.spp, count, &cancelled));
        self.cones = Some(renderer.cones());
        let guide = renderer.training().map(|t| (t.status(), t.guide().clone()));
        lane.keep(renderer);
        if cancelled() {
            return; // partial: the pending command restarts this film
        }
        lane.elapsed += start.elapsed();
        lane.spp += count;
        lane.passes += 1;
        lane.stats += stats;
        if equal_time && self.time_budget.is_none() && self.target.is_some_and(|t| lane.spp >= t) {
            self.time_budget = Some(lane.stats.cpu);
        }
        let lane = &self.lanes[i];
        let pixels = &lane.film.pixels;
        let frame = Frame {
            lane: i,
            generation,
            width: lane.film.width,
            height: lane.film.height,
            radiance: lane.film.means(),
            std_error: pixels.iter().map(|p| p.std_error() as f32).collect(),
            relative_variance: pixels.iter().map(|p| p.relative_variance() as f32).collect(),
            largest_share: pixels.iter().map(|p| p.largest_share() as f32).collect(),
            spp: lane.spp,
            passes: lane.passes,
            elapsed: lane.elapsed,
            stats: lane.stats,
            settings: lane.settings,
            scene_name: self.scene.name.clone(),
            camera: self.scene.camera,
            preview: false,
            guide,
        };
        self.publish(frame);
    }
}
