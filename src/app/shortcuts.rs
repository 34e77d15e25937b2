//! Keyboard for the classroom, and the help window that lists it.

use super::viewer::Viewer;
use crate::render::Strategy;
use crate::session::views::View;
use egui::Key;

/// Shortcuts and what they do, in the order the help window lists them.
pub const SHORTCUTS: &[(&str, &str)] = &[
    ("1 – 9", "choose a strategy"),
    ("Space", "pause / resume"),
    ("R", "restart accumulation"),
    ("+ / −", "exposure up / down by half a stop"),
    ("S", "save a screenshot (PNG, EXR, JSON)"),
    ("C", "compare mode on / off"),
    ("X", "swap A and B"),
    ("V", "next view: image, error maps"),
    ("P", "convergence plot"),
    ("F", "hide / show the panels"),
    ("I", "probe mode on / off (then click a point); hold I and hover to probe"),
    ("Ctrl + click", "probe the point under the cursor"),
    ("F1 or ?", "this help"),
    ("left drag", "orbit"),
    ("right or middle drag, shift + drag", "pan"),
    ("scroll", "zoom"),
    ("double-click", "reset the camera"),
    ("right-click", "pick the material under the cursor"),
];

pub fn handle(v: &mut Viewer, ui: &mut egui::Ui) {
    if ui.ctx().egui_wants_keyboard_input() {
        return; // typing in a text field
    }
    let keys = [Key::Num1, Key::Num2, Key::Num3, Key::Num4, Key::Num5, Key::Num6, Key::Num7, Key::Num8, Key::Num9];
    let pressed = |k: Key| ui.input(|i| i.key_pressed(k));
    for (i, k) in keys.into_iter().enumerate() {
        if pressed(k)
            && let Some(&s) = Strategy::ALL.get(i)
        {
            v.set_strategy(s);
        }
    }
    if pressed(Key::I) {
        v.probe.mode = !v.probe.mode;
        v.probe.open |= v.probe.mode;
    }
    if pressed(Key::Space) {
        v.set_paused(!v.paused);
    }
    if pressed(Key::R) {
        v.restart();
    }
    if pressed(Key::Plus) || pressed(Key::Equals) {
        v.set_exposure(v.exposure + 0.5);
    }
    if pressed(Key::Minus) {
        v.set_exposure(v.exposure - 0.5);
    }
    if pressed(Key::S) {
        v.screenshot();
    }
    if pressed(Key::C) {
        v.set_comparing(!v.comparing);
    }
    if pressed(Key::X) && v.comparing {
        v.swap_lanes();
    }
    if pressed(Key::V) {
        let views: Vec<View> = View::ALL.into_iter().filter(|w| v.comparing || !w.needs_comparison()).collect();
        let next = views.iter().position(|w| *w == v.view).map_or(0, |i| (i + 1) % views.len());
        v.set_view(views[next]);
    }
    if pressed(Key::P) {
        if v.show_plot {
            v.show_plot = false;
        } else {
            v.show_convergence_plot();
        }
    }
    if pressed(Key::F) {
        v.hide_panels = !v.hide_panels;
    }
    if pressed(Key::F1) || pressed(Key::Questionmark) {
        v.show_help = !v.show_help;
    }
}

pub fn help_window(v: &mut Viewer, ui: &mut egui::Ui) {
    let mut open = v.show_help;
    egui::Window::new("Shortcuts").open(&mut open).resizable(false).show(ui.ctx(), |ui| {
        egui::Grid::new("shortcuts").striped(true).show(ui, |ui| {
            for (key, what) in SHORTCUTS {
                ui.strong(*key);
                ui.label(*what);
                ui.end_row();
            }
        });
    });
    v.show_help = open;
}
