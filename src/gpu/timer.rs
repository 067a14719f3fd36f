//! GPU time of one pass: timestamp queries where the adapter has them,
//! otherwise wall time around submit + wait.

use std::time::Instant;

use super::readback::{read_buffer, staging_buffer};
use super::{GpuContext, GpuError};

/// Two timestamps around a compute pass, resolved and read back on demand.
pub struct PassTimer {
    queries: Option<(wgpu::QuerySet, wgpu::Buffer, wgpu::Buffer)>,
    period_ns: f64,
}

impl PassTimer {
    pub fn new(gpu: &GpuContext) -> PassTimer {
        let queries = gpu.timestamps.then(|| {
            let set = gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 2,
            });
            let resolve = gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamp resolve"),
                size: 2 * wgpu::QUERY_SIZE as u64,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let read = staging_buffer(&gpu.device, "timestamp readback", 2 * wgpu::QUERY_SIZE as u64);
            (set, resolve, read)
        });
        PassTimer { queries, period_ns: f64::from(gpu.queue.get_timestamp_period()) }
    }

    /// Timestamp writes for a compute pass descriptor (None without support).
    pub fn pass_writes(&self) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        self.queries.as_ref().map(|(set, _, _)| wgpu::ComputePassTimestampWrites {
            query_set: set,
            beginning_of_pass_write_index: Some(0),
            end_of_pass_write_index: Some(1),
        })
    }

    /// Call after the pass, in the same encoder.
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        if let Some((set, resolve, read)) = &self.queries {
            encoder.resolve_query_set(set, 0..2, resolve, 0);
            encoder.copy_buffer_to_buffer(resolve, 0, read, 0, None);
        }
    }

    /// Submits `encoder`, waits, and returns the pass's milliseconds (GPU
    /// timestamps if available, else wall time of submit + wait).
    pub fn submit_and_measure(&self, gpu: &GpuContext, encoder: wgpu::CommandEncoder) -> Result<f64, GpuError> {
        let start = Instant::now();
        gpu.queue.submit([encoder.finish()]);
        gpu.wait()?;
        let wall_ms = start.elapsed().as_secs_f64() * 1e3;
        match &self.queries {
            Some((_, _, read)) => {
                let bytes = read_buffer(gpu, read)?;
                let ticks: &[u64] = bytemuck::cast_slice(&bytes);
                Ok(ticks[1].wrapping_sub(ticks[0]) as f64 * self.period_ns / 1e6)
            }
            None => Ok(wall_ms),
        }
    }
}
