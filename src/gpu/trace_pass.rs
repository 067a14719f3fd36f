//! The ray tracing compute pass: one thread per pixel walks the SVO (or the
//! dense grid) and writes a colour texture plus a hit record per pixel.

use bytemuck::{Pod, Zeroable};
use glam::IVec3;

use super::context::compute_pipeline;
use super::prelude::with_prelude;
use super::readback::{read_storage, read_texture_rgba8};
use super::{GpuContext, GpuError, SceneBuffers};
use crate::camera::RayBasis;
use crate::scene::Octree;
use crate::settings::{RenderSettings, TraceMode, View};
use crate::trace::{Footprint, Hit};

const COMMON_WGSL: &str = include_str!("../../shaders/common.wgsl");
const SVO_WGSL: &str = include_str!("../../shaders/trace_svo.wgsl");
const GRID_WGSL: &str = include_str!("../../shaders/trace_grid.wgsl");
const FLOOR_WGSL: &str = include_str!("../../shaders/floor.wgsl");

/// What a frame dispatches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kernel {
    /// The scene, traced (the SVO with its beam prepass, or the grid);
    /// `lod`: the SVO kernels with the level-of-detail test compiled in.
    Trace { mode: TraceMode, shadows: bool, lod: bool },
    /// Everything but the traversal: the floor a frame cannot go below.
    Floor,
}

impl From<&RenderSettings> for Kernel {
    fn from(settings: &RenderSettings) -> Kernel {
        let lod = settings.mode == TraceMode::Svo && settings.lod > 0.0;
        Kernel::Trace { mode: settings.mode, shadows: settings.shadows, lod }
    }
}

/// Twin of `FrameUniforms` in `shaders/common.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct FrameUniforms {
    pub eye: [f32; 3],
    pub root: u32,
    pub forward: [f32; 3],
    pub depth: u32,
    pub right: [f32; 3],
    pub view: u32,
    pub up: [f32; 3],
    pub width: u32,
    pub grid_min: [i32; 3],
    pub height: u32,
    pub grid_dims: [u32; 3],
    pub highlight_on: u32,
    pub highlight_min: [i32; 3],
    /// 1: write the per-pixel hit records (see [`TracePass::read_hits`]).
    pub hit_records: u32,
    pub highlight_max: [i32; 3],
    /// Word index of the first brick in the pool buffer.
    pub brick_base: u32,
    /// `crate::trace::iteration_bound` of the tree: no valid ray reaches it.
    pub max_iterations: u32,
    /// Level of detail: [`crate::trace::Footprint::per_t`] of camera rays.
    pub lod_per_t: f32,
    pub _pad: [u32; 2],
}

impl FrameUniforms {
    /// Uniforms for a frame: camera basis, tree root and grid placement.
    /// `highlight` is an inclusive tree-local voxel box to tint.
    pub fn new(
        basis: &RayBasis,
        tree: &Octree,
        buffers: &SceneBuffers,
        view: View,
        highlight: Option<(IVec3, IVec3)>,
        lod: Footprint,
    ) -> FrameUniforms {
        let (lo, hi) = highlight.unwrap_or((IVec3::ZERO, IVec3::NEG_ONE));
        FrameUniforms {
            eye: basis.eye.into(),
            root: tree.root_word(),
            forward: basis.forward.into(),
            depth: tree.depth(),
            right: basis.right.into(),
            view: view.code(),
            up: basis.up.into(),
            width: basis.width,
            grid_min: buffers.grid_min.into(),
            height: basis.height,
            grid_dims: buffers.grid_dims.into(),
            highlight_on: u32::from(highlight.is_some()),
            highlight_min: lo.into(),
            hit_records: 0,
            highlight_max: hi.into(),
            brick_base: buffers.brick_base(),
            max_iterations: crate::trace::iteration_bound(tree.depth()),
            lod_per_t: lod.per_t,
            _pad: [0; 2],
        }
    }
}

/// Size-dependent outputs: the colour texture and the hit records.
struct Target {
    texture: wgpu::Texture,
    view: wgpu::TextureView,
    hits_buf: wgpu::Buffer,
    /// One f32 per tile of BEAM_TILE² pixels, written by the beam prepass.
    beam_buf: wgpu::Buffer,
    /// The tiles the beam found something in (`TracedTiles`: a count,
    /// zeroed each frame, then a u32 per tile) and the indirect dispatch
    /// arguments of the trace made from it (three u32).
    traced_tiles: wgpu::Buffer,
    dispatch_args: wgpu::Buffer,
    width: u32,
    height: u32,
    /// Whether `hits_buf` holds a record per pixel.
    hit_records: bool,
}

/// Side of the pixel tile that shares one beam; it sizes the beam buffer and
/// sets the shader's `BEAM_TILE` override.
const BEAM_TILE: u32 = 16;
// The per-pixel kernels cover a tile with 8×8 workgroups.
const _: () = assert!(BEAM_TILE.is_multiple_of(8));

/// The beam's list of traced tiles is dispatched in rows of this many tiles
/// (a dispatch is at most 65535 workgroups per axis); it has room for every
/// tile, rounded up to whole rows.
pub(super) const ROW_TILES: u64 = 64;

/// The floor kernel's workgroups are rows of this many pixels: 256 bytes of
/// the output, four cache lines, each shared with another workgroup only at
/// the row's ends. An 8×8 workgroup wrote half a line per row and left the
/// other half to a neighbour that lavapipe runs on another thread: with
/// rows, the floor takes 22 % less time and an SVO frame 6–12 % less (A/B,
/// docs/traversal.md).
pub(super) const FLOOR_ROW: u32 = 64;

/// Pipelines are compiled per tracer and per shadow setting (an override
/// constant), so a scene rendered without shadows pays nothing for them. The
/// SVO frame runs in four dispatches: the floor kernel draws every pixel as
/// sky, the beam prepass (one thread per tile of pixels) lists the tiles with
/// something in them, a one-thread kernel turns their count into a dispatch
/// size, and the per-pixel trace (which starts where the beam allows) runs on
/// those tiles only.
pub struct TracePass {
    layout: wgpu::BindGroupLayout,
    /// Group 1 of `tile_dispatch`: the indirect arguments it writes.
    args_layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    /// [svo without shadows, svo with, grid without, grid with].
    pipelines: [wgpu::ComputePipeline; 4],
    beam: wgpu::ComputePipeline,
    tile_dispatch: wgpu::ComputePipeline,
    /// The SVO kernels with level of detail, compiled on first use from
    /// `svo`: [without shadows, with shadows, beam].
    lod_pipelines: Option<[wgpu::ComputePipeline; 3]>,
    svo: wgpu::ShaderModule,
    floor: wgpu::ComputePipeline,
    uniform_buf: wgpu::Buffer,
    target: Target,
    bind_group: wgpu::BindGroup,
    args_bind_group: wgpu::BindGroup,
    bound_generation: u64,
}

/// A compute-visible binding of a frame's constants (`size` bytes): a
/// read-only storage buffer, not a uniform buffer. Lavapipe (Mesa 22)
/// compiles a kernel again, on the queue, whenever its uniform buffer is
/// bound anew, with the values that decide branches folded in ("inlined
/// uniforms"): 70–100 ms stalls every few frames while the camera moved.
/// No uniform buffer, nothing to fold in.
pub(super) fn constants_entry(binding: u32, size: usize) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: wgpu::BufferSize::new(size as u64),
        },
        count: None,
    }
}

/// The buffer behind a `constants_entry` binding, written each frame.
pub(super) fn constants_buffer(device: &wgpu::Device, label: &str, size: usize) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size as u64,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// The binding of the RGBA8 output texture a kernel writes.
pub(super) fn output_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format: wgpu::TextureFormat::Rgba8Unorm,
            view_dimension: wgpu::TextureViewDimension::D2,
        },
        count: None,
    }
}

/// The RGBA8 texture a kernel writes and the blit (or a readback) reads.
pub(super) fn output_texture(
    device: &wgpu::Device,
    label: &str,
    width: u32,
    height: u32,
) -> (wgpu::Texture, wgpu::TextureView) {
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8Unorm,
        usage: wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
    (texture, view)
}

pub(super) fn buffer_entry(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

impl TracePass {
    /// The pipelines and a 1×1 output; [`TracePass::resize`] sizes it.
    pub fn new(gpu: &GpuContext, buffers: &SceneBuffers) -> Result<TracePass, GpuError> {
        let device = &gpu.device;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("trace bind group layout"),
            entries: &[
                constants_entry(0, std::mem::size_of::<FrameUniforms>()),
                buffer_entry(1, true),
                buffer_entry(3, true),
                buffer_entry(4, true),
                output_entry(5),
                buffer_entry(6, false),
                buffer_entry(7, false),
                buffer_entry(12, false),
            ],
        });
        let args_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("dispatch arguments layout"),
            entries: &[buffer_entry(0, false)],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("trace pipeline layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let args_pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("tile dispatch pipeline layout"),
            bind_group_layouts: &[Some(&layout), Some(&args_layout)],
            immediate_size: 0,
        });
        let svo = gpu.shader("trace_svo.wgsl", &with_prelude(&[COMMON_WGSL, SVO_WGSL]))?;
        let grid = gpu.shader("trace_grid.wgsl", &with_prelude(&[COMMON_WGSL, GRID_WGSL]))?;
        let pipeline = |module, entry, constants: &[(&str, f64)], label| {
            compute_pipeline(&gpu.device, &pipeline_layout, module, entry, constants, label)
        };
        let tile = ("BEAM_TILE", f64::from(BEAM_TILE));
        let pipelines = [
            pipeline(&svo, "main", &[("SHADOWS", 0.0), tile], "trace svo")?,
            pipeline(&svo, "main", &[("SHADOWS", 1.0), tile], "trace svo + shadows")?,
            pipeline(&grid, "main", &[("SHADOWS", 0.0)], "trace grid")?,
            pipeline(&grid, "main", &[("SHADOWS", 1.0)], "trace grid + shadows")?,
        ];
        let beam = pipeline(&svo, "beam", &[tile], "beam prepass")?;
        let tile_dispatch =
            compute_pipeline(&gpu.device, &args_pipeline_layout, &svo, "tile_dispatch", &[tile], "tile dispatch")?;
        let floor_module = gpu.shader("floor.wgsl", &with_prelude(&[COMMON_WGSL, FLOOR_WGSL]))?;
        let floor = pipeline(&floor_module, "main", &[], "floor")?;
        let uniform_buf = constants_buffer(device, "frame uniforms", std::mem::size_of::<FrameUniforms>());
        let target = Self::make_target(device, 1, 1, false);
        let bind_group = Self::make_bind_group(device, &layout, &uniform_buf, buffers, &target);
        let args_bind_group = Self::make_args_bind_group(device, &args_layout, &target);
        let bound_generation = buffers.generation;
        Ok(TracePass {
            layout,
            args_layout,
            pipeline_layout,
            pipelines,
            beam,
            tile_dispatch,
            lod_pipelines: None,
            svo,
            floor,
            uniform_buf,
            target,
            bind_group,
            args_bind_group,
            bound_generation,
        })
    }

    /// Compiles the level-of-detail kernels if `kernel` needs them and they
    /// are not compiled yet (a frame with `--lod` above 0).
    ///
    /// # Errors
    /// A kernel that does not compile.
    pub fn ensure_kernel(&mut self, gpu: &GpuContext, kernel: Kernel) -> Result<(), GpuError> {
        if !matches!(kernel, Kernel::Trace { lod: true, .. }) || self.lod_pipelines.is_some() {
            return Ok(());
        }
        let pipeline = |entry, constants: &[(&str, f64)], label| {
            compute_pipeline(&gpu.device, &self.pipeline_layout, &self.svo, entry, constants, label)
        };
        let (tile, lod) = (("BEAM_TILE", f64::from(BEAM_TILE)), ("LOD", 1.0));
        self.lod_pipelines = Some([
            pipeline("main", &[("SHADOWS", 0.0), tile, lod], "trace svo, lod")?,
            pipeline("main", &[("SHADOWS", 1.0), tile, lod], "trace svo + shadows, lod")?,
            pipeline("beam", &[tile, lod], "beam prepass, lod")?,
        ]);
        Ok(())
    }

    /// The outputs; the hit records (16 bytes a pixel) only when asked for,
    /// so that a large image does not need a buffer past the binding limit.
    fn make_target(device: &wgpu::Device, width: u32, height: u32, hit_records: bool) -> Target {
        let (width, height) = (width.max(1), height.max(1));
        let (texture, view) = output_texture(device, "trace output", width, height);
        let buffer = |label, size, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::STORAGE | usage,
                mapped_at_creation: false,
            })
        };
        let hits_buf =
            buffer("hit records", Self::hits_bytes(width, height, hit_records), wgpu::BufferUsages::COPY_SRC);
        let tiles = u64::from(width.div_ceil(BEAM_TILE)) * u64::from(height.div_ceil(BEAM_TILE));
        let beam_buf = buffer("beam distances", tiles * 4, wgpu::BufferUsages::empty());
        let traced_tiles =
            buffer("traced tiles", 4 + tiles.next_multiple_of(ROW_TILES) * 4, wgpu::BufferUsages::COPY_DST);
        let dispatch_args = buffer("trace dispatch arguments", 12, wgpu::BufferUsages::INDIRECT);
        Target { texture, view, hits_buf, beam_buf, traced_tiles, dispatch_args, width, height, hit_records }
    }

    fn make_args_bind_group(device: &wgpu::Device, layout: &wgpu::BindGroupLayout, target: &Target) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("dispatch arguments"),
            layout,
            entries: &[wgpu::BindGroupEntry { binding: 0, resource: target.dispatch_args.as_entire_binding() }],
        })
    }

    fn make_bind_group(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        uniform_buf: &wgpu::Buffer,
        buffers: &SceneBuffers,
        target: &Target,
    ) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("trace bind group"),
            layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: uniform_buf.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: buffers.pool_buf.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 3, resource: buffers.palette_buf.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 4, resource: buffers.grid_buf.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 5, resource: wgpu::BindingResource::TextureView(&target.view) },
                wgpu::BindGroupEntry { binding: 6, resource: target.hits_buf.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 7, resource: target.beam_buf.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 12, resource: target.traced_tiles.as_entire_binding() },
            ],
        })
    }

    fn hits_bytes(width: u32, height: u32, hit_records: bool) -> u64 {
        if hit_records { u64::from(width) * u64::from(height) * 16 } else { 16 }
    }

    /// Re-creates the outputs for a new size (never zero) or when hit
    /// records are turned on or off.
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] when the image or its hit records exceed the
    /// adapter's limits; the old outputs are kept.
    pub fn resize(
        &mut self,
        gpu: &GpuContext,
        buffers: &SceneBuffers,
        (width, height): (u32, u32),
        hit_records: bool,
    ) -> Result<(), GpuError> {
        let (width, height) = (width.max(1), height.max(1));
        let target = &self.target;
        if (width, height, hit_records) == (target.width, target.height, target.hit_records) {
            return Ok(());
        }
        gpu.check_image_size(width, height)?;
        gpu.check_binding("the hit records", Self::hits_bytes(width, height, hit_records))?;
        let device = &gpu.device;
        self.target = Self::make_target(device, width, height, hit_records);
        self.bind_group = Self::make_bind_group(device, &self.layout, &self.uniform_buf, buffers, &self.target);
        self.args_bind_group = Self::make_args_bind_group(device, &self.args_layout, &self.target);
        self.bound_generation = buffers.generation;
        Ok(())
    }

    pub fn size(&self) -> (u32, u32) {
        (self.target.width, self.target.height)
    }

    /// The colour output, for the blit to the window.
    pub fn output_view(&self) -> &wgpu::TextureView {
        &self.target.view
    }

    /// Writes this frame's uniforms and rebinds buffers that were re-created.
    pub fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        buffers: &SceneBuffers,
        uniforms: &FrameUniforms,
    ) {
        if buffers.generation != self.bound_generation {
            self.bind_group = Self::make_bind_group(device, &self.layout, &self.uniform_buf, buffers, &self.target);
            self.bound_generation = buffers.generation;
        }
        queue.write_buffer(&self.uniform_buf, 0, bytemuck::bytes_of(uniforms));
    }

    /// Records the dispatches: for the SVO the sky (the floor kernel), the
    /// beam prepass, the trace's size and the trace of the listed tiles; for
    /// the grid its per-pixel kernel; or the floor alone.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        kernel: Kernel,
        timestamps: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) {
        if matches!(kernel, Kernel::Trace { mode: TraceMode::Svo, .. }) {
            // The beam prepass appends to the list of traced tiles from zero.
            encoder.clear_buffer(&self.target.traced_tiles, 0, Some(4));
        }
        let mut pass = encoder
            .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("trace"), timestamp_writes: timestamps });
        pass.set_bind_group(0, &self.bind_group, &[]);
        let (mode, shadows, lod) = match kernel {
            Kernel::Trace { mode, shadows, lod } => (mode, shadows, lod),
            Kernel::Floor => {
                self.encode_floor(&mut pass);
                return;
            }
        };
        let index = match mode {
            TraceMode::Svo => 0,
            TraceMode::Grid => 2,
        } + usize::from(shadows);
        // `ensure_kernel` compiled these; without them the exact kernels run.
        let lod_pipelines = self.lod_pipelines.as_ref().filter(|_| lod);
        let trace = lod_pipelines.map_or(&self.pipelines[index], |p| &p[usize::from(shadows)]);
        if mode == TraceMode::Grid {
            pass.set_pipeline(trace);
            pass.dispatch_workgroups(self.target.width.div_ceil(8), self.target.height.div_ceil(8), 1);
            return;
        }
        self.encode_floor(&mut pass);
        let (tiles_x, tiles_y) = (self.target.width.div_ceil(BEAM_TILE), self.target.height.div_ceil(BEAM_TILE));
        pass.set_pipeline(lod_pipelines.map_or(&self.beam, |p| &p[2]));
        pass.dispatch_workgroups(tiles_x.div_ceil(8), tiles_y.div_ceil(8), 1);
        pass.set_pipeline(&self.tile_dispatch);
        pass.set_bind_group(1, &self.args_bind_group, &[]);
        pass.dispatch_workgroups(1, 1, 1);
        pass.set_pipeline(trace);
        pass.dispatch_workgroups_indirect(&self.target.dispatch_args, 0);
    }

    /// Every pixel as a miss: the floor of a frame, and the sky of an SVO
    /// frame under the tiles the trace then draws over.
    fn encode_floor(&self, pass: &mut wgpu::ComputePass<'_>) {
        pass.set_pipeline(&self.floor);
        pass.dispatch_workgroups(self.target.width.div_ceil(FLOOR_ROW), self.target.height, 1);
    }

    /// Reads back the hit record of every pixel.
    pub fn read_hits(&self, gpu: &GpuContext) -> Result<Vec<Hit>, GpuError> {
        let records: Vec<[u32; 4]> = read_storage(gpu, &self.target.hits_buf, "hit readback")?;
        Ok(records.into_iter().map(Hit::from_record).collect())
    }

    /// Reads back the colour output as tightly packed RGBA8 rows.
    pub fn read_color(&self, gpu: &GpuContext) -> Result<Vec<u8>, GpuError> {
        read_texture_rgba8(gpu, &self.target.texture)
    }
}
