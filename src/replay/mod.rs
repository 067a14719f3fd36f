//! The replay language: scripts of edits, camera moves, renders and
//! expectations, run headless by `octovox replay` and played or recorded by
//! the window. `docs/replay.md` describes it.

mod parse;
mod record;
mod run;

use std::fmt;
use std::path::PathBuf;

use glam::{DVec3, IVec3};

use crate::tool::{Brush, Tool};

pub use parse::{MAX_SCRIPT_BYTES, ScriptError, load_script, parse_script, split_words};
pub use record::Recorder;
pub use run::{Failure, Runner, RunnerMode, ScriptReport, StepResult};

/// One line of a script.
#[derive(Clone, Debug, PartialEq)]
pub enum Command {
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
    Brush(Brush),
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
    Line(IVec3, IVec3),
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
}

/// A parsed command with its 1-based line number.
#[derive(Clone, Debug, PartialEq)]
pub struct Line {
    pub number: usize,
    pub command: Command,
}

/// A parsed script: its file (for messages and relative paths) and lines.
#[derive(Clone, Debug)]
pub struct Script {
    pub path: PathBuf,
    pub lines: Vec<Line>,
}

/// Writes a command back as a script line (what `--record` produces).
impl fmt::Display for Command {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let v = |p: IVec3| format!("{} {} {}", p.x, p.y, p.z);
        match self {
            Command::Load(path) => write!(f, "load {}", quoted(path)),
            Command::New => write!(f, "new"),
            Command::Demo(crate::scene::demo::BuiltIn::Terrain) => write!(f, "demo"),
            Command::Demo(built_in) => write!(f, "demo {}", built_in.name()),
            Command::Camera { eye, target, fov } => {
                write!(f, "camera {} {} {} {} {} {}", eye.x, eye.y, eye.z, target.x, target.y, target.z)?;
                match fov {
                    Some(fov) => write!(f, " {fov}"),
                    None => Ok(()),
                }
            }
            Command::Viewport(w, h) => write!(f, "viewport {w} {h}"),
            Command::Brush(Brush::Voxel) => write!(f, "brush voxel"),
            Command::Brush(Brush::Sphere(r)) => write!(f, "brush sphere {r}"),
            Command::Brush(Brush::Box(s)) => write!(f, "brush box {}", v(*s)),
            Command::Color(c) => write!(f, "color {c}"),
            Command::Place(p) => write!(f, "place {}", v(*p)),
            Command::Remove(p) => write!(f, "remove {}", v(*p)),
            Command::Paint(p) => write!(f, "paint {}", v(*p)),
            Command::Click { x, y, tool } => write!(f, "click {x} {y} {}", tool.name()),
            Command::Undo(n) => write!(f, "undo {n}"),
            Command::Redo(n) => write!(f, "redo {n}"),
            Command::Save(path) => write!(f, "save {}", quoted(path)),
            Command::Render(path) => write!(f, "render {}", quoted(path)),
            Command::ExpectVoxel(p, n) => write!(f, "expect voxel {} {n}", v(*p)),
            Command::ExpectCount(n) => write!(f, "expect count {n}"),
            Command::ExpectWritten(n) => write!(f, "expect written <= {n}"),
            Command::ExpectImage(path, tol) => write!(f, "expect image {} {tol}", quoted(path)),
            Command::Fill(p) => write!(f, "fill {}", v(*p)),
            Command::Extrude(p, n, layers) => write!(f, "extrude {} {} {layers}", v(*p), v(*n)),
            Command::Line(a, b) => write!(f, "line {} {}", v(*a), v(*b)),
            Command::Mirror(None) => write!(f, "mirror off"),
            Command::Mirror(Some((axis, c))) => write!(f, "mirror {} {c}", ["x", "y", "z"][*axis]),
            Command::Pick(p) => write!(f, "pick {}", v(*p)),
            Command::Rgb(index, [r, g, b]) => write!(f, "rgb {index} {r} {g} {b}"),
            Command::Material(index, material) => {
                write!(f, "material {index} {}", &material.kind.vox_name()[1..])?;
                material.params.iter().try_for_each(|(key, value)| write!(f, " {key} {value}"))
            }
            Command::Select(None) => write!(f, "select off"),
            Command::Select(Some((a, b))) => write!(f, "select {} {}", v(*a), v(*b)),
            Command::Copy => write!(f, "copy"),
            Command::Cut => write!(f, "cut"),
            Command::Delete => write!(f, "delete"),
            Command::Paste(p) => write!(f, "paste {}", v(*p)),
            Command::Move(d) => write!(f, "move {}", v(*d)),
            Command::ExpectEffects(names) if names.is_empty() => write!(f, "expect effects none"),
            Command::ExpectEffects(names) => write!(f, "expect effects {}", names.join(" ")),
        }
    }
}

/// A path as a script word: as it is, or in quotes when it holds spaces,
/// `#`, quotes, backslashes or control characters: `\"` and `\\` for
/// quotes and backslashes, `\n`, `\r`, `\t` and `\u{HEX}` for control
/// characters (a name with a newline would otherwise end the line).
pub fn quoted(path: &std::path::Path) -> String {
    let text = path.to_string_lossy();
    let special = |c: char| c.is_whitespace() || c.is_control() || matches!(c, '#' | '"' | '\\');
    if !text.is_empty() && !text.chars().any(special) {
        return text.into_owned();
    }
    let mut out = String::with_capacity(text.len() + 2);
    out.push('"');
    for c in text.chars() {
        match c {
            '"' | '\\' => {
                out.push('\\');
                out.push(c);
            }
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            c if c.is_control() => out.push_str(&format!("\\u{{{:x}}}", u32::from(c))),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// The edit a `place`/`remove`/`paint` line (or a recorded click) becomes.
pub fn edit_command(tool: Tool, at: IVec3) -> Command {
    match tool {
        Tool::Attach => Command::Place(at),
        Tool::Erase => Command::Remove(at),
        Tool::Paint => Command::Paint(at),
    }
}

/// `expect effects`: whether the path tracer's effect set for this scene
/// with `settings` is exactly `want` (in any order), and the set's names.
pub fn effects_match(
    scene: &crate::scene::Scene,
    settings: &crate::settings::PathSettings,
    want: &[String],
) -> (bool, Vec<&'static str>) {
    let names = crate::trace::path::effects_for(&scene.tree, &scene.palette, settings).names();
    let mut got = names.clone();
    let mut expected: Vec<&str> = want.iter().map(String::as_str).collect();
    got.sort_unstable();
    expected.sort_unstable();
    (got == expected, names)
}

/// The edit a palette line (`rgb`, `material`) makes on `palette`; `None`
/// for other lines. The replay runner and the window's player both use it.
pub fn palette_edit(command: &Command, palette: &crate::scene::Palette) -> Option<crate::edit::Edit> {
    let (index, color, material) = match command {
        Command::Rgb(index, [r, g, b]) => (*index, [*r, *g, *b, 255], palette.material(*index).clone()),
        Command::Material(index, material) => (*index, palette.color(*index), (**material).clone()),
        _ => return None,
    };
    Some(crate::edit::Edit::Palette { index, color, material: Box::new(material) })
}

/// `pick X Y Z`: the colour of the voxel there, or why there is none.
pub fn picked_color(scene: &crate::scene::Scene, at: IVec3) -> Result<u8, String> {
    match scene.tree.get(at) {
        0 => Err(format!("no voxel at {at} to pick a colour from")),
        value => Ok(value),
    }
}
