//! The GPU's own time for a render: timestamps at the start and end of each
//! compute pass, where the device has them.

use super::{Gpu, GpuError, Prepared};

/// The start and end stamps of each compute pass of a render (a band of
/// rows, the display), resolved and read back together.
pub(super) struct Timer {
    queries: wgpu::QuerySet,
    resolved: wgpu::Buffer,
    readback: wgpu::Buffer,
}

/// Passes stamped before the stamps are read back.
pub(super) const TIMER_PAIRS: u32 = 64;

impl Timer {
    /// The stamps of a prepared scene's passes, where `gpu` has them.
    pub(super) fn new(gpu: &Gpu) -> Option<Timer> {
        gpu.timestamps.then(|| Timer {
            queries: gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass times"),
                ty: wgpu::QueryType::Timestamp,
                count: 2 * TIMER_PAIRS,
            }),
            resolved: gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("pass times"),
                size: wgpu::QUERY_RESOLVE_BUFFER_ALIGNMENT * TIMER_PAIRS as u64,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            readback: gpu.readback("readback", 16 * TIMER_PAIRS as u64),
        })
    }
}

impl Prepared<'_> {
    /// The GPU's own time (s) for the last render or pass, from its
    /// timestamps: the tracing, resolving and display passes without the
    /// host's waits, uploads and read-backs. None where the device has no
    /// timestamps.
    pub fn device_seconds(&self) -> Option<f64> {
        *self.device_seconds.lock().expect("device time")
    }

    pub(super) fn start_device_time(&self) {
        *self.device_seconds.lock().expect("device time") = None;
    }

    pub(super) fn add_device_time(&self, seconds: f64) {
        *self
            .device_seconds
            .lock()
            .expect("device time")
            .get_or_insert(0.0) += seconds;
    }

    /// Resolves the stamps of the `pair`-th pass, in the command buffer of
    /// the pass itself (lavapipe's stamps resolved in a later submission
    /// measured only a fraction of the work).
    pub(super) fn resolve_stamps(&self, enc: &mut wgpu::CommandEncoder, pair: u32) {
        if let Some(t) = &self.timer {
            let at = wgpu::QUERY_RESOLVE_BUFFER_ALIGNMENT * pair as u64;
            enc.resolve_query_set(&t.queries, 2 * pair..2 * pair + 2, &t.resolved, at);
            enc.copy_buffer_to_buffer(&t.resolved, at, &t.readback, 16 * pair as u64, 16);
        }
    }

    /// Reads back the stamps of the first `pairs` passes since the last
    /// read (resolved by [`Prepared::resolve_stamps`]): their GPU time (s).
    pub(super) fn read_times(&self, pairs: u32) -> Result<f64, GpuError> {
        let (Some(t), true) = (&self.timer, pairs > 0) else {
            return Ok(0.0);
        };
        let gpu = self.gpu;
        let stamps: Vec<u64> = gpu.read(&t.readback, 16 * pairs as u64)?;
        let ticks: u64 = stamps
            .chunks_exact(2)
            .map(|p| p[1].saturating_sub(p[0]))
            .sum();
        Ok(ticks as f64 * gpu.queue.get_timestamp_period() as f64 * 1e-9)
    }

    /// The timestamp writes of the `pair`-th compute pass, where the device
    /// has them.
    pub(super) fn stamps(&self, pair: u32) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        self.timer
            .as_ref()
            .map(|t| wgpu::ComputePassTimestampWrites {
                query_set: &t.queries,
                beginning_of_pass_write_index: Some(2 * pair),
                end_of_pass_write_index: Some(2 * pair + 1),
            })
    }
}
