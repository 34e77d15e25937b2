//! The background integrator: a thread that owns the film and refines it pass after pass.
//!
//! The UI sends [`Command`]s over a channel and takes the newest [`Frame`] from a latest-value slot: it never
//! waits for a pass and never receives stale frames. A command that changes what is rendered bumps a generation
//! counter at once, which the pass in flight polls row by row, so the new setting shows in the next frame. The
//! worker calls `notify` after every pass (the app binds it to `request_repaint`).

use super::{Film, PassStats, RenderSettings, Renderer};
use crate::scene::{Camera, Material, Scene};
use glam::Vec3;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, Sender, TryRecvError, channel};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// What the UI can ask of the worker.
pub enum Command {
    /// Render another scene (its camera included).
    SetScene(Arc<Scene>),
    SetSettings(RenderSettings),
    SetCamera(Camera),
    SetMaterial {
        index: usize,
        material: Material,
    },
    /// Samples per pixel taken in one pass (how often a frame is published).
    SetSppPerPass(u32),
    /// Stop refining at this many samples per pixel (`None`: never).
    SetTargetSpp(Option<u32>),
    Pause(bool),
    /// Discard the film and start again.
    Restart,
    Quit,
}

impl Command {
    /// Whether the command changes what the film converges to (and so restarts accumulation).
    fn restarts(&self) -> bool {
        matches!(
            self,
            Command::SetScene(_)
                | Command::SetSettings(_)
                | Command::SetCamera(_)
                | Command::SetMaterial { .. }
                | Command::Restart
        )
    }
}

/// A snapshot of the film after a pass.
#[derive(Clone, Debug)]
pub struct Frame {
    /// Increases with every restart; frames of one generation refine the same image.
    pub generation: u64,
    pub width: u32,
    pub height: u32,
    /// Mean radiance per pixel (linear RGB), row 0 at the top.
    pub radiance: Vec<Vec3>,
    pub spp: u32,
    pub passes: u32,
    /// Rendering time since the restart (pauses excluded).
    pub elapsed: Duration,
    /// Totals since the restart.
    pub stats: PassStats,
    pub settings: RenderSettings,
    pub scene_name: String,
    pub camera: Camera,
    /// A half-resolution, one-sample preview published right after a restart, before the first full pass.
    pub preview: bool,
}

/// Handle to the integrator thread; dropping it stops the thread.
pub struct Worker {
    commands: Sender<Command>,
    latest: Arc<Mutex<Option<Arc<Frame>>>>,
    generation: Arc<AtomicU64>,
    thread: Option<JoinHandle<()>>,
}

impl Worker {
    /// Starts rendering `scene` at once. `threads`: size of the pass's thread pool (leave the UI a core).
    pub fn spawn(
        scene: Arc<Scene>,
        settings: RenderSettings,
        threads: usize,
        notify: impl Fn() + Send + 'static,
    ) -> Self {
        let (commands, rx) = channel();
        let latest = Arc::new(Mutex::new(None));
        let generation = Arc::new(AtomicU64::new(0));
        let state = State::new(scene, settings, latest.clone(), generation.clone(), Box::new(notify));
        let thread =
            std::thread::Builder::new().name("integrator".into()).spawn(move || state.run(rx, threads.max(1))).ok();
        Self { commands, latest, generation, thread }
    }

    /// Sends a command; one that changes the image cancels the pass in flight first.
    pub fn send(&self, command: Command) {
        if command.restarts() {
            self.generation.fetch_add(1, Ordering::SeqCst);
        }
        let _ = self.commands.send(command);
    }

    /// The newest frame, if one was published since the last call.
    pub fn take_frame(&self) -> Option<Arc<Frame>> {
        self.latest.lock().ok()?.take()
    }

    /// The current generation: frames of this generation or later show every command sent so far.
    pub fn generation(&self) -> u64 {
        self.generation.load(Ordering::SeqCst)
    }
}

impl Drop for Worker {
    fn drop(&mut self) {
        self.generation.fetch_add(1, Ordering::SeqCst);
        let _ = self.commands.send(Command::Quit);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// Everything the worker thread owns.
struct State {
    scene: Arc<Scene>,
    settings: RenderSettings,
    film: Film,
    spp: u32,
    passes: u32,
    stats: PassStats,
    elapsed: Duration,
    spp_per_pass: u32,
    target: Option<u32>,
    paused: bool,
    /// The generation this film belongs to.
    film_generation: u64,
    /// Whether the preview of this generation was published.
    previewed: bool,
    latest: Arc<Mutex<Option<Arc<Frame>>>>,
    generation: Arc<AtomicU64>,
    notify: Box<dyn Fn() + Send>,
}

impl State {
    fn new(
        scene: Arc<Scene>,
        settings: RenderSettings,
        latest: Arc<Mutex<Option<Arc<Frame>>>>,
        generation: Arc<AtomicU64>,
        notify: Box<dyn Fn() + Send>,
    ) -> Self {
        let film = Film::new(scene.camera.width, scene.camera.height);
        Self {
            scene,
            settings,
            film,
            spp: 0,
            passes: 0,
            stats: PassStats::default(),
            elapsed: Duration::ZERO,
            spp_per_pass: 1,
            target: None,
            paused: false,
            film_generation: 0,
            previewed: false,
            latest,
            generation,
            notify,
        }
    }

    fn idle(&self) -> bool {
        self.paused || self.target.is_some_and(|t| self.spp >= t)
    }

    /// `threads` run the passes; the first pass after a restart uses every core, so that a new setting shows as
    /// soon as possible (the UI is idle then).
    fn run(mut self, rx: Receiver<Command>, threads: usize) {
        let Ok(pool) = rayon::ThreadPoolBuilder::new().num_threads(threads).build() else { return };
        let all = std::thread::available_parallelism().map_or(threads, |n| n.get().max(threads));
        let Ok(first_pool) = rayon::ThreadPoolBuilder::new().num_threads(all).build() else { return };
        loop {
            // Apply every pending command; block only when there is nothing to render.
            let mut restart = false;
            loop {
                let command = if self.idle() && !restart {
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
                restart |= command.restarts();
                if !self.apply(command) {
                    return;
                }
            }
            if restart {
                self.restart();
            }
            if self.idle() {
                continue;
            }
            if !self.previewed {
                self.preview(&first_pool);
            }
            self.pass(if self.passes == 0 { &first_pool } else { &pool });
        }
    }

    /// Returns false on `Quit`.
    fn apply(&mut self, command: Command) -> bool {
        match command {
            Command::SetScene(scene) => self.scene = scene,
            Command::SetSettings(s) => self.settings = s,
            Command::SetCamera(camera) => Arc::make_mut(&mut self.scene).camera = camera,
            Command::SetMaterial { index, material } => {
                if let Some(m) = Arc::make_mut(&mut self.scene).materials.get_mut(index) {
                    *m = material;
                }
            }
            Command::SetSppPerPass(n) => self.spp_per_pass = n.max(1),
            Command::SetTargetSpp(t) => self.target = t,
            Command::Pause(p) => self.paused = p,
            Command::Restart => {}
            Command::Quit => return false,
        }
        true
    }

    fn restart(&mut self) {
        let (w, h) = (self.scene.camera.width, self.scene.camera.height);
        if (self.film.width, self.film.height) == (w, h) {
            self.film.clear();
        } else {
            self.film = Film::new(w, h);
        }
        self.spp = 0;
        self.passes = 0;
        self.stats = PassStats::default();
        self.elapsed = Duration::ZERO;
        self.film_generation = self.generation.load(Ordering::SeqCst);
        self.previewed = false;
    }

    /// Publishes a quick look at a new setting: one sample per pixel at half resolution (a quarter of a full
    /// pass), upsampled. It goes to a separate film: the accumulated image is not touched.
    fn preview(&mut self, pool: &rayon::ThreadPool) {
        self.previewed = true;
        let camera = self.scene.camera;
        if camera.width * camera.height < 128 * 128 {
            return; // a full pass is quick enough
        }
        let small = Camera { width: camera.width.div_ceil(2), height: camera.height.div_ceil(2), ..camera };
        let generation = self.film_generation;
        let current = &self.generation;
        let cancelled = move || current.load(Ordering::Relaxed) != generation;
        let renderer = Renderer::with_camera(&self.scene, self.settings, &small);
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
            generation,
            width: camera.width,
            height: camera.height,
            radiance,
            spp: 0,
            passes: 0,
            elapsed: Duration::ZERO,
            stats,
            settings: self.settings,
            scene_name: self.scene.name.clone(),
            camera,
            preview: true,
        });
    }

    fn publish(&self, frame: Frame) {
        if let Ok(mut slot) = self.latest.lock() {
            *slot = Some(Arc::new(frame));
        }
        (self.notify)();
    }

    fn pass(&mut self, pool: &rayon::ThreadPool) {
        let count = match self.target {
            Some(t) => self.spp_per_pass.min(t - self.spp),
            None => self.spp_per_pass,
        };
        let generation = self.film_generation;
        let current = &self.generation;
        let cancelled = move || current.load(Ordering::Relaxed) != generation;
        let start = Instant::now();
        let renderer = Renderer::new(&self.scene, self.settings);
        let stats = pool.install(|| renderer.render_pass(&mut self.film, self.spp, count, &cancelled));
        if cancelled() {
            return; // partial: the pending command restarts the film
        }
        self.elapsed += start.elapsed();
        self.spp += count;
        self.passes += 1;
        self.stats += stats;
        let frame = Frame {
            generation,
            width: self.film.width,
            height: self.film.height,
            radiance: self.film.means(),
            spp: self.spp,
            passes: self.passes,
            elapsed: self.elapsed,
            stats: self.stats,
            settings: self.settings,
            scene_name: self.scene.name.clone(),
            camera: self.scene.camera,
            preview: false,
        };
        self.publish(frame);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::Strategy;
    use crate::scene::load_scene;

    fn wait_for(worker: &Worker, pred: impl Fn(&Frame) -> bool) -> Arc<Frame> {
        let start = Instant::now();
        loop {
            if let Some(f) = worker.take_frame()
                && pred(&f)
            {
                return f;
            }
            assert!(start.elapsed() < Duration::from_secs(30), "no matching frame");
            std::thread::sleep(Duration::from_millis(2));
        }
    }

    fn small_scene() -> Arc<Scene> {
        let mut scene = load_scene("cornell-box").expect("bundled");
        scene.camera.width = 32;
        scene.camera.height = 32;
        Arc::new(scene)
    }

    #[test]
    fn refines_then_restarts_on_a_new_strategy() {
        let worker = Worker::spawn(small_scene(), RenderSettings::default(), 1, || {});
        let f = wait_for(&worker, |f| f.spp >= 3);
        assert_eq!(f.settings.strategy, Strategy::Emitter);
        worker.send(Command::SetSettings(RenderSettings { strategy: Strategy::Cosine, ..RenderSettings::default() }));
        let g = wait_for(&worker, |g| g.settings.strategy == Strategy::Cosine);
        assert!(g.generation > f.generation);
        // Restarted: the film holds exactly samples 0..spp of the new strategy, however many passes ran.
        let mut film = Film::new(32, 32);
        Renderer::new(&small_scene(), g.settings).render_pass(&mut film, 0, g.spp, &|| false);
        assert_eq!(g.radiance, film.means(), "accumulation restarted");
    }

    #[test]
    fn stops_at_the_target_and_is_the_same_image_as_a_batch_render() {
        let scene = small_scene();
        let worker = Worker::spawn(scene.clone(), RenderSettings::default(), 1, || {});
        worker.send(Command::SetTargetSpp(Some(5)));
        worker.send(Command::SetSppPerPass(2));
        let f = wait_for(&worker, |f| f.spp == 5);
        std::thread::sleep(Duration::from_millis(50));
        assert!(worker.take_frame().is_none(), "idle at the target");
        // The progressive film equals a one-shot render of the same samples.
        let mut film = Film::new(32, 32);
        Renderer::new(&scene, RenderSettings::default()).render_pass(&mut film, 0, 5, &|| false);
        assert_eq!(f.radiance, film.means());
    }
}
