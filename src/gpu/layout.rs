//! What the Rust side and the shaders share by layout: every `#[repr(C)]`
//! twin of a WGSL struct the passes bind (the palette's materials and the
//! lights are the CPU reference's own, in `crate::trace::path`), the
//! dispatch shapes the WGSL prelude is generated from, and the binding and
//! texture helpers every pass builds its bind groups with.

use bytemuck::{Pod, Zeroable};
use glam::IVec3;

use super::SceneBuffers;
use crate::camera::RayBasis;
use crate::scene::Octree;
use crate::settings::View;
use crate::trace::Footprint;

/// The beam's list of traced tiles is dispatched in rows of this many tiles
/// (a dispatch is at most 65535 workgroups per axis); it has room for every
/// tile, rounded up to whole rows.
pub const ROW_TILES: u64 = 64;

/// The floor kernel's workgroups are rows of this many pixels: 256 bytes of
/// the output, four cache lines, each shared with another workgroup only at
/// the row's ends. An 8×8 workgroup wrote half a line per row and left the
/// other half to a neighbour that lavapipe runs on another thread: with
/// rows, the floor takes 22 % less time and an SVO frame 6–12 % less (A/B,
/// docs/traversal.md).
pub const FLOOR_ROW: u32 = 64;

/// The colour highlighted voxels (the brush's reach, the selection) are
/// mixed toward, and by how much.
pub const HIGHLIGHT_TINT: [f32; 3] = [1.0, 0.85, 0.2];
pub const HIGHLIGHT_MIX: f32 = 0.45;

/// How far a ground grid line's pixels are mixed toward white.
pub const GRID_MIX: f32 = 0.27;

/// The ground's grid, traced: lines `step` voxels apart on the plane
/// `y`, from `lo` to `hi` in x and z (world voxels, inclusive ends). Traced
/// with the voxels, so that they hide the lines behind them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GroundGrid {
    pub y: i32,
    pub lo: [i32; 2],
    pub hi: [i32; 2],
    pub step: u32,
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
    /// 1: rays start across the image plane along `forward` ([`RayBasis::ortho`]).
    pub ortho: u32,
    /// Level of detail: [`crate::trace::Footprint::at_start`] of camera rays.
    pub lod_at_start: f32,
    /// 1: draw the ground grid (`GroundGrid`, tree-local here).
    pub ground_on: u32,
    pub ground_step: u32,
    pub ground_y: i32,
    pub ground_x0: i32,
    pub ground_x1: i32,
    pub ground_z0: i32,
    pub ground_z1: i32,
    /// Nodes of the instance tree (0: the pool holds one model, `root`).
    pub instance_nodes: u32,
    /// 1: rays land on the ground plane y = `plane_y` (tree-local; see
    /// `crate::trace::ground`).
    pub plane_on: u32,
    pub plane_y: i32,
    pub _pad: [u32; 2],
}

impl FrameUniforms {
    /// Uniforms for a frame: camera basis, tree root and grid placement.
    /// `highlight` is an inclusive world voxel box to tint.
    pub fn new(
        basis: &RayBasis,
        tree: &Octree,
        buffers: &SceneBuffers,
        view: View,
        highlight: Option<(IVec3, IVec3)>,
        lod: Footprint,
    ) -> FrameUniforms {
        let local = highlight.map(|(lo, hi)| (lo - tree.origin(), hi - tree.origin()));
        let (lo, hi) = local.unwrap_or((IVec3::ZERO, IVec3::NEG_ONE));
        // A scene drawn as instances is traced from its instance tree; the
        // composed tree is not on the GPU.
        let instanced = buffers.instance_nodes.is_some();
        FrameUniforms {
            eye: basis.eye.into(),
            root: if instanced { 0 } else { tree.root_word() },
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
            ortho: u32::from(basis.ortho),
            lod_at_start: lod.at_start,
            instance_nodes: buffers.instance_nodes.unwrap_or(0),
            ..FrameUniforms::default()
        }
    }

    /// The same uniforms with the ground plane at world height `plane`, if
    /// one, in a tree whose local coordinates start at `origin`.
    pub fn with_plane(self, plane: Option<i32>, origin: IVec3) -> FrameUniforms {
        let Some(y) = plane else { return self };
        FrameUniforms { plane_on: 1, plane_y: y - origin.y, ..self }
    }

    /// The same uniforms drawing `ground` (world voxels) in a tree whose
    /// local coordinates start at `origin`.
    pub fn with_ground(self, ground: Option<GroundGrid>, origin: IVec3) -> FrameUniforms {
        let Some(g) = ground else { return self };
        FrameUniforms {
            ground_on: 1,
            ground_step: g.step.max(1),
            ground_y: g.y - origin.y,
            ground_x0: g.lo[0] - origin.x,
            ground_x1: g.hi[0] - origin.x,
            ground_z0: g.lo[1] - origin.z,
            ground_z1: g.hi[1] - origin.z,
            ..self
        }
    }
}

/// Twin of `PathUniforms` in `shaders/path.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct PathUniforms {
    pub sky_horizon: [f32; 3],
    pub sample_index: u32,
    pub sky_zenith: [f32; 3],
    pub bounces: u32,
    pub shadow_samples: u32,
    pub emitter_count: u32,
    /// The band of rows this dispatch traces (`end_row` at most the height).
    pub first_row: u32,
    pub end_row: u32,
    /// Added to `sample_index` in the random sequences: the seed's first
    /// sample (`PathSettings::first_sample`).
    pub first_sample: u32,
    /// WGSL rounds the struct's size up to its `vec3`s' 16-byte alignment.
    pub padding: [u32; 3],
}

// The size WGSL gives its twin: a field added here must fit it or grow both.
const _: () = assert!(std::mem::size_of::<PathUniforms>() == 64);

/// Twin of `DenoiseUniforms` in `shaders/denoise.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct DenoiseUniforms {
    pub eye: [f32; 3],
    pub width: u32,
    pub forward: [f32; 3],
    pub height: u32,
    /// One pixel's width in voxels: `at_start + per_t · depth`.
    pub at_start: f32,
    pub per_t: f32,
    /// Pixels between the taps of an `atrous` dispatch.
    pub step: u32,
    /// 1: `prepare` writes the light (the filter follows); 0: only the
    /// noise estimate's sums.
    pub light: u32,
}

impl DenoiseUniforms {
    pub fn new(frame: &crate::trace::denoise::Frame, step: u32, light: bool) -> DenoiseUniforms {
        DenoiseUniforms {
            eye: frame.eye.into(),
            width: frame.width,
            forward: frame.forward.into(),
            height: frame.height,
            at_start: frame.footprint.at_start,
            per_t: frame.footprint.per_t,
            step,
            light: u32::from(light),
        }
    }
}

/// A compute-visible binding of a frame's constants (`size` bytes): a
/// read-only storage buffer, not a uniform buffer. Lavapipe (Mesa 22)
/// compiles a kernel again, on the queue, whenever its uniform buffer is
/// bound anew, with the values that decide branches folded in ("inlined
/// uniforms"): 70–100 ms stalls every few frames while the camera moved.
/// No uniform buffer, nothing to fold in.
pub fn constants_entry(binding: u32, size: usize) -> wgpu::BindGroupLayoutEntry {
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
pub fn constants_buffer(device: &wgpu::Device, label: &str, size: usize) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size as u64,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// The binding of the RGBA8 output texture a kernel writes.
pub fn output_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
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
pub fn output_texture(
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

/// A bind group's entry binding all of `buffer`.
pub fn buffer_resource(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry { binding, resource: buffer.as_entire_binding() }
}

pub fn buffer_entry(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
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
