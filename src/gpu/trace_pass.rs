//! The ray tracing compute pass: one thread per pixel walks the SVO (or the
//! dense grid) and writes a colour texture plus a hit record per pixel.

use super::bindings;
use std::collections::HashMap;

use super::context::compute_pipeline;
use super::layout::{
    FLOOR_ROW, FrameUniforms, ROW_TILES, buffer_entry, constants_buffer, constants_entry, output_entry, output_texture,
};
use super::readback::{read_storage, read_texture_rgba8};
use super::shaders::Module;
use super::{GpuContext, GpuError, SceneBuffers};
use crate::settings::{RenderSettings, TraceMode};
use crate::trace::Hit;

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

/// Pipelines are compiled per tracer and per shadow setting, level of
/// detail and scene kind (override constants), so a scene rendered without
/// shadows pays nothing for them, nor a scene of one model for instances. The
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
    /// [grid without shadows, grid with].
    grid: [wgpu::ComputePipeline; 2],
    /// The SVO kernels by (level of detail, instances): [without shadows,
    /// with shadows, beam]. The exact ones of one model are compiled at
    /// start, the others from `svo` on first use.
    svo_kernels: HashMap<(bool, bool), [wgpu::ComputePipeline; 3]>,
    tile_dispatch: wgpu::ComputePipeline,
    svo: wgpu::ShaderModule,
    floor: wgpu::ComputePipeline,
    uniform_buf: wgpu::Buffer,
    target: Target,
    bind_group: wgpu::BindGroup,
    args_bind_group: wgpu::BindGroup,
    bound_generation: u64,
}

impl TracePass {
    /// The pipelines and a 1×1 output; [`TracePass::resize`] sizes it.
    pub fn new(gpu: &GpuContext, buffers: &SceneBuffers) -> Result<TracePass, GpuError> {
        let device = &gpu.device;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("trace bind group layout"),
            entries: &[
                constants_entry(bindings::FRAME_CONSTANTS, std::mem::size_of::<FrameUniforms>()),
                buffer_entry(bindings::POOL, true),
                buffer_entry(bindings::INSTANCES, true),
                buffer_entry(bindings::PALETTE, true),
                buffer_entry(bindings::GRID, true),
                output_entry(bindings::OUT_COLOR),
                buffer_entry(bindings::HIT_RECORDS, false),
                buffer_entry(bindings::BEAM_DISTANCE, false),
                buffer_entry(bindings::TRACED, false),
            ],
        });
        let args_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("dispatch arguments layout"),
            entries: &[buffer_entry(bindings::DISPATCH_ARGS, false)],
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
        let svo = gpu.module(Module::TraceSvo)?;
        let grid = gpu.module(Module::TraceGrid)?;
        let pipeline = |module, entry, constants: &[(&str, f64)], label| {
            compute_pipeline(&gpu.device, &pipeline_layout, module, entry, constants, label)
        };
        let tile = ("BEAM_TILE", f64::from(BEAM_TILE));
        let grid = [
            pipeline(&grid, "main", &[("SHADOWS", 0.0)], "trace grid")?,
            pipeline(&grid, "main", &[("SHADOWS", 1.0)], "trace grid + shadows")?,
        ];
        let exact = svo_kernels(&gpu.device, &pipeline_layout, &svo, (false, false))?;
        let tile_dispatch =
            compute_pipeline(&gpu.device, &args_pipeline_layout, &svo, "tile_dispatch", &[tile], "tile dispatch")?;
        let floor_module = gpu.module(Module::Floor)?;
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
            grid,
            svo_kernels: HashMap::from([((false, false), exact)]),
            tile_dispatch,
            svo,
            floor,
            uniform_buf,
            target,
            bind_group,
            args_bind_group,
            bound_generation,
        })
    }

    /// Compiles the SVO kernels `kernel` needs if they are not compiled yet
    /// (a frame with `--lod` above 0; `instances`: a scene drawn as
    /// instances, whose kernels have the instance walk).
    ///
    /// # Errors
    /// A kernel that does not compile.
    pub fn ensure_kernel(&mut self, gpu: &GpuContext, kernel: Kernel, instances: bool) -> Result<(), GpuError> {
        let Kernel::Trace { mode: TraceMode::Svo, lod, .. } = kernel else { return Ok(()) };
        if !self.svo_kernels.contains_key(&(lod, instances)) {
            let kernels = svo_kernels(&gpu.device, &self.pipeline_layout, &self.svo, (lod, instances))?;
            self.svo_kernels.insert((lod, instances), kernels);
        }
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
            entries: &[wgpu::BindGroupEntry {
                binding: bindings::DISPATCH_ARGS,
                resource: target.dispatch_args.as_entire_binding(),
            }],
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
                wgpu::BindGroupEntry { binding: bindings::FRAME_CONSTANTS, resource: uniform_buf.as_entire_binding() },
                wgpu::BindGroupEntry { binding: bindings::POOL, resource: buffers.pool_buf.as_entire_binding() },
                wgpu::BindGroupEntry {
                    binding: bindings::INSTANCES,
                    resource: buffers.instances_buf.as_entire_binding(),
                },
                wgpu::BindGroupEntry { binding: bindings::PALETTE, resource: buffers.palette_buf.as_entire_binding() },
                wgpu::BindGroupEntry { binding: bindings::GRID, resource: buffers.grid_buf.as_entire_binding() },
                wgpu::BindGroupEntry {
                    binding: bindings::OUT_COLOR,
                    resource: wgpu::BindingResource::TextureView(&target.view),
                },
                wgpu::BindGroupEntry { binding: bindings::HIT_RECORDS, resource: target.hits_buf.as_entire_binding() },
                wgpu::BindGroupEntry {
                    binding: bindings::BEAM_DISTANCE,
                    resource: target.beam_buf.as_entire_binding(),
                },
                wgpu::BindGroupEntry { binding: bindings::TRACED, resource: target.traced_tiles.as_entire_binding() },
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
    /// the grid its per-pixel kernel; or the floor alone. `instances`: the
    /// scene is drawn as instances (as for [`TracePass::ensure_kernel`]).
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        (kernel, instances): (Kernel, bool),
        timestamps: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) {
        if matches!(kernel, Kernel::Trace { mode: TraceMode::Svo, .. }) {
            // The beam prepass appends to the list of traced tiles from zero.
            encoder.clear_buffer(&self.target.traced_tiles, 0, Some(4));
        }
        let mut pass = encoder
            .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("trace"), timestamp_writes: timestamps });
        pass.set_bind_group(0, &self.bind_group, &[]);
        let (mode, shadows, key) = match kernel {
            Kernel::Trace { mode, shadows, lod } => (mode, shadows, (lod, instances)),
            Kernel::Floor => {
                self.encode_floor(&mut pass);
                return;
            }
        };
        if mode == TraceMode::Grid {
            pass.set_pipeline(&self.grid[usize::from(shadows)]);
            pass.dispatch_workgroups(self.target.width.div_ceil(8), self.target.height.div_ceil(8), 1);
            return;
        }
        // `ensure_kernel` compiled these.
        let Some(kernels) = self.svo_kernels.get(&key) else {
            log::error!("the SVO kernels {key:?} were not compiled");
            return;
        };
        self.encode_floor(&mut pass);
        let (tiles_x, tiles_y) = (self.target.width.div_ceil(BEAM_TILE), self.target.height.div_ceil(BEAM_TILE));
        pass.set_pipeline(&kernels[2]);
        pass.dispatch_workgroups(tiles_x.div_ceil(8), tiles_y.div_ceil(8), 1);
        pass.set_pipeline(&self.tile_dispatch);
        pass.set_bind_group(1, &self.args_bind_group, &[]);
        pass.dispatch_workgroups(1, 1, 1);
        pass.set_pipeline(&kernels[usize::from(shadows)]);
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

/// The SVO kernels for (level of detail, instances): [trace without
/// shadows, trace with shadows, beam prepass].
fn svo_kernels(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    svo: &wgpu::ShaderModule,
    (lod, instances): (bool, bool),
) -> Result<[wgpu::ComputePipeline; 3], GpuError> {
    let flag = |on: bool| if on { 1.0 } else { 0.0 };
    let common = [("BEAM_TILE", f64::from(BEAM_TILE)), ("LOD", flag(lod)), ("INSTANCES", flag(instances))];
    let label =
        |what: &str| format!("{what}{}{}", if lod { ", lod" } else { "" }, if instances { ", instances" } else { "" });
    let main = |shadows: bool| {
        let mut constants = common.to_vec();
        constants.push(("SHADOWS", flag(shadows)));
        compute_pipeline(
            device,
            layout,
            svo,
            "main",
            &constants,
            &label(if shadows { "trace svo + shadows" } else { "trace svo" }),
        )
    };
    Ok([main(false)?, main(true)?, compute_pipeline(device, layout, svo, "beam", &common, &label("beam prepass"))?])
}
