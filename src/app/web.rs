//! The browser shell: eframe's web runner on WebGPU around the same
//! editing session as the desktop window (docs/web.md). The page's canvas
//! shows the scene as the desktop's window does: egui's panels over the
//! trace, which the one renderer draws each frame into a texture the size
//! of the canvas. Input goes through the same table (`input`), panels and
//! trace through the same code (`drawing`); files through the page's
//! (`files`). What the page cannot do yet (what must wait for the GPU: the
//! preset measurement, a script's renders; screenshots) it says where it
//! is asked.

mod events;
mod files;

use std::cell::RefCell;

use wasm_bindgen::JsCast as _;
use web_time::Instant;

use octovox::gpu::{BlitMode, BlitPass, GpuContext, Renderer};

use super::drawing::{self, FrameFacts};
use super::frame_bench::Bench;
use super::gesture::Gesture;
use super::input::{Input, InputEvent};
use super::motion::{FrameTimes, MotionScale};
use super::session::Session;
use super::{AppCommand, camera_control, preview, slow_clicks};
use crate::cli::{Cli, WindowArgs};

/// The canvas the page gives the editor, and the line that says how the
/// start goes (web/index.html).
const CANVAS_ID: &str = "octovox";
const STATUS_ID: &str = "status";

/// The scene's texture: the blit writes the trace's sRGB-encoded bytes
/// as they are, which is what egui's textures hold (gamma-encoded
/// `Rgba8Unorm`).
const SCENE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

thread_local! {
    /// The running page: kept for as long as the page lives.
    static RUNNER: RefCell<Option<eframe::WebRunner>> = const { RefCell::new(None) };
}

/// Starts the editor in the page's canvas; a browser without WebGPU, or a
/// start that fails, gets a message in the page instead of a blank canvas.
pub fn start() {
    // A second logger (a reload in the same module) is not an error.
    let _ = eframe::WebLogger::init(log::LevelFilter::Info);
    wasm_bindgen_futures::spawn_local(async {
        match run().await {
            Ok(()) => set_status(None),
            Err(message) => {
                log::error!("octovox: {message}");
                set_status(Some(&message));
            }
        }
    });
}

async fn run() -> Result<(), String> {
    let document = web_sys::window().and_then(|w| w.document()).ok_or("the page has no document")?;
    let canvas = document
        .get_element_by_id(CANVAS_ID)
        .and_then(|e| e.dyn_into::<web_sys::HtmlCanvasElement>().ok())
        .ok_or_else(|| format!("the page has no canvas #{CANVAS_ID}"))?;
    if !has_webgpu_adapter().await {
        return Err("This browser offers no WebGPU, which octovox draws with (it is missing, turned off, or \
                    no GPU can serve it). Chrome and Edge 113 or later and Firefox 141 or later on Windows \
                    have it; on Linux, Chrome needs --enable-unsafe-webgpu. The desktop build runs on \
                    Vulkan: see the README."
            .into());
    }
    let (args, open) = args_from_query()?;
    let runner = eframe::WebRunner::new();
    let app = Box::new(move |cc: &eframe::CreationContext<'_>| -> Result<Box<dyn eframe::App>, _> {
        Ok(Box::new(WebApp::new(cc, &args, open)?))
    });
    let started = runner.start(canvas, web_options(), app).await;
    RUNNER.with(|r| *r.borrow_mut() = Some(runner));
    started.map_err(|e| format!("the editor could not start: {}", js_text(&e)))
}

/// WebGPU only (eframe would fall back to WebGL, which has no compute
/// shaders), on a device with what octovox asks of the adapter.
fn web_options() -> eframe::WebOptions {
    let mut setup = egui_wgpu::WgpuSetupCreateNew::without_display_handle();
    setup.instance_descriptor.backends = wgpu::Backends::BROWSER_WEBGPU;
    setup.device_descriptor = std::sync::Arc::new(GpuContext::device_descriptor);
    eframe::WebOptions {
        wgpu_options: egui_wgpu::WgpuConfiguration {
            wgpu_setup: egui_wgpu::WgpuSetup::CreateNew(setup),
            ..Default::default()
        },
        ..Default::default()
    }
}

/// The page's query as the desktop's command line: `?spp=4&shading=path`
/// is `octovox --spp 4 --shading path`; and `?open=URL`, a model to fetch
/// and open (a model shared as a link).
fn args_from_query() -> Result<(WindowArgs, Option<String>), String> {
    use clap::Parser as _;
    let search = web_sys::window().and_then(|w| w.location().search().ok()).unwrap_or_default();
    let mut argv = vec!["octovox".to_string()];
    let mut open = None;
    for pair in search.trim_start_matches('?').split('&').filter(|p| !p.is_empty()) {
        let (key, value) = pair.split_once('=').unwrap_or((pair, ""));
        if key == "open" {
            open = Some(decode(value));
            continue;
        }
        argv.push(format!("--{}", decode(key)));
        if !value.is_empty() {
            argv.push(decode(value));
        }
    }
    let args = Cli::try_parse_from(argv).map_err(|e| format!("the page's address: {e}"))?;
    Ok((args.window, open))
}

fn decode(text: &str) -> String {
    js_sys::decode_uri_component(&text.replace('+', " ")).map_or_else(|_| text.to_string(), String::from)
}

/// Whether `navigator.gpu` is there and gives an adapter (Chromium on
/// Linux has the object but no adapter unless WebGPU is turned on).
async fn has_webgpu_adapter() -> bool {
    let Some(window) = web_sys::window() else { return false };
    let Ok(gpu) = js_sys::Reflect::get(&window.navigator(), &"gpu".into()) else { return false };
    if gpu.is_undefined() || gpu.is_null() {
        return false;
    }
    let request =
        js_sys::Reflect::get(&gpu, &"requestAdapter".into()).ok().and_then(|f| f.dyn_into::<js_sys::Function>().ok());
    let Some(promise) = request.and_then(|f| f.call0(&gpu).ok()).and_then(|p| p.dyn_into::<js_sys::Promise>().ok())
    else {
        return false;
    };
    wasm_bindgen_futures::JsFuture::from(promise)
        .await
        .is_ok_and(|adapter| !adapter.is_null() && !adapter.is_undefined())
}

fn js_text(value: &wasm_bindgen::JsValue) -> String {
    value
        .as_string()
        .or_else(|| value.dyn_ref::<js_sys::Error>().map(|e| String::from(e.message())))
        .unwrap_or_else(|| format!("{value:?}"))
}

/// Shows `message` in the page's status line, or hides the line.
fn set_status(message: Option<&str>) {
    let Some(status) = web_sys::window().and_then(|w| w.document()).and_then(|d| d.get_element_by_id(STATUS_ID)) else {
        return;
    };
    match message {
        Some(text) => {
            status.set_text_content(Some(text));
            let _ = status.set_attribute("class", "error");
        }
        None => {
            let _ = status.set_attribute("hidden", "");
        }
    }
}

/// The scene's texture and its place among egui's textures.
struct SceneTexture {
    size: (u32, u32),
    /// What the blit draws into.
    target: wgpu::TextureView,
    id: egui::TextureId,
}

/// The page: the session, its input, and the scene's texture.
struct WebApp {
    session: Session,
    input: Input,
    blit: BlitPass,
    scene: Option<SceneTexture>,
    /// Files given to the page, for the next frame.
    files: files::Inbox,
    /// The render scale's factor while the camera moves.
    motion: MotionScale,
    /// Carried from frame to frame by the trace (`Session::encode_trace`).
    preview_before_path: bool,
    path_reported: bool,
    ready: bool,
    /// `?bench-frames=N`, as the desktop's `--bench-frames N`.
    bench: Option<Bench>,
}

impl WebApp {
    fn new(cc: &eframe::CreationContext<'_>, args: &WindowArgs, open: Option<String>) -> Result<WebApp, String> {
        let state = cc.wgpu_render_state.as_ref().ok_or("eframe opened no WebGPU device")?;
        let gpu = GpuContext::from_parts(
            state.instance.clone(),
            state.adapter.clone(),
            state.device.clone(),
            state.queue.clone(),
        );
        let blit = BlitPass::new(&gpu, SCENE_FORMAT, BlitMode::Replace).map_err(|e| e.to_string())?;
        let mut renderer = Renderer::new(gpu).map_err(|e| e.to_string())?;
        // The page never waits for the GPU: it cannot (docs/web.md).
        renderer.wait_for_frames = false;
        renderer.path_bands = drawing::MAX_PATH_BANDS / 2;
        // Journals a page before this one left: the session offers them.
        files::restore_kept();
        let mut session = Session::start(args);
        let kept = files::kept_documents();
        if !kept.is_empty() {
            let names: Vec<String> = kept.iter().map(|d| d.display().to_string()).collect();
            report!("kept: {}", names.join(", "));
            // The page cannot keep the files themselves: the user opens them.
            session.ui.info(format!(
                "unsaved edits of {} are kept in this browser: open the file again to recover them",
                names.join(", ")
            ));
        }
        session.renderer = Some(renderer);
        session.upload();
        let files = files::Inbox::default();
        if let Some(url) = open {
            files.fetch(url, cc.egui_ctx.clone());
        }
        Ok(WebApp {
            session,
            input: Input::default(),
            blit,
            scene: None,
            files,
            motion: MotionScale::default(),
            preview_before_path: false,
            path_reported: false,
            ready: false,
            bench: args.bench_frames.map(Bench::new),
        })
    }

    /// Has the session carry out `command`, then does what it asks.
    fn execute(&mut self, ctx: &egui::Context, command: AppCommand) {
        self.session.execute(command);
        let effects = self.session.take_effects();
        if effects.redraw || effects.screenshot {
            ctx.request_repaint();
        }
        if effects.title
            && let Some(document) = web_sys::window().and_then(|w| w.document())
        {
            document.set_title(&self.session.state.title(self.session.unsaved()));
        }
        if effects.screenshot {
            self.session.ui.error("the page takes no screenshots: use the browser's (docs/web.md)".to_string());
        }
        if let Some((kind, start)) = effects.ask_path
            && let Some(command) = self.files.ask(ctx, kind, &start)
        {
            self.execute(ctx, command);
        }
    }

    /// Opens what was given to the page since the last frame: picked,
    /// dropped or fetched files.
    fn take_files(&mut self, ctx: &egui::Context) {
        for file in ctx.input(|i| i.raw.dropped_files.clone()) {
            self.files.dropped(file, ctx.clone());
        }
        let (commands, failures) = self.files.take();
        for failure in failures {
            self.session.ui.error(failure);
        }
        for command in commands {
            self.execute(ctx, command);
        }
    }

    /// The canvas's size and scale, as the session's picking reads them.
    fn sync_view(&mut self, ctx: &egui::Context) {
        let ppp = ctx.pixels_per_point();
        let rect = ctx.content_rect();
        let size = ((rect.width() * ppp).round().max(1.0) as u32, (rect.height() * ppp).round().max(1.0) as u32);
        self.session.view.window = size;
        self.session.view.scale_factor = f64::from(ppp);
        self.session.view.motion_factor = self.motion.factor();
    }

    /// This frame's mouse and keys, through the one input table.
    fn read_input(&mut self, ctx: &egui::Context) {
        let (events, ppp) = ctx.input(|i| (i.events.clone(), i.pixels_per_point));
        let wants_keys = ctx.egui_wants_keyboard_input() || self.session.ui.prompt_open;
        for event in events.iter().flat_map(|e| events::translate(e, ppp)) {
            let consumed = match event {
                // Decided by position against the last frame's panels, as
                // on the desktop (issue 47, item 1); none yet: the panels'.
                InputEvent::Button { pressed: true, .. } | InputEvent::Wheel { .. } => {
                    match (self.session.hover.view, self.input.cursor()) {
                        (Some(view), Some(at)) => preview::ui_at(ctx, view, at),
                        _ => true,
                    }
                }
                InputEvent::Key(_) => wants_keys,
                _ => false,
            } || self.session.ui.prompt_open;
            let extruding = matches!(self.session.gesture, Gesture::Extrude { .. });
            let commands = self.input.on_event(&event, consumed, self.session.state.tool, extruding);
            self.session.pointer = self.input.pointer();
            for command in commands {
                self.execute(ctx, command);
            }
        }
    }

    /// The texture the scene is drawn into, the canvas's size.
    fn scene_texture(&mut self, frame: &eframe::Frame) -> Option<&SceneTexture> {
        let size = self.session.view.window;
        if self.scene.as_ref().is_none_or(|s| s.size != size) {
            let state = frame.wgpu_render_state()?;
            let texture = state.device.create_texture(&wgpu::TextureDescriptor {
                label: Some("page scene"),
                size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: SCENE_FORMAT,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            });
            let target = texture.create_view(&wgpu::TextureViewDescriptor::default());
            let mut egui_renderer = state.renderer.write();
            let id = match self.scene.take() {
                Some(old) => {
                    egui_renderer.update_egui_texture_from_wgpu_texture(
                        &state.device,
                        &target,
                        wgpu::FilterMode::Nearest,
                        old.id,
                    );
                    old.id
                }
                None => egui_renderer.register_native_texture(&state.device, &target, wgpu::FilterMode::Nearest),
            };
            self.scene = Some(SceneTexture { size, target, id });
        }
        self.scene.as_ref()
    }

    /// Counts a frame of `?bench-frames=N` and asks for the next; after
    /// the last, reports as the desktop does. The page's frames come as the
    /// browser draws them (at most its display's rate).
    fn bench_step(&mut self, ctx: &egui::Context) {
        if !self.ready {
            return;
        }
        let Some(bench) = &mut self.bench else { return };
        match bench.frame(&self.session) {
            Some(line) => {
                report!("{line}");
                self.bench = None;
            }
            None => ctx.request_repaint(),
        }
    }

    /// Traces the scene into its texture and submits it, ahead of egui's
    /// own submit of this frame.
    fn trace(&mut self, ctx: &egui::Context) {
        let Some(target) = self.scene.as_ref().map(|s| s.target.clone()) else { return };
        let Some(device) = self.session.renderer.as_ref().map(|r| r.gpu.device.clone()) else { return };
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("page frame") });
        let facts = FrameFacts { moving: self.motion.moving(), modal: self.session.ui.modal_open() };
        let path = self.session.encode_trace(&mut encoder, facts, &mut self.preview_before_path);
        let Some(renderer) = self.session.renderer.as_mut() else { return };
        self.blit.prepare(&device, renderer.output_view());
        self.blit.encode(&mut encoder, &target, None);
        match renderer.submit(Vec::new(), encoder) {
            Ok(submitted) => self.session.frame_submitted(path, submitted, &mut self.path_reported),
            Err(err) => log::error!("the frame failed: {err}"),
        }
        let animating =
            self.session.keeps_drawing(facts, self.preview_before_path) || self.input.fly_direction().is_some();
        if animating {
            ctx.request_repaint();
        } else if let Some(at) = self.motion.settles_at() {
            // Once the camera keeps still, one more frame at full scale.
            ctx.request_repaint_after(at.saturating_duration_since(Instant::now()));
        }
    }
}

impl eframe::App for WebApp {
    fn raw_input_hook(&mut self, ctx: &egui::Context, raw_input: &mut egui::RawInput) {
        slow_clicks::allow_for_frame_length(ctx, raw_input);
    }

    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        let started = Instant::now();
        let ctx = ui.ctx().clone();
        self.sync_view(&ctx);
        self.read_input(&ctx);
        self.take_files(&ctx);
        self.session.poll_loading();
        if self.ready {
            self.session.play_step();
        }
        if let Some(dir) = self.input.fly_direction() {
            let seconds = f64::from(ctx.input(|i| i.stable_dt)).min(0.1);
            camera_control::fly(&mut self.session.state.camera, dir, seconds);
        }
        // The scene first, under everything; this frame's trace fills the
        // texture before egui draws.
        let Some(id) = self.scene_texture(frame).map(|s| s.id) else { return };
        let painter = ctx.layer_painter(egui::LayerId::background());
        let uv = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
        painter.image(id, ctx.content_rect(), uv, egui::Color32::WHITE);
        let panels = self.session.show_panels(ui);
        for shape in panels.overlays {
            painter.with_clip_rect(shape.clip_rect).add(shape.shape);
        }
        self.session.hover.pointer_over_ui = ctx.is_pointer_over_egui();
        for command in panels.commands {
            self.execute(&ctx, command);
        }
        self.session.palette_released(&ctx);
        // The camera is final for this frame: pick how many pixels to trace.
        let stats = &self.session.readouts.stats;
        let last = FrameTimes { frame_ms: stats.frame_ms, trace_ms: stats.trace_ms };
        self.motion.update(&self.session.state.camera, started, last, self.session.state.frame_target_ms, false);
        self.session.readouts.stats.scale = self.session.render_scale();
        self.sync_view(&ctx);
        self.session.update_hover();
        self.session.update_previews();
        self.session.sync_grid();
        self.trace(&ctx);
        // What this frame wrote (a Save, an Export, a script's `save`) goes
        // to the user.
        for name in files::download_written() {
            report!("downloaded: {name}");
        }
        files::store_kept();
        self.session.readouts.stats.frame_ms = started.elapsed().as_secs_f64() * 1e3;
        if !self.ready && self.session.doc.loading.is_none() {
            self.ready = true;
            let (w, h) = self.session.view.window;
            report!("octovox: ready {w}x{h}");
        }
        self.bench_step(&ctx);
    }
}
