//! The editing session without a window: the document, the editor's
//! window-side state (tool, modes, camera, settings), the gesture under
//! way, what the cursor is over, and the panels' state. It takes commands
//! ([`Session::execute`]: mouse, keys, panels, played scripts) and says
//! what the window must do in [`Effects`] (redraw, retitle, ask for a path,
//! take a screenshot, close). What it needs of the window comes in as plain
//! data ([`ViewSize`], [`Pointer`]); picking is the CPU's, from those.
//! The scene's GPU copy is the one renderer, present once a device exists:
//! without one (the tests) edits stay dirty in the pool, as before the
//! window's first frame.

use std::path::{Path, PathBuf};

use glam::IVec3;

use octovox::camera::Camera;
use octovox::edit::Edit;
use octovox::edit::selection::Region;
use octovox::editor::Outcome;
use octovox::gpu::Renderer;
use octovox::gpu::scene_buffers::UploadStats;
use octovox::io::atomic::WriteOptions;
use octovox::replay::{Ran, Recorder, StepError, StepResult, step};
use octovox::scene::Scene;
use octovox::script::Line;
use octovox::trace::pick;

use super::dialog_kind::DialogKind;
use super::document::Document;
use super::gesture::{self, Gesture, Stroke};
use super::preview::Hover;
use super::state::{EditorState, Mode, Pick, Tool};
use super::ui::{Readouts, UiState};
use crate::cli::WindowArgs;

use super::{AppCommand, Pending, SAVES_DIR, StrokePhase, camera_control, drag, outliner, presets, ui};

/// The window's size as the session needs it: for picking (a window pixel
/// is a trace pixel by the render scale) and for framing.
#[derive(Clone, Copy, Debug)]
pub(super) struct ViewSize {
    /// Physical pixels.
    pub window: (u32, u32),
    /// Physical pixels per point.
    pub scale_factor: f64,
    /// The render scale's factor while the camera moves (1 at rest).
    pub motion_factor: f32,
}

/// The pointer and the modifier keys, as the previews read them.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Pointer {
    pub cursor: Option<(f64, f64)>,
    pub ctrl: bool,
    pub shift: bool,
    pub alt: bool,
}

/// What the window must do after the session acted.
#[derive(Debug, Default)]
pub(super) struct Effects {
    pub redraw: bool,
    /// The title (file name, unsaved mark) changed.
    pub title: bool,
    /// Ask for a path for this kind, starting here.
    pub ask_path: Option<(DialogKind, String)>,
    pub screenshot: bool,
    /// The session is over (Quit with nothing left unsaved).
    pub exit: bool,
}

/// The editing session (see the module documentation).
pub(super) struct Session {
    pub doc: Document,
    /// The tool, modes, camera, render settings and the file's name.
    pub state: EditorState,
    pub gesture: Gesture,
    pub hover: Hover,
    pub ui: UiState,
    pub readouts: Readouts,
    /// The scene's copy on the GPU: the same renderer as headless `render`
    /// and `replay` use; `None` until a device exists.
    pub renderer: Option<Renderer>,
    pub view: ViewSize,
    pub pointer: Pointer,
    /// A camera given on the command line for this file: it wins when the
    /// file opens.
    pub camera_for: Option<PathBuf>,
    pub(super) effects: Effects,
}

impl Session {
    /// A session on an empty document, its view `window` pixels.
    pub fn new(window: (u32, u32)) -> Session {
        Session {
            doc: Document::default(),
            state: EditorState::default(),
            gesture: Gesture::Idle,
            hover: Hover::default(),
            ui: UiState::default(),
            readouts: Readouts::default(),
            renderer: None,
            view: ViewSize { window, scale_factor: 1.0, motion_factor: 1.0 },
            pointer: Pointer::default(),
            camera_for: None,
            effects: Effects::default(),
        }
    }

    /// The session the command line asks for: its settings and camera, its
    /// scripts, and its file opening (or the built-in scene, with any
    /// untitled scene a dead session left offered back).
    pub fn start(args: &WindowArgs) -> Session {
        let mut session = Session::new(args.size);
        session.open_script_files(args.replay.as_deref(), args.record.as_deref());
        session.state.settings.render_scale = args.render_scale;
        session.state.settings.shadows = !args.no_shadows;
        session.state.settings.lod = args.lod;
        session.state.shading = args.shading;
        session.state.sample_target = args.samples;
        session.state.denoise = !args.no_denoise;
        if let Some((eye, target)) = args.camera {
            session.state.camera = Camera { eye, target, ..session.state.camera };
            session.camera_for = args.file.clone();
        }
        match args.file.clone() {
            Some(path) => session.start_loading(path),
            None => {
                let built_in = args.demo.unwrap_or_default();
                session.replace_scene(built_in.scene(), octovox::script::Line::Demo(built_in), None);
                if args.camera.is_none() {
                    session.frame_box(session.doc.editor.scene.solid_bounds());
                }
                // An untitled scene of a session that died: offer it back.
                if let Some(journal) = octovox::journal::orphaned_untitled(Path::new(SAVES_DIR)).first() {
                    session.found_journal(journal.clone(), None);
                }
            }
        }
        session
    }

    /// What the window must do for what the session did since the last take.
    pub fn take_effects(&mut self) -> Effects {
        std::mem::take(&mut self.effects)
    }

    /// Asks the window for a frame.
    pub(super) fn request_redraw(&mut self) {
        self.effects.redraw = true;
    }

    /// Asks the window to ask for a path.
    pub(super) fn ask_path(&mut self, kind: DialogKind, start: String) {
        self.effects.ask_path = Some((kind, start));
    }

    // ----- the one path for changes: edit → history → octree → upload ------------

    /// Ctrl+Z / Ctrl+Shift+Z: one step, if there is one.
    pub(super) fn undo_redo(&mut self, undo: bool) {
        let what = if undo { "undo" } else { "redo" };
        let (undoable, redoable) = self.doc.editor.history.steps();
        if (if undo { undoable } else { redoable }) == 0 {
            return self.ui.info(format!("nothing to {what}"));
        }
        self.act(if undo { octovox::script::Line::Undo(1) } else { octovox::script::Line::Redo(1) }, what);
    }

    /// A mouse or key action as an editor line; a refusal goes to the
    /// message line as `what refused: …`.
    pub(super) fn act(&mut self, line: octovox::script::Line, what: &str) {
        if let Err(err) = self.run_line(&line) {
            self.ui.error(format!("{what} refused: {err}"));
        }
    }

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
    pub(super) fn followed_up(&mut self, line: &Line, outcome: &Outcome, selection: Option<Region>, in_stroke: bool) {
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

    /// Whether the scene differs from its file: the history is not at the
    /// state it was saved or loaded at (undoing back to it is no change).
    pub(super) fn unsaved(&self) -> bool {
        self.state.saved_state != Some(self.doc.editor.history.state_id())
    }

    /// Follows up a change: `record` writes it to the recording and the
    /// journal *before* it is reported done (a crash
    /// after the report loses nothing); what changed goes to the GPU and
    /// everything that depends on the voxels is refreshed. Prints `WHAT: N
    /// bytes written` (the tests read it).
    pub(super) fn after_change(&mut self, what: &str, record: impl Fn(&mut Recorder) -> std::io::Result<()>) {
        self.ui.change_made();
        self.record(record);
        let upload = self.upload();
        self.readouts.stats.last_edit_bytes = Some(upload.bytes);
        self.readouts.stats.last_edit_ranges = upload.ranges;
        report!(
            "{what}: {} bytes written in {} ranges{}",
            upload.bytes,
            upload.ranges,
            if upload.grew { " (buffer grew)" } else { "" }
        );
        self.hover.extrude_preview = None;
        self.hover.fill_preview = None;
        self.update_title();
        self.request_redraw();
    }

    /// Flushes the pool's dirty ranges (only those) and the palette (1 KiB,
    /// which palette edits change) to the GPU buffers; the stats count the pool.
    pub(super) fn upload(&mut self) -> UploadStats {
        match &mut self.renderer {
            Some(renderer) => renderer.sync(&mut self.doc.editor.scene),
            // No device yet: the ranges stay dirty and go up with the first frame.
            None => UploadStats::default(),
        }
    }

    pub(super) fn update_title(&mut self) {
        self.effects.title = true;
    }

    // ----- commands -----------------------------------------------------------

    /// Carries out one command. Panels, keys, the mouse and played replay
    /// scripts all end up here.
    pub fn execute(&mut self, command: AppCommand) {
        if command.edits_scene() && self.doc.loading.is_some() {
            return self.ui.info("still loading…");
        }
        if self.ui.playback.playing() && !command.keeps_playing() {
            self.timeline_key(&AppCommand::TogglePlay);
        }
        match command {
            AppCommand::PointerEdit { phase, tool, x, y } => self.pointer_edit(phase, tool, x, y),
            AppCommand::ExtrudeDrag { phase, x, y } => self.extrude_drag(phase, x, y),
            AppCommand::EditPalette { edit, dragging } => self.palette_edit(edit, dragging),
            AppCommand::Cut => self.act(octovox::script::Line::Cut, "cut"),
            // Object mode: Delete and X/Y/Z act on the picked object.
            AppCommand::DeleteSelection if self.state.mode == Mode::Object => {
                self.act(octovox::script::Line::Object(octovox::script::ObjectLine::Delete), "object")
            }
            AppCommand::Turn { axis, flip: false } if self.state.mode == Mode::Object => {
                self.act(octovox::script::Line::Object(octovox::script::ObjectLine::Rotate(axis)), "object")
            }
            // An object does not flip: Shift picks the axis the ring and the
            // Turn row turn it about.
            AppCommand::Turn { axis, flip: true } if self.state.mode == Mode::Object => {
                self.ui.outliner.turn.axis = axis;
                let said = format!("the ring turns the object about {}", ["x", "y", "z"][axis]);
                report!("{said}");
                self.ui.info(said);
            }
            AppCommand::DeleteSelection => self.act(octovox::script::Line::Delete, "delete"),
            AppCommand::PasteAtCursor => self.paste_at_cursor(),
            AppCommand::Nudge(nudge) => self.nudge(nudge),
            AppCommand::Turn { axis, flip: false } => self.act(octovox::script::Line::Rotate(axis), "rotate"),
            AppCommand::Turn { axis, flip: true } => self.act(octovox::script::Line::Flip(axis), "flip"),
            AppCommand::Undo => self.undo_redo(true),
            AppCommand::Redo => self.undo_redo(false),
            AppCommand::ApplyPreset(i) => {
                if let Some(preset) = presets::PRESETS.get(i) {
                    preset.apply(&mut self.state);
                    report!("preset: {}", preset.name);
                }
            }
            AppCommand::MeasurePresets => self.measure_presets(),
            AppCommand::ToggleLine => self.toggle_mode(Mode::Line),
            AppCommand::ToggleSelect => self.toggle_mode(Mode::Select),
            AppCommand::ToggleObject => self.toggle_mode(Mode::Object),
            AppCommand::Copy => match self.run_line(&octovox::script::Line::Copy) {
                Ok(_) => {
                    let voxels = self.doc.editor.clipboard().map_or(0, octovox::edit::selection::Block::voxels);
                    self.ui.info(format!("copied {voxels} voxels"));
                }
                Err(err) => self.ui.error(format!("copy refused: {err}")),
            },
            AppCommand::SelectNone => self.act(octovox::script::Line::Select(None), "select"),
            AppCommand::Object(line) => self.act(octovox::script::Line::Object(line), "object"),
            AppCommand::ShowFrame(frame) => self.show_frame(frame),
            AppCommand::TogglePlay | AppCommand::StepFrame(_) | AppCommand::Key(_) => self.timeline_key(&command),
            AppCommand::Lines(lines) => {
                for line in lines {
                    let word = line.word();
                    self.act(line, word);
                }
            }
            AppCommand::FillAt { x, y } => {
                if let Some(pick) = self.pick_or_say(x, y, "no voxel there to fill") {
                    self.act(octovox::script::Line::Fill(pick.voxel), "fill");
                }
            }
            AppCommand::PickColor { x, y } => {
                if let Some(pick) = self.pick_or_say(x, y, "no voxel there to pick a colour from") {
                    self.act(octovox::script::Line::Pick(pick.voxel), "pick");
                    report!("picked colour {}", self.doc.editor.tools.color);
                }
            }
            AppCommand::SetTool(tool) => {
                // A tool is what a press applies: select and object mode,
                // where a press picks, give way to the brush.
                if !self.state.mode.uses_brush() {
                    self.toggle_mode(self.state.mode);
                }
                self.state.tool = tool;
            }
            AppCommand::Orbit { dx, dy } => camera_control::orbit(&mut self.state.camera, dx, dy),
            AppCommand::Pan { dx, dy } => {
                let height = self.view.window.1;
                camera_control::pan(&mut self.state.camera, dx, dy, height);
            }
            AppCommand::Zoom { steps, at } => {
                // Toward the voxel under the cursor (a pick that fails zooms to the target).
                let toward = at.and_then(|(x, y)| self.pick_or_ground(x, y).ok().flatten());
                let toward = toward.map(|pick| pick.voxel.as_dvec3() + glam::DVec3::splat(0.5));
                camera_control::zoom(&mut self.state.camera, steps, toward);
            }
            AppCommand::ToggleProjection => camera_control::toggle_projection(&mut self.state.camera),
            AppCommand::ViewFrom(side) => camera_control::view_from(&mut self.state.camera, side.as_dvec3()),
            AppCommand::FrameModel => self.frame_box(self.doc.editor.scene.solid_bounds()),
            AppCommand::FrameSelection => {
                let selected = self.doc.editor.selection.map(|r| (r.min, r.max));
                self.frame_box(selected.or_else(|| self.doc.editor.scene.solid_bounds()));
            }
            AppCommand::New => self.guard_unsaved(Pending::New),
            AppCommand::Open(path) => self.guard_unsaved(Pending::Open(path)),
            AppCommand::Quit => self.guard_unsaved(Pending::Quit),
            AppCommand::Save => match self.state.path.clone() {
                Some(path) => {
                    self.save_document(&path, WriteOptions::default());
                }
                None => self.ask_path(DialogKind::SaveAs, "saves/untitled.vox".into()),
            },
            AppCommand::SaveAs(path) => self.save_as(path, WriteOptions::default()),
            AppCommand::SaveOver(path) => self.save_as(path, WriteOptions::forced(true)),
            AppCommand::AskOpen => {
                let start = self.state.path.as_ref().map(|p| p.display().to_string()).unwrap_or_default();
                self.ask_path(DialogKind::Open, start);
            }
            AppCommand::AskSaveAs => {
                let start = self.state.path.as_ref().map_or("saves/untitled.vox".into(), |p| p.display().to_string());
                self.ask_path(DialogKind::SaveAs, start);
            }
            AppCommand::AskExport => {
                let start = self.state.path.as_ref().map_or("saves/untitled.obj".into(), |p| p.with_extension("obj"));
                self.ask_path(DialogKind::Export, start.display().to_string());
            }
            AppCommand::AskPlayScript => self.ask_path(DialogKind::PlayScript, String::new()),
            AppCommand::PlayScript(path) => self.open_script_files(Some(&path), None),
            AppCommand::AskPalette { save } => {
                let kind = if save { DialogKind::SavePalette } else { DialogKind::LoadPalette };
                self.ask_path(kind, if save { "saves/palette.png".into() } else { String::new() });
            }
            AppCommand::Export(path) => self.export(&path),
            AppCommand::Screenshot => self.effects.screenshot = true,
            AppCommand::Resolve(choice) => self.resolve(choice),
            AppCommand::RecoverJournal(journal, checks) => self.recover_journal(&journal, checks),
            AppCommand::DiscardJournal(journal) => octovox::journal::discard(&journal),
        }
        self.request_redraw();
    }

    /// Frames the box (the whole model, or the selection), centred in the
    /// part of the window that the side panel leaves free.
    pub(super) fn frame_box(&mut self, bounds: Option<(IVec3, IVec3)>) {
        camera_control::frame_model(&mut self.state.camera, bounds);
        let (scale, height) = (self.view.scale_factor, self.view.window.1);
        let (left, right) = self.side_panels();
        camera_control::pan(&mut self.state.camera, f64::from(left - right) * scale * 0.5, 0.0, height);
    }

    /// Widths in points of the panels at the window's left and right sides.
    pub(super) fn side_panels(&self) -> (f32, f32) {
        let outliner = self.doc.editor.scene.pickable_objects().is_some();
        (ui::PANEL_WIDTH, if outliner { outliner::OUTLINER_WIDTH } else { 0.0 })
    }

    // ----- picking and mouse edits ---------------------------------------------------

    /// The render scale this frame traces at: the user's, lowered while the
    /// camera moves.
    pub(super) fn render_scale(&self) -> f32 {
        self.state.settings.render_scale.clamp(octovox::settings::MIN_RENDER_SCALE, 1.0) * self.view.motion_factor
    }

    /// The window's size in physical pixels (the requested one before it opens).
    pub(super) fn window_size(&self) -> (u32, u32) {
        self.view.window
    }

    /// The trace resolution for the current window size and render scale.
    pub(super) fn trace_size(&self) -> (u32, u32) {
        let (w, h) = self.window_size();
        let scale = self.render_scale();
        (((w as f32 * scale).round() as u32).max(1), ((h as f32 * scale).round() as u32).max(1))
    }

    /// CPU pick of the voxel and face under window pixel (x, y), in world
    /// coordinates. Same ray as the GPU's pixel (window pixels map to trace
    /// pixels by the render scale; the panels sit over the image).
    /// A ray that gave up is an error, never "nothing under the cursor".
    pub(super) fn pick_at(&self, x: f64, y: f64) -> Result<Option<Pick>, pick::GaveUp> {
        self.pick_pixel(x, y, false)
    }

    /// [`Session::pick_at`], or where there is no voxel and the ground is on,
    /// the ground cell under y = 0 (value 0): what Attach, lines, selections
    /// and pastes start from in an empty scene.
    pub(super) fn pick_or_ground(&self, x: f64, y: f64) -> Result<Option<Pick>, pick::GaveUp> {
        self.pick_pixel(x, y, self.doc.editor.ground)
    }

    pub(super) fn pick_pixel(&self, x: f64, y: f64, ground: bool) -> Result<Option<Pick>, pick::GaveUp> {
        let (window_w, window_h) = self.window_size();
        let (w, h) = self.trace_size();
        if x < 0.0 || y < 0.0 || x >= f64::from(window_w) || y >= f64::from(window_h) {
            return Ok(None);
        }
        let px = ((x * f64::from(w) / f64::from(window_w)) as u32).min(w - 1);
        let py = ((y * f64::from(h) / f64::from(window_h)) as u32).min(h - 1);
        let hit = pick::pick_with_ground(&self.doc.editor.scene, &self.state.camera, (w, h), (px, py), ground)?;
        Ok(hit)
    }

    /// The voxel under window pixel (x, y) for a click; when there is none,
    /// `nothing` (or why the ray gave up) goes to the message line.
    pub(super) fn pick_or_say(&mut self, x: f64, y: f64, nothing: &str) -> Option<Pick> {
        self.say_if_none(self.pick_at(x, y), nothing)
    }

    /// [`Session::pick_or_say`] with the ground ([`Session::pick_or_ground`]).
    pub(super) fn pick_or_ground_or_say(&mut self, x: f64, y: f64, nothing: &str) -> Option<Pick> {
        self.say_if_none(self.pick_or_ground(x, y), nothing)
    }

    pub(super) fn say_if_none(&mut self, picked: Result<Option<Pick>, pick::GaveUp>, nothing: &str) -> Option<Pick> {
        match picked {
            Ok(Some(pick)) => Some(pick),
            Ok(None) => {
                self.ui.info(nothing);
                None
            }
            Err(gave_up) => {
                self.ui.error(gave_up.to_string());
                None
            }
        }
    }

    /// `mode` on, or off when it is on; a line or box drag under way ends.
    pub(super) fn toggle_mode(&mut self, mode: Mode) {
        // An object drag's undo step closes with it.
        if matches!(self.gesture, Gesture::ObjectDrag { .. }) {
            self.close_strokes();
        }
        self.state.toggle_mode(mode);
        if matches!(self.gesture, Gesture::Line { .. } | Gesture::Select { .. }) {
            self.gesture = Gesture::Idle;
        }
    }

    /// Ends the line drag under way; returns where it started.
    pub(super) fn end_line(&mut self) -> Option<IVec3> {
        let start = self.gesture.line_start();
        if start.is_some() {
            self.gesture = Gesture::Idle;
        }
        start
    }

    /// Line mode: the press picks the start (in front of the face), the
    /// release the end; the brush is placed along the line as one step.
    pub(super) fn line_edit(&mut self, phase: StrokePhase, x: f64, y: f64) {
        let target = match self.pick_or_ground(x, y) {
            Ok(Some(pick)) => Some(pick.in_front()),
            Ok(None) => None,
            Err(gave_up) => {
                self.ui.error(gave_up.to_string());
                None
            }
        };
        let why =
            if self.doc.editor.ground { "no voxel or ground there" } else { "no voxel there, and the ground is off" };
        match phase {
            StrokePhase::Begin => {
                self.gesture = target.map_or(Gesture::Idle, |start| Gesture::Line { start });
                if target.is_none() {
                    self.ui.info(format!("a line starts on a voxel face or the ground: {why}"));
                }
            }
            StrokePhase::Move => {}
            StrokePhase::End | StrokePhase::Click => match (self.end_line().or(target), target) {
                (Some(a), Some(b)) => self.act(octovox::script::Line::Segment(a, b), "line"),
                (Some(_), None) => self.ui.info(format!("no line drawn: it ends on the sky ({why})")),
                (None, _) => {}
            },
        }
    }

    /// A Ctrl+drag extrude: the face under the press, then at the release
    /// the layers the drag covers along the face's normal as drawn on
    /// screen (one layer = the on-screen length of one voxel step).
    pub(super) fn extrude_drag(&mut self, phase: StrokePhase, x: f64, y: f64) {
        match phase {
            StrokePhase::Begin => {
                self.gesture = self
                    .pick_or_say(x, y, "no face under the cursor to extrude")
                    .filter(|p| p.normal != IVec3::ZERO)
                    .map_or(Gesture::Idle, |face| Gesture::Extrude { face, start: (x, y) });
            }
            // While dragging, the message line says what the release will do.
            StrokePhase::Move => {
                if let Some(layers) = self.extrude_layers(x, y) {
                    let how = if layers < 0 { "in" } else { "out" };
                    self.ui.info(format!("extrude {how} {} layer(s)", layers.abs()));
                }
            }
            StrokePhase::End => {
                let layers = self.extrude_layers(x, y);
                let Gesture::Extrude { face: pick, .. } = std::mem::take(&mut self.gesture) else { return };
                let Some(layers) = layers.filter(|l| *l != 0) else { return };
                self.act(octovox::script::Line::Extrude(pick.voxel, pick.normal, layers), "extrude");
            }
            StrokePhase::Click => {}
        }
    }

    /// The layers a Ctrl+drag from its start to (x, y) covers.
    pub(super) fn extrude_layers(&self, x: f64, y: f64) -> Option<i32> {
        let Gesture::Extrude { face: pick, start } = self.gesture else { return None };
        let face = (pick.voxel - self.doc.editor.scene.origin()).as_vec3()
            + glam::Vec3::splat(0.5)
            + pick.normal.as_vec3() * 0.5;
        self.screen_steps(face, pick.normal, start, (x, y))
    }

    /// The whole voxel steps along `normal` that a drag from window pixel
    /// `start` to `end` covers at the (tree-local) point `face`
    /// ([`drag::screen_steps`] through the window's camera): extrudes and
    /// selection handles.
    pub(super) fn screen_steps(
        &self,
        face: glam::Vec3,
        normal: IVec3,
        start: (f64, f64),
        end: (f64, f64),
    ) -> Option<i32> {
        drag::screen_steps(&self.view_basis(), face, normal, start, end)
    }

    /// The camera's rays over the whole window, tree-local.
    pub(super) fn view_basis(&self) -> octovox::camera::RayBasis {
        let (w, h) = self.window_size();
        self.state.camera.basis(w, h, self.doc.editor.scene.origin())
    }

    /// A palette change from the panel, as `rgb` and `material` lines (the
    /// parts that changed); changes while a control is held form one undo
    /// step, and so do the two lines of one change.
    pub(super) fn palette_edit(&mut self, edit: Edit, dragging: bool) {
        let lines = gesture::palette_lines(&self.doc.editor.scene.palette, edit);
        if !matches!(self.gesture, Gesture::Palette) {
            self.begin_stroke(Gesture::Palette);
        }
        for line in &lines {
            if let Err(err) = self.run_line(line) {
                self.ui.error(format!("edit refused: {err}"));
                break;
            }
        }
        if !dragging {
            self.close_strokes();
        }
    }

    /// Starts a gesture whose edits are one undo step: `stroke begin`.
    pub(super) fn begin_stroke(&mut self, gesture: Gesture) {
        if let Err(err) = self.run_line(&octovox::script::Line::Stroke(true)) {
            return self.ui.error(format!("stroke refused: {err}"));
        }
        self.gesture = gesture;
    }

    /// Ends the gesture of a mouse drag or a held palette control: `stroke
    /// end`, which closes its undo step in the history, the recording and
    /// the journal alike.
    pub(super) fn close_strokes(&mut self) {
        if self.gesture.groups_edits() {
            self.end_stroke();
        }
    }

    /// Runs `stroke end`; the drag that made the stroke is over.
    pub(super) fn end_stroke(&mut self) {
        if self.gesture.groups_edits() {
            self.gesture = Gesture::Idle;
        }
        if let Err(err) = self.run_line(&octovox::script::Line::Stroke(false)) {
            self.ui.error(format!("stroke refused: {err}"));
        }
    }

    pub(super) fn pointer_edit(&mut self, phase: StrokePhase, tool: Tool, x: f64, y: f64) {
        match self.state.mode {
            Mode::Line => return self.line_edit(phase, x, y),
            Mode::Select => return self.select_drag(phase, x, y),
            Mode::Object => return self.object_click(phase, x, y),
            Mode::Brush => {}
        }
        match phase {
            StrokePhase::Begin => {
                self.begin_stroke(Gesture::Stroke(Stroke { tool, plane: None, last_center: None }));
                self.stroke_step(x, y);
            }
            StrokePhase::Move => self.stroke_step(x, y),
            StrokePhase::End => self.close_strokes(),
            StrokePhase::Click => {
                self.pointer_edit(StrokePhase::Begin, tool, x, y);
                self.pointer_edit(StrokePhase::End, tool, x, y);
            }
        }
    }

    /// One brush application of the open stroke at (x, y), if it lands on a
    /// new cell of the stroke's layer.
    pub(super) fn stroke_step(&mut self, x: f64, y: f64) {
        let Some(stroke) = self.gesture.stroke() else { return };
        // Attach builds on the ground too; Erase and Paint need a voxel.
        let picked = if stroke.tool == Tool::Attach { self.pick_or_ground(x, y) } else { self.pick_at(x, y) };
        let pick = match picked {
            Ok(Some(pick)) => pick,
            Ok(None) => return,
            Err(gave_up) => {
                self.ui.error(gave_up.to_string());
                return;
            }
        };
        let Some(step) = stroke.step_at(&pick, self.doc.editor.tools.brush.reach()) else { return };
        // The stroke's first step picks the object it hits (it edits that
        // one to the end); each step is the script line a click there is:
        // the same path as every line, recorded and journaled as one edit
        // of the stroke.
        let picked = self.doc.editor.object_line_for(&pick).filter(|_| step.first);
        let ran = picked
            .map_or(Ok(()), |picked| self.run_line(&picked).map(|_| ()))
            .and_then(|()| self.run_line(&step.line).map(|_| ()));
        match ran {
            Ok(_) => self.with_stroke(|stroke| stroke.stepped(&step)),
            Err(err) => self.ui.error(format!("edit refused: {err}")),
        }
    }

    pub(super) fn with_stroke(&mut self, f: impl FnOnce(&mut Stroke)) {
        if let Some(stroke) = self.gesture.stroke_mut() {
            f(stroke);
        }
    }
}

/// The palette index used most often is a better first colour than 1.
pub(super) fn first_used_color(scene: &Scene) -> Option<u8> {
    let counts = scene.counts();
    counts.present().max_by_key(|v| counts.get(*v))
}

#[cfg(test)]
mod tests;
