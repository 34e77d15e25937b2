//! The central view: the accumulated image, kept at its aspect ratio (or 1:1 pixels), with orbit (left drag),
//! pan (right or middle drag, or shift + left drag), zoom (scroll), reset (double-click) and material picking
//! (right-click).

use super::orbit;
use super::viewer::Viewer;

pub fn viewport_ui(v: &mut Viewer, ui: &mut egui::Ui) {
    let available = ui.available_size();
    let ctx = ui.ctx().clone();
    let Some(texture) = v.texture(&ctx) else {
        ui.centered_and_justified(|ui| ui.spinner());
        return;
    };
    let image_size = texture.size_vec2();
    let texture_id = texture.id();
    let scale = if v.one_to_one {
        1.0 / ui.ctx().pixels_per_point()
    } else {
        (available.x / image_size.x).min(available.y / image_size.y).max(0.01)
    };
    let size = image_size * scale;
    let rect = egui::Rect::from_center_size(ui.max_rect().center(), size);
    let response = ui.allocate_rect(rect, egui::Sense::click_and_drag());
    ui.painter().image(
        texture_id,
        rect,
        egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0)),
        egui::Color32::WHITE,
    );

    if response.double_clicked() {
        v.reset_camera();
        return;
    }
    let drag = response.drag_delta() / size.y;
    if drag != egui::Vec2::ZERO {
        let panning = response.dragged_by(egui::PointerButton::Secondary)
            || response.dragged_by(egui::PointerButton::Middle)
            || ui.input(|i| i.modifiers.shift);
        let camera = if panning {
            orbit::pan(&v.camera, drag.x, drag.y)
        } else {
            orbit::orbit(&v.camera, drag.x * std::f32::consts::PI, drag.y * std::f32::consts::PI)
        };
        v.set_camera(camera);
    }
    if response.hovered() {
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 {
            v.set_camera(orbit::zoom(&v.camera, (-scroll * 0.002).exp()));
        }
    }
    if response.secondary_clicked()
        && let Some(pos) = response.interact_pointer_pos()
    {
        let local = (pos - rect.min) / scale;
        if let Some(t) = v.scene.pick(local.x as u32, local.y as u32) {
            v.selected_material = v.scene.triangles[t as usize].material as usize;
        }
    }
}
