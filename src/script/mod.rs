//! The script language: its syntax tree ([`Line`], [`NumberedLine`],
//! [`Script`]), the parser and the printer. Scripts are run headless by
//! `octovox replay`, played and recorded by the window and written by the
//! crash journal; `docs/replay.md` describes them. This room knows no
//! editor, no GPU and no window: `crate::replay` runs what it parses.

mod parse;
mod print;

use std::path::PathBuf;

use glam::{DVec3, IVec3};

use crate::edit::brush::{Brush, Tool};
use crate::scene::anim::Ease;

pub use parse::{MAX_SCRIPT_BYTES, ScriptError, load_script, parse_script, split_words};
pub use print::quoted;

/// One line of a script.
#[derive(Clone, Debug, PartialEq)]
pub enum Line {
    Load(PathBuf),
    New,
    /// The built-in demo scene (what the window opens without a file).
    /// A built-in scene (`demo` alone: the terrain).
    Demo(crate::scene::demo::BuiltIn),
    Camera {
        eye: DVec3,
        target: DVec3,
        fov: Option<f32>,
    },
    Viewport(u32, u32),
    /// `ortho HEIGHT`: an orthographic view showing HEIGHT world voxels
    /// from the image's bottom to its top (the `camera` line's eye gives the
    /// direction only); `perspective` (None) goes back to the field of view.
    Projection(Option<f32>),
    Brush(Brush),
    /// `stroke begin` (true), `stroke end` (false): the edits between are
    /// one undo step, as a mouse drag or a held palette control makes them.
    /// A line that [`Line::ends_stroke`] ends an open one first.
    Stroke(bool),
    /// `ground on|off`: whether a `click` (and the mouse) that hits no voxel
    /// lands on the ground, the plane y = 0 (on after `new`, or any scene
    /// that starts empty).
    Ground(bool),
    Color(u8),
    Place(IVec3),
    Remove(IVec3),
    Paint(IVec3),
    Click {
        x: u32,
        y: u32,
        tool: Tool,
    },
    Undo(u32),
    Redo(u32),
    Save(PathBuf),
    Render(PathBuf),
    ExpectVoxel(IVec3, u8),
    ExpectCount(u64),
    ExpectWritten(u64),
    ExpectImage(PathBuf, f64),
    /// The path tracer's effect set for the scene, as names (any order).
    ExpectEffects(Vec<String>),
    /// `line X1 Y1 Z1 X2 Y2 Z2`: the brush placed with the current colour at
    /// every cell of the line, ends included (one undo step).
    Segment(IVec3, IVec3),
    /// `mirror x|y|z C`: later brush edits are also applied mirrored across
    /// the plane at C (a whole or half number); `mirror off` ends them all.
    Mirror(Option<(usize, f64)>),
    /// `fill X Y Z`: the 6-connected region of the voxel's colour takes the
    /// current colour (one undo step).
    Fill(IVec3),
    /// `pick X Y Z`: the eyedropper; the voxel's colour becomes the current one.
    Pick(IVec3),
    /// `extrude X Y Z NX NY NZ N`: the connected coplanar faces facing
    /// (NX, NY, NZ) around voxel (X, Y, Z)'s move out N layers (in, N < 0).
    Extrude(IVec3, IVec3, i32),
    /// `rgb INDEX R G B`: a palette entry's colour (an undoable edit).
    Rgb(u8, [u8; 3]),
    /// `material INDEX KIND [KEY VALUE]...`: a palette entry's material,
    /// with exactly these parameters (an undoable edit).
    Material(u8, Box<crate::scene::Material>),
    /// `select X1 Y1 Z1 X2 Y2 Z2`: the inclusive box later `copy`, `cut`,
    /// `delete` and `move` act on; `select off` clears it.
    Select(Option<(IVec3, IVec3)>),
    /// `copy`: the selected voxels go to the clipboard.
    Copy,
    /// `cut`: copy, then delete (one undo step).
    Cut,
    /// `delete`: empties the selected box (one undo step).
    Delete,
    /// `paste X Y Z`: the clipboard's voxels with its box's min corner at
    /// (X, Y, Z), which becomes the selection (one undo step).
    Paste(IVec3),
    /// `move DX DY DZ`: the selected voxels move by (DX, DY, DZ), and the
    /// selection with them (one undo step).
    Move(IVec3),
    /// `rotate x|y|z`: the selected voxels turn a quarter counter-clockwise
    /// seen from the positive axis, about the selected box's centre; the
    /// selection becomes the turned box (one undo step).
    Rotate(usize),
    /// `flip x|y|z`: the selected voxels are mirrored along the axis within
    /// their box (one undo step).
    Flip(usize),
    /// `object N|NAME`: pick the object later edits go to (by index in
    /// walk order from 0, or by name or `group/name` path); the other
    /// `object` lines change the picked one (each an undoable edit).
    Object(ObjectLine),
    /// `layer N NAME`, `layer N hide|show` (an undoable edit).
    Layer(u32, LayerLine),
    /// `palette load PATH`, `palette save PATH`, `palette set INDEX HEX…`,
    /// `palette preset NAME`.
    Palette(PaletteLine),
    /// `expect palette INDEX R G B`: the entry's colour.
    ExpectPalette(u8, [u8; 3]),
    /// `expect objects N`: the scene places N objects.
    ExpectObjects(usize),
    /// `expect models N`: the scene stores N models (each once).
    ExpectModels(usize),
    /// `frame N`: show frame N of the animation (every key sampled there).
    Frame(u32),
    /// `anim range A B`, `anim fps N`, `anim loop on|off`.
    Anim(AnimLine),
    /// `expect frame N`: frame N is shown.
    ExpectFrame(u32),
}

impl Line {
    /// What kind of line it is: the one place the editor's grouping, the
    /// recorder and the journal read it from.
    pub fn kind(&self) -> Kind {
        match self {
            Line::Place(_) | Line::Paint(_) | Line::Segment(..) | Line::Fill(_) => Kind::Edit { color: true },
            Line::Object(ObjectLine::Cell { tool, .. }) => Kind::Edit { color: *tool != Tool::Erase },
            Line::Remove(_)
            | Line::Extrude(..)
            | Line::Cut
            | Line::Delete
            | Line::Paste(_)
            | Line::Move(_)
            | Line::Rotate(_)
            | Line::Flip(_)
            | Line::Rgb(..)
            | Line::Material(..)
            | Line::Layer(..)
            | Line::Object(
                ObjectLine::New(_)
                | ObjectLine::Move(_)
                | ObjectLine::Rotate(_)
                | ObjectLine::Duplicate { .. }
                | ObjectLine::Unique
                | ObjectLine::Regroup(..)
                | ObjectLine::Merge(_)
                | ObjectLine::Delete
                | ObjectLine::Hide(_)
                | ObjectLine::Lock(_)
                | ObjectLine::Rename(_)
                | ObjectLine::Layer(_)
                | ObjectLine::Key(_)
                | ObjectLine::Unkey
                | ObjectLine::Turn { .. },
            )
            | Line::Anim(_)
            | Line::Palette(PaletteLine::Set { .. } | PaletteLine::Preset(_)) => Kind::Edit { color: false },
            Line::Stroke(_) => Kind::Stroke,
            Line::Brush(_) | Line::Color(_) | Line::Mirror(_) => Kind::Tool,
            Line::Object(ObjectLine::Pick(_)) | Line::Select(_) | Line::Copy | Line::Frame(_) => Kind::State,
            Line::Undo(_) | Line::Redo(_) => Kind::History,
            Line::Load(_) | Line::New | Line::Demo(_) => Kind::Scene,
            Line::Camera { .. } | Line::Viewport(..) | Line::Projection(_) => Kind::View,
            Line::Ground(_)
            | Line::Pick(_)
            | Line::Click { .. }
            | Line::Save(_)
            | Line::Render(_)
            | Line::Palette(PaletteLine::Load(_) | PaletteLine::Save(_)) => Kind::Host,
            Line::ExpectVoxel(..)
            | Line::ExpectCount(_)
            | Line::ExpectWritten(_)
            | Line::ExpectImage(..)
            | Line::ExpectEffects(_)
            | Line::ExpectPalette(..)
            | Line::ExpectObjects(_)
            | Line::ExpectModels(_)
            | Line::ExpectFrame(_) => Kind::Check,
        }
    }

    /// Whether the line ends an open stroke before it runs: every line but
    /// the edits a stroke is made of (`place`, `remove`, `paint`, `object
    /// N`, `object move` and `object turn` of a drag, `rgb` and `material` of a held
    /// palette control), the view and the checks, which change nothing.
    /// The editor, the window's recorder and the crash journal go by this
    /// one rule, so a recording replays into the undo steps the window made.
    pub fn ends_stroke(&self) -> bool {
        let of_a_stroke = matches!(
            self,
            Line::Place(_)
                | Line::Remove(_)
                | Line::Paint(_)
                | Line::Rgb(..)
                | Line::Material(..)
                | Line::Object(
                    ObjectLine::Pick(_) | ObjectLine::Move(_) | ObjectLine::Turn { .. } | ObjectLine::Cell { .. }
                )
        );
        !of_a_stroke && !matches!(self.kind(), Kind::Stroke | Kind::View | Kind::Check)
    }

    /// Whether the line is a check (`expect …`), which changes nothing.
    pub fn is_check(&self) -> bool {
        self.kind() == Kind::Check
    }

    /// The command word the line starts with (`place`, `object`,
    /// `expect`, …): what the window's messages name a line by.
    pub fn word(&self) -> &'static str {
        match self {
            Line::Load(_) => "load",
            Line::New => "new",
            Line::Demo(_) => "demo",
            Line::Camera { .. } => "camera",
            Line::Viewport(..) => "viewport",
            Line::Projection(Some(_)) => "ortho",
            Line::Projection(None) => "perspective",
            Line::Brush(_) => "brush",
            Line::Stroke(_) => "stroke",
            Line::Ground(_) => "ground",
            Line::Color(_) => "color",
            Line::Place(_) => "place",
            Line::Remove(_) => "remove",
            Line::Paint(_) => "paint",
            Line::Click { .. } => "click",
            Line::Undo(_) => "undo",
            Line::Redo(_) => "redo",
            Line::Save(_) => "save",
            Line::Render(_) => "render",
            Line::ExpectVoxel(..)
            | Line::ExpectCount(_)
            | Line::ExpectWritten(_)
            | Line::ExpectImage(..)
            | Line::ExpectEffects(_)
            | Line::ExpectPalette(..)
            | Line::ExpectObjects(_)
            | Line::ExpectModels(_)
            | Line::ExpectFrame(_) => "expect",
            Line::Frame(_) => "frame",
            Line::Anim(_) => "anim",
            Line::Segment(..) => "line",
            Line::Mirror(_) => "mirror",
            Line::Fill(_) => "fill",
            Line::Pick(_) => "pick",
            Line::Extrude(..) => "extrude",
            Line::Rgb(..) => "rgb",
            Line::Material(..) => "material",
            Line::Select(_) => "select",
            Line::Copy => "copy",
            Line::Cut => "cut",
            Line::Delete => "delete",
            Line::Paste(_) => "paste",
            Line::Move(_) => "move",
            Line::Rotate(_) => "rotate",
            Line::Flip(_) => "flip",
            Line::Object(_) => "object",
            Line::Layer(..) => "layer",
            Line::Palette(_) => "palette",
        }
    }
}

/// What kind of line a [`Line`] is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A change to the scene: one undo step, or one edit of the open
    /// stroke; `color`: it uses the current colour.
    Edit { color: bool },
    /// `stroke begin`, `stroke end`.
    Stroke,
    /// The tools: brush, colour, mirror planes.
    Tool,
    /// The editor's other state: the picked object, the selection, the
    /// clipboard.
    State,
    /// `undo`, `redo`.
    History,
    /// A new scene: `load`, `new`, `demo`.
    Scene,
    /// The view: camera, viewport, projection.
    View,
    /// The host's: files written or read, the ground, the eyedropper, a
    /// click (which becomes an edit line).
    Host,
    /// A check (`expect …`).
    Check,
}

/// An angle in degrees as a script gives it, compared bit for bit (a line
/// printed and read again is the same line).
#[derive(Clone, Copy, Debug)]
pub struct Degrees(pub f64);

impl PartialEq for Degrees {
    fn eq(&self, other: &Degrees) -> bool {
        self.0.to_bits() == other.0.to_bits()
    }
}

impl Eq for Degrees {}

/// What an `object` line does.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ObjectLine {
    Pick(ObjectRef),
    /// `object new NAME`: an empty object in the top group, picked.
    New(String),
    /// `object move DX DY DZ` (world voxels).
    Move(IVec3),
    /// `object rotate x|y|z`: a quarter turn counter-clockwise seen from the
    /// positive axis, about the object's pivot.
    Rotate(usize),
    /// `object duplicate [reference]`: a copy (true: the same model placed again).
    Duplicate {
        reference: bool,
    },
    /// `object unique`: the picked placement gets a model of its own.
    Unique,
    /// `object before N|NAME` (false), `object after N|NAME` (true): the
    /// picked object goes into that object's group, next to it, staying
    /// where it is drawn.
    Regroup(ObjectRef, bool),
    /// `object merge N|NAME…`: the objects named become part of the picked
    /// one, whose new model holds all their voxels; they are deleted.
    Merge(Vec<ObjectRef>),
    Delete,
    /// `object hide` (true) or `object show` (false).
    Hide(bool),
    /// `object lock` (true) or `object unlock` (false).
    Lock(bool),
    Rename(String),
    /// `object layer N`.
    Layer(u32),
    /// `object turn x|y|z DEGREES`: turn counter-clockwise seen from the
    /// positive axis, about the pivot, by any finite angle.
    Turn {
        axis: usize,
        degrees: Degrees,
    },
    /// `object key [step|linear|smooth]`: key the transform at the frame
    /// shown with what it shows, eased that way to the next key.
    Key(Ease),
    /// `object unkey`: take the key at the frame shown out.
    Unkey,
    /// `object place|remove|paint X Y Z`: the brush at cell X Y Z of the
    /// picked object's model (its own cells, as its .vox numbers them):
    /// what a click on a freely turned object runs, as a model cell there
    /// may stand for no world cell.
    Cell {
        tool: Tool,
        at: IVec3,
    },
}

/// What an `anim` line sets (each an undoable edit of the document).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AnimLine {
    /// `anim range A B`: the frames played, A to B.
    Range(u32, u32),
    /// `anim fps N`.
    Fps(u32),
    /// `anim loop on|off`: whether playing starts again at the range's start.
    Loop(bool),
}

/// What a `palette` line does.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum PaletteLine {
    /// `palette load PATH`: a .png, .hex or .gpl file's colours from index 1
    /// on (one undo step; a recording writes the `palette set` it became).
    Load(PathBuf),
    /// `palette save PATH`: the 255 colours as .png (256×1), .hex or .gpl.
    Save(PathBuf),
    /// `palette set INDEX RRGGBB…`: colours from entry INDEX on (one undo step).
    Set { first: u8, colors: Vec<[u8; 3]> },
    /// `palette preset NAME`: a built-in palette (one undo step).
    Preset(String),
}

/// What a `layer N …` line does.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum LayerLine {
    /// `hide` (true) or `show` (false).
    Hide(bool),
    Name(String),
    /// `color R G B`.
    Color([u8; 3]),
    /// `active`: `object new` puts objects on this layer.
    Active,
}

impl LayerLine {
    /// The layer attribute the line sets (`None`: removes it), or `None`
    /// for `active`, which changes no layer.
    pub fn attribute(&self) -> Option<(&'static str, Option<String>)> {
        match self {
            LayerLine::Hide(hidden) => Some(("_hidden", hidden.then(|| "1".to_owned()))),
            LayerLine::Name(name) => Some(("_name", Some(name.clone()))),
            LayerLine::Color([r, g, b]) => Some(("_color", Some(format!("{r} {g} {b}")))),
            LayerLine::Active => None,
        }
    }
}

/// Which object an `object` line names.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ObjectRef {
    Index(usize),
    Name(String),
}

/// A parsed command with its 1-based line number.
#[derive(Clone, Debug, PartialEq)]
pub struct NumberedLine {
    pub number: usize,
    pub command: Line,
}

/// A parsed script: its file (for messages and relative paths) and lines.
#[derive(Clone, Debug)]
pub struct Script {
    pub path: PathBuf,
    pub lines: Vec<NumberedLine>,
}

/// The line a click with `tool` on `picked` runs: the edit of the world
/// cell it names ([`edit_command`]), or on a freely turned object the edit
/// of the model cell under the cursor, in the model's cells.
pub fn click_command(tool: Tool, picked: &crate::trace::pick::Picked) -> Line {
    use crate::edit::brush::click_target;
    match picked.model {
        Some(model) => Line::Object(ObjectLine::Cell { tool, at: click_target(tool, model.cell, model.normal) }),
        None => edit_command(tool, click_target(tool, picked.voxel, picked.normal)),
    }
}

/// The edit a `place`/`remove`/`paint` line (or a recorded click) becomes.
pub fn edit_command(tool: Tool, at: IVec3) -> Line {
    match tool {
        Tool::Attach => Line::Place(at),
        Tool::Erase => Line::Remove(at),
        Tool::Paint => Line::Paint(at),
    }
}
