//! Recording a window session as a script (`octovox --record PATH`): the
//! camera, brush and colour in force, and every click as the
//! `place`/`remove`/`paint` it became, so `octovox replay` reproduces it.

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::camera::Camera;
use crate::edit::brush::Brush;
use crate::edit::mirror::Mirror;
use crate::editor::Tools;
use crate::script::{Kind, Line};

/// Where a recorder's lines go: a file, or in the browser one of the
/// page's files ([`crate::io::page_files`]).
#[cfg(not(target_arch = "wasm32"))]
type Sink = std::fs::File;
#[cfg(target_arch = "wasm32")]
type Sink = PageFile;

/// One of the browser page's files, written at its end.
#[cfg(target_arch = "wasm32")]
pub struct PageFile(PathBuf);

#[cfg(target_arch = "wasm32")]
impl Write for PageFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        crate::io::page_files::append(&self.0, buf);
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// Writes script lines as the user works. Lines are flushed as they are
/// written, so a crash loses nothing that was recorded.
pub struct Recorder {
    out: std::io::BufWriter<Sink>,
    path: PathBuf,
    camera: Option<Camera>,
    brush: Option<Brush>,
    color: Option<u8>,
    /// Mirror planes the script has in force.
    mirror: Mirror,
    /// Undo steps written and still undoable / redoable: an edit outside
    /// a stroke is one, a stroke with edits is one.
    done: u32,
    undone: u32,
    /// The edits of the open stroke, if one is open. Its `stroke begin` is
    /// written before its first edit (a stroke without edits, a click on
    /// nothing, leaves no lines), its `stroke end` when it ends: at its own
    /// line or at one that ends it (`Line::ends_stroke`, the rule the
    /// editor groups edits by).
    stroke: Option<u32>,
}

impl Recorder {
    pub fn create(path: &Path) -> std::io::Result<Recorder> {
        Recorder::with_header(path, "recorded by octovox --record")
    }

    /// A recorder whose file starts with the comment `# HEADER`.
    pub fn with_header(path: &Path, header: &str) -> std::io::Result<Recorder> {
        let mut recorder = Recorder::on(path, create(path)?);
        recorder.line(&format!("# {header}"))?;
        Ok(recorder)
    }

    /// A crash journal at `path`, locked (an advisory lock, held until the
    /// recorder is dropped) so that a second window on the same document
    /// finds it live and leaves it alone; started with the comment
    /// `# HEADER`. A journal another process holds is refused untouched;
    /// one whose first line cannot be written is removed, not left empty.
    ///
    /// # Errors
    /// The file cannot be opened, is locked by another process
    /// (`WouldBlock`), or cannot be written.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn journal(path: &Path, header: &str) -> std::io::Result<Recorder> {
        let file = std::fs::OpenOptions::new().read(true).write(true).create(true).truncate(false).open(path)?;
        lock(&file, path)?;
        let started = file.set_len(0).and_then(|()| {
            let mut recorder = Recorder::on(path, file);
            recorder.line(&format!("# {header}"))?;
            Ok(recorder)
        });
        if started.is_err() {
            let _ = std::fs::remove_file(path);
        }
        started
    }

    /// A crash journal at `path` among the page's files, which the page
    /// keeps in the browser's storage (one tab holds a page's journals).
    ///
    /// # Errors
    /// None in practice (the page's files are memory).
    #[cfg(target_arch = "wasm32")]
    pub fn journal(path: &Path, header: &str) -> std::io::Result<Recorder> {
        Recorder::with_header(path, header)
    }

    /// A recorder that goes on at the end of an existing script (a recovered
    /// journal, locked as [`Recorder::journal`] locks it): the camera, brush
    /// and colour are written again before the next edit, and undo does not
    /// reach before this point.
    pub fn append(path: &Path) -> std::io::Result<Recorder> {
        let mut recorder = Recorder::on(path, open_to_append(path)?);
        // The script may end with mirror planes on; this recorder starts with none.
        recorder.command(&Line::Mirror(None))?;
        Ok(recorder)
    }

    fn on(path: &Path, file: Sink) -> Recorder {
        Recorder {
            out: std::io::BufWriter::new(file),
            path: path.to_path_buf(),
            camera: None,
            brush: None,
            color: None,
            mirror: Mirror::default(),
            done: 0,
            undone: 0,
            stroke: None,
        }
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    fn line(&mut self, text: &str) -> std::io::Result<()> {
        writeln!(self.out, "{text}")?;
        self.out.flush()
    }

    /// A journal's note on the file it edits or saves to: `#@ TEXT`, a
    /// comment to scripts (`crate::journal` reads it).
    pub fn note(&mut self, text: &str) -> std::io::Result<()> {
        self.line(&format!("#@ {text}"))
    }

    fn command(&mut self, command: &Line) -> std::io::Result<()> {
        self.line(&command.to_string())
    }

    /// The scene was replaced: `load PATH` (absolute), or `demo`/`new`.
    pub fn scene(&mut self, command: Line) -> std::io::Result<()> {
        (self.done, self.undone, self.stroke) = (0, 0, None);
        self.command(&command)
    }

    /// A line the editor ran (`octovox::editor::Editor::run`) with `tools`
    /// in force: edit lines after the state they depend on where it
    /// changed, each one undo step or one edit of the open stroke (an edit
    /// that `changed` nothing makes no step and is not written); `stroke`,
    /// `select` and `copy` lines as they are; tool lines as they change
    /// the tools. Expectations and file lines are not part of a recording.
    pub fn ran(&mut self, command: &Line, tools: &Tools, camera: &Camera, changed: bool) -> std::io::Result<()> {
        if command.ends_stroke() {
            self.end_stroke()?;
        }
        let color = match command.kind() {
            Kind::Edit { color } => color.then_some(tools.color),
            Kind::Stroke => {
                self.end_stroke()?;
                self.stroke = (*command == Line::Stroke(true)).then_some(0);
                return Ok(());
            }
            // Tools as they change (the panels and keys run these lines);
            // again before an edit where the script's differ (after an
            // eyedropper pick, or where a journal goes on).
            Kind::Tool => {
                return match command {
                    Line::Brush(brush) => self.set_brush(*brush),
                    Line::Color(color) => self.set_color(*color),
                    _ => self.set_mirror(&tools.mirror),
                };
            }
            // Picking an object, selecting and copying: state later edits
            // depend on.
            Kind::State => return self.command(command),
            Kind::History => {
                return match *command {
                    Line::Undo(n) => (0..n).try_for_each(|_| self.undo()),
                    Line::Redo(n) => (0..n).try_for_each(|_| self.redo()),
                    _ => Ok(()),
                };
            }
            // Scenes are written by `Recorder::scene`; the camera before the
            // edit that uses it; a click as the edit it became; files and
            // checks are not part of a recording.
            Kind::Scene | Kind::View | Kind::Host | Kind::Check => return Ok(()),
        };
        if !changed {
            return Ok(());
        }
        self.edit_state(camera, tools.brush, color, &tools.mirror)?;
        self.undone = 0;
        match self.stroke {
            Some(0) => self.command(&Line::Stroke(true))?,
            Some(_) => {}
            None => self.done += 1,
        }
        self.stroke = self.stroke.map(|edits| edits + 1);
        self.command(command)
    }

    /// Ends the open stroke: one step and a `stroke end` if it has edits.
    fn end_stroke(&mut self) -> std::io::Result<()> {
        if self.stroke.take().is_some_and(|edits| edits > 0) {
            self.done += 1;
            self.command(&Line::Stroke(false))?;
        }
        Ok(())
    }

    /// Writes the camera, brush, colour (when the edit uses one) and mirror
    /// planes an edit depends on, where they changed.
    fn edit_state(&mut self, camera: &Camera, brush: Brush, color: Option<u8>, mirror: &Mirror) -> std::io::Result<()> {
        self.set_mirror(mirror)?;
        if self.camera != Some(*camera) {
            // The projection with the first camera (a journal appended to
            // may have left either in force), then where it changed.
            let projection_was = self.camera.map(|c| c.ortho);
            self.camera = Some(*camera);
            let (eye, target) = (camera.eye, camera.target);
            self.command(&Line::Camera { eye, target, fov: Some(camera.fov_y_deg) })?;
            if projection_was != Some(camera.ortho) {
                self.command(&Line::Projection(camera.ortho))?;
            }
        }
        self.set_brush(brush)?;
        color.map_or(Ok(()), |color| self.set_color(color))
    }

    /// Writes `brush` where the script's brush is another.
    fn set_brush(&mut self, brush: Brush) -> std::io::Result<()> {
        if self.brush == Some(brush) {
            return Ok(());
        }
        self.brush = Some(brush);
        self.command(&Line::Brush(brush))
    }

    /// Writes `color` where the script's colour is another.
    fn set_color(&mut self, color: u8) -> std::io::Result<()> {
        if self.color == Some(color) {
            return Ok(());
        }
        self.color = Some(color);
        self.command(&Line::Color(color))
    }

    /// Writes `mirror` lines when the planes in force changed.
    fn set_mirror(&mut self, mirror: &Mirror) -> std::io::Result<()> {
        if self.mirror == *mirror {
            return Ok(());
        }
        self.mirror = *mirror;
        self.command(&Line::Mirror(None))?;
        for axis in 0..3 {
            if let Some(c) = mirror.plane(axis) {
                self.command(&Line::Mirror(Some((axis, c))))?;
            }
        }
        Ok(())
    }

    /// Whether an `undo` would be written: a step made since this recorder
    /// started is left to undo.
    pub fn can_undo(&self) -> bool {
        self.done > 0 || self.stroke.is_some_and(|edits| edits > 0)
    }

    /// Whether a `redo` would be written.
    pub fn can_redo(&self) -> bool {
        self.undone > 0
    }

    /// `undo 1`, where a step is left to undo (an undo ends the stroke).
    pub fn undo(&mut self) -> std::io::Result<()> {
        self.end_stroke()?;
        if self.done == 0 {
            return Ok(());
        }
        (self.done, self.undone) = (self.done - 1, self.undone + 1);
        self.command(&Line::Undo(1))
    }

    /// `redo 1`, where a step is left to redo.
    pub fn redo(&mut self) -> std::io::Result<()> {
        self.end_stroke()?;
        if self.undone == 0 {
            return Ok(());
        }
        (self.done, self.undone) = (self.done + 1, self.undone - 1);
        self.command(&Line::Redo(1))
    }
}

#[cfg(not(target_arch = "wasm32"))]
fn create(path: &Path) -> std::io::Result<Sink> {
    std::fs::File::create(path)
}

#[cfg(target_arch = "wasm32")]
fn create(path: &Path) -> std::io::Result<Sink> {
    crate::io::page_files::write(path, Vec::new());
    Ok(PageFile(path.to_path_buf()))
}

/// An existing journal, locked, to write at its end.
#[cfg(not(target_arch = "wasm32"))]
fn open_to_append(path: &Path) -> std::io::Result<Sink> {
    let file = std::fs::OpenOptions::new().append(true).open(path)?;
    lock(&file, path)?;
    Ok(file)
}

#[cfg(target_arch = "wasm32")]
fn open_to_append(path: &Path) -> std::io::Result<Sink> {
    use crate::io::page_files;
    page_files::exists(path).then(|| PageFile(path.to_path_buf())).ok_or_else(page_files::not_found)
}

/// Takes the advisory lock of a journal, or says who holds it.
#[cfg(not(target_arch = "wasm32"))]
fn lock(file: &std::fs::File, path: &Path) -> std::io::Result<()> {
    file.try_lock().map_err(|err| match err {
        std::fs::TryLockError::WouldBlock => std::io::Error::new(
            std::io::ErrorKind::WouldBlock,
            format!("{} is held by another octovox window", path.display()),
        ),
        std::fs::TryLockError::Error(err) => err,
    })
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)] // in tests a panic is the failure report

    use super::*;

    /// Issue 26: `object` and `layer` lines were not recorded, so a kill
    /// after Ctrl+H (or any object change) lost it at recovery.
    #[test]
    fn object_and_layer_lines_are_recorded_in_order() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("r.ovr");
        let mut recorder = Recorder::create(&path).unwrap();
        let text = ["object 2", "object hide", "layer 1 hide", "object move 1 0 0", "rotate y", "flip x"];
        let script = crate::script::parse_script(&path, &text.join("\n")).unwrap();
        for line in &script.lines {
            recorder.ran(&line.command, &Tools::default(), &Camera::default(), true).unwrap();
        }
        drop(recorder);
        let written = std::fs::read_to_string(&path).unwrap();
        let kept: Vec<&str> = written.lines().filter(|l| text.contains(l)).collect();
        assert_eq!(kept, text, "{written}");
    }

    /// Issue 46: a stroke was one undo step in the window but one line per
    /// edit in the recording, so a recording replayed into other undo
    /// steps. The window's lines (as the mouse makes them: `stroke begin`,
    /// its edits, `stroke end`; a click on nothing; a key line inside a
    /// stroke, which ends it) run through an editor and the recorder; the
    /// recording, replayed through a fresh editor, has the same steps, and
    /// undoing them one by one shows the same voxels at every step.
    #[test]
    fn a_recording_replays_into_the_undo_steps_the_window_made() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("r.ovr");
        let mut recorder = Recorder::create(&path).unwrap();
        let mut window = crate::editor::Editor::default();
        let lines = [
            "new",
            "stroke begin",
            "place 0 0 0",
            "place 1 0 0",
            "place 2 0 0",
            "stroke end",
            "stroke begin",
            "stroke end",
            "stroke begin",
            "place 0 1 0",
            "stroke end",
            "stroke begin",
            "place 5 0 0",
            "brush sphere 1",
            "place 8 0 0",
            "stroke begin",
            "rgb 3 10 20 30",
            "rgb 3 11 20 30",
            "stroke end",
            "undo 1",
            "stroke begin",
            "remove 0 0 0",
            "remove 1 0 0",
        ];
        let script = crate::script::parse_script(&path, &lines.join("\n")).unwrap();
        for line in &script.lines {
            let changed = window.run(&line.command).unwrap() == crate::editor::Outcome::Changed;
            let ran = if line.command == Line::New {
                recorder.scene(Line::New)
            } else {
                recorder.ran(&line.command, &window.tools, &Camera::default(), changed)
            };
            ran.unwrap();
        }
        drop(recorder);
        let recorded = std::fs::read_to_string(&path).unwrap();
        assert_eq!(recorded.matches("stroke begin").count(), 5, "the empty stroke leaves no lines:\n{recorded}");
        let mut replayed = crate::editor::Editor::default();
        for line in crate::script::parse_script(&path, &recorded).unwrap().lines {
            replayed.run(&line.command).unwrap();
        }
        assert_eq!(replayed.history.steps(), window.history.steps(), "{recorded}");
        assert_eq!(window.history.steps(), (5, 0));
        for _ in 0..5 {
            assert_eq!(replayed.scene.voxels(), window.scene.voxels(), "{recorded}");
            assert_eq!(replayed.scene.palette.color(3), window.scene.palette.color(3));
            window.run(&Line::Undo(1)).unwrap();
            replayed.run(&Line::Undo(1)).unwrap();
        }
        assert_eq!(replayed.scene.voxels(), window.scene.voxels());
        assert_eq!((window.history.steps(), replayed.history.steps()), ((0, 5), (0, 5)));
    }

    /// Issue 46: the panels wrote brush, colour and mirror into the tools
    /// and the recorder rebuilt lines by diffing them before each edit. The
    /// panels now run lines, and the recorder writes each as it runs
    /// (once where it changes nothing in the script).
    #[test]
    fn tool_lines_are_recorded_as_they_run() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.ovr");
        let mut recorder = Recorder::create(&path).unwrap();
        let mut editor = crate::editor::Editor::default();
        let text = "brush sphere 3\nbrush sphere 3\ncolor 7\nmirror off\nmirror x 4.5\nbrush sphere 4\nplace 1 2 3\n";
        for line in crate::script::parse_script(&path, text).unwrap().lines {
            let changed = editor.run(&line.command).unwrap() == crate::editor::Outcome::Changed;
            recorder.ran(&line.command, &editor.tools, &Camera::default(), changed).unwrap();
        }
        drop(recorder);
        let written = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<&str> = written.lines().filter(|l| !l.starts_with('#') && !l.starts_with("camera")).collect();
        assert_eq!(
            lines,
            ["brush sphere 3", "color 7", "mirror off", "mirror x 4.5", "brush sphere 4", "perspective", "place 1 2 3"],
            "{written}"
        );
    }

    /// An edit that changes nothing (`palette set` of the colours there
    /// are) makes no undo step in the editor, and the recorder writes none:
    /// a journal counted one and could `undo` past what the window could.
    #[test]
    fn an_edit_that_changes_nothing_is_not_recorded() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("n.ovr");
        let mut recorder = Recorder::create(&path).unwrap();
        let mut editor = crate::editor::Editor::default();
        for text in ["palette set 3 010203", "palette set 3 010203"] {
            let line = crate::script::parse_script(&path, text).unwrap().lines.remove(0).command;
            let changed = editor.run(&line).unwrap() == crate::editor::Outcome::Changed;
            recorder.ran(&line, &editor.tools, &Camera::default(), changed).unwrap();
        }
        assert_eq!(editor.history.steps(), (1, 0));
        recorder.undo().unwrap();
        assert!(!recorder.can_undo(), "the recorder counts the editor's one step");
        drop(recorder);
        let written = std::fs::read_to_string(&path).unwrap();
        assert_eq!(written.matches("palette set").count(), 1, "{written}");
    }

    /// Issue 24, item 6: a journal whose first line could not be written
    /// (a full disk) was left behind empty. `/dev/full` is such a disk.
    #[cfg(unix)]
    #[test]
    fn a_journal_that_cannot_be_written_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let journal = dir.path().join(".doc.vox.octovox-journal.ovr");
        std::os::unix::fs::symlink("/dev/full", &journal).unwrap();
        assert!(Recorder::journal(&journal, "test").is_err());
        assert!(std::fs::symlink_metadata(&journal).is_err(), "nothing is left at the journal's path");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }
}
