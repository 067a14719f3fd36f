//! GPU time of one pass: timestamp queries where the adapter has them,
//! otherwise wall time around submit + wait.
//!
//! A frame that waits for the GPU reads its own timestamps; a frame that
//! does not (the window's) maps them once the GPU is done and reads them on
//! a later frame, skipping the queries of frames while the read-back buffer
//! is still mapped.

use std::sync::Arc;
use std::sync::atomic::{AtomicU8, Ordering};
use web_time::Instant;

use super::readback::{read_buffer, staging_buffer};
use super::{GpuContext, GpuError};

/// States of the read-back buffer.
const FREE: u8 = 0;
const WRITTEN: u8 = 1;
const MAPPING: u8 = 2;
const MAPPED: u8 = 3;

/// Two timestamps around a compute pass, resolved and read back on demand.
pub struct PassTimer {
    queries: Option<(wgpu::QuerySet, wgpu::Buffer, wgpu::Buffer)>,
    period_ns: f64,
    /// Where the read-back buffer is in its cycle (see the constants above).
    state: Arc<AtomicU8>,
    /// The last pass time read back, for frames that do not wait.
    last_ms: f64,
    /// Whether the timestamps agree with the wall clock. On lavapipe they
    /// stop doing so once the path kernel has run (a trace of 25 ms reads as
    /// 0.02 ms); from then on passes are timed by the wall clock.
    trusted: bool,
    /// Frames submitted without waiting: every `CHECK_EVERY`th waits, so
    /// that the timestamps are checked against the wall clock.
    unwaited: u32,
}

/// A frame that does not wait waits every this many frames, to check the
/// timestamps against the wall clock.
const CHECK_EVERY: u32 = 64;

/// Timestamps below this share of a frame's wall time, in a frame of more
/// than `IMPLAUSIBLE_ABOVE_MS`, cannot be the frame's.
const IMPLAUSIBLE_SHARE: f64 = 0.05;
const IMPLAUSIBLE_ABOVE_MS: f64 = 10.0;

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
        let period_ns = f64::from(gpu.queue.get_timestamp_period());
        PassTimer { queries, period_ns, state: Arc::new(AtomicU8::new(FREE)), last_ms: 0.0, trusted: true, unwaited: 0 }
    }

    /// Timestamp writes for a compute pass descriptor (None without support,
    /// or while the last ones are still being read back).
    pub fn pass_writes(&self) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        if !self.recording() {
            return None;
        }
        self.queries.as_ref().map(|(set, _, _)| wgpu::ComputePassTimestampWrites {
            query_set: set,
            beginning_of_pass_write_index: Some(0),
            end_of_pass_write_index: Some(1),
        })
    }

    /// Call after the pass, in the same encoder.
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        if let Some((set, resolve, read)) = &self.queries
            && self.recording()
        {
            encoder.resolve_query_set(set, 0..2, resolve, 0);
            encoder.copy_buffer_to_buffer(resolve, 0, read, 0, None);
            self.state.store(WRITTEN, Ordering::Release);
        }
    }

    /// Submits `buffers` and returns at once with the pass time of the
    /// latest frame read back so far (the window's frames). Adapters without
    /// timestamps measure wall time, which needs the wait.
    pub fn submit_without_waiting(
        &mut self,
        gpu: &GpuContext,
        buffers: Vec<wgpu::CommandBuffer>,
    ) -> Result<f64, GpuError> {
        self.unwaited += 1;
        if !self.trusted || self.unwaited.is_multiple_of(CHECK_EVERY) || self.queries.is_none() {
            return self.submit_and_measure(gpu, buffers);
        }
        self.submit_and_collect(gpu, buffers)
    }

    /// Submits `buffers`, has the timestamps mapped once the GPU is done,
    /// and returns the latest read back so far.
    fn submit_and_collect(&mut self, gpu: &GpuContext, buffers: Vec<wgpu::CommandBuffer>) -> Result<f64, GpuError> {
        gpu.queue.submit(buffers);
        let Some((_, _, read)) = &self.queries else { return Ok(self.last_ms) };
        if self.state.compare_exchange(WRITTEN, MAPPING, Ordering::AcqRel, Ordering::Acquire).is_ok() {
            let state = Arc::clone(&self.state);
            read.slice(..).map_async(wgpu::MapMode::Read, move |result| {
                state.store(if result.is_ok() { MAPPED } else { FREE }, Ordering::Release);
            });
        }
        self.collect(gpu)?;
        Ok(self.last_ms)
    }

    /// Reads timestamps a finished frame left mapped, if any.
    pub fn collect(&mut self, gpu: &GpuContext) -> Result<(), GpuError> {
        gpu.device.poll(wgpu::PollType::Poll).map_err(|e| GpuError::Readback(e.to_string()))?;
        let Some((_, _, read)) = &self.queries else { return Ok(()) };
        if self.state.load(Ordering::Acquire) != MAPPED {
            return Ok(());
        }
        let ms = read.slice(..).get_mapped_range().ok().map(|bytes| self.milliseconds(&bytes));
        read.unmap();
        self.state.store(FREE, Ordering::Release);
        self.last_ms = ms.unwrap_or(self.last_ms);
        Ok(())
    }

    /// Submits `buffers`, waits, and returns the pass's milliseconds (GPU
    /// timestamps if available, else wall time of submit + wait).
    /// In the browser, which cannot wait for the GPU, the latest time read
    /// back so far (a frame or more old), as for frames that do not wait.
    pub fn submit_and_measure(&mut self, gpu: &GpuContext, buffers: Vec<wgpu::CommandBuffer>) -> Result<f64, GpuError> {
        if cfg!(target_arch = "wasm32") {
            return self.submit_and_collect(gpu, buffers);
        }
        let start = Instant::now();
        gpu.queue.submit(buffers);
        gpu.wait()?;
        let wall_ms = start.elapsed().as_secs_f64() * 1e3;
        if let Some((_, _, read)) = &self.queries
            && self.state.load(Ordering::Acquire) == WRITTEN
        {
            let bytes = read_buffer(gpu, read)?;
            self.state.store(FREE, Ordering::Release);
            let ms = self.milliseconds(&bytes);
            if wall_ms > IMPLAUSIBLE_ABOVE_MS && ms < wall_ms * IMPLAUSIBLE_SHARE {
                log::warn!(
                    "GPU timestamps say {ms:.3} ms for a {wall_ms:.1} ms frame; timing by the wall clock from now on"
                );
                self.trusted = false;
            } else {
                self.last_ms = ms;
                return Ok(ms);
            }
        } else {
            // No timestamps, or this pass had none (a read-back was under way).
            self.collect(gpu)?;
        }
        self.last_ms = wall_ms;
        Ok(wall_ms)
    }

    /// Whether this pass records timestamps: they are trusted and the
    /// read-back buffer is free.
    fn recording(&self) -> bool {
        self.trusted && self.state.load(Ordering::Acquire) == FREE
    }

    /// Whether the pass times come from GPU timestamps (else the wall clock).
    pub fn uses_timestamps(&self) -> bool {
        self.queries.is_some() && self.trusted
    }

    /// Milliseconds between the two timestamps in `bytes`.
    fn milliseconds(&self, bytes: &[u8]) -> f64 {
        let tick = |i: usize| bytes.get(i * 8..i * 8 + 8).and_then(|b| b.try_into().ok()).map_or(0, u64::from_le_bytes);
        tick(1).wrapping_sub(tick(0)) as f64 * self.period_ns / 1e6
    }
}
