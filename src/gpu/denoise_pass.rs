//! The denoising pass over the path tracer's accumulation: `prepare`, the
//! à-trous iterations and `finish` of `shaders/denoise.wgsl`, dispatched in
//! one compute pass, and the noise estimate `prepare` leaves behind. The
//! filter itself is explained in `crate::trace::denoise`, its CPU twin.

use super::bindings;
use super::context::compute_pipeline;
use super::layout::{
    DenoiseUniforms, buffer_entry, buffer_resource, constants_buffer, constants_entry, output_entry, output_texture,
};
use super::readback::{read_storage, read_texture_rgba8};
use super::shaders::Module;
use super::{GpuContext, GpuError, PathPass};
use crate::trace::denoise::{Frame, ITERATIONS};

/// The dispatches of a filter: `prepare`, the iterations, `finish`.
pub const STAGES: usize = ITERATIONS as usize + 2;
/// The side of a workgroup, in pixels (`@workgroup_size(8, 8)`).
const GROUP: u32 = 8;

/// One dispatch: its constants and its bind group (the light buffers it
/// reads and writes).
struct Stage {
    constants: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
}

/// Size-dependent outputs and the stages bound to them.
struct Target {
    texture: wgpu::Texture,
    view: wgpu::TextureView,
    partials: wgpu::Buffer,
    /// `prepare`, the iterations, `finish`.
    stages: Vec<Stage>,
    width: u32,
    height: u32,
}

pub struct DenoisePass {
    layout: wgpu::BindGroupLayout,
    prepare: wgpu::ComputePipeline,
    atrous: wgpu::ComputePipeline,
    finish: wgpu::ComputePipeline,
    target: Option<Target>,
}

fn light_buffer(device: &wgpu::Device, pixels: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("denoise light"),
        size: (pixels * 16).max(16),
        usage: wgpu::BufferUsages::STORAGE,
        mapped_at_creation: false,
    })
}

fn groups(width: u32, height: u32) -> (u32, u32) {
    (width.div_ceil(GROUP), height.div_ceil(GROUP))
}

impl DenoisePass {
    pub fn new(gpu: &GpuContext) -> Result<DenoisePass, GpuError> {
        let device = &gpu.device;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("denoise bind group layout"),
            entries: &[
                constants_entry(bindings::DENOISE_CONSTANTS, std::mem::size_of::<DenoiseUniforms>()),
                buffer_entry(bindings::ACCUM, true),
                buffer_entry(bindings::GUIDES, true),
                buffer_entry(bindings::LIGHT_IN, true),
                buffer_entry(bindings::LIGHT_OUT, false),
                output_entry(bindings::OUT_COLOR),
                buffer_entry(bindings::PARTIALS, false),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("denoise pipeline layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let module = gpu.module(Module::Denoise)?;
        let pipeline = |entry: &str| compute_pipeline(device, &pipeline_layout, &module, entry, &[], "denoiser");
        Ok(DenoisePass {
            prepare: pipeline("prepare")?,
            atrous: pipeline("atrous")?,
            finish: pipeline("finish")?,
            layout,
            target: None,
        })
    }

    /// Binds the path pass's accumulation at its size; called whenever the
    /// path pass re-creates it.
    pub fn bind(&mut self, gpu: &GpuContext, path: &PathPass) {
        let device = &gpu.device;
        let (width, height) = path.size();
        let pixels = u64::from(width) * u64::from(height);
        let (texture, view) = output_texture(device, "denoised output", width, height);
        let (gx, gy) = groups(width, height);
        let partials = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("noise partials"),
            size: u64::from(gx * gy) * 4,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let light = [light_buffer(device, pixels), light_buffer(device, pixels)];
        let (accum, guides) = path.sample_buffers();
        // prepare writes light[0]; iteration i reads light[i % 2] and writes
        // the other; finish reads what the last one wrote.
        let writes: Vec<usize> = std::iter::once(0).chain((0..ITERATIONS as usize).map(|i| (i + 1) % 2)).collect();
        let last = *writes.last().unwrap_or(&0);
        let stages = writes
            .iter()
            .copied()
            .chain([1 - last])
            .map(|out| {
                let constants = constants_buffer(device, "denoise constants", std::mem::size_of::<DenoiseUniforms>());
                let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("denoise bind group"),
                    layout: &self.layout,
                    entries: &[
                        buffer_resource(bindings::DENOISE_CONSTANTS, &constants),
                        buffer_resource(bindings::ACCUM, accum),
                        buffer_resource(bindings::GUIDES, guides),
                        buffer_resource(bindings::LIGHT_IN, &light[1 - out]),
                        buffer_resource(bindings::LIGHT_OUT, &light[out]),
                        wgpu::BindGroupEntry {
                            binding: bindings::OUT_COLOR,
                            resource: wgpu::BindingResource::TextureView(&view),
                        },
                        buffer_resource(bindings::PARTIALS, &partials),
                    ],
                });
                Stage { constants, bind_group }
            })
            .collect();
        self.target = Some(Target { texture, view, partials, stages, width, height });
    }

    /// Records `prepare` (the light and the noise estimate's partial sums)
    /// and, with `filter`, the iterations and `finish` (the denoised
    /// image) for the accumulation seen from `frame`.
    pub fn encode(&self, gpu: &GpuContext, encoder: &mut wgpu::CommandEncoder, frame: &Frame, filter: bool) {
        let stages = if filter { 0..STAGES } else { 0..1 };
        self.encode_stages(gpu, encoder, frame, stages, filter);
    }

    /// Records the dispatches `stages` of [`STAGES`] (0 `prepare`, then the
    /// iterations, the last `finish`); `light`: `prepare` writes the light
    /// for a filter to follow. The window records one stage a frame.
    pub fn encode_stages(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        frame: &Frame,
        stages: std::ops::Range<usize>,
        light: bool,
    ) {
        let Some(target) = &self.target else { return };
        let steps = std::iter::once(0).chain((0..ITERATIONS).map(|i| 1 << i)).chain([0]);
        let chosen = || target.stages.iter().zip(steps.clone()).enumerate().filter(|(i, _)| stages.contains(i));
        for (_, (stage, step)) in chosen() {
            let uniforms = DenoiseUniforms::new(frame, step, light);
            gpu.queue.write_buffer(&stage.constants, 0, bytemuck::bytes_of(&uniforms));
        }
        let mut pass =
            encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("denoise"), ..Default::default() });
        let (gx, gy) = groups(target.width, target.height);
        for (i, (stage, _)) in chosen() {
            let pipeline = match i {
                0 => &self.prepare,
                i if i == STAGES - 1 => &self.finish,
                _ => &self.atrous,
            };
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &stage.bind_group, &[]);
            pass.dispatch_workgroups(gx, gy, 1);
        }
    }

    /// The sum over pixels of the displayed variance `prepare` measured last
    /// (see `crate::trace::denoise::noise_estimate`).
    pub fn read_variance_sum(&self, gpu: &GpuContext) -> Result<f64, GpuError> {
        let Some(target) = &self.target else { return Ok(0.0) };
        let partials: Vec<f32> = read_storage(gpu, &target.partials, "noise readback")?;
        Ok(partials.iter().map(|&p| f64::from(p)).sum())
    }

    pub fn output_view(&self) -> Option<&wgpu::TextureView> {
        self.target.as_ref().map(|t| &t.view)
    }

    /// The denoised image as tightly packed RGBA8 rows, with its size.
    pub fn read_color(&self, gpu: &GpuContext) -> Result<((u32, u32), Vec<u8>), GpuError> {
        let target = self.target.as_ref().ok_or_else(|| GpuError::Readback("nothing was denoised".into()))?;
        Ok(((target.width, target.height), read_texture_rgba8(gpu, &target.texture)?))
    }
}
