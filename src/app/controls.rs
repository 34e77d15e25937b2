//! The side panel: scene, strategy, light selection, comparison, sampling budget, seed, exposure, Phong material,
//! export.

use super::viewer::Viewer;
use crate::render::{Heuristic, Strategy};
use crate::scene::{BUNDLED_SCENES, LightSelection};
use glam::Vec3;

pub fn controls_ui(v: &mut Viewer, ui: &mut egui::Ui) {
    if let Some(error) = v.error.clone() {
        ui.colored_label(ui.visuals().error_fg_color, format!("Error: {error}"));
        if ui.button("Dismiss").clicked() {
            v.error = None;
        }
        ui.separator();
    }
    scene_ui(v, ui);
    ui.separator();
    strategy_ui(v, ui);
    ui.separator();
    super::compare::compare_ui(v, ui);
    ui.separator();
    sampling_ui(v, ui);
    ui.separator();
    material_ui(v, ui);
    ui.separator();
    export_ui(v, ui);
}

fn scene_ui(v: &mut Viewer, ui: &mut egui::Ui) {
    ui.heading("Scene");
    let current = v.scene.name.clone();
    egui::ComboBox::from_label("bundled").selected_text(&current).show_ui(ui, |ui| {
        for s in BUNDLED_SCENES {
            if ui.selectable_label(s.name == current, s.name).clicked() && s.name != current {
                v.open(s.name.to_string());
            }
        }
    });
    ui.horizontal(|ui| {
        let label = ui.label("file");
        ui.add(egui::TextEdit::singleline(&mut v.open_path).hint_text("scene .toml or .obj").desired_width(170.0))
            .labelled_by(label.id);
        if ui.button("Open").clicked() && !v.open_path.trim().is_empty() {
            v.open(v.open_path.trim().to_string());
        }
        if ui.add_enabled(v.dialog.is_none(), egui::Button::new("Browse…")).clicked() {
            v.open_dialog(super::files::FileKind::Scene);
        }
    });
    if !v.recent.entries.is_empty() {
        let mut chosen = None;
        egui::ComboBox::from_label("recent").selected_text("open a recent file").width(220.0).show_ui(ui, |ui| {
            for path in &v.recent.entries {
                if ui.selectable_label(false, path.as_str()).clicked() {
                    chosen = Some(path.clone());
                }
            }
        });
        if let Some(path) = chosen {
            v.open_path = path.clone();
            v.open(path);
        }
    }
    ui.small("or drop a .toml or .obj file on the window");
    if let Some(l) = &v.loading {
        ui.horizontal(|ui| {
            ui.spinner();
            ui.label(format!("loading {} ({:.1} s)", l.what, l.started.elapsed().as_secs_f32()));
        });
    }
    // What loading ignored or replaced (MTL statements, missing files, degenerate triangles): never silent.
    for w in &v.scene.warnings {
        ui.colored_label(ui.visuals().warn_fg_color, format!("warning: {w}"));
    }
}

fn strategy_ui(v: &mut Viewer, ui: &mut egui::Ui) {
    ui.heading("Strategy");
    for (i, s) in Strategy::ALL.into_iter().enumerate() {
        let r = ui.radio(v.settings.strategy == s, format!("{} {}", i + 1, s.name()));
        if r.clicked() {
            v.set_strategy(s);
        }
    }
    let s = v.settings.strategy;
    ui.label(s.description());
    ui.label(egui::RichText::new(s.pdf_formula()).monospace());
    if s == Strategy::Mis {
        mis_ui(v, ui);
    }
    if Strategy::learns(&v.settings) || (v.comparing && Strategy::learns(&v.settings_b)) {
        guide_ui(v, ui);
    }
    let mut selection = v.settings.light_selection;
    egui::ComboBox::from_label("light selection p_Δ").selected_text(selection.name()).show_ui(ui, |ui| {
        for l in LightSelection::ALL {
            ui.selectable_value(&mut selection, l, l.name());
        }
    });
    if selection != v.settings.light_selection {
        v.settings.light_selection = selection;
        v.apply_settings();
    }
}

/// MIS: which two techniques, which heuristic, and how a pixel sample's directions split between the two.
fn mis_ui(v: &mut Viewer, ui: &mut egui::Ui) {
    let mut mis = v.settings.mis;
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
    if mis != v.settings.mis {
        v.settings.mis = mis;
        v.apply_settings();
    }
}

/// Path guiding: how long the guide learns, whether its training samples count, and starting it again.
fn guide_ui(v: &mut Viewer, ui: &mut egui::Ui) {
    let mut guiding = v.settings.guiding;
    ui.add(egui::Slider::new(&mut guiding.training_spp, 0..=1024).logarithmic(true).text("training spp"))
        .on_hover_text(
            "Iterations of 1, 2, 4, … samples per pixel learn the guide until this budget, then it is frozen",
        );
    ui.checkbox(&mut guiding.discard_training, "discard training samples")
        .on_hover_text("Leave the training passes out of the image (each pass is unbiased either way)");
    if guiding != v.settings.guiding {
        v.settings.guiding = guiding;
        v.apply_settings();
    }
    if ui.button("Reset guide").on_hover_text("Forget what the guide learned and learn again").clicked() {
        v.reset_guide();
    }
}

/// Directions per pixel sample that the MIS split slider shares out.
const MIS_DIRECTIONS: u32 = 4;

fn sampling_ui(v: &mut Viewer, ui: &mut egui::Ui) {
    ui.heading("Sampling");
    let mut changed = ui
        .checkbox(&mut v.auto_pass, "passes sized by time")
        .on_hover_text("Each pass lasts 30–250 ms at the rate measured so far (the first one sample per pixel)")
        .changed();
    changed |=
        ui.add_enabled(!v.auto_pass, egui::Slider::new(&mut v.spp_per_pass, 1..=64).text("spp per pass")).changed();
    ui.horizontal(|ui| {
        let mut limited = v.target_spp.is_some();
        changed |= ui.checkbox(&mut limited, "stop at").changed();
        let mut target = v.target_spp.unwrap_or(256);
        changed |=
            ui.add_enabled(limited, egui::DragValue::new(&mut target).range(1..=1_000_000).suffix(" spp")).changed();
        v.target_spp = limited.then_some(target);
    });
    if changed {
        v.send_spp();
    }
    let mut seed = v.settings.seed;
    if ui.add(egui::DragValue::new(&mut seed).prefix("seed ")).changed() {
        v.settings.seed = seed;
        v.apply_settings();
    }
    ui.horizontal(|ui| {
        ui.label("resolution");
        for long_side in [128, 256, 512, 1024] {
            let current = v.camera.width.max(v.camera.height) == long_side;
            if ui.selectable_label(current, long_side.to_string()).clicked() {
                v.set_resolution(long_side);
            }
        }
    });
    let mut exposure = v.exposure;
    if ui.add(egui::Slider::new(&mut exposure, -10.0..=10.0).step_by(0.25).text("exposure (stops)")).changed() {
        v.set_exposure(exposure);
    }
    ui.checkbox(&mut v.one_to_one, "1:1 pixels");
    ui.horizontal(|ui| {
        let label = if v.paused { "Resume" } else { "Pause" };
        if ui.button(label).clicked() {
            v.set_paused(!v.paused);
        }
        if ui.button("Restart").clicked() {
            v.restart();
        }
    });
}

fn material_ui(v: &mut Viewer, ui: &mut egui::Ui) {
    ui.heading("Material");
    if v.scene.materials.is_empty() {
        ui.label("(none)");
        return;
    }
    v.selected_material = v.selected_material.min(v.scene.materials.len() - 1);
    let name = |i: usize, v: &Viewer| v.scene.material_names.get(i).cloned().unwrap_or_else(|| format!("#{i}"));
    let selected = name(v.selected_material, v);
    egui::ComboBox::from_label("material").selected_text(selected).show_ui(ui, |ui| {
        for i in 0..v.scene.materials.len() {
            let n = name(i, v);
            ui.selectable_value(&mut v.selected_material, i, n);
        }
    });
    ui.small("or right-click the image to pick the material under the cursor");
    let mut m = v.scene.materials[v.selected_material];
    rgb_ui(ui, "k_d", &mut m.kd);
    rgb_ui(ui, "k_s", &mut m.ks);
    ui.add(egui::Slider::new(&mut m.alpha, 0.0..=1e5).logarithmic(true).text("α"));
    if m.is_emissive() {
        ui.label(format!("emits L_e = ({:.3}, {:.3}, {:.3})", m.emission.x, m.emission.y, m.emission.z));
    }
    if m.exceeds_energy_conservation() {
        ui.colored_label(ui.visuals().warn_fg_color, "Warning: k_d + k_s > 1 is not energy-conserving");
    }
    v.set_material(v.selected_material, m);
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

fn export_ui(v: &mut Viewer, ui: &mut egui::Ui) {
    ui.heading("Screenshot");
    ui.horizontal(|ui| {
        let label = ui.label("folder");
        ui.text_edit_singleline(&mut v.export_folder).labelled_by(label.id);
    });
    if ui.button("Save screenshot (S)").clicked() {
        v.screenshot();
    }
    if let Some(m) = &v.message {
        ui.label(m);
    }
}
