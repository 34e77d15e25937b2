//! [`Session`]: everything a live session is, without a UI. It owns the worker, the scene, lane A's and lane B's
//! settings, the reference, the probe and the convergence history, and every setter sends what it changed to the
//! worker, so no caller can change a setting and forget to render it. The viewer ([`crate::app`]) is a shell over
//! it; a tour step ([`crate::tour`]) is a function that sets one; tests drive it without egui.

mod history;
mod probing;

pub use history::series_label;
pub use probing::ProbeOptions;

use super::probe::{ProbeRequest, ProbeView, ProbeWorker};
use super::views::View;
use super::worker::{A, B, Budget, Command, Frame, PassSize, ReferenceStatus, Worker};
use crate::measure::{Reference, Series};
use crate::render::{Footprint, RenderSettings, Strategy};
use crate::scene::{Camera, Material, Scene};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// What [`Session::poll`] found.
#[derive(Debug, Default)]
pub struct Update {
    /// A lane shows a new image (a restart's first frame, or the reference changed the error maps).
    pub restarted: bool,
    /// A lane refined the image it shows.
    pub refined: bool,
    /// The probe answered.
    pub probed: bool,
    /// Why the integrator stopped, if it did.
    pub failure: Option<String>,
    /// Time from the last restart request to its first frame, when that frame arrived now, and its size.
    pub restart_latency: Option<(Duration, u32, u32)>,
}

/// A live session: one image (or two, compare mode), a reference, a probe, and their history.
pub struct Session {
    worker: Worker,
    scene: Arc<Scene>,
    /// What the scene was opened from (a bundled scene's name or a path): a tour step naming it again keeps it.
    source: String,
    /// The scene file's camera ([`Session::reset_camera`] returns to it) and materials.
    home_camera: Camera,
    home_materials: Vec<Material>,
    settings: RenderSettings,
    settings_b: RenderSettings,
    comparing: bool,
    budget: Budget,
    pass_size: PassSize,
    target_spp: Option<u32>,
    paused: bool,
    exposure: f32,
    view: View,
    reference: ReferenceStatus,
    reference_spp: u32,
    reference_cache: Option<PathBuf>,
    /// Compare mode asks for a reference (for its error maps and plot); off for `illumlab tour`.
    reference_for_compare: bool,
    /// Convergence runs against the current reference, one per estimator, in the order first seen.
    history: Vec<Series>,
    frames: [Option<Arc<Frame>>; 2],
    /// Per lane: the generation of the last command that restarted it (its frames before are stale).
    restarted_at: [u64; 2],
    /// When the last restart was requested, until its first frame.
    restart_sent: Option<Instant>,
    restart_latency: Option<Duration>,
    /// Until a restart's first frame, the worker's notices ask for a repaint at once.
    awaiting_frame: Arc<AtomicBool>,
    probe_worker: ProbeWorker,
    /// The probed pixel and the camera it was picked with.
    probe_pixel: Option<((u32, u32), Camera)>,
    probe: ProbeOptions,
    probe_view: Option<ProbeView>,
    last_request: Option<ProbeRequest>,
}

/// Called by the worker and the probe when they have news; `true` asks for it at once (a restart's first frame,
/// a probe answer), `false` whenever convenient (a refinement).
pub type Notify = Arc<dyn Fn(bool) + Send + Sync>;

impl Session {
    /// A session rendering `scene` (opened from `source`) at once on `threads` threads.
    pub fn new(scene: Arc<Scene>, source: impl Into<String>, threads: usize, notify: Notify) -> Self {
        let awaiting_frame = Arc::new(AtomicBool::new(true));
        let settings = RenderSettings::default();
        let worker = {
            let (awaiting, notify) = (awaiting_frame.clone(), notify.clone());
            Worker::spawn(scene.clone(), settings, threads, move || notify(awaiting.load(Ordering::Relaxed)))
        };
        let probe_worker = ProbeWorker::spawn(move || notify(true));
        let mut session = Self {
            worker,
            home_camera: scene.camera,
            home_materials: scene.materials.clone(),
            scene,
            source: source.into(),
            settings,
            settings_b: RenderSettings { strategy: Strategy::Cosine, ..settings },
            comparing: false,
            budget: Budget::EqualSamples,
            pass_size: PassSize::Auto,
            target_spp: None,
            paused: false,
            exposure: 0.0,
            view: View::Image,
            reference: ReferenceStatus::Off,
            reference_spp: 1024,
            reference_cache: crate::measure::default_cache_folder(),
            reference_for_compare: true,
            history: Vec::new(),
            frames: [None, None],
            restarted_at: [0; 2],
            restart_sent: None,
            restart_latency: None,
            awaiting_frame,
            probe_worker,
            probe_pixel: None,
            probe: ProbeOptions::default(),
            probe_view: None,
            last_request: None,
        };
        session.note_restart(&[A, B]);
        session
    }

    /// A session without a UI to wake (tests, `illumlab tour`).
    pub fn headless(scene: Arc<Scene>, source: impl Into<String>, threads: usize) -> Self {
        Self::new(scene, source, threads, Arc::new(|_| {}))
    }

    // ----- what it shows -----

    pub fn scene(&self) -> &Arc<Scene> {
        &self.scene
    }
    /// What the scene was opened from: a bundled scene's name or a path.
    pub fn source(&self) -> &str {
        &self.source
    }
    pub fn camera(&self) -> Camera {
        self.scene.camera
    }
    pub fn home_camera(&self) -> Camera {
        self.home_camera
    }
    /// The materials as the scene file has them.
    pub fn home_materials(&self) -> &[Material] {
        &self.home_materials
    }
    /// Lane A's settings.
    pub fn settings(&self) -> RenderSettings {
        self.settings
    }
    /// Lane B's settings (rendered in compare mode).
    pub fn settings_b(&self) -> RenderSettings {
        self.settings_b
    }
    pub fn is_comparing(&self) -> bool {
        self.comparing
    }
    pub fn budget(&self) -> Budget {
        self.budget
    }
    pub fn pass_size(&self) -> PassSize {
        self.pass_size
    }
    pub fn target_spp(&self) -> Option<u32> {
        self.target_spp
    }
    pub fn is_paused(&self) -> bool {
        self.paused
    }
    /// Exposure in stops.
    pub fn exposure(&self) -> f32 {
        self.exposure
    }
    pub fn view(&self) -> View {
        self.view
    }
    /// Lane A's newest frame.
    pub fn frame(&self) -> Option<&Arc<Frame>> {
        self.frames[A].as_ref()
    }
    /// Lane B's newest frame, in compare mode.
    pub fn frame_b(&self) -> Option<&Arc<Frame>> {
        self.frames[B].as_ref().filter(|_| self.comparing)
    }
    pub fn reference_status(&self) -> &ReferenceStatus {
        &self.reference
    }
    /// The reference, once ready.
    pub fn reference(&self) -> Option<&Arc<Reference>> {
        match &self.reference {
            ReferenceStatus::Ready { reference, .. } => Some(reference),
            _ => None,
        }
    }
    /// How the reference is rendered: its estimator, footprint and seed.
    pub fn reference_description(&self) -> String {
        let r = crate::measure::reference_settings(self.settings.footprint);
        format!("{} ({}), {} footprint, its own seed {}", r.strategy.name(), r.mis.label(), r.footprint.name(), r.seed)
    }
    pub fn reference_spp(&self) -> u32 {
        self.reference_spp
    }
    /// The convergence runs recorded against the current reference.
    pub fn history(&self) -> &[Series] {
        &self.history
    }
    /// Time from the last restart request to its first frame.
    pub fn restart_latency(&self) -> Option<Duration> {
        self.restart_latency
    }
    /// Both lanes shown (A, and B in compare mode) have frames of their current settings, past the preview, and
    /// are done with `spp` samples per pixel: at `spp`, or under equal time in compare mode, at the CPU time the
    /// first lane to reach `spp` needed (where the worker stops them).
    pub fn reached(&self, spp: u32) -> bool {
        let current = |l: usize| self.frames[l].as_ref().filter(|f| f.generation >= self.restarted_at[l] && !f.preview);
        if !self.comparing {
            return current(A).is_some_and(|f| f.spp >= spp);
        }
        let (Some(a), Some(b)) = (current(A), current(B)) else { return false };
        match self.budget {
            Budget::EqualSamples => a.spp >= spp && b.spp >= spp,
            Budget::EqualTime => {
                let done =
                    |f: &Frame, other: &Frame| f.spp >= spp || (other.spp >= spp && f.stats.cpu >= other.stats.cpu);
                done(a, b) && done(b, a)
            }
        }
    }

    // ----- what it does -----

    /// Takes the newest frames, reference and probe answer; records convergence; sends a probe request if what the
    /// probe depends on changed. Call it once per UI frame (or in a loop, headless).
    pub fn poll(&mut self) -> Update {
        let mut update = Update { failure: self.worker.take_failure(), ..Default::default() };
        if let Some(status) = self.worker.take_reference() {
            // Progress reports of the same render change neither the runs nor the maps.
            let progress = matches!(
                (&self.reference, &status),
                (ReferenceStatus::Rendering { .. }, ReferenceStatus::Rendering { .. })
            );
            if !progress {
                self.history.clear();
                update.restarted = true;
            }
            self.reference = status;
        }
        for lane in [A, B] {
            let Some(frame) = self.worker.take_lane(lane) else { continue };
            if lane == B && !self.comparing {
                continue; // a frame from before compare mode was left
            }
            if let Some(sent) = self.restart_sent
                && frame.generation >= self.restarted_at[lane]
            {
                self.restart_latency = Some(sent.elapsed());
                self.restart_sent = None;
                update.restart_latency = Some((sent.elapsed(), frame.width, frame.height));
            }
            if self.restart_sent.is_none() {
                self.awaiting_frame.store(false, Ordering::Relaxed);
            }
            self.record(&frame);
            let shown = &mut self.frames[lane];
            // A refinement of the image on screen may wait for the next upload; anything else shows at once.
            if shown.as_ref().is_some_and(|f| f.generation == frame.generation && !f.preview) {
                update.refined = true;
            } else {
                update.restarted = true;
            }
            *shown = Some(frame);
        }
        // An answer that arrives after the probe was closed (or the scene changed) is dropped.
        if let Some(view) = self.probe_worker.take()
            && self.probe_pixel.is_some()
        {
            self.probe_view = Some(view);
            update.probed = true;
        }
        self.request_probe();
        update
    }

    /// Sends a command; one that restarts lanes marks their frames stale until the new ones arrive.
    fn send(&mut self, command: Command) {
        let lanes: Vec<usize> = command.resets().iter().copied().filter(|&i| i == A || i == B).collect();
        self.worker.send(command);
        if !lanes.is_empty() {
            self.note_restart(&lanes);
        }
    }

    fn note_restart(&mut self, lanes: &[usize]) {
        let g = self.worker.generation();
        for &l in lanes {
            self.restarted_at[l] = g;
        }
        self.restart_sent = Some(Instant::now());
        self.awaiting_frame.store(true, Ordering::Relaxed);
    }

    /// Names what the scene was opened from (a bundled scene's name or a path).
    pub fn set_source(&mut self, source: impl Into<String>) {
        self.source = source.into();
    }

    /// Opens another scene (already loaded) from `source`; its camera becomes the home camera. The probe point and
    /// the convergence runs belong to the old scene and go; the worker restarts both lanes and the reference.
    pub fn set_scene(&mut self, scene: Scene, source: impl Into<String>) {
        self.set_probe_pixel(None);
        self.history.clear();
        self.home_camera = scene.camera;
        self.home_materials = scene.materials.clone();
        self.scene = Arc::new(scene);
        self.source = source.into();
        self.send(Command::SetScene(self.scene.clone()));
    }

    /// Lane A's settings; B follows A's light selection, MIS settings, seed, footprint and guiding (B keeps its
    /// own strategy).
    pub fn set_settings(&mut self, settings: RenderSettings) {
        if settings != self.settings {
            self.settings = settings;
            self.send(Command::SetSettings(settings));
        }
        let b = RenderSettings { strategy: self.settings_b.strategy, ..self.settings };
        if b != self.settings_b {
            self.settings_b = b;
            self.send_compare();
        }
    }

    pub fn set_strategy(&mut self, strategy: Strategy) {
        self.set_settings(RenderSettings { strategy, ..self.settings });
    }

    /// Where camera rays go in their pixels, for A and B and the reference (which restarts with it).
    pub fn set_footprint(&mut self, footprint: Footprint) {
        self.set_settings(RenderSettings { footprint, ..self.settings });
    }

    pub fn set_strategy_b(&mut self, strategy: Strategy) {
        if self.settings_b.strategy != strategy {
            self.settings_b.strategy = strategy;
            self.send_compare();
        }
    }

    /// Enters or leaves compare mode; entering asks for a reference if there is none.
    pub fn set_comparing(&mut self, on: bool) {
        if self.comparing == on {
            return;
        }
        self.comparing = on;
        self.frames[B] = None;
        self.send_compare();
        if on && self.reference_for_compare {
            self.ensure_reference();
        }
    }

    /// Compare mode with B = `strategy` (one restart).
    pub fn compare_with(&mut self, strategy: Strategy) {
        if self.comparing {
            self.set_strategy_b(strategy);
        } else {
            self.settings_b.strategy = strategy;
            self.set_comparing(true);
        }
    }

    /// Whether entering compare mode asks for a reference (a view that needs one always does).
    pub fn set_reference_for_compare(&mut self, on: bool) {
        self.reference_for_compare = on;
    }

    /// Swaps the estimators of A and B (both restart; with common random numbers they reconverge identically).
    pub fn swap_lanes(&mut self) {
        std::mem::swap(&mut self.settings.strategy, &mut self.settings_b.strategy);
        self.send(Command::SetSettings(self.settings));
        self.send_compare();
    }

    fn send_compare(&mut self) {
        let b = self.comparing.then_some(self.settings_b);
        self.send(Command::SetCompare(b));
    }

    pub fn set_budget(&mut self, budget: Budget) {
        if self.budget != budget {
            self.budget = budget;
            self.send(Command::SetBudget(budget));
        }
    }

    /// The image or an error map; one that needs a reference asks for it.
    pub fn set_view(&mut self, view: View) {
        self.view = view;
        if view.needs_reference() {
            self.ensure_reference();
        }
    }

    pub fn set_exposure(&mut self, stops: f32) {
        if stops.is_finite() {
            self.exposure = stops.clamp(-20.0, 20.0);
        }
    }

    pub fn set_camera(&mut self, camera: Camera) {
        if camera.validate().is_ok() && camera != self.scene.camera {
            Arc::make_mut(&mut self.scene).camera = camera;
            self.send(Command::SetCamera(camera));
        }
    }

    /// Back to the scene file's camera, at the current image size.
    pub fn reset_camera(&mut self) {
        let c = self.scene.camera;
        self.set_camera(Camera { width: c.width, height: c.height, ..self.home_camera });
    }

    /// The image size: `long_side` pixels on the longer side, the scene file's aspect.
    pub fn set_resolution(&mut self, long_side: u32) {
        self.set_camera(self.scene.camera.with_long_side(&self.home_camera, long_side));
    }

    /// Material `index` of the scene (only a change copies the scene, which the worker and the probe share).
    pub fn set_material(&mut self, index: usize, material: Material) {
        if self.scene.materials.get(index).is_some_and(|m| *m != material)
            && let Some(m) = Arc::make_mut(&mut self.scene).materials.get_mut(index)
        {
            *m = material;
            self.send(Command::SetMaterial { index, material });
        }
    }

    /// Samples per pixel per pass, and where refining stops.
    pub fn set_sampling(&mut self, pass_size: PassSize, target_spp: Option<u32>) {
        self.pass_size = pass_size;
        self.target_spp = target_spp.map(|t| t.max(1));
        self.worker.send(Command::SetPassSize(pass_size));
        self.worker.send(Command::SetTargetSpp(self.target_spp));
    }

    pub fn set_paused(&mut self, paused: bool) {
        self.paused = paused;
        self.worker.send(Command::Pause(paused));
    }

    /// Discards the films and starts again (the reference stays).
    pub fn restart(&mut self) {
        self.send(Command::Restart);
    }

    /// Forgets what `guided` learned and learns again from the first sample.
    pub fn reset_guide(&mut self) {
        self.send(Command::ResetGuide);
    }

    /// Samples per pixel of the next reference rendered.
    pub fn set_reference_spp(&mut self, spp: u32) {
        self.reference_spp = spp.max(1);
    }

    /// Where reference renders are cached (`None`: not cached).
    pub fn set_reference_cache(&mut self, folder: Option<PathBuf>) {
        self.reference_cache = folder;
    }

    /// Asks for a reference (rendered, or from the cache) unless one is ready or on its way.
    pub fn ensure_reference(&mut self) {
        if matches!(self.reference, ReferenceStatus::Off | ReferenceStatus::Failed(_)) {
            self.compute_reference();
        }
    }

    pub fn compute_reference(&mut self) {
        self.send(Command::SetReference { spp: Some(self.reference_spp), cache: self.reference_cache.clone() });
        self.reference = ReferenceStatus::Rendering { spp: 0, target: self.reference_spp, elapsed: Duration::ZERO };
    }

    /// Uses the reference in this EXR file.
    pub fn load_reference(&mut self, path: PathBuf) {
        self.send(Command::LoadReference(path));
    }

    pub fn clear_history(&mut self) {
        self.history.clear();
    }
}
