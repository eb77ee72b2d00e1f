//! Timing GPU work: timestamp queries where the adapter has trustworthy ones, CPU wall
//! time otherwise (software adapters such as lavapipe, whose timestamps we measured to
//! disagree with the wall clock), always labelled with its source.

use crate::gpu::GpuContext;
use crate::sim::gpu_sim::map_read;

/// Where a duration came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TimingSource {
    /// GPU timestamp queries around the recorded work.
    GpuTimestamps,
    /// Submit-to-idle wall clock (includes submission overhead).
    CpuWallTime,
}

impl TimingSource {
    /// A label for tables and the stats panel.
    pub fn label(self) -> &'static str {
        match self {
            TimingSource::GpuTimestamps => "GPU timestamps",
            TimingSource::CpuWallTime => "CPU wall time",
        }
    }
}

/// Measures the duration of recorded GPU work (blocking; benches and tests).
pub struct GpuTimer {
    queries: Option<(wgpu::QuerySet, wgpu::Buffer)>,
    period_ns: f64,
    /// What `time` measures with.
    pub source: TimingSource,
}

/// The features to request for timing, when the adapter has them.
pub fn timing_features(adapter: &wgpu::Adapter) -> wgpu::Features {
    adapter.features()
        & (wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS)
}

impl GpuTimer {
    /// Timestamps when the device has them and is not a CPU adapter, wall time otherwise.
    pub fn new(ctx: &GpuContext) -> Self {
        let wanted =
            wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS;
        if ctx.device.features().contains(wanted) && !ctx.is_cpu_adapter() {
            let set = ctx.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("GpuTimer::queries"),
                ty: wgpu::QueryType::Timestamp,
                count: 2,
            });
            let resolve = ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("GpuTimer::resolve"),
                size: 16,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            Self {
                queries: Some((set, resolve)),
                period_ns: ctx.queue.get_timestamp_period() as f64,
                source: TimingSource::GpuTimestamps,
            }
        } else {
            Self {
                queries: None,
                period_ns: 1.0,
                source: TimingSource::CpuWallTime,
            }
        }
    }

    /// Records `work` into a fresh encoder, submits it, waits, and returns its duration
    /// in milliseconds.
    pub fn time(&self, ctx: &GpuContext, work: impl FnOnce(&mut wgpu::CommandEncoder)) -> f64 {
        // Drain earlier work so the wall clock measures only this submission.
        let _ = ctx.device.poll(wgpu::PollType::wait_indefinitely());
        let mut enc = ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("GpuTimer::time"),
            });
        if let Some((set, _)) = &self.queries {
            enc.write_timestamp(set, 0);
        }
        work(&mut enc);
        let readback = self.queries.as_ref().map(|(set, resolve)| {
            enc.write_timestamp(set, 1);
            enc.resolve_query_set(set, 0..2, resolve, 0);
            let staging = ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("GpuTimer::staging"),
                size: 16,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            enc.copy_buffer_to_buffer(resolve, 0, &staging, 0, 16);
            staging
        });
        let start = std::time::Instant::now();
        ctx.queue.submit([enc.finish()]);
        let _ = ctx.device.poll(wgpu::PollType::wait_indefinitely());
        let wall_ms = start.elapsed().as_secs_f64() * 1e3;
        match readback.map(|staging| map_read(ctx, &staging)) {
            Some(Ok(bytes)) => {
                let t: Vec<u64> = bytemuck::pod_collect_to_vec(&bytes);
                t[1].saturating_sub(t[0]) as f64 * self.period_ns * 1e-6
            }
            _ => wall_ms,
        }
    }
}

/// The median of a list of samples (NaN when empty).
pub fn median(samples: &mut [f64]) -> f64 {
    if samples.is_empty() {
        return f64::NAN;
    }
    samples.sort_by(|a, b| a.total_cmp(b));
    let n = samples.len();
    if n % 2 == 1 {
        samples[n / 2]
    } else {
        0.5 * (samples[n / 2 - 1] + samples[n / 2])
    }
}
