//! The side panel's comparison section: compare mode with B's strategy, swap, budget, layout and wipe; the view
//! (image or error map); the reference (status, spp, compute, load an EXR); export.

use super::viewer::UiState;
use crate::render::{Footprint, Strategy};
use crate::session::Session;
use crate::session::views::View;
use crate::session::worker::{Budget, ReferenceStatus};
use std::path::PathBuf;

pub fn compare_ui(s: &mut Session, u: &mut UiState, ui: &mut egui::Ui) {
    ui.heading("Compare");
    let mut on = s.is_comparing();
    if ui.checkbox(&mut on, "Compare A | B (C)").changed() {
        s.set_comparing(on);
    }
    if s.is_comparing() {
        ui.horizontal(|ui| {
            ui.label(format!("A: {}", s.settings().strategy.name()));
            let mut b = s.settings_b().strategy;
            egui::ComboBox::from_label("B strategy").selected_text(b.name()).show_ui(ui, |ui| {
                for strategy in Strategy::ALL {
                    ui.selectable_value(&mut b, strategy, strategy.name());
                }
            });
            s.set_strategy_b(b);
        });
        if ui.button("Swap A/B (X)").clicked() {
            s.swap_lanes();
        }
        ui.horizontal(|ui| {
            for budget in [Budget::EqualSamples, Budget::EqualTime] {
                if ui.radio(s.budget() == budget, budget.name()).clicked() {
                    s.set_budget(budget);
                }
            }
        });
        ui.small(match s.budget() {
            Budget::EqualSamples => "both reach the same spp",
            Budget::EqualTime => "both get the same CPU time; each shows its own spp",
        });
        ui.checkbox(&mut u.side_by_side, "side by side");
        let side_by_side = u.side_by_side;
        ui.add_enabled(!side_by_side, egui::Slider::new(&mut u.wipe, 0.0..=1.0).text("wipe"));
        ui.small("Same seed, same random streams per pixel: the difference you see is the estimator.");
    }
    ui.separator();
    view_ui(s, ui);
    footprint_ui(s, ui);
    ui.separator();
    reference_ui(s, u, ui);
    if s.is_comparing() {
        ui.separator();
        if ui.button("Export comparison").clicked() {
            super::compare_mode::export_comparison(s, u);
        }
    }
    if ui.button("Convergence plot (P)").clicked() {
        super::convergence::toggle_plot(s, u);
    }
}

fn view_ui(s: &mut Session, ui: &mut egui::Ui) {
    ui.heading("View");
    let mut view = s.view();
    egui::ComboBox::from_label("show").selected_text(view.name()).show_ui(ui, |ui| {
        for option in View::ALL {
            if option.needs_comparison() && !s.is_comparing() {
                continue;
            }
            ui.selectable_value(&mut view, option, option.name());
        }
    });
    if view != s.view() {
        s.set_view(view);
    }
    if view != View::Image {
        ui.small(view.description());
    }
}

/// Pictures or measurements: a jittered footprint antialiases, fixed primary hits leave the estimator's error
/// alone (and a reference rendered the same way).
fn footprint_ui(s: &mut Session, ui: &mut egui::Ui) {
    let mut fixed = s.settings().footprint == Footprint::Centre;
    if ui
        .checkbox(&mut fixed, "Fixed primary hits (measure the estimator)")
        .on_hover_text(
            "Every sample goes through its pixel's centre: the jitter of the pixel footprint, common to every \
             strategy, leaves the error, and the reference is rendered the same way. Off: a box filter, for pictures.",
        )
        .changed()
    {
        s.set_footprint(if fixed { Footprint::Centre } else { Footprint::Jittered });
    }
    ui.small(format!("Errors: {}.", s.settings().footprint.description()));
}

fn reference_ui(s: &mut Session, u: &mut UiState, ui: &mut egui::Ui) {
    ui.heading("Reference");
    match s.reference_status() {
        ReferenceStatus::Off => {
            ui.label("none yet");
        }
        ReferenceStatus::Rendering { spp, target, elapsed } => {
            let (spp, target, elapsed) = (*spp, *target, elapsed.as_secs_f64());
            let done = spp as f32 / target.max(1) as f32;
            let eta = if spp > 0 {
                format!(", about {:.0} s left", elapsed / spp as f64 * (target - spp) as f64)
            } else {
                String::new()
            };
            ui.add(egui::ProgressBar::new(done).text(format!("rendering {spp}/{target} spp{eta}")));
            ui.small(s.reference_description());
        }
        ReferenceStatus::Ready { reference, note } => {
            let spp = if reference.spp > 0 { format!("{} spp, ", reference.spp) } else { String::new() };
            ui.label(format!("ready: {spp}{note}"));
            if reference.noise_mse() > 0.0 {
                ui.small(format!("its own RMSE (noise floor): {:.2e}", reference.noise_mse().sqrt()));
            }
        }
        ReferenceStatus::Failed(e) => {
            ui.colored_label(ui.visuals().error_fg_color, format!("reference failed: {e}"));
        }
    }
    ui.horizontal(|ui| {
        let mut spp = s.reference_spp();
        if ui.add(egui::DragValue::new(&mut spp).range(16..=65536).suffix(" spp")).changed() {
            s.set_reference_spp(spp);
        }
        if ui.button("Compute reference").clicked() {
            s.compute_reference();
        }
    });
    ui.horizontal(|ui| {
        let label = ui.label("EXR");
        ui.add(egui::TextEdit::singleline(&mut u.reference_path).hint_text("reference .exr").desired_width(150.0))
            .labelled_by(label.id);
        if ui.button("Load").clicked() && !u.reference_path.trim().is_empty() {
            s.load_reference(PathBuf::from(u.reference_path.trim()));
        }
        if ui.add_enabled(u.dialog.is_none(), egui::Button::new("Browse…")).clicked() {
            super::files::open_dialog(u, super::files::FileKind::Reference);
        }
    });
}
