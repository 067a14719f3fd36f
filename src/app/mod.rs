//! The sandbox window: winit `ApplicationHandler`, wgpu surface, the frame
//! (pool upload → trace → blit → egui → present), and `execute`, the one
//! place every command — mouse, keyboard, panel, later replay — is carried out.

/// Prints one status line on stdout (`edit: …`, `saved: …`, `octovox: ready`;
/// tests and scripts read them). A closed stdout is not an error worth dying for.
macro_rules! report {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}

mod camera_control;
mod capture;
mod command;
mod input;
mod script;
mod state;
mod ui;

use std::cell::Cell;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::mpsc::{self, Receiver, TryRecvError};
use std::time::{Duration, Instant};

use anyhow::Context as _;
use glam::IVec3;
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::window::{Window, WindowId};

use octovox::camera::Camera;
use octovox::edit::{Edit, History};
use octovox::gpu::scene_buffers::UploadStats;
use octovox::gpu::timer::PassTimer;
use octovox::gpu::{BlitPass, FrameUniforms, GpuContext, SceneBuffers, TracePass};
use octovox::scene::Scene;
use octovox::settings::TraceMode;
use octovox::trace::grid::DenseGrid;
use octovox::trace::svo;

use crate::cli::WindowArgs;
pub use command::{Choice, Command, Pending, StrokePhase};
use input::Input;
use state::{EditorState, Pick, Tool};
use ui::{DialogKind, Stats, UiState};

/// Where Screenshot writes, relative to the working directory.
const SCREENSHOT_DIR: &str = "saves";

/// Opens the window and runs until it is closed.
pub fn run(args: WindowArgs) -> anyhow::Result<ExitCode> {
    let event_loop = EventLoop::new().context("cannot open a window (is DISPLAY or WAYLAND_DISPLAY set?)")?;
    let instance = GpuContext::window_instance(Box::new(event_loop.owned_display_handle()));
    let mut app = App::new(args, instance);
    event_loop.run_app(&mut app).context("the event loop failed")?;
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
    gpu: GpuContext,
    buffers: SceneBuffers,
    trace: TracePass,
    blit: BlitPass,
    timer: PassTimer,
    egui_state: egui_winit::State,
    egui_renderer: egui_wgpu::Renderer,
    textures_to_free: Vec<egui::TextureId>,
}

/// A .vox being read on a background thread.
struct Loading {
    path: PathBuf,
    started: Instant,
    result: Receiver<Result<Scene, String>>,
}

/// An open mouse stroke: its tool, the face (normal and layer) it started
/// on, and the last brush centre applied.
struct Stroke {
    tool: Tool,
    plane: Option<(IVec3, i32)>,
    last_center: Option<IVec3>,
}

/// `--bench-frames`: frames left and the measurements so far.
struct Bench {
    left: u32,
    total: u32,
    started: Option<Instant>,
    trace_ms: f64,
}

struct App {
    instance: Option<wgpu::Instance>,
    args: WindowArgs,
    gfx: Option<Gfx>,
    scene: Scene,
    history: History,
    state: EditorState,
    ui: UiState,
    input: Input,
    stats: Stats,
    pick: Option<Pick>,
    pointer_over_ui: bool,
    stroke: Option<Stroke>,
    loading: Option<Loading>,
    grid_stale: bool,
    screenshot_requested: bool,
    ready: bool,
    last_frame: Option<Instant>,
    next_repaint: Option<Instant>,
    /// A frame was asked for since the last one (see `request_redraw`).
    redraw_wanted: Cell<bool>,
    bench: Option<Bench>,
    fatal: Option<anyhow::Error>,
    /// `--replay`: the script being played.
    player: Option<script::Player>,
    /// `--record`: where the session is written as a script.
    recorder: Option<octovox::replay::Recorder>,
    /// Where the next screenshot goes (a script's `render PATH`), else `saves/`.
    screenshot_path: Option<PathBuf>,
}

impl App {
    fn new(args: WindowArgs, instance: wgpu::Instance) -> App {
        let mut app = App {
            instance: Some(instance),
            gfx: None,
            scene: Scene::default(),
            history: History::default(),
            state: EditorState::default(),
            ui: UiState::default(),
            input: Input::default(),
            stats: Stats::default(),
            pick: None,
            pointer_over_ui: false,
            stroke: None,
            loading: None,
            grid_stale: true,
            screenshot_requested: false,
            ready: false,
            last_frame: None,
            next_repaint: None,
            redraw_wanted: Cell::new(true),
            bench: args.bench_frames.map(|n| Bench { left: n.max(1), total: n.max(1), started: None, trace_ms: 0.0 }),
            fatal: None,
            player: None,
            recorder: None,
            screenshot_path: None,
            args,
        };
        app.open_script_files();
        app.state.settings.render_scale = app.args.render_scale.clamp(0.25, 1.0);
        app.state.settings.shadows = !app.args.no_shadows;
        if let Some((eye, target)) = app.args.camera {
            app.state.camera = Camera { eye, target, fov_y_deg: app.state.camera.fov_y_deg };
        }
        match app.args.file.clone() {
            Some(path) => app.start_loading(path),
            None => {
                app.replace_scene(octovox::scene::demo::demo_scene(), None);
                if app.args.camera.is_none() {
                    app.frame_model();
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
            .with_title(self.state.title())
            .with_inner_size(winit::dpi::PhysicalSize::new(width, height));
        let window = Arc::new(event_loop.create_window(attributes).context("cannot create the window")?);
        let surface = instance.create_surface(window.clone()).context("cannot create a surface for the window")?;
        let gpu = pollster::block_on(GpuContext::with_instance(instance, Some(&surface)))?;
        let size = window.inner_size();
        let mut config = surface
            .get_default_config(&gpu.adapter, size.width.max(1), size.height.max(1))
            .context("the GPU cannot present to this window")?;
        let caps = surface.get_capabilities(&gpu.adapter);
        // egui-wgpu wants a non-sRGB target; the trace output is already sRGB-encoded.
        if let Some(format) = caps.formats.iter().copied().find(|f| !f.is_srgb()) {
            config.format = format;
        }
        let can_copy_frame = caps.usages.contains(wgpu::TextureUsages::COPY_SRC);
        if can_copy_frame {
            config.usage |= wgpu::TextureUsages::COPY_SRC;
        }
        config.present_mode =
            if self.bench.is_some() { wgpu::PresentMode::AutoNoVsync } else { wgpu::PresentMode::AutoVsync };
        surface.configure(&gpu.device, &config);
        let buffers = SceneBuffers::new(&gpu.device);
        let trace = TracePass::new(&gpu, &buffers, config.width, config.height)?;
        let blit = BlitPass::new(&gpu, config.format)?;
        let timer = PassTimer::new(&gpu);
        let egui_state = egui_winit::State::new(
            egui::Context::default(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            window.theme(),
            Some(gpu.device.limits().max_texture_dimension_2d as usize),
        );
        let egui_renderer = egui_wgpu::Renderer::new(&gpu.device, config.format, egui_wgpu::RendererOptions::default());
        log::info!("window on {} ({:?}, {}x{})", gpu.adapter_name, config.format, config.width, config.height);
        Ok(Gfx {
            window,
            surface,
            config,
            can_copy_frame,
            gpu,
            buffers,
            trace,
            blit,
            timer,
            egui_state,
            egui_renderer,
            textures_to_free: Vec::new(),
        })
    }

    /// Asks for a frame. Only frames asked for here are drawn: on X11 with
    /// lavapipe every present comes back as another `RedrawRequested`, and
    /// drawing those would keep two cores busy with an unchanged picture.
    fn request_redraw(&self) {
        if let Some(gfx) = &self.gfx {
            self.redraw_wanted.set(true);
            gfx.window.request_redraw();
        }
    }

    // ----- the one path for changes: edit → history → octree → upload ------------

    /// Applies an edit the way every edit is applied: `History::apply` on the
    /// octree, then the pool's dirty ranges go to the GPU.
    pub fn apply_edit(&mut self, edit: Edit) -> bool {
        match self.history.apply(&mut self.scene.tree, edit) {
            Ok(()) => {
                self.after_change("edit");
                true
            }
            Err(err) => {
                self.ui.error(format!("edit refused: {err}"));
                false
            }
        }
    }

    /// Sends what changed to the GPU and refreshes everything that depends on
    /// the voxels. Prints `WHAT: N bytes written` (the e2e test reads it).
    fn after_change(&mut self, what: &str) {
        let upload = self.upload();
        self.stats.last_edit_bytes = upload.bytes;
        self.stats.last_edit_ranges = upload.ranges;
        report!(
            "{what}: {} bytes written in {} ranges{}",
            upload.bytes,
            upload.ranges,
            if upload.grew { " (buffer grew)" } else { "" }
        );
        self.state.dirty = true;
        self.grid_stale = true;
        self.update_title();
        self.request_redraw();
    }

    /// Flushes the pool's dirty ranges (only those) to the GPU buffers.
    fn upload(&mut self) -> UploadStats {
        match &mut self.gfx {
            Some(gfx) => gfx.buffers.upload_pool(&gfx.gpu.device, &gfx.gpu.queue, &mut self.scene.tree),
            // No device yet: the ranges stay dirty and go up with the first frame.
            None => UploadStats::default(),
        }
    }

    /// Puts a new scene in place (load, New, start-up) and uploads it whole.
    fn replace_scene(&mut self, scene: Scene, path: Option<PathBuf>) {
        let line = match &path {
            Some(path) => octovox::replay::Command::Load(std::fs::canonicalize(path).unwrap_or_else(|_| path.clone())),
            None if scene.tree.solid_voxels() == 0 => octovox::replay::Command::New,
            None => octovox::replay::Command::Demo,
        };
        self.record(|r| r.scene(line));
        self.scene = scene;
        self.history.clear();
        self.stroke = None;
        // An imported mesh has no .vox to save back to: Save asks for one
        // rather than writing .vox bytes over the .obj.
        self.state.path = path.filter(|p| !octovox::io::is_mesh_path(p));
        self.state.dirty = false;
        self.state.color = first_used_color(&self.scene).unwrap_or(self.state.color);
        self.grid_stale = true;
        if let Some(gfx) = &self.gfx {
            gfx.buffers.upload_palette(&gfx.gpu.queue, &self.scene.palette);
        }
        let upload = self.upload();
        log::info!("scene uploaded: {} bytes", upload.bytes);
        self.update_title();
        self.request_redraw();
    }

    fn update_title(&self) {
        if let Some(gfx) = &self.gfx {
            gfx.window.set_title(&self.state.title());
        }
    }

    // ----- commands -----------------------------------------------------------

    /// Carries out one command. Panels, keys, the mouse and (later) replay
    /// scripts all end up here.
    fn execute(&mut self, command: Command, event_loop: &ActiveEventLoop) {
        let busy_loading = self.loading.is_some();
        match command {
            Command::Edit(edit) if !busy_loading => {
                self.apply_edit(edit);
            }
            Command::PointerEdit { phase, tool, x, y } if !busy_loading => self.pointer_edit(phase, tool, x, y),
            Command::Undo if !busy_loading => match self.history.undo(&mut self.scene.tree) {
                Ok(true) => {
                    self.record(|r| r.undo());
                    self.after_change("undo");
                }
                Ok(false) => self.ui.info("nothing to undo"),
                Err(err) => self.ui.error(format!("undo failed: {err}")),
            },
            Command::Redo if !busy_loading => match self.history.redo(&mut self.scene.tree) {
                Ok(true) => {
                    self.record(|r| r.redo());
                    self.after_change("redo");
                }
                Ok(false) => self.ui.info("nothing to redo"),
                Err(err) => self.ui.error(format!("redo failed: {err}")),
            },
            Command::Edit(_) | Command::PointerEdit { .. } | Command::Undo | Command::Redo => {
                self.ui.info("still loading…");
            }
            Command::SetTool(tool) => self.state.tool = tool,
            Command::SetCamera(camera) => self.state.camera = camera,
            Command::Orbit { dx, dy } => camera_control::orbit(&mut self.state.camera, dx, dy),
            Command::Pan { dx, dy } => {
                let height = self.gfx.as_ref().map_or(1, |g| g.config.height);
                camera_control::pan(&mut self.state.camera, dx, dy, height);
            }
            Command::Zoom { steps } => camera_control::zoom(&mut self.state.camera, steps),
            Command::FrameModel => self.frame_model(),
            Command::New => self.guard_unsaved(Pending::New, event_loop),
            Command::Open(path) => self.guard_unsaved(Pending::Open(path), event_loop),
            Command::Quit => self.guard_unsaved(Pending::Quit, event_loop),
            Command::Save => match self.state.path.clone() {
                Some(path) => {
                    self.save(&path);
                }
                None => self.ui.dialog = Some((DialogKind::SaveAs, "saves/untitled.vox".into())),
            },
            Command::SaveAs(path) => {
                if self.save(&path) {
                    self.state.path = Some(path);
                    self.update_title();
                    // A prompt that asked for a path to save to can now go on.
                    if let Some(pending) = self.ui.pending.take() {
                        self.perform(pending, event_loop);
                    }
                }
            }
            Command::AskOpen => {
                let start = self.state.path.as_ref().map(|p| p.display().to_string()).unwrap_or_default();
                self.ui.dialog = Some((DialogKind::Open, start));
            }
            Command::AskSaveAs => {
                let start = self.state.path.as_ref().map_or("saves/untitled.vox".into(), |p| p.display().to_string());
                self.ui.dialog = Some((DialogKind::SaveAs, start));
            }
            Command::Screenshot => self.screenshot_requested = true,
            Command::Resolve(choice) => self.resolve(choice, event_loop),
        }
        self.request_redraw();
    }

    /// Runs `action` now, or first asks about unsaved changes.
    fn guard_unsaved(&mut self, action: Pending, event_loop: &ActiveEventLoop) {
        if self.state.dirty {
            self.ui.pending = Some(action);
            self.ui.prompt_open = true;
        } else {
            self.perform(action, event_loop);
        }
    }

    fn resolve(&mut self, choice: Choice, event_loop: &ActiveEventLoop) {
        self.ui.prompt_open = false;
        let Some(pending) = self.ui.pending.take() else { return };
        match choice {
            Choice::Cancel => {}
            Choice::Discard => self.perform(pending, event_loop),
            Choice::Save => match self.state.path.clone() {
                Some(path) => {
                    if self.save(&path) {
                        self.perform(pending, event_loop);
                    }
                }
                None => {
                    // Ask for a path; SaveAs carries on with the pending action.
                    self.ui.pending = Some(pending);
                    self.ui.dialog = Some((DialogKind::SaveAs, "saves/untitled.vox".into()));
                }
            },
        }
    }

    fn perform(&mut self, action: Pending, event_loop: &ActiveEventLoop) {
        match action {
            Pending::New => {
                self.replace_scene(Scene::default(), None);
                self.state.camera = Camera { fov_y_deg: self.state.camera.fov_y_deg, ..Camera::default() };
                // A lone voxel to attach to: an empty scene gives the mouse nothing to hit.
                let color = self.state.color.max(1);
                if let Err(err) = self
                    .scene
                    .tree
                    .apply_brush(&octovox::scene::Shape::Voxel(IVec3::ZERO), octovox::scene::Op::Place(color))
                {
                    self.ui.error(format!("cannot seed the new scene: {err}"));
                }
                self.record(|r| r.seed(color, IVec3::ZERO));
                self.upload();
                self.state.dirty = false;
                camera_control::frame_model(&mut self.state.camera, Some((IVec3::splat(-4), IVec3::splat(4))));
            }
            Pending::Open(path) => self.start_loading(path),
            Pending::Quit => event_loop.exit(),
        }
    }

    /// Saves atomically; reports the outcome in the UI and on stdout.
    fn save(&mut self, path: &Path) -> bool {
        match octovox::io::save_scene(path, &self.scene) {
            Ok(()) => {
                report!("saved: {}", path.display());
                self.state.dirty = false;
                self.ui.info(format!("saved {}", path.display()));
                self.update_title();
                true
            }
            Err(err) => {
                self.ui.error(format!("save failed: {err}"));
                false
            }
        }
    }

    /// Reads a .vox (or voxelizes an .obj) on a background thread; the
    /// window keeps drawing.
    fn start_loading(&mut self, path: PathBuf) {
        let (tx, rx) = mpsc::channel();
        let thread_path = path.clone();
        let spawned = std::thread::Builder::new().name("vox loader".into()).spawn(move || {
            let result = octovox::io::load_scene(&thread_path, 0).map_err(|e| e.to_string());
            // The window may have closed meanwhile; then nobody wants the scene.
            let _ = tx.send(result);
        });
        match spawned {
            Ok(_) => self.loading = Some(Loading { path, started: Instant::now(), result: rx }),
            Err(err) => self.ui.error(format!("cannot start loading: {err}")),
        }
        self.request_redraw();
    }

    fn poll_loading(&mut self) {
        let Some(loading) = &self.loading else { return };
        let result = match loading.result.try_recv() {
            Ok(result) => result,
            Err(TryRecvError::Empty) => return,
            Err(TryRecvError::Disconnected) => Err("the loader thread stopped".to_string()),
        };
        let Some(loading) = self.loading.take() else { return };
        match result {
            Ok(scene) => {
                let seconds = loading.started.elapsed().as_secs_f64();
                report!("loaded: {} ({} voxels, {seconds:.2} s)", loading.path.display(), scene.tree.solid_voxels());
                self.replace_scene(scene, Some(loading.path.clone()));
                // A camera from the command line wins for the file it came with.
                let keep_camera = self.args.camera.is_some() && self.args.file.as_ref() == Some(&loading.path);
                if !keep_camera {
                    self.frame_model();
                }
                self.ui.info(format!("opened {}", loading.path.display()));
            }
            Err(err) => self.ui.error(format!("cannot open {}: {err}", loading.path.display())),
        }
    }

    /// Frames the whole model, centred in the part of the window that the
    /// side panel leaves free.
    fn frame_model(&mut self) {
        camera_control::frame_model(&mut self.state.camera, self.scene.tree.solid_bounds());
        let (scale, height) =
            self.gfx.as_ref().map_or((1.0, self.args.size.1), |g| (g.window.scale_factor(), g.config.height));
        camera_control::pan(&mut self.state.camera, f64::from(ui::PANEL_WIDTH) * scale * 0.5, 0.0, height);
    }

    // ----- picking and mouse edits ---------------------------------------------------

    /// The trace resolution for the current window size and render scale.
    fn trace_size(&self) -> (u32, u32) {
        let (w, h) = self.gfx.as_ref().map_or(self.args.size, |g| (g.config.width, g.config.height));
        let scale = self.state.settings.render_scale.clamp(0.25, 1.0);
        (((w as f32 * scale).round() as u32).max(1), ((h as f32 * scale).round() as u32).max(1))
    }

    /// CPU pick of the voxel and face under window pixel (x, y), in world
    /// coordinates. Same ray as the GPU's pixel (window pixels map to trace
    /// pixels by the render scale; the panels sit over the image).
    fn pick_at(&self, x: f64, y: f64) -> Option<Pick> {
        let (window_w, window_h) = self.gfx.as_ref().map_or(self.args.size, |g| (g.config.width, g.config.height));
        let (w, h) = self.trace_size();
        if x < 0.0 || y < 0.0 || x >= f64::from(window_w) || y >= f64::from(window_h) {
            return None;
        }
        let px = ((x * f64::from(w) / f64::from(window_w)) as u32).min(w - 1);
        let py = ((y * f64::from(h) / f64::from(window_h)) as u32).min(h - 1);
        let hit = svo::pick(&self.scene.tree, &self.state.camera, (w, h), px, py)?;
        Some(Pick { voxel: hit.voxel, normal: hit.normal, value: hit.value })
    }

    fn pointer_edit(&mut self, phase: StrokePhase, tool: Tool, x: f64, y: f64) {
        match phase {
            StrokePhase::Begin => {
                self.history.begin_stroke();
                self.stroke = Some(Stroke { tool, plane: None, last_center: None });
                self.stroke_step(x, y);
            }
            StrokePhase::Move => self.stroke_step(x, y),
            StrokePhase::End => {
                self.history.end_stroke();
                self.stroke = None;
                self.record(|r| {
                    r.end_step();
                    Ok(())
                });
            }
            StrokePhase::Click => {
                self.pointer_edit(StrokePhase::Begin, tool, x, y);
                self.pointer_edit(StrokePhase::End, tool, x, y);
            }
        }
    }

    /// One brush application of the open stroke at (x, y), if it lands on a
    /// new cell of the stroke's layer.
    fn stroke_step(&mut self, x: f64, y: f64) {
        let Some(stroke) = &self.stroke else { return };
        let Some(pick) = self.pick_at(x, y) else { return };
        if stroke.tool == Tool::Attach && pick.normal == IVec3::ZERO {
            return; // the camera is inside a voxel: no face to attach to
        }
        let layer = (pick.normal, pick.voxel.dot(pick.normal));
        // Attach and Erase strokes stay on the face they started on, within
        // the brush's reach of its layer: the cells they reveal or create
        // would otherwise be picked next and the stroke would dig or pile up
        // toward the camera.
        let reach = self.state.brush().reach();
        let off_layer = |(normal, depth): (IVec3, i32)| normal != layer.0 || (layer.1 - depth).abs() > reach;
        if stroke.tool != Tool::Paint && stroke.plane.is_some_and(off_layer) {
            return;
        }
        let (center, edit) = self.state.edit_at(stroke.tool, &pick);
        if stroke.last_center == Some(center) {
            return;
        }
        let tool = stroke.tool;
        if self.apply_edit(edit)
            && let Some(stroke) = &mut self.stroke
        {
            stroke.plane.get_or_insert(layer);
            stroke.last_center = Some(center);
            let (camera, brush, color) = (self.state.camera, self.state.brush(), self.state.color.max(1));
            self.record(|r| r.edit(&camera, brush, color, tool, center));
        }
    }

    // ----- the frame ------------------------------------------------------------

    /// One frame, top to bottom: background load, camera fly, panels and their
    /// commands, hover pick, trace, blit, egui, present.
    fn frame(&mut self, event_loop: &ActiveEventLoop) {
        let started = Instant::now();
        let seconds = self.last_frame.map_or(0.0, |t| started.duration_since(t).as_secs_f64().min(0.1));
        if let Some(last) = self.last_frame {
            let interval = started.duration_since(last).as_secs_f64();
            if interval < 1.0 {
                let fps = 1.0 / interval.max(1e-6);
                self.stats.fps = if self.stats.fps == 0.0 { fps } else { self.stats.fps * 0.9 + fps * 0.1 };
            }
        }
        self.last_frame = Some(started);

        self.poll_loading();
        if self.ready {
            self.play_step(event_loop);
        }
        if let Some(dir) = self.input.fly_direction() {
            camera_control::fly(&mut self.state.camera, dir, seconds);
        }

        // Panels first: they may change settings and produce commands.
        let Some(gfx) = &mut self.gfx else { return };
        let raw_input = gfx.egui_state.take_egui_input(&gfx.window);
        let ctx = gfx.egui_state.egui_ctx().clone();
        let loading = self.loading.as_ref().map(|l| (l.path.clone(), l.started.elapsed().as_secs_f64()));
        let mut commands = Vec::new();
        let full = {
            let info = ui::Info {
                palette: &self.scene.palette,
                tree: &self.scene.tree,
                stats: &self.stats,
                adapter: &gfx.gpu.adapter_name,
                timestamps: gfx.gpu.timestamps,
                loading: loading.as_ref().map(|(p, s)| (p.as_path(), *s)),
                can_undo: self.history.can_undo(),
                can_redo: self.history.can_redo(),
            };
            let (state, ui_state) = (&mut self.state, &mut self.ui);
            let pick = self.pick;
            ctx.run_ui(raw_input, |ui| {
                commands = ui::show(ui, state, ui_state, &info);
                if let Some(pick) = pick {
                    ui::draw_brush_outline(ui, state, &pick, &info);
                }
            })
        };
        self.pointer_over_ui = ctx.is_pointer_over_egui();
        gfx.egui_state.handle_platform_output(&gfx.window, full.platform_output);
        let repaint_delay = full.viewport_output.get(&egui::ViewportId::ROOT).map(|v| v.repaint_delay);
        if !commands.is_empty() {
            log::debug!("panel commands {commands:?}");
        }
        for command in commands {
            self.execute(command, event_loop);
        }

        // Hover pick: what a click would edit, highlighted before any click.
        self.pick = match self.input.cursor() {
            Some((x, y)) if !self.pointer_over_ui && self.loading.is_none() => self.pick_at(x, y),
            _ => None,
        };
        self.sync_grid();

        let trace_size = self.trace_size();
        let Some(gfx) = &mut self.gfx else { return };
        let prims = ctx.tessellate(full.shapes, full.pixels_per_point);
        // Textures are uploaded before the swapchain image is acquired, so a
        // skipped frame never loses them.
        let mut textures = full.textures_delta;
        for (id, deltas) in textures.set.drain() {
            for delta in deltas {
                gfx.egui_renderer.update_texture(&gfx.gpu.device, &gfx.gpu.queue, id, &delta);
            }
        }
        // Freed only after a frame that no longer uses them was submitted.
        gfx.textures_to_free.extend(textures.free.drain());
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [gfx.config.width, gfx.config.height],
            pixels_per_point: full.pixels_per_point,
        };

        // Trace.
        let tree = &self.scene.tree;
        gfx.trace.resize(&gfx.gpu.device, &gfx.buffers, trace_size.0, trace_size.1);
        let basis = self.state.camera.basis(trace_size.0, trace_size.1, tree.origin());
        let highlight = self.pick.map(|pick| {
            let (lo, hi) = self.state.preview_box(&pick);
            (lo - tree.origin(), hi - tree.origin())
        });
        let uniforms = FrameUniforms::new(&basis, tree, &gfx.buffers, self.state.settings.view, highlight);
        gfx.trace.prepare(&gfx.gpu.device, &gfx.gpu.queue, &gfx.buffers, &uniforms);
        let mut encoder =
            gfx.gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("trace") });
        gfx.trace.encode(&mut encoder, &self.state.settings, gfx.timer.pass_writes());
        gfx.timer.resolve(&mut encoder);
        match gfx.timer.submit_and_measure(&gfx.gpu, encoder) {
            Ok(ms) => self.stats.trace_ms = ms,
            Err(err) => log::warn!("trace timing failed: {err}"),
        }

        // Blit + egui onto the swapchain image.
        let frame = match gfx.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(frame) | wgpu::CurrentSurfaceTexture::Suboptimal(frame) => frame,
            wgpu::CurrentSurfaceTexture::Outdated => {
                log::debug!("surface outdated; reconfiguring");
                gfx.surface.configure(&gfx.gpu.device, &gfx.config);
                self.redraw_wanted.set(true);
                gfx.window.request_redraw();
                return;
            }
            wgpu::CurrentSurfaceTexture::Lost => {
                // A lost surface must be made again; if that fails too, keep
                // the old one and retry on the next frame.
                log::warn!("surface lost; creating it again");
                match gfx.gpu.instance.create_surface(gfx.window.clone()) {
                    Ok(surface) => gfx.surface = surface,
                    Err(err) => log::error!("cannot re-create the surface: {err}"),
                }
                gfx.surface.configure(&gfx.gpu.device, &gfx.config);
                self.redraw_wanted.set(true);
                gfx.window.request_redraw();
                return;
            }
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => {
                log::debug!("surface timeout or occluded; skipping the frame");
                self.redraw_wanted.set(true);
                gfx.window.request_redraw();
                return;
            }
            wgpu::CurrentSurfaceTexture::Validation => {
                log::error!("surface validation error; reconfiguring");
                gfx.surface.configure(&gfx.gpu.device, &gfx.config);
                return;
            }
        };
        let view = frame.texture.create_view(&wgpu::TextureViewDescriptor::default());
        gfx.blit.prepare(&gfx.gpu.device, gfx.trace.output_view());
        let mut encoder =
            gfx.gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("present") });
        gfx.blit.encode(&mut encoder, &view);
        let user_buffers =
            gfx.egui_renderer.update_buffers(&gfx.gpu.device, &gfx.gpu.queue, &mut encoder, &prims, &screen);
        {
            let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("egui"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &view,
                    resolve_target: None,
                    depth_slice: None,
                    ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            gfx.egui_renderer.render(&mut pass.forget_lifetime(), &prims, &screen);
        }
        let window_copy = (self.screenshot_requested && gfx.can_copy_frame)
            .then(|| capture::copy_frame(gfx, &mut encoder, &frame.texture));
        gfx.gpu.queue.submit(user_buffers.into_iter().chain([encoder.finish()]));
        gfx.window.pre_present_notify();
        gfx.gpu.queue.present(frame);
        for id in std::mem::take(&mut gfx.textures_to_free) {
            gfx.egui_renderer.free_texture(&id);
        }

        if std::mem::take(&mut self.screenshot_requested) {
            self.save_screenshot(window_copy);
        }
        self.stats.frame_ms = started.elapsed().as_secs_f64() * 1e3;
        if !self.ready && self.loading.is_none() {
            self.ready = true;
            let (w, h) = self.gfx.as_ref().map_or((0, 0), |g| (g.config.width, g.config.height));
            report!("octovox: ready {w}x{h}");
        }
        self.bench_step(event_loop);

        // Keep drawing while something moves; otherwise wait for input.
        let animating = self.loading.is_some()
            || self.input.fly_direction().is_some()
            || self.bench.is_some()
            || self.player.is_some();
        self.next_repaint = match repaint_delay {
            _ if animating => Some(Instant::now()),
            Some(delay) if delay < Duration::from_secs(5) => Some(Instant::now() + delay),
            _ => None,
        };
    }

    /// Rebuilds and uploads the dense grid while grid mode is on and the voxels changed.
    fn sync_grid(&mut self) {
        if self.state.settings.mode != TraceMode::Grid || !self.grid_stale {
            return;
        }
        let Some(gfx) = &mut self.gfx else { return };
        match DenseGrid::from_octree(&self.scene.tree) {
            Some(grid) => {
                gfx.buffers.upload_grid(&gfx.gpu.device, &gfx.gpu.queue, &grid);
                self.grid_stale = false;
            }
            None => {
                self.state.settings.mode = TraceMode::Svo;
                self.ui.error("the scene is too wide for a dense grid; back to SVO");
            }
        }
    }
}

/// The palette index used most often is a better first colour than 1.
fn first_used_color(scene: &Scene) -> Option<u8> {
    let mut counts = [0u64; 256];
    scene.tree.for_each_solid_cell(|_, size, value| counts[usize::from(value)] += 1u64 << (3 * size.trailing_zeros()));
    (1..=255u8).max_by_key(|v| counts[usize::from(*v)]).filter(|v| counts[usize::from(*v)] > 0)
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.gfx.is_some() || self.fatal.is_some() {
            return;
        }
        match self.init_gfx(event_loop) {
            Ok(gfx) => {
                gfx.buffers.upload_palette(&gfx.gpu.queue, &self.scene.palette);
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
        let response = gfx.egui_state.on_window_event(&gfx.window, &event);
        if response.repaint && !matches!(event, WindowEvent::RedrawRequested) {
            self.redraw_wanted.set(true);
            gfx.window.request_redraw();
        }
        match &event {
            WindowEvent::CloseRequested => {
                self.execute(Command::Quit, event_loop);
                return;
            }
            WindowEvent::Resized(size) => {
                // Minimised windows report 0×0: keep the old configuration
                // and draw nothing until there is a size again.
                if size.width > 0 && size.height > 0 {
                    gfx.config.width = size.width;
                    gfx.config.height = size.height;
                    gfx.surface.configure(&gfx.gpu.device, &gfx.config);
                    self.redraw_wanted.set(true);
                    gfx.window.request_redraw();
                }
                return;
            }
            WindowEvent::DroppedFile(path) => {
                self.execute(Command::Open(path.clone()), event_loop);
                return;
            }
            WindowEvent::RedrawRequested => {
                let size = gfx.window.inner_size();
                if size.width > 0 && size.height > 0 && self.redraw_wanted.take() {
                    self.frame(event_loop);
                }
                return;
            }
            _ => {}
        }
        // The prompt is modal: while it is open the scene gets no input.
        let consumed = response.consumed || self.ui.prompt_open;
        for command in self.input.on_event(&event, consumed, self.state.tool) {
            self.execute(command, event_loop);
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        match self.next_repaint {
            Some(at) if at <= Instant::now() => {
                self.next_repaint = None;
                self.request_redraw();
                event_loop.set_control_flow(ControlFlow::Wait);
            }
            Some(at) => event_loop.set_control_flow(ControlFlow::WaitUntil(at)),
            None => event_loop.set_control_flow(ControlFlow::Wait),
        }
    }
}
