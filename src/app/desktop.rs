//! The desktop shell: the winit window and its wgpu surface around the
//! editing session. It turns window events into commands (`input`), lays
//! out the panels, draws and presents the frame (`frame`) and does what the
//! session asks (`App::apply_effects`).

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::time::Instant;

use anyhow::Context as _;
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::window::{Window, WindowId};

use octovox::gpu::{BlitMode, BlitPass, GpuContext, Renderer};

use super::gesture::Gesture;
use super::input::{self, Input};
use super::session::Session;
use super::{AppCommand, drawing, preview};
use crate::cli::WindowArgs;
use clock::FrameClock;
use egui_layers::EguiLayers;

mod capture;
mod clock;
mod egui_layers;
mod file_dialog;
mod frame;
mod frame_stats;

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
    blit: BlitPass,
    egui_state: egui_winit::State,
    egui: EguiLayers,
}

/// The window: the winit and egui shell around the editing session. It
/// turns window events into commands for the session, draws and presents
/// frames, and does what the session's [`session::Effects`] ask.
struct App {
    args: WindowArgs,
    /// Until the window opens.
    instance: Option<wgpu::Instance>,
    /// The window and everything on the GPU, once it is open.
    gfx: Option<Gfx>,
    session: Session,
    frames: FrameClock,
    input: Input,
    /// A native file dialog that is open.
    file_dialog: Option<file_dialog::NativeDialog>,
    fatal: Option<anyhow::Error>,
}

impl App {
    fn new(args: WindowArgs, instance: wgpu::Instance) -> App {
        App {
            instance: Some(instance),
            gfx: None,
            session: Session::start(&args),
            frames: FrameClock::new(&args),
            input: Input::default(),
            file_dialog: None,
            fatal: None,
            args,
        }
    }

    // ----- window and GPU set-up -------------------------------------------------

    fn init_gfx(&mut self, event_loop: &ActiveEventLoop) -> anyhow::Result<(Gfx, Renderer)> {
        let instance = self.instance.take().context("the window was created twice")?;
        let (width, height) = self.args.size;
        let attributes = Window::default_attributes()
            .with_title(self.session.state.title(self.session.unsaved()))
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
        renderer.path_bands = drawing::MAX_PATH_BANDS / 2;
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
        Ok((Gfx { window, surface, config, can_copy_frame, blit, egui_state, egui }, renderer))
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

    /// Has the session carry out `command`, then does what it asks.
    fn execute(&mut self, command: AppCommand, event_loop: &ActiveEventLoop) {
        self.session.execute(command);
        self.apply_effects(event_loop);
    }

    /// Does what the session asked of the window since the last time.
    fn apply_effects(&mut self, event_loop: &ActiveEventLoop) {
        let effects = self.session.take_effects();
        if effects.screenshot {
            self.frames.screenshot_requested = true;
        }
        if effects.redraw || effects.screenshot {
            self.request_redraw();
        }
        if effects.title
            && let Some(gfx) = &self.gfx
        {
            gfx.window.set_title(&self.session.state.title(self.session.unsaved()));
        }
        if let Some((kind, start)) = effects.ask_path {
            self.ask_path(kind, start);
        }
        if effects.exit {
            event_loop.exit();
        }
    }

    /// Tells the session the window's size, its scale and the render
    /// scale's factor in motion (what its picking and framing read).
    fn sync_view(&mut self) {
        if let Some(gfx) = &self.gfx {
            self.session.view.window = (gfx.config.width, gfx.config.height);
            self.session.view.scale_factor = gfx.window.scale_factor();
        }
        self.session.view.motion_factor = self.frames.motion.factor();
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.gfx.is_some() || self.fatal.is_some() {
            return;
        }
        match self.init_gfx(event_loop) {
            Ok((gfx, renderer)) => {
                self.gfx = Some(gfx);
                self.session.renderer = Some(renderer);
                self.sync_view();
                // Whatever was built before the device existed goes up now.
                self.session.upload();
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
        let asking =
            self.session.ui.prompt_open || self.session.ui.recover.is_some() || self.session.ui.replace.is_some();
        let to_egui = asking
            || self.session.ui.dialog.is_some()
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
                    let Some(gpu) = self.session.renderer.as_ref().map(|r| &r.gpu) else { return };
                    (gfx.config.width, gfx.config.height) = surface_size(*size, gpu);
                    gfx.surface.configure(&gpu.device, &gfx.config);
                    self.frames.redraw_wanted.set(true);
                    gfx.window.request_redraw();
                    self.sync_view();
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
        let consumed = match (starts, self.session.hover.view, self.input.cursor()) {
            (true, Some(view), Some(at)) => preview::ui_at(gfx.egui_state.egui_ctx(), view, at),
            // Before the first frame, and for releases, motion and keys:
            // egui's verdict.
            _ => response.consumed || (starts && self.session.hover.pointer_over_ui),
        } || self.session.ui.prompt_open;
        let extruding = matches!(self.session.gesture, Gesture::Extrude { .. });
        let Some(event) = input::InputEvent::from_winit(&event) else { return };
        let commands = self.input.on_event(&event, consumed, self.session.state.tool, extruding);
        self.session.pointer = self.input.pointer();
        for command in commands {
            self.execute(command, event_loop);
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        self.apply_effects(event_loop);
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
