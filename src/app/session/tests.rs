//! Gestures without a window or a GPU (issue 46): each drives the session
//! as the window does, with pointer commands at the pixels where the scene
//! is drawn (the session picks on the CPU), and checks the script lines
//! its recording holds, its undo steps and the lines its crash journal
//! got. The recording then replays headless into the same undo steps and
//! voxels.

use std::path::{Path, PathBuf};

use glam::{DVec3, IVec3, Vec3};

use octovox::camera::Camera;
use octovox::io::atomic::WriteOptions;
use octovox::replay::{Runner, RunnerMode};
use octovox::scene::{Octree, Op, Palette, Scene, Shape};
use octovox::script::Line;

use super::Session;
use crate::app::command::{AppCommand, StrokePhase};
use crate::app::state::{Mode, Tool};

const WINDOW: (u32, u32) = (800, 600);

/// A session on `scene`, saved first as `doc.vox` in a folder of its own
/// (the journal goes beside it), recording to `recorded.ovr` there, seen
/// from `eye` toward `target`.
struct Fixture {
    session: Session,
    dir: tempfile::TempDir,
}

impl Fixture {
    fn new(scene: Scene, eye: DVec3, target: DVec3) -> Fixture {
        let dir = tempfile::tempdir().unwrap();
        let document = dir.path().join("doc.vox");
        octovox::io::save_scene(&document, &scene, WriteOptions::default()).unwrap();
        let mut session = Session::new(WINDOW);
        let recording = dir.path().join("recorded.ovr");
        session.open_script_files(None, Some(&recording));
        let scene = octovox::io::load_scene(&document, 0).unwrap();
        session.replace_scene(scene, Line::Load(document), None);
        session.state.camera = Camera { eye, target, fov_y_deg: 50.0, ortho: None };
        Fixture { session, dir }
    }

    /// An 8 × 1 × 8 floor of colour 1 at y = 0, seen from above at a slant.
    fn floor() -> Fixture {
        let mut tree = Octree::default();
        tree.apply_brush(&Shape::Box { min: IVec3::ZERO, max: IVec3::new(7, 0, 7) }, Op::Place(1)).unwrap();
        let scene = Scene::new(Palette::default(), tree);
        Fixture::new(scene, DVec3::new(4.5, 18.0, 14.0), DVec3::new(4.0, 0.0, 4.0))
    }

    /// Where the world point `p` is drawn in the window.
    fn pixel(&self, p: Vec3) -> (f64, f64) {
        let origin = self.session.doc.editor.scene.origin().as_vec3();
        let (x, y) = self.session.view_basis().project(p - origin).expect("the point is in view");
        (f64::from(x), f64::from(y))
    }

    /// Where the top face of the floor's cell (x, 0, z) is drawn.
    fn top(&self, x: i32, z: i32) -> (f64, f64) {
        self.pixel(Vec3::new(x as f32 + 0.5, 1.0, z as f32 + 0.5))
    }

    fn pointer(&mut self, phase: StrokePhase, tool: Tool, (x, y): (f64, f64)) {
        self.session.execute(AppCommand::PointerEdit { phase, tool, x, y });
        assert_eq!(self.session.ui.message.as_ref().filter(|m| m.1).map(|m| m.0.clone()), None, "no error");
    }

    /// A press at the first point, moves through the rest, a release at the last.
    fn drag(&mut self, tool: Tool, at: &[(f64, f64)]) {
        self.pointer(StrokePhase::Begin, tool, at[0]);
        at[1..].iter().for_each(|&p| self.pointer(StrokePhase::Move, tool, p));
        self.pointer(StrokePhase::End, tool, at[at.len() - 1]);
    }

    /// The lines of `file` that `keep` names, comments and state lines left out.
    fn lines_of(file: &Path, keep: &[&str]) -> Vec<String> {
        let text = std::fs::read_to_string(file).unwrap_or_default();
        text.lines().filter(|l| keep.iter().any(|k| l.starts_with(k))).map(String::from).collect()
    }

    fn recorded(&self, keep: &[&str]) -> Vec<String> {
        Fixture::lines_of(&self.dir.path().join("recorded.ovr"), keep)
    }

    fn journal(&self) -> PathBuf {
        octovox::journal::journal_path(&self.dir.path().join("doc.vox"))
    }

    /// The recording, replayed headless by `octovox replay`'s runner, makes
    /// the session's undo steps and voxels.
    fn replays_the_same(&mut self) {
        self.session.doc.recorder = None;
        let script = octovox::script::load_script(&self.dir.path().join("recorded.ovr")).unwrap();
        let mut runner = Runner::new(RunnerMode::Cpu);
        let report = runner.run(&script);
        assert!(report.failures.is_empty(), "{:?}", report.failures);
        let editor = &self.session.doc.editor;
        assert_eq!(runner.editor.history.steps(), editor.history.steps(), "the same undo steps");
        assert_eq!(runner.editor.scene.voxels(), editor.scene.voxels(), "the same voxels");
    }
}

const EDITS: &[&str] = &["stroke", "place", "remove", "paint", "line", "extrude", "select", "object"];

/// An Attach drag along the floor's top: a voxel on each new cell under
/// the pointer (a pointer resting on one cell adds nothing), one undo
/// step, the same lines in the recording and the journal, and one undo
/// takes it all away.
#[test]
fn an_attach_stroke_is_one_undo_step_in_the_recording_and_the_journal() {
    let mut f = Fixture::floor();
    let path = [f.top(1, 2), f.top(1, 2), f.top(2, 2), f.top(3, 2)];
    f.drag(Tool::Attach, &path);
    let lines = ["stroke begin", "place 1 1 2", "place 2 1 2", "place 3 1 2", "stroke end"];
    assert_eq!(f.recorded(EDITS), lines);
    assert_eq!(Fixture::lines_of(&f.journal(), EDITS), lines, "the journal holds the stroke");
    assert_eq!(f.session.doc.editor.history.steps(), (1, 0));
    assert_eq!(f.session.doc.editor.scene.solid_voxels(), 64 + 3);
    f.replays_the_same();
    f.session.execute(AppCommand::Undo);
    assert_eq!(f.session.doc.editor.scene.solid_voxels(), 64, "one undo takes the stroke away");
    assert_eq!(Fixture::lines_of(&f.journal(), &["undo"]), ["undo 1"]);
}

/// Line mode: the press picks the cell in front of the pressed face, the
/// release the one in front of the released face; one `line`, one step.
#[test]
fn a_line_drag_is_one_line_and_one_undo_step() {
    let mut f = Fixture::floor();
    f.session.execute(AppCommand::ToggleLine);
    assert_eq!(f.session.state.mode, Mode::Line);
    f.drag(Tool::Attach, &[f.top(1, 1), f.top(3, 1), f.top(6, 1)]);
    assert_eq!(f.recorded(EDITS), ["line 1 1 1 6 1 1"]);
    assert_eq!(Fixture::lines_of(&f.journal(), EDITS), ["line 1 1 1 6 1 1"]);
    assert_eq!(f.session.doc.editor.history.steps(), (1, 0));
    assert_eq!(f.session.doc.editor.scene.solid_voxels(), 64 + 6);
    f.replays_the_same();
}

/// A Ctrl+drag from the floor's top, up by the on-screen length of three
/// voxels: one `extrude` of three layers, one step.
#[test]
fn a_ctrl_drag_extrudes_in_one_line_and_one_undo_step() {
    let mut f = Fixture::floor();
    let face = Vec3::new(3.5, 1.0, 3.5);
    let (press, release) = (f.pixel(face), f.pixel(face + Vec3::Y * 3.0));
    for (phase, (x, y)) in [(StrokePhase::Begin, press), (StrokePhase::Move, release), (StrokePhase::End, release)] {
        f.session.execute(AppCommand::ExtrudeDrag { phase, x, y });
    }
    assert_eq!(f.recorded(EDITS), ["extrude 3 0 3 0 1 0 3"]);
    assert_eq!(Fixture::lines_of(&f.journal(), EDITS), ["extrude 3 0 3 0 1 0 3"]);
    assert_eq!(f.session.doc.editor.history.steps(), (1, 0));
    assert_eq!(f.session.doc.editor.scene.solid_voxels(), 64 * 4, "the whole floor is one face");
    f.replays_the_same();
}

/// Select mode: a drag from one cell to another selects the box between
/// them: one `select`, which is no undo step and no change to journal.
#[test]
fn a_box_select_is_one_line_and_no_undo_step() {
    let mut f = Fixture::floor();
    f.session.execute(AppCommand::ToggleSelect);
    f.drag(Tool::Attach, &[f.top(1, 1), f.top(4, 2), f.top(5, 4)]);
    assert_eq!(f.recorded(EDITS), ["select 1 0 1 5 0 4"]);
    let region = f.session.doc.editor.selection.unwrap();
    assert_eq!((region.min, region.max), (IVec3::new(1, 0, 1), IVec3::new(5, 0, 4)));
    assert_eq!(f.session.doc.editor.history.steps(), (0, 0));
    assert!(!f.journal().exists(), "nothing changed: no journal");
    f.replays_the_same();
}

/// Object mode on a scene of objects: the press picks the object under it
/// (`object N`), the drag's whole-voxel moves over the ground are `object
/// move` lines of one stroke, one undo step.
#[test]
fn an_object_drag_is_one_undo_step() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/assets/vox/format/test_groups.vox");
    let scene = octovox::io::load_scene(&file, 0).unwrap();
    // The top face of the highest voxel, seen from above.
    let (highest, _) = *scene.voxels().iter().max_by_key(|(p, _)| p.y).unwrap();
    let at = highest.as_vec3() + Vec3::new(0.5, 1.0, 0.5);
    let mut f = Fixture::new(scene, at.as_dvec3() + DVec3::new(4.0, 90.0, 60.0), at.as_dvec3());
    f.session.execute(AppCommand::ToggleObject);
    let before = f.session.doc.editor.scene.voxels();
    f.drag(Tool::Attach, &[f.pixel(at), f.pixel(at + Vec3::X * 2.0), f.pixel(at + Vec3::new(2.0, 0.0, -3.0))]);
    let lines = f.recorded(EDITS);
    assert!(lines[0].starts_with("object ") && lines[0].split(' ').count() == 2, "{lines:?}");
    assert_eq!(lines[1..], ["stroke begin", "object move 2 0 0", "object move 0 0 -3", "stroke end"]);
    assert_eq!(f.session.doc.editor.history.steps(), (1, 0));
    assert_ne!(f.session.doc.editor.scene.voxels(), before, "the object moved");
    f.replays_the_same();
    f.session.execute(AppCommand::Undo);
    assert_eq!(f.session.doc.editor.scene.voxels(), before, "one undo puts it back");
}

/// The Outliner's Turn row: the picked object turned by a typed angle is
/// one `object turn` line, one undo step, and replays to the same voxels.
#[test]
fn a_typed_turn_is_one_line_and_one_undo_step() {
    use octovox::script::{Degrees, ObjectLine, ObjectRef};
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/assets/vox/format/test_groups.vox");
    let scene = octovox::io::load_scene(&file, 0).unwrap();
    let mut f = Fixture::new(scene, DVec3::new(0.0, 60.0, 90.0), DVec3::ZERO);
    let before = f.session.doc.editor.scene.voxels();
    let turn = ObjectLine::Turn { axis: 1, degrees: Degrees(30.5) };
    f.session.execute(AppCommand::Lines(vec![Line::Object(ObjectLine::Pick(ObjectRef::Index(3))), Line::Object(turn)]));
    assert_eq!(f.recorded(EDITS), ["object 3", "object turn y 30.5"]);
    assert_eq!(f.session.doc.editor.history.steps(), (1, 0));
    assert_ne!(f.session.doc.editor.scene.voxels(), before, "the object turned");
    f.replays_the_same();
}

/// Object mode's rotation ring: a press on the ring around the picked
/// object and a drag a quarter of the way round it, counter-clockwise on
/// screen (seen from above), turn the object 90° about the world's up axis
/// in whole degrees: `object turn y` lines of one stroke summing to 90,
/// one undo step, the cells of `object rotate y`, and the same on replay.
#[test]
fn a_drag_round_the_ring_turns_the_picked_object() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/assets/vox/format/test_groups.vox");
    let scene = octovox::io::load_scene(&file, 0).unwrap();
    let mut rotated = octovox::editor::Editor::default();
    rotated.set_scene(scene.clone());
    for line in ["object 3", "object rotate y"] {
        rotated.run(&octovox::script::parse_script(Path::new("r.ovr"), line).unwrap().lines[0].command).unwrap();
    }
    let mut f = Fixture::new(scene, DVec3::new(2.0, 120.0, 8.0), DVec3::new(0.0, 0.0, 0.0));
    f.session.execute(AppCommand::ToggleObject);
    f.session.execute(AppCommand::Object(octovox::script::ObjectLine::Pick(octovox::script::ObjectRef::Index(3))));
    let (centre, radius) = f.session.ring().expect("a ring around the picked object");
    let at = |degrees: f64| {
        let a = degrees.to_radians();
        (centre.x + radius * a.cos(), centre.y - radius * a.sin())
    };
    let path: Vec<(f64, f64)> = (0..=9).map(|k| at(f64::from(k) * 10.0)).collect();
    f.drag(Tool::Attach, &path);
    let lines = f.recorded(EDITS);
    assert_eq!(lines[..2], ["object 3", "stroke begin"], "{lines:?}");
    assert_eq!(lines.last().map(String::as_str), Some("stroke end"));
    let turned: f64 = lines[2..lines.len() - 1]
        .iter()
        .map(|l| l.strip_prefix("object turn y ").expect("a turn about y").parse::<f64>().unwrap())
        .sum();
    assert_eq!(turned, 90.0, "{lines:?}");
    assert_eq!(f.session.doc.editor.history.steps(), (1, 0), "one undo step");
    assert!(f.session.doc.editor.scene.voxels() == rotated.scene.voxels(), "the cells of a quarter rotate");
    f.replays_the_same();
}

/// File ▸ Play script… asks for a script, and the chosen one plays a
/// line a frame through the edit path, from the scene as it is; its
/// `expect` lines pass.
#[test]
fn a_script_chosen_in_the_window_plays_from_the_scene_as_it_is() {
    let mut f = Fixture::floor();
    f.session.execute(AppCommand::AskPlayScript);
    let asked = f.session.take_effects().ask_path;
    assert_eq!(asked.map(|(kind, _)| kind), Some(crate::app::dialog_kind::DialogKind::PlayScript));
    let script = f.dir.path().join("tower.ovr");
    std::fs::write(&script, "color 5\nplace 3 1 3\nplace 3 2 3\nexpect voxel 3 2 3 5\nexpect count 66\n").unwrap();
    f.session.execute(AppCommand::PlayScript(script));
    let mut frames = 0;
    while f.session.doc.player.is_some() {
        f.session.play_step();
        frames += 1;
    }
    assert_eq!(frames, 6, "a line a frame, then the summary");
    let scene = &f.session.doc.editor.scene;
    assert_eq!((scene.voxel(IVec3::new(3, 1, 3)), scene.voxel(IVec3::new(3, 0, 3))), (5, 1), "placed on the floor");
    assert!(f.session.doc.editor.history.can_undo());
}
