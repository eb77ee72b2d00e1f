//! What `ignis edit --frames N` reports, and the per-frame log it is made from.

use std::time::{Duration, Instant};

use crate::editor::diagnostics::stats::median;

/// Frames left out of the reported median (start-up: pipeline creation, first present).
pub const WARMUP_FRAMES: usize = 3;

/// The frame clock: intervals between frames and the CPU time of their recording.
#[derive(Debug, Default)]
pub struct FrameLog {
    /// Frames begun (the first is 1).
    pub index: u64,
    last: Option<Instant>,
    frame_secs: Vec<f32>,
    cpu_secs: Vec<f32>,
}

/// This frame's place in the run.
#[derive(Clone, Copy, Debug)]
pub struct Tick {
    /// Time since the last frame began, seconds (1/60 for the first).
    pub dt_secs: f64,
    /// The last frame of a `--frames` run.
    pub is_last: bool,
}

impl FrameLog {
    /// Begins a frame of a run that ends after `frames` (if given).
    pub fn tick(&mut self, frames: Option<u32>) -> Tick {
        let now = Instant::now();
        let dt_secs = self
            .last
            .map_or(1.0 / 60.0, |t| now.duration_since(t).as_secs_f64());
        self.last = Some(now);
        self.index += 1;
        Tick {
            dt_secs,
            is_last: frames.is_some_and(|n| self.index >= u64::from(n)),
        }
    }

    /// Records a frame's interval and CPU time (the first frame, start-up, is left out).
    pub fn record(&mut self, tick: Tick, cpu: Duration) {
        if self.index > 1 {
            self.frame_secs.push(tick.dt_secs as f32);
            self.cpu_secs.push(cpu.as_secs_f32());
        }
    }

    /// Median (frame interval, CPU time) after the warm-up, seconds.
    pub fn medians(&self) -> (f32, f32) {
        let warm = self.frame_secs.len().min(WARMUP_FRAMES);
        (
            median(&self.frame_secs[warm..]),
            median(&self.cpu_secs[warm..]),
        )
    }
}

/// What a run with `--frames` measured.
#[derive(Clone, Debug)]
pub struct RunReport {
    /// Frames rendered.
    pub frames: u32,
    /// Median interval between frames after the warm-up, seconds.
    pub median_frame_secs: f32,
    /// Median CPU wall time of the sim + render recording, seconds.
    pub median_cpu_secs: f32,
    /// Particles alive at the end.
    pub alive: u64,
    /// The viewport's render size, pixels.
    pub viewport_px: (u32, u32),
    /// The window's size, pixels.
    pub window_px: (u32, u32),
    /// The adapter.
    pub adapter: String,
    /// The per-stage breakdown (`--profile`).
    pub profile: Option<String>,
    /// GPU devices lost and recreated during the run.
    pub devices_recreated: u32,
    /// With the retained window image: (frames painted in full, viewport-only frames).
    pub ui_repaints: Option<(u64, u64)>,
    /// `--edit-around-loss`: what the scripted edits ended with.
    pub edits: Option<String>,
}

impl std::fmt::Display for RunReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let fps = if self.median_frame_secs > 0.0 {
            1.0 / self.median_frame_secs
        } else {
            0.0
        };
        write!(
            f,
            "edit: {} frames, median frame {:.1} ms ({:.1} fps), median CPU wall time (sim + \
                render recording) {:.1} ms; window {}x{}, viewport {}x{} px, {} particles \
                alive, on {}",
            self.frames,
            self.median_frame_secs * 1e3,
            fps,
            self.median_cpu_secs * 1e3,
            self.window_px.0,
            self.window_px.1,
            self.viewport_px.0,
            self.viewport_px.1,
            self.alive,
            self.adapter
        )?;
        if let Some((full, live)) = self.ui_repaints {
            write!(
                f,
                "\nretained UI: {full} frames painted in full, {live} only over the viewport \
                    and timeline"
            )?;
        }
        if self.devices_recreated > 0 {
            write!(
                f,
                "\nGPU device lost and recreated {} time(s); the effect and its undo history \
                    were kept",
                self.devices_recreated
            )?;
        }
        if let Some(edits) = &self.edits {
            write!(f, "\n{edits}")?;
        }
        if let Some(profile) = &self.profile {
            write!(f, "\n{profile}")?;
        }
        Ok(())
    }
}
