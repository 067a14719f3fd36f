//! Hover previews of the actions that are not brush clicks, worked out when
//! the cursor reaches another voxel and drawn over the image by `ui`: the
//! faces an extrude moves (Ctrl held, or a Ctrl+drag), the voxels a fill
//! recolours (Shift held with Paint), the box a paste fills (select mode
//! with a clipboard) and the colour the eyedropper takes (Alt held).

use glam::IVec3;

use octovox::edit::selection::Region;

use super::gesture::Gesture;
use super::session::Session;
use super::state::{Mode, Tool};

/// The faces an extrude would move: those of the region around `face`
/// (voxel, normal), and the layers the drag covers so far.
pub(super) struct ExtrudePreview {
    pub face: (IVec3, IVec3),
    pub voxels: Vec<IVec3>,
    pub layers: i32,
}

/// What a fill from `start` would recolour: its voxels' bounds and count
/// (`None`: a region too large to fill).
pub(super) struct FillPreview {
    start: IVec3,
    pub region: Option<((IVec3, IVec3), usize)>,
}

/// What the cursor is over, and what the actions it would start there
/// would change.
#[derive(Default)]
pub(super) struct Hover {
    /// The voxel and face under the cursor.
    pub pick: Option<super::state::Pick>,
    /// The cursor is over a panel: the scene takes no clicks.
    pub pointer_over_ui: bool,
    /// The part of the window the panels left to the view in the last
    /// frame, in points (`None` before the first frame).
    pub view: Option<egui::Rect>,
    /// What an extrude from the face under the cursor (Ctrl held) or the
    /// Ctrl+drag under way would move.
    pub extrude_preview: Option<ExtrudePreview>,
    /// What a Shift+click fill with Paint would recolour.
    pub fill_preview: Option<FillPreview>,
}

/// Whether egui drew at window pixel `at` in the last frame: outside the
/// view the panels left, or on a window, dialog, menu, popup or the axis
/// gizmo. Decided by position, not by egui's hover (which lags a frame).
pub(super) fn ui_at(ctx: &egui::Context, view: egui::Rect, (x, y): (f64, f64)) -> bool {
    let scale = f64::from(ctx.pixels_per_point());
    let at = egui::pos2((x / scale) as f32, (y / scale) as f32);
    !view.contains(at) || ctx.layer_id_at(at).is_some_and(|layer| layer.order != egui::Order::Background)
}

impl Session {
    /// The hover pick: what a click would edit, highlighted before any click.
    pub(super) fn update_hover(&mut self) {
        self.hover.pick = match self.pointer.cursor {
            // A hover over a ray that gave up highlights nothing; a click says why.
            Some((x, y)) if !self.hover.pointer_over_ui && self.doc.loading.is_none() => {
                // What builds on the ground shows where it lands there too.
                let on_ground = self.state.tool == Tool::Attach || self.state.mode != Mode::Brush;
                if on_ground { self.pick_or_ground(x, y) } else { self.pick_at(x, y) }.ok().flatten()
            }
            _ => None,
        };
    }

    pub(super) fn update_previews(&mut self) {
        self.update_extrude_preview();
        self.update_fill_preview();
    }

    /// Keeps the extrude preview up to date: the region of the face a
    /// Ctrl+drag started on, else of the face under the cursor while Ctrl
    /// is held (line and select modes have no extrude).
    fn update_extrude_preview(&mut self) {
        let face = match self.gesture {
            Gesture::Extrude { face, .. } => Some(face),
            _ if self.pointer.ctrl && self.state.mode == Mode::Brush => self.hover.pick,
            _ => None,
        }
        .filter(|p| p.normal != IVec3::ZERO && p.value != 0)
        .map(|p| (p.voxel, p.normal));
        let Some(face) = face else {
            self.hover.extrude_preview = None;
            return;
        };
        if self.hover.extrude_preview.as_ref().is_none_or(|p| p.face != face) {
            // A region too large to extrude previews nothing; the release says why.
            let region = octovox::edit::extrude::face_region(self.doc.editor.scene.drawn(), face.0, face.1);
            let voxels = region.map(|r| r.into_iter().map(|(p, _)| p).collect()).unwrap_or_default();
            self.hover.extrude_preview = Some(ExtrudePreview { face, voxels, layers: 0 });
        }
        let layers = self.pointer.cursor.and_then(|(x, y)| self.extrude_layers(x, y)).unwrap_or(0);
        if let Some(preview) = &mut self.hover.extrude_preview {
            preview.layers = layers;
        }
    }

    /// Keeps the fill preview up to date: the region a Shift+click with
    /// Paint would recolour.
    fn update_fill_preview(&mut self) {
        let plain_mode = self.state.mode == Mode::Brush;
        let start = self
            .hover
            .pick
            .filter(|_| plain_mode && self.state.tool == Tool::Paint && self.pointer.shift)
            .map(|p| p.voxel);
        let Some(start) = start else {
            self.hover.fill_preview = None;
            return;
        };
        if self.hover.fill_preview.as_ref().is_some_and(|p| p.start == start) {
            return;
        }
        let region = octovox::edit::fill::fill_region(self.doc.editor.scene.drawn(), start).ok().map(|voxels| {
            let lo = voxels.iter().copied().reduce(IVec3::min).unwrap_or(start);
            let hi = voxels.iter().copied().reduce(IVec3::max).unwrap_or(start);
            ((lo, hi), voxels.len())
        });
        self.hover.fill_preview = Some(FillPreview { start, region });
    }

    /// The box Ctrl+V would fill: in select mode, the clipboard's block in
    /// front of the face under the cursor.
    pub(super) fn paste_preview(&self) -> Option<Region> {
        let pick = self.hover.pick.filter(|_| self.state.mode == Mode::Select)?;
        Some(self.doc.editor.clipboard()?.region_at(pick.voxel + pick.normal))
    }

    /// The colour Alt+click would pick: the voxel's under the cursor.
    pub(super) fn eyedropper_preview(&self) -> Option<u8> {
        self.hover.pick.filter(|p| self.pointer.alt && p.value != 0).map(|p| p.value)
    }
}
