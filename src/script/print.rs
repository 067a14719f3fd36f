//! Writing commands back as script lines (what `--record` and the crash
//! journal produce); the parser reads every line this writes.

use std::fmt;

use glam::IVec3;

use super::{AnimLine, LayerLine, Line, ObjectLine, ObjectRef, PaletteLine};
use crate::edit::brush::Brush;

/// Writes a command back as a script line (what `--record` produces).
impl fmt::Display for Line {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let v = |p: IVec3| format!("{} {} {}", p.x, p.y, p.z);
        match self {
            Line::Load(path) => write!(f, "load {}", quoted(path)),
            Line::New => write!(f, "new"),
            Line::Demo(crate::scene::demo::BuiltIn::Terrain) => write!(f, "demo"),
            Line::Demo(built_in) => write!(f, "demo {}", built_in.name()),
            Line::Camera { eye, target, fov } => {
                write!(f, "camera {} {} {} {} {} {}", eye.x, eye.y, eye.z, target.x, target.y, target.z)?;
                match fov {
                    Some(fov) => write!(f, " {fov}"),
                    None => Ok(()),
                }
            }
            Line::Viewport(w, h) => write!(f, "viewport {w} {h}"),
            Line::Projection(Some(height)) => write!(f, "ortho {height}"),
            Line::Projection(None) => write!(f, "perspective"),
            Line::Stroke(begin) => write!(f, "stroke {}", if *begin { "begin" } else { "end" }),
            Line::Ground(on) => write!(f, "ground {}", if *on { "on" } else { "off" }),
            Line::Brush(Brush::Voxel) => write!(f, "brush voxel"),
            Line::Brush(Brush::Sphere(r)) => write!(f, "brush sphere {r}"),
            Line::Brush(Brush::Box(s)) => write!(f, "brush box {}", v(*s)),
            Line::Color(c) => write!(f, "color {c}"),
            Line::Place(p) => write!(f, "place {}", v(*p)),
            Line::Remove(p) => write!(f, "remove {}", v(*p)),
            Line::Paint(p) => write!(f, "paint {}", v(*p)),
            Line::Click { x, y, tool } => write!(f, "click {x} {y} {}", tool.name()),
            Line::Undo(n) => write!(f, "undo {n}"),
            Line::Redo(n) => write!(f, "redo {n}"),
            Line::Save(path) => write!(f, "save {}", quoted(path)),
            Line::Render(path) => write!(f, "render {}", quoted(path)),
            Line::ExpectVoxel(p, n) => write!(f, "expect voxel {} {n}", v(*p)),
            Line::ExpectCount(n) => write!(f, "expect count {n}"),
            Line::ExpectWritten(n) => write!(f, "expect written <= {n}"),
            Line::ExpectImage(path, tol) => write!(f, "expect image {} {tol}", quoted(path)),
            Line::Fill(p) => write!(f, "fill {}", v(*p)),
            Line::Extrude(p, n, layers) => write!(f, "extrude {} {} {layers}", v(*p), v(*n)),
            Line::Segment(a, b) => write!(f, "line {} {}", v(*a), v(*b)),
            Line::Mirror(None) => write!(f, "mirror off"),
            Line::Mirror(Some((axis, c))) => write!(f, "mirror {} {c}", ["x", "y", "z"][*axis]),
            Line::Pick(p) => write!(f, "pick {}", v(*p)),
            Line::Rgb(index, [r, g, b]) => write!(f, "rgb {index} {r} {g} {b}"),
            Line::Material(index, material) => {
                write!(f, "material {index} {}", &material.kind.vox_name()[1..])?;
                material.params.iter().try_for_each(|(key, value)| write!(f, " {key} {value}"))
            }
            Line::Select(None) => write!(f, "select off"),
            Line::Select(Some((a, b))) => write!(f, "select {} {}", v(*a), v(*b)),
            Line::Copy => write!(f, "copy"),
            Line::Cut => write!(f, "cut"),
            Line::Delete => write!(f, "delete"),
            Line::Paste(p) => write!(f, "paste {}", v(*p)),
            Line::Move(d) => write!(f, "move {}", v(*d)),
            Line::Rotate(axis) => write!(f, "rotate {}", ["x", "y", "z"][*axis]),
            Line::Flip(axis) => write!(f, "flip {}", ["x", "y", "z"][*axis]),
            Line::ExpectEffects(names) if names.is_empty() => write!(f, "expect effects none"),
            Line::ExpectEffects(names) => write!(f, "expect effects {}", names.join(" ")),
            Line::Object(ObjectLine::Pick(ObjectRef::Index(n))) => write!(f, "object {n}"),
            Line::Object(ObjectLine::Pick(ObjectRef::Name(name))) => {
                write!(f, "object {}", quoted_name(name))
            }
            Line::Object(ObjectLine::Hide(true)) => write!(f, "object hide"),
            Line::Object(ObjectLine::Hide(false)) => write!(f, "object show"),
            Line::Object(ObjectLine::Lock(true)) => write!(f, "object lock"),
            Line::Object(ObjectLine::Lock(false)) => write!(f, "object unlock"),
            Line::Object(ObjectLine::New(name)) => write!(f, "object new {}", quoted_name(name)),
            Line::Object(ObjectLine::Move(d)) => write!(f, "object move {}", v(*d)),
            Line::Object(ObjectLine::Rotate(axis)) => write!(f, "object rotate {}", ["x", "y", "z"][*axis]),
            Line::Object(ObjectLine::Duplicate { reference: false }) => write!(f, "object duplicate"),
            Line::Object(ObjectLine::Duplicate { reference: true }) => write!(f, "object duplicate reference"),
            Line::Object(ObjectLine::Unique) => write!(f, "object unique"),
            Line::Object(ObjectLine::Regroup(target, after)) => {
                write!(f, "object {} ", if *after { "after" } else { "before" })?;
                match target {
                    ObjectRef::Index(i) => write!(f, "{i}"),
                    ObjectRef::Name(name) => write!(f, "{}", quoted_name(name)),
                }
            }
            Line::Object(ObjectLine::Merge(others)) => {
                write!(f, "object merge")?;
                for other in others {
                    match other {
                        ObjectRef::Index(i) => write!(f, " {i}")?,
                        ObjectRef::Name(name) => write!(f, " {}", quoted_name(name))?,
                    }
                }
                Ok(())
            }
            Line::Object(ObjectLine::Delete) => write!(f, "object delete"),
            Line::Object(ObjectLine::Rename(name)) => {
                write!(f, "object rename {}", quoted_name(name))
            }
            Line::Object(ObjectLine::Layer(id)) => write!(f, "object layer {id}"),
            Line::Object(ObjectLine::Key(ease)) => write!(f, "object key {}", ease.name()),
            Line::Object(ObjectLine::Unkey) => write!(f, "object unkey"),
            // Rust prints the shortest text that reads back as the same number.
            Line::Object(ObjectLine::Turn { axis, degrees }) => {
                write!(f, "object turn {} {}", ["x", "y", "z"][*axis], degrees.0)
            }
            // The same word as the world cell's edit (`place`, `remove`, `paint`).
            Line::Object(ObjectLine::Cell { tool, at }) => {
                write!(f, "object {} {}", super::edit_command(*tool, *at).word(), v(*at))
            }
            Line::Frame(n) => write!(f, "frame {n}"),
            Line::Anim(AnimLine::Range(a, b)) => write!(f, "anim range {a} {b}"),
            Line::Anim(AnimLine::Fps(n)) => write!(f, "anim fps {n}"),
            Line::Anim(AnimLine::Loop(on)) => write!(f, "anim loop {}", if *on { "on" } else { "off" }),
            Line::ExpectFrame(n) => write!(f, "expect frame {n}"),
            Line::Layer(id, LayerLine::Hide(true)) => write!(f, "layer {id} hide"),
            Line::Layer(id, LayerLine::Hide(false)) => write!(f, "layer {id} show"),
            Line::Layer(id, LayerLine::Name(name)) => write!(f, "layer {id} {}", quoted_name(name)),
            Line::Layer(id, LayerLine::Color([r, g, b])) => write!(f, "layer {id} color {r} {g} {b}"),
            Line::Layer(id, LayerLine::Active) => write!(f, "layer {id} active"),
            Line::Palette(PaletteLine::Load(path)) => write!(f, "palette load {}", quoted(path)),
            Line::Palette(PaletteLine::Save(path)) => write!(f, "palette save {}", quoted(path)),
            Line::Palette(PaletteLine::Set { first, colors }) => {
                write!(f, "palette set {first}")?;
                colors.iter().try_for_each(|[r, g, b]| write!(f, " {r:02x}{g:02x}{b:02x}"))
            }
            Line::Palette(PaletteLine::Preset(name)) => write!(f, "palette preset {name}"),
            Line::ExpectPalette(index, [r, g, b]) => write!(f, "expect palette {index} {r} {g} {b}"),
            Line::ExpectObjects(n) => write!(f, "expect objects {n}"),
            Line::ExpectModels(n) => write!(f, "expect models {n}"),
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
