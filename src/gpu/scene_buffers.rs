//! The scene on the GPU: the node pool (patched by dirty ranges), the
//! palette, and the dense grid for the baseline tracer.
//!
//! Nodes and bricks share one buffer, nodes first and bricks from
//! `brick_base`: the tracer then reads either with one load instruction,
//! and on CPU-emulated GPUs every load site in the loop is a scalar loop
//! over the SIMD lanes.

use crate::gpu_pool::{PoolTooLarge, Region, SlotArena, Upload};
use crate::scene::instances::ObjectsUpload;
use crate::scene::{Palette, Scene, SceneUpload};
use crate::trace::grid::DenseGrid;

/// Smallest buffer we create; zero-sized bindings are not allowed.
const MIN_BUFFER_BYTES: u64 = 16;

/// What the last upload did, for the stats panel and tests.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct UploadStats {
    pub bytes: u64,
    pub ranges: usize,
    pub grew: bool,
}

/// GPU buffers of one scene. `generation` changes whenever a buffer is
/// re-created, so passes know to rebuild their bind groups.
pub struct SceneBuffers {
    pub pool_buf: wgpu::Buffer,
    /// Bytes reserved for nodes at the start of `pool_buf`; bricks follow.
    node_capacity: u64,
    /// Bytes reserved for bricks after them.
    brick_capacity: u64,
    /// The instance tree and records of a scene of objects
    /// (`crate::scene::instances`).
    pub instances_buf: wgpu::Buffer,
    /// Nodes of the instance tree: `Some` when the pool holds a scene of
    /// objects (then tracing starts at the tree), `None` for one model.
    pub instance_nodes: Option<u32>,
    pub palette_buf: wgpu::Buffer,
    pub grid_buf: wgpu::Buffer,
    pub grid_min: glam::IVec3,
    pub grid_dims: glam::UVec3,
    pub generation: u64,
}

fn storage_buffer(device: &wgpu::Device, label: &str, size: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size.max(MIN_BUFFER_BYTES).next_multiple_of(4),
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    })
}

impl SceneBuffers {
    pub fn new(device: &wgpu::Device) -> SceneBuffers {
        SceneBuffers {
            pool_buf: storage_buffer(device, "node pool", 0),
            node_capacity: 0,
            brick_capacity: 0,
            instances_buf: storage_buffer(device, "instances", 0),
            instance_nodes: None,
            palette_buf: storage_buffer(device, "palette", 256 * 4),
            grid_buf: storage_buffer(device, "dense grid", 0),
            grid_min: glam::IVec3::ZERO,
            grid_dims: glam::UVec3::ZERO,
            generation: 0,
        }
    }

    /// Sends what changed to the GPU (see [`Scene::take_uploads_within`]):
    /// for one drawn octree only its changed slots, a pool that outgrew its
    /// buffer getting a bigger one, filled by a GPU-side copy of the old
    /// contents, its headroom cut to what one binding of `max_bytes` allows;
    /// for a scene drawn as instances its models' changed slots and the
    /// instance words that changed, in new buffers when the layout changed.
    ///
    /// # Errors
    /// [`PoolTooLarge`] when the pool does not fit one buffer binding of
    /// `max_bytes`; nothing is written then.
    pub fn upload_pool(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &mut Scene,
        max_bytes: u64,
    ) -> Result<UploadStats, PoolTooLarge> {
        if scene.instanced().is_some() != self.instance_nodes.is_some() {
            // The buffers hold the other kind of copy (the scene gained or
            // lost its last reference): everything goes up afresh.
            scene.forget_uploads();
            (self.node_capacity, self.brick_capacity) = (0, 0);
        }
        match scene.take_uploads_within(max_bytes)? {
            SceneUpload::Tree(upload) => Ok(self.write_tree(device, queue, scene, &upload)),
            SceneUpload::Objects(upload) => Ok(self.write_objects(device, queue, &upload)),
        }
    }

    /// The one model's dirty slots (after growing the buffer if it must).
    fn write_tree(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &Scene,
        upload: &Upload,
    ) -> UploadStats {
        let node_capacity = upload.nodes.grow_to_bytes().unwrap_or(self.node_capacity);
        let brick_capacity = upload.bricks.grow_to_bytes().unwrap_or(self.brick_capacity);
        let grew = (node_capacity, brick_capacity) != (self.node_capacity, self.brick_capacity);
        if grew {
            self.grow(device, queue, node_capacity, brick_capacity);
        }
        self.instance_nodes = None;
        let pool = scene.drawn().pool();
        write_region(queue, &self.pool_buf, 0, &upload.nodes, &pool.nodes);
        write_region(queue, &self.pool_buf, self.node_capacity, &upload.bricks, &pool.bricks);
        UploadStats {
            bytes: upload.byte_count(),
            ranges: upload.nodes.range_count() + upload.bricks.range_count(),
            grew,
        }
    }

    /// The models' changed slots and the instance words that changed, in
    /// new buffers when the layout or the number of words changed.
    fn write_objects(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, upload: &ObjectsUpload) -> UploadStats {
        if let Some((nodes, bricks)) = upload.pool_size {
            self.pool_buf = storage_buffer(device, "node pool", nodes + bricks);
            (self.node_capacity, self.brick_capacity) = (nodes, bricks);
            self.generation += 1;
        }
        if let Some(bytes) = upload.instances_size {
            self.instances_buf = storage_buffer(device, "instances", bytes);
            self.generation += 1;
        }
        for (at, bytes) in &upload.pool {
            queue.write_buffer(&self.pool_buf, *at, bytes);
        }
        for (at, bytes) in &upload.instances {
            queue.write_buffer(&self.instances_buf, *at, bytes);
        }
        self.instance_nodes = Some(upload.instance_nodes);
        UploadStats {
            bytes: upload.byte_count(),
            ranges: upload.range_count(),
            grew: upload.pool_size.is_some() || upload.instances_size.is_some(),
        }
    }

    /// Where the bricks start in the pool buffer, in 32-bit words.
    pub fn brick_base(&self) -> u32 {
        u32::try_from(self.node_capacity / 4).unwrap_or(u32::MAX)
    }

    /// Re-creates the pool buffer with the given region sizes and copies
    /// both old regions across on the GPU.
    fn grow(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, node_capacity: u64, brick_capacity: u64) {
        let bigger = storage_buffer(device, "node pool", node_capacity + brick_capacity);
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("pool grow") });
        // A region may also shrink (its headroom given up to fit the binding
        // limit): the slots past its new size are free, so only what fits is copied.
        let (nodes_kept, bricks_kept) =
            (self.node_capacity.min(node_capacity), self.brick_capacity.min(brick_capacity));
        if nodes_kept > 0 {
            encoder.copy_buffer_to_buffer(&self.pool_buf, 0, &bigger, 0, nodes_kept);
        }
        if bricks_kept > 0 {
            encoder.copy_buffer_to_buffer(&self.pool_buf, self.node_capacity, &bigger, node_capacity, bricks_kept);
        }
        // Submitted now: queued writes run at the start of the *next*
        // submit, so they land after this copy, not under it.
        queue.submit([encoder.finish()]);
        self.pool_buf = bigger;
        self.node_capacity = node_capacity;
        self.brick_capacity = brick_capacity;
        self.generation += 1;
    }

    /// Writes the 256 palette colours (RGBA8, one word each).
    pub fn upload_palette(&self, queue: &wgpu::Queue, palette: &Palette) {
        queue.write_buffer(&self.palette_buf, 0, bytemuck::cast_slice(&palette.colors));
    }

    /// Replaces the dense grid (only the grid tracer reads it).
    pub fn upload_grid(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, grid: &DenseGrid) {
        let bytes = grid.data.len() as u64;
        if self.grid_buf.size() < bytes.max(MIN_BUFFER_BYTES).next_multiple_of(4) {
            self.grid_buf = storage_buffer(device, "dense grid", bytes);
            self.generation += 1;
        }
        let mut data = grid.data.clone();
        data.resize(data.len().next_multiple_of(4), 0);
        queue.write_buffer(&self.grid_buf, 0, &data);
        self.grid_min = grid.min;
        self.grid_dims = grid.dims;
    }
}

/// Writes the region's changed ranges into `buffer` from byte `base` on.
fn write_region<T: bytemuck::Pod>(
    queue: &wgpu::Queue,
    buffer: &wgpu::Buffer,
    base: u64,
    region: &Region,
    arena: &SlotArena<T>,
) {
    for (offset, bytes) in region.ranges(arena) {
        queue.write_buffer(buffer, base + offset, bytes);
    }
}
