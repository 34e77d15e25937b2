//! The viewer's state and its frame: take the newest frame from the worker, draw the panels, send what changed.

use super::loader::Loading;
use super::orbit;
use crate::measure::{ColorScale, Series, default_cache_folder};
use crate::render::{Footprint, RenderSettings, Strategy};
use crate::scene::{Camera, Material, Scene};
use crate::session::snapshot::write_snapshot;
use crate::session::views::View;
use crate::session::worker::{Budget, Command, Frame, PassSize, ReferenceStatus, Worker};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Everything the UI shows and edits. The film itself lives in the worker.
pub struct Viewer {
    pub(super) worker: Worker,
    /// Where the worker's `notify` sends repaint requests, once a context is known.
    repaint: Arc<Mutex<Option<egui::Context>>>,
    /// The UI's copy of the scene: names, materials, and geometry for picking under the cursor.
    pub(super) scene: Arc<Scene>,
    /// The scene file's camera: double-click returns to it.
    pub(super) home_camera: Camera,
    pub(super) camera: Camera,
    pub(super) settings: RenderSettings,
    /// Passes sized by time ([`PassSize::Auto`]), or `spp_per_pass` each.
    pub(super) auto_pass: bool,
    pub(super) spp_per_pass: u32,
    pub(super) target_spp: Option<u32>,
    pub(super) paused: bool,
    pub(super) exposure: f32,
    pub(super) one_to_one: bool,
    pub(super) selected_material: usize,
    pub(super) frame: Option<Arc<Frame>>,
    /// Compare mode: lane B renders `settings_b` beside A.
    pub(super) comparing: bool,
    pub(super) settings_b: RenderSettings,
    pub(super) frame_b: Option<Arc<Frame>>,
    pub(super) budget: Budget,
    pub(super) side_by_side: bool,
    /// Where the split is, as a fraction of the image width (A left, B right).
    pub(super) wipe: f32,
    pub(super) view: View,
    /// The scale of the error maps on display, and why the chosen map cannot be shown (if so).
    pub(super) scale: Option<ColorScale>,
    pub(super) view_note: Option<&'static str>,
    pub(super) reference: ReferenceStatus,
    pub(super) reference_spp: u32,
    pub(super) reference_path: String,
    pub(super) reference_cache: Option<PathBuf>,
    /// Convergence runs against the current reference, one per estimator, in the order first seen.
    pub(super) history: Vec<Series>,
    pub(super) show_plot: bool,
    /// The plot shows relative RMSE instead of RMSE.
    pub(super) plot_relative: bool,
    /// Where the image (A's, in compare mode) was last drawn, in points.
    pub(super) image_rect: Option<egui::Rect>,
    /// Textures of lanes A and B.
    pub(super) textures: [Option<egui::TextureHandle>; 2],
    /// The textures must be refilled (a restarted image, view or exposure).
    pub(super) texture_stale: bool,
    /// A refined frame of the image shown waits for its upload ([`super::frames::UPLOAD_INTERVAL`]).
    pub(super) refined: bool,
    /// Set from a restart to its first frame: the worker's notices repaint at once meanwhile.
    pub(super) awaiting_frame: Arc<AtomicBool>,
    pub(super) last_upload: Option<Instant>,
    pub(super) loading: Option<Loading>,
    pub(super) error: Option<String>,
    pub(super) message: Option<String>,
    pub(super) open_path: String,
    pub(super) export_folder: String,
    pub(super) show_help: bool,
    pub(super) hide_panels: bool,
    /// When the last restart was requested, and the generation that answers it.
    pub(super) restart_sent: Option<(Instant, u64)>,
    /// Time from the last restart request to its first frame on screen.
    pub(super) restart_latency: Option<Duration>,
    /// Recent UI frame times (for the status bar).
    pub(super) ui_frame_times: Vec<Duration>,
    /// `ILLUMLAB_TRACE` set: print latencies and frame times on stderr (for scripts/measure-viewer.sh).
    pub(super) trace: bool,
    /// Start of the previous UI frame and the recent intervals between frames (painting included).
    last_ui_start: Option<Instant>,
    ui_intervals: Vec<Duration>,
    /// The probe panel and its thread.
    pub(super) probe: super::probe::ProbeUi,
    /// A native file dialog while it is open.
    pub(super) dialog: Option<super::files::Dialog>,
    /// Scene files opened before, newest first.
    pub(super) recent: super::files::RecentFiles,
}

impl Viewer {
    /// The viewer on `scene`, its passes on every core.
    pub fn with_scene(scene: Arc<Scene>) -> Self {
        Self::with_threads(scene, None)
    }

    /// The viewer with `threads` rendering passes (`None`: every core). Measured on two cores under Xvfb
    /// (docs/performance-history.md): with both rendering, the viewer refines 1.7× as fast as with one, at the same
    /// toggle latency; the UI stays responsive because refined frames are repainted only every 250 ms.
    pub fn with_threads(scene: Arc<Scene>, threads: Option<usize>) -> Self {
        let repaint: Arc<Mutex<Option<egui::Context>>> = Arc::new(Mutex::new(None));
        // Until the first frame of a new setting arrives the worker's news repaints at once; refinements after it
        // wait for the next upload.
        let awaiting_frame = Arc::new(AtomicBool::new(true));
        let notify = super::frames::frame_notifier(&repaint, awaiting_frame.clone());
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        let threads = threads.unwrap_or(cores).max(1);
        let settings = RenderSettings::default();
        let worker = Worker::spawn(scene.clone(), settings, threads, notify);
        let probe = super::probe::ProbeUi::new(super::frames::notifier(&repaint));
        let camera = scene.camera;
        let mut viewer = Self {
            worker,
            repaint,
            home_camera: camera,
            camera,
            scene,
            settings,
            auto_pass: true,
            spp_per_pass: 8,
            target_spp: None,
            paused: false,
            exposure: 0.0,
            one_to_one: false,
            selected_material: 0,
            frame: None,
            comparing: false,
            settings_b: RenderSettings { strategy: Strategy::Cosine, ..settings },
            frame_b: None,
            budget: Budget::EqualSamples,
            side_by_side: false,
            wipe: 0.5,
            view: View::Image,
            scale: None,
            view_note: None,
            reference: ReferenceStatus::Off,
            reference_spp: 1024,
            reference_path: String::new(),
            reference_cache: default_cache_folder(),
            history: Vec::new(),
            show_plot: false,
            plot_relative: true,
            image_rect: None,
            textures: [None, None],
            texture_stale: false,
            refined: false,
            awaiting_frame,
            last_upload: None,
            loading: None,
            error: None,
            message: None,
            open_path: String::new(),
            export_folder: "screenshots".into(),
            show_help: false,
            hide_panels: false,
            restart_sent: None,
            restart_latency: None,
            ui_frame_times: Vec::new(),
            trace: std::env::var_os("ILLUMLAB_TRACE").is_some(),
            last_ui_start: None,
            ui_intervals: Vec::new(),
            probe,
            dialog: None,
            recent: super::files::RecentFiles::default(),
        };
        viewer.note_restart();
        viewer
    }

    /// Sets strategy, light selection, seed, target and exposure (as the `view` command line does).
    pub fn configure(&mut self, settings: RenderSettings, target_spp: Option<u32>, exposure: f32) {
        self.settings = settings;
        self.settings_b = RenderSettings { strategy: self.settings_b.strategy, ..settings };
        self.target_spp = target_spp;
        self.set_exposure(exposure);
        self.send_restarting(Command::SetSettings(settings));
        self.send_spp();
    }

    /// The newest frame shown.
    pub fn frame(&self) -> Option<&Frame> {
        self.frame.as_deref()
    }

    /// The scene the UI is showing (the last one that loaded successfully).
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The error on display, if any.
    pub fn error(&self) -> Option<&str> {
        self.error.as_deref()
    }

    /// Where screenshots go.
    pub fn set_export_folder(&mut self, folder: impl Into<String>) {
        self.export_folder = folder.into();
    }

    /// True while a scene is loading in the background.
    pub fn is_loading(&self) -> bool {
        self.loading.is_some()
    }

    /// Lets the worker wake this context when a frame is ready.
    pub fn bind_repaint(&self, ctx: egui::Context) {
        if let Ok(mut slot) = self.repaint.lock() {
            *slot = Some(ctx);
        }
    }

    /// The whole UI for one frame (eframe's `App::ui` calls this; tests drive it through egui_kittest).
    pub fn ui(&mut self, ui: &mut egui::Ui) {
        let start = Instant::now();
        if let Some(last) = self.last_ui_start.replace(start) {
            self.ui_intervals.push(start - last);
        }
        if self.repaint.lock().is_ok_and(|c| c.is_none()) {
            self.bind_repaint(ui.ctx().clone());
        }
        self.take_dropped_files(ui.ctx());
        self.poll_loading();
        self.take_frames();
        self.poll_probe(ui.ctx());
        super::shortcuts::handle(self, ui);
        if !self.hide_panels {
            egui::Panel::bottom("status").show(ui, |ui| super::status::status_ui(self, ui));
            egui::Panel::left("controls").resizable(true).default_size(300.0).show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| super::controls::controls_ui(self, ui));
            });
        }
        egui::CentralPanel::default().show(ui, |ui| super::viewport::viewport_ui(self, ui));
        super::shortcuts::help_window(self, ui);
        super::convergence::convergence_window(self, ui);
        super::probe::probe_window(self, ui);
        if ui.ctx().input(|i| !i.raw.hovered_files.is_empty()) {
            egui::Area::new(egui::Id::unique("drop-hint")).anchor(egui::Align2::CENTER_CENTER, [0.0, 0.0]).show(
                ui.ctx(),
                |ui| {
                    egui::Frame::popup(ui.style())
                        .show(ui, |ui| ui.heading("Drop to open: a scene (.toml, .obj) or a reference (.exr)"))
                },
            );
        }
        if self.loading.is_some() || self.frame.is_none() {
            ui.ctx().request_repaint_after(Duration::from_millis(30));
        }
        self.ui_frame_times.push(start.elapsed());
        if self.ui_frame_times.len() >= 120 {
            if self.trace {
                let mut t = self.ui_frame_times.clone();
                t.sort();
                let ms = |d: Duration| d.as_secs_f64() * 1e3;
                eprintln!("trace: ui-frame median {:.2} ms, max {:.2} ms", ms(t[t.len() / 2]), ms(t[t.len() - 1]));
                let mut i = std::mem::take(&mut self.ui_intervals);
                i.sort();
                if !i.is_empty() {
                    eprintln!("trace: frame-interval median {:.2} ms, min {:.2} ms", ms(i[i.len() / 2]), ms(i[0]));
                }
            }
            self.ui_frame_times.clear();
        }
    }

    pub(super) fn set_exposure(&mut self, stops: f32) {
        self.exposure = stops.clamp(-20.0, 20.0);
        self.texture_stale = true;
    }

    /// Sends a command that restarts accumulation and starts timing its first frame.
    pub(super) fn send_restarting(&mut self, command: Command) {
        self.worker.send(command);
        self.note_restart();
    }

    fn note_restart(&mut self) {
        self.restart_sent = Some((Instant::now(), self.worker.generation()));
        self.awaiting_frame.store(true, Ordering::Relaxed);
    }

    /// Forgets what `guided` learned and learns again from the first sample.
    pub(super) fn reset_guide(&mut self) {
        self.send_restarting(Command::ResetGuide);
    }

    pub(super) fn set_strategy(&mut self, strategy: Strategy) {
        if self.settings.strategy != strategy {
            self.settings.strategy = strategy;
            self.send_restarting(Command::SetSettings(self.settings));
        }
    }

    /// Where camera rays go in their pixels, for A and B and the reference (which restarts with it).
    pub(super) fn set_footprint(&mut self, footprint: Footprint) {
        if self.settings.footprint != footprint {
            self.settings.footprint = footprint;
            self.apply_settings();
        }
    }

    /// Sends A's settings; B follows A's light selection, MIS settings, seed and footprint (its own strategy).
    pub(super) fn apply_settings(&mut self) {
        self.send_restarting(Command::SetSettings(self.settings));
        let b = RenderSettings { strategy: self.settings_b.strategy, ..self.settings };
        if b != self.settings_b {
            self.settings_b = b;
            self.send_compare();
        }
    }

    pub(super) fn set_camera(&mut self, camera: Camera) {
        if camera.validate().is_ok() && camera != self.camera {
            self.camera = camera;
            Arc::make_mut(&mut self.scene).camera = camera;
            self.send_restarting(Command::SetCamera(camera));
        }
    }

    pub(super) fn reset_camera(&mut self) {
        let home = Camera { width: self.camera.width, height: self.camera.height, ..self.home_camera };
        self.set_camera(home);
    }

    pub(super) fn set_resolution(&mut self, long_side: u32) {
        let c = orbit::with_long_side(&self.camera, &self.home_camera, long_side);
        self.set_camera(c);
    }

    pub(super) fn set_material(&mut self, index: usize, material: Material) {
        // Only a change copies the scene (which the worker and the probe share).
        if self.scene.materials.get(index).is_some_and(|m| *m != material)
            && let Some(m) = Arc::make_mut(&mut self.scene).materials.get_mut(index)
        {
            *m = material;
            self.send_restarting(Command::SetMaterial { index, material });
        }
    }

    pub(super) fn set_paused(&mut self, paused: bool) {
        self.paused = paused;
        self.worker.send(Command::Pause(paused));
    }

    pub(super) fn restart(&mut self) {
        self.send_restarting(Command::Restart);
    }

    /// Starts loading a bundled scene or a file in the background; the current scene stays until it succeeds.
    /// Wakes the UI from another thread (a dialog's, a loader's).
    pub(super) fn waker(&self) -> impl Fn() + Send + 'static {
        super::frames::notifier(&self.repaint)
    }

    pub(super) fn open(&mut self, what: String) {
        self.loading = Some(Loading::start(what, self.waker()));
        self.error = None;
    }

    fn poll_loading(&mut self) {
        let Some(result) = self.loading.as_ref().and_then(Loading::poll) else { return };
        let what = self.loading.take().map(|l| l.what).unwrap_or_default();
        match result {
            Ok(scene) => {
                if std::path::Path::new(&what).is_file()
                    && let Err(e) = self.recent.push(&what)
                {
                    self.error = Some(e);
                }
                self.home_camera = scene.camera;
                self.camera = scene.camera;
                self.selected_material = 0;
                // The scene's warnings are shown under the scene, for as long as it is loaded.
                self.message = None;
                self.scene = Arc::new(scene);
                self.send_restarting(Command::SetScene(self.scene.clone()));
            }
            Err(e) => self.error = Some(e.to_string()),
        }
    }

    /// Writes PNG, EXR and JSON of the current frame; the outcome is shown, never fatal.
    pub(super) fn screenshot(&mut self) {
        let Some(frame) = self.frame.clone() else {
            self.message = Some("nothing to save yet".into());
            return;
        };
        match write_snapshot(&frame, &PathBuf::from(&self.export_folder), self.exposure) {
            Ok(paths) => {
                self.message = Some(format!("saved {} (+ .exr, .json)", paths.png.display()));
                self.error = None;
                match self.export_probe() {
                    Some(Ok(probes)) => {
                        self.message = Some(format!(
                            "saved {} (+ .exr, .json) and {} probe pictures",
                            paths.png.display(),
                            probes.len()
                        ))
                    }
                    Some(Err(e)) => self.error = Some(format!("probe not saved: {e}")),
                    None => {}
                }
            }
            Err(e) => self.error = Some(format!("screenshot not saved: {e}")),
        }
    }

    pub(super) fn send_spp(&mut self) {
        let size = if self.auto_pass { PassSize::Auto } else { PassSize::Fixed(self.spp_per_pass) };
        self.worker.send(Command::SetPassSize(size));
        self.worker.send(Command::SetTargetSpp(self.target_spp));
    }
}
