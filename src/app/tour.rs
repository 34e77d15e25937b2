//! Presenting a tour: the caption (large enough for the back of a room), the keys a presenter remote sends, the
//! tour section of the side panel (present the lecture, open a tour file, save this view as a step). Stepping is
//! [`crate::tour::Presenter`]'s, on the session; this is its shell.

use super::viewer::{UiState, Viewer};
use crate::session::Session;
use crate::tour::{Caption, Presenter, Step, Tour, append_step};
use egui::{Key, RichText};

/// Sizes of the caption's text, in points (at the UI's zoom 1): readable from the back of a room at 1280×800.
const TITLE_SIZE: f32 = 30.0;
const FORMULA_SIZE: f32 = 22.0;
const TEXT_SIZE: f32 = 19.0;

impl Viewer {
    /// Goes to the next step of the tour (Page Down), if one is presented.
    pub fn next_step(&mut self) {
        step(&mut self.session, &mut self.ui, Move::Next);
    }

    /// Goes back one step (Page Up).
    pub fn previous_step(&mut self) {
        step(&mut self.session, &mut self.ui, Move::Previous);
    }
}

enum Move {
    Next,
    Previous,
    First,
    Last,
}

fn step(s: &mut Session, u: &mut UiState, m: Move) {
    let Some(p) = u.tour.as_mut() else { return };
    let last = p.tour.steps.len().saturating_sub(1);
    let to = match m {
        Move::Next => (p.index() + 1).min(last),
        Move::Previous => p.index().saturating_sub(1),
        Move::First => 0,
        Move::Last => last,
    };
    // Page Down on the last step (Page Up on the first) leaves the step, and what the presenter changed, alone.
    if to == p.index() {
        return;
    }
    u.error = p.go(to, s).err().map(|e| e.to_string());
    // The probe's window opens with a step that probes, and closes with one that does not.
    u.probe.open = s.probe_pixel().is_some();
}

/// Page Down / Page Up (what presenter remotes send), the arrow keys, Home / End, and T for the presenter view.
pub(super) fn keys(s: &mut Session, u: &mut UiState, ui: &egui::Ui) {
    if u.tour.is_none() {
        return;
    }
    let pressed = |keys: &[Key]| ui.input(|i| keys.iter().any(|k| i.key_pressed(*k)));
    if pressed(&[Key::PageDown, Key::ArrowRight, Key::ArrowDown]) {
        step(s, u, Move::Next);
    }
    if pressed(&[Key::PageUp, Key::ArrowLeft, Key::ArrowUp]) {
        step(s, u, Move::Previous);
    }
    if pressed(&[Key::Home]) {
        step(s, u, Move::First);
    }
    if pressed(&[Key::End]) {
        step(s, u, Move::Last);
    }
    if pressed(&[Key::T]) {
        u.presenter_view = !u.presenter_view;
    }
}

/// The step's caption above the image: title, formula, what to look at, and where in the tour we are.
pub(super) fn caption_panel(s: &mut Session, u: &mut UiState, ui: &mut egui::Ui) {
    let Some(p) = &u.tour else { return };
    let (index, count) = (p.index(), p.tour.steps.len());
    let caption = p.step().caption.clone();
    let tour_title = p.tour.title.clone();
    let mut go = None;
    egui::Panel::top("caption").show(ui, |ui| {
        ui.add_space(6.0);
        ui.horizontal(|ui| {
            ui.label(RichText::new(&caption.title).size(TITLE_SIZE).strong());
            ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
                if ui.add_enabled(index + 1 < count, egui::Button::new(RichText::new("Next").size(18.0))).clicked() {
                    go = Some(Move::Next);
                }
                ui.label(RichText::new(format!("{tour_title} · {} / {count}", index + 1)).size(16.0));
                if ui.add_enabled(index > 0, egui::Button::new(RichText::new("Previous").size(18.0))).clicked() {
                    go = Some(Move::Previous);
                }
            });
        });
        if !caption.formula.is_empty() {
            // egui's fonts have no ‖: the norm is written |…|.
            ui.label(RichText::new(caption.formula.replace('‖', "|")).size(FORMULA_SIZE).monospace());
        }
        if !caption.text.is_empty() {
            ui.label(RichText::new(&caption.text).size(TEXT_SIZE));
        }
        if let Some(e) = &u.error {
            ui.colored_label(ui.visuals().error_fg_color, RichText::new(e).size(TEXT_SIZE));
        }
        ui.add_space(4.0);
    });
    if let Some(m) = go {
        step(s, u, m);
    }
}

/// The side panel's tour section.
pub(super) fn tour_ui(s: &mut Session, u: &mut UiState, ui: &mut egui::Ui) {
    ui.heading("Tour");
    if let Some(p) = &u.tour {
        let (index, titles) = (p.index(), p.tour.steps.iter().map(|s| s.caption.title.clone()).collect::<Vec<_>>());
        let mut chosen = index;
        egui::ComboBox::from_label("step")
            .selected_text(format!("{}. {}", index + 1, titles[index]))
            .width(230.0)
            .show_ui(ui, |ui| {
                for (i, t) in titles.iter().enumerate() {
                    ui.selectable_value(&mut chosen, i, format!("{}. {t}", i + 1));
                }
            });
        if chosen != index
            && let Some(p) = u.tour.as_mut()
        {
            u.error = p.go(chosen, s).err().map(|e| e.to_string());
            u.probe.open = s.probe_pixel().is_some();
        }
        ui.horizontal(|ui| {
            ui.checkbox(&mut u.presenter_view, "presenter view (T)");
            if ui.button("End tour").clicked() {
                u.tour = None;
                u.presenter_view = false;
            }
        });
        ui.small("Page Down / Page Up or the arrow keys step through it.");
    } else if ui.button("Present the lecture").on_hover_text("The bundled tour of \"Illumination Integrals\"").clicked()
    {
        present(s, u, Tour::lecture());
    }
    ui.horizontal(|ui| {
        let label = ui.label("tour file");
        ui.add(egui::TextEdit::singleline(&mut u.tour_path).hint_text("my-tour.toml").desired_width(150.0))
            .labelled_by(label.id);
        if ui.button("Present").clicked() && !u.tour_path.trim().is_empty() {
            let path = u.tour_path.trim().to_string();
            open_tour(s, u, &path);
        }
    });
    if ui
        .button("Save this view as a step")
        .on_hover_text("Appends the current settings (scene, strategies, view, camera, probe …) to the tour file")
        .clicked()
    {
        save_step(s, u);
    }
}

/// Presents `tour` from its first step; an error is shown and the viewer keeps running.
pub(super) fn present(s: &mut Session, u: &mut UiState, tour: Tour) {
    match Presenter::start(tour.clone(), s) {
        Ok(p) => {
            u.tour = Some(p);
            u.error = None;
        }
        Err(e) => {
            u.error = Some(e.to_string());
            u.tour = (!tour.steps.is_empty()).then(|| Presenter::new(tour, s));
        }
    }
    u.presenter_view = true;
    u.probe.open = s.probe_pixel().is_some();
}

/// Opens and presents a tour file; an invalid one is one error on screen.
pub(super) fn open_tour(s: &mut Session, u: &mut UiState, path: &str) {
    match Tour::load(path) {
        Ok(tour) => {
            u.tour_path = path.to_string();
            present(s, u, tour);
        }
        Err(e) => u.error = Some(e.to_string()),
    }
}

/// A `.toml` file with `[[step]]` tables is a tour, not a scene.
pub(super) fn is_tour_file(path: &std::path::Path) -> bool {
    std::fs::read_to_string(path)
        .ok()
        .and_then(|t| t.parse::<toml::Table>().ok())
        .is_some_and(|t| t.contains_key("step"))
}

/// Appends the current view to the tour file, with the presented step's caption (or a numbered title).
fn save_step(s: &Session, u: &mut UiState) {
    let path = match u.tour_path.trim() {
        "" => "my-tour.toml".to_string(),
        p => p.to_string(),
    };
    let caption = u.tour.as_ref().map(|p| p.step().caption.clone()).unwrap_or_else(|| Caption {
        title: format!("{} with {}", s.scene().name, s.settings().strategy.name()),
        ..Caption::default()
    });
    match append_step(std::path::Path::new(&path), &Step::from_session(s, caption)) {
        Ok(()) => {
            u.message = Some(format!("appended a step to {path}"));
            u.tour_path = path;
        }
        Err(e) => u.error = Some(e),
    }
}
