//! `ignis edit --profile`: where a frame's time goes, stage by stage.
//!
//! The GPU is drained after every stage, so each stage's wall time includes the GPU work
//! it submitted. This serialises CPU and GPU (the frame gets slower than without it), but
//! on a software adapter, where the "GPU" is the same two cores, the split is what
//! matters.

use std::time::Instant;

use crate::gpu::GpuContext;

use crate::editor::diagnostics::stats::median;

/// The stages of one editor frame, in order.
pub const STAGES: [&str; 5] = [
    "ui",
    "simulation",
    "viewport render",
    "egui paint",
    "present",
];

/// Per-stage timings of every profiled frame.
#[derive(Debug)]
pub struct StageProfiler {
    is_enabled: bool,
    last: Instant,
    stage: usize,
    secs: [Vec<f32>; STAGES.len()],
}

impl StageProfiler {
    /// A profiler; a disabled one costs nothing and never waits.
    pub fn new(is_enabled: bool) -> Self {
        Self {
            is_enabled,
            last: Instant::now(),
            stage: 0,
            secs: Default::default(),
        }
    }

    /// Starts a frame: drains the GPU so the first stage starts clean.
    pub fn begin(&mut self, ctx: &GpuContext) {
        if self.is_enabled {
            drain(ctx);
            self.last = Instant::now();
            self.stage = 0;
        }
    }

    /// Ends the current stage (after draining the GPU) and starts the next.
    pub fn end_stage(&mut self, ctx: &GpuContext) {
        if !self.is_enabled {
            return;
        }
        drain(ctx);
        let now = Instant::now();
        if let Some(v) = self.secs.get_mut(self.stage) {
            v.push(now.duration_since(self.last).as_secs_f32());
        }
        self.stage += 1;
        self.last = now;
    }

    /// "stage median ms" for every stage, skipping the first `warmup` frames; `None`
    /// when disabled.
    pub fn report(&self, warmup: usize) -> Option<String> {
        if !self.is_enabled {
            return None;
        }
        let parts: Vec<String> = STAGES
            .iter()
            .zip(&self.secs)
            .map(|(name, v)| {
                let skip = warmup.min(v.len().saturating_sub(1));
                format!("{name} {:.1}", median(&v[skip..]) * 1e3)
            })
            .collect();
        Some(format!(
            "profile (median ms per stage, GPU drained after each): {}",
            parts.join(", ")
        ))
    }
}

fn drain(ctx: &GpuContext) {
    if let Err(err) = ctx.device.poll(wgpu::PollType::wait_indefinitely()) {
        log::warn!("profiling: waiting for the GPU failed: {err}");
    }
}
