//! Plain editor state: tool, brush, colour, camera and render settings. No
//! wgpu, winit or egui types live here, so the UI, the input handler and a
//! replay script all read and change the same data. Tools, brushes and
//! what a click does come from `octovox::tool`, shared with replay's `click`.

use std::path::PathBuf;

use glam::IVec3;

use octovox::camera::Camera;
use octovox::edit::Edit;
use octovox::settings::{PathSettings, RenderSettings, Shading};
pub use octovox::tool::{Brush, Tool, click_edit};

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
    /// Frame time to hold while the camera moves (the render scale drops
    /// as far as needed), milliseconds.
    pub frame_target_ms: f32,
    pub shading: Shading,
    pub path_settings: PathSettings,
    /// Samples the path tracer accumulates at rest before it stops.
    pub sample_target: u32,
    /// Mirror planes in force for brush edits.
    pub mirror: octovox::mirror::Mirror,
    /// Line mode (L): a press-drag-release places the brush along a line.
    pub line_mode: bool,
    /// Where the line being dragged starts (the cell in front of the face).
    pub line_start: Option<IVec3>,
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
            frame_target_ms: super::motion::DEFAULT_TARGET_MS,
            shading: Shading::default(),
            path_settings: PathSettings::default(),
            sample_target: octovox::settings::DEFAULT_SAMPLE_TARGET,
            mirror: octovox::mirror::Mirror::default(),
            line_mode: false,
            line_start: None,
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
        if let Some(start) = self.line_start {
            // While a line is dragged: the box from its start to here.
            let end = pick.voxel + pick.normal;
            let ((a, b), (c, d)) = (self.brush().shape_at(start).bounds(), self.brush().shape_at(end).bounds());
            return (a.min(c), b.max(d));
        }
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
    use octovox::scene::{Op, Shape};

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
