//! What the user (or, later, a replay script) asks the app to do. The panels
//! and the input handler produce these; `Session::execute` is the one place that
//! carries them out, so a scripted edit and a mouse edit share every step.

use std::path::PathBuf;

use octovox::edit::Edit;

use super::state::Tool;

/// Where a pointer edit is in its stroke.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StrokePhase {
    /// Button pressed: open an undo step and edit under the pointer.
    Begin,
    /// Pointer moved with the button held: edit the new cell, same undo step.
    Move,
    /// Button released: close the undo step.
    End,
    /// A press and release in one (a right click, or a scripted click).
    Click,
}

/// A direction on screen for the arrow keys, as the camera sees it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Nudge {
    Left,
    Right,
    Away,
    Near,
    Up,
    Down,
}

/// What the unsaved-changes prompt was opened for.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Pending {
    New,
    Open(PathBuf),
    Quit,
}

/// The answer to the unsaved-changes prompt.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Choice {
    Save,
    Discard,
    Cancel,
}

#[derive(Clone, Debug, PartialEq)]
pub enum AppCommand {
    /// Edit with `tool` at the window pixel `(x, y)` (physical pixels).
    PointerEdit {
        phase: StrokePhase,
        tool: Tool,
        x: f64,
        y: f64,
    },
    /// A palette entry changed in the panel; while `dragging` (a slider or
    /// the colour picker held), the changes join one undo step.
    EditPalette {
        edit: Edit,
        dragging: bool,
    },
    Undo,
    Redo,
    /// Flood fill from the voxel under window pixel (x, y) with the current
    /// colour (Shift+click with the Paint tool).
    FillAt {
        x: f64,
        y: f64,
    },
    /// The eyedropper: the colour of the voxel under window pixel (x, y)
    /// becomes the current colour.
    PickColor {
        x: f64,
        y: f64,
    },
    /// Ctrl+drag from a face: extrude its coplanar region by the layers
    /// the drag covers along the face's normal on screen (Begin, then End).
    ExtrudeDrag {
        phase: StrokePhase,
        x: f64,
        y: f64,
    },
    /// Line mode on or off (L).
    ToggleLine,
    /// Box select mode on or off (B): a left drag selects a box, or drags
    /// a face of the selected one.
    ToggleSelect,
    /// Object mode on or off (Tab).
    ToggleObject,
    /// An `object` line on the picked object (the Object menu's keys).
    Object(octovox::script::ObjectLine),
    /// Script lines a panel or dialog asks for, run in order (the Objects
    /// panel's `object N` and `object hide`, the Layers panel's `layer N
    /// hide`, the palette's `palette preset`, `load` and `save`).
    Lines(Vec<octovox::script::Line>),
    /// Show frame N while playing or scrubbing: the editor's `frame N`,
    /// not recorded or journaled (the frame where it stops is a line).
    ShowFrame(u32),
    /// Play or pause the animation (Space).
    TogglePlay,
    /// Show the frame before (−1) or after (+1), as a `frame N` line.
    StepFrame(i32),
    /// Key the object the timeline keys at the frame shown (true: K), or
    /// take its key there out (false: Shift+K).
    Key(bool),
    /// Edit ▸ Copy, Cut, Delete, Select none: the `copy`, `cut`, `delete`
    /// and `select off` lines.
    Copy,
    Cut,
    DeleteSelection,
    SelectNone,
    /// `paste` with the block's min corner in front of the face under the cursor.
    PasteAtCursor,
    /// `move` the selection one voxel along the world axis nearest to a
    /// direction on screen (arrow keys, Page Up / Page Down).
    Nudge(Nudge),
    /// `rotate` (a quarter turn about world axis `axis`) or `flip` (a
    /// mirror image along it) of the selection.
    Turn {
        axis: usize,
        flip: bool,
    },
    /// Set the quality knobs to preset `PRESETS[i]`.
    ApplyPreset(usize),
    /// Measure what each preset costs and how far it is from the reference.
    MeasurePresets,
    SetTool(Tool),
    Orbit {
        dx: f64,
        dy: f64,
    },
    Pan {
        dx: f64,
        dy: f64,
    },
    /// Wheel `steps` toward the point under window pixel `at`, if any.
    Zoom {
        steps: f64,
        at: Option<(f64, f64)>,
    },
    /// Orthographic ↔ perspective.
    ToggleProjection,
    /// Look at the target from this side (a world axis: +z front, +x right, +y top).
    ViewFrom(glam::IVec3),
    FrameModel,
    /// Frame the selected box (the model when nothing is selected).
    FrameSelection,
    /// Start over with an empty scene (asks first if there are unsaved changes).
    New,
    /// Load a .vox on a background thread (asks first if there are unsaved changes).
    Open(PathBuf),
    /// Save to the current file, or ask for one.
    Save,
    SaveAs(PathBuf),
    /// Save As, replacing the file even though it is read-only (the user
    /// said so in the prompt).
    SaveOver(PathBuf),
    /// Write the visible faces as an .obj, .ply or .glb mesh.
    Export(PathBuf),
    /// Show the Open, Save As or Export path dialog.
    AskOpen,
    AskSaveAs,
    AskExport,
    /// Ask for a replay script to play in the window.
    AskPlayScript,
    /// Play a replay script (.ovr) from the scene as it is, a line a frame,
    /// as `--replay` does.
    PlayScript(PathBuf),
    /// Ask for a palette file to load, or to save the palette to.
    AskPalette {
        save: bool,
    },
    Screenshot,
    Quit,
    /// Answer to the unsaved-changes prompt.
    Resolve(Choice),
    /// Answers to the crash-recovery prompt: apply the open document's
    /// journal (to a document changed since, if the checks say so), or
    /// delete it.
    RecoverJournal(PathBuf, octovox::journal::Checks),
    DiscardJournal(PathBuf),
}

impl AppCommand {
    /// Whether the animation may go on playing while it runs: the view's
    /// commands and playing's own. Any other stops playing first, at a
    /// `frame N` line, so that what it does is recorded at its frame and
    /// reads the frame composed.
    pub fn keeps_playing(&self) -> bool {
        matches!(
            self,
            AppCommand::ShowFrame(_)
                | AppCommand::TogglePlay
                | AppCommand::Orbit { .. }
                | AppCommand::Pan { .. }
                | AppCommand::Zoom { .. }
                | AppCommand::ToggleProjection
                | AppCommand::ViewFrom(_)
                | AppCommand::Screenshot
        )
    }

    /// Whether the command edits the scene: refused while a file loads
    /// (the scene it would edit is about to be replaced).
    pub fn edits_scene(&self) -> bool {
        matches!(
            self,
            AppCommand::PointerEdit { .. }
                | AppCommand::ExtrudeDrag { .. }
                | AppCommand::EditPalette { .. }
                | AppCommand::Cut
                | AppCommand::DeleteSelection
                | AppCommand::PasteAtCursor
                | AppCommand::Nudge(_)
                | AppCommand::Turn { .. }
                | AppCommand::Undo
                | AppCommand::Redo
                | AppCommand::ShowFrame(_)
                | AppCommand::TogglePlay
                | AppCommand::StepFrame(_)
                | AppCommand::Key(_)
        )
    }
}
