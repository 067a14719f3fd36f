//! The axis gizmo in the top-right corner of the view: the world axes as
//! the camera sees them, and whether the view is orthographic. A click on
//! an axis end looks from that side (View ▸ Front view and the others).

use egui::{Color32, Pos2, Sense, Stroke, Vec2};
use glam::IVec3;

use super::command::AppCommand;
use octovox::camera::Camera;

/// Side of the gizmo's square, in points.
const SIZE: f32 = 84.0;
/// How far an axis end reaches from the centre.
const REACH: f32 = 30.0;
/// How near a click must come to an axis end to take it.
const HIT_RADIUS: f32 = 9.0;

/// The six axis ends: the world axis, its label and colour.
const ENDS: [(IVec3, &str, Color32); 6] = [
    (IVec3::X, "X", Color32::from_rgb(230, 80, 80)),
    (IVec3::Y, "Y", Color32::from_rgb(110, 200, 90)),
    (IVec3::Z, "Z", Color32::from_rgb(90, 140, 240)),
    (IVec3::NEG_X, "", Color32::from_rgb(150, 60, 60)),
    (IVec3::NEG_Y, "", Color32::from_rgb(70, 130, 60)),
    (IVec3::NEG_Z, "", Color32::from_rgb(60, 90, 160)),
];

/// Where each axis end is drawn relative to the centre (screen y down), and
/// its depth toward the eye (larger: nearer).
fn projected(camera: &Camera) -> [(Vec2, f64); 6] {
    let (forward, right, up) = camera.axes();
    ENDS.map(|(axis, _, _)| {
        let a = axis.as_dvec3();
        (Vec2::new(a.dot(right) as f32, -a.dot(up) as f32) * REACH, -a.dot(forward))
    })
}

/// Draws the gizmo at the top right of the view, left of a panel `right`
/// points wide; a click on an axis end asks for the view from it.
pub fn show(ctx: &egui::Context, camera: &Camera, right: f32, out: &mut Vec<AppCommand>) {
    let at = Vec2::new(-8.0 - right, 32.0);
    egui::Area::new(egui::Id::unique("axis gizmo")).anchor(egui::Align2::RIGHT_TOP, at).show(ctx, |ui| {
        let (rect, response) = ui.allocate_exact_size(Vec2::splat(SIZE), Sense::click());
        let painter = ui.painter_at(rect);
        let center = rect.center();
        painter.circle_filled(center, SIZE * 0.5, Color32::from_black_alpha(90));
        let ends = projected(camera);
        // Far ends first, so the near ones are drawn over them.
        let mut order: Vec<usize> = (0..6).collect();
        order.sort_by(|&a, &b| ends[a].1.total_cmp(&ends[b].1));
        for i in order {
            let (axis, label, color) = ENDS[i];
            let tip = center + ends[i].0;
            if axis.max_element() > 0 {
                painter.line_segment([center, tip], Stroke::new(2.0, color));
            }
            painter.circle_filled(tip, if label.is_empty() { 4.0 } else { 7.0 }, color);
            painter.text(tip, egui::Align2::CENTER_CENTER, label, egui::FontId::proportional(10.0), Color32::WHITE);
        }
        let projection = if camera.ortho.is_some() { "ortho" } else { "persp" };
        let bottom = center + Vec2::new(0.0, SIZE * 0.5 - 3.0);
        let font = egui::FontId::proportional(10.0);
        painter.text(bottom, egui::Align2::CENTER_BOTTOM, projection, font, Color32::from_gray(220));
        let nearest = |pos: Pos2| {
            (0..6)
                .filter(|&i| (center + ends[i].0).distance(pos) <= HIT_RADIUS)
                .max_by(|&a, &b| ends[a].1.total_cmp(&ends[b].1))
        };
        if response.clicked()
            && let Some(i) = response.interact_pointer_pos().and_then(nearest)
        {
            out.push(AppCommand::ViewFrom(ENDS[i].0));
        }
        response.on_hover_text("click an axis end to look from that side · O: orthographic or perspective");
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_axis_toward_the_eye_is_nearest_and_points_its_way() {
        let camera = Camera { eye: glam::DVec3::new(0.0, 0.0, 10.0), ..Camera::default() };
        let ends = projected(&camera);
        let (nearest, _) = ends.iter().enumerate().max_by(|a, b| a.1.1.total_cmp(&b.1.1)).unwrap();
        assert_eq!(ENDS[nearest].0, IVec3::Z, "the +z end faces an eye on +z");
        assert!(ends[0].0.x > 20.0 && ends[1].0.y < -20.0, "x to the right, y up on screen: {ends:?}");
        // From the top: x still to the right, the front (+z) at the bottom.
        let top = Camera { eye: glam::DVec3::new(0.0, 10.0, 0.0), ..Camera::default() };
        let ends = projected(&top);
        assert!(ends[0].0.x > 20.0 && ends[2].0.y > 20.0, "{ends:?}");
    }
}
