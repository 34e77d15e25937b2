//! The side panel's comparison section: compare mode with B's strategy, swap, budget, layout and wipe; the view
//! (image or error map); the reference (status, spp, compute, load an EXR); export.

use super::viewer::Viewer;
use crate::render::{Footprint, Strategy};
use crate::session::views::View;
use crate::session::worker::{Budget, ReferenceStatus};
use std::path::PathBuf;

pub fn compare_ui(v: &mut Viewer, ui: &mut egui::Ui) {
    ui.heading("Compare");
    let mut on = v.comparing;
    if ui.checkbox(&mut on, "Compare A | B (C)").changed() {
        v.set_comparing(on);
    }
    if v.comparing {
        ui.horizontal(|ui| {
            ui.label(format!("A: {}", v.settings.strategy.name()));
            let mut b = v.settings_b.strategy;
            egui::ComboBox::from_label("B strategy").selected_text(b.name()).show_ui(ui, |ui| {
                for s in Strategy::ALL {
                    ui.selectable_value(&mut b, s, s.name());
                }
            });
            v.set_strategy_b(b);
        });
        if ui.button("Swap A/B (X)").clicked() {
            v.swap_lanes();
        }
        ui.horizontal(|ui| {
            for budget in [Budget::EqualSamples, Budget::EqualTime] {
                if ui.radio(v.budget == budget, budget.name()).clicked() {
                    v.set_budget(budget);
                }
            }
        });
        ui.small(match v.budget {
            Budget::EqualSamples => "both reach the same spp",
            Budget::EqualTime => "both get the same CPU time; each shows its own spp",
        });
        ui.checkbox(&mut v.side_by_side, "side by side");
        let mut wipe = v.wipe;
        if ui.add_enabled(!v.side_by_side, egui::Slider::new(&mut wipe, 0.0..=1.0).text("wipe")).changed() {
            v.set_wipe(wipe);
        }
        ui.small("Same seed, same random streams per pixel: the difference you see is the estimator.");
    }
    ui.separator();
    view_ui(v, ui);
    footprint_ui(v, ui);
    ui.separator();
    reference_ui(v, ui);
    if v.comparing {
        ui.separator();
        if ui.button("Export comparison").clicked() {
            v.export_comparison();
        }
    }
    if ui.button("Convergence plot (P)").clicked() {
        if v.show_plot {
            v.show_plot = false;
        } else {
            v.show_convergence_plot();
        }
    }
}

fn view_ui(v: &mut Viewer, ui: &mut egui::Ui) {
    ui.heading("View");
    let mut view = v.view;
    egui::ComboBox::from_label("show").selected_text(view.name()).show_ui(ui, |ui| {
        for option in View::ALL {
            if option.needs_comparison() && !v.comparing {
                continue;
            }
            ui.selectable_value(&mut view, option, option.name());
        }
    });
    v.set_view(view);
    if view != View::Image {
        ui.small(view.description());
    }
}

/// Pictures or measurements: a jittered footprint antialiases, fixed primary hits leave the estimator's error
/// alone (and a reference rendered the same way).
fn footprint_ui(v: &mut Viewer, ui: &mut egui::Ui) {
    let mut fixed = v.settings.footprint == Footprint::Centre;
    if ui
        .checkbox(&mut fixed, "Fixed primary hits (measure the estimator)")
        .on_hover_text(
            "Every sample goes through its pixel's centre: the jitter of the pixel footprint, common to every \
             strategy, leaves the error, and the reference is rendered the same way. Off: a box filter, for pictures.",
        )
        .changed()
    {
        v.set_footprint(if fixed { Footprint::Centre } else { Footprint::Jittered });
    }
    ui.small(format!("Errors: {}.", v.settings.footprint.description()));
}

fn reference_ui(v: &mut Viewer, ui: &mut egui::Ui) {
    ui.heading("Reference");
    match &v.reference {
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
            ui.small("MIS (projected solid angle + BRDF, power heuristic), its own seed");
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
        ui.add(egui::DragValue::new(&mut v.reference_spp).range(16..=65536).suffix(" spp"));
        if ui.button("Compute reference").clicked() {
            v.compute_reference();
        }
    });
    ui.horizontal(|ui| {
        let label = ui.label("EXR");
        ui.add(egui::TextEdit::singleline(&mut v.reference_path).hint_text("reference .exr").desired_width(150.0))
            .labelled_by(label.id);
        if ui.button("Load").clicked() && !v.reference_path.trim().is_empty() {
            v.load_reference(PathBuf::from(v.reference_path.trim()));
        }
        if ui.add_enabled(v.dialog.is_none(), egui::Button::new("Browse…")).clicked() {
            v.open_dialog(super::files::FileKind::Reference);
        }
    });
}
