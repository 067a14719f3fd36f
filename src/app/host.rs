//! The window as a host of the one script interpreter
//! (`octovox::replay::step`): played lines and what mouse and key actions
//! become run through it, so a line means what it means in `octovox
//! replay`. Once it has run, an edit goes to the GPU, the recording and
//! the journal here.

use std::path::Path;

use glam::{DVec3, IVec3};

use octovox::camera::Camera;
use octovox::edit::selection::Region;
use octovox::editor::{Editor, Outcome};
use octovox::io::atomic::WriteOptions;
use octovox::io::output::{OutputKind, check_output};
use octovox::replay::{Host, HostError, Ran, Recorder, StepError, StepResult, step};
use octovox::script::Line;
use octovox::settings::RenderSettings;
use octovox::trace::pick;

use super::App;

impl App {
    /// Runs one line that a mouse or key action became, as a script line.
    pub(super) fn run_line(&mut self, line: &Line) -> Result<StepResult, StepError> {
        self.run_script_line(Path::new("."), line)
    }

    /// Runs one line (paths relative to `base`) and follows it up. A line
    /// that ends a stroke (a key action during a drag) ends the drag too:
    /// the editor has closed its undo step, and the recording and the
    /// journal count steps by the same rule (`Line::ends_stroke`).
    pub(super) fn run_script_line(&mut self, base: &Path, line: &Line) -> Result<StepResult, StepError> {
        // Ended by its own line first, so that the recording and the journal
        // close it even where `line` is then refused.
        if line.ends_stroke() && self.doc.editor.history.stroke_open() {
            self.end_stroke();
        }
        let result = step(self, base, line)?;
        if let StepResult::Ran(Ran { line, outcome, selection, picked }) = &result {
            let in_stroke = self.doc.editor.history.stroke_open();
            if let Some(picked) = picked {
                self.followed_up(picked, &Outcome::State, *selection, in_stroke);
            }
            self.followed_up(line, outcome, *selection, in_stroke);
        }
        Ok(result)
    }

    /// Follows up an editor line: an edit goes to the GPU, the recording
    /// and the journal; a new scene starts its journal as Open does.
    /// `in_stroke`: the line is an edit of the stroke under way.
    fn followed_up(&mut self, line: &Line, outcome: &Outcome, selection: Option<Region>, in_stroke: bool) {
        if matches!(outcome, Outcome::Replaced) {
            return self.scene_replaced(line.clone(), None);
        }
        if matches!(outcome, Outcome::Changed) {
            // A journal that the line starts begins with the selection before it.
            self.open_journal(selection);
        }
        let (tools, camera) = (self.doc.editor.tools, self.state.camera);
        let changed = matches!(outcome, Outcome::Changed);
        let ran = |r: &mut Recorder| r.ran(line, &tools, &camera, changed);
        match (outcome, line) {
            // Undo and redo: the journal gets them as lines only if it holds the steps.
            (Outcome::Changed, Line::Undo(n) | Line::Redo(n)) => {
                let undo = matches!(line, Line::Undo(_));
                (0..*n).for_each(|_| self.record_undo(undo));
                self.after_change(if undo { "undo" } else { "redo" }, |_| Ok(()));
            }
            // A block copied before the journal started: the journal starts again after the paste.
            (Outcome::Changed, Line::Paste(_)) if !self.doc.clipboard_journaled => {
                self.record_to_recording(ran);
                self.restart_journal_from_snapshot();
                self.after_change("paste", |_| Ok(()));
            }
            // A step of a mouse stroke or a palette control prints `edit: …`.
            (Outcome::Changed, _) if in_stroke => self.after_change("edit", ran),
            // A frame says which (`frame 12: N bytes written`).
            (Outcome::Changed, Line::Frame(_)) => self.after_change(&line.to_string(), ran),
            (Outcome::Changed, _) => {
                // The line's command word names it in the printed line (`fill: N bytes written`).
                self.after_change(line.word(), ran);
            }
            _ => {
                self.record(ran);
                report!("ran: {line}");
                self.request_redraw();
            }
        }
        if matches!(line, Line::Copy | Line::Cut) {
            self.doc.clipboard_journaled = self.doc.journal.is_some();
        }
    }

    /// The rule every command that writes follows: the kind's extension,
    /// never an input (the played script, the open document).
    fn check_write(&self, path: &Path, kind: OutputKind) -> Result<(), HostError> {
        let inputs: Vec<&Path> = self.doc.player.iter().map(|p| p.path()).chain(self.state.path.as_deref()).collect();
        Ok(check_output(path, kind, &inputs, false)?)
    }

    /// `render PATH` in the window: the image `octovox replay` makes (the
    /// script's viewport, the default settings), by the window's renderer.
    fn render_for_script(&mut self, path: &Path) -> Result<image::RgbaImage, HostError> {
        self.check_write(path, OutputKind::Image)?;
        let gfx = self.gfx.as_mut().ok_or(HostError::NoGpuYet)?;
        let viewport = self.doc.player.as_ref().map_or(octovox::replay::DEFAULT_VIEWPORT, |p| p.viewport);
        let settings = RenderSettings { ground: self.doc.editor.ground_plane(), ..RenderSettings::default() };
        gfx.renderer.render(&self.doc.editor.scene, &self.state.camera, viewport, &settings, None)?;
        let image = gfx.renderer.read_image()?;
        octovox::io::png::save_png(&image, path, WriteOptions::default())?;
        report!("screenshot: {}", path.display());
        self.request_redraw();
        Ok(image)
    }
}

impl Host for App {
    fn editor(&mut self) -> &mut Editor {
        &mut self.doc.editor
    }

    /// Read in the background, as File ▸ Open does; the player waits for it.
    fn load(&mut self, path: &Path) -> Result<(), HostError> {
        self.start_loading(path.to_path_buf());
        Ok(())
    }

    fn set_camera(&mut self, eye: DVec3, target: DVec3, fov_y_deg: Option<f32>) {
        let fov_y_deg = fov_y_deg.unwrap_or(self.state.camera.fov_y_deg);
        self.state.camera = Camera { eye, target, fov_y_deg, ..self.state.camera };
        self.request_redraw();
    }

    fn set_projection(&mut self, ortho: Option<f32>) {
        self.state.camera.ortho = ortho;
        self.request_redraw();
    }

    /// The size of the script's renders; clicks name pixels of the window.
    fn set_viewport(&mut self, width: u32, height: u32) {
        if let Some(player) = &mut self.doc.player {
            player.viewport = (width, height);
        }
    }

    fn pick(&mut self, x: u32, y: u32) -> Result<Option<(IVec3, IVec3, u8)>, pick::GaveUp> {
        let pick = self.pick_or_ground(f64::from(x) + 0.5, f64::from(y) + 0.5)?;
        Ok(pick.map(|pick| (pick.voxel, pick.normal, pick.value)))
    }

    fn save(&mut self, path: &Path) -> Result<(), HostError> {
        if self.save_document(path, WriteOptions::default()) { Ok(()) } else { Err(HostError::NotSaved(path.into())) }
    }

    fn render(&mut self, path: &Path) -> Result<(), HostError> {
        let image = self.render_for_script(path)?;
        if let Some(player) = &mut self.doc.player {
            player.last_render = Some(image);
        }
        Ok(())
    }

    fn save_palette(&mut self, path: &Path) -> Result<(), HostError> {
        self.check_write(path, OutputKind::Palette)?;
        octovox::io::palette_file::save(&self.doc.editor.scene.palette, path)?;
        report!("palette saved: {}", path.display());
        Ok(())
    }

    fn last_render(&self) -> Option<&image::RgbaImage> {
        self.doc.player.as_ref()?.last_render.as_ref()
    }

    fn last_written(&self) -> Option<u64> {
        self.readouts.stats.last_edit_bytes
    }
}
