//! The central view: the accumulated image (or an error map), kept at its aspect ratio (or 1:1 pixels), with
//! orbit (left drag), pan (right or middle drag, or shift + left drag), zoom (scroll), reset (double-click) and
//! material picking (right-click). In compare mode A and B share the view, split by a draggable wipe line, or
//! stand side by side; error maps get a legend with their scale.

use super::orbit;
use super::viewer::UiState;
use crate::measure::gradient;
use crate::session::Session;
use crate::session::views::View;
use crate::session::worker::{A, B};

pub fn viewport_ui(s: &mut Session, u: &mut UiState, ui: &mut egui::Ui) {
    let ctx = ui.ctx().clone();
    let [Some(tex_a), tex_b] = super::frames::textures(s, u, &ctx) else {
        ui.centered_and_justified(|ui| ui.spinner());
        return;
    };
    let Some(frame) = s.frame().cloned() else { return };
    let legend_height = if s.view() == View::Image { 0.0 } else { 44.0 };
    let mut available = ui.available_size() - egui::vec2(0.0, legend_height);
    let side_by_side = s.is_comparing() && u.side_by_side && tex_b.is_some();
    if side_by_side {
        available.x = (available.x - 8.0) / 2.0;
    }
    let image_size = egui::vec2(frame.width as f32, frame.height as f32);
    let scale = if u.one_to_one {
        1.0 / ui.ctx().pixels_per_point()
    } else {
        (available.x / image_size.x).min(available.y / image_size.y).max(0.01)
    };
    let size = image_size * scale;
    let area = ui.max_rect();
    let center = area.center() - egui::vec2(0.0, legend_height / 2.0);
    let uv = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
    let painter = ui.painter().clone();

    // The image rect(s) and what the pointer does on them.
    let rects: Vec<egui::Rect> = if side_by_side {
        let offset = egui::vec2(size.x / 2.0 + 4.0, 0.0);
        vec![egui::Rect::from_center_size(center - offset, size), egui::Rect::from_center_size(center + offset, size)]
    } else {
        vec![egui::Rect::from_center_size(center, size)]
    };
    let mut responses = Vec::new();
    for (i, rect) in rects.iter().enumerate() {
        responses.push(ui.interact(*rect, ui.make_persistent_id(("image", i)), egui::Sense::click_and_drag()));
    }
    let rect = rects[0];
    u.image_rect = Some(rect);
    painter.image(tex_a, rect, uv, egui::Color32::WHITE);
    match (tex_b, side_by_side) {
        (Some(tex_b), true) => {
            painter.image(tex_b, rects[1], uv, egui::Color32::WHITE);
        }
        (Some(tex_b), false) if s.is_comparing() => {
            let x = rect.min.x + u.wipe * rect.width();
            let right = egui::Rect::from_min_max(egui::pos2(x, rect.min.y), rect.max);
            painter.with_clip_rect(right).image(tex_b, rect, uv, egui::Color32::WHITE);
            wipe_handle(u, ui, rect, x);
        }
        _ => {}
    }
    if s.is_comparing() {
        lane_labels(s, &painter, &rects);
    }
    if let Some(note) = u.view_note.filter(|_| s.view() != View::Image) {
        let at = rect.center_top() + egui::vec2(0.0, 28.0);
        let text = format!("{}: {note} (showing the image)", s.view().name());
        painter.text(at, egui::Align2::CENTER_TOP, text, egui::FontId::proportional(14.0), egui::Color32::YELLOW);
    }
    if s.view() != View::Image {
        let bar =
            egui::Rect::from_min_size(egui::pos2(area.center().x - 200.0, rect.max.y + 8.0), egui::vec2(400.0, 12.0));
        legend(s, u, &painter, bar);
    }

    if let Some((x, y)) = s.probe_marker() {
        for r in &rects {
            let at = r.min + egui::vec2(x as f32 + 0.5, y as f32 + 0.5) * scale;
            let stroke = egui::Stroke::new(2.0, egui::Color32::from_rgb(90, 200, 255));
            painter.circle_stroke(at, 7.0, stroke);
            painter.hline(at.x - 12.0..=at.x - 4.0, at.y, stroke);
            painter.hline(at.x + 4.0..=at.x + 12.0, at.y, stroke);
            painter.vline(at.x, at.y - 12.0..=at.y - 4.0, stroke);
            painter.vline(at.x, at.y + 4.0..=at.y + 12.0, stroke);
        }
    }
    for (i, response) in responses.iter().enumerate() {
        pointer(s, u, ui, response, rects[i], scale, size);
    }
}

/// The wipe line: drag it to move the split.
fn wipe_handle(u: &mut UiState, ui: &mut egui::Ui, rect: egui::Rect, x: f32) {
    let grip = egui::Rect::from_center_size(egui::pos2(x, rect.center().y), egui::vec2(12.0, rect.height()));
    let response = ui
        .interact(grip, ui.make_persistent_id("wipe"), egui::Sense::drag())
        .on_hover_cursor(egui::CursorIcon::ResizeHorizontal);
    if response.dragged()
        && let Some(p) = response.interact_pointer_pos()
    {
        u.wipe = ((p.x - rect.min.x) / rect.width()).clamp(0.0, 1.0);
    }
    let stroke =
        egui::Stroke::new(if response.hovered() || response.dragged() { 3.0 } else { 1.5 }, egui::Color32::WHITE);
    ui.painter().vline(x, rect.y_range(), stroke);
    ui.painter().circle_filled(egui::pos2(x, rect.center().y), 6.0, egui::Color32::WHITE);
}

/// "A: strategy, spp" in the top-left and "B: …" in the top-right corner.
fn lane_labels(s: &Session, painter: &egui::Painter, rects: &[egui::Rect]) {
    let font = egui::FontId::proportional(14.0);
    for (lane, frame) in [(A, s.frame().map(|f| &**f)), (B, s.frame_b().map(|f| &**f))] {
        let Some(f) = frame else { continue };
        let rect = rects.get(lane).unwrap_or(&rects[0]);
        let (pos, align) = match (lane, rects.len()) {
            (B, 1) => (rect.right_top() + egui::vec2(-6.0, 6.0), egui::Align2::RIGHT_TOP),
            _ => (rect.left_top() + egui::vec2(6.0, 6.0), egui::Align2::LEFT_TOP),
        };
        let text = format!(
            "{}: {}  {} spp  {:.2} s CPU",
            ["A", "B"][lane],
            f.settings.strategy.name(),
            f.spp,
            f.stats.cpu.as_secs_f64()
        );
        let galley = painter.layout_no_wrap(text, font.clone(), egui::Color32::WHITE);
        let r = align.anchor_size(pos, galley.size()).expand(3.0);
        painter.rect_filled(r, 3.0, egui::Color32::from_black_alpha(160));
        painter.galley(r.min + egui::vec2(3.0, 3.0), galley, egui::Color32::WHITE);
    }
}

/// The colour bar of the error map, its ticks (powers of ten) and what it shows.
fn legend(s: &Session, u: &UiState, painter: &egui::Painter, bar: egui::Rect) {
    let Some(scale) = u.scale.filter(|_| u.view_note.is_none()) else { return };
    let steps = 64;
    for k in 0..steps {
        let t0 = k as f32 / steps as f32;
        let [r, g, b, _] = gradient(t0 + 0.5 / steps as f32);
        let x0 = bar.min.x + t0 * bar.width();
        let cell = egui::Rect::from_min_max(
            egui::pos2(x0, bar.min.y),
            egui::pos2(x0 + bar.width() / steps as f32 + 0.5, bar.max.y),
        );
        painter.rect_filled(cell, 0.0, egui::Color32::from_rgb(r, g, b));
    }
    let font = egui::FontId::proportional(11.0);
    let color = painter.ctx().global_style().visuals.text_color();
    for (t, value) in scale.ticks() {
        let x = bar.min.x + t * bar.width();
        painter.vline(x, bar.max.y..=bar.max.y + 4.0, egui::Stroke::new(1.0, color));
        painter.text(
            egui::pos2(x, bar.max.y + 4.0),
            egui::Align2::CENTER_TOP,
            format!("{value:.0e}"),
            font.clone(),
            color,
        );
    }
    let text = format!("{} (log scale, shared by A and B): {}", s.view().name(), s.view().description());
    painter.text(bar.left_top() - egui::vec2(0.0, 2.0), egui::Align2::LEFT_BOTTOM, text, font, color);
}

/// Camera and picking on one image rect.
fn pointer(
    s: &mut Session,
    u: &mut UiState,
    ui: &egui::Ui,
    response: &egui::Response,
    rect: egui::Rect,
    scale: f32,
    size: egui::Vec2,
) {
    // The probe: a click in probe mode, Ctrl-click, or hovering with I held.
    let pixel_at = |pos: egui::Pos2| {
        let local = (pos - rect.min) / scale;
        (local.x >= 0.0 && local.y >= 0.0).then_some((local.x as u32, local.y as u32))
    };
    let probing_click = response.clicked() && (u.probe.mode || ui.input(|i| i.modifiers.command));
    let probing_hover =
        response.hovered() && ui.input(|i| i.key_down(egui::Key::I)) && !ui.ctx().egui_wants_keyboard_input();
    if (probing_click || probing_hover)
        && let Some(p) = response.interact_pointer_pos().or(response.hover_pos()).and_then(pixel_at)
    {
        super::probe::probe_pixel(s, u, p);
        return;
    }
    if response.double_clicked() {
        s.reset_camera();
        return;
    }
    let drag = response.drag_delta() / size.y;
    if drag != egui::Vec2::ZERO {
        let panning = response.dragged_by(egui::PointerButton::Secondary)
            || response.dragged_by(egui::PointerButton::Middle)
            || ui.input(|i| i.modifiers.shift);
        let camera = if panning {
            orbit::pan(&s.camera(), drag.x, drag.y)
        } else {
            orbit::orbit(&s.camera(), drag.x * std::f32::consts::PI, drag.y * std::f32::consts::PI)
        };
        s.set_camera(camera);
    }
    if response.hovered() {
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 {
            s.set_camera(orbit::zoom(&s.camera(), (-scroll * 0.002).exp()));
        }
    }
    if response.secondary_clicked()
        && let Some(pos) = response.interact_pointer_pos()
    {
        let local = (pos - rect.min) / scale;
        if let Some(t) = s.scene().pick(local.x as u32, local.y as u32) {
            u.selected_material = s.scene().triangles[t as usize].material as usize;
        }
    }
}
