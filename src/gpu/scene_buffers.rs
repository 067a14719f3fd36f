//! The scene on the GPU: node and brick pools (patched by dirty ranges),
//! the palette, and the dense grid for the baseline tracer.

use crate::gpu_pool::{Region, SlotArena};
use crate::scene::{Octree, Palette};
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
    pub nodes_buf: wgpu::Buffer,
    pub bricks_buf: wgpu::Buffer,
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
            nodes_buf: storage_buffer(device, "octree nodes", 0),
            bricks_buf: storage_buffer(device, "octree bricks", 0),
            palette_buf: storage_buffer(device, "palette", 256 * 4),
            grid_buf: storage_buffer(device, "dense grid", 0),
            grid_min: glam::IVec3::ZERO,
            grid_dims: glam::UVec3::ZERO,
            generation: 0,
        }
    }

    /// Flushes the pool's dirty ranges to the GPU: only changed slots are
    /// written; a pool that outgrew its buffer gets a bigger one, filled by a
    /// GPU-side copy of the old contents.
    pub fn upload_pool(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, tree: &mut Octree) -> UploadStats {
        let upload = tree.pool_mut().flush();
        let pool = tree.pool();
        let grew_nodes = write_region(device, queue, &mut self.nodes_buf, "octree nodes", &upload.nodes, &pool.nodes);
        let grew_bricks =
            write_region(device, queue, &mut self.bricks_buf, "octree bricks", &upload.bricks, &pool.bricks);
        if grew_nodes || grew_bricks {
            self.generation += 1;
        }
        UploadStats {
            bytes: upload.byte_count(),
            ranges: upload.nodes.range_count() + upload.bricks.range_count(),
            grew: grew_nodes || grew_bricks,
        }
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

/// Grows `buffer` if the region asks for it (copying the old contents on the
/// GPU), then writes the region's ranges. Returns whether it grew.
fn write_region<T: bytemuck::Pod>(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    buffer: &mut wgpu::Buffer,
    label: &str,
    region: &Region,
    arena: &SlotArena<T>,
) -> bool {
    let grew = match region.grow_to_bytes() {
        Some(bytes) if bytes > buffer.size() => {
            let bigger = storage_buffer(device, label, bytes);
            let mut encoder =
                device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("pool grow") });
            encoder.copy_buffer_to_buffer(buffer, 0, &bigger, 0, buffer.size());
            // Submitted now: queued writes run at the start of the *next*
            // submit, so they land after this copy, not under it.
            queue.submit([encoder.finish()]);
            *buffer = bigger;
            true
        }
        _ => false,
    };
    for (offset, bytes) in region.ranges(arena) {
        queue.write_buffer(buffer, offset, bytes);
    }
    grew
}
