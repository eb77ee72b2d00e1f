//! Timing GPU work: timestamp queries where the adapter has trustworthy ones, CPU wall
//! time otherwise (software adapters such as lavapipe, whose timestamps we measured to
//! disagree with the wall clock), always labelled with its source.

use crate::gpu::GpuContext;
use crate::gpu::readback::map_read;

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
        if ctx.device.features().contains(wanted) && ctx.profile.timestamps {
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

#[cfg(feature = "editor")]
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

/// Frames in flight the pass timer can wait on before it skips timing a frame.
const RING: usize = 3;
/// Timestamp spans per frame.
const MAX_SPANS: u32 = 8;

#[derive(Default)]
enum SlotState {
    #[default]
    Free,
    /// Recorded into the current frame's encoder.
    Recording(Vec<&'static str>),
    /// Submitted; the map request is in flight.
    Mapping(
        Vec<&'static str>,
        std::sync::Arc<std::sync::atomic::AtomicBool>,
    ),
}

/// Per-pass GPU timestamps for a running frame loop, read back without stalling: a ring
/// of query buffers, each mapped asynchronously and read a frame or two later.
pub struct PassTimer {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readbacks: Vec<wgpu::Buffer>,
    states: Vec<SlotState>,
    current: Option<usize>,
    next: usize,
    period_ns: f64,
    /// The latest complete measurement: (pass label, milliseconds).
    pub latest: Vec<(&'static str, f64)>,
    /// How many measurements have completed (`latest` is the last of them).
    pub completed: u64,
}

impl PassTimer {
    /// A pass timer when the device has trustworthy timestamps (not a CPU adapter).
    pub fn new(ctx: &GpuContext) -> Option<Self> {
        if !Self::available(ctx) {
            return None;
        }
        Self::new_even_on_cpu(ctx)
    }

    /// Whether [`PassTimer::new`] gives a timer on this device.
    pub fn available(ctx: &GpuContext) -> bool {
        ctx.profile.timestamps && ctx.device.features().contains(Self::FEATURES)
    }

    /// The device features a pass timer needs.
    const FEATURES: wgpu::Features =
        wgpu::Features::TIMESTAMP_QUERY.union(wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS);

    /// A pass timer whenever the device has the timestamp features (tests use this on
    /// software adapters, whose readings are not trusted for figures).
    pub fn new_even_on_cpu(ctx: &GpuContext) -> Option<Self> {
        if !ctx.device.features().contains(Self::FEATURES) {
            return None;
        }
        let count = MAX_SPANS * 2;
        let set = ctx.device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("PassTimer::queries"),
            ty: wgpu::QueryType::Timestamp,
            count,
        });
        let size = count as u64 * 8;
        let resolve = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("PassTimer::resolve"),
            size,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let readbacks = (0..RING)
            .map(|_| {
                ctx.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("PassTimer::readback"),
                    size,
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                })
            })
            .collect();
        Some(Self {
            set,
            resolve,
            readbacks,
            states: (0..RING).map(|_| SlotState::Free).collect(),
            current: None,
            next: 0,
            period_ns: ctx.queue.get_timestamp_period() as f64,
            latest: Vec::new(),
            completed: 0,
        })
    }

    /// Starts a frame; returns false (and times nothing this frame) when every readback
    /// buffer is still in flight.
    pub fn begin_frame(&mut self) -> bool {
        let slot = self.next;
        if matches!(self.states[slot], SlotState::Free) {
            self.states[slot] = SlotState::Recording(Vec::new());
            self.current = Some(slot);
            self.next = (slot + 1) % RING;
            true
        } else {
            self.current = None;
            false
        }
    }

    /// Records `work` between two timestamps labelled `label`.
    pub fn scope<R>(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        label: &'static str,
        work: impl FnOnce(&mut wgpu::CommandEncoder) -> R,
    ) -> R {
        let index = match self.current.map(|s| &mut self.states[s]) {
            Some(SlotState::Recording(labels)) if (labels.len() as u32) < MAX_SPANS => {
                labels.push(label);
                Some(labels.len() as u32 - 1)
            }
            _ => None,
        };
        if let Some(i) = index {
            enc.write_timestamp(&self.set, 2 * i);
        }
        let r = work(enc);
        if let Some(i) = index {
            enc.write_timestamp(&self.set, 2 * i + 1);
        }
        r
    }

    /// Resolves this frame's timestamps into its readback buffer (before `finish`).
    pub fn end_frame(&mut self, enc: &mut wgpu::CommandEncoder) {
        let Some(slot) = self.current else {
            return;
        };
        if let SlotState::Recording(labels) = &self.states[slot]
            && !labels.is_empty()
        {
            let n = labels.len() as u32 * 2;
            enc.resolve_query_set(&self.set, 0..n, &self.resolve, 0);
            enc.copy_buffer_to_buffer(&self.resolve, 0, &self.readbacks[slot], 0, n as u64 * 8);
        }
    }

    /// Call after the frame's submit: requests the asynchronous map.
    pub fn after_submit(&mut self) {
        let Some(slot) = self.current.take() else {
            return;
        };
        let labels = match std::mem::take(&mut self.states[slot]) {
            SlotState::Recording(labels) if !labels.is_empty() => labels,
            _ => return,
        };
        let done = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        let flag = done.clone();
        self.readbacks[slot]
            .slice(..)
            .map_async(wgpu::MapMode::Read, move |r| {
                if r.is_ok() {
                    flag.store(true, std::sync::atomic::Ordering::Release);
                }
            });
        self.states[slot] = SlotState::Mapping(labels, done);
    }

    /// Collects finished measurements into `latest` (non-blocking).
    pub fn poll(&mut self, ctx: &GpuContext) {
        let _ = ctx.device.poll(wgpu::PollType::Poll);
        for slot in 0..RING {
            let ready = matches!(&self.states[slot], SlotState::Mapping(_, done) if done.load(std::sync::atomic::Ordering::Acquire));
            if !ready {
                continue;
            }
            if let SlotState::Mapping(labels, _) = std::mem::take(&mut self.states[slot]) {
                let buffer = &self.readbacks[slot];
                let times: Option<Vec<u64>> = buffer
                    .slice(..)
                    .get_mapped_range()
                    .ok()
                    .map(|v| bytemuck::pod_collect_to_vec(&v));
                buffer.unmap();
                if let Some(t) = times {
                    self.latest = labels
                        .iter()
                        .enumerate()
                        .map(|(i, l)| {
                            (
                                *l,
                                t[2 * i + 1].saturating_sub(t[2 * i]) as f64
                                    * self.period_ns
                                    * 1e-6,
                            )
                        })
                        .collect();
                    self.completed += 1;
                }
            }
        }
    }
}
