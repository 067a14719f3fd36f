//! One frame of the window, top to bottom: background load, script step,
//! camera fly, panels and their commands, hover pick, trace, blit + egui,
//! present, and when to draw the next one.

use std::cell::Cell;
use std::time::{Duration, Instant};

use winit::event_loop::ActiveEventLoop;

use octovox::gpu::schedule::Wants;
use octovox::gpu::{FrameInput, GpuContext, PathOptions, PathView, Submitted};
use octovox::settings::{PathSettings, RenderSettings, Shading, TraceMode, View};
use octovox::trace::grid::DenseGrid;

use super::gesture::Gesture;
use super::state::Mode;
use super::{App, Gfx, camera_control, capture, motion, slow_clicks, ui};

/// Most bands a path-traced sample is split into.
pub(super) const MAX_PATH_BANDS: u32 = 16;

/// Shapes drawn over the scene this frame (`ui::take_scene_overlays`).
type Overlays = Vec<egui::epaint::ClippedShape>;

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
            frames.push(motion::FrameParts {
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
        self.sync_grid();
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
        let (paste, eyedropper, selection) =
            (self.session.paste_preview(), self.session.eyedropper_preview(), self.session.shown_selection());
        let gfx = self.gfx.as_mut()?;
        let renderer = self.session.renderer.as_ref()?;
        let raw_input = gfx.egui_state.take_egui_input(&gfx.window);
        let ctx = gfx.egui_state.egui_ctx().clone();
        slow_clicks::allow_for_frame_length(&ctx, &raw_input);
        let loading = self
            .session
            .doc
            .loading
            .as_ref()
            .map(|l| (l.path.clone(), l.started.elapsed().as_secs_f64(), l.progress.fraction()));
        let mut commands = Vec::new();
        let mut overlays = Vec::new();
        let mut view = None;
        let mut full = {
            let info = ui::Info {
                palette: &self.session.doc.editor.scene.palette,
                scene: &self.session.doc.editor.scene,
                line_start: self.session.gesture.line_start(),
                stats: self.session.readouts.shown_stats.take(&ctx, &self.session.readouts.stats),
                adapter: &renderer.gpu.adapter_name,
                timestamps: renderer.timed_by_gpu(),
                loading: loading.as_ref().map(|(p, s, f)| (p.as_path(), *s, *f)),
                can_undo: self.session.doc.editor.history.can_undo(),
                can_redo: self.session.doc.editor.history.can_redo(),
                history: {
                    let (steps, bytes) = self.session.doc.editor.history.usage();
                    (steps, bytes, self.session.doc.editor.history.memory_limit_bytes)
                },
                presets: self.session.readouts.presets_measured.as_deref(),
                selection,
                has_clipboard: self.session.doc.editor.clipboard().is_some(),
                recent: self.session.doc.recent.files().cloned().collect(),
                extrude: self.session.hover.extrude_preview.as_ref().map(|p| (p.voxels.as_slice(), p.face.1, p.layers)),
                fill: self.session.hover.fill_preview.as_ref().map(|p| p.region),
                paste,
                eyedropper,
                objects: self.session.doc.editor.scene.pickable_objects(),
                ground: self.session.doc.editor.ground,
            };
            let (state, ui_state, tools) =
                (&mut self.session.state, &mut self.session.ui, &self.session.doc.editor.tools);
            let pick = self.session.hover.pick;
            ctx.run_ui(raw_input, |ui| {
                commands = ui::show(ui, state, tools, ui_state, &info);
                view = Some(ui.available_rect_before_wrap());
                ui::draw_ground(ui, state, &info);
                ui::draw_selection(ui, state, &info);
                if let Some((voxels, normal, layers)) = info.extrude {
                    ui::draw_extrude(ui, state, &info, voxels, normal, layers);
                } else if let Some(pick) = pick.filter(|_| state.mode.uses_brush() && info.fill.is_none()) {
                    ui::draw_brush_outline(ui, state, tools, &pick, &info);
                }
                ui::draw_action_previews(ui, state, &info);
                overlays = ui::take_scene_overlays(ui.ctx());
            })
        };
        self.session.hover.pointer_over_ui = ctx.is_pointer_over_egui();
        self.session.hover.view = view;
        gfx.egui_state.handle_platform_output(&gfx.window, std::mem::take(&mut full.platform_output));
        if !commands.is_empty() {
            log::debug!("panel commands {commands:?}");
        }
        for command in commands {
            self.execute(command, event_loop);
        }
        // A palette control let go without a last change still ends its step.
        if matches!(self.session.gesture, Gesture::Palette) && !ctx.input(|i| i.pointer.any_down()) {
            self.session.close_strokes();
        }
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
        let (trace_size, selection, modal) =
            (self.session.trace_size(), self.session.shown_selection(), self.modal_open());
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
        // While a file loads, previews only: a path-traced sample of a big
        // view takes seconds on a CPU adapter, and the closed prompt or the
        // progress would not show until it ended (issue 47, item 6).
        let wants_path =
            path_traced(&self.session.state, self.frames.motion.moving()) && self.session.doc.loading.is_none();
        let (scene, state) = (&self.session.doc.editor.scene, &self.session.state);
        // Where clicks build on the ground, the ground plane is drawn, and
        // takes the voxels' shadows.
        let plane = self.session.doc.editor.ground_plane();
        let path_settings = PathSettings { ground: plane, ..state.path_settings };
        let view = PathView { scene, camera: &state.camera, size: trace_size, settings: &path_settings };
        // Select mode tints the selected voxels in path-traced frames too
        // (not the brush's reach, which follows the pointer: every move
        // would start the accumulation over).
        let tinted = selection.filter(|_| state.mode == Mode::Select).map(|r| (r.min, r.max));
        let grid = self.session.doc.editor.ground.then(|| state.ground_grid());
        // A dialog over the view holds the accumulation where it is: its
        // frames stay cheap, and the dialog answers at once.
        let held = modal.then_some(renderer.path.accumulation.samples);
        let sample_target = held.unwrap_or(state.sample_target).max(1);
        let wants = Wants { denoise: state.denoise, estimate_noise: true, sample_target };
        let options = PathOptions { highlight: tinted, grid, wants };
        let restarts = wants_path && renderer.path_restarts(&view, false, &options);
        let path = wants_path && (!restarts || self.frames.preview_before_path);
        self.frames.preview_before_path = wants_path && !path;
        let input = if path {
            FrameInput::Path { view, restart: false, options }
        } else {
            // Select mode tints the selected voxels; the brush's modes what it would touch.
            let highlight = match self.session.state.mode {
                Mode::Select => selection.map(|r| (r.min, r.max)),
                Mode::Object => None,
                Mode::Brush | Mode::Line => self.session.hover.pick.map(|pick| {
                    self.session.state.preview_box(
                        &self.session.doc.editor.tools,
                        &pick,
                        self.session.gesture.line_start(),
                    )
                }),
            };
            let settings = RenderSettings { ground: plane, ..state.settings };
            FrameInput::preview(scene, &state.camera, trace_size, &settings, highlight, grid)
        };
        if let Err(err) = renderer.encode(&mut encoder, &input) {
            log::error!("trace failed: {err}");
        }
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
            Ok(submitted) => self.frame_submitted(path, submitted),
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

    /// What a submitted frame took, for the stats and the path tracer's
    /// band size.
    fn frame_submitted(&mut self, path: bool, submitted: Submitted) {
        let Some(renderer) = self.session.renderer.as_mut() else { return };
        if !path {
            self.session.readouts.stats.trace_ms = submitted.ms;
            (self.session.readouts.stats.path, self.session.readouts.stats.noise) = (None, None);
            return;
        }
        let Some(frame) = submitted.path else { return };
        if frame.added {
            self.session.readouts.stats.trace_ms = frame.ms;
            // A slow sample is spread over frames of about the frame-time
            // target: a frame that must show a moved camera then waits for
            // one band, not a whole sample.
            let bands = (frame.ms / f64::from(self.session.state.frame_target_ms)).ceil();
            renderer.path_bands = (bands as u32).clamp(1, MAX_PATH_BANDS);
            self.session.readouts.stats.noise = match renderer.noise_estimate() {
                Ok(noise) => noise,
                Err(err) => {
                    log::warn!("no noise estimate: {err}");
                    None
                }
            };
            if let Some(noise) = self.session.readouts.stats.noise
                && frame.samples.is_power_of_two()
            {
                report!("noise: {noise:.5} at {} samples", frame.samples);
            }
        }
        // Once the view is final: the samples done and, with Denoise on,
        // their filter (which runs a stage a frame after the last sample).
        let done = frame.samples >= self.session.state.sample_target.max(1) && !renderer.denoise_pending();
        if done && !self.frames.path_reported {
            let effects = frame.effects.names().join(" ");
            report!("path: {} samples, effects [{effects}]", frame.samples);
        }
        self.frames.path_reported = done;
        self.session.readouts.stats.path = Some(frame);
    }

    /// Keeps drawing while something moves; otherwise waits for input (or
    /// for when egui asks to be drawn again).
    fn schedule_repaint(&mut self, repaint_delay: Option<Duration>) {
        let filtering = self.session.renderer.as_ref().is_some_and(|renderer| renderer.denoise_pending());
        let accumulating = !self.modal_open()
            && self
                .session
                .readouts
                .stats
                .path
                .is_some_and(|p| p.samples < self.session.state.sample_target || filtering);
        let animating = accumulating
            || self.frames.preview_before_path
            || self.session.doc.loading.is_some()
            || self.input.fly_direction().is_some()
            || self.frames.bench.is_some()
            || self.session.doc.player.is_some();
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

    /// Rebuilds and uploads the dense grid while grid mode is on and the voxels changed.
    fn sync_grid(&mut self) {
        let Some(renderer) = &mut self.session.renderer else { return };
        let revision = self.session.doc.editor.scene.revision();
        if self.session.state.settings.mode != TraceMode::Grid || renderer.grid_of() == Some(revision) {
            return;
        }
        let sent = match DenseGrid::from_octree(self.session.doc.editor.scene.drawn()) {
            Ok(grid) => renderer.set_grid(&grid, revision).map_err(|err| err.to_string()),
            Err(err) => Err(err.to_string()),
        };
        if let Err(err) = sent {
            self.session.state.settings.mode = TraceMode::Svo;
            self.session.ui.error(format!("{err}; back to SVO"));
        }
    }
}

/// Whether this frame is path traced: by the user's choice, and at rest
/// only in the default mode (the preview keeps a moving camera fluid).
fn path_traced(state: &super::state::EditorState, moving: bool) -> bool {
    // The path tracer walks the SVO and shades; the grid and the debug views are the preview's.
    let shaded_svo = state.settings.mode == TraceMode::Svo && state.settings.view == View::Shaded;
    match state.shading {
        Shading::Preview => false,
        Shading::Rest => shaded_svo && !moving,
        Shading::Path => shaded_svo,
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
