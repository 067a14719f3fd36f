//! One frame of the window, top to bottom: background load, script step,
//! camera fly, panels and their commands, hover pick, trace, blit + egui,
//! present, and when to draw the next one.

use std::cell::Cell;
use std::time::{Duration, Instant};

use winit::event_loop::ActiveEventLoop;

use octovox::gpu::GpuContext;

use super::super::drawing::{FrameFacts, Overlays, Panels};
use super::super::{camera_control, motion, slow_clicks};
use super::{App, Gfx, capture, frame_stats};

impl App {
    pub(super) fn frame(&mut self, event_loop: &ActiveEventLoop) {
        let started = Instant::now();
        let interval_ms = self.frames.last_frame.map(|last| started.duration_since(last).as_secs_f64() * 1e3);
        let seconds = self.measure_interval(started);
        self.session.poll_loading();
        self.poll_file_dialog(event_loop);
        if self.frames.ready {
            self.session.play_step();
        }
        if let Some(dir) = self.input.fly_direction() {
            camera_control::fly(&mut self.session.state.camera, dir, seconds);
        }
        // Panels first: they may change settings and produce commands.
        let panels_started = Instant::now();
        let Some((ctx, full, overlays)) = self.run_panels(event_loop) else { return };
        self.session.readouts.stats.panels_ms = panels_started.elapsed().as_secs_f64() * 1e3;
        // The camera is final for this frame: pick how many pixels to trace.
        let screenshot = self.frames.screenshot_requested;
        let last = motion::FrameTimes {
            frame_ms: self.session.readouts.stats.frame_ms,
            trace_ms: self.session.readouts.stats.trace_ms,
        };
        self.frames.motion.update(
            &self.session.state.camera,
            started,
            last,
            self.session.state.frame_target_ms,
            screenshot,
        );
        self.session.readouts.stats.scale = self.session.render_scale();
        // The interval since the last frame is a moving frame's time when
        // that one moved too: before a motion it also holds the time the
        // window sat idle (the wait for work in flight shows in the next).
        let counted = std::mem::replace(&mut self.session.readouts.stats.moving, self.frames.motion.moving())
            && self.frames.motion.moving();
        if let (Some(frames), Some(interval_ms), true) = (&mut self.frames.moving_frames, interval_ms, counted) {
            let s = &self.session.readouts.stats;
            frames.push(frame_stats::FrameParts {
                interval_ms,
                trace_ms: s.trace_ms,
                panels_ms: s.panels_ms,
                acquire_ms: s.acquire_ms,
                draw_ms: s.draw_ms,
                submit_ms: s.submit_ms,
                scale: s.scale,
            });
        }
        self.sync_view();
        self.session.update_hover();
        self.session.update_previews();
        self.session.sync_grid();
        let repaint_delay = full.viewport_output.get(&egui::ViewportId::ROOT).map(|v| v.repaint_delay);
        let Some(window_copy) = self.trace_and_present(&ctx, full, overlays) else { return };
        if std::mem::take(&mut self.frames.screenshot_requested) {
            self.save_screenshot(window_copy);
        }
        self.session.readouts.stats.frame_ms = started.elapsed().as_secs_f64() * 1e3;
        if !self.frames.ready && self.session.doc.loading.is_none() {
            self.frames.ready = true;
            let (w, h) = self.gfx.as_ref().map_or((0, 0), |g| (g.config.width, g.config.height));
            report!("octovox: ready {w}x{h}");
        }
        self.bench_step(event_loop);
        self.schedule_repaint(repaint_delay);
        self.apply_effects(event_loop);
    }

    /// Updates the smoothed frame rate; returns the seconds since the last
    /// frame (at most 0.1, so a stall does not fling the flying camera).
    fn measure_interval(&mut self, started: Instant) -> f64 {
        let seconds = self.frames.last_frame.map_or(0.0, |t| started.duration_since(t).as_secs_f64().min(0.1));
        if let Some(last) = self.frames.last_frame {
            let interval = started.duration_since(last).as_secs_f64();
            if interval < 1.0 {
                let fps = 1.0 / interval.max(1e-6);
                self.session.readouts.stats.fps = if self.session.readouts.stats.fps == 0.0 {
                    fps
                } else {
                    self.session.readouts.stats.fps * 0.9 + fps * 0.1
                };
            }
        }
        self.frames.last_frame = Some(started);
        seconds
    }

    /// Lays out the panels and carries out the commands they produced.
    /// Returns egui's output and, apart, the shapes drawn over the scene.
    fn run_panels(&mut self, event_loop: &ActiveEventLoop) -> Option<(egui::Context, egui::FullOutput, Overlays)> {
        let gfx = self.gfx.as_mut()?;
        self.session.renderer.as_ref()?;
        let raw_input = gfx.egui_state.take_egui_input(&gfx.window);
        let ctx = gfx.egui_state.egui_ctx().clone();
        slow_clicks::allow_for_frame_length(&ctx, &raw_input);
        let session = &mut self.session;
        let mut panels = None;
        let mut full = ctx.run_ui(raw_input, |ui| panels = Some(session.show_panels(ui)));
        let Panels { commands, overlays } = panels?;
        self.session.hover.pointer_over_ui = ctx.is_pointer_over_egui();
        gfx.egui_state.handle_platform_output(&gfx.window, std::mem::take(&mut full.platform_output));
        if !commands.is_empty() {
            log::debug!("panel commands {commands:?}");
        }
        for command in commands {
            self.execute(command, event_loop);
        }
        self.session.palette_released(&ctx);
        Some((ctx, full, overlays))
    }

    /// Traces the scene, then draws it and the panels onto the window and
    /// presents. Returns `None` when the frame was skipped (surface not
    /// ready), else the window copy for a pending screenshot.
    fn trace_and_present(
        &mut self,
        ctx: &egui::Context,
        mut full: egui::FullOutput,
        overlays: Overlays,
    ) -> Option<Option<capture::WindowCopy>> {
        let modal = self.modal_open();
        let gfx = self.gfx.as_mut()?;
        let renderer = self.session.renderer.as_mut()?;
        let tessellate_started = Instant::now();
        let panels = ctx.tessellate(full.shapes, full.pixels_per_point);
        let overlays = ctx.tessellate(overlays, full.pixels_per_point);
        self.session.readouts.stats.panels_ms += tessellate_started.elapsed().as_secs_f64() * 1e3;
        gfx.egui.set_textures(&renderer.gpu, &mut full.textures_delta);
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [gfx.config.width, gfx.config.height],
            pixels_per_point: full.pixels_per_point,
        };

        // One encoder and one submit a frame: the trace (the one encode path
        // that headless rendering uses too), the blit and the panels. An
        // accumulation that starts over is preceded by a preview frame, shown
        // until its first sample (which may come in bands) is complete.
        let present_started = Instant::now();
        let frame = acquire_frame(gfx, &renderer.gpu, &self.frames.redraw_wanted)?;
        let acquired = Instant::now();
        let device = renderer.gpu.device.clone();
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame") });
        let facts = FrameFacts { moving: self.frames.motion.moving(), modal };
        let path = self.session.encode_trace(&mut encoder, facts, &mut self.frames.preview_before_path);
        let Some(renderer) = self.session.renderer.as_mut() else { return Some(None) };
        let view = frame.texture.create_view(&wgpu::TextureViewDescriptor::default());
        gfx.blit.prepare(&device, renderer.output_view());
        // The blit and the panels are render passes labelled with their
        // names; a debug group around a render pass crashes lavapipe (Mesa
        // 22.3) in `CommandEncoder::finish`, so only the compute passes get one.
        gfx.blit.encode(&mut encoder, &view, None);
        let user_buffers = gfx.egui.encode(&renderer.gpu, &mut encoder, &view, &panels, &overlays, &screen);
        let window_copy = (self.frames.screenshot_requested && gfx.can_copy_frame)
            .then(|| capture::copy_frame(gfx, &renderer.gpu, &mut encoder, &frame.texture));
        let recorded = Instant::now();
        match renderer.submit(user_buffers, encoder) {
            Ok(submitted) => self.session.frame_submitted(path, submitted, &mut self.frames.path_reported),
            Err(err) => log::error!("the frame failed: {err}"),
        }
        let (Some(gfx), Some(renderer)) = (self.gfx.as_mut(), self.session.renderer.as_ref()) else {
            return Some(window_copy);
        };
        gfx.window.pre_present_notify();
        renderer.gpu.queue.present(frame);
        gfx.egui.free_textures();
        let ms = |from: Instant, to: Instant| to.duration_since(from).as_secs_f64() * 1e3;
        let now = Instant::now();
        (self.session.readouts.stats.acquire_ms, self.session.readouts.stats.draw_ms) =
            (ms(present_started, acquired), ms(acquired, recorded));
        (self.session.readouts.stats.submit_ms, self.session.readouts.stats.present_ms) =
            (ms(recorded, now), ms(present_started, now));
        Some(window_copy)
    }

    /// Keeps drawing while something moves; otherwise waits for input (or
    /// for when egui asks to be drawn again).
    fn schedule_repaint(&mut self, repaint_delay: Option<Duration>) {
        let facts = FrameFacts { moving: self.frames.motion.moving(), modal: self.modal_open() };
        let animating = self.session.keeps_drawing(facts, self.frames.preview_before_path)
            || self.input.fly_direction().is_some()
            || self.frames.bench.is_some();
        self.frames.next_repaint = match repaint_delay {
            _ if animating => Some(Instant::now()),
            // An open native dialog is looked at ten times a second.
            _ if self.file_dialog.is_some() => Some(Instant::now() + Duration::from_millis(100)),
            Some(delay) if delay < Duration::from_secs(5) => Some(Instant::now() + delay),
            _ => None,
        };
        // Input draws the frames while the camera moves; once it keeps
        // still, one more frame draws the resting view at full scale.
        if let Some(at) = self.frames.motion.settles_at() {
            self.frames.next_repaint = Some(self.frames.next_repaint.map_or(at, |next| next.min(at)));
        }
    }

    /// Whether a dialog of the window or the desktop waits for an answer.
    fn modal_open(&self) -> bool {
        self.session.ui.modal_open() || self.file_dialog.is_some()
    }
}

/// The swapchain image to draw on, or `None` when this frame must be skipped
/// (the surface is reconfigured or re-created, and another frame asked for).
fn acquire_frame(gfx: &mut Gfx, gpu: &GpuContext, redraw_wanted: &Cell<bool>) -> Option<wgpu::SurfaceTexture> {
    let retry = |gfx: &Gfx| {
        redraw_wanted.set(true);
        gfx.window.request_redraw();
    };
    match gfx.surface.get_current_texture() {
        wgpu::CurrentSurfaceTexture::Success(frame) | wgpu::CurrentSurfaceTexture::Suboptimal(frame) => Some(frame),
        wgpu::CurrentSurfaceTexture::Outdated => {
            log::debug!("surface outdated; reconfiguring");
            gfx.surface.configure(&gpu.device, &gfx.config);
            retry(gfx);
            None
        }
        wgpu::CurrentSurfaceTexture::Lost => {
            // A lost surface must be made again; if that fails too, keep
            // the old one and retry on the next frame.
            log::warn!("surface lost; creating it again");
            match gpu.instance.create_surface(gfx.window.clone()) {
                Ok(surface) => gfx.surface = surface,
                Err(err) => log::error!("cannot re-create the surface: {err}"),
            }
            gfx.surface.configure(&gpu.device, &gfx.config);
            retry(gfx);
            None
        }
        wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => {
            log::debug!("surface timeout or occluded; skipping the frame");
            retry(gfx);
            None
        }
        wgpu::CurrentSurfaceTexture::Validation => {
            log::error!("surface validation error; reconfiguring");
            gfx.surface.configure(&gpu.device, &gfx.config);
            None
        }
    }
}
