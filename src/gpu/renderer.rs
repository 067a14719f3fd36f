//! The scene renderer: device, scene buffers and the trace pass together,
//! with the one encode path of a frame. `render`, `replay`, `bench`, the GPU
//! tests and the window (which blits its output to a surface) all use it.

use glam::IVec3;

use super::scene_buffers::UploadStats;
use super::timer::PassTimer;
use super::{FrameUniforms, GpuContext, GpuError, Kernel, PathPass, PathUniforms, SceneBuffers, TracePass};
use crate::camera::{Camera, RayBasis};
use crate::scene::{Octree, Palette};
use crate::settings::{PathSettings, RenderSettings, View};
use crate::trace::grid::DenseGrid;
use crate::trace::path::materials::{Effects, material_table};
use crate::trace::path::{effects_for, lights};
use crate::trace::{Footprint, Hit};

/// Which pass drew the last frame (the one the window shows).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Shown {
    Trace,
    Path,
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

/// What a path-traced accumulation is of: the scene, the camera, the
/// traced size and the settings. A change to any of them starts it over.
#[derive(Clone, Copy)]
pub struct PathView<'a> {
    pub tree: &'a Octree,
    pub palette: &'a Palette,
    pub camera: &'a Camera,
    pub size: (u32, u32),
    pub settings: &'a PathSettings,
}

fn path_key(view: &PathView) -> PathKey {
    let PathView { tree, palette, camera, size, settings } = *view;
    let basis = camera.basis(size.0.max(1), size.1.max(1), tree.origin());
    PathKey { basis, settings: *settings, effects: effects_for(tree, palette, settings) }
}

/// Whether an accumulation of `key` starts over: the scene or the size
/// changed, or the key (camera, settings, effects) differs from the one
/// `accumulating`.
fn starts_over(accumulating: Option<PathKey>, key: &PathKey, resized: bool, scene_changed: bool) -> bool {
    scene_changed || resized || accumulating != Some(*key)
}

/// What an accumulation is of: a change restarts it.
#[derive(Clone, Copy, Debug, PartialEq)]
struct PathKey {
    basis: RayBasis,
    settings: PathSettings,
    effects: Effects,
}

pub struct Renderer {
    pub gpu: GpuContext,
    pub buffers: SceneBuffers,
    pub pass: TracePass,
    pub path: PathPass,
    timer: PassTimer,
    shown: Shown,
    /// The accumulation's key and sample count.
    path_key: Option<PathKey>,
    path_samples: u32,
    path_lights: usize,
    /// The band of the sample under way, of how many, and the milliseconds
    /// of its bands so far.
    path_band: (u32, u32),
    path_band_ms: f64,
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
    /// The accumulation stops growing at this many samples (the window's
    /// resting view); headless renders leave it unbounded.
    pub sample_target: u32,
    /// Whether frames write the per-pixel hit records that
    /// [`Renderer::read_hits`] returns; off by default, as they cost time.
    pub hit_records: bool,
    /// Whether the last frame wrote them.
    records_written: bool,
    /// Why the last sync could not upload the pool; frames fail with it
    /// until a sync succeeds.
    pool_error: Option<String>,
}

impl Renderer {
    pub fn new(gpu: GpuContext) -> Result<Renderer, GpuError> {
        let buffers = SceneBuffers::new(&gpu.device);
        let pass = TracePass::new(&gpu, &buffers)?;
        let path = PathPass::new(&gpu, &buffers)?;
        let timer = PassTimer::new(&gpu);
        Ok(Renderer {
            gpu,
            buffers,
            pass,
            path,
            timer,
            shown: Shown::Trace,
            path_key: None,
            path_samples: 0,
            path_lights: 0,
            path_band: (0, 1),
            path_band_ms: 0.0,
            path_bands: 1,
            sample_target: u32::MAX,
            wait_for_frames: true,
            hit_records: false,
            records_written: false,
            pool_error: None,
        })
    }

    /// A renderer on the default headless adapter.
    pub fn headless() -> Result<Renderer, GpuError> {
        Renderer::new(GpuContext::headless()?)
    }

    /// Sends the pool's changes since the last call and the palette. A pool
    /// too large for one buffer binding is not sent: frames then fail with
    /// [`GpuError::TooLarge`] saying so, until a sync succeeds.
    pub fn sync(&mut self, tree: &mut Octree, palette: &Palette) -> UploadStats {
        self.buffers.upload_palette(&self.gpu.queue, palette);
        let limit = self.gpu.device.limits().max_storage_buffer_binding_size;
        match self.buffers.upload_pool(&self.gpu.device, &self.gpu.queue, tree, limit) {
            Ok(stats) => {
                self.pool_error = None;
                stats
            }
            Err(err) => {
                self.pool_error = Some(format!("{err} ({})", self.gpu.adapter_name));
                UploadStats::default()
            }
        }
    }

    /// The pool's upload error, as a frame's error.
    fn check_pool(&self) -> Result<(), GpuError> {
        self.pool_error.clone().map_or(Ok(()), |message| Err(GpuError::TooLarge(message)))
    }

    /// Uploads the dense grid the grid tracer walks.
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] when the grid is larger than a binding may be.
    pub fn set_grid(&mut self, grid: &DenseGrid) -> Result<(), GpuError> {
        self.gpu.check_binding("the dense grid", grid.data.len() as u64)?;
        self.buffers.upload_grid(&self.gpu.device, &self.gpu.queue, grid);
        Ok(())
    }

    /// Traces one frame and waits for it; returns the pass's milliseconds.
    /// `highlight` is an inclusive world-space voxel box to tint.
    ///
    /// # Errors
    /// An image larger than the adapter allows, or any validation error
    /// while the frame is recorded: never a silently blank image.
    pub fn render(
        &mut self,
        tree: &Octree,
        camera: &Camera,
        size: (u32, u32),
        settings: &RenderSettings,
        highlight: Option<(IVec3, IVec3)>,
    ) -> Result<f64, GpuError> {
        self.frame(tree, camera, size, (settings.view, settings.lod), highlight, Kernel::from(settings))
    }

    /// A frame of the floor kernel (everything but the traversal, see
    /// `shaders/floor.wgsl`); returns its milliseconds.
    ///
    /// # Errors
    /// As [`Renderer::render`].
    pub fn render_floor(&mut self, tree: &Octree, camera: &Camera, size: (u32, u32)) -> Result<f64, GpuError> {
        self.frame(tree, camera, size, (View::Shaded, 0.0), None, Kernel::Floor)
    }

    /// The one encode path of a frame: outputs sized, uniforms written, the
    /// kernel dispatched and timed, all inside a validation scope.
    fn frame(
        &mut self,
        tree: &Octree,
        camera: &Camera,
        size: (u32, u32),
        (view, lod): (View, f32),
        highlight: Option<(IVec3, IVec3)>,
        kernel: Kernel,
    ) -> Result<f64, GpuError> {
        self.check_pool()?;
        let gpu = &self.gpu;
        gpu.checked(|| {
            self.pass.resize(gpu, &self.buffers, size, self.hit_records)?;
            self.pass.ensure_kernel(gpu, kernel)?;
            let basis = camera.basis(size.0.max(1), size.1.max(1), tree.origin());
            let local = highlight.map(|(lo, hi)| (lo - tree.origin(), hi - tree.origin()));
            let uniforms = FrameUniforms {
                hit_records: u32::from(self.hit_records),
                ..FrameUniforms::new(&basis, tree, &self.buffers, view, local, Footprint::of_pixels(&basis, lod))
            };
            self.records_written = self.hit_records;
            self.shown = Shown::Trace;
            self.pass.prepare(&gpu.device, &gpu.queue, &self.buffers, &uniforms);
            let mut encoder =
                gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame") });
            self.pass.encode(&mut encoder, kernel, self.timer.pass_writes());
            self.timer.resolve(&mut encoder);
            submit(&mut self.timer, gpu, self.wait_for_frames, encoder)
        })
    }

    /// Adds one path-traced sample per pixel to the accumulation and shows
    /// the mean. The accumulation restarts when the camera, the size, the
    /// settings or the effect set change, and when `scene_changed` says the
    /// voxels or the palette did (the materials and lights are then sent
    /// again).
    ///
    /// # Errors
    /// As [`Renderer::render`].
    pub fn render_path(&mut self, view: &PathView, scene_changed: bool) -> Result<PathFrame, GpuError> {
        self.check_pool()?;
        let PathView { tree, palette, size, settings, .. } = *view;
        let gpu = &self.gpu;
        gpu.checked(|| {
            let resized = self.path.resize(gpu, &self.buffers, size)?;
            let key = path_key(view);
            let effects = key.effects;
            // The materials and lights go up again when the scene or the effect set changed.
            let send_scene = scene_changed || resized || self.path_key.is_none_or(|k| k.effects != effects);
            if send_scene {
                let lights = if effects.emit { lights::emitters(tree, palette) } else { Vec::new() };
                self.path.upload_scene(gpu, &self.buffers, &material_table(palette), &lights);
                self.path_lights = lights.len();
            }
            if starts_over(self.path_key, &key, resized, scene_changed) {
                self.path_samples = 0;
                self.path_key = Some(key);
                self.path_band.0 = 0;
            }
            if self.path_band.0 == 0 {
                self.path_band = (0, self.path_bands.clamp(1, size.1.max(1)));
                self.path_band_ms = 0.0;
            }
            let (band, bands) = self.path_band;
            let band_rows = |band: u32| size.1.max(1) * band / bands;
            let (first_row, end_row) = (band_rows(band), band_rows(band + 1));
            if self.path_samples >= self.sample_target && self.shown == Shown::Path {
                let lights = self.path_lights;
                let samples = self.path_samples;
                return Ok(PathFrame { ms: 0.0, samples, effects, kernel: effects, lights, added: false });
            }
            let (sky_horizon, sky_zenith) = settings.sky.colors();
            let path = PathUniforms {
                sky_horizon,
                sample_index: self.path_samples,
                sky_zenith,
                bounces: settings.bounces,
                shadow_samples: settings.shadow_samples,
                emitter_count: self.path_lights as u32,
                first_row,
                end_row,
            };
            let frame = FrameUniforms::new(&key.basis, tree, &self.buffers, View::Shaded, None, Footprint::EXACT);
            self.path.prepare(gpu, &self.buffers, &frame, &path);
            let mut encoder =
                gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("path frame") });
            let rows = end_row - first_row;
            let kernel = self.path.encode(gpu, &mut encoder, effects, rows, self.timer.pass_writes())?;
            self.timer.resolve(&mut encoder);
            self.path_band_ms += submit(&mut self.timer, gpu, true, encoder)?;
            self.path_band.0 = (band + 1) % bands;
            let added = self.path_band.0 == 0;
            self.path_samples += u32::from(added);
            // Until its first sample has every row, the accumulation is not
            // shown: the trace output is (the window traces the preview first).
            self.shown = if self.path_samples > 0 { Shown::Path } else { Shown::Trace };
            let (ms, samples, lights) = (self.path_band_ms, self.path_samples, self.path_lights);
            Ok(PathFrame { ms, samples, effects, kernel, lights, added })
        })
    }

    /// Whether [`Renderer::render_path`] with these arguments would start
    /// the accumulation over. The window then traces the preview first: it
    /// is shown until the new accumulation's first sample, which may come
    /// in bands, is complete.
    pub fn path_restarts(&self, view: &PathView, scene_changed: bool) -> bool {
        let resized = self.path.size() != (view.size.0.max(1), view.size.1.max(1));
        starts_over(self.path_key, &path_key(view), resized, scene_changed)
    }

    /// Compiles the path kernel a scene needs with `settings` now, so that the
    /// next frames run it rather than the all-effects stand-in.
    ///
    /// # Errors
    /// A kernel that does not compile.
    pub fn compile_path_kernel(
        &mut self,
        tree: &Octree,
        palette: &Palette,
        settings: &PathSettings,
    ) -> Result<(), GpuError> {
        let effects = effects_for(tree, palette, settings);
        self.path.compile_now(&self.gpu.device, effects)
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

    /// The output of the last frame, for the window's blit.
    pub fn output_view(&self) -> &wgpu::TextureView {
        match self.shown {
            Shown::Trace => self.pass.output_view(),
            Shown::Path => self.path.output_view(),
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
        };
        image::RgbaImage::from_raw(w, h, bytes).ok_or_else(|| GpuError::Readback("texture size mismatch".into()))
    }
}

/// Submits a frame: waits for it and returns its milliseconds, or, without
/// `wait`, returns at once with the latest time read back (an earlier frame's).
fn submit(timer: &mut PassTimer, gpu: &GpuContext, wait: bool, encoder: wgpu::CommandEncoder) -> Result<f64, GpuError> {
    if wait { timer.submit_and_measure(gpu, encoder) } else { timer.submit_without_waiting(gpu, encoder) }
}
