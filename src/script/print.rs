//! Writing commands back as script lines (what `--record` and the crash
//! journal produce); the parser reads every line this writes.

use std::fmt;

use glam::IVec3;

use super::{Command, LayerLine, ObjectLine, ObjectRef, PaletteLine};
use crate::edit::brush::Brush;

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
            Command::Projection(Some(height)) => write!(f, "ortho {height}"),
            Command::Projection(None) => write!(f, "perspective"),
            Command::Ground(on) => write!(f, "ground {}", if *on { "on" } else { "off" }),
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
            Command::Rotate(axis) => write!(f, "rotate {}", ["x", "y", "z"][*axis]),
            Command::Flip(axis) => write!(f, "flip {}", ["x", "y", "z"][*axis]),
            Command::ExpectEffects(names) if names.is_empty() => write!(f, "expect effects none"),
            Command::ExpectEffects(names) => write!(f, "expect effects {}", names.join(" ")),
            Command::Object(ObjectLine::Pick(ObjectRef::Index(n))) => write!(f, "object {n}"),
            Command::Object(ObjectLine::Pick(ObjectRef::Name(name))) => {
                write!(f, "object {}", quoted_name(name))
            }
            Command::Object(ObjectLine::Hide(true)) => write!(f, "object hide"),
            Command::Object(ObjectLine::Hide(false)) => write!(f, "object show"),
            Command::Object(ObjectLine::Lock(true)) => write!(f, "object lock"),
            Command::Object(ObjectLine::Lock(false)) => write!(f, "object unlock"),
            Command::Object(ObjectLine::New(name)) => write!(f, "object new {}", quoted_name(name)),
            Command::Object(ObjectLine::Move(d)) => write!(f, "object move {}", v(*d)),
            Command::Object(ObjectLine::Rotate(axis)) => write!(f, "object rotate {}", ["x", "y", "z"][*axis]),
            Command::Object(ObjectLine::Duplicate { reference: false }) => write!(f, "object duplicate"),
            Command::Object(ObjectLine::Duplicate { reference: true }) => write!(f, "object duplicate reference"),
            Command::Object(ObjectLine::Unique) => write!(f, "object unique"),
            Command::Object(ObjectLine::Regroup(target, after)) => {
                write!(f, "object {} ", if *after { "after" } else { "before" })?;
                match target {
                    ObjectRef::Index(i) => write!(f, "{i}"),
                    ObjectRef::Name(name) => write!(f, "{}", quoted_name(name)),
                }
            }
            Command::Object(ObjectLine::Merge(others)) => {
                write!(f, "object merge")?;
                for other in others {
                    match other {
                        ObjectRef::Index(i) => write!(f, " {i}")?,
                        ObjectRef::Name(name) => write!(f, " {}", quoted_name(name))?,
                    }
                }
                Ok(())
            }
            Command::Object(ObjectLine::Delete) => write!(f, "object delete"),
            Command::Object(ObjectLine::Rename(name)) => {
                write!(f, "object rename {}", quoted_name(name))
            }
            Command::Object(ObjectLine::Layer(id)) => write!(f, "object layer {id}"),
            Command::Layer(id, LayerLine::Hide(true)) => write!(f, "layer {id} hide"),
            Command::Layer(id, LayerLine::Hide(false)) => write!(f, "layer {id} show"),
            Command::Layer(id, LayerLine::Name(name)) => write!(f, "layer {id} {}", quoted_name(name)),
            Command::Layer(id, LayerLine::Color([r, g, b])) => write!(f, "layer {id} color {r} {g} {b}"),
            Command::Layer(id, LayerLine::Active) => write!(f, "layer {id} active"),
            Command::Palette(PaletteLine::Load(path)) => write!(f, "palette load {}", quoted(path)),
            Command::Palette(PaletteLine::Save(path)) => write!(f, "palette save {}", quoted(path)),
            Command::Palette(PaletteLine::Set { first, colors }) => {
                write!(f, "palette set {first}")?;
                colors.iter().try_for_each(|[r, g, b]| write!(f, " {r:02x}{g:02x}{b:02x}"))
            }
            Command::Palette(PaletteLine::Preset(name)) => write!(f, "palette preset {name}"),
            Command::ExpectPalette(index, [r, g, b]) => write!(f, "expect palette {index} {r} {g} {b}"),
            Command::ExpectObjects(n) => write!(f, "expect objects {n}"),
            Command::ExpectModels(n) => write!(f, "expect models {n}"),
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
    in_quotes(&text)
}

/// A name (of an object, a group path or a layer) as a script word: as it
/// is when it is a plain word (letters, digits, `_ - . /`, not all digits
/// and not a word the parser reads as a keyword where a name may stand),
/// else in quotes, which the parser always reads as a name.
pub fn quoted_name(name: &str) -> String {
    let plain_char = |c: char| c.is_alphanumeric() || matches!(c, '_' | '-' | '.' | '/');
    let plain = name.chars().all(plain_char)
        && !name.bytes().all(|b| b.is_ascii_digit())
        && !super::parse::NAME_KEYWORDS.contains(&name);
    if plain { name.to_owned() } else { in_quotes(name) }
}

/// `text` in quotes, with quotes, backslashes and control characters escaped.
fn in_quotes(text: &str) -> String {
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
