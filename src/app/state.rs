//! Plain window state: the tool, the remembered brush sizes, the camera and
//! render settings. No wgpu, winit or egui types live here. The brush,
//! colour and mirror planes are the editor's (`octovox::editor::Tools`), so
//! the panel shows what a played script set; what a click does comes from
//! `octovox::tool`, shared with replay's `click`.

use std::path::PathBuf;

use glam::IVec3;

use octovox::camera::Camera;
use octovox::edit::Edit;
pub use octovox::edit::brush::{Brush, Tool, click_edit};
use octovox::editor::Tools;
use octovox::settings::{PathSettings, RenderSettings, Shading};

/// The voxel and face under the cursor, in world coordinates (and on a
/// freely turned object the model cell).
pub use octovox::trace::pick::Picked as Pick;

/// The brush shapes the panel offers; switching shapes keeps each one's
/// last size (in `EditorState`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BrushKind {
    Voxel,
    Sphere,
    Box,
}

impl BrushKind {
    pub fn of(brush: Brush) -> BrushKind {
        match brush {
            Brush::Voxel => BrushKind::Voxel,
            Brush::Sphere(_) => BrushKind::Sphere,
            Brush::Box(_) => BrushKind::Box,
        }
    }
}

/// Everything the user chose, as plain data.
#[derive(Clone, Debug)]
pub struct EditorState {
    pub tool: Tool,
    /// The sizes a sphere and a box brush get when the panel switches to them.
    pub sphere_radius: i32,
    pub box_size: i32,
    pub camera: Camera,
    pub settings: RenderSettings,
    /// The file Save writes to; `None` for a new or demo scene.
    pub path: Option<PathBuf>,
    /// The history's state when the scene was last saved or loaded
    /// (`History::state_id`); `None` when no state of it is in a file (a
    /// recovered journal's scene, or one saved in the middle of a stroke).
    /// Whether there are unsaved changes is derived from it (`Session::unsaved`).
    pub saved_state: Option<u64>,
    /// Frame time to hold while the camera moves (the render scale drops
    /// as far as needed), milliseconds.
    pub frame_target_ms: f32,
    pub shading: Shading,
    pub path_settings: PathSettings,
    /// Samples the path tracer accumulates at rest before it stops.
    pub sample_target: u32,
    /// Whether the path-traced view is shown denoised (the raw samples
    /// when off).
    pub denoise: bool,
    /// What a left drag does (the drag under way is the `Gesture`).
    pub mode: Mode,
    /// Side of the working volume outlined on the ground (voxels): x and z
    /// in -side/2..side/2, y in 0..side.
    pub volume: i32,
}

/// What a left drag does: apply the tool, place the brush along a line
/// (L), select a box and move its faces (B), or pick objects (Tab: object
/// mode, where the arrows and PageUp/PageDown move the picked object).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Mode {
    #[default]
    Brush,
    Line,
    Select,
    Object,
}

impl Mode {
    /// Whether a left drag applies the brush (so its reach is previewed).
    pub fn uses_brush(self) -> bool {
        matches!(self, Mode::Brush | Mode::Line)
    }
}

/// The working volume's side in a new scene (MagicaVoxel opens on 40³,
/// Goxel on a grid plane).
pub const DEFAULT_VOLUME: i32 = 32;

/// Sides the working volume may have.
pub const VOLUME_RANGE: std::ops::RangeInclusive<i32> = 2..=1024;

impl Default for EditorState {
    fn default() -> EditorState {
        EditorState {
            tool: Tool::Attach,
            volume: DEFAULT_VOLUME,
            sphere_radius: 3,
            box_size: 3,
            camera: Camera::default(),
            settings: RenderSettings::default(),
            path: None,
            saved_state: None,
            frame_target_ms: super::motion::DEFAULT_TARGET_MS,
            shading: Shading::default(),
            path_settings: PathSettings::default(),
            sample_target: octovox::settings::DEFAULT_SAMPLE_TARGET,
            denoise: true,
            mode: Mode::Brush,
        }
    }
}

impl EditorState {
    /// The brush of `kind` at its remembered size.
    pub fn brush_of(&self, kind: BrushKind) -> Brush {
        match kind {
            BrushKind::Voxel => Brush::Voxel,
            BrushKind::Sphere => Brush::Sphere(self.sphere_radius.max(0)),
            BrushKind::Box => Brush::Box(IVec3::splat(self.box_size.max(1))),
        }
    }

    /// The edit the current tool makes at `pick`, with `tool` overriding the
    /// current one (a right click erases while Attach is active).
    pub fn edit_at(&self, tools: &Tools, tool: Tool, pick: &Pick) -> (IVec3, Edit) {
        click_edit(tool, &tools.brush, tools.color.max(1), pick.voxel, pick.normal)
    }

    /// The brush's shape where a click at `pick` would apply it (not while
    /// a line from `line_start` is dragged: then [`EditorState::preview_box`]
    /// spans it).
    pub fn preview_shape(
        &self,
        tools: &Tools,
        pick: &Pick,
        line_start: Option<IVec3>,
    ) -> Option<octovox::scene::Shape> {
        let (center, _) = self.edit_at(tools, self.tool, pick);
        line_start.is_none().then(|| tools.brush.shape_at(center))
    }

    /// Inclusive world box of the cells the brush would touch at `pick`,
    /// or that a line dragged from `line_start` to `pick` would.
    pub fn preview_box(&self, tools: &Tools, pick: &Pick, line_start: Option<IVec3>) -> (IVec3, IVec3) {
        if let Some(start) = line_start {
            // While a line is dragged: the box from its start to here.
            let end = pick.voxel + pick.normal;
            let ((a, b), (c, d)) = (tools.brush.shape_at(start).bounds(), tools.brush.shape_at(end).bounds());
            return (a.min(c), b.max(d));
        }
        let (center, _) = self.edit_at(tools, self.tool, pick);
        tools.brush.shape_at(center).bounds()
    }

    /// The working volume's cells, inclusive: x and z in
    /// -volume/2..volume/2, y from 0.
    pub fn working_volume(&self) -> (IVec3, IVec3) {
        let half = self.volume / 2;
        let lo = IVec3::new(-half, 0, -half);
        (lo, lo + IVec3::splat(self.volume - 1))
    }

    /// The ground's grid under the working volume, on its cells' edges at
    /// y = 0, at most 64 lines a side (a large volume gets a coarser grid).
    pub fn ground_grid(&self) -> octovox::gpu::GroundGrid {
        let (lo, hi) = self.working_volume();
        let step = (self.volume / 64).max(1) as u32;
        octovox::gpu::GroundGrid { y: 0, lo: [lo.x, lo.z], hi: [hi.x + 1, hi.z + 1], step }
    }

    /// `mode` on, or back to the brush when it is on already.
    /// The tool whose button is lit: the one a left press applies, so none
    /// in select and object mode, where a press picks (issue 47, item 4:
    /// "Attach" stayed lit beside "Object" and "Select").
    pub fn lit_tool(&self) -> Option<Tool> {
        self.mode.uses_brush().then_some(self.tool)
    }

    pub fn toggle_mode(&mut self, mode: Mode) {
        self.mode = if self.mode == mode { Mode::Brush } else { mode };
    }

    /// Title-bar text: file name and an asterisk for unsaved changes.
    pub fn title(&self, unsaved: bool) -> String {
        let name = self
            .path
            .as_ref()
            .and_then(|p| p.file_name())
            .map_or_else(|| "untitled".to_string(), |n| n.to_string_lossy().into_owned());
        format!("octovox — {name}{}", if unsaved { " *" } else { "" })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use octovox::scene::{Op, Shape};

    /// One lit button says the one mode: a tool is lit only where a press
    /// applies it, and choosing one in select or object mode goes back to
    /// the brush (`App`'s `SetTool`).
    #[test]
    fn a_tool_is_lit_only_where_a_press_applies_it() {
        let mut state = EditorState::default();
        for (mode, lit) in [(Mode::Brush, true), (Mode::Line, true), (Mode::Select, false), (Mode::Object, false)] {
            state.mode = mode;
            assert_eq!(state.lit_tool(), lit.then_some(state.tool), "{mode:?}");
        }
    }

    #[test]
    fn attach_places_in_front_of_the_face() {
        let (state, tools) = (EditorState::default(), Tools { color: 7, ..Tools::default() });
        let pick = Pick { voxel: IVec3::new(1, 2, 3), normal: IVec3::Y, value: 4, model: None };
        let (center, edit) = state.edit_at(&tools, Tool::Attach, &pick);
        assert_eq!(center, IVec3::new(1, 3, 3));
        assert_eq!(edit, Edit::Brush { shape: Shape::Voxel(center), op: Op::Place(7) });
        let (center, edit) = state.edit_at(&tools, Tool::Erase, &pick);
        assert_eq!(center, pick.voxel);
        assert_eq!(edit, Edit::Brush { shape: Shape::Voxel(pick.voxel), op: Op::Remove });
    }

    #[test]
    fn brush_sizes_follow_the_kind() {
        let mut state = EditorState { box_size: 4, ..EditorState::default() };
        let mut tools = Tools { brush: state.brush_of(BrushKind::Box), ..Tools::default() };
        let pick = Pick { voxel: IVec3::ZERO, normal: IVec3::X, value: 1, model: None };
        assert_eq!(state.preview_box(&tools, &pick, None), (IVec3::new(-1, -2, -2), IVec3::new(2, 1, 1)));
        state.sphere_radius = 2;
        tools.brush = state.brush_of(BrushKind::Sphere);
        state.tool = Tool::Paint;
        assert_eq!(state.preview_box(&tools, &pick, None), (IVec3::splat(-2), IVec3::splat(2)));
        assert_eq!(BrushKind::of(tools.brush), BrushKind::Sphere);
    }
}
