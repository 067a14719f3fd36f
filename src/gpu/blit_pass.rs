//! Draws a texture onto a render target (the window's swapchain image) with
//! a fullscreen triangle: the trace output, replacing what the target held
//! (a render-scaled trace is stretched with linear filtering; at scale 1
//! every pixel centre samples its own texel exactly), or a layer of the
//! target's size with premultiplied alpha, over what the target holds (the
//! window's panels, kept across frames).

use super::bindings;
use super::{GpuContext, GpuError};

/// How the blit meets what the target already holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BlitMode {
    /// Clears the target and stretches the source over it, opaque.
    Replace,
    /// Draws a source of the target's size over it, premultiplied alpha, texel for pixel.
    Over,
}

pub struct BlitPass {
    mode: BlitMode,
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
    sampler: wgpu::Sampler,
    bind_group: Option<wgpu::BindGroup>,
}

impl BlitPass {
    /// A blit into targets of `target_format`.
    pub fn new(gpu: &GpuContext, target_format: wgpu::TextureFormat, mode: BlitMode) -> Result<BlitPass, GpuError> {
        let device = &gpu.device;
        let module = gpu.module(super::shaders::Module::Blit)?;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("blit bind group layout"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: bindings::SOURCE,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: bindings::SOURCE_SAMPLER,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("blit pipeline layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let (entry_point, blend) = match mode {
            BlitMode::Replace => ("fs_main", None),
            BlitMode::Over => ("fs_over", Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING)),
        };
        let pipeline = gpu.validated("blit", |device| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("blit"),
                layout: Some(&pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs_main"),
                    compilation_options: wgpu::PipelineCompilationOptions::default(),
                    buffers: &[],
                },
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(entry_point),
                    compilation_options: wgpu::PipelineCompilationOptions::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format: target_format,
                        blend,
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                primitive: wgpu::PrimitiveState::default(),
                depth_stencil: None,
                multisample: wgpu::MultisampleState::default(),
                multiview_mask: None,
                cache: None,
            })
        })?;
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("blit sampler"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        Ok(BlitPass { mode, layout, pipeline, sampler, bind_group: None })
    }

    /// Binds the texture to draw. Called every frame: the trace output is
    /// re-created on resize, and one bind group per frame costs next to nothing.
    pub fn prepare(&mut self, device: &wgpu::Device, source: &wgpu::TextureView) {
        self.bind_group = Some(device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("blit bind group"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: bindings::SOURCE,
                    resource: wgpu::BindingResource::TextureView(source),
                },
                wgpu::BindGroupEntry {
                    binding: bindings::SOURCE_SAMPLER,
                    resource: wgpu::BindingResource::Sampler(&self.sampler),
                },
            ],
        }));
    }

    /// Records the draw into `target`; with `areas` (pixel rectangles x, y,
    /// width, height, which must not overlap), into those only.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, target: &wgpu::TextureView, areas: Option<&[[u32; 4]]>) {
        let Some(bind_group) = &self.bind_group else { return };
        let load = match self.mode {
            BlitMode::Replace => wgpu::LoadOp::Clear(wgpu::Color::BLACK),
            BlitMode::Over => wgpu::LoadOp::Load,
        };
        let mut pass = color_pass(encoder, target, load, "blit");
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, bind_group, &[]);
        match areas {
            None => pass.draw(0..3, 0..1),
            Some(areas) => {
                for &[x, y, width, height] in areas {
                    pass.set_scissor_rect(x, y, width, height);
                    pass.draw(0..3, 0..1);
                }
            }
        }
    }
}

/// A render pass that draws into `view` alone, after `load`.
pub fn color_pass(
    encoder: &mut wgpu::CommandEncoder,
    view: &wgpu::TextureView,
    load: wgpu::LoadOp<wgpu::Color>,
    label: &str,
) -> wgpu::RenderPass<'static> {
    encoder
        .begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view,
                resolve_target: None,
                depth_slice: None,
                ops: wgpu::Operations { load, store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        })
        .forget_lifetime()
}
