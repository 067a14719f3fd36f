//! Plain editor state: tool, brush, colour, camera and render settings. No
//! wgpu, winit or egui types live here, so the UI, the input handler and a
//! replay script all read and change the same data.
//!
//! `Tool`, `Brush` and `click_edit` mirror `src/tool.rs` on the main branch
//! (names and semantics kept identical) so the two can be merged into one.

use std::path::PathBuf;

use glam::IVec3;

use octovox::camera::Camera;
use octovox::edit::Edit;
use octovox::scene::{Op, Shape};
use octovox::settings::RenderSettings;

/// What a click does (MagicaVoxel's names and keys: T, R, G).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Tool {
    /// Place voxels on the face that was clicked.
    #[default]
    Attach,
    /// Remove the clicked voxels.
    Erase,
    /// Recolour the clicked voxels.
    Paint,
}

impl Tool {
    pub const ALL: [Tool; 3] = [Tool::Attach, Tool::Erase, Tool::Paint];

    pub fn label(self) -> &'static str {
        match self {
            Tool::Attach => "Attach (T)",
            Tool::Erase => "Erase (R)",
            Tool::Paint => "Paint (G)",
        }
    }

    /// The operation this tool performs with a colour.
    pub fn op(self, color: u8) -> Op {
        match self {
            Tool::Attach => Op::Place(color),
            Tool::Erase => Op::Remove,
            Tool::Paint => Op::Paint(color),
        }
    }

    /// The cell a click acts on: Attach works in front of the face that was hit.
    pub fn target(self, voxel: IVec3, normal: IVec3) -> IVec3 {
        match self {
            Tool::Attach => voxel + normal,
            Tool::Erase | Tool::Paint => voxel,
        }
    }
}

/// The brush shape, centred on the cell a click picks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Brush {
    #[default]
    Voxel,
    /// Cells with dx² + dy² + dz² ≤ r².
    Sphere(i32),
    /// `size` cells per axis, from `center - size / 2`.
    Box(IVec3),
}

impl Brush {
    /// How far the brush reaches from its centre along an axis.
    pub fn reach(&self) -> i32 {
        match *self {
            Brush::Voxel => 0,
            Brush::Sphere(radius) => radius.max(0),
            Brush::Box(size) => size.max_element().max(1) / 2,
        }
    }

    pub fn shape_at(&self, center: IVec3) -> Shape {
        match *self {
            Brush::Voxel => Shape::Voxel(center),
            Brush::Sphere(radius) => Shape::Sphere { center, radius },
            Brush::Box(size) => Shape::centered_box(center, size),
        }
    }
}

/// The edit of a click with `tool` on (world) `voxel` through the face with
/// `normal`; also returns the brush centre.
pub fn click_edit(tool: Tool, brush: &Brush, color: u8, voxel: IVec3, normal: IVec3) -> (IVec3, Edit) {
    let center = tool.target(voxel, normal);
    (center, Edit::Brush { shape: brush.shape_at(center), op: tool.op(color) })
}

/// The voxel and face under the cursor, in world coordinates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pick {
    pub voxel: IVec3,
    pub normal: IVec3,
    pub value: u8,
}

/// Which brush-size widget the panel shows; the numbers live in `EditorState`
/// so that switching shapes keeps each one's size.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum BrushKind {
    #[default]
    Voxel,
    Sphere,
    Box,
}

/// Everything the user chose, as plain data.
#[derive(Clone, Debug)]
pub struct EditorState {
    pub tool: Tool,
    pub brush_kind: BrushKind,
    pub sphere_radius: i32,
    pub box_size: i32,
    /// Palette index used by Attach and Paint (1..=255).
    pub color: u8,
    pub camera: Camera,
    pub settings: RenderSettings,
    /// The file Save writes to; `None` for a new or demo scene.
    pub path: Option<PathBuf>,
    /// Edits since the last save or load.
    pub dirty: bool,
}

impl Default for EditorState {
    fn default() -> EditorState {
        EditorState {
            tool: Tool::Attach,
            brush_kind: BrushKind::Voxel,
            sphere_radius: 3,
            box_size: 3,
            color: 1,
            camera: Camera::default(),
            settings: RenderSettings::default(),
            path: None,
            dirty: false,
        }
    }
}

impl EditorState {
    pub fn brush(&self) -> Brush {
        match self.brush_kind {
            BrushKind::Voxel => Brush::Voxel,
            BrushKind::Sphere => Brush::Sphere(self.sphere_radius.max(0)),
            BrushKind::Box => Brush::Box(IVec3::splat(self.box_size.max(1))),
        }
    }

    /// The edit the current tool makes at `pick`, with `tool` overriding the
    /// current one (a right click erases while Attach is active).
    pub fn edit_at(&self, tool: Tool, pick: &Pick) -> (IVec3, Edit) {
        click_edit(tool, &self.brush(), self.color.max(1), pick.voxel, pick.normal)
    }

    /// Inclusive world box of the cells the brush would touch at `pick`.
    pub fn preview_box(&self, pick: &Pick) -> (IVec3, IVec3) {
        let (center, _) = self.edit_at(self.tool, pick);
        self.brush().shape_at(center).bounds()
    }

    /// Title-bar text: file name and an asterisk for unsaved changes.
    pub fn title(&self) -> String {
        let name = self
            .path
            .as_ref()
            .and_then(|p| p.file_name())
            .map_or_else(|| "untitled".to_string(), |n| n.to_string_lossy().into_owned());
        format!("octovox — {name}{}", if self.dirty { " *" } else { "" })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn attach_places_in_front_of_the_face() {
        let state = EditorState { color: 7, ..EditorState::default() };
        let pick = Pick { voxel: IVec3::new(1, 2, 3), normal: IVec3::Y, value: 4 };
        let (center, edit) = state.edit_at(Tool::Attach, &pick);
        assert_eq!(center, IVec3::new(1, 3, 3));
        assert_eq!(edit, Edit::Brush { shape: Shape::Voxel(center), op: Op::Place(7) });
        let (center, edit) = state.edit_at(Tool::Erase, &pick);
        assert_eq!(center, pick.voxel);
        assert_eq!(edit, Edit::Brush { shape: Shape::Voxel(pick.voxel), op: Op::Remove });
    }

    #[test]
    fn brush_sizes_follow_the_kind() {
        let mut state = EditorState { brush_kind: BrushKind::Box, box_size: 4, ..EditorState::default() };
        let pick = Pick { voxel: IVec3::ZERO, normal: IVec3::X, value: 1 };
        assert_eq!(state.preview_box(&pick), (IVec3::new(-1, -2, -2), IVec3::new(2, 1, 1)));
        state.brush_kind = BrushKind::Sphere;
        state.sphere_radius = 2;
        state.tool = Tool::Paint;
        assert_eq!(state.preview_box(&pick), (IVec3::splat(-2), IVec3::splat(2)));
    }
}
