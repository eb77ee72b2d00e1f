//! Seeking: [`Player::seek`] puts the clock at any time with the state playing there would
//! reach. It replays the steps as fast as the GPU goes, from the start or — with fixed
//! steps and [`Player::keep_seek_snapshots`] — from the latest snapshot at or before the
//! target. Snapshots are taken only of a state simulated from time 0 under the current
//! effect (after a restart or a seek, until the next change). A snapshot is every instance's state after a step (GPU copies of its buffers
//! and its planning); with fixed steps the state after step `n` does not depend on the
//! frames that got there, so snapshots taken while playing at any rate serve any seek.

use crate::effect::TimeMode;
use crate::sim::snapshot::SimSnapshot;
use crate::sim::stepper::Stepper;

use super::instances::Backing;
use super::player::{MAX_STEPS_PER_RECORD, Player};

/// A seek waits for the GPU after this many submits (bounding the staging memory in
/// flight).
const SUBMITS_PER_WAIT: u64 = 32;

/// Frames one seek replays at most (a seek beyond is cut there).
const MAX_SEEK_FRAMES: u64 = 10_000_000;

/// The snapshots a player keeps, and when the next is due.
#[derive(Default)]
pub(super) struct SeekSnapshots {
    /// Steps between snapshots (0: none are kept).
    every_steps: u64,
    /// `every_steps` as asked (the memory bound doubles `every_steps`; a clear resets it).
    asked_steps: u64,
    /// The state is all of the current effect: simulated from time 0 (a restart or a
    /// seek) since the last change. Snapshots are taken only then.
    clean: bool,
    /// GPU memory the snapshots may take.
    max_bytes: u64,
    /// Oldest first, each with the step after which it was taken.
    list: Vec<(u64, Vec<SimSnapshot>)>,
    /// The step the last seek restored a snapshot of (`None`: it replayed from time 0).
    last_start: Option<u64>,
}

impl SeekSnapshots {
    /// Forgets every snapshot (the effect, a seed, a shader or the instances changed):
    /// none is taken again until the clock restarts from time 0.
    pub(super) fn clear(&mut self) {
        self.list.clear();
        self.every_steps = self.asked_steps;
        self.clean = false;
    }

    /// The clock went back to time 0 under the current effect: snapshots may be taken.
    pub(super) fn restarted(&mut self) {
        self.clean = true;
    }

    fn bytes(&self) -> u64 {
        self.list
            .iter()
            .flat_map(|(_, sims)| sims)
            .map(SimSnapshot::bytes)
            .sum()
    }
}

impl Player {
    /// Keeps a snapshot of every instance every `every_secs` of simulated time (fixed-step
    /// effects whose instances have simulations of their own, as the editor's), within
    /// `max_bytes` of GPU memory: when more would be needed, every other snapshot is
    /// dropped and the interval doubles. `every_secs` ≤ 0 keeps none. Snapshots are
    /// forgotten when the effect, a seed or the instances change.
    pub fn keep_seek_snapshots(&mut self, every_secs: f64, max_bytes: u64) {
        let step = f64::from(self.effect.time.step_secs).max(1e-6);
        let every_steps = if every_secs > 0.0 && every_secs.is_finite() {
            (every_secs / step).round().clamp(1.0, 1e12) as u64
        } else {
            0
        };
        self.snapshots = SeekSnapshots {
            every_steps,
            asked_steps: every_steps,
            clean: false,
            max_bytes,
            list: Vec::new(),
            last_start: None,
        };
        // A player still at time 0 may take snapshots from now; else from its next restart.
        if self.steps_done().is_none_or(|s| s == 0) {
            self.snapshots.restarted();
        }
    }

    /// GPU memory the seek snapshots hold now, and how many there are.
    pub fn seek_snapshot_bytes(&self) -> (u64, usize) {
        (self.snapshots.bytes(), self.snapshots.list.len())
    }

    /// Where the last [`Player::seek`] started its replay: the simulated time (seconds) of
    /// the snapshot it restored, or `None` when it replayed from time 0 (no snapshot at or
    /// before its target, or none kept). A tool can show what a seek cost with it.
    pub fn last_seek_start_secs(&self) -> Option<f64> {
        let step = self.snapshots.last_start?;
        Some(step as f64 * f64::from(self.effect.time.step_secs))
    }

    /// Whether snapshots can stand for this player's state: fixed steps, and every
    /// instance with a simulation of its own.
    fn snapshots_apply(&self) -> bool {
        self.snapshots.asked_steps > 0
            && self.effect.time.mode == TimeMode::FixedStep
            && self
                .instances
                .iter()
                .all(|i| matches!(i.state, Backing::Own(_)))
    }

    /// Steps simulated so far (every instance steps together).
    fn steps_done(&self) -> Option<u64> {
        self.instances.iter().find_map(|i| match &i.state {
            Backing::Own(sim) => Some(sim.planner.step_index),
            Backing::Batched { .. } => None,
        })
    }

    /// After a record's steps: a snapshot when one is due (copies recorded into `enc`).
    pub(super) fn take_snapshot_if_due(&mut self, enc: &mut wgpu::CommandEncoder) {
        if !self.snapshots_apply() || !self.snapshots.clean {
            return;
        }
        let Some(step) = self.steps_done() else {
            return;
        };
        let every = self.snapshots.every_steps;
        let last = self.snapshots.list.last().map_or(0, |(s, _)| *s);
        if step < last + every || self.snapshots.list.iter().any(|(s, _)| *s == step) {
            return;
        }
        let sims = self
            .instances
            .iter()
            .filter_map(|i| match &i.state {
                Backing::Own(sim) => Some(sim.snapshot(enc)),
                Backing::Batched { .. } => None,
            })
            .collect();
        let at = self.snapshots.list.partition_point(|(s, _)| *s < step);
        self.snapshots.list.insert(at, (step, sims));
        while self.snapshots.bytes() > self.snapshots.max_bytes && !self.snapshots.list.is_empty() {
            let mut k = 0;
            self.snapshots.list.retain(|_| {
                k += 1;
                k % 2 == 0
            });
            self.snapshots.every_steps *= 2;
        }
    }

    /// Plays the clock from the start to `secs` as fast as the GPU goes: the frames of
    /// `frame_dt_secs` that playing to `secs` would have taken (the nearest whole number)
    /// are replayed, each frame's steps recorded and submitted at once, with no sort or
    /// draw — from the latest snapshot at or before the target when there is one. The
    /// state after it is bit-identical to playing those frames one by one (with fixed
    /// steps, to playing to `secs` at any frame rate), and so is the next frame's
    /// interpolation. The pause is kept. Returns the frames the seek stands for: 0 for a
    /// time or frame duration that is not a positive finite number (the clock restarts).
    pub fn seek(&mut self, secs: f64, frame_dt_secs: f64) -> u64 {
        let frames = if secs > 0.0 && frame_dt_secs > 0.0 && secs.is_finite() {
            ((secs / frame_dt_secs).round() as u64).min(MAX_SEEK_FRAMES)
        } else {
            0
        };
        if self.snapshots_apply() {
            self.seek_fixed_steps(frames, frame_dt_secs);
        } else {
            self.replay_frames((0..frames).map(|_| frame_dt_secs));
        }
        frames
    }

    /// Plays the clock from the start through exactly these frames (their wall-clock
    /// durations), as fast as the GPU goes: the state playing them one by one reaches,
    /// bit for bit, whatever the time mode — the way to seek a frame-delta effect, whose
    /// state depends on every frame's duration. The pause is kept.
    pub fn replay(&mut self, frame_dts_secs: &[f64]) {
        self.replay_frames(frame_dts_secs.iter().copied());
    }

    /// [`Player::replay`] over any sequence of frame durations.
    fn replay_frames(&mut self, frame_dts_secs: impl Iterator<Item = f64>) {
        let was_paused = std::mem::replace(&mut self.is_paused, false);
        self.restart();
        self.snapshots.clean = true;
        self.snapshots.last_start = None;
        for (frame, dt) in frame_dts_secs.enumerate() {
            self.advance(dt);
            self.submit_steps(frame as u64);
        }
        self.simulated = false;
        self.is_paused = was_paused;
    }

    /// [`Player::seek`] with fixed steps: the steps those frames take (counted on the CPU),
    /// replayed from the latest snapshot at or before them.
    fn seek_fixed_steps(&mut self, frames: u64, frame_dt_secs: f64) {
        // Each frame runs its steps (as playing does: the stepper's cap, then every step).
        let mut stepper = Stepper::default();
        let (mut steps, mut alpha) = (0u64, 1.0);
        for _ in 0..frames {
            let plan = stepper.advance(frame_dt_secs, &self.effect.time);
            steps += u64::from(plan.steps);
            alpha = plan.alpha;
        }
        self.restart();
        self.snapshots.clean = true;
        let from = self.restore_latest(steps);
        self.snapshots.last_start = (from > 0).then_some(from);
        let dt = self.effect.time.step_secs;
        let mut done = from;
        let mut submits = 0;
        while done < steps {
            let k = (steps - done).min(u64::from(MAX_STEPS_PER_RECORD)) as u32;
            self.pending = (k, dt);
            self.submit_steps(submits);
            done += u64::from(k);
            submits += 1;
        }
        self.stepper = stepper;
        self.alpha = alpha;
        self.pending = (0, 0.0);
        // Every step is recorded and nothing is pending: the next `record` steps nothing.
        self.simulated = false;
    }

    /// Restores the latest snapshot taken at or before step `steps` into every instance;
    /// returns its step (0 when none applies: the restarted state).
    fn restore_latest(&mut self, steps: u64) -> u64 {
        let Some(i) = self.snapshots.list.iter().rposition(|(s, _)| *s <= steps) else {
            return 0;
        };
        let (step, sims) = &self.snapshots.list[i];
        let step = *step;
        let mut enc = self
            .ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("ignis::seek::restore"),
            });
        let restored = self
            .instances
            .iter_mut()
            .filter_map(|i| match &mut i.state {
                Backing::Own(sim) => Some(sim),
                Backing::Batched { .. } => None,
            })
            .zip(sims)
            .all(|(sim, snap)| sim.restore(&mut enc, snap));
        self.ctx.queue.submit([enc.finish()]);
        if restored {
            step
        } else {
            // A pool changed under the snapshot: start again from time 0.
            self.snapshots.list.clear();
            self.restart();
            0
        }
    }

    /// Records the pending steps in an encoder of their own and submits it (waiting for
    /// the GPU every few submits, so that staging memory is reused).
    fn submit_steps(&mut self, index: u64) {
        let mut enc = self
            .ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("ignis::seek"),
            });
        self.simulate(&mut enc);
        self.ctx.queue.submit([enc.finish()]);
        if index % SUBMITS_PER_WAIT == SUBMITS_PER_WAIT - 1 {
            let _ = self.ctx.device.poll(wgpu::PollType::wait_indefinitely());
        }
    }
}
