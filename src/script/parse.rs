//! Parsing scripts: one command per line, `#` comments, errors that name the
//! file, line and column and what was expected.

use std::path::{Path, PathBuf};

use glam::{DVec3, IVec3};

use super::{AnimLine, Degrees, LayerLine, Line, NumberedLine, ObjectLine, ObjectRef, PaletteLine, Script};
use crate::camera::{FOV_RANGE_DEG, check_fov};
use crate::edit::brush::{Brush, Tool};
use crate::scene::anim::{Ease, MAX_FPS};
use crate::scene::demo::BuiltIn;
use crate::scene::shape::MAX_BRUSH_EXTENT;
use clap::ValueEnum as _;

/// A script that cannot be read or parsed, or a line that failed to run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{message} at {}:{line}:{column}", file.display())]
pub struct ScriptError {
    pub file: PathBuf,
    pub line: usize,
    pub column: usize,
    pub message: String,
}

/// A word of a line (quotes removed, escapes resolved) and the 1-based
/// column it starts at.
#[derive(Clone)]
struct Token {
    text: String,
    column: usize,
    /// Whether any of it was in quotes: a quoted word is a name or a path,
    /// never a keyword.
    quoted: bool,
}

/// The words that mean something where an object's or a layer's name may
/// also stand (`object hide`, `layer 0 color`): a name spelled like one is
/// written in quotes (`super::print::quoted_name`).
pub(super) const NAME_KEYWORDS: &[&str] = &[
    "before",
    "after",
    "merge",
    "hide",
    "show",
    "lock",
    "unlock",
    "new",
    "move",
    "rotate",
    "duplicate",
    "reference",
    "unique",
    "delete",
    "rename",
    "layer",
    "color",
    "active",
    "key",
    "unkey",
    "turn",
    "place",
    "remove",
    "paint",
];

/// Reads the tokens of one line, left to right, with errors that point at
/// the token (or at the end of the line when one is missing).
struct Cursor {
    tokens: Vec<Token>,
    next: usize,
    end_column: usize,
}

type Fail = (usize, String);

/// The words of `line` as a script line's are split (quotes removed,
/// escapes resolved, `#` starting a comment); the journal's notes use it.
///
/// # Errors
/// A quote that is not closed, or a bad escape.
pub fn split_words(line: &str) -> Result<Vec<String>, WordError> {
    Cursor::new(line).map(|cursor| cursor.tokens.into_iter().map(|t| t.text).collect()).map_err(|(_, error)| error)
}

/// Why the words of a line cannot be split.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum WordError {
    #[error("an escape at the end of the line")]
    EscapeAtEnd,
    #[error("expected \\u{{HEX}} (a character's code in hexadecimal)")]
    BadUnicodeEscape,
    #[error("a quote that is not closed on this line")]
    UnclosedQuote,
}

/// Why the count of `undo N` / `redo N` is refused.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
enum CountError {
    #[error("count {0} is too large (at most {max})", max = u32::MAX)]
    TooLarge(String),
    #[error("expected a count ≥ 1, found '{0}'")]
    NotACount(String),
}

/// The character an escape inside quotes stands for, the backslash read:
/// `\"`, `\\`, `\n`, `\r`, `\t` or `\u{HEX}` (what [`super::quoted`]
/// writes).
fn unescape(chars: &mut std::iter::Peekable<impl Iterator<Item = (char, usize)>>) -> Result<char, WordError> {
    let Some((c, _)) = chars.next() else { return Err(WordError::EscapeAtEnd) };
    Ok(match c {
        'n' => '\n',
        'r' => '\r',
        't' => '\t',
        'u' => {
            let bad = || WordError::BadUnicodeEscape;
            if chars.next().map(|(c, _)| c) != Some('{') {
                return Err(bad());
            }
            let mut hex = String::new();
            loop {
                match chars.next() {
                    Some(('}', _)) => break,
                    Some((c, _)) if c.is_ascii_hexdigit() && hex.len() < 6 => hex.push(c),
                    _ => return Err(bad()),
                }
            }
            u32::from_str_radix(&hex, 16).ok().and_then(char::from_u32).ok_or_else(bad)?
        }
        other => other,
    })
}

impl Token {
    fn new(column: usize) -> Token {
        Token { text: String::new(), column, quoted: false }
    }
}

impl Cursor {
    /// Splits a line into words: whitespace separates them, `"…"` quotes a
    /// word that holds spaces or `#` (with `\"` and `\\` inside), and `#`
    /// outside quotes starts a comment. One pass, so a long line costs
    /// linear time.
    fn new(line: &str) -> Result<Cursor, (usize, WordError)> {
        let mut tokens = Vec::new();
        let mut current: Option<Token> = None;
        let mut quote_column = None;
        let mut chars = line.chars().zip(1..).peekable();
        let mut end_column = 1;
        while let Some((c, column)) = chars.next() {
            if quote_column.is_some() {
                match c {
                    '"' => quote_column = None,
                    '\\' if matches!(chars.peek(), Some(('"' | '\\' | 'n' | 'r' | 't' | 'u', _))) => {
                        let escaped = unescape(&mut chars).map_err(|error| (column, error))?;
                        if let Some(token) = current.as_mut() {
                            token.text.push(escaped);
                        }
                    }
                    _ => current.get_or_insert_with(|| Token::new(column)).text.push(c),
                }
                end_column = column + 1;
                continue;
            }
            match c {
                '#' => break,
                c if c.is_whitespace() => tokens.extend(current.take()),
                '"' => {
                    quote_column = Some(column);
                    current.get_or_insert_with(|| Token::new(column)).quoted = true;
                }
                c => current.get_or_insert_with(|| Token::new(column)).text.push(c),
            }
            if !c.is_whitespace() {
                end_column = column + 1;
            }
        }
        if let Some(column) = quote_column {
            return Err((column, WordError::UnclosedQuote));
        }
        tokens.extend(current);
        Ok(Cursor { tokens, next: 0, end_column })
    }

    fn is_empty(&self) -> bool {
        self.tokens.is_empty()
    }

    fn word(&mut self, what: &str) -> Result<Token, Fail> {
        let token = self.tokens.get(self.next).cloned().ok_or((self.end_column, format!("missing {what}")))?;
        self.next += 1;
        Ok(token)
    }

    fn optional(&mut self) -> Option<Token> {
        let token = self.tokens.get(self.next).cloned();
        self.next += usize::from(token.is_some());
        token
    }

    /// Consumes the next word if it is `word`.
    fn take(&mut self, word: &str) -> bool {
        let found = self.tokens.get(self.next).is_some_and(|t| t.text == word);
        self.next += usize::from(found);
        found
    }

    fn number<T: std::str::FromStr>(&mut self, what: &str) -> Result<T, Fail> {
        let token = self.word(what)?;
        token.text.parse().map_err(|_| (token.column, format!("expected {what}, found '{}'", token.text)))
    }

    fn int_in(&mut self, what: &str, range: std::ops::RangeInclusive<i64>) -> Result<i64, Fail> {
        let token = self.word(what)?;
        let value: i64 = token
            .text
            .parse()
            .map_err(|_| (token.column, format!("expected {what} (an integer), found '{}'", token.text)))?;
        if !range.contains(&value) {
            return Err((token.column, format!("{what} {value} is outside {}..={}", range.start(), range.end())));
        }
        Ok(value)
    }

    fn float(&mut self, what: &str) -> Result<f64, Fail> {
        let token = self.word(what)?;
        match token.text.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err((token.column, format!("expected {what} (a number), found '{}'", token.text))),
        }
    }

    fn position(&mut self) -> Result<IVec3, Fail> {
        let limit = i64::from(crate::scene::octree::WORLD_LIMIT) - 1;
        let mut p = [0; 3];
        for (axis, name) in p.iter_mut().zip(["X", "Y", "Z"]) {
            *axis = self.int_in(name, -limit..=limit)? as i32;
        }
        Ok(IVec3::from(p))
    }

    /// Red, green and blue, each 0..=255.
    fn rgb(&mut self) -> Result<[u8; 3], Fail> {
        let mut rgb = [0u8; 3];
        for (slot, what) in rgb.iter_mut().zip(["red", "green", "blue"]) {
            *slot = self.int_in(what, 0..=255)? as u8;
        }
        Ok(rgb)
    }

    /// `x`, `y` or `z`, as 0, 1 or 2.
    fn axis(&mut self) -> Result<usize, Fail> {
        let axis = self.word("x, y or z")?;
        match axis.text.as_str() {
            "x" => Ok(0),
            "y" => Ok(1),
            "z" => Ok(2),
            other => Err((axis.column, format!("expected x, y or z, found '{other}'"))),
        }
    }

    fn path(&mut self) -> Result<PathBuf, Fail> {
        let token = self.word("a path")?;
        if token.text.is_empty() {
            return Err((token.column, "an empty path".to_owned()));
        }
        Ok(PathBuf::from(token.text))
    }

    /// Fails if anything is left on the line.
    fn finish(&self) -> Result<(), Fail> {
        match self.tokens.get(self.next) {
            Some(extra) => Err((extra.column, format!("unexpected '{}' after the command", extra.text))),
            None => Ok(()),
        }
    }
}

/// Parses script text. `file` is used in messages and to resolve paths.
pub fn parse_script(file: &Path, text: &str) -> Result<Script, Vec<ScriptError>> {
    let mut lines = Vec::new();
    let mut errors = Vec::new();
    // A byte-order mark (some Windows editors write one) is not a command.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    for (index, raw) in text.lines().enumerate() {
        let parsed = Cursor::new(raw).map_err(|(column, error)| (column, error.to_string())).and_then(|mut cursor| {
            if cursor.is_empty() {
                return Ok(None);
            }
            let command = parse_command(&mut cursor)?;
            cursor.finish()?;
            Ok(Some(command))
        });
        match parsed {
            Ok(None) => {}
            Ok(Some(command)) => lines.push(NumberedLine { number: index + 1, command }),
            Err((column, message)) => {
                errors.push(ScriptError { file: file.to_path_buf(), line: index + 1, column, message })
            }
        }
    }
    if errors.is_empty() { Ok(Script { path: file.to_path_buf(), lines }) } else { Err(errors) }
}

/// Reads and parses a script file.
pub fn load_script(path: &Path) -> Result<Script, Vec<ScriptError>> {
    let fail = |message: String| vec![ScriptError { file: path.to_path_buf(), line: 0, column: 0, message }];
    let bytes =
        crate::io::input::read_limited(path, MAX_SCRIPT_BYTES).map_err(|e| fail(format!("cannot read script: {e}")))?;
    let text = String::from_utf8(bytes).map_err(|_| fail("cannot read script: it is not UTF-8 text".to_owned()))?;
    parse_script(path, &text)
}

/// Largest script file read: 64 MiB, about a million edit lines.
pub const MAX_SCRIPT_BYTES: u64 = 64 << 20;

/// The count of `undo N` / `redo N`: a whole number 1..=u32::MAX.
fn parse_count(text: &str) -> Result<u32, CountError> {
    let digits = !text.is_empty() && text.bytes().all(|b| b.is_ascii_digit());
    match text.parse::<u32>() {
        Ok(n) if n >= 1 => Ok(n),
        // A number past u32 is a count, only too large (not "not ≥ 1").
        Err(_) if digits && text.trim_start_matches('0').len() >= 10 => Err(CountError::TooLarge(text.to_owned())),
        _ => Err(CountError::NotACount(text.to_owned())),
    }
}

fn parse_command(c: &mut Cursor) -> Result<Line, Fail> {
    let name = c.word("a command")?;
    Ok(match name.text.as_str() {
        "load" => Line::Load(c.path()?),
        "new" => Line::New,
        "demo" => Line::Demo(match c.optional() {
            None => BuiltIn::Terrain,
            Some(t) => BuiltIn::from_str(&t.text, true)
                .map_err(|_| (t.column, format!("expected terrain, showroom or interior, found '{}'", t.text)))?,
        }),
        "camera" => {
            let mut v = [0.0; 6];
            for (slot, what) in v.iter_mut().zip(["EX", "EY", "EZ", "TX", "TY", "TZ"]) {
                *slot = c.float(what)?;
            }
            let fov = match c.optional() {
                Some(t) => {
                    let fov = t.text.parse::<f32>().ok().and_then(|f| check_fov(f).ok());
                    let (lo, hi) = (FOV_RANGE_DEG.start(), FOV_RANGE_DEG.end());
                    Some(fov.ok_or((t.column, format!("field of view '{}' must be {lo}..={hi} degrees", t.text)))?)
                }
                None => None,
            };
            let (eye, target) = (DVec3::new(v[0], v[1], v[2]), DVec3::new(v[3], v[4], v[5]));
            crate::camera::check_camera(eye, target).map_err(|error| (name.column, error.to_string()))?;
            Line::Camera { eye, target, fov }
        }
        "ortho" => {
            let t = c.word("the view's height in voxels")?;
            let height = t.text.parse::<f32>().ok().and_then(|h| crate::camera::check_ortho(h).ok());
            let (lo, hi) = (crate::camera::ORTHO_RANGE.start(), crate::camera::ORTHO_RANGE.end());
            Line::Projection(Some(
                height.ok_or((t.column, format!("orthographic height '{}' must be {lo}..={hi} voxels", t.text)))?,
            ))
        }
        "perspective" => Line::Projection(None),
        "viewport" => Line::Viewport(c.int_in("width", 1..=8192)? as u32, c.int_in("height", 1..=8192)? as u32),
        "brush" => Line::Brush(parse_brush(c)?),
        "stroke" => {
            let t = c.word("begin or end")?;
            Line::Stroke(match t.text.as_str() {
                "begin" => true,
                "end" => false,
                other => return Err((t.column, format!("expected begin or end, found '{other}'"))),
            })
        }
        "ground" => {
            let t = c.word("on or off")?;
            Line::Ground(match t.text.as_str() {
                "on" => true,
                "off" => false,
                other => return Err((t.column, format!("expected on or off, found '{other}'"))),
            })
        }
        "color" => Line::Color(c.int_in("palette index", 1..=255)? as u8),
        "rgb" => {
            let index = c.int_in("palette index", 1..=255)? as u8;
            Line::Rgb(index, c.rgb()?)
        }
        "palette" => Line::Palette(parse_palette(c)?),
        "material" => parse_material(c)?,
        "place" => Line::Place(c.position()?),
        "remove" => Line::Remove(c.position()?),
        "paint" => Line::Paint(c.position()?),
        "pick" => Line::Pick(c.position()?),
        "fill" => Line::Fill(c.position()?),
        "extrude" => {
            let (at, normal) = (c.position()?, c.position()?);
            let limit = i64::from(crate::scene::shape::MAX_BRUSH_EXTENT);
            Line::Extrude(at, normal, c.int_in("layers", -limit..=limit)? as i32)
        }
        "line" => Line::Segment(c.position()?, c.position()?),
        "select" if c.take("off") => Line::Select(None),
        "select" => {
            let (a, b) = (c.position()?, c.position()?);
            if (a - b).abs().max_element() >= MAX_BRUSH_EXTENT {
                return Err((name.column, format!("a selection is at most {MAX_BRUSH_EXTENT} voxels wide")));
            }
            Line::Select(Some((a, b)))
        }
        "copy" => Line::Copy,
        "cut" => Line::Cut,
        "delete" => Line::Delete,
        "paste" => Line::Paste(c.position()?),
        "move" => Line::Move(c.position()?),
        "rotate" => Line::Rotate(c.axis()?),
        "flip" => Line::Flip(c.axis()?),
        "mirror" => {
            let axis = c.word("x, y, z or off")?;
            match axis.text.as_str() {
                "off" => Line::Mirror(None),
                name @ ("x" | "y" | "z") => {
                    let token = c.word("the plane's coordinate")?;
                    let limit = f64::from(crate::scene::octree::WORLD_LIMIT);
                    let plane =
                        token.text.parse::<f64>().ok().filter(|v| v.abs() < limit && (v * 2.0).fract() == 0.0).ok_or(
                            (
                                token.column,
                                format!("plane '{}' must be a whole or half number inside the world", token.text),
                            ),
                        )?;
                    Line::Mirror(Some((usize::from(name.as_bytes()[0] - b'x'), plane)))
                }
                other => return Err((axis.column, format!("expected x, y, z or off, found '{other}'"))),
            }
        }
        "click" => {
            let x = c.int_in("pixel x", 0..=8191)? as u32;
            let y = c.int_in("pixel y", 0..=8191)? as u32;
            let t = c.word("attach, erase or paint")?;
            let tool = Tool::from_name(&t.text)
                .ok_or((t.column, format!("expected attach, erase or paint, found '{}'", t.text)))?;
            Line::Click { x, y, tool }
        }
        "undo" | "redo" => {
            let n = match c.optional() {
                Some(t) => parse_count(&t.text).map_err(|error| (t.column, error.to_string()))?,
                None => 1,
            };
            if name.text == "undo" { Line::Undo(n) } else { Line::Redo(n) }
        }
        "save" => Line::Save(c.path()?),
        "render" => Line::Render(c.path()?),
        "expect" => parse_expect(c)?,
        "object" => Line::Object(parse_object(c)?),
        "frame" => Line::Frame(c.int_in("a frame", 0..=i64::from(u32::MAX))? as u32),
        "anim" => Line::Anim(parse_anim(c)?),
        "layer" => {
            let id = c.int_in("layer id", 0..=i64::from(u32::MAX - 1))? as u32;
            let what = c.word("hide, show, color, active or a name")?;
            Line::Layer(
                id,
                match what.text.as_str() {
                    _ if what.quoted => LayerLine::Name(what.text),
                    "hide" => LayerLine::Hide(true),
                    "show" => LayerLine::Hide(false),
                    "active" => LayerLine::Active,
                    "color" => {
                        let mut channel = || c.int_in("a colour channel", 0..=255).map(|v| v as u8);
                        LayerLine::Color([channel()?, channel()?, channel()?])
                    }
                    _ => LayerLine::Name(what.text),
                },
            )
        }
        other => return Err((name.column, format!("unknown command '{other}'"))),
    })
}

/// `object N|NAME`, and what the picked object does: `new NAME`, `move DX
/// DY DZ`, `rotate x|y|z`, `duplicate [reference]`, `unique`, `delete`,
/// `hide`, `show`, `lock`, `unlock`, `rename NAME`, `layer N`, `before N|NAME`, `after
/// N|NAME`, `merge N|NAME…`, `turn`, `key`, `unkey`, `place|remove|paint X Y Z`. (An object
/// named like one of these words is picked by its index or its path.)
fn parse_object(c: &mut Cursor) -> Result<ObjectLine, Fail> {
    let word = c.word("an object index or name, or what the picked object does")?;
    Ok(match word.text.as_str() {
        _ if word.quoted => ObjectLine::Pick(object_ref(word)?),
        "before" => ObjectLine::Regroup(object_ref(c.word("an object")?)?, false),
        "after" => ObjectLine::Regroup(object_ref(c.word("an object")?)?, true),
        "merge" => {
            let mut others = vec![object_ref(c.word("an object to merge")?)?];
            while let Some(word) = c.optional() {
                others.push(object_ref(word)?);
            }
            ObjectLine::Merge(others)
        }
        "hide" => ObjectLine::Hide(true),
        "show" => ObjectLine::Hide(false),
        "lock" => ObjectLine::Lock(true),
        "unlock" => ObjectLine::Lock(false),
        "new" => ObjectLine::New(c.word("a name")?.text),
        "move" => ObjectLine::Move(c.position()?),
        "rotate" => ObjectLine::Rotate(c.axis()?),
        "turn" => {
            let axis = c.axis()?;
            let token = c.word("an angle in degrees")?;
            let degrees = token.text.parse::<f64>().ok().filter(|d| d.is_finite()).ok_or_else(|| {
                (token.column, format!("expected an angle in degrees (a number), found '{}'", token.text))
            })?;
            ObjectLine::Turn { axis, degrees: Degrees(degrees) }
        }
        "duplicate" => ObjectLine::Duplicate { reference: c.take("reference") },
        "unique" => ObjectLine::Unique,
        "delete" => ObjectLine::Delete,
        "rename" => ObjectLine::Rename(c.word("a name")?.text),
        "layer" => ObjectLine::Layer(c.int_in("layer id", 0..=i64::from(u32::MAX - 1))? as u32),
        "key" => ObjectLine::Key(match c.optional() {
            None => Ease::Linear,
            Some(word) => Ease::from_name(&word.text)
                .ok_or((word.column, format!("expected step, linear or smooth, found '{}'", word.text)))?,
        }),
        "unkey" => ObjectLine::Unkey,
        "place" => ObjectLine::Cell { tool: Tool::Attach, at: c.position()? },
        "remove" => ObjectLine::Cell { tool: Tool::Erase, at: c.position()? },
        "paint" => ObjectLine::Cell { tool: Tool::Paint, at: c.position()? },
        _ => ObjectLine::Pick(object_ref(word)?),
    })
}

/// `anim range A B`, `anim fps N`, `anim loop on|off`.
fn parse_anim(c: &mut Cursor) -> Result<AnimLine, Fail> {
    let what = c.word("range, fps or loop")?;
    Ok(match what.text.as_str() {
        "range" => {
            let first = c.int_in("the first frame", 0..=i64::from(u32::MAX))? as u32;
            let last = c.int_in("the last frame", i64::from(first)..=i64::from(u32::MAX))? as u32;
            AnimLine::Range(first, last)
        }
        "fps" => AnimLine::Fps(c.int_in("frames a second", 1..=i64::from(MAX_FPS))? as u32),
        "loop" => {
            let word = c.word("on or off")?;
            AnimLine::Loop(match word.text.as_str() {
                "on" => true,
                "off" => false,
                other => return Err((word.column, format!("expected on or off, found '{other}'"))),
            })
        }
        other => return Err((what.column, format!("expected range, fps or loop, found '{other}'"))),
    })
}

/// An object by index (digits) or by name or `group/name` path.
fn object_ref(word: Token) -> Result<ObjectRef, Fail> {
    match word.text.as_str() {
        "" => Err((word.column, "an empty object name".to_owned())),
        text if word.quoted => Ok(ObjectRef::Name(text.to_owned())),
        text if text.bytes().all(|b| b.is_ascii_digit()) => Ok(ObjectRef::Index(
            text.parse().map_err(|_| (word.column, format!("object index '{text}' is too large")))?,
        )),
        text => Ok(ObjectRef::Name(text.to_owned())),
    }
}

/// `palette load PATH`, `palette save PATH`, `palette set INDEX RRGGBB…`
/// (entries INDEX.. up to 255) or `palette preset NAME`.
fn parse_palette(c: &mut Cursor) -> Result<PaletteLine, Fail> {
    let what = c.word("load, save, set or preset")?;
    Ok(match what.text.as_str() {
        "load" => PaletteLine::Load(c.path()?),
        "save" => PaletteLine::Save(c.path()?),
        "set" => {
            let first = c.int_in("palette index", 1..=255)? as u8;
            let mut colors = Vec::new();
            while let Some(word) = c.optional() {
                if usize::from(first) + colors.len() > 255 {
                    return Err((word.column, format!("colours past palette index 255 (from {first})")));
                }
                let color = crate::io::palette_file::parse_hex(&word.text)
                    .ok_or((word.column, format!("expected a colour RRGGBB, found '{}'", word.text)))?;
                colors.push(color);
            }
            if colors.is_empty() {
                return Err((c.end_column, "expected at least one colour RRGGBB".to_owned()));
            }
            PaletteLine::Set { first, colors }
        }
        "preset" => {
            let name = c.word("a preset name")?;
            if crate::io::palette_file::preset(&name.text).is_none() {
                let names: Vec<&str> = crate::io::palette_file::PRESETS.iter().map(|(n, _)| *n).collect();
                return Err((name.column, format!("expected a preset ({}), found '{}'", names.join(", "), name.text)));
            }
            PaletteLine::Preset(name.text)
        }
        other => return Err((what.column, format!("expected load, save, set or preset, found '{other}'"))),
    })
}

fn parse_brush(c: &mut Cursor) -> Result<Brush, Fail> {
    let kind = c.word("voxel, sphere or box")?;
    let extent = i64::from(MAX_BRUSH_EXTENT);
    Ok(match kind.text.as_str() {
        "voxel" => Brush::Voxel,
        "sphere" => Brush::Sphere(c.int_in("sphere radius", 0..=extent)? as i32),
        "box" => {
            let mut s = [0; 3];
            for (slot, what) in s.iter_mut().zip(["box size SX", "box size SY", "box size SZ"]) {
                *slot = c.int_in(what, 1..=extent)? as i32;
            }
            Brush::Box(IVec3::from(s))
        }
        other => return Err((kind.column, format!("expected voxel, sphere or box, found '{other}'"))),
    })
}

fn parse_expect(c: &mut Cursor) -> Result<Line, Fail> {
    let what = c.word("voxel, count, written, image, effects, palette, objects, models or frame")?;
    Ok(match what.text.as_str() {
        "voxel" => {
            let p = c.position()?;
            Line::ExpectVoxel(p, c.int_in("palette index", 0..=255)? as u8)
        }
        "count" => Line::ExpectCount(c.number("a voxel count")?),
        "written" => {
            let op = c.word("<=")?;
            if op.text != "<=" {
                return Err((op.column, format!("expected '<=', found '{}'", op.text)));
            }
            Line::ExpectWritten(c.number("a byte count")?)
        }
        "image" => {
            let path = c.path()?;
            let tolerance = match c.optional() {
                Some(t) => t
                    .text
                    .parse::<f64>()
                    .ok()
                    .filter(|v| (0.0..=1.0).contains(v))
                    .ok_or((t.column, format!("tolerance '{}' must be a fraction in 0..=1", t.text)))?,
                None => 0.0,
            };
            Line::ExpectImage(path, tolerance)
        }
        "effects" => Line::ExpectEffects(parse_effect_names(c)?),
        "palette" => {
            let index = c.int_in("palette index", 1..=255)? as u8;
            Line::ExpectPalette(index, c.rgb()?)
        }
        "objects" => Line::ExpectObjects(c.number("an object count")?),
        "models" => Line::ExpectModels(c.number("a model count")?),
        "frame" => Line::ExpectFrame(c.int_in("a frame", 0..=i64::from(u32::MAX))? as u32),
        other => {
            return Err((
                what.column,
                format!(
                    "expected voxel, count, written, image, effects, palette, objects, models or frame, found '{other}'"
                ),
            ));
        }
    })
}

/// `material INDEX KIND [KEY VALUE]...`: the keys MATL chunks hold as
/// numbers (`_rough`, `_metal`, `_ri`, `_emit`, …), each with a number.
fn parse_material(c: &mut Cursor) -> Result<Line, Fail> {
    let index = c.int_in("palette index", 1..=255)? as u8;
    let kind_token = c.word("a material kind (diffuse, metal, glass, emit, media)")?;
    let kind = crate::scene::MaterialKind::from_vox_name(&format!("_{}", kind_token.text.trim_start_matches('_')))
        .ok_or((
            kind_token.column,
            format!("expected diffuse, metal, glass, emit or media, found '{}'", kind_token.text),
        ))?;
    let mut material = crate::scene::Material::new(kind);
    while let Some(key) = c.optional() {
        if !crate::scene::palette::is_numeric_key(&key.text) {
            return Err((
                key.column,
                format!("'{}' is not a material parameter (_rough, _metal, _ri, _trans, _emit, _flux, …)", key.text),
            ));
        }
        let value = c.float(&format!("a number for {}", key.text))?;
        if let Some(range) = crate::scene::palette::param_range(&key.text)
            && !range.contains(&(value as f32))
        {
            let (lo, hi) = (range.start(), range.end());
            return Err((key.column, format!("{} {value} is outside {lo}..={hi}", key.text)));
        }
        material.params.insert(key.text, value.to_string());
    }
    Ok(Line::Material(index, Box::new(material)))
}

/// `none`, or one or more of the effect names.
fn parse_effect_names(c: &mut Cursor) -> Result<Vec<String>, Fail> {
    const NAMES: [&str; 5] = ["sun", "sky", "emit", "metal", "glass"];
    let first = c.word("effect names (sun, sky, emit, metal, glass) or none")?;
    if first.text == "none" {
        return Ok(Vec::new());
    }
    let mut names = Vec::new();
    let mut next = Some(first);
    while let Some(token) = next {
        if !NAMES.contains(&token.text.as_str()) {
            return Err((
                token.column,
                format!("expected an effect (sun, sky, emit, metal, glass), found '{}'", token.text),
            ));
        }
        names.push(token.text);
        next = c.optional();
    }
    Ok(names)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    fn errors(text: &str) -> Vec<String> {
        parse_script(Path::new("build.ovr"), text).err().unwrap_or_default().iter().map(|e| e.to_string()).collect()
    }

    #[test]
    fn errors_name_file_line_and_column() {
        let text = "new\n\n# comment\nbrush sphere 3\n\n\n\n\n\n\n\nplcae 1 2 3\n";
        assert_eq!(errors(text), vec!["unknown command 'plcae' at build.ovr:12:1"]);
        assert_eq!(errors("place 1 2"), vec!["missing Z at build.ovr:1:10"]);
        // Issue 24, item 17: a count past u32 was "expected a count ≥ 1".
        assert_eq!(
            errors("undo 4294967296"),
            vec!["count 4294967296 is too large (at most 4294967295) at build.ovr:1:6"]
        );
        // Issue 24, item 10: non-finite cameras and out-of-range materials were accepted.
        assert_eq!(
            errors("camera 1e39 0 0 0 0 0"),
            vec![
                "camera eye [1000000000000000000000000000000000000000, 0, 0] is outside ±2^28 (±268435456) on some axis at build.ovr:1:1"
            ]
        );
        assert_eq!(errors("material 1 glass _ri -1"), vec!["_ri -1 is outside 1..=3 at build.ovr:1:18"]);
        assert_eq!(errors("material 1 glass _trans -3"), vec!["_trans -3 is outside 0..=1 at build.ovr:1:18"]);
        assert_eq!(errors("material 1 glass _ri 1.5 _trans 0.5"), Vec::<String>::new());
        assert_eq!(errors("redo 0"), vec!["expected a count ≥ 1, found '0' at build.ovr:1:6"]);
        assert_eq!(errors("undo -3"), vec!["expected a count ≥ 1, found '-3' at build.ovr:1:6"]);
        assert_eq!(errors("color 0"), vec!["palette index 0 is outside 1..=255 at build.ovr:1:7"]);
        assert_eq!(errors("color 300"), vec!["palette index 300 is outside 1..=255 at build.ovr:1:7"]);
        assert_eq!(errors("brush sphere -1"), vec!["sphere radius -1 is outside 0..=4096 at build.ovr:1:14"]);
        assert_eq!(
            errors("brush sphere 1000000000"),
            vec!["sphere radius 1000000000 is outside 0..=4096 at build.ovr:1:14"]
        );
        assert_eq!(errors("expect written < 3"), vec!["expected '<=', found '<' at build.ovr:1:16"]);
        assert_eq!(errors("new extra"), vec!["unexpected 'extra' after the command at build.ovr:1:5"]);
        assert_eq!(errors("anim range 5 2"), vec!["the last frame 2 is outside 5..=4294967295 at build.ovr:1:14"]);
        assert_eq!(errors("frame -1"), vec!["a frame -1 is outside 0..=4294967295 at build.ovr:1:7"]);
        assert_eq!(
            errors("object key bouncy"),
            vec!["expected step, linear or smooth, found 'bouncy' at build.ovr:1:12"]
        );
        assert_eq!(errors("anim fps 0"), vec!["frames a second 0 is outside 1..=240 at build.ovr:1:10"]);
        assert_eq!(errors("object turn y 45"), Vec::<String>::new(), "any angle");
        assert_eq!(
            errors("object turn y inf"),
            vec!["expected an angle in degrees (a number), found 'inf' at build.ovr:1:15"]
        );
        assert_eq!(
            errors("object turn y NaN"),
            vec!["expected an angle in degrees (a number), found 'NaN' at build.ovr:1:15"]
        );
        assert_eq!(errors("click 3 4 smash"), vec!["expected attach, erase or paint, found 'smash' at build.ovr:1:11"]);
        assert_eq!(errors("select 0 0 0 5000 0 0"), vec!["a selection is at most 4096 voxels wide at build.ovr:1:1"]);
        assert_eq!(errors("paste 1 2"), vec!["missing Z at build.ovr:1:10"]);
        assert_eq!(
            errors("demo castle"),
            vec!["expected terrain, showroom or interior, found 'castle' at build.ovr:1:6"]
        );
        assert_eq!(
            errors("expect effects sun shiny"),
            vec!["expected an effect (sun, sky, emit, metal, glass), found 'shiny' at build.ovr:1:20"]
        );
    }

    #[test]
    fn every_command_round_trips_through_display() {
        let text = "load a.vox\nnew\ndemo\ncamera 1 2 3 4 5 6.5 40\nviewport 64 48\nbrush voxel\nbrush sphere 3\nbrush box 1 2 3\n\
                    color 7\nplace -1 2 3\nremove 1 2 3\npaint 1 2 -3\nclick 3 4 erase\nundo 2\nredo 1\nsave b.vox\n\
                    render c.png\nexpect voxel 1 2 3 0\nexpect count 5\nexpect written <= 512\nexpect image c.png 0.01\n\
                    demo showroom\nexpect effects sun glass\nexpect effects none\nrgb 4 1 2 3\nselect 1 2 3 -4 5 6\nselect off\ncopy\ncut\ndelete\n\
                    paste 1 -2 3\nmove 0 0 -1\nrotate y\nflip z\npalette load \"my p.gpl\"\npalette save p.hex\n\
                    palette set 3 ff0000 00Ff00\npalette preset pico8\nexpect palette 7 1 2 3\n\
                    material 4 glass _ri 1.45 _trans 0.5\nmaterial 5 diffuse\npick 1 -2 3\nfill 0 0 -1\nmirror x 4.5\nmirror z -2\nmirror off\nline 1 2 3 -4 5 6\n\
                    extrude 1 2 3 0 -1 0 -2\nobject 3\nobject \"tree 4/top\"\nobject hide\nobject show\nlayer 2 hide\n\
                    ortho 42.5\nperspective\nground off\nground on\nlayer 0 show\nexpect objects 19\nexpect models 15\nobject new \"a b\"\nobject move 1 -2 3\nobject rotate z\n\
                    object duplicate\nobject duplicate reference\nobject unique\nobject delete\nobject rename top\n\
                    object layer 3\nlayer 4 \"roof tiles\"\nlayer 4 color 10 200 255\nlayer 2 active\nobject merge 3 \"tree 4/top\" 7\nobject before 2\nobject after \"a b\"\nobject lock\nobject unlock\nstroke begin\nstroke end\n\
                    frame 12\nanim range 0 30\nanim fps 24\nanim loop off\nexpect frame 12\nobject key smooth\nobject key\nobject unkey\n\
                    object turn y -90\nobject turn x 450.0\nobject turn z 0.1\nobject turn x -1e-7\nobject turn y 89.9999\n\
                    object place 1 -2 3\nobject remove 0 0 0\nobject paint -4 5 6\nobject \"place\"\n";
        let script = parse_script(Path::new("t.ovr"), text).unwrap();
        let printed: String = script.lines.iter().map(|l| format!("{}\n", l.command)).collect();
        let again = parse_script(Path::new("t.ovr"), &printed).unwrap();
        assert_eq!(
            script.lines.iter().map(|l| &l.command).collect::<Vec<_>>(),
            again.lines.iter().map(|l| &l.command).collect::<Vec<_>>()
        );
        assert_eq!(script.lines.len(), 96);
        // Each line's word is the one it is printed with.
        for line in &script.lines {
            assert_eq!(line.command.to_string().split(' ').next(), Some(line.command.word()), "{}", line.command);
            // The checks are exactly the `expect` lines.
            assert_eq!(line.command.is_check(), line.command.word() == "expect", "{}", line.command);
        }
    }

    #[test]
    fn quotes_keep_spaces_and_hashes_and_printing_quotes_them() {
        let text = "\u{feff}save \"../out/has#hash.vox\" # a comment\nload \"my models/a \\\"b\\\" \\\\.vox\"\nrender plain.png\n";
        let script = parse_script(Path::new("q.ovr"), text).unwrap();
        let commands: Vec<&Line> = script.lines.iter().map(|l| &l.command).collect();
        assert_eq!(
            commands,
            [
                &Line::Save(PathBuf::from("../out/has#hash.vox")),
                &Line::Load(PathBuf::from("my models/a \"b\" \\.vox")),
                &Line::Render(PathBuf::from("plain.png")),
            ]
        );
        for command in commands {
            let printed = command.to_string();
            let again = parse_script(Path::new("q.ovr"), &printed).unwrap();
            assert_eq!(&again.lines[0].command, command, "{printed}");
        }
        assert_eq!(errors("save \"open"), vec!["a quote that is not closed on this line at build.ovr:1:6"]);
        assert_eq!(errors("save \"\""), vec!["an empty path at build.ovr:1:6"]);
        assert_eq!(errors("\u{feff}nwe"), vec!["unknown command 'nwe' at build.ovr:1:1"]);
    }

    /// A recorded name with a newline ended the `load` line there, and the
    /// journal or `--record` script no longer parsed (issue 24, item 4).
    #[test]
    fn control_characters_in_names_round_trip() {
        for name in ["two\nlines.vox", "tab\there.vox", "bell\u{7}\r\u{1b}.vox", "mixed \"q\" \\ \n#.vox"] {
            let command = Line::Load(PathBuf::from(name));
            let printed = command.to_string();
            assert!(!printed.contains('\n') && !printed.chars().any(char::is_control), "{printed:?}");
            let again = parse_script(Path::new("q.ovr"), &printed).unwrap();
            assert_eq!(again.lines.len(), 1, "{printed:?}");
            assert_eq!(again.lines[0].command, command, "{printed:?}");
        }
        assert_eq!(
            errors("load \"a\\u{zz}.vox\""),
            vec!["expected \\u{HEX} (a character's code in hexadecimal) at build.ovr:1:8"]
        );
    }

    /// A layer renamed `color` was journaled as `layer 0 color`, which does
    /// not parse, and one renamed `hide` came back as a hidden layer (issue
    /// 48, item 4): every keyword, number and odd character round-trips as
    /// a name wherever a name stands.
    #[test]
    fn every_keyword_and_odd_character_round_trips_as_a_name() {
        let mut names: Vec<String> = NAME_KEYWORDS.iter().map(|k| (*k).to_owned()).collect();
        names.extend(
            ["12", "0", "a b", "#x", "\"q\"", "back\\slash", "two\nlines", "tab\t", "\u{7}", "ünï", "a/b", "-3", "x,y"]
                .map(str::to_owned),
        );
        names.extend(["brush", "object", "layer", "on", "off", "x", "reference"].map(str::to_owned));
        for name in &names {
            let r = || ObjectRef::Name(name.clone());
            let commands = [
                Line::Layer(0, LayerLine::Name(name.clone())),
                Line::Object(ObjectLine::Pick(r())),
                Line::Object(ObjectLine::New(name.clone())),
                Line::Object(ObjectLine::Rename(name.clone())),
                Line::Object(ObjectLine::Regroup(r(), true)),
                Line::Object(ObjectLine::Merge(vec![r(), ObjectRef::Index(3), r()])),
            ];
            for command in commands {
                let printed = command.to_string();
                let again = parse_script(Path::new("n.ovr"), &printed).unwrap_or_else(|e| panic!("{printed:?}: {e:?}"));
                assert_eq!(again.lines.len(), 1, "{printed:?}");
                assert_eq!(again.lines[0].command, command, "{printed:?}");
            }
        }
        // Plain names stay unquoted, so older journals read as they did.
        assert_eq!(Line::Layer(2, LayerLine::Name("roof".to_owned())).to_string(), "layer 2 roof");
        assert_eq!(Line::Layer(2, LayerLine::Name("hide".to_owned())).to_string(), "layer 2 \"hide\"");
        assert_eq!(errors("object \"\""), vec!["an empty object name at build.ovr:1:8"]);
    }

    /// A 2 MB line took 31 s to reject when columns were counted from the
    /// start of the line for every word; one pass takes milliseconds. The
    /// bound is loose on purpose: it only catches quadratic time again.
    #[test]
    fn a_huge_line_is_rejected_quickly() {
        let line = format!("place 1 2 3{}", " 4".repeat(1_000_000));
        let start = web_time::Instant::now();
        let errors = errors(&line);
        assert_eq!(errors, vec!["unexpected '4' after the command at build.ovr:1:13"]);
        assert!(start.elapsed().as_secs_f64() < 5.0, "took {:?}", start.elapsed());
    }
}
