//! Keyboard for the classroom, and the help window that lists it.

use super::viewer::UiState;
use crate::render::Strategy;
use crate::session::Session;
use crate::session::views::View;
use egui::Key;

/// Shortcuts and what they do, in the order the help window lists them.
pub const SHORTCUTS: &[(&str, &str)] = &[
    ("Page Down, → or ↓", "tour: next step (what presenter remotes send)"),
    ("Page Up, ← or ↑", "tour: previous step"),
    ("Home / End", "tour: first / last step"),
    ("T", "tour: presenter view on / off (image, caption and probe only)"),
    ("Ctrl + / Ctrl − / Ctrl 0", "UI larger / smaller / default (remembered)"),
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

pub fn handle(s: &mut Session, u: &mut UiState, ui: &mut egui::Ui) {
    if ui.ctx().egui_wants_keyboard_input() {
        return; // typing in a text field
    }
    let pressed = |k: Key| ui.input(|i| i.key_pressed(k));
    // Ctrl + / − / 0 scale the UI (egui's zoom); they must not also change the exposure.
    let command = ui.input(|i| i.modifiers.command);
    super::tour::keys(s, u, ui);
    let keys = [Key::Num1, Key::Num2, Key::Num3, Key::Num4, Key::Num5, Key::Num6, Key::Num7, Key::Num8, Key::Num9];
    for (i, k) in keys.into_iter().enumerate() {
        if pressed(k)
            && !command
            && let Some(&strategy) = Strategy::ALL.get(i)
        {
            s.set_strategy(strategy);
        }
    }
    if pressed(Key::I) {
        u.probe.mode = !u.probe.mode;
        u.probe.open |= u.probe.mode;
    }
    if pressed(Key::Space) {
        s.set_paused(!s.is_paused());
    }
    if pressed(Key::R) {
        s.restart();
    }
    if !command && (pressed(Key::Plus) || pressed(Key::Equals)) {
        s.set_exposure(s.exposure() + 0.5);
    }
    if !command && pressed(Key::Minus) {
        s.set_exposure(s.exposure() - 0.5);
    }
    if pressed(Key::S) {
        super::viewer::screenshot(s, u);
    }
    if pressed(Key::C) {
        s.set_comparing(!s.is_comparing());
    }
    if pressed(Key::X) && s.is_comparing() {
        s.swap_lanes();
    }
    if pressed(Key::V) {
        let views: Vec<View> = View::ALL.into_iter().filter(|w| s.is_comparing() || !w.needs_comparison()).collect();
        let next = views.iter().position(|w| *w == s.view()).map_or(0, |i| (i + 1) % views.len());
        s.set_view(views[next]);
    }
    if pressed(Key::P) {
        super::convergence::toggle_plot(s, u);
    }
    if pressed(Key::F) {
        u.hide_panels = !u.hide_panels;
    }
    if pressed(Key::F1) || pressed(Key::Questionmark) {
        u.show_help = !u.show_help;
    }
}

pub fn help_window(u: &mut UiState, ui: &mut egui::Ui) {
    let mut open = u.show_help;
    egui::Window::new("Shortcuts").open(&mut open).resizable(false).show(ui.ctx(), |ui| {
        egui::Grid::new("shortcuts").striped(true).show(ui, |ui| {
            for (key, what) in SHORTCUTS {
                ui.strong(*key);
                ui.label(*what);
                ui.end_row();
            }
        });
    });
    u.show_help = open;
}
