//! What one frame draws, the same in both shells (the desktop window and
//! the browser page): the panels and the shapes over the scene, the trace
//! of the scene (a path-traced sample or the preview), and what a
//! submitted frame tells the readouts.

use octovox::gpu::schedule::Wants;
use octovox::gpu::{FrameInput, PathOptions, PathView, Submitted};
use octovox::settings::{PathSettings, RenderSettings, Shading, TraceMode, View};

use super::gesture::Gesture;
use super::session::Session;
use super::state::{EditorState, Mode};
use super::{AppCommand, ui};

/// Most bands a path-traced sample is split into.
pub(super) const MAX_PATH_BANDS: u32 = 16;

/// Whether the path tracer's noise is measured: it is read back from the
/// GPU, which the browser's page cannot wait for (docs/web.md).
const NOISE_READ_BACK: bool = cfg!(not(target_arch = "wasm32"));

/// Shapes drawn over the scene this frame (`ui::take_scene_overlays`).
pub(super) type Overlays = Vec<egui::epaint::ClippedShape>;

/// What the panels gave: the commands they produced and the shapes drawn
/// over the scene.
pub(super) struct Panels {
    pub commands: Vec<AppCommand>,
    pub overlays: Overlays,
}

/// How the shell's frame stands, as the trace needs it.
#[derive(Clone, Copy, Debug)]
pub(super) struct FrameFacts {
    /// The camera moves (the preview keeps it fluid).
    pub moving: bool,
    /// A dialog of the window or the desktop waits for an answer.
    pub modal: bool,
}

impl Session {
    /// Lays out the panels in `ui` and draws what goes over the scene;
    /// notes the view's rectangle and whether the pointer is over a panel.
    pub(super) fn show_panels(&mut self, ui: &mut egui::Ui) -> Panels {
        let loading = self.loading_shown();
        let (paste, eyedropper, selection) = (self.paste_preview(), self.eyedropper_preview(), self.shown_selection());
        let ctx = ui.ctx().clone();
        let Some(renderer) = self.renderer.as_ref() else {
            return Panels { commands: Vec::new(), overlays: Vec::new() };
        };
        let info = ui::Info {
            palette: &self.doc.editor.scene.palette,
            scene: &self.doc.editor.scene,
            line_start: self.gesture.line_start(),
            stats: self.readouts.shown_stats.take(&ctx, &self.readouts.stats),
            adapter: &renderer.gpu.adapter_name,
            timestamps: renderer.timed_by_gpu(),
            loading: loading.as_ref().map(|(p, s, f)| (p.as_path(), *s, *f)),
            can_undo: self.doc.editor.history.can_undo(),
            can_redo: self.doc.editor.history.can_redo(),
            history: {
                let (steps, bytes) = self.doc.editor.history.usage();
                (steps, bytes, self.doc.editor.history.memory_limit_bytes)
            },
            presets: self.readouts.presets_measured.as_deref(),
            selection,
            has_clipboard: self.doc.editor.clipboard().is_some(),
            recent: self.doc.recent.files().cloned().collect(),
            extrude: self.hover.extrude_preview.as_ref().map(|p| (p.voxels.as_slice(), p.face.1, p.layers)),
            fill: self.hover.fill_preview.as_ref().map(|p| p.region),
            paste,
            eyedropper,
            objects: self.doc.editor.scene.pickable_objects(),
            ground: self.doc.editor.ground,
        };
        let (state, ui_state, tools) = (&mut self.state, &mut self.ui, &self.doc.editor.tools);
        let pick = self.hover.pick;
        let commands = ui::show(ui, state, tools, ui_state, &info);
        let view = ui.available_rect_before_wrap();
        ui::draw_ground(ui, state, &info);
        ui::draw_selection(ui, state, &info, ui_state.outliner.turn.axis);
        if let Some((voxels, normal, layers)) = info.extrude {
            ui::draw_extrude(ui, state, &info, voxels, normal, layers);
        } else if let Some(pick) = pick.filter(|_| state.mode.uses_brush() && info.fill.is_none()) {
            ui::draw_brush_outline(ui, state, tools, &pick, &info);
        }
        ui::draw_action_previews(ui, state, &info);
        let overlays = ui::take_scene_overlays(&ctx);
        self.hover.view = Some(view);
        Panels { commands, overlays }
    }

    /// After the panels' commands: a palette control let go without a
    /// last change still ends its step.
    pub(super) fn palette_released(&mut self, ctx: &egui::Context) {
        if matches!(self.gesture, Gesture::Palette) && !ctx.input(|i| i.pointer.any_down()) {
            self.close_strokes();
        }
    }

    /// Records this frame's trace into `encoder`: a path-traced sample (or
    /// a band of one) where the view asks for it, else the preview. An
    /// accumulation that starts over is preceded by a preview frame, shown
    /// until its first sample is complete (`preview_before_path` carries
    /// that from frame to frame). Returns whether the frame is path traced.
    pub(super) fn encode_trace(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        facts: FrameFacts,
        preview_before_path: &mut bool,
    ) -> bool {
        let (trace_size, selection) = (self.trace_size(), self.shown_selection());
        let Some(renderer) = self.renderer.as_mut() else { return false };
        // While a file loads, previews only: a path-traced sample of a big
        // view takes seconds on a CPU adapter, and the closed prompt or the
        // progress would not show until it ended (issue 47, item 6).
        let wants_path = path_traced(&self.state, facts.moving) && self.doc.loading.is_none();
        let (scene, state) = (&self.doc.editor.scene, &self.state);
        // Where clicks build on the ground, the ground plane is drawn, and
        // takes the voxels' shadows.
        let plane = self.doc.editor.ground_plane();
        let path_settings = PathSettings { ground: plane, ..state.path_settings };
        let view = PathView { scene, camera: &state.camera, size: trace_size, settings: &path_settings };
        // Select mode tints the selected voxels in path-traced frames too
        // (not the brush's reach, which follows the pointer: every move
        // would start the accumulation over).
        let tinted = selection.filter(|_| state.mode == Mode::Select).map(|r| (r.min, r.max));
        let grid = self.doc.editor.ground.then(|| state.ground_grid());
        // A dialog over the view holds the accumulation where it is: its
        // frames stay cheap, and the dialog answers at once.
        let held = facts.modal.then_some(renderer.path.accumulation.samples);
        let sample_target = held.unwrap_or(state.sample_target).max(1);
        let wants = Wants { denoise: state.denoise, estimate_noise: NOISE_READ_BACK, sample_target };
        let options = PathOptions { highlight: tinted, grid, wants };
        let restarts = wants_path && renderer.path_restarts(&view, false, &options);
        let path = wants_path && (!restarts || *preview_before_path);
        *preview_before_path = wants_path && !path;
        let input = if path {
            FrameInput::Path { view, restart: false, options }
        } else {
            // Select mode tints the selected voxels; the brush's modes what it would touch.
            let highlight = match state.mode {
                Mode::Select => selection.map(|r| (r.min, r.max)),
                Mode::Object => None,
                Mode::Brush | Mode::Line => self
                    .hover
                    .pick
                    .map(|pick| state.preview_box(&self.doc.editor.tools, &pick, self.gesture.line_start())),
            };
            let settings = RenderSettings { ground: plane, ..state.settings };
            FrameInput::preview(scene, &state.camera, trace_size, &settings, highlight, grid)
        };
        if let Err(err) = renderer.encode(encoder, &input) {
            log::error!("trace failed: {err}");
        }
        path
    }

    /// What a submitted frame took, for the stats and the path tracer's
    /// band size. `path_reported` carries whether the finished view was
    /// reported already.
    pub(super) fn frame_submitted(&mut self, path: bool, submitted: Submitted, path_reported: &mut bool) {
        let Some(renderer) = self.renderer.as_mut() else { return };
        let stats = &mut self.readouts.stats;
        if !path {
            stats.trace_ms = submitted.ms;
            (stats.path, stats.noise) = (None, None);
            return;
        }
        let Some(frame) = submitted.path else { return };
        if frame.added {
            stats.trace_ms = frame.ms;
            // A slow sample is spread over frames of about the frame-time
            // target: a frame that must show a moved camera then waits for
            // one band, not a whole sample.
            let bands = (frame.ms / f64::from(self.state.frame_target_ms)).ceil();
            renderer.path_bands = (bands as u32).clamp(1, MAX_PATH_BANDS);
            stats.noise = match NOISE_READ_BACK.then(|| renderer.noise_estimate()) {
                None => None,
                Some(Ok(noise)) => noise,
                Some(Err(err)) => {
                    log::warn!("no noise estimate: {err}");
                    None
                }
            };
            if let Some(noise) = stats.noise
                && frame.samples.is_power_of_two()
            {
                report!("noise: {noise:.5} at {} samples", frame.samples);
            }
        }
        // Once the view is final: the samples done and, with Denoise on,
        // their filter (which runs a stage a frame after the last sample).
        let done = frame.samples >= self.state.sample_target.max(1) && !renderer.denoise_pending();
        if done && !*path_reported {
            let effects = frame.effects.names().join(" ");
            report!("path: {} samples, effects [{effects}]", frame.samples);
        }
        *path_reported = done;
        stats.path = Some(frame);
    }

    /// Whether the next frame is wanted at once, whatever the input: the
    /// path tracer has samples to add or their filter to run (not while a
    /// dialog holds it), a preview stands in for a path-traced frame, a
    /// file loads or a script plays. (The shells add their own: flying,
    /// `--bench-frames`.)
    pub(super) fn keeps_drawing(&self, facts: FrameFacts, preview_before_path: bool) -> bool {
        let filtering = self.renderer.as_ref().is_some_and(|renderer| renderer.denoise_pending());
        let accumulating =
            !facts.modal && self.readouts.stats.path.is_some_and(|p| p.samples < self.state.sample_target || filtering);
        accumulating || preview_before_path || self.doc.loading.is_some() || self.doc.player.is_some()
    }

    /// What a file being loaded shows: its path, the seconds since it
    /// started, and the fraction done where the loader knows it.
    fn loading_shown(&self) -> Option<(std::path::PathBuf, f64, Option<f32>)> {
        self.doc.loading.as_ref().map(|l| (l.path.clone(), l.started.elapsed().as_secs_f64(), l.progress.fraction()))
    }

    /// Rebuilds and uploads the dense grid while grid mode is on and the voxels changed.
    pub(super) fn sync_grid(&mut self) {
        let Some(renderer) = &mut self.renderer else { return };
        let revision = self.doc.editor.scene.revision();
        if self.state.settings.mode != TraceMode::Grid || renderer.grid_of() == Some(revision) {
            return;
        }
        let sent = match octovox::trace::grid::DenseGrid::from_octree(self.doc.editor.scene.drawn()) {
            Ok(grid) => renderer.set_grid(&grid, revision).map_err(|err| err.to_string()),
            Err(err) => Err(err.to_string()),
        };
        if let Err(err) = sent {
            self.state.settings.mode = TraceMode::Svo;
            self.ui.error(format!("{err}; back to SVO"));
        }
    }
}

/// Whether this frame is path traced: by the user's choice, and at rest
/// only in the default mode (the preview keeps a moving camera fluid).
fn path_traced(state: &EditorState, moving: bool) -> bool {
    // The path tracer walks the SVO and shades; the grid and the debug views are the preview's.
    let shaded_svo = state.settings.mode == TraceMode::Svo && state.settings.view == View::Shaded;
    match state.shading {
        Shading::Preview => false,
        Shading::Rest => shaded_svo && !moving,
        Shading::Path => shaded_svo,
    }
}
