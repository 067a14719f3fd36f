//! Parsing scripts: one command per line, `#` comments, errors that name the
//! file, line and column and what was expected.

use std::path::{Path, PathBuf};

use glam::{DVec3, IVec3};

use super::{Command, Line, Script};
use crate::scene::shape::MAX_BRUSH_EXTENT;
use crate::tool::{Brush, Tool};

/// A script that cannot be read or parsed, or a line that failed to run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{message} at {}:{line}:{column}", file.display())]
pub struct ScriptError {
    pub file: PathBuf,
    pub line: usize,
    pub column: usize,
    pub message: String,
}

/// A word of a line and the 1-based column it starts at.
#[derive(Clone, Copy)]
struct Token<'a> {
    text: &'a str,
    column: usize,
}

/// Reads the tokens of one line, left to right, with errors that point at
/// the token (or at the end of the line when one is missing).
struct Cursor<'a> {
    tokens: Vec<Token<'a>>,
    next: usize,
    end_column: usize,
}

type Fail = (usize, String);

impl<'a> Cursor<'a> {
    fn new(text: &'a str) -> Cursor<'a> {
        let mut tokens = Vec::new();
        let mut start = None;
        for (i, c) in text.char_indices().chain(std::iter::once((text.len(), ' '))) {
            match (c.is_whitespace(), start) {
                (false, None) => start = Some(i),
                (true, Some(s)) => {
                    tokens.push(Token { text: &text[s..i], column: text[..s].chars().count() + 1 });
                    start = None;
                }
                _ => {}
            }
        }
        Cursor { tokens, next: 0, end_column: text.trim_end().chars().count() + 1 }
    }

    fn word(&mut self, what: &str) -> Result<Token<'a>, Fail> {
        let token = self.tokens.get(self.next).copied().ok_or((self.end_column, format!("missing {what}")))?;
        self.next += 1;
        Ok(token)
    }

    fn optional(&mut self) -> Option<Token<'a>> {
        let token = self.tokens.get(self.next).copied();
        self.next += usize::from(token.is_some());
        token
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

    fn path(&mut self) -> Result<PathBuf, Fail> {
        Ok(PathBuf::from(self.word("a path")?.text))
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
    for (index, raw) in text.lines().enumerate() {
        let content = raw.split('#').next().unwrap_or("");
        if content.trim().is_empty() {
            continue;
        }
        let mut cursor = Cursor::new(content);
        match parse_command(&mut cursor).and_then(|c| cursor.finish().map(|()| c)) {
            Ok(command) => lines.push(Line { number: index + 1, command }),
            Err((column, message)) => {
                errors.push(ScriptError { file: file.to_path_buf(), line: index + 1, column, message })
            }
        }
    }
    if errors.is_empty() { Ok(Script { path: file.to_path_buf(), lines }) } else { Err(errors) }
}

/// Reads and parses a script file.
pub fn load_script(path: &Path) -> Result<Script, Vec<ScriptError>> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        vec![ScriptError { file: path.to_path_buf(), line: 0, column: 0, message: format!("cannot read script: {e}") }]
    })?;
    parse_script(path, &text)
}

fn parse_command(c: &mut Cursor) -> Result<Command, Fail> {
    let name = c.word("a command")?;
    Ok(match name.text {
        "load" => Command::Load(c.path()?),
        "new" => Command::New,
        "demo" => Command::Demo,
        "camera" => {
            let mut v = [0.0; 6];
            for (slot, what) in v.iter_mut().zip(["EX", "EY", "EZ", "TX", "TY", "TZ"]) {
                *slot = c.float(what)?;
            }
            let fov = match c.optional() {
                Some(t) => match t.text.parse::<f32>() {
                    Ok(f) if (1.0..=179.0).contains(&f) => Some(f),
                    _ => return Err((t.column, format!("field of view '{}' must be 1..=179 degrees", t.text))),
                },
                None => None,
            };
            let (eye, target) = (DVec3::new(v[0], v[1], v[2]), DVec3::new(v[3], v[4], v[5]));
            if eye == target {
                return Err((name.column, "camera eye and target are the same point".into()));
            }
            Command::Camera { eye, target, fov }
        }
        "viewport" => Command::Viewport(c.int_in("width", 1..=8192)? as u32, c.int_in("height", 1..=8192)? as u32),
        "brush" => Command::Brush(parse_brush(c)?),
        "color" => Command::Color(c.int_in("palette index", 1..=255)? as u8),
        "place" => Command::Place(c.position()?),
        "remove" => Command::Remove(c.position()?),
        "paint" => Command::Paint(c.position()?),
        "click" => {
            let x = c.int_in("pixel x", 0..=8191)? as u32;
            let y = c.int_in("pixel y", 0..=8191)? as u32;
            let t = c.word("attach, erase or paint")?;
            let tool = Tool::from_name(t.text)
                .ok_or((t.column, format!("expected attach, erase or paint, found '{}'", t.text)))?;
            Command::Click { x, y, tool }
        }
        "undo" | "redo" => {
            let n = match c.optional() {
                Some(t) => t
                    .text
                    .parse::<u32>()
                    .ok()
                    .filter(|n| *n >= 1)
                    .ok_or((t.column, format!("expected a count ≥ 1, found '{}'", t.text)))?,
                None => 1,
            };
            if name.text == "undo" { Command::Undo(n) } else { Command::Redo(n) }
        }
        "save" => Command::Save(c.path()?),
        "render" => Command::Render(c.path()?),
        "expect" => parse_expect(c)?,
        other => return Err((name.column, format!("unknown command '{other}'"))),
    })
}

fn parse_brush(c: &mut Cursor) -> Result<Brush, Fail> {
    let kind = c.word("voxel, sphere or box")?;
    let extent = i64::from(MAX_BRUSH_EXTENT);
    Ok(match kind.text {
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

fn parse_expect(c: &mut Cursor) -> Result<Command, Fail> {
    let what = c.word("voxel, count, written or image")?;
    Ok(match what.text {
        "voxel" => {
            let p = c.position()?;
            Command::ExpectVoxel(p, c.int_in("palette index", 0..=255)? as u8)
        }
        "count" => Command::ExpectCount(c.number("a voxel count")?),
        "written" => {
            let op = c.word("<=")?;
            if op.text != "<=" {
                return Err((op.column, format!("expected '<=', found '{}'", op.text)));
            }
            Command::ExpectWritten(c.number("a byte count")?)
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
            Command::ExpectImage(path, tolerance)
        }
        other => return Err((what.column, format!("expected voxel, count, written or image, found '{other}'"))),
    })
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
        assert_eq!(errors("color 0"), vec!["palette index 0 is outside 1..=255 at build.ovr:1:7"]);
        assert_eq!(errors("color 300"), vec!["palette index 300 is outside 1..=255 at build.ovr:1:7"]);
        assert_eq!(errors("brush sphere -1"), vec!["sphere radius -1 is outside 0..=4096 at build.ovr:1:14"]);
        assert_eq!(
            errors("brush sphere 1000000000"),
            vec!["sphere radius 1000000000 is outside 0..=4096 at build.ovr:1:14"]
        );
        assert_eq!(errors("expect written < 3"), vec!["expected '<=', found '<' at build.ovr:1:16"]);
        assert_eq!(errors("new extra"), vec!["unexpected 'extra' after the command at build.ovr:1:5"]);
        assert_eq!(errors("click 3 4 smash"), vec!["expected attach, erase or paint, found 'smash' at build.ovr:1:11"]);
    }

    #[test]
    fn every_command_round_trips_through_display() {
        let text = "load a.vox\nnew\ndemo\ncamera 1 2 3 4 5 6.5 40\nviewport 64 48\nbrush voxel\nbrush sphere 3\nbrush box 1 2 3\n\
                    color 7\nplace -1 2 3\nremove 1 2 3\npaint 1 2 -3\nclick 3 4 erase\nundo 2\nredo 1\nsave b.vox\n\
                    render c.png\nexpect voxel 1 2 3 0\nexpect count 5\nexpect written <= 512\nexpect image c.png 0.01\n";
        let script = parse_script(Path::new("t.ovr"), text).unwrap();
        let printed: String = script.lines.iter().map(|l| format!("{}\n", l.command)).collect();
        let again = parse_script(Path::new("t.ovr"), &printed).unwrap();
        assert_eq!(
            script.lines.iter().map(|l| &l.command).collect::<Vec<_>>(),
            again.lines.iter().map(|l| &l.command).collect::<Vec<_>>()
        );
        assert_eq!(script.lines.len(), 21);
    }
}
