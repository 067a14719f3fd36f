//! The progressive path tracing pass: one sample per pixel per dispatch,
//! accumulated in a float buffer (with the sums of squares, and the
//! denoiser's guides from the first sample), the mean written to a display
//! texture.
//!
//! The kernel is compiled per effect set and per scene kind (override
//! constants of `shaders/path.wgsl` and `shaders/instances.wgsl`) on worker
//! threads and kept, so a diffuse-only scene runs a kernel without metal,
//! glass or emitter code, a scene not drawn as instances one without the
//! instance walk, and a scene that gains an effect runs the kernel with
//! every effect (the same image) until its own is compiled.

use super::bindings;
use std::collections::HashMap;
use std::sync::mpsc;

use glam::Vec3;

use super::context::compute_pipeline;
use super::layout::{
    FrameUniforms, PathUniforms, buffer_entry, buffer_resource, constants_buffer, constants_entry, output_entry,
    output_texture,
};
use super::readback::{read_storage, read_texture_rgba8};
use super::shaders::Module;
use super::{GpuContext, GpuError, SceneBuffers};
use crate::camera::RayBasis;
use crate::settings::PathSettings;
use crate::trace::denoise::{Guide, Sums};
use crate::trace::path::lights::Emitter;
use crate::trace::path::materials::{Effects, GpuMaterial};

/// A kernel: compiled, or being compiled on a worker thread.
enum Compiled {
    Ready(wgpu::ComputePipeline),
    Compiling(mpsc::Receiver<Result<wgpu::ComputePipeline, GpuError>>),
}

fn thread_gone() -> GpuError {
    GpuError::Shader { name: "path tracer".into(), message: "the compile thread ended without a result".into() }
}

/// What a path kernel is compiled for: the effects, and whether the scene
/// is drawn as instances (the instance walk compiled in).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
struct KernelKey {
    effects: Effects,
    instances: bool,
}

impl KernelKey {
    /// The stand-in while this kernel compiles: every effect, for the same
    /// kind of scene.
    fn stand_in(self) -> KernelKey {
        KernelKey { effects: Effects::ALL, ..self }
    }
}

/// Compiles the path kernel for a key (on any thread).
fn compile(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    key: KernelKey,
) -> Result<wgpu::ComputePipeline, GpuError> {
    let mut constants = key.effects.constants().to_vec();
    constants.push(("INSTANCES", if key.instances { 1.0 } else { 0.0 }));
    compute_pipeline(device, layout, module, "path", &constants, "path tracer")
}

const EMITTER_BYTES: u64 = std::mem::size_of::<Emitter>() as u64;
/// Bytes per pixel of the accumulation: sums and count, sums of squares,
/// sums of the first hits' albedo.
pub const ACCUM_BYTES: u64 = 48;
/// Bytes per pixel of the denoiser's guides.
pub const GUIDE_BYTES: u64 = std::mem::size_of::<Guide>() as u64;

/// Size-dependent outputs.
struct Target {
    texture: wgpu::Texture,
    view: wgpu::TextureView,
    /// Three vec4 per pixel: the RGB sums and the sample count, the sums of
    /// squares, the sums of the first hits' albedo.
    accum: wgpu::Buffer,
    /// The denoiser's [`Guide`] per pixel, written by the first sample.
    guides: wgpu::Buffer,
    width: u32,
    height: u32,
}

pub struct PathPass {
    layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    module: wgpu::ShaderModule,
    kernels: HashMap<KernelKey, Compiled>,
    frame_buf: wgpu::Buffer,
    path_buf: wgpu::Buffer,
    materials_buf: wgpu::Buffer,
    emitters_buf: wgpu::Buffer,
    target: Target,
    bind_group: wgpu::BindGroup,
    bound_generation: u64,
    /// The accumulation's state on the CPU side: what it is of, its samples.
    pub accumulation: Accumulation,
}

/// What an accumulation is of: a change restarts it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathKey {
    pub basis: RayBasis,
    pub settings: PathSettings,
    pub effects: Effects,
    /// The world box of voxels tinted (`PathOptions::highlight`).
    pub highlight: Option<(glam::IVec3, glam::IVec3)>,
    /// The ground grid drawn (`PathOptions::grid`), in world voxels.
    pub ground: Option<super::layout::GroundGrid>,
    /// The scene's revision (`Scene::revision`): an edit starts over.
    pub revision: u64,
}

/// The path tracer's accumulation: its key, the samples so far, the lights
/// sent with the scene, and the band of the sample under way (of how many,
/// and the milliseconds of its bands so far).
#[derive(Clone, Copy, Debug)]
pub struct Accumulation {
    pub key: Option<PathKey>,
    pub samples: u32,
    pub lights: usize,
    pub band: (u32, u32),
    pub band_ms: f64,
}

impl Default for Accumulation {
    fn default() -> Accumulation {
        Accumulation { key: None, samples: 0, lights: 0, band: (0, 1), band_ms: 0.0 }
    }
}

impl Accumulation {
    /// Whether an accumulation of `key` starts over: the scene or the size
    /// changed, or the key (camera, settings, effects) differs.
    pub fn starts_over(&self, key: &PathKey, resized: bool, restart: bool) -> bool {
        restart || resized || self.key != Some(*key)
    }
}

/// The pass's own buffers that its bind group holds.
struct BindParts<'a> {
    frame: &'a wgpu::Buffer,
    path: &'a wgpu::Buffer,
    materials: &'a wgpu::Buffer,
    emitters: &'a wgpu::Buffer,
}

fn make_bind_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    buffers: &SceneBuffers,
    parts: &BindParts,
    target: &Target,
) -> wgpu::BindGroup {
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("path bind group"),
        layout,
        entries: &[
            buffer_resource(bindings::FRAME_CONSTANTS, parts.frame),
            buffer_resource(bindings::POOL, &buffers.pool_buf),
            buffer_resource(bindings::INSTANCES, &buffers.instances_buf),
            buffer_resource(bindings::PALETTE, &buffers.palette_buf),
            wgpu::BindGroupEntry {
                binding: bindings::OUT_COLOR,
                resource: wgpu::BindingResource::TextureView(&target.view),
            },
            buffer_resource(bindings::PATH_CONSTANTS, parts.path),
            buffer_resource(bindings::MATERIALS, parts.materials),
            buffer_resource(bindings::EMITTERS, parts.emitters),
            buffer_resource(bindings::ACCUM, &target.accum),
            buffer_resource(bindings::GUIDES, &target.guides),
        ],
    })
}

fn storage(device: &wgpu::Device, label: &str, size: u64, extra: wgpu::BufferUsages) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size.max(16),
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | extra,
        mapped_at_creation: false,
    })
}

impl PathPass {
    pub fn new(gpu: &GpuContext, buffers: &SceneBuffers) -> Result<PathPass, GpuError> {
        let device = &gpu.device;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("path bind group layout"),
            entries: &[
                constants_entry(bindings::FRAME_CONSTANTS, std::mem::size_of::<FrameUniforms>()),
                buffer_entry(bindings::POOL, true),
                buffer_entry(bindings::INSTANCES, true),
                buffer_entry(bindings::PALETTE, true),
                output_entry(bindings::OUT_COLOR),
                constants_entry(bindings::PATH_CONSTANTS, std::mem::size_of::<PathUniforms>()),
                buffer_entry(bindings::MATERIALS, true),
                buffer_entry(bindings::EMITTERS, true),
                buffer_entry(bindings::ACCUM, false),
                buffer_entry(bindings::GUIDES, false),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("path pipeline layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let module = gpu.module(Module::Path)?;
        let frame_buf = constants_buffer(device, "path frame uniforms", std::mem::size_of::<FrameUniforms>());
        let path_buf = constants_buffer(device, "path uniforms", std::mem::size_of::<PathUniforms>());
        let materials_buf =
            storage(device, "materials", 256 * std::mem::size_of::<GpuMaterial>() as u64, wgpu::BufferUsages::empty());
        // A binding holds at least one element, even when there are no lights.
        let emitters_buf = storage(device, "emitters", EMITTER_BYTES, wgpu::BufferUsages::empty());
        let target = Self::make_target(device, 1, 1);
        let parts =
            BindParts { frame: &frame_buf, path: &path_buf, materials: &materials_buf, emitters: &emitters_buf };
        let bind_group = make_bind_group(device, &layout, buffers, &parts, &target);
        Ok(PathPass {
            layout,
            pipeline_layout,
            module,
            kernels: HashMap::new(),
            frame_buf,
            path_buf,
            materials_buf,
            emitters_buf,
            target,
            bind_group,
            bound_generation: buffers.generation,
            accumulation: Accumulation::default(),
        })
    }

    fn make_target(device: &wgpu::Device, width: u32, height: u32) -> Target {
        let (texture, view) = output_texture(device, "path output", width, height);
        let pixels = u64::from(width) * u64::from(height);
        let accum = storage(device, "accumulation", pixels * ACCUM_BYTES, wgpu::BufferUsages::COPY_SRC);
        let guides = storage(device, "denoise guides", pixels * GUIDE_BYTES, wgpu::BufferUsages::COPY_SRC);
        Target { texture, view, accum, guides, width, height }
    }

    fn rebind(&mut self, device: &wgpu::Device, buffers: &SceneBuffers) {
        let parts = BindParts {
            frame: &self.frame_buf,
            path: &self.path_buf,
            materials: &self.materials_buf,
            emitters: &self.emitters_buf,
        };
        self.bind_group = make_bind_group(device, &self.layout, buffers, &parts, &self.target);
        self.bound_generation = buffers.generation;
    }

    /// Starts compiling a kernel on a worker thread (on the desktop).
    fn start(&mut self, device: &wgpu::Device, key: KernelKey) {
        if self.kernels.contains_key(&key) {
            return;
        }
        let (tx, rx) = mpsc::channel();
        let (device, layout, module) = (device.clone(), self.pipeline_layout.clone(), self.module.clone());
        // The receiver may be gone (the pass was dropped): nothing to do then.
        let work = move || {
            let _ = tx.send(compile(&device, &layout, &module, key));
        };
        #[cfg(not(target_arch = "wasm32"))]
        std::thread::spawn(work);
        // The browser's page has one thread here: the kernel is compiled now
        // (WebGPU compiles it asynchronously behind the handle anyway).
        #[cfg(target_arch = "wasm32")]
        work();
        self.kernels.insert(key, Compiled::Compiling(rx));
    }

    /// Whether the kernel of `key` is ready, taking a finished compile.
    fn ready(&mut self, key: KernelKey, wait: bool) -> Result<bool, GpuError> {
        let Some(Compiled::Compiling(rx)) = self.kernels.get(&key) else {
            return Ok(self.kernels.contains_key(&key));
        };
        let result = if wait {
            rx.recv().map_err(|_| thread_gone())?
        } else {
            match rx.try_recv() {
                Ok(result) => result,
                Err(mpsc::TryRecvError::Empty) => return Ok(false),
                Err(mpsc::TryRecvError::Disconnected) => Err(thread_gone()),
            }
        };
        match result {
            Ok(pipeline) => {
                self.kernels.insert(key, Compiled::Ready(pipeline));
                Ok(true)
            }
            Err(err) => {
                self.kernels.remove(&key);
                Err(err)
            }
        }
    }

    /// The kernel that runs now for `key`: its own once compiled; until
    /// then the kernel with every effect, if that one is ready (it draws the
    /// same image, see `bench effects`), so a new one is compiled off the
    /// frame path; on first use, its own after a wait.
    fn kernel_for(&mut self, device: &wgpu::Device, key: KernelKey) -> Result<KernelKey, GpuError> {
        let stand_in = key.stand_in();
        self.start(device, key);
        if self.ready(key, false)? {
            self.start(device, stand_in);
            return Ok(key);
        }
        if self.ready(stand_in, false)? {
            return Ok(stand_in);
        }
        self.ready(key, true)?;
        self.start(device, stand_in);
        Ok(key)
    }

    /// Re-creates the outputs for a new size; returns whether it did (the
    /// accumulation then starts over).
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] when the image or its accumulation buffer
    /// exceed the adapter's limits; the old outputs are kept.
    pub fn resize(
        &mut self,
        gpu: &GpuContext,
        buffers: &SceneBuffers,
        (width, height): (u32, u32),
    ) -> Result<bool, GpuError> {
        let (width, height) = (width.max(1), height.max(1));
        if (width, height) == (self.target.width, self.target.height) {
            return Ok(false);
        }
        gpu.check_image_size(width, height)?;
        gpu.check_binding("the accumulation buffer", u64::from(width) * u64::from(height) * ACCUM_BYTES)?;
        self.target = Self::make_target(&gpu.device, width, height);
        self.rebind(&gpu.device, buffers);
        Ok(true)
    }

    pub fn size(&self) -> (u32, u32) {
        (self.target.width, self.target.height)
    }

    pub fn output_view(&self) -> &wgpu::TextureView {
        &self.target.view
    }

    /// Uploads the material table and the emitter list (on a restart).
    pub fn upload_scene(
        &mut self,
        gpu: &GpuContext,
        buffers: &SceneBuffers,
        materials: &[GpuMaterial],
        lights: &[Emitter],
    ) {
        gpu.queue.write_buffer(&self.materials_buf, 0, bytemuck::cast_slice(materials));
        let bytes: &[u8] = bytemuck::cast_slice(lights);
        if bytes.len() as u64 > self.emitters_buf.size() {
            self.emitters_buf = storage(&gpu.device, "emitters", bytes.len() as u64, wgpu::BufferUsages::empty());
            self.rebind(&gpu.device, buffers);
        }
        if !bytes.is_empty() {
            gpu.queue.write_buffer(&self.emitters_buf, 0, bytes);
        }
    }

    /// Writes this sample's uniforms and rebinds re-created scene buffers.
    pub fn prepare(&mut self, gpu: &GpuContext, buffers: &SceneBuffers, frame: &FrameUniforms, path: &PathUniforms) {
        if buffers.generation != self.bound_generation {
            self.rebind(&gpu.device, buffers);
        }
        gpu.queue.write_buffer(&self.frame_buf, 0, bytemuck::bytes_of(frame));
        gpu.queue.write_buffer(&self.path_buf, 0, bytemuck::bytes_of(path));
    }

    /// Compiles the kernel of `effects` (for a scene of objects when
    /// `instances`) now if it is not ready (benchmarks time the kernel of a
    /// set, not its stand-in).
    pub fn compile_now(&mut self, device: &wgpu::Device, effects: Effects, instances: bool) -> Result<(), GpuError> {
        let key = KernelKey { effects, instances };
        self.start(device, key);
        self.ready(key, true).map(|_| ())
    }

    /// Records one sample's dispatch for `effects` (in a scene of objects
    /// when `instances`) over `rows` rows (the uniforms' band); returns the
    /// effect set of the kernel that ran (see [`PathPass::kernel_for`]).
    pub fn encode(
        &mut self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        (effects, instances): (Effects, bool),
        rows: u32,
        timestamps: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) -> Result<Effects, GpuError> {
        let width = self.size().0;
        let used = self.kernel_for(&gpu.device, KernelKey { effects, instances })?;
        let Some(Compiled::Ready(pipeline)) = self.kernels.get(&used) else { return Err(thread_gone()) };
        let mut pass = encoder
            .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("path"), timestamp_writes: timestamps });
        pass.set_bind_group(0, &self.bind_group, &[]);
        pass.set_pipeline(pipeline);
        pass.dispatch_workgroups(width.div_ceil(8), rows.div_ceil(8), 1);
        Ok(used.effects)
    }

    /// The mean radiance of every pixel so far, row-major.
    pub fn read_radiance(&self, gpu: &GpuContext) -> Result<Vec<Vec3>, GpuError> {
        Ok(self.read_sums(gpu)?.iter().map(Sums::mean).collect())
    }

    /// The accumulation's sums of every pixel, row-major.
    pub fn read_sums(&self, gpu: &GpuContext) -> Result<Vec<Sums>, GpuError> {
        let words: Vec<[f32; 4]> = read_storage(gpu, &self.target.accum, "accumulation readback")?;
        let pixels = (self.target.width * self.target.height) as usize;
        let rgb = |v: [f32; 4]| Vec3::new(v[0], v[1], v[2]);
        let sums = words.chunks_exact(3).take(pixels);
        Ok(sums
            .map(|p| Sums { sum: rgb(p[0]), squares: rgb(p[1]), albedo: rgb(p[2]), count: p[0][3] as u32 })
            .collect())
    }

    /// The denoiser's guides of every pixel, row-major.
    pub fn read_guides(&self, gpu: &GpuContext) -> Result<Vec<Guide>, GpuError> {
        let guides: Vec<Guide> = read_storage(gpu, &self.target.guides, "guide readback")?;
        Ok(guides.into_iter().take((self.target.width * self.target.height) as usize).collect())
    }

    /// The buffers the denoiser reads: the accumulation and the guides.
    pub fn sample_buffers(&self) -> (&wgpu::Buffer, &wgpu::Buffer) {
        (&self.target.accum, &self.target.guides)
    }

    /// The display texture as tightly packed RGBA8 rows.
    pub fn read_color(&self, gpu: &GpuContext) -> Result<Vec<u8>, GpuError> {
        read_texture_rgba8(gpu, &self.target.texture)
    }
}
