//! Copying GPU buffers back to the CPU (tests, screenshots, headless renders).

use super::{GpuContext, GpuError};

/// Maps a `MAP_READ` buffer and returns its bytes.
///
/// # Errors
/// In the browser always: WebGPU maps a buffer through a promise the
/// page's one thread cannot wait on (docs/web.md lists what that leaves out).
#[cfg(target_arch = "wasm32")]
pub fn read_buffer(_gpu: &GpuContext, _buffer: &wgpu::Buffer) -> Result<Vec<u8>, GpuError> {
    Err(GpuError::Readback("the browser cannot wait for GPU memory to be read back".into()))
}

/// Maps a `MAP_READ` buffer and returns its bytes.
#[cfg(not(target_arch = "wasm32"))]
pub fn read_buffer(gpu: &GpuContext, buffer: &wgpu::Buffer) -> Result<Vec<u8>, GpuError> {
    let (tx, rx) = std::sync::mpsc::channel();
    buffer.slice(..).map_async(wgpu::MapMode::Read, move |result| {
        // The receiver lives until recv() below returns; a failed send only
        // means nobody waits any more.
        let _ = tx.send(result);
    });
    gpu.wait()?;
    rx.recv().map_err(|e| GpuError::Readback(e.to_string()))?.map_err(|e| GpuError::Readback(e.to_string()))?;
    let bytes = buffer.slice(..).get_mapped_range().map_err(|e| GpuError::Readback(e.to_string()))?.to_vec();
    buffer.unmap();
    Ok(bytes)
}

/// A buffer the CPU can map for reading.
pub fn staging_buffer(device: &wgpu::Device, label: &str, size: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size.max(4),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// Copies a storage buffer into a mapped staging buffer and returns it as
/// `T`s (copied out, so the bytes' alignment does not matter).
pub fn read_storage<T: bytemuck::Pod>(
    gpu: &GpuContext,
    buffer: &wgpu::Buffer,
    label: &str,
) -> Result<Vec<T>, GpuError> {
    let size = buffer.size();
    let staging = staging_buffer(&gpu.device, label, size);
    let mut encoder = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) });
    encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, size);
    gpu.queue.submit([encoder.finish()]);
    Ok(bytemuck::pod_collect_to_vec(&read_buffer(gpu, &staging)?))
}

/// Bytes per row of a texture copy: `width * 4` rounded up to wgpu's 256.
pub fn padded_row_bytes(width: u32) -> u32 {
    (width * 4).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT
}

/// Reads an RGBA8 texture into tightly packed rows.
pub fn read_texture_rgba8(gpu: &GpuContext, texture: &wgpu::Texture) -> Result<Vec<u8>, GpuError> {
    let (width, height) = (texture.width(), texture.height());
    let padded = padded_row_bytes(width);
    let staging = staging_buffer(&gpu.device, "texture readback", u64::from(padded) * u64::from(height));
    let mut encoder = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("readback") });
    encoder.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &staging,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded),
                rows_per_image: Some(height),
            },
        },
        wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
    );
    gpu.queue.submit([encoder.finish()]);
    let bytes = read_buffer(gpu, &staging)?;
    let row = (width * 4) as usize;
    Ok(bytes.chunks(padded as usize).flat_map(|r| &r[..row]).copied().collect())
}
