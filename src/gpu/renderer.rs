//! The scene renderer: device, scene buffers and the trace pass together,
//! with the one encode path of a frame. `render`, `replay`, `bench`, the GPU
//! tests and the window (which blits its output to a surface) all use it.

use glam::IVec3;

use super::context::validated;
use super::path_pass::PathKey;
use super::scene_buffers::UploadStats;
use super::schedule::{FilterFrame, FilterSchedule, Wants};
use super::timer::PassTimer;
use super::{
    DenoisePass, FrameUniforms, GpuContext, GpuError, GroundGrid, Kernel, PathPass, PathUniforms, SceneBuffers,
    TracePass,
};
use crate::camera::Camera;
use crate::scene::Scene;
use crate::settings::{PathSettings, RenderSettings, View};
use crate::trace::denoise::{Frame, Guide, Sums};
use crate::trace::grid::DenseGrid;
use crate::trace::path::materials::{Effects, material_table};
use crate::trace::path::{effects_for, lights};
use crate::trace::{Footprint, Hit};

/// Which pass drew the last frame (the one the window shows).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Shown {
    Trace,
    Path,
    /// The path tracer's accumulation, denoised.
    Denoised,
}

/// What a path-traced frame did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathFrame {
    /// Milliseconds of the sample this frame completed (all its bands).
    pub ms: f64,
    /// Samples accumulated so far, this one included.
    pub samples: u32,
    pub effects: Effects,
    /// The effects of the kernel that ran: `effects`, or all of them while
    /// the kernel of `effects` is being compiled.
    pub kernel: Effects,
    /// Emissive cells sampled as lights.
    pub lights: usize,
    /// Whether this call completed a sample (none once `sample_target` is
    /// reached, nor after a band that is not the image's last).
    pub added: bool,
}

/// What one frame draws: the preview (a trace kernel: the SVO or grid
/// tracer, or the floor) or the next band of a path-traced sample.
pub enum FrameInput<'a> {
    Trace(Preview<'a>),
    Path {
        view: PathView<'a>,
        /// Start the accumulation over even where its key is the same (a
        /// change to the scene shows in its revision, which the key holds).
        restart: bool,
        /// What the frame shows over the samples, and wants of them.
        options: PathOptions,
    },
}

/// What a path-traced frame is asked for beyond its view: the tint and the
/// grid it draws (a change starts the accumulation over, as each sample
/// counts them) and what it wants of the accumulation (target, filter,
/// noise). Headless renders take the default: no tint or grid, unbounded,
/// unfiltered (they call [`Renderer::denoise_now`] once at the end).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathOptions {
    /// The world box of voxels tinted (the window's selection, as the
    /// preview tints it).
    pub highlight: Option<(IVec3, IVec3)>,
    /// The ground grid drawn with the voxels (the window's, in a scene
    /// with its ground on).
    pub grid: Option<GroundGrid>,
    pub wants: Wants,
}

impl Default for PathOptions {
    fn default() -> PathOptions {
        let wants = Wants { denoise: false, estimate_noise: false, sample_target: u32::MAX };
        PathOptions { highlight: None, grid: None, wants }
    }
}

/// A frame of a trace kernel.
#[derive(Clone, Copy)]
pub struct Preview<'a> {
    pub scene: &'a Scene,
    pub camera: &'a Camera,
    pub size: (u32, u32),
    pub view: View,
    pub lod: f32,
    /// An inclusive world-space voxel box to tint.
    pub highlight: Option<(IVec3, IVec3)>,
    pub kernel: Kernel,
    /// The world height of the ground plane, if one is drawn.
    pub ground: Option<i32>,
    /// The ground grid drawn with the voxels.
    pub grid: Option<GroundGrid>,
}

impl<'a> FrameInput<'a> {
    /// The preview of `scene` with `settings`.
    pub fn preview(
        scene: &'a Scene,
        camera: &'a Camera,
        size: (u32, u32),
        settings: &RenderSettings,
        highlight: Option<(IVec3, IVec3)>,
        grid: Option<GroundGrid>,
    ) -> FrameInput<'a> {
        let (view, lod, kernel, ground) = (settings.view, settings.lod, Kernel::from(settings), settings.ground);
        FrameInput::Trace(Preview { scene, camera, size, view, lod, highlight, kernel, ground, grid })
    }
}

/// What [`Renderer::encode`] recorded, for [`Renderer::submit`] to complete.
enum Recorded {
    Trace,
    Path {
        kernel: Effects,
        effects: Effects,
        /// Whether the denoiser's `prepare` ran after this band.
        prepared: bool,
    },
    /// The accumulation has its samples: no pass this frame.
    Nothing(PathFrame),
}

/// A submitted frame: the pass's milliseconds, and what a path-traced
/// frame added.
pub struct Submitted {
    pub ms: f64,
    pub path: Option<PathFrame>,
}

/// What a path-traced accumulation is of: the scene, the camera, the
/// traced size and the settings. A change to any of them starts it over.
#[derive(Clone, Copy)]
pub struct PathView<'a> {
    pub scene: &'a Scene,
    pub camera: &'a Camera,
    pub size: (u32, u32),
    pub settings: &'a PathSettings,
}

/// The key of `view`'s accumulation with the tint and grid of `options`.
fn path_key(view: &PathView, options: &PathOptions) -> PathKey {
    let PathView { scene, camera, size, settings } = *view;
    let basis = camera.basis(size.0.max(1), size.1.max(1), scene.origin());
    let (highlight, ground) = (options.highlight, options.grid);
    let (effects, revision) = (effects_for(scene, settings), scene.revision());
    PathKey { basis, settings: *settings, effects, highlight, ground, revision }
}

pub struct Renderer {
    pub gpu: GpuContext,
    pub buffers: SceneBuffers,
    pub pass: TracePass,
    pub path: PathPass,
    pub denoiser: DenoisePass,
    timer: PassTimer,
    shown: Shown,
    /// Bands a path-traced sample is split into, one per call (taken when
    /// a sample starts; 1 by default): the window spreads a slow sample over
    /// several frames, so that a frame that must show a moved camera does
    /// not wait for a whole one.
    pub path_bands: u32,
    /// Whether a traced frame waits for the GPU (headless renders, tests,
    /// benches); the window turns it off, so its trace, blit and present are
    /// queued back to back and the times shown are a frame old. A
    /// path-traced frame always waits: at rest such frames follow each
    /// other without input, and queued ahead they made the first frame of a
    /// moving camera wait for several of them.
    pub wait_for_frames: bool,
    /// What the last path-traced frame wanted of the accumulation
    /// ([`PathOptions::wants`]): whether the filter is still pending and
    /// what the output shows follow from it between frames.
    wants: Wants,
    /// The sample count the last noise measurement saw.
    noise_of: Option<u32>,
    /// The denoiser's filter over the current accumulation, a stage a
    /// frame (the window's): see [`FilterSchedule`].
    filter: FilterSchedule,
    /// Whether frames write the per-pixel hit records that
    /// [`Renderer::read_hits`] returns; off by default, as they cost time.
    pub hit_records: bool,
    /// Whether the last frame wrote them.
    records_written: bool,
    /// Why the last sync could not upload the pool; frames fail with it
    /// until a sync succeeds.
    pool_error: Option<crate::gpu_pool::PoolTooLarge>,
    /// What the frame being recorded holds, until it is submitted.
    recorded: Option<Recorded>,
    /// The scene revision the dense grid was made from.
    grid_of: Option<u64>,
}

impl Renderer {
    pub fn new(gpu: GpuContext) -> Result<Renderer, GpuError> {
        let buffers = SceneBuffers::new(&gpu.device);
        let pass = TracePass::new(&gpu, &buffers)?;
        let path = PathPass::new(&gpu, &buffers)?;
        let mut denoiser = DenoisePass::new(&gpu)?;
        denoiser.bind(&gpu, &path);
        let timer = PassTimer::new(&gpu);
        Ok(Renderer {
            gpu,
            buffers,
            pass,
            path,
            denoiser,
            timer,
            shown: Shown::Trace,
            wants: PathOptions::default().wants,
            noise_of: None,
            filter: FilterSchedule::default(),
            path_bands: 1,
            wait_for_frames: true,
            hit_records: false,
            records_written: false,
            pool_error: None,
            recorded: None,
            grid_of: None,
        })
    }

    /// A renderer on the default headless adapter.
    pub fn headless() -> Result<Renderer, GpuError> {
        Renderer::new(GpuContext::headless()?)
    }

    /// Sends the pool's changes since the last call and the palette. A pool
    /// too large for one buffer binding is not sent: frames then fail with
    /// [`GpuError::PoolTooLarge`] saying so, until a sync succeeds.
    pub fn sync(&mut self, scene: &mut Scene) -> UploadStats {
        self.buffers.upload_palette(&self.gpu.queue, &scene.palette);
        let limit = self.gpu.device.limits().max_storage_buffer_binding_size;
        match self.buffers.upload_pool(&self.gpu.device, &self.gpu.queue, scene, limit) {
            Ok(stats) => {
                self.pool_error = None;
                stats
            }
            Err(err) => {
                self.pool_error = Some(err);
                UploadStats::default()
            }
        }
    }

    /// The pool's upload error, as a frame's error.
    fn check_pool(&self) -> Result<(), GpuError> {
        match self.pool_error {
            Some(pool) => Err(GpuError::PoolTooLarge { pool, adapter: self.gpu.adapter_name.clone() }),
            None => Ok(()),
        }
    }

    /// Uploads the dense grid the grid tracer walks, made from the scene
    /// of `revision`.
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] when the grid is larger than a binding may be.
    pub fn set_grid(&mut self, grid: &DenseGrid, revision: u64) -> Result<(), GpuError> {
        self.gpu.check_binding("the dense grid", grid.data.len() as u64)?;
        self.buffers.upload_grid(&self.gpu.device, &self.gpu.queue, grid);
        self.grid_of = Some(revision);
        Ok(())
    }

    /// The revision of the scene the dense grid was made from (see
    /// [`Renderer::set_grid`]), if one was sent.
    pub fn grid_of(&self) -> Option<u64> {
        self.grid_of
    }

    /// Traces one frame and waits for it; returns the pass's milliseconds.
    /// `highlight` is an inclusive world-space voxel box to tint.
    ///
    /// # Errors
    /// An image larger than the adapter allows, or any validation error
    /// while the frame is recorded: never a silently blank image.
    pub fn render(
        &mut self,
        scene: &Scene,
        camera: &Camera,
        size: (u32, u32),
        settings: &RenderSettings,
        highlight: Option<(IVec3, IVec3)>,
    ) -> Result<f64, GpuError> {
        Ok(self.render_frame(&FrameInput::preview(scene, camera, size, settings, highlight, None))?.ms)
    }

    /// A frame of the floor kernel (everything but the traversal, see
    /// `shaders/floor.wgsl`); returns its milliseconds.
    ///
    /// # Errors
    /// As [`Renderer::render`].
    pub fn render_floor(&mut self, scene: &Scene, camera: &Camera, size: (u32, u32)) -> Result<f64, GpuError> {
        let floor = Preview {
            scene,
            camera,
            size,
            view: View::Shaded,
            lod: 0.0,
            highlight: None,
            kernel: Kernel::Floor,
            ground: None,
            grid: None,
        };
        let input = FrameInput::Trace(floor);
        Ok(self.render_frame(&input)?.ms)
    }

    /// Adds one path-traced sample per pixel to the accumulation and shows
    /// the mean. The accumulation restarts when the camera, the size, the
    /// settings or the effect set change, and when `restart` says the
    /// voxels or the palette did (the materials and lights are then sent
    /// again).
    ///
    /// # Errors
    /// As [`Renderer::render`].
    pub fn render_path(&mut self, view: &PathView, restart: bool) -> Result<PathFrame, GpuError> {
        self.render_path_with(view, restart, PathOptions::default())
    }

    /// [`Renderer::render_path`] with `options` (a tint, a grid, a target,
    /// the filter).
    ///
    /// # Errors
    /// As [`Renderer::render`].
    pub fn render_path_with(
        &mut self,
        view: &PathView,
        restart: bool,
        options: PathOptions,
    ) -> Result<PathFrame, GpuError> {
        let submitted = self.render_frame(&FrameInput::Path { view: *view, restart, options })?;
        submitted.path.ok_or_else(|| GpuError::Readback("a path frame reported no sample".into()))
    }

    /// One frame on its own encoder, submitted at once (headless renders;
    /// the window records its blit and panels after [`Renderer::encode`] in
    /// the same encoder and then calls [`Renderer::submit`]).
    ///
    /// # Errors
    /// As [`Renderer::render`].
    pub fn render_frame(&mut self, input: &FrameInput) -> Result<Submitted, GpuError> {
        let mut encoder =
            self.gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame") });
        self.encode(&mut encoder, input)?;
        self.submit(Vec::new(), encoder)
    }

    /// Records the frame's pass into `encoder`, in a debug group of its
    /// name: the outputs sized, the uniforms written, the kernel dispatched
    /// and timed. [`Renderer::submit`] completes it.
    ///
    /// # Errors
    /// As [`Renderer::render`].
    pub fn encode(&mut self, encoder: &mut wgpu::CommandEncoder, input: &FrameInput) -> Result<(), GpuError> {
        self.check_pool()?;
        self.recorded = None;
        let device = self.gpu.device.clone();
        let recorded = validated(&device, || match *input {
            FrameInput::Trace(preview) => {
                encoder.push_debug_group("trace");
                let traced = self.encode_trace(encoder, &preview);
                encoder.pop_debug_group();
                traced.map(|()| Recorded::Trace)
            }
            FrameInput::Path { view, restart, options } => {
                encoder.push_debug_group("path");
                let traced = self.encode_path(encoder, &view, restart, &options);
                encoder.pop_debug_group();
                traced
            }
        })?;
        self.recorded = Some(recorded);
        Ok(())
    }

    fn encode_trace(&mut self, encoder: &mut wgpu::CommandEncoder, preview: &Preview) -> Result<(), GpuError> {
        let Preview { scene, camera, size, view, lod, highlight, kernel, ground, grid } = *preview;
        // A scene drawn as instances runs the kernels with the instance walk.
        let instances = self.buffers.instance_nodes.is_some();
        let tree = scene.drawn();
        let gpu = &self.gpu;
        self.pass.resize(gpu, &self.buffers, size, self.hit_records)?;
        self.pass.ensure_kernel(gpu, kernel, instances)?;
        let basis = camera.basis(size.0.max(1), size.1.max(1), tree.origin());
        let uniforms = FrameUniforms {
            hit_records: u32::from(self.hit_records),
            ..FrameUniforms::new(&basis, tree, &self.buffers, view, highlight, Footprint::of_pixels(&basis, lod))
                .with_ground(grid, tree.origin())
                .with_plane(ground, tree.origin())
        };
        self.records_written = self.hit_records;
        self.shown = Shown::Trace;
        self.pass.prepare(&gpu.device, &gpu.queue, &self.buffers, &uniforms);
        self.pass.encode(encoder, (kernel, instances), self.timer.pass_writes());
        self.timer.resolve(encoder);
        Ok(())
    }

    /// Records the next band of a path-traced sample, or nothing when the
    /// accumulation has its samples.
    fn encode_path(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        view: &PathView,
        restart: bool,
        options: &PathOptions,
    ) -> Result<Recorded, GpuError> {
        let PathView { scene, size, settings, .. } = *view;
        self.wants = options.wants;
        let gpu = &self.gpu;
        let resized = self.path.resize(gpu, &self.buffers, size)?;
        if resized {
            self.denoiser.bind(gpu, &self.path);
        }
        let mut acc = self.path.accumulation;
        let key = path_key(view, options);
        let effects = key.effects;
        // The materials and lights go up again when the scene or the effect set changed.
        let send_scene =
            restart || resized || acc.key.is_none_or(|k| k.effects != effects || k.revision != key.revision);
        if send_scene {
            let lights = if effects.emit { lights::emitters(scene) } else { Vec::new() };
            self.path.upload_scene(gpu, &self.buffers, &material_table(&scene.palette), &lights);
            acc.lights = lights.len();
        }
        if acc.starts_over(&key, resized, restart) {
            acc.samples = 0;
            acc.key = Some(key);
            acc.band.0 = 0;
            (self.filter, self.noise_of) = (FilterSchedule::default(), None);
        }
        if acc.band.0 == 0 {
            acc.band = (0, self.path_bands.clamp(1, size.1.max(1)));
            acc.band_ms = 0.0;
        }
        self.path.accumulation = acc;
        if acc.samples >= self.wants.sample_target && self.shown != Shown::Trace {
            let filter = self.filter.at_rest(acc.samples, self.wants);
            self.encode_filter(encoder, &key, filter);
            self.shown = self.accumulation_shown();
            let (lights, samples) = (acc.lights, acc.samples);
            return Ok(Recorded::Nothing(PathFrame {
                ms: 0.0,
                samples,
                effects,
                kernel: effects,
                lights,
                added: false,
            }));
        }
        let (band, bands) = acc.band;
        let band_rows = |band: u32| size.1.max(1) * band / bands;
        let (first_row, end_row) = (band_rows(band), band_rows(band + 1));
        let (sky_horizon, sky_zenith) = settings.sky.colors();
        let path = PathUniforms {
            sky_horizon,
            sample_index: acc.samples,
            sky_zenith,
            bounces: settings.bounces,
            shadow_samples: settings.shadow_samples,
            emitter_count: acc.lights as u32,
            first_row,
            end_row,
            first_sample: settings.first_sample(),
            padding: [0; 3],
        };
        let (drawn, highlight) = (scene.drawn(), key.highlight);
        let frame = FrameUniforms::new(&key.basis, drawn, &self.buffers, View::Shaded, highlight, Footprint::EXACT)
            .with_ground(key.ground, drawn.origin())
            .with_plane(settings.ground, drawn.origin());
        self.path.prepare(gpu, &self.buffers, &frame, &path);
        let instances = self.buffers.instance_nodes.is_some();
        let rows = end_row - first_row;
        let kernel = self.path.encode(gpu, encoder, (effects, instances), rows, self.timer.pass_writes())?;
        self.timer.resolve(encoder);
        // Until its first sample has every row, the accumulation is not
        // shown: the trace output is (the window traces the preview first).
        // What this band completes is shown by the frame that records it.
        let completes = band + 1 == bands;
        let filter = self.filter.band(completes, acc.samples + u32::from(completes), self.wants);
        let prepared = filter.prepare.is_some();
        self.encode_filter(encoder, &key, filter);
        self.shown = if acc.samples + u32::from(completes) > 0 { self.accumulation_shown() } else { Shown::Trace };
        Ok(Recorded::Path { kernel, effects, prepared })
    }

    /// Records the denoiser's dispatches the schedule chose for a frame.
    fn encode_filter(&mut self, encoder: &mut wgpu::CommandEncoder, key: &PathKey, filter: FilterFrame) {
        let frame = Frame::of(&key.basis);
        if let Some(starts) = filter.prepare {
            self.denoiser.encode_stages(&self.gpu, encoder, &frame, 0..1, starts);
        }
        if let Some(stage) = filter.stage {
            self.denoiser.encode_stages(&self.gpu, encoder, &frame, stage..stage + 1, true);
        }
    }

    /// Whether the window should keep drawing for the filter: one is under
    /// way, or the last sample's has not run.
    pub fn denoise_pending(&self) -> bool {
        self.filter.pending(self.path.accumulation.samples, self.wants)
    }

    /// How the accumulation is shown: denoised when asked and done.
    fn accumulation_shown(&self) -> Shown {
        if self.filter.shows_denoised(self.wants) { Shown::Denoised } else { Shown::Path }
    }

    /// Denoises the accumulation as it stands and shows it; returns the
    /// wall-clock milliseconds of the filter (submit to finish).
    ///
    /// # Errors
    /// Nothing accumulated yet, or a validation error of the pass.
    pub fn denoise_now(&mut self) -> Result<f64, GpuError> {
        let acc = self.path.accumulation;
        let key = acc.key.filter(|_| acc.samples > 0);
        let key = key.ok_or_else(|| GpuError::Readback("no path-traced samples to denoise".into()))?;
        let device = self.gpu.device.clone();
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("denoise") });
        validated(&device, || {
            self.denoiser.encode(&self.gpu, &mut encoder, &Frame::of(&key.basis), true);
            Ok(())
        })?;
        let start = web_time::Instant::now();
        self.gpu.checked(|| {
            self.gpu.queue.submit([encoder.finish()]);
            self.gpu.wait()
        })?;
        let ms = start.elapsed().as_secs_f64() * 1e3;
        self.filter.filtered_now(acc.samples);
        (self.noise_of, self.shown) = (Some(acc.samples), Shown::Denoised);
        Ok(ms)
    }

    /// The remaining noise of the accumulation, estimated from its samples
    /// (`crate::trace::denoise::noise_estimate`): `None` below two samples.
    /// Measured now (the denoiser's `prepare`, without the light) unless the
    /// last sample's frame did (`Wants::estimate_noise` of its options).
    ///
    /// # Errors
    /// A failed measurement or readback.
    pub fn noise_estimate(&mut self) -> Result<Option<f32>, GpuError> {
        let acc = self.path.accumulation;
        let Some(key) = acc.key.filter(|_| acc.samples >= 2) else { return Ok(None) };
        if self.noise_of != Some(acc.samples) {
            let device = self.gpu.device.clone();
            let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("noise") });
            validated(&device, || {
                self.denoiser.encode_stages(&self.gpu, &mut encoder, &Frame::of(&key.basis), 0..1, false);
                Ok(())
            })?;
            self.gpu.checked(|| {
                self.gpu.queue.submit([encoder.finish()]);
                Ok(())
            })?;
            self.noise_of = Some(acc.samples);
        }
        let (w, h) = self.path.size();
        let sum = self.denoiser.read_variance_sum(&self.gpu)?;
        Ok(Some((sum / (3.0 * f64::from(w) * f64::from(h))).sqrt() as f32))
    }

    /// Submits the frame [`Renderer::encode`] recorded, after `before` (the
    /// window's panels upload their buffers in them), as one submit; waits
    /// for path-traced frames and where `wait_for_frames` says so, and
    /// returns the pass's milliseconds (a frame old when it did not wait)
    /// and, for a path-traced frame, what it added.
    ///
    /// # Errors
    /// Any validation error of the frame's commands.
    pub fn submit(
        &mut self,
        before: Vec<wgpu::CommandBuffer>,
        encoder: wgpu::CommandEncoder,
    ) -> Result<Submitted, GpuError> {
        let recorded = self.recorded.take();
        let (gpu, timer) = (&self.gpu, &mut self.timer);
        let wait = self.wait_for_frames || matches!(recorded, Some(Recorded::Path { .. }));
        let ms = gpu.checked(|| {
            let buffers: Vec<wgpu::CommandBuffer> = before.into_iter().chain([encoder.finish()]).collect();
            match recorded {
                None | Some(Recorded::Nothing(_)) => {
                    gpu.queue.submit(buffers);
                    Ok(0.0)
                }
                Some(_) if wait => timer.submit_and_measure(gpu, buffers),
                Some(_) => timer.submit_without_waiting(gpu, buffers),
            }
        })?;
        let path = match recorded {
            Some(Recorded::Path { kernel, effects, prepared }) => {
                let frame = self.path_band_done(ms, kernel, effects);
                if prepared {
                    self.noise_of = Some(frame.samples);
                }
                Some(frame)
            }
            Some(Recorded::Nothing(frame)) => Some(frame),
            _ => None,
        };
        Ok(Submitted { ms, path })
    }

    /// Counts a submitted band of a path-traced sample.
    fn path_band_done(&mut self, ms: f64, kernel: Effects, effects: Effects) -> PathFrame {
        let acc = &mut self.path.accumulation;
        acc.band_ms += ms;
        acc.band.0 = (acc.band.0 + 1) % acc.band.1;
        let added = acc.band.0 == 0;
        acc.samples += u32::from(added);
        PathFrame { ms: acc.band_ms, samples: acc.samples, effects, kernel, lights: acc.lights, added }
    }

    /// Drops the accumulation: the next path-traced frame starts over.
    pub fn forget_path(&mut self) {
        self.path.accumulation.key = None;
    }

    /// Whether [`Renderer::render_path`] with these arguments would start
    /// the accumulation over. The window then traces the preview first: it
    /// is shown until the new accumulation's first sample, which may come
    /// in bands, is complete.
    pub fn path_restarts(&self, view: &PathView, restart: bool, options: &PathOptions) -> bool {
        let resized = self.path.size() != (view.size.0.max(1), view.size.1.max(1));
        self.path.accumulation.starts_over(&path_key(view, options), resized, restart)
    }

    /// Compiles the path kernel a scene needs with `settings` now, so that the
    /// next frames run it rather than the all-effects stand-in.
    ///
    /// # Errors
    /// A kernel that does not compile.
    pub fn compile_path_kernel(&mut self, scene: &Scene, settings: &PathSettings) -> Result<(), GpuError> {
        let effects = effects_for(scene, settings);
        self.path.compile_now(&self.gpu.device, effects, scene.instanced().is_some())
    }

    /// Whether frame times come from GPU timestamps (else the wall clock:
    /// the adapter has none, or they proved implausible).
    pub fn timed_by_gpu(&self) -> bool {
        self.timer.uses_timestamps()
    }

    /// The mean radiance per pixel of the path tracer's accumulation.
    pub fn read_radiance(&self) -> Result<Vec<glam::Vec3>, GpuError> {
        self.path.read_radiance(&self.gpu)
    }

    /// The accumulation's sums and the denoiser's guides of every pixel,
    /// row-major, for a filter on the CPU (`crate::trace::oidn`).
    pub fn read_samples(&self) -> Result<(Vec<Sums>, Vec<Guide>), GpuError> {
        Ok((self.path.read_sums(&self.gpu)?, self.path.read_guides(&self.gpu)?))
    }

    /// The output of the last frame, for the window's blit.
    pub fn output_view(&self) -> &wgpu::TextureView {
        match self.shown {
            Shown::Trace => self.pass.output_view(),
            Shown::Path => self.path.output_view(),
            Shown::Denoised => self.denoiser.output_view().unwrap_or(self.path.output_view()),
        }
    }

    /// The hit records of the last frame, which must have been rendered with
    /// `hit_records` on.
    pub fn read_hits(&self) -> Result<Vec<Hit>, GpuError> {
        if !self.records_written {
            return Err(GpuError::Readback("the last frame wrote no hit records (set Renderer::hit_records)".into()));
        }
        self.pass.read_hits(&self.gpu)
    }

    /// The last frame as an RGBA image.
    pub fn read_image(&self) -> Result<image::RgbaImage, GpuError> {
        let ((w, h), bytes) = match self.shown {
            Shown::Trace => (self.pass.size(), self.pass.read_color(&self.gpu)?),
            Shown::Path => (self.path.size(), self.path.read_color(&self.gpu)?),
            Shown::Denoised => self.denoiser.read_color(&self.gpu)?,
        };
        image::RgbaImage::from_raw(w, h, bytes).ok_or_else(|| GpuError::Readback("texture size mismatch".into()))
    }
}
