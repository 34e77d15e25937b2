//! The status bar: progress and the measured rates.

use super::viewer::UiState;
use crate::session::Session;

pub fn status_ui(s: &Session, u: &UiState, ui: &mut egui::Ui) {
    ui.horizontal_wrapped(|ui| {
        let Some(f) = s.frame().cloned() else {
            // Before the first frame: starting, or stopped (the error is at the top of the side panel).
            ui.label(if u.error.is_some() { "not rendering: see the error" } else { "starting…" });
            return;
        };
        let seconds = f.elapsed.as_secs_f64().max(1e-9);
        if f.preview {
            ui.label("preview (½ resolution, 1 spp)");
        } else {
            ui.label(format!("{} spp", f.spp));
        }
        ui.separator();
        ui.label(format!("{} passes", f.passes));
        ui.separator();
        ui.label(format!("{:.2} s", f.elapsed.as_secs_f64()));
        ui.separator();
        ui.label(format!("{:.2} M samples/s", f.stats.samples as f64 / seconds / 1e6));
        ui.separator();
        ui.label(format!("{:.2} M rays/s", f.stats.rays as f64 / seconds / 1e6));
        ui.separator();
        ui.label(format!("shadow rays in {}", s.scene().accel().shadow_walk())).on_hover_text(
            "ILLUMLAB_VECTORS=avx2 in the environment chooses 8 lanes on any CPU; in a tree deeper than four levels each \
             shadow ray walks alone; every way gives the same image",
        );
        ui.separator();
        let dropped = format!("{} non-finite dropped", f.stats.non_finite);
        if f.stats.non_finite > 0 {
            ui.colored_label(ui.visuals().warn_fg_color, dropped);
        } else {
            ui.label(dropped);
        }
        ui.separator();
        ui.label(format!("{}×{}", f.width, f.height));
        if let Some((t, _)) = &f.guide {
            ui.separator();
            let size = format!("{} leaves, {} nodes, {:.0} KiB", t.leaves, t.dtree_nodes, t.bytes as f64 / 1024.0);
            ui.label(match (t.kept, t.frozen) {
                (true, _) => format!("guide kept (frozen): {size}"),
                (false, true) => {
                    format!("guide frozen after {} iterations ({} spp): {size}", t.iteration, t.learned_spp)
                }
                (false, false) => format!(
                    "guide learning: iteration {} ({} spp learned), {size}, built in {:.1} ms",
                    t.iteration,
                    t.learned_spp,
                    t.build.as_secs_f64() * 1e3
                ),
            });
        }
        if let Some(l) = s.restart_latency() {
            ui.separator();
            ui.label(format!("restart to frame {:.0} ms", l.as_secs_f64() * 1e3));
        }
        if !u.ui_frame_times.is_empty() {
            let mut t: Vec<_> = u.ui_frame_times.clone();
            t.sort();
            ui.separator();
            ui.label(format!("UI {:.1} ms", t[t.len() / 2].as_secs_f64() * 1e3));
        }
        if s.is_paused() {
            ui.separator();
            ui.strong("paused");
        }
    });
}
