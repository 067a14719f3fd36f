//! The sandbox window: the winit `ApplicationHandler`, the wgpu surface,
//! and `execute`, the one place every command (mouse, keyboard, panel) is
//! carried out. What it holds is in plain structs, each in its own file
//! (`document`, `gesture`, `preview`'s `Hover`, `clock`, `ui`); edits are
//! script lines run through the one interpreter (`host`); the frame is in
//! `frame`, opening and saving in `files`.

/// Prints one status line on stdout (`edit: …`, `saved: …`, `octovox: ready`;
/// tests and scripts read them). A closed stdout is not an error worth dying for.
macro_rules! report {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}

mod actions;
mod browser;
mod camera_control;
mod capture;
mod clock;
mod command;
mod dialog_kind;
mod document;
mod drag;
mod egui_layers;
mod file_dialog;
mod files;
mod frame;
mod gesture;
mod gizmo;
mod host;
mod input;
mod journal;
mod motion;
mod outliner;
mod presets;
mod preview;
mod recent;
mod script;
mod selection;
mod slow_clicks;
mod state;
mod timeline;
mod ui;

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::time::Instant;

use anyhow::Context as _;
use glam::IVec3;
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::window::{Window, WindowId};

use octovox::camera::Camera;
use octovox::edit::Edit;
use octovox::gpu::scene_buffers::UploadStats;
use octovox::gpu::{BlitMode, BlitPass, GpuContext, Renderer};
use octovox::io::atomic::WriteOptions;
use octovox::replay::Recorder;
use octovox::scene::Scene;
use octovox::trace::pick;

use crate::cli::WindowArgs;
use clock::FrameClock;
pub use command::{AppCommand, Choice, Nudge, Pending, StrokePhase};
use dialog_kind::DialogKind;
use document::Document;
use egui_layers::EguiLayers;
use gesture::{Gesture, Stroke};
use input::Input;
use preview::Hover;
use state::{EditorState, Mode, Pick, Tool};
use ui::{Readouts, UiState};

/// Where screenshots and the journal of an untitled scene go, relative to
/// the working directory.
const SAVES_DIR: &str = "saves";

/// Opens the window and runs until it is closed.
pub fn run(args: WindowArgs) -> anyhow::Result<ExitCode> {
    if let Some(record) = &args.record {
        // Checked before anything opens: recording truncates its file.
        let inputs: Vec<&std::path::Path> = args.file.iter().chain(&args.replay).map(PathBuf::as_path).collect();
        octovox::io::output::check_output(record, octovox::io::output::OutputKind::Script, &inputs, args.force)?;
    }
    let event_loop = EventLoop::new().context("cannot open a window (is DISPLAY or WAYLAND_DISPLAY set?)")?;
    let instance = GpuContext::window_instance(Box::new(event_loop.owned_display_handle()));
    let mut app = App::new(args, instance);
    event_loop.run_app(&mut app).context("the event loop failed")?;
    if let Some(frames) = &app.frames.moving_frames {
        report!("frame-stats: {}", frames.summary());
    }
    match app.fatal.take() {
        Some(err) => Err(err),
        None => Ok(ExitCode::SUCCESS),
    }
}

/// The window and everything on the GPU.
struct Gfx {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    /// The swapchain can be copied from (window screenshots).
    can_copy_frame: bool,
    /// The scene's buffers and the trace pass: the same renderer as headless
    /// `render` and `replay` use.
    renderer: Renderer,
    blit: BlitPass,
    egui_state: egui_winit::State,
    egui: EguiLayers,
}

/// The window. What it holds is in plain structs, each in its own file:
/// the document, the gesture under way, what the cursor is over, the
/// frame clock, the panels' state and readouts.
struct App {
    args: WindowArgs,
    /// Until the window opens.
    instance: Option<wgpu::Instance>,
    /// The window and everything on the GPU, once it is open.
    gfx: Option<Gfx>,
    doc: Document,
    /// The tool, modes, camera, render settings and the file's name.
    state: EditorState,
    gesture: Gesture,
    hover: Hover,
    frames: FrameClock,
    ui: UiState,
    readouts: Readouts,
    input: Input,
    fatal: Option<anyhow::Error>,
}

impl App {
    fn new(args: WindowArgs, instance: wgpu::Instance) -> App {
        let mut app = App {
            instance: Some(instance),
            gfx: None,
            doc: Document::default(),
            state: EditorState::default(),
            gesture: Gesture::Idle,
            hover: Hover::default(),
            frames: FrameClock::new(&args),
            ui: UiState::default(),
            readouts: Readouts::default(),
            input: Input::default(),
            fatal: None,
            args,
        };
        app.open_script_files();
        app.state.settings.render_scale = app.args.render_scale;
        app.state.settings.shadows = !app.args.no_shadows;
        app.state.settings.lod = app.args.lod;
        app.state.shading = app.args.shading;
        app.state.sample_target = app.args.samples;
        app.state.denoise = !app.args.no_denoise;
        if let Some((eye, target)) = app.args.camera {
            app.state.camera = Camera { eye, target, ..app.state.camera };
        }
        match app.args.file.clone() {
            Some(path) => app.start_loading(path),
            None => {
                let built_in = app.args.demo.unwrap_or_default();
                app.replace_scene(built_in.scene(), octovox::script::Line::Demo(built_in), None);
                if app.args.camera.is_none() {
                    app.frame_box(app.doc.editor.scene.solid_bounds());
                }
                // An untitled scene of a session that died: offer it back.
                if let Some(journal) = octovox::journal::orphaned_untitled(std::path::Path::new(SAVES_DIR)).first() {
                    app.found_journal(journal.clone(), None);
                }
            }
        }
        app
    }

    // ----- window and GPU set-up -------------------------------------------------

    fn init_gfx(&mut self, event_loop: &ActiveEventLoop) -> anyhow::Result<Gfx> {
        let instance = self.instance.take().context("the window was created twice")?;
        let (width, height) = self.args.size;
        let attributes = Window::default_attributes()
            .with_title(self.state.title(self.unsaved()))
            .with_inner_size(winit::dpi::PhysicalSize::new(width, height));
        let window = Arc::new(event_loop.create_window(attributes).context("cannot create the window")?);
        let surface = instance.create_surface(window.clone()).context("cannot create a surface for the window")?;
        let gpu = pollster::block_on(GpuContext::with_instance(instance, Some(&surface)))?;
        let size = window.inner_size();
        let (width, height) = surface_size(size, &gpu);
        let mut config =
            surface.get_default_config(&gpu.adapter, width, height).context("the GPU cannot present to this window")?;
        let caps = surface.get_capabilities(&gpu.adapter);
        // egui-wgpu wants a non-sRGB target; the trace output is already sRGB-encoded.
        if let Some(format) = caps.formats.iter().copied().find(|f| !f.is_srgb()) {
            config.format = format;
        }
        let can_copy_frame = caps.usages.contains(wgpu::TextureUsages::COPY_SRC);
        if can_copy_frame {
            config.usage |= wgpu::TextureUsages::COPY_SRC;
        }
        let cpu = gpu.adapter.get_info().device_type == wgpu::DeviceType::Cpu;
        config.present_mode = present_mode(&caps.present_modes, cpu, self.frames.bench.is_some());
        surface.configure(&gpu.device, &config);
        let blit = BlitPass::new(&gpu, config.format, BlitMode::Replace)?;
        let mut renderer = Renderer::new(gpu)?;
        // The trace, blit and present are queued back to back; times shown are a frame old.
        renderer.wait_for_frames = false;
        // Until a path-traced sample has been timed, samples come in bands
        // as on a slow adapter; a fast one goes back to whole samples after
        // the first.
        renderer.path_bands = frame::MAX_PATH_BANDS / 2;
        let gpu = &renderer.gpu;
        let egui_state = egui_winit::State::new(
            egui::Context::default(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            window.theme(),
            Some(gpu.device.limits().max_texture_dimension_2d as usize),
        );
        let egui = EguiLayers::new(gpu, config.format)?;
        log::info!(
            "window on {} ({:?}, {:?}, {}x{})",
            gpu.adapter_name,
            config.format,
            config.present_mode,
            config.width,
            config.height
        );
        Ok(Gfx { window, surface, config, can_copy_frame, renderer, blit, egui_state, egui })
    }

    /// Asks for a frame. Only frames asked for here are drawn: on X11 with
    /// lavapipe every present comes back as another `RedrawRequested`, and
    /// drawing those would keep two cores busy with an unchanged picture.
    fn request_redraw(&self) {
        if let Some(gfx) = &self.gfx {
            self.frames.redraw_wanted.set(true);
            gfx.window.request_redraw();
        }
    }

    // ----- the one path for changes: edit → history → octree → upload ------------

    /// Ctrl+Z / Ctrl+Shift+Z: one step, if there is one.
    fn undo_redo(&mut self, undo: bool) {
        let what = if undo { "undo" } else { "redo" };
        let (undoable, redoable) = self.doc.editor.history.steps();
        if (if undo { undoable } else { redoable }) == 0 {
            return self.ui.info(format!("nothing to {what}"));
        }
        self.act(if undo { octovox::script::Line::Undo(1) } else { octovox::script::Line::Redo(1) }, what);
    }

    /// A mouse or key action as an editor line; a refusal goes to the
    /// message line as `what refused: …`.
    fn act(&mut self, line: octovox::script::Line, what: &str) {
        if let Err(err) = self.run_line(&line) {
            self.ui.error(format!("{what} refused: {err}"));
        }
    }

    /// Shows frame `frame` while playing or scrubbing: the editor's `frame
    /// N`, uploaded and drawn, but not recorded or journaled (`timeline`).
    fn show_frame(&mut self, frame: u32) {
        match self.doc.editor.play_frame(frame) {
            Ok(_) => {
                let upload = self.upload();
                self.readouts.stats.last_edit_bytes = Some(upload.bytes);
                self.readouts.stats.last_edit_ranges = upload.ranges;
                self.request_redraw();
            }
            Err(err) => self.ui.error(format!("frame {frame} refused: {err}")),
        }
    }

    /// Space, comma, period, K and Shift+K: play or pause, step a frame,
    /// key or unkey the object the timeline keys.
    fn timeline_key(&mut self, command: &AppCommand) {
        let Some(objects) = self.doc.editor.scene.objects() else {
            return self.ui.info("this scene is one model: it has no animation");
        };
        let shown = u32::try_from(objects.frame).unwrap_or(u32::MAX);
        let lines = match *command {
            AppCommand::TogglePlay => timeline::toggle(&mut self.ui.playback, shown).into_iter().collect(),
            AppCommand::StepFrame(by) => vec![octovox::script::Line::Frame(timeline::stepped(objects, shown, by))],
            AppCommand::Key(on) => {
                let line = if on {
                    octovox::script::ObjectLine::Key(self.ui.playback.ease)
                } else {
                    octovox::script::ObjectLine::Unkey
                };
                match timeline::key_lines(objects, line) {
                    Some(lines) => lines,
                    None => return self.ui.info("pick an object to key it"),
                }
            }
            _ => Vec::new(),
        };
        for line in lines {
            let word = line.word();
            self.act(line, word);
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
    fn after_change(&mut self, what: &str, record: impl Fn(&mut Recorder) -> std::io::Result<()>) {
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
    fn upload(&mut self) -> UploadStats {
        match &mut self.gfx {
            Some(gfx) => gfx.renderer.sync(&mut self.doc.editor.scene),
            // No device yet: the ranges stay dirty and go up with the first frame.
            None => UploadStats::default(),
        }
    }

    fn update_title(&self) {
        if let Some(gfx) = &self.gfx {
            gfx.window.set_title(&self.state.title(self.unsaved()));
        }
    }

    // ----- commands -----------------------------------------------------------

    /// Carries out one command. Panels, keys, the mouse and played replay
    /// scripts all end up here.
    fn execute(&mut self, command: AppCommand, event_loop: &ActiveEventLoop) {
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
            AppCommand::Turn { flip: true, .. } if self.state.mode == Mode::Object => {
                self.ui.info("an object turns (X, Y, Z) but does not flip");
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
                let height = self.gfx.as_ref().map_or(1, |g| g.config.height);
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
            AppCommand::New => self.guard_unsaved(Pending::New, event_loop),
            AppCommand::Open(path) => self.guard_unsaved(Pending::Open(path), event_loop),
            AppCommand::Quit => self.guard_unsaved(Pending::Quit, event_loop),
            AppCommand::Save => match self.state.path.clone() {
                Some(path) => {
                    self.save_document(&path, WriteOptions::default());
                }
                None => self.ask_path(DialogKind::SaveAs, "saves/untitled.vox".into()),
            },
            AppCommand::SaveAs(path) => self.save_as(path, WriteOptions::default(), event_loop),
            AppCommand::SaveOver(path) => self.save_as(path, WriteOptions::forced(true), event_loop),
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
            AppCommand::AskPalette { save } => {
                let kind = if save { DialogKind::SavePalette } else { DialogKind::LoadPalette };
                self.ask_path(kind, if save { "saves/palette.png".into() } else { String::new() });
            }
            AppCommand::Export(path) => self.export(&path),
            AppCommand::Screenshot => self.frames.screenshot_requested = true,
            AppCommand::Resolve(choice) => self.resolve(choice, event_loop),
            AppCommand::RecoverJournal(journal, checks) => self.recover_journal(&journal, checks),
            AppCommand::DiscardJournal(journal) => {
                let _ = std::fs::remove_file(journal);
            }
        }
        self.request_redraw();
    }

    /// Frames the box (the whole model, or the selection), centred in the
    /// part of the window that the side panel leaves free.
    fn frame_box(&mut self, bounds: Option<(IVec3, IVec3)>) {
        camera_control::frame_model(&mut self.state.camera, bounds);
        let (scale, height) =
            self.gfx.as_ref().map_or((1.0, self.args.size.1), |g| (g.window.scale_factor(), g.config.height));
        let (left, right) = self.side_panels();
        camera_control::pan(&mut self.state.camera, f64::from(left - right) * scale * 0.5, 0.0, height);
    }

    /// Widths in points of the panels at the window's left and right sides.
    fn side_panels(&self) -> (f32, f32) {
        let outliner = self.doc.editor.scene.pickable_objects().is_some();
        (ui::PANEL_WIDTH, if outliner { outliner::OUTLINER_WIDTH } else { 0.0 })
    }

    // ----- picking and mouse edits ---------------------------------------------------

    /// The render scale this frame traces at: the user's, lowered while the
    /// camera moves.
    fn render_scale(&self) -> f32 {
        self.state.settings.render_scale.clamp(octovox::settings::MIN_RENDER_SCALE, 1.0) * self.frames.motion.factor()
    }

    /// The window's size in physical pixels (the requested one before it opens).
    fn window_size(&self) -> (u32, u32) {
        self.gfx.as_ref().map_or(self.args.size, |g| (g.config.width, g.config.height))
    }

    /// The trace resolution for the current window size and render scale.
    fn trace_size(&self) -> (u32, u32) {
        let (w, h) = self.window_size();
        let scale = self.render_scale();
        (((w as f32 * scale).round() as u32).max(1), ((h as f32 * scale).round() as u32).max(1))
    }

    /// CPU pick of the voxel and face under window pixel (x, y), in world
    /// coordinates. Same ray as the GPU's pixel (window pixels map to trace
    /// pixels by the render scale; the panels sit over the image).
    /// A ray that gave up is an error, never "nothing under the cursor".
    fn pick_at(&self, x: f64, y: f64) -> Result<Option<Pick>, pick::GaveUp> {
        self.pick_pixel(x, y, false)
    }

    /// [`App::pick_at`], or where there is no voxel and the ground is on,
    /// the ground cell under y = 0 (value 0): what Attach, lines, selections
    /// and pastes start from in an empty scene.
    fn pick_or_ground(&self, x: f64, y: f64) -> Result<Option<Pick>, pick::GaveUp> {
        self.pick_pixel(x, y, self.doc.editor.ground)
    }

    fn pick_pixel(&self, x: f64, y: f64, ground: bool) -> Result<Option<Pick>, pick::GaveUp> {
        let (window_w, window_h) = self.window_size();
        let (w, h) = self.trace_size();
        if x < 0.0 || y < 0.0 || x >= f64::from(window_w) || y >= f64::from(window_h) {
            return Ok(None);
        }
        let px = ((x * f64::from(w) / f64::from(window_w)) as u32).min(w - 1);
        let py = ((y * f64::from(h) / f64::from(window_h)) as u32).min(h - 1);
        let hit = pick::pick_with_ground(&self.doc.editor.scene, &self.state.camera, (w, h), (px, py), ground)?;
        Ok(hit.map(|hit| Pick { voxel: hit.voxel, normal: hit.normal, value: hit.value }))
    }

    /// The voxel under window pixel (x, y) for a click; when there is none,
    /// `nothing` (or why the ray gave up) goes to the message line.
    fn pick_or_say(&mut self, x: f64, y: f64, nothing: &str) -> Option<Pick> {
        self.say_if_none(self.pick_at(x, y), nothing)
    }

    /// [`App::pick_or_say`] with the ground ([`App::pick_or_ground`]).
    fn pick_or_ground_or_say(&mut self, x: f64, y: f64, nothing: &str) -> Option<Pick> {
        self.say_if_none(self.pick_or_ground(x, y), nothing)
    }

    fn say_if_none(&mut self, picked: Result<Option<Pick>, pick::GaveUp>, nothing: &str) -> Option<Pick> {
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
    fn toggle_mode(&mut self, mode: Mode) {
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
    fn end_line(&mut self) -> Option<IVec3> {
        let start = self.gesture.line_start();
        if start.is_some() {
            self.gesture = Gesture::Idle;
        }
        start
    }

    /// Line mode: the press picks the start (in front of the face), the
    /// release the end; the brush is placed along the line as one step.
    fn line_edit(&mut self, phase: StrokePhase, x: f64, y: f64) {
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
    fn extrude_drag(&mut self, phase: StrokePhase, x: f64, y: f64) {
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
    fn extrude_layers(&self, x: f64, y: f64) -> Option<i32> {
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
    fn screen_steps(&self, face: glam::Vec3, normal: IVec3, start: (f64, f64), end: (f64, f64)) -> Option<i32> {
        drag::screen_steps(&self.view_basis(), face, normal, start, end)
    }

    /// The camera's rays over the whole window, tree-local.
    pub(super) fn view_basis(&self) -> octovox::camera::RayBasis {
        let (w, h) = self.window_size();
        self.state.camera.basis(w, h, self.doc.editor.scene.origin())
    }

    /// Measures the quality presets from the current camera (a second or
    /// so on lavapipe; the window waits meanwhile) and prints the result.
    fn measure_presets(&mut self) {
        let window = self.window_size();
        let Some(gfx) = &mut self.gfx else { return };
        match presets::measure(&mut gfx.renderer, &self.doc.editor.scene, &self.state.camera, window) {
            Ok(measured) => {
                let line: Vec<String> = presets::PRESETS
                    .iter()
                    .zip(&measured)
                    .map(|(p, m)| format!("{} {:.1} ms FLIP {:.3}", p.name, m.ms, m.flip))
                    .collect();
                report!("presets: {}", line.join("; "));
                self.readouts.presets_measured = Some(measured);
            }
            Err(err) => self.ui.error(format!("cannot measure the presets: {err}")),
        }
        self.request_redraw();
    }

    /// A palette change from the panel, as `rgb` and `material` lines (the
    /// parts that changed); changes while a control is held form one undo
    /// step, and so do the two lines of one change.
    fn palette_edit(&mut self, edit: Edit, dragging: bool) {
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

    fn pointer_edit(&mut self, phase: StrokePhase, tool: Tool, x: f64, y: f64) {
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
    fn stroke_step(&mut self, x: f64, y: f64) {
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
        let picked = self.doc.editor.object_line_at(pick.voxel).filter(|_| step.first);
        let ran = picked
            .map_or(Ok(()), |picked| self.run_line(&picked).map(|_| ()))
            .and_then(|()| self.run_line(&step.line).map(|_| ()));
        match ran {
            Ok(_) => self.with_stroke(|stroke| stroke.stepped(&step)),
            Err(err) => self.ui.error(format!("edit refused: {err}")),
        }
    }

    fn with_stroke(&mut self, f: impl FnOnce(&mut Stroke)) {
        if let Some(stroke) = self.gesture.stroke_mut() {
            f(stroke);
        }
    }
}

/// The palette index used most often is a better first colour than 1.
fn first_used_color(scene: &Scene) -> Option<u8> {
    let counts = scene.counts();
    counts.present().max_by_key(|v| counts.get(*v))
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.gfx.is_some() || self.fatal.is_some() {
            return;
        }
        match self.init_gfx(event_loop) {
            Ok(gfx) => {
                self.gfx = Some(gfx);
                // Whatever was built before the device existed goes up now.
                self.upload();
                self.request_redraw();
            }
            Err(err) => {
                self.fatal = Some(err);
                event_loop.exit();
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let Some(gfx) = &mut self.gfx else { return };
        if !matches!(event, WindowEvent::RedrawRequested) {
            log::trace!("window event {event:?}");
        }
        // Tab is object mode's key, not egui's focus step, unless a text
        // field has the keyboard or a dialog asks (its buttons take Tab).
        let asking = self.ui.prompt_open || self.ui.recover.is_some() || self.ui.replace.is_some();
        let to_egui = asking
            || self.ui.dialog.is_some()
            || gfx.egui_state.egui_ctx().egui_wants_keyboard_input()
            || !is_tab_key(&event);
        let response = if to_egui { gfx.egui_state.on_window_event(&gfx.window, &event) } else { Default::default() };
        if response.repaint && !matches!(event, WindowEvent::RedrawRequested) {
            self.frames.redraw_wanted.set(true);
            gfx.window.request_redraw();
        }
        match &event {
            WindowEvent::CloseRequested => {
                self.execute(AppCommand::Quit, event_loop);
                return;
            }
            WindowEvent::Resized(size) => {
                // Minimised windows report 0×0: keep the old configuration
                // and draw nothing until there is a size again.
                if size.width > 0 && size.height > 0 {
                    (gfx.config.width, gfx.config.height) = surface_size(*size, &gfx.renderer.gpu);
                    gfx.surface.configure(&gfx.renderer.gpu.device, &gfx.config);
                    self.frames.redraw_wanted.set(true);
                    gfx.window.request_redraw();
                }
                return;
            }
            WindowEvent::DroppedFile(path) => {
                self.execute(AppCommand::Open(path.clone()), event_loop);
                return;
            }
            WindowEvent::RedrawRequested => {
                let size = gfx.window.inner_size();
                if size.width > 0 && size.height > 0 && self.frames.redraw_wanted.take() {
                    self.frame(event_loop);
                }
                return;
            }
            _ => {}
        }
        // The prompt is modal: while it is open the scene gets no input. A
        // press or a wheel is egui's where egui drew in the last frame and
        // the scene's elsewhere, decided by the pointer's position: egui's
        // own verdict comes from the hover of the last frame, so a pointer
        // moved onto a button and pressed before the next frame reached the
        // scene behind it (issue 47, item 1), and one moved off the panel
        // onto the model lost its click. A wheel over the side panel is the
        // panel's even where egui lets it go (at the end of its scroll
        // range), never a zoom of the view.
        let starts = matches!(
            event,
            WindowEvent::MouseInput { state: winit::event::ElementState::Pressed, .. } | WindowEvent::MouseWheel { .. }
        );
        let consumed = match (starts, self.hover.view, self.input.cursor()) {
            (true, Some(view), Some(at)) => preview::ui_at(gfx.egui_state.egui_ctx(), view, at),
            // Before the first frame, and for releases, motion and keys:
            // egui's verdict.
            _ => response.consumed || (starts && self.hover.pointer_over_ui),
        } || self.ui.prompt_open;
        let extruding = matches!(self.gesture, Gesture::Extrude { .. });
        for command in self.input.on_event(&event, consumed, self.state.tool, extruding) {
            self.execute(command, event_loop);
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        match self.frames.next_repaint {
            Some(at) if at <= Instant::now() => {
                self.frames.next_repaint = None;
                self.request_redraw();
                event_loop.set_control_flow(ControlFlow::Wait);
            }
            Some(at) => event_loop.set_control_flow(ControlFlow::WaitUntil(at)),
            None => event_loop.set_control_flow(ControlFlow::Wait),
        }
    }
}

/// How frames reach the window. Mailbox where there is one: no tearing,
/// and no wait for a vertical blank (the window draws only when something
/// changed, so it never spins). On a CPU adapter (lavapipe), Immediate: its
/// frames are copied to the window whole, so they cannot tear, and its FIFO
/// held orbiting at 9–14 fps where Immediate gives 20–22 (docs/window.md).
/// Else FIFO, the vsync every adapter has. `--bench-frames` never waits.
fn present_mode(available: &[wgpu::PresentMode], cpu: bool, bench: bool) -> wgpu::PresentMode {
    use wgpu::PresentMode::{AutoNoVsync, AutoVsync, Immediate, Mailbox};
    if bench {
        AutoNoVsync
    } else if available.contains(&Mailbox) {
        Mailbox
    } else if cpu && available.contains(&Immediate) {
        Immediate
    } else {
        AutoVsync
    }
}

/// The surface size for a window size: never zero, and never larger than
/// the GPU's textures allow (wgpu panics past that); a window larger than
/// the limit shows the image stretched, with a warning.
fn surface_size(size: winit::dpi::PhysicalSize<u32>, gpu: &GpuContext) -> (u32, u32) {
    let limit = gpu.device.limits().max_texture_dimension_2d;
    if size.width > limit || size.height > limit {
        log::warn!("the window is {}x{}; this GPU draws at most {limit}x{limit}", size.width, size.height);
    }
    (size.width.clamp(1, limit), size.height.clamp(1, limit))
}

/// Whether `event` is a press or release of the Tab key.
fn is_tab_key(event: &WindowEvent) -> bool {
    use winit::keyboard::{KeyCode, PhysicalKey};
    matches!(event, WindowEvent::KeyboardInput { event, .. } if event.physical_key == PhysicalKey::Code(KeyCode::Tab))
}

#[cfg(test)]
mod tests {
    use super::present_mode;
    use wgpu::PresentMode::{AutoNoVsync, AutoVsync, Fifo, Immediate, Mailbox};

    #[test]
    fn frames_reach_the_window_without_waiting_for_a_blank_where_they_can() {
        assert_eq!(present_mode(&[Fifo, Mailbox, Immediate], false, false), Mailbox);
        assert_eq!(present_mode(&[Fifo, Immediate], true, false), Immediate, "a CPU adapter copies frames whole");
        assert_eq!(present_mode(&[Fifo, Immediate], false, false), AutoVsync, "a GPU without Mailbox would tear");
        assert_eq!(present_mode(&[Fifo], true, true), AutoNoVsync, "--bench-frames never waits");
    }
}
