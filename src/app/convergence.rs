//! The convergence window (egui_plot): RMSE against the reference on log–log axes, against spp and against CPU
//! seconds, one curve per estimator run in this session, with a 1/√N slope for orientation and the reference's
//! noise floor; below, efficiency `1/(MSE · s)` per estimator with the winner highlighted.

use super::viewer::UiState;
use crate::measure::{ConvergencePoint, Metric, Series, most_efficient};
use crate::session::Session;
use crate::session::worker::ReferenceStatus;
use egui_plot::{GridMark, HLine, Legend, Line, LineStyle, Plot, PlotPoints, Points};

/// Opens the plot (asking for a reference if there is none), or closes it.
pub(super) fn toggle_plot(s: &mut Session, u: &mut UiState) {
    u.show_plot = !u.show_plot;
    if u.show_plot {
        s.ensure_reference();
    }
}

pub fn convergence_window(s: &mut Session, u: &mut UiState, ui: &mut egui::Ui) {
    let mut open = u.show_plot;
    egui::Window::new("Convergence").open(&mut open).default_size([760.0, 520.0]).show(ui.ctx(), |ui| {
        match s.reference_status() {
            ReferenceStatus::Ready { .. } => {}
            ReferenceStatus::Rendering { spp, target, .. } => {
                ui.label(format!("Waiting for the reference ({spp}/{target} spp): errors are measured against it."));
                return;
            }
            ReferenceStatus::Failed(e) => {
                ui.colored_label(ui.visuals().error_fg_color, format!("No reference: {e}"));
                return;
            }
            ReferenceStatus::Off => {
                ui.label("No reference yet: compute or load one (Compare panel).");
                return;
            }
        }
        if s.history().iter().all(|r| r.points.is_empty()) {
            ui.label("Runs appear here as they refine.");
            return;
        }
        ui.horizontal(|ui| {
            ui.radio_value(&mut u.plot_relative, false, "RMSE");
            ui.radio_value(&mut u.plot_relative, true, "relative RMSE, sqrt(relMSE)");
        });
        ui.label(format!(
            "Measured with {}; the reference's own noise (dotted) is subtracted.",
            s.settings().footprint.description()
        ));
        ui.small(if u.plot_relative {
            "Each pixel's error relative to its brightness: dark regions count as much as visible lights."
        } else {
            "Absolute error: pixels on the edges of visible lights dominate it, for every estimator alike."
        });
        let relative = u.plot_relative;
        let floor = s.reference().map_or(0.0, |r| if relative { r.noise_rel_mse() } else { r.noise_mse() }.sqrt());
        let y: fn(&ConvergencePoint) -> f64 = if relative { |p| p.rel_mse.sqrt() } else { |p| p.rmse() };
        let y_label = if relative { "relative RMSE" } else { "RMSE" };
        ui.columns(2, |columns| {
            plot(
                &mut columns[0],
                "rmse-spp",
                ("samples per pixel", y_label),
                s.history(),
                floor,
                (|p| p.spp as f64, y),
            );
            plot(&mut columns[1], "rmse-seconds", ("CPU seconds", y_label), s.history(), floor, (|p| p.seconds, y));
        });
        efficiency_table(ui, s.history());
        if s.history().iter().any(|r| r.points.first().is_some_and(|p| p.spp > 1)) {
            ui.small("Runs that began before the reference was ready start late: press R to record them from 1 spp.");
        }
        if ui.button("Clear runs").clicked() {
            s.clear_history();
        }
    });
    u.show_plot = open;
}

type Axis = fn(&ConvergencePoint) -> f64;

/// Plots log10 values of (x, y) and labels the axes with the values.
fn plot(ui: &mut egui::Ui, id: &str, labels: (&str, &str), series: &[Series], floor: f64, (x_of, y_of): (Axis, Axis)) {
    let log = |x: f64| x.log10();
    let label = |m: GridMark, _: &std::ops::RangeInclusive<f64>| {
        let v = 10f64.powf(m.value);
        if (0.01..10000.0).contains(&v) { format!("{}", (v * 1000.0).round() / 1000.0) } else { format!("{v:.0e}") }
    };
    let lines: Vec<(String, Vec<[f64; 2]>)> = series
        .iter()
        .map(|s| {
            let pts = s
                .points
                .iter()
                .filter(|p| x_of(p) > 0.0 && y_of(p) > 0.0)
                .map(|p| [log(x_of(p)), log(y_of(p))])
                .collect();
            (s.label.clone(), pts)
        })
        .collect();
    let all: Vec<[f64; 2]> = lines.iter().flat_map(|l| l.1.iter().copied()).collect();
    let range = |k: usize| {
        let lo = all.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min);
        let hi = all.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max);
        (lo, hi)
    };
    let ((x0, x1), (y0, y1)) = (range(0), range(1));
    let y0 = if floor > 0.0 { y0.min(log(floor)) } else { y0 };
    // Fixed bounds around the data (a tenth of a decade of margin): the plot follows new points and cannot be
    // dragged away from them.
    let mut plot = Plot::new(id)
        .height(300.0)
        .legend(Legend::default())
        .x_axis_label(labels.0)
        .y_axis_label(labels.1)
        .x_axis_formatter(label)
        .y_axis_formatter(label)
        .allow_drag(false)
        .allow_zoom(false)
        .allow_scroll(false);
    if x0.is_finite() && y0.is_finite() {
        plot = plot.include_x(x0 - 0.1).include_x(x1 + 0.1).include_y(y0 - 0.1).include_y(y1 + 0.1);
    }
    plot.show(ui, |plot| {
        for (label, pts) in lines {
            plot.line(Line::new(label.clone(), PlotPoints::from(pts.clone())).width(2.0));
            plot.points(Points::new(label, PlotPoints::from(pts)).radius(2.5));
        }
        // A −½ slope through the middle of the data.
        if x0.is_finite() && x1 > x0 {
            let n = all.len() as f64;
            let (mx, my) = (all.iter().map(|p| p[0]).sum::<f64>() / n, all.iter().map(|p| p[1]).sum::<f64>() / n);
            let guide: Vec<[f64; 2]> = [x0, x1].iter().map(|&x| [x, my - 0.5 * (x - mx)]).collect();
            plot.line(
                Line::new("slope -1/2", PlotPoints::from(guide))
                    .style(LineStyle::dashed_loose())
                    .color(egui::Color32::GRAY),
            );
        }
        if floor > 0.0 {
            plot.hline(HLine::new("reference noise (subtracted)", log(floor)).style(LineStyle::dotted_dense()));
        }
    });
}

/// Per run at its largest budget: spp, CPU seconds, RMSE, relMSE, and both efficiencies; the best in each
/// efficiency column is highlighted.
fn efficiency_table(ui: &mut egui::Ui, series: &[Series]) {
    let best = [Metric::Mse, Metric::RelMse].map(|m| most_efficient(series, m));
    egui::Grid::new("efficiency").striped(true).num_columns(7).show(ui, |ui| {
        for h in ["estimator", "spp", "CPU s", "RMSE", "relMSE", "1/(MSE·s)", "1/(relMSE·s)"] {
            ui.strong(h);
        }
        ui.end_row();
        for (i, s) in series.iter().enumerate() {
            let Some(p) = s.last() else { continue };
            ui.label(&s.label);
            ui.label(p.spp.to_string());
            ui.label(format!("{:.2}", p.seconds));
            ui.label(format!("{:.3e}", p.rmse()));
            ui.label(format!("{:.3e}", p.rel_mse));
            for (k, metric) in [Metric::Mse, Metric::RelMse].into_iter().enumerate() {
                let text = metric.efficiency(p).map_or("—".to_string(), |e| format!("{e:.3e}"));
                if best[k] == Some(i) {
                    ui.label(egui::RichText::new(format!("{text} best")).strong().color(ui.visuals().warn_fg_color));
                } else {
                    ui.label(text);
                }
            }
            ui.end_row();
        }
    });
    ui.small("Efficiency: higher is better; it compares estimators at any budget because MSE falls as 1/N, that is as 1/time.");
}
