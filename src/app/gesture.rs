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
    pub plane: Option<(IVec3, i32)>,
    pub last_center: Option<IVec3>,
}

impl Gesture {
    /// Whether the gesture's edits are one undo step (between the `stroke
    /// begin` and `stroke end` it runs): a brush stroke, a held palette
    /// control, an object drag.
    pub fn groups_edits(&self) -> bool {
        matches!(self, Gesture::Stroke(_) | Gesture::Palette | Gesture::ObjectDrag { .. })
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
