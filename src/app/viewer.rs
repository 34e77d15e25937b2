//! The viewer: a [`Session`] (everything that renders, headless) and the [`UiState`] (what only the window has:
//! textures, open windows, the wipe's position, messages). Each frame takes the session's news, draws the panels
//! — functions of `(&mut Session, &mut UiState, ui)` — and the session sends what they changed.

use super::files::{RecentFiles, UiScale};
use super::loader::Loading;
use crate::measure::ColorScale;
use crate::render::RenderSettings;
use crate::scene::Scene;
use crate::session::Session;
use crate::session::snapshot::write_snapshot;
use crate::session::worker::Frame;
use crate::tour::{Presenter, Tour};
use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// What only the window has. The settings, frames, reference, probe and history are the session's.
pub struct UiState {
    /// Where the session's notices send repaint requests, once a context is known.
    pub(super) repaint: Arc<Mutex<Option<egui::Context>>>,
    /// The spp per pass the slider shows (sent when "passes sized by time" is off).
    pub(super) spp_per_pass: u32,
    pub(super) one_to_one: bool,
    pub(super) selected_material: usize,
    pub(super) side_by_side: bool,
    /// Where the split is, as a fraction of the image width (A left, B right).
    pub(super) wipe: f32,
    /// The scale of the error maps on display, and why the chosen map cannot be shown (if so).
    pub(super) scale: Option<ColorScale>,
    pub(super) view_note: Option<&'static str>,
    /// Where the image (A's, in compare mode) was last drawn, in points.
    pub(super) image_rect: Option<egui::Rect>,
    /// Textures of lanes A and B.
    pub(super) textures: [Option<egui::TextureHandle>; 2],
    /// The textures must be refilled (a restarted image, view or exposure).
    pub(super) texture_stale: bool,
    /// A refined frame of the image shown waits for its upload ([`super::frames::UPLOAD_INTERVAL`]).
    pub(super) refined: bool,
    pub(super) last_upload: Option<Instant>,
    /// What the textures were made with: a change of view, exposure or compare mode refills them.
    pub(super) shown_with: (crate::session::views::View, f32, bool),
    pub(super) loading: Option<Loading>,
    pub(super) error: Option<String>,
    pub(super) message: Option<String>,
    pub(super) open_path: String,
    pub(super) reference_path: String,
    pub(super) export_folder: String,
    pub(super) show_help: bool,
    pub(super) hide_panels: bool,
    pub(super) show_plot: bool,
    /// The plot shows relative RMSE instead of RMSE.
    pub(super) plot_relative: bool,
    /// Recent UI frame times (for the status bar).
    pub(super) ui_frame_times: Vec<Duration>,
    /// `ILLUMLAB_TRACE` set: print latencies and frame times on stderr (for scripts/measure-viewer.sh).
    pub(super) trace: bool,
    /// Start of the previous UI frame and the recent intervals between frames (painting included).
    pub(super) last_ui_start: Option<Instant>,
    pub(super) ui_intervals: Vec<Duration>,
    /// The probe window's state.
    pub(super) probe: super::probe::ProbeUi,
    /// A native file dialog while it is open.
    pub(super) dialog: Option<super::files::Dialog>,
    /// Scene files opened before, newest first.
    pub(super) recent: RecentFiles,
    /// The UI's zoom (Ctrl + / −), remembered between runs.
    pub(super) ui_scale: UiScale,
    /// The tour being presented, and the presenter view (image, caption and probe only).
    pub(super) tour: Option<Presenter>,
    pub(super) presenter_view: bool,
    /// The tour file the tour panel opens and saves steps to.
    pub(super) tour_path: String,
}

/// The window's state: the session and the UI's own.
pub struct Viewer {
    pub(super) session: Session,
    pub(super) ui: UiState,
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
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        let threads = threads.unwrap_or(cores).max(1);
        let source = scene.name.clone();
        let session = Session::new(scene, source, threads, super::frames::repaint_notify(&repaint));
        let ui = UiState {
            repaint,
            spp_per_pass: 8,
            one_to_one: false,
            selected_material: 0,
            side_by_side: false,
            wipe: 0.5,
            scale: None,
            view_note: None,
            image_rect: None,
            textures: [None, None],
            texture_stale: false,
            refined: false,
            last_upload: None,
            shown_with: (session.view(), session.exposure(), false),
            loading: None,
            error: None,
            message: None,
            open_path: String::new(),
            reference_path: String::new(),
            export_folder: "screenshots".into(),
            show_help: false,
            hide_panels: false,
            show_plot: false,
            plot_relative: true,
            ui_frame_times: Vec::new(),
            trace: std::env::var_os("ILLUMLAB_TRACE").is_some(),
            last_ui_start: None,
            ui_intervals: Vec::new(),
            probe: super::probe::ProbeUi::default(),
            dialog: None,
            recent: RecentFiles::default(),
            ui_scale: UiScale::default(),
            tour: None,
            presenter_view: false,
            tour_path: String::new(),
        };
        Self { session, ui }
    }

    /// The session underneath: settings, frames, reference, probe, history.
    pub fn session(&self) -> &Session {
        &self.session
    }

    /// The session, to set it as the command line or a test does (the UI follows on its next frame).
    pub fn session_mut(&mut self) -> &mut Session {
        &mut self.session
    }

    /// Sets strategy, light selection, seed, target and exposure (as the `view` command line does).
    pub fn configure(&mut self, settings: RenderSettings, target_spp: Option<u32>, exposure: f32) {
        self.session.set_settings(settings);
        self.session.set_sampling(self.session.pass_size(), target_spp);
        self.session.set_exposure(exposure);
    }

    /// The newest frame shown.
    pub fn frame(&self) -> Option<&Frame> {
        self.session.frame().map(|f| &**f)
    }

    /// Lane B's newest frame shown (compare mode).
    pub fn frame_b(&self) -> Option<&Frame> {
        self.session.frame_b().map(|f| &**f)
    }

    /// The scene the UI is showing (the last one that loaded successfully).
    pub fn scene(&self) -> &Scene {
        self.session.scene()
    }

    /// The error on display, if any.
    pub fn error(&self) -> Option<&str> {
        self.ui.error.as_deref()
    }

    /// Where screenshots go.
    pub fn set_export_folder(&mut self, folder: impl Into<String>) {
        self.ui.export_folder = folder.into();
    }

    /// True while a scene is loading in the background.
    pub fn is_loading(&self) -> bool {
        self.ui.loading.is_some()
    }

    /// Where the image (A's, in compare mode) was last drawn, in points.
    pub fn image_rect(&self) -> Option<egui::Rect> {
        self.ui.image_rect
    }

    /// Why the chosen error map is not shown, if it is not (e.g. "zero everywhere").
    pub fn view_note(&self) -> Option<&'static str> {
        self.ui.view_note
    }

    pub fn wipe(&self) -> f32 {
        self.ui.wipe
    }

    /// Opens the convergence window (asking for a reference if there is none).
    pub fn show_convergence_plot(&mut self) {
        self.ui.show_plot = true;
        self.session.ensure_reference();
    }

    /// Starts presenting `tour` at its first step, in the presenter view; an error is shown, and the viewer keeps
    /// running.
    pub fn present(&mut self, tour: Tour) {
        super::tour::present(&mut self.session, &mut self.ui, tour);
    }

    /// The tour being presented and the step shown.
    pub fn presenter(&self) -> Option<&Presenter> {
        self.ui.tour.as_ref()
    }

    /// Whether the presenter view (image, caption and probe only) is on.
    pub fn is_presenting(&self) -> bool {
        self.ui.presenter_view
    }

    /// Lets the session wake this context when a frame is ready.
    pub fn bind_repaint(&self, ctx: egui::Context) {
        if let Ok(mut slot) = self.ui.repaint.lock() {
            *slot = Some(ctx);
        }
    }

    /// The whole UI for one frame (eframe's `App::ui` calls this; tests drive it through egui_kittest).
    pub fn ui(&mut self, ui: &mut egui::Ui) {
        let (s, u) = (&mut self.session, &mut self.ui);
        let start = Instant::now();
        if let Some(last) = u.last_ui_start.replace(start) {
            u.ui_intervals.push(start - last);
        }
        if let Ok(mut slot) = u.repaint.lock()
            && slot.is_none()
        {
            *slot = Some(ui.ctx().clone());
        }
        u.ui_scale.remember(ui.ctx());
        super::files::take_dropped_files(s, u, ui.ctx());
        super::loader::poll_loading(s, u);
        super::frames::take_frames(s, u);
        super::probe::take_probe(s, u, ui.ctx());
        super::shortcuts::handle(s, u, ui);
        let presenting = u.presenter_view && u.tour.is_some();
        if !u.hide_panels && !presenting {
            egui::Panel::bottom("status").show(ui, |ui| super::status::status_ui(s, u, ui));
            egui::Panel::left("controls").resizable(true).default_size(300.0).show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| super::controls::controls_ui(s, u, ui));
            });
        }
        if presenting || u.tour.is_some() && !u.hide_panels {
            super::tour::caption_panel(s, u, ui);
        }
        if presenting && s.probe_pixel().is_some() {
            super::probe::presenter_probe_panel(s, u, ui);
        }
        egui::CentralPanel::default().show(ui, |ui| super::viewport::viewport_ui(s, u, ui));
        super::shortcuts::help_window(u, ui);
        if !presenting {
            super::convergence::convergence_window(s, u, ui);
        }
        if !presenting {
            super::probe::probe_window(s, u, ui);
        }
        if ui.ctx().input(|i| !i.raw.hovered_files.is_empty()) {
            egui::Area::new(egui::Id::unique("drop-hint")).anchor(egui::Align2::CENTER_CENTER, [0.0, 0.0]).show(
                ui.ctx(),
                |ui| {
                    egui::Frame::popup(ui.style())
                        .show(ui, |ui| ui.heading("Drop to open: a scene (.toml, .obj) or a reference (.exr)"))
                },
            );
        }
        if u.loading.is_some() || s.frame().is_none() {
            ui.ctx().request_repaint_after(Duration::from_millis(30));
        }
        u.ui_frame_times.push(start.elapsed());
        if u.ui_frame_times.len() >= 120 {
            if u.trace {
                let mut t = u.ui_frame_times.clone();
                t.sort();
                let ms = |d: Duration| d.as_secs_f64() * 1e3;
                eprintln!("trace: ui-frame median {:.2} ms, max {:.2} ms", ms(t[t.len() / 2]), ms(t[t.len() - 1]));
                let mut i = std::mem::take(&mut u.ui_intervals);
                i.sort();
                if !i.is_empty() {
                    eprintln!("trace: frame-interval median {:.2} ms, min {:.2} ms", ms(i[i.len() / 2]), ms(i[0]));
                }
            }
            u.ui_frame_times.clear();
        }
    }
}

impl UiState {
    /// Wakes the UI from another thread (a dialog's, a loader's).
    pub(super) fn waker(&self) -> impl Fn() + Send + 'static {
        super::frames::notifier(&self.repaint)
    }

    /// Starts loading a bundled scene or a file in the background; the current scene stays until it succeeds.
    pub(super) fn open(&mut self, what: String) {
        self.loading = Some(Loading::start(what, self.waker()));
        self.error = None;
    }
}

/// Writes PNG, EXR and JSON of the current frame (and the probe's pictures); the outcome is shown, never fatal.
pub(super) fn screenshot(s: &Session, u: &mut UiState) {
    let Some(frame) = s.frame().cloned() else {
        u.message = Some("nothing to save yet".into());
        return;
    };
    match write_snapshot(&frame, &PathBuf::from(&u.export_folder), s.exposure()) {
        Ok(paths) => {
            u.message = Some(format!("saved {} (+ .exr, .json)", paths.png.display()));
            u.error = None;
            match s.probe_view().map(|v| v.export(std::path::Path::new(&u.export_folder))) {
                Some(Ok(probes)) => {
                    u.message = Some(format!(
                        "saved {} (+ .exr, .json) and {} probe pictures",
                        paths.png.display(),
                        probes.len()
                    ))
                }
                Some(Err(e)) => u.error = Some(format!("probe not saved: {e}")),
                None => {}
            }
        }
        Err(e) => u.error = Some(format!("screenshot not saved: {e}")),
    }
}
