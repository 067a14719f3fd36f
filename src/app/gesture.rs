//! The drag or held control under way, one at a time (the mode a drag
//! starts in is `EditorState::mode`).

use glam::IVec3;
use octovox::edit::selection::Region;

use super::state::{Pick, Tool};

/// What the mouse (or a held panel control) is doing now.
#[derive(Default)]
pub(super) enum Gesture {
    #[default]
    Idle,
    /// A brush stroke: its steps are one undo step.
    Stroke(Stroke),
    /// A palette control is held: its changes are one undo step.
    Palette,
    /// A line drag (line mode) from the cell in front of the pressed face.
    Line { start: IVec3 },
    /// A box-select drag (select mode), and the box it would select now.
    Select { drag: SelectDrag, preview: Option<Region> },
    /// A Ctrl+drag extrude: the face it started on and where the drag began.
    Extrude { face: Pick, start: (f64, f64) },
    /// An object dragged (object mode): the world voxel it was grabbed
    /// at, the window pixel the drag began at, and how far it has moved so
    /// far (its moves are one undo step).
    ObjectDrag { at: IVec3, start: (f64, f64), moved: IVec3 },
    /// The rotation ring dragged (object mode): the ring's centre in window
    /// pixels, the pointer's last angle about it, the degrees dragged so far
    /// and the whole degrees turned (its turns are one undo step).
    Ring { centre: glam::DVec2, last: f64, dragged: f64, turned: i64 },
}

/// A selection drag under way.
#[derive(Clone, Copy, Debug)]
pub(super) enum SelectDrag {
    /// A new box from this voxel.
    NewBox(IVec3),
    /// A face of the selected box, by its outward normal, dragged from
    /// this window pixel.
    Face { normal: IVec3, start: (f64, f64) },
}

/// An open mouse stroke: its tool, the face (normal and layer) it started
/// on, and the last brush centre applied.
pub(super) struct Stroke {
    pub tool: Tool,
    pub plane: Option<Layer>,
    pub last_center: Option<(Option<usize>, IVec3)>,
}

/// A face layer a stroke stays on: in the scene's cells, or (a freely
/// turned object's face) in that object's model cells, the stroke's steps
/// following its turned face. The frame (`None`: the scene's), the face's
/// normal and its depth along the normal.
pub(super) type Layer = (Option<usize>, IVec3, i32);

/// A step a stroke takes: the line it runs, the face layer it is on, and
/// whether it is the stroke's first (which picks the object it hits).
#[derive(Debug, PartialEq)]
pub(super) struct StrokeStep {
    pub line: octovox::script::Line,
    pub layer: Layer,
    pub center: (Option<usize>, IVec3),
    pub first: bool,
}

impl Stroke {
    /// The step the pointer over `pick` makes, with a brush of `reach`:
    /// none where the brush would land where the last step did, or (Attach
    /// and Erase) off the face the stroke started on by more than the
    /// reach (the cells a stroke reveals or creates would otherwise be
    /// picked next, and it would dig or pile up toward the camera), or
    /// where Attach has no face (the camera inside a voxel). Over a freely
    /// turned object both are of its model cells, as the click's line is.
    pub fn step_at(&self, pick: &Pick, reach: i32) -> Option<StrokeStep> {
        if self.tool == Tool::Attach && pick.normal == IVec3::ZERO {
            return None;
        }
        let (frame, cell, normal) = match pick.model {
            Some(m) => (Some(m.object), m.cell, m.normal),
            None => (None, pick.voxel, pick.normal),
        };
        let layer = (frame, normal, cell.dot(normal));
        let off_layer = |(on, along, depth): Layer| on != frame || along != normal || (layer.2 - depth).abs() > reach;
        if self.tool != Tool::Paint && self.plane.is_some_and(off_layer) {
            return None;
        }
        let center = (frame, octovox::edit::brush::click_target(self.tool, cell, normal));
        if self.last_center == Some(center) {
            return None;
        }
        let line = octovox::script::click_command(self.tool, pick);
        Some(StrokeStep { line, layer, center, first: self.last_center.is_none() })
    }

    /// The stroke after `step` ran.
    pub fn stepped(&mut self, step: &StrokeStep) {
        self.plane.get_or_insert(step.layer);
        self.last_center = Some(step.center);
    }
}

impl Gesture {
    /// Whether the gesture's edits are one undo step (between the `stroke
    /// begin` and `stroke end` it runs): a brush stroke, a held palette
    /// control, an object drag, a ring drag.
    pub fn groups_edits(&self) -> bool {
        matches!(self, Gesture::Stroke(_) | Gesture::Palette | Gesture::ObjectDrag { .. } | Gesture::Ring { .. })
    }

    pub fn stroke_mut(&mut self) -> Option<&mut Stroke> {
        match self {
            Gesture::Stroke(stroke) => Some(stroke),
            _ => None,
        }
    }

    pub fn stroke(&self) -> Option<&Stroke> {
        match self {
            Gesture::Stroke(stroke) => Some(stroke),
            _ => None,
        }
    }

    /// Where the line being dragged starts.
    pub fn line_start(&self) -> Option<IVec3> {
        match self {
            Gesture::Line { start } => Some(*start),
            _ => None,
        }
    }

    /// The box the selection drag would select now.
    pub fn select_preview(&self) -> Option<Region> {
        match self {
            Gesture::Select { preview, .. } => *preview,
            _ => None,
        }
    }
}

/// The lines a palette control's change runs: `rgb` and `material`, for
/// the parts of entry `index` that differ from `palette`'s.
pub(super) fn palette_lines(
    palette: &octovox::scene::Palette,
    edit: octovox::edit::Edit,
) -> Vec<octovox::script::Line> {
    use octovox::script::Line;
    let octovox::edit::Edit::Palette { index, color: [r, g, b, _], material } = edit else { return Vec::new() };
    let mut lines = Vec::new();
    if palette.color(index)[..3] != [r, g, b] {
        lines.push(Line::Rgb(index, [r, g, b]));
    }
    if *palette.material(index) != *material {
        lines.push(Line::Material(index, material));
    }
    lines
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // in tests a panic is the failure report
mod tests {
    use glam::IVec3;
    use octovox::camera::Camera;
    use octovox::editor::Editor;
    use octovox::replay::Recorder;
    use octovox::scene::{Octree, Op, Palette, Scene, Shape};
    use octovox::script::Line;

    use super::{Stroke, Tool};
    use crate::app::state::Pick;

    /// A 8 × 1 × 8 floor of colour 1 at y = 0.
    fn floor() -> Editor {
        let mut tree = Octree::default();
        tree.apply_brush(&Shape::Box { min: IVec3::ZERO, max: IVec3::new(7, 0, 7) }, Op::Place(1)).unwrap();
        let mut editor = Editor::default();
        editor.set_scene(Scene::new(Palette::default(), tree));
        editor
    }

    /// Lines run as the window runs them: through the editor, then the
    /// recorder (the crash journal writes the same).
    struct Journaled {
        recorder: Recorder,
        path: std::path::PathBuf,
        _dir: tempfile::TempDir,
    }

    impl Journaled {
        fn new() -> Journaled {
            let dir = tempfile::tempdir().unwrap();
            let path = dir.path().join("journal.ovr");
            Journaled { recorder: Recorder::create(&path).unwrap(), path, _dir: dir }
        }

        fn run(&mut self, editor: &mut Editor, line: &Line) {
            let changed = editor.run(line).unwrap() == octovox::editor::Outcome::Changed;
            self.recorder.ran(line, &editor.tools, &Camera::default(), changed).unwrap();
        }

        /// What the recorder wrote.
        fn written(self) -> String {
            drop(self.recorder);
            std::fs::read_to_string(&self.path).unwrap()
        }
    }

    /// A stroke of `tool` over `picks`, as the window runs it: `stroke
    /// begin`, a step's line wherever the stroke takes one, `stroke end`.
    /// Returns the recorded lines.
    fn stroke(editor: &mut Editor, tool: Tool, picks: &[Pick]) -> Vec<String> {
        let mut journal = Journaled::new();
        journal.run(editor, &Line::Stroke(true));
        let mut open = Stroke { tool, plane: None, last_center: None };
        for pick in picks {
            if let Some(step) = open.step_at(pick, editor.tools.brush.reach()) {
                journal.run(editor, &step.line);
                open.stepped(&step);
            }
        }
        journal.run(editor, &Line::Stroke(false));
        let text = journal.written();
        text.lines()
            .filter(|l| !l.starts_with('#') && !l.starts_with("camera") && *l != "perspective")
            .map(String::from)
            .collect()
    }

    fn top(x: i32, z: i32) -> Pick {
        Pick { voxel: IVec3::new(x, 0, z), normal: IVec3::Y, value: 1, model: None }
    }

    /// Issue 46: gestures were tested only through Xvfb. An Attach drag
    /// along the floor: a voxel on each new cell of the floor's top (the
    /// pointer resting on one cell adds nothing; the top of a voxel the
    /// stroke just placed is off its layer and adds nothing), one undo
    /// step, and the lines a journal gets.
    #[test]
    fn an_attach_stroke_places_along_its_face_in_one_undo_step() {
        let mut editor = floor();
        let placed_top = Pick { voxel: IVec3::new(1, 1, 2), normal: IVec3::Y, value: 1, model: None };
        let picks = [top(1, 2), top(1, 2), placed_top, top(2, 2), top(3, 2)];
        let lines = stroke(&mut editor, Tool::Attach, &picks);
        assert_eq!(
            lines,
            ["brush voxel", "color 1", "stroke begin", "place 1 1 2", "place 2 1 2", "place 3 1 2", "stroke end"]
        );
        assert_eq!(editor.history.steps(), (1, 0), "one undo step");
        assert_eq!(editor.scene.solid_voxels(), 64 + 3);
        editor.run(&Line::Undo(1)).unwrap();
        assert_eq!(editor.scene.solid_voxels(), 64, "one undo takes the stroke away");
    }

    /// A held palette control: each change runs the `rgb` or `material`
    /// line of what differs, inside one stroke: one undo step, and the
    /// journal's lines say so.
    #[test]
    fn a_held_palette_control_is_one_undo_step() {
        use octovox::edit::Edit;
        use octovox::scene::{Material, MaterialKind};
        let mut editor = floor();
        let mut journal = Journaled::new();
        let diffuse = Box::new(editor.scene.palette.material(5).clone());
        let metal = Box::new(Material::new(MaterialKind::Metal));
        let drag = [([10, 0, 0, 255], diffuse.clone()), ([20, 0, 0, 255], diffuse.clone()), ([20, 0, 0, 255], metal)];
        journal.run(&mut editor, &Line::Stroke(true));
        for (color, material) in drag {
            let lines = super::palette_lines(&editor.scene.palette, Edit::Palette { index: 5, color, material });
            assert_eq!(lines.len(), 1, "only the part that changed: {lines:?}");
            lines.iter().for_each(|line| journal.run(&mut editor, line));
        }
        journal.run(&mut editor, &Line::Stroke(false));
        let written = journal.written();
        // The state an edit depends on comes first (camera, projection, brush).
        let lines: Vec<&str> = written.lines().skip_while(|l| *l != "stroke begin").collect();
        assert_eq!(lines, ["stroke begin", "rgb 5 10 0 0", "rgb 5 20 0 0", "material 5 metal", "stroke end"]);
        assert_eq!(editor.history.steps(), (1, 0));
        assert_eq!(editor.scene.palette.color(5)[..3], [20, 0, 0]);
        editor.run(&Line::Undo(1)).unwrap();
        assert_eq!(*editor.scene.palette.material(5), *diffuse, "one undo puts the entry back");
    }

    /// Over a freely turned object a stroke follows the turned face by its
    /// model cells: the face's world cells climb and its nearest axis
    /// changes as the pointer moves along it, which stopped an Attach drag
    /// after its first step (off the layer it started on); the model cells
    /// stay on one layer of the model's face. A pick of the scene's own
    /// cells is off that layer.
    #[test]
    fn a_stroke_over_a_turned_face_steps_by_its_model_cells() {
        use octovox::trace::pick::ModelCell;
        let on_face = |x: i32| Pick {
            voxel: IVec3::new(x, x / 2, 0),
            normal: if x % 3 == 0 { IVec3::X } else { IVec3::Y },
            value: 1,
            model: Some(ModelCell { object: 0, cell: IVec3::new(x, 2, 3), normal: IVec3::Z }),
        };
        let mut open = Stroke { tool: Tool::Attach, plane: None, last_center: None };
        let mut lines = Vec::new();
        for pick in [on_face(0), on_face(0), on_face(1), on_face(2), on_face(5)] {
            if let Some(step) = open.step_at(&pick, 0) {
                lines.push(step.line.to_string());
                open.stepped(&step);
            }
        }
        assert_eq!(lines, ["object place 0 2 4", "object place 1 2 4", "object place 2 2 4", "object place 5 2 4"]);
        assert!(open.step_at(&top(3, 3), 0).is_none(), "the scene's cells are off the turned face's layer");
    }

    /// An Erase drag digs one layer, and a Paint drag follows the pointer
    /// to any face; a stroke that edits nothing leaves no step and no lines.
    #[test]
    fn erase_stays_on_its_layer_paint_goes_anywhere_and_an_empty_stroke_is_nothing() {
        let mut editor = floor();
        let below = Pick { voxel: IVec3::new(2, -1, 2), normal: IVec3::Y, value: 1, model: None };
        let lines = stroke(&mut editor, Tool::Erase, &[top(1, 1), below, top(2, 1)]);
        assert_eq!(lines, ["brush voxel", "stroke begin", "remove 1 0 1", "remove 2 0 1", "stroke end"]);
        let side = Pick { voxel: IVec3::new(7, 0, 5), normal: IVec3::X, value: 1, model: None };
        let lines = stroke(&mut editor, Tool::Paint, &[top(4, 4), side]);
        assert_eq!(lines, ["brush voxel", "color 1", "stroke begin", "paint 4 0 4", "paint 7 0 5", "stroke end"]);
        assert_eq!(editor.history.steps(), (2, 0));
        let inside = Pick { voxel: IVec3::new(3, 0, 3), normal: IVec3::ZERO, value: 1, model: None };
        assert!(stroke(&mut editor, Tool::Attach, &[inside]).is_empty(), "no face to attach to");
        assert_eq!(editor.history.steps(), (2, 0), "an empty stroke leaves no step");
    }
}
