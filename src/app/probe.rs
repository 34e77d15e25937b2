//! The probe panel: pick a point (probe mode with `I` and a click, or Ctrl-click; hold `I` and hover), and see
//! the lecture's hemisphere pictures there for the current strategy (A and B side by side in compare mode), the
//! running estimate against the quadrature, the histogram of sample values, a chi-square test of the sampler at
//! that point, and a table that measures every strategy there. The work runs on the probe's own thread
//! ([`crate::session::probe`]); this is its shell.

use super::viewer::{UiState, Viewer};
use crate::math::luminance;
use crate::probe::{HISTOGRAM_BINS, HISTOGRAM_DECADES, PROJECTION, chi2};
use crate::session::Session;
use crate::session::probe::ProbeView;
use egui_plot::{Bar, BarChart, Plot};

/// The probe window's own state (what it probes, and how, is the session's).
#[derive(Default)]
pub struct ProbeUi {
    /// Clicks pick the probe point.
    pub(super) mode: bool,
    pub(super) open: bool,
    /// The session's answer changed: its pictures must be uploaded again.
    pub(super) stale: bool,
    textures: Vec<egui::TextureHandle>,
}

impl Viewer {
    /// Probes pixel (x, y) of the current camera.
    pub fn set_probe_pixel(&mut self, pixel: (u32, u32)) {
        probe_pixel(&mut self.session, &mut self.ui, pixel);
    }

    /// The newest probe answer on display.
    pub fn probe_view(&self) -> Option<&ProbeView> {
        self.session.probe_view()
    }
}

/// Probes `pixel` and opens the window.
pub(super) fn probe_pixel(s: &mut Session, u: &mut UiState, pixel: (u32, u32)) {
    s.set_probe_pixel(Some(pixel));
    u.probe.open = true;
}

/// Uploads the pictures of a new answer.
pub(super) fn take_probe(s: &Session, u: &mut UiState, ctx: &egui::Context) {
    if !std::mem::take(&mut u.probe.stale) {
        return;
    }
    let Some(view) = s.probe_view() else { return };
    u.probe.textures = view
        .lanes
        .iter()
        .enumerate()
        .map(|(i, (_, pic))| {
            let image = egui::ColorImage::from_rgba_unmultiplied([pic.width, pic.height], &pic.rgba);
            ctx.load_texture(format!("probe {i}"), image, egui::TextureOptions::LINEAR)
        })
        .collect();
    if u.trace {
        eprintln!("trace: probe answered in {:.1} ms", view.elapsed.as_secs_f64() * 1e3);
    }
    // A probe set by a tour step or the command line opens the window.
    u.probe.open |= s.probe_pixel().is_some();
}

/// The probe window.
pub fn probe_window(s: &mut Session, u: &mut UiState, ui: &mut egui::Ui) {
    if !u.probe.open {
        return;
    }
    let mut open = true;
    let right = ui.ctx().content_rect().right();
    egui::Window::new("Probe").open(&mut open).default_size([620.0, 720.0]).default_pos([right - 640.0, 30.0]).show(
        ui.ctx(),
        |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| probe_ui(s, u, ui));
        },
    );
    if !open {
        u.probe.open = false;
        u.probe.mode = false;
        s.set_probe_pixel(None);
    }
}

fn probe_ui(s: &mut Session, u: &mut UiState, ui: &mut egui::Ui) {
    let mut options = s.probe_options();
    ui.horizontal(|ui| {
        ui.checkbox(&mut u.probe.mode, "probe mode (I): a click picks the point");
        ui.checkbox(&mut options.follow, "follow the camera");
    });
    ui.horizontal(|ui| {
        let l = &mut options.layers;
        ui.checkbox(&mut l.integrand, "integrand f L cos");
        ui.checkbox(&mut l.density, "density p");
        ui.checkbox(&mut l.ratio, "ratio");
        ui.checkbox(&mut l.outlines, "lights");
        ui.checkbox(&mut l.samples, "samples");
        ui.checkbox(&mut l.guide, "learned guide").on_hover_text("guided: the density its guide learned here");
    });
    ui.horizontal(|ui| {
        // Copies, written back only when moved: a logarithmic slider may round the value it is given.
        let p = &mut options.settings;
        let (mut samples, mut keep) = (p.samples, p.keep as u64);
        if ui.add(egui::Slider::new(&mut samples, 100..=200_000).logarithmic(true).text("samples")).changed() {
            p.samples = samples;
        }
        if ui.add(egui::Slider::new(&mut keep, 0..=100_000).logarithmic(true).text("dots")).changed() {
            p.keep = keep as usize;
        }
    });
    ui.horizontal(|ui| {
        if ui.button("Chi-square here").clicked() {
            options.settings.chi2_samples = 200_000;
        }
        ui.checkbox(&mut options.table, "measure every strategy here");
        if ui.button("Save probe (PNG + JSON)").clicked() {
            match s.probe_view().map(|v| v.export(std::path::Path::new(&u.export_folder))) {
                Some(Ok(paths)) => {
                    u.message = Some(format!(
                        "saved {}",
                        paths.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ")
                    ))
                }
                Some(Err(e)) => u.error = Some(format!("probe not saved: {e}")),
                None => {}
            }
        }
    });
    if options != s.probe_options() {
        s.set_probe_options(options);
    }
    let Some(view) = s.probe_view() else {
        ui.spinner();
        return;
    };
    let waiting = !s.probe_is_current();
    let Some(point) = view.point else {
        ui.label(format!("pixel {},{}: the camera ray meets no surface", view.request.pixel.0, view.request.pixel.1));
        return;
    };
    let scene = s.scene();
    let material = scene.material_names.get(point.material as usize).map_or("?", |n| n.as_str());
    // In the scene files' coordinates (a scene far from the origin renders rebased).
    let position = scene.origin + point.position.as_dvec3();
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
    let lanes: Vec<_> = view.lanes.iter().zip(&u.probe.textures).collect();
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

/// The probe in the presenter view: a panel on the right with each lane's picture and the three numbers that say
/// which estimator wins at the point, in type readable from the back of a room.
pub(super) fn presenter_probe_panel(s: &Session, u: &UiState, ui: &mut egui::Ui) {
    let Some(view) = s.probe_view() else { return };
    let width = ui.available_width() * 0.42;
    egui::Panel::right("presenter-probe").resizable(true).default_size(width).show(ui, |ui| {
        let Some(point) = view.point else {
            ui.label(egui::RichText::new("the probed pixel sees no surface").size(16.0));
            return;
        };
        let material = s.scene().material_names.get(point.material as usize).map_or("?", |n| n.as_str());
        ui.label(
            egui::RichText::new(format!("Probe: pixel {},{} ({material})", point.pixel.0, point.pixel.1)).size(16.0),
        );
        ui.small("integrand · density p · ratio, on the hemisphere (centre = n); dots: the last samples");
        for (((report, picture), texture), lane) in view.lanes.iter().zip(&u.probe.textures).zip(["A", "B"]) {
            ui.separator();
            let name = if view.lanes.len() > 1 { format!("{lane}: ") } else { String::new() };
            ui.label(egui::RichText::new(format!("{name}{}", report.strategy.name())).size(18.0).strong());
            let w = ui.available_width();
            ui.image((texture.id(), egui::vec2(w, w * picture.height as f32 / picture.width as f32)));
            let truth = luminance(report.quadrature.value) as f64;
            let run = &report.run;
            let big = |t: String| egui::RichText::new(t).size(16.0);
            let unconverged = if report.quadrature.budget_reached { ", not converged" } else { "" };
            ui.label(big(format!(
                "estimate {:.4} ± {:.4}   (quadrature {truth:.4}{unconverged})",
                run.mean_luminance(),
                run.luminance_std_error()
            )));
            ui.label(big(format!("σ²/μ² of one sample: {:.3}", run.relative_variance(truth))));
        }
    });
}
