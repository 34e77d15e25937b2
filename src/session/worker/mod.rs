//! The background integrator: a thread that owns the films and refines them pass after pass.
//!
//! It renders one image (lane A) or, in compare mode, two (lanes A and B: two estimators of the same scene and
//! camera, with the same per-pixel random streams), and optionally a reference in between. The UI sends
//! [`Command`]s over a channel and takes the newest [`Frame`] of each lane from latest-value slots: it never
//! waits for a pass and never receives stale frames. A command that changes what a lane converges to bumps that
//! lane's generation at once; the lane's pass in flight polls it row by row, so the new setting shows in the next
//! frame. The worker calls `notify` after every pass (the app binds it to `request_repaint`).
//!
//! Budgets in compare mode: **equal samples** runs the lane with fewer spp next, so both reach the same spp;
//! **equal time** runs the lane with less CPU time next (each row's thread CPU clock, summed), so both get the
//! same time within one pass and each shows its own spp. With a target spp, equal time stops each lane at the CPU
//! time the first one needed to reach the target.

mod command;
mod frame;
mod lane;
mod pass_size;
mod reference_job;

pub use command::{Budget, Command};
pub use frame::{Frame, ReferenceStatus};
pub use pass_size::PassSize;

use crate::render::{Film, Footprint, PixelCones, RenderSettings, Renderer};
use crate::scene::{Camera, Scene};
use lane::Lane;
use reference_job::ReferenceJob;
use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, Sender, TryRecvError, channel};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Lane indices.
pub const A: usize = 0;
pub const B: usize = 1;
/// The reference's index among the generation counters.
const R: usize = 2;

/// Handle to the integrator thread; dropping it stops the thread.
pub struct Worker {
    /// Commands with the generation they were sent at.
    commands: Sender<(u64, Command)>,
    latest: Arc<Slots>,
    shared: Arc<Shared>,
    thread: Option<JoinHandle<()>>,
}

/// Latest-value slots, one per lane, and the reference's.
#[derive(Default)]
struct Slots {
    frames: [Mutex<Option<Arc<Frame>>>; 2],
    reference: Mutex<Option<ReferenceStatus>>,
    /// What stopped the integrator (no thread, no pool, a pass that panicked), for the UI to show.
    failure: Mutex<Option<String>>,
}

/// Counters the UI bumps and passes poll.
#[derive(Default)]
struct Shared {
    /// Bumped by every command that restarts something.
    generation: AtomicU64,
    /// Per lane and reference: the generation of the last command that restarted it.
    resets: [AtomicU64; 3],
}

impl Worker {
    /// Starts rendering `scene` at once. `threads`: size of the pass's thread pool.
    pub fn spawn(
        scene: Arc<Scene>,
        settings: RenderSettings,
        threads: usize,
        notify: impl Fn() + Send + 'static,
    ) -> Self {
        let (commands, rx) = channel();
        let latest = Arc::new(Slots::default());
        let shared = Arc::new(Shared::default());
        let state = State::new(scene, settings, latest.clone(), shared.clone(), Box::new(notify));
        let thread =
            match std::thread::Builder::new().name("integrator".into()).spawn(move || state.run(rx, threads.max(1))) {
                Ok(thread) => Some(thread),
                Err(e) => {
                    if let Ok(mut slot) = latest.failure.lock() {
                        *slot = Some(format!("cannot start the integrator thread: {e}"));
                    }
                    None
                }
            };
        Self { commands, latest, shared, thread }
    }

    /// Why the integrator stopped, if it did since the last call: the UI shows it (rendering resumes, if it
    /// can, with the next command that restarts an image).
    pub fn take_failure(&self) -> Option<String> {
        self.latest.failure.lock().ok()?.take()
    }

    /// Sends a command; one that changes an image cancels that image's pass in flight first. The generation
    /// travels with the command, so the worker restarts an image only once the command that changed it arrived.
    pub fn send(&self, command: Command) {
        let resets = command.resets();
        let g = if resets.is_empty() {
            self.shared.generation.load(Ordering::SeqCst)
        } else {
            let g = self.shared.generation.fetch_add(1, Ordering::SeqCst) + 1;
            for &i in resets {
                self.shared.resets[i].store(g, Ordering::SeqCst);
            }
            g
        };
        let _ = self.commands.send((g, command));
    }

    /// Lane A's newest frame, if one was published since the last call.
    pub fn take_frame(&self) -> Option<Arc<Frame>> {
        self.take_lane(A)
    }

    /// The newest frame of `lane` ([`A`] or [`B`]), if one was published since the last call.
    pub fn take_lane(&self, lane: usize) -> Option<Arc<Frame>> {
        self.latest.frames[lane].lock().ok()?.take()
    }

    /// The reference's status, if it changed since the last call.
    pub fn take_reference(&self) -> Option<ReferenceStatus> {
        self.latest.reference.lock().ok()?.take()
    }

    /// The generation of the last command sent: a frame whose lane was restarted by it carries this generation
    /// or a later one.
    pub fn generation(&self) -> u64 {
        self.shared.generation.load(Ordering::SeqCst)
    }
}

impl Drop for Worker {
    fn drop(&mut self) {
        let g = self.shared.generation.fetch_add(1, Ordering::SeqCst) + 1;
        self.shared.resets.iter().for_each(|r| r.store(g, Ordering::SeqCst));
        let _ = self.commands.send((g, Command::Quit));
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// Everything the worker thread owns.
struct State {
    scene: Arc<Scene>,
    /// The pixel cones the lanes' passes found for this scene's geometry (and its camera, which each renderer
    /// checks), kept from pass to pass.
    cones: Option<Arc<PixelCones>>,
    lanes: [Lane; 2],
    comparing: bool,
    budget: Budget,
    /// Equal time with a target: the CPU time the first lane needed to reach it.
    time_budget: Option<Duration>,
    pass_size: PassSize,
    target: Option<u32>,
    paused: bool,
    /// What the reference should be: the spp to render and where to cache it, or a file.
    reference_spp: Option<u32>,
    reference_cache: Option<PathBuf>,
    reference_file: Option<PathBuf>,
    job: Option<ReferenceJob>,
    /// The reference's generation, to discard a pass cancelled by a scene change.
    reference_generation: u64,
    /// The footprint of the reference set up last: a lane with another restarts it.
    reference_footprint: Footprint,
    /// Passes run: the reference gets every other one while lanes are busy.
    turn: u64,
    /// Per lane and reference: the generation of the last command received that restarts it.
    received: [u64; 3],
    latest: Arc<Slots>,
    shared: Arc<Shared>,
    notify: Box<dyn Fn() + Send>,
    /// A pass panicked: nothing renders until a command restarts an image.
    stalled: bool,
    /// Tests: make the next pass panic.
    #[cfg(test)]
    panic_in_next_pass: bool,
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
    fn new(
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
    fn run(mut self, rx: Receiver<(u64, Command)>, threads: usize) {
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
#[cfg(test)]
mod tests;
