//! The side panel: scene, strategy, light selection, comparison, sampling budget, seed, exposure, Phong material,
//! export.

use super::viewer::UiState;
use crate::render::{Heuristic, RenderSettings, Strategy};
use crate::scene::{BUNDLED_SCENES, LightSelection};
use crate::session::Session;
use crate::session::worker::PassSize;
use glam::Vec3;

pub fn controls_ui(s: &mut Session, u: &mut UiState, ui: &mut egui::Ui) {
    if let Some(error) = u.error.clone() {
        ui.colored_label(ui.visuals().error_fg_color, format!("Error: {error}"));
        if ui.button("Dismiss").clicked() {
            u.error = None;
        }
        ui.separator();
    }
    super::tour::tour_ui(s, u, ui);
    ui.separator();
    scene_ui(s, u, ui);
    ui.separator();
    strategy_ui(s, ui);
    ui.separator();
    super::compare::compare_ui(s, u, ui);
    ui.separator();
    sampling_ui(s, u, ui);
    ui.separator();
    material_ui(s, u, ui);
    ui.separator();
    export_ui(s, u, ui);
}

fn scene_ui(s: &mut Session, u: &mut UiState, ui: &mut egui::Ui) {
    ui.heading("Scene");
    let current = s.scene().name.clone();
    egui::ComboBox::from_label("bundled").selected_text(&current).show_ui(ui, |ui| {
        for b in BUNDLED_SCENES {
            if ui.selectable_label(b.name == current, b.name).clicked() && b.name != current {
                u.open(b.name.to_string());
            }
        }
    });
    ui.horizontal(|ui| {
        let label = ui.label("file");
        ui.add(egui::TextEdit::singleline(&mut u.open_path).hint_text("scene .toml or .obj").desired_width(170.0))
            .labelled_by(label.id);
        if ui.button("Open").clicked() && !u.open_path.trim().is_empty() {
            let path = u.open_path.trim().to_string();
            if super::tour::is_tour_file(std::path::Path::new(&path)) {
                super::tour::open_tour(s, u, &path);
            } else {
                u.open(path);
            }
        }
        if ui.add_enabled(u.dialog.is_none(), egui::Button::new("Browse…")).clicked() {
            super::files::open_dialog(u, super::files::FileKind::Scene);
        }
    });
    if !u.recent.entries.is_empty() {
        let mut chosen = None;
        egui::ComboBox::from_label("recent").selected_text("open a recent file").width(220.0).show_ui(ui, |ui| {
            for path in &u.recent.entries {
                if ui.selectable_label(false, path.as_str()).clicked() {
                    chosen = Some(path.clone());
                }
            }
        });
        if let Some(path) = chosen {
            u.open_path = path.clone();
            u.open(path);
        }
    }
    ui.small("or drop a .toml or .obj file on the window");
    if let Some(l) = &u.loading {
        ui.horizontal(|ui| {
            ui.spinner();
            ui.label(format!("loading {} ({:.1} s)", l.what, l.started.elapsed().as_secs_f32()));
        });
    }
    // What loading ignored or replaced (MTL statements, missing files, degenerate triangles): never silent.
    for w in &s.scene().warnings {
        ui.colored_label(ui.visuals().warn_fg_color, format!("warning: {w}"));
    }
}

fn strategy_ui(s: &mut Session, ui: &mut egui::Ui) {
    ui.heading("Strategy");
    for (i, strategy) in Strategy::ALL.into_iter().enumerate() {
        let r = ui.radio(s.settings().strategy == strategy, format!("{} {}", i + 1, strategy.name()));
        if r.clicked() {
            s.set_strategy(strategy);
        }
    }
    let strategy = s.settings().strategy;
    ui.label(strategy.description());
    ui.label(egui::RichText::new(strategy.pdf_formula()).monospace());
    if strategy == Strategy::Mis {
        mis_ui(s, ui);
    }
    if Strategy::learns(&s.settings()) || (s.is_comparing() && Strategy::learns(&s.settings_b())) {
        guide_ui(s, ui);
    }
    let mut selection = s.settings().light_selection;
    egui::ComboBox::from_label("light selection p_Δ").selected_text(selection.name()).show_ui(ui, |ui| {
        for l in LightSelection::ALL {
            ui.selectable_value(&mut selection, l, l.name());
        }
    });
    s.set_settings(RenderSettings { light_selection: selection, ..s.settings() });
}

/// MIS: which two techniques, which heuristic, and how a pixel sample's directions split between the two.
fn mis_ui(s: &mut Session, ui: &mut egui::Ui) {
    let mut mis = s.settings().mis;
    for (i, label) in ["MIS technique 1", "MIS technique 2"].into_iter().enumerate() {
        egui::ComboBox::from_label(label).selected_text(mis.techniques[i].name()).show_ui(ui, |ui| {
            for t in Strategy::techniques() {
                ui.selectable_value(&mut mis.techniques[i], t, t.name());
            }
        });
    }
    ui.horizontal(|ui| {
        for h in Heuristic::ALL {
            ui.radio_value(&mut mis.heuristic, h, h.name());
        }
        ui.label("heuristic");
    });
    // Only a move of the slider re-splits: a split set elsewhere (the command line's 1,1) stays as it is.
    let mut first = mis.samples[0].min(MIS_DIRECTIONS);
    if ui.add(egui::Slider::new(&mut first, 0..=MIS_DIRECTIONS).text("technique 1 / 2 split")).changed() {
        mis.samples = [first, MIS_DIRECTIONS - first];
    }
    let [a, b] = mis.techniques.map(|t| t.name());
    ui.small(format!("{} {a} + {} {b} directions per pixel sample", mis.samples[0], mis.samples[1]));
    s.set_settings(RenderSettings { mis, ..s.settings() });
}

/// Path guiding: how long the guide learns, whether its training samples count, and starting it again.
fn guide_ui(s: &mut Session, ui: &mut egui::Ui) {
    let mut guiding = s.settings().guiding;
    ui.add(egui::Slider::new(&mut guiding.training_spp, 0..=1024).logarithmic(true).text("training spp"))
        .on_hover_text(
            "Iterations of 1, 2, 4, … samples per pixel learn the guide until this budget, then it is frozen",
        );
    ui.checkbox(&mut guiding.discard_training, "discard training samples")
        .on_hover_text("Leave the training passes out of the image (each pass is unbiased either way)");
    s.set_settings(RenderSettings { guiding, ..s.settings() });
    if ui.button("Reset guide").on_hover_text("Forget what the guide learned and learn again").clicked() {
        s.reset_guide();
    }
}

/// Directions per pixel sample that the MIS split slider shares out.
const MIS_DIRECTIONS: u32 = 4;

fn sampling_ui(s: &mut Session, u: &mut UiState, ui: &mut egui::Ui) {
    ui.heading("Sampling");
    let mut auto_pass = s.pass_size() == PassSize::Auto;
    if let PassSize::Fixed(n) = s.pass_size() {
        u.spp_per_pass = n;
    }
    let mut target_spp = s.target_spp();
    let mut changed = ui
        .checkbox(&mut auto_pass, "passes sized by time")
        .on_hover_text("Each pass lasts 30–250 ms at the rate measured so far (the first one sample per pixel)")
        .changed();
    changed |=
        ui.add_enabled(!auto_pass, egui::Slider::new(&mut u.spp_per_pass, 1..=64).text("spp per pass")).changed();
    ui.horizontal(|ui| {
        let mut limited = target_spp.is_some();
        changed |= ui.checkbox(&mut limited, "stop at").changed();
        let mut target = target_spp.unwrap_or(256);
        changed |=
            ui.add_enabled(limited, egui::DragValue::new(&mut target).range(1..=1_000_000).suffix(" spp")).changed();
        target_spp = limited.then_some(target);
    });
    if changed {
        let size = if auto_pass { PassSize::Auto } else { PassSize::Fixed(u.spp_per_pass) };
        s.set_sampling(size, target_spp);
    }
    let mut seed = s.settings().seed;
    if ui.add(egui::DragValue::new(&mut seed).prefix("seed ")).changed() {
        s.set_settings(RenderSettings { seed, ..s.settings() });
    }
    ui.horizontal(|ui| {
        ui.label("resolution");
        for long_side in [128, 256, 512, 1024] {
            let current = s.camera().width.max(s.camera().height) == long_side;
            if ui.selectable_label(current, long_side.to_string()).clicked() {
                s.set_resolution(long_side);
            }
        }
    });
    let mut exposure = s.exposure();
    if ui.add(egui::Slider::new(&mut exposure, -10.0..=10.0).step_by(0.25).text("exposure (stops)")).changed() {
        s.set_exposure(exposure);
    }
    ui.checkbox(&mut u.one_to_one, "1:1 pixels");
    ui.horizontal(|ui| {
        let label = if s.is_paused() { "Resume" } else { "Pause" };
        if ui.button(label).clicked() {
            s.set_paused(!s.is_paused());
        }
        if ui.button("Restart").clicked() {
            s.restart();
        }
    });
}

fn material_ui(s: &mut Session, u: &mut UiState, ui: &mut egui::Ui) {
    ui.heading("Material");
    let scene = s.scene().clone();
    if scene.materials.is_empty() {
        ui.label("(none)");
        return;
    }
    u.selected_material = u.selected_material.min(scene.materials.len() - 1);
    let name = |i: usize| scene.material_names.get(i).cloned().unwrap_or_else(|| format!("#{i}"));
    egui::ComboBox::from_label("material").selected_text(name(u.selected_material)).show_ui(ui, |ui| {
        for i in 0..scene.materials.len() {
            ui.selectable_value(&mut u.selected_material, i, name(i));
        }
    });
    ui.small("or right-click the image to pick the material under the cursor");
    let mut m = scene.materials[u.selected_material];
    rgb_ui(ui, "k_d", &mut m.kd);
    rgb_ui(ui, "k_s", &mut m.ks);
    ui.add(egui::Slider::new(&mut m.alpha, 0.0..=1e5).logarithmic(true).text("α"));
    if m.is_emissive() {
        ui.label(format!("emits L_e = ({:.3}, {:.3}, {:.3})", m.emission.x, m.emission.y, m.emission.z));
    }
    if m.exceeds_energy_conservation() {
        ui.colored_label(ui.visuals().warn_fg_color, "Warning: k_d + k_s > 1 is not energy-conserving");
    }
    s.set_material(u.selected_material, m);
}

fn rgb_ui(ui: &mut egui::Ui, label: &str, c: &mut Vec3) {
    ui.horizontal(|ui| {
        ui.label(label);
        for (value, channel) in [(&mut c.x, "r"), (&mut c.y, "g"), (&mut c.z, "b")] {
            ui.add(
                egui::DragValue::new(value).range(0.0..=1.0).speed(0.005).max_decimals(3).prefix(format!("{channel} ")),
            );
        }
    });
}

fn export_ui(s: &mut Session, u: &mut UiState, ui: &mut egui::Ui) {
    ui.heading("Screenshot");
    ui.horizontal(|ui| {
        let label = ui.label("folder");
        ui.text_edit_singleline(&mut u.export_folder).labelled_by(label.id);
    });
    if ui.button("Save screenshot (S)").clicked() {
        super::viewer::screenshot(s, u);
    }
    if let Some(m) = &u.message {
        ui.label(m);
    }
}
