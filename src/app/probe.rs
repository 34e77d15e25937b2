//! The probe panel: pick a point (probe mode with `I` and a click, or Ctrl-click; hold `I` and hover), and see
//! the lecture's hemisphere pictures there for the current strategy (A and B side by side in compare mode), the
//! running estimate against the quadrature, the histogram of sample values, a chi-square test of the sampler at
//! that point, and a table that measures every strategy there. The work runs on the probe's own thread
//! ([`crate::session::probe`]); this is its shell.

use super::viewer::Viewer;
use crate::math::luminance;
use crate::probe::{HISTOGRAM_BINS, HISTOGRAM_DECADES, Layers, PROJECTION, ProbeSettings, chi2};
use crate::session::probe::{ProbeRequest, ProbeView, ProbeWorker};
use crate::session::worker::Frame;
use egui_plot::{Bar, BarChart, Plot};

/// What the probe panel shows and asks for.
pub struct ProbeUi {
    worker: ProbeWorker,
    /// Clicks pick the probe point.
    pub(super) mode: bool,
    /// The probed pixel and the camera it was picked with.
    pub(super) pixel: Option<((u32, u32), crate::scene::Camera)>,
    /// Re-probe the same pixel when the camera moves (else the point stays where it was picked).
    pub(super) follow: bool,
    pub(super) settings: ProbeSettings,
    pub(super) layers: Layers,
    pub(super) table: bool,
    pub(super) view: Option<ProbeView>,
    last_request: Option<ProbeRequest>,
    textures: Vec<egui::TextureHandle>,
    pub(super) open: bool,
}

impl ProbeUi {
    pub fn new(notify: impl Fn() + Send + 'static) -> Self {
        Self {
            worker: ProbeWorker::spawn(notify),
            mode: false,
            pixel: None,
            follow: false,
            settings: ProbeSettings { keep: 2_000, ..Default::default() },
            layers: Layers::default(),
            table: false,
            view: None,
            last_request: None,
            textures: Vec::new(),
            open: false,
        }
    }
}

impl Viewer {
    /// Probes pixel (x, y) of the current camera.
    pub fn set_probe_pixel(&mut self, pixel: (u32, u32)) {
        self.probe.pixel = Some((pixel, self.camera));
        self.probe.open = true;
        self.probe.settings.chi2_samples = 0;
    }

    /// The newest probe answer on display.
    pub fn probe_view(&self) -> Option<&ProbeView> {
        self.probe.view.as_ref()
    }

    /// Sends a new request when what the probe depends on changed, and takes the newest answer.
    pub(super) fn poll_probe(&mut self, ctx: &egui::Context) {
        if let Some(view) = self.probe.worker.take() {
            self.probe.textures = view
                .lanes
                .iter()
                .enumerate()
                .map(|(i, (_, pic))| {
                    let image = egui::ColorImage::from_rgba_unmultiplied([pic.width, pic.height], &pic.rgba);
                    ctx.load_texture(format!("probe {i}"), image, egui::TextureOptions::LINEAR)
                })
                .collect();
            if self.trace {
                let kind = if self.probe.view.as_ref().and_then(|v| v.point) == view.point {
                    "same point"
                } else {
                    "new point"
                };
                eprintln!("trace: probe answered in {:.1} ms ({kind})", view.elapsed.as_secs_f64() * 1e3);
            }
            self.probe.view = Some(view);
        }
        let Some((pixel, picked_with)) = self.probe.pixel else { return };
        if self.probe.follow && picked_with != self.camera {
            self.probe.pixel = Some((pixel, self.camera));
        }
        let camera = self.probe.pixel.map_or(self.camera, |p| p.1);
        let mut lanes = vec![self.settings];
        let guide_of = |f: Option<&Frame>| f.and_then(|f| f.guide.as_ref()).map(|(_, g)| g.clone());
        let mut guides = vec![guide_of(self.frame.as_deref())];
        if self.comparing {
            lanes.push(self.settings_b);
            guides.push(guide_of(self.frame_b.as_deref()));
        }
        let request = ProbeRequest {
            scene: self.scene.clone(),
            camera,
            pixel,
            lanes,
            guides,
            settings: self.probe.settings,
            layers: self.probe.layers,
            table: self.probe.table,
        };
        if self.probe.last_request.as_ref() != Some(&request) {
            self.probe.worker.request(request.clone());
            self.probe.last_request = Some(request);
        }
    }

    /// Where the probe's marker goes: the probed pixel, while the camera is the one it was picked with.
    pub(super) fn probe_marker(&self) -> Option<(u32, u32)> {
        self.probe.pixel.filter(|(_, c)| *c == self.camera).map(|(p, _)| p)
    }

    /// Writes the probe's pictures and numbers beside screenshots; `None` without a probe.
    pub(super) fn export_probe(&mut self) -> Option<Result<Vec<std::path::PathBuf>, String>> {
        let view = self.probe.view.as_ref()?;
        Some(view.export(std::path::Path::new(&self.export_folder)))
    }
}

/// The probe window.
pub fn probe_window(v: &mut Viewer, ui: &mut egui::Ui) {
    if !v.probe.open {
        return;
    }
    let mut open = true;
    let right = ui.ctx().content_rect().right();
    egui::Window::new("Probe").open(&mut open).default_size([620.0, 720.0]).default_pos([right - 640.0, 30.0]).show(
        ui.ctx(),
        |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| probe_ui(v, ui));
        },
    );
    if !open {
        v.probe.open = false;
        v.probe.pixel = None;
        v.probe.view = None;
        v.probe.last_request = None;
    }
}

fn probe_ui(v: &mut Viewer, ui: &mut egui::Ui) {
    ui.horizontal(|ui| {
        ui.checkbox(&mut v.probe.mode, "probe mode (I): a click picks the point");
        ui.checkbox(&mut v.probe.follow, "follow the camera");
    });
    ui.horizontal(|ui| {
        let l = &mut v.probe.layers;
        ui.checkbox(&mut l.integrand, "integrand f L cos");
        ui.checkbox(&mut l.density, "density p");
        ui.checkbox(&mut l.ratio, "ratio");
        ui.checkbox(&mut l.outlines, "lights");
        ui.checkbox(&mut l.samples, "samples");
        ui.checkbox(&mut l.guide, "learned guide").on_hover_text("guided: the density its guide learned here");
    });
    ui.horizontal(|ui| {
        // Copies, written back only when moved: a logarithmic slider may round the value it is given.
        let s = &mut v.probe.settings;
        let (mut samples, mut keep) = (s.samples, s.keep as u64);
        if ui.add(egui::Slider::new(&mut samples, 100..=200_000).logarithmic(true).text("samples")).changed() {
            s.samples = samples;
        }
        if ui.add(egui::Slider::new(&mut keep, 0..=100_000).logarithmic(true).text("dots")).changed() {
            s.keep = keep as usize;
        }
    });
    ui.horizontal(|ui| {
        if ui.button("Chi-square here").clicked() {
            v.probe.settings.chi2_samples = 200_000;
        }
        ui.checkbox(&mut v.probe.table, "measure every strategy here");
        if ui.button("Save probe (PNG + JSON)").clicked() {
            match v.export_probe() {
                Some(Ok(paths)) => {
                    v.message = Some(format!(
                        "saved {}",
                        paths.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ")
                    ))
                }
                Some(Err(e)) => v.error = Some(format!("probe not saved: {e}")),
                None => {}
            }
        }
    });
    let Some(view) = &v.probe.view else {
        ui.spinner();
        return;
    };
    let waiting = v.probe.last_request.as_ref() != Some(&view.request);
    let Some(point) = view.point else {
        ui.label(format!("pixel {},{}: the camera ray meets no surface", view.request.pixel.0, view.request.pixel.1));
        return;
    };
    let material = v.scene.material_names.get(point.material as usize).map_or("?", |s| s.as_str());
    // In the scene files' coordinates (a scene far from the origin renders rebased).
    let position = v.scene.origin + point.position.as_dvec3();
    ui.label(format!(
        "pixel {},{}  p = ({:.3}, {:.3}, {:.3})  n = ({:.2}, {:.2}, {:.2})  ω_o = ({:.2}, {:.2}, {:.2})  material {material}{}",
        point.pixel.0,
        point.pixel.1,
        position.x,
        position.y,
        position.z,
        point.normal.x,
        point.normal.y,
        point.normal.z,
        point.wo.x,
        point.wo.y,
        point.wo.z,
        if waiting { "  (updating…)" } else { "" }
    ));
    ui.small(format!("{PROJECTION}. Computed in {:.0} ms.", view.elapsed.as_secs_f64() * 1e3));
    ui.small("left: integrand / L_o · middle: density p(ω) (same log scale) · right: their ratio (white = ideal, red = too rare: fireflies) · dots: last samples by weight f L cos/p relative to L_o (blue low, red high; grey = zero; rings = MIS's 2nd technique; MIS dots grow with their weight)");
    if view.lanes.iter().any(|(r, _)| r.chi2.is_some()) {
        ui.small("chi-square rows: draws observed per cell · counts the pdf expects (same log scale) · residual (o − e)/√e from −4 (blue) to +4 (red); MIS: one row per technique");
    }
    ui.separator();
    let lanes: Vec<_> = view.lanes.iter().zip(&v.probe.textures).collect();
    if let [a, b] = lanes[..] {
        // Compare mode: A and B side by side, at the same point with the same random streams.
        ui.columns(2, |columns| {
            for (ui, (label, ((report, picture), texture))) in columns.iter_mut().zip([("A: ", a), ("B: ", b)]) {
                lane_ui(ui, label, report, picture, texture);
            }
        });
    } else if let Some(((report, picture), texture)) = lanes.first() {
        lane_ui(ui, "", report, picture, texture);
    }
    if let Some(rows) = &view.table {
        ui.separator();
        ui.strong("Every strategy here (one thread, against the quadrature)");
        egui::Grid::new("probe-table").striped(true).num_columns(5).show(ui, |ui| {
            for h in ["strategy", "σ²/μ² per sample", "samples/s", "efficiency 1/(σ²t)", "z"] {
                ui.strong(h);
            }
            ui.end_row();
            for r in rows {
                ui.label(r.strategy);
                ui.label(format!("{:.4}", r.relative_variance));
                ui.label(format!("{:.2e}", r.samples_per_second));
                ui.label(format!("{:.3e}", r.efficiency));
                ui.label(format!("{:+.2}", r.z));
                ui.end_row();
            }
        });
    }
}

/// One lane's picture and numbers.
fn lane_ui(
    ui: &mut egui::Ui,
    label: &str,
    report: &crate::probe::ProbeReport,
    picture: &crate::probe::Picture,
    texture: &egui::TextureHandle,
) {
    // egui's fonts have no ‖: the norm is written |…|.
    ui.strong(format!("{label}{} — {}", report.strategy.name(), report.strategy.pdf_formula().replace('‖', "|")));
    let width = ui.available_width().min(picture.width as f32 * 1.2);
    let size = egui::vec2(width, width * picture.height as f32 / picture.width as f32);
    ui.image((texture.id(), size));
    numbers_ui(ui, report);
}

fn numbers_ui(ui: &mut egui::Ui, r: &crate::probe::ProbeReport) {
    let truth = luminance(r.quadrature.value) as f64;
    let run = &r.run;
    let (lo, hi) = run.interval_95();
    egui::Grid::new(("probe-numbers", r.strategy.name())).num_columns(2).show(ui, |ui| {
        let mut row = |k: &str, v: String| {
            ui.label(k);
            ui.label(v);
            ui.end_row();
        };
        row(
            "estimate",
            format!(
                "{:.5} ± {:.5} (95%: {lo:.5} … {hi:.5}), {} samples",
                run.mean_luminance(),
                run.luminance_std_error(),
                run.samples
            ),
        );
        row(
            "quadrature",
            format!(
                "{truth:.5} ({} evaluations{})",
                r.quadrature.nodes,
                if r.quadrature.budget_reached { ", budget reached" } else { "" }
            ),
        );
        // A quadrature that ran out of budget (shadow edges, light through an opening) is no truth to judge by.
        let unconverged =
            if r.quadrature.budget_reached { " (against a quadrature that did not converge)" } else { "" };
        row("z-score", format!("{:+.2}{unconverged}", run.z_score(truth)));
        row("σ²/μ² of one sample", format!("{:.4}", run.relative_variance(truth)));
        let zeros: Vec<String> =
            run.zero_counts().filter(|(_, n)| *n > 0).map(|(o, n)| format!("{} {n}", o.name())).collect();
        row("zero directions", if zeros.is_empty() { "none".into() } else { zeros.join(", ") });
        row("non-finite samples", run.non_finite.to_string());
        row("speed", format!("{:.2} M samples/s", 1e-6 / run.seconds_per_sample()));
        if let Some(c) = &r.chi2 {
            let verdict = if c.p_value >= chi2::level(1) { "pass" } else { "FAIL" };
            row(
                "chi-square",
                format!(
                    "p = {:.4} ({verdict} at 1%), {:.1} on {} dof, ∫p dω = {:.4}, {} ({} draws)",
                    c.p_value, c.statistic, c.dof, c.integral, c.binning, c.samples
                ),
            );
        }
    });
    let (lo, hi) = HISTOGRAM_DECADES;
    let step = (hi - lo) / HISTOGRAM_BINS as f32;
    let bars: Vec<Bar> = run
        .histogram
        .iter()
        .enumerate()
        .filter(|(_, n)| **n > 0)
        .map(|(i, &n)| Bar::new((lo + (i as f32 + 0.5) * step) as f64, n as f64).width(step as f64))
        .collect();
    ui.small(format!("histogram of one-sample values / L_o (log10), {} zero", run.histogram_zeros));
    Plot::new(("probe-histogram", r.strategy.name())).height(90.0).allow_scroll(false).allow_drag(false).show(
        ui,
        |plot| {
            plot.bar_chart(BarChart::new("samples", bars));
        },
    );
}
