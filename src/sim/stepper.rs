//! Time stepping: fixed step with an accumulator, or one clamped step per frame.
//!
//! Simulated time is an f64 sum of step sizes and a u64 step count — never an
//! ever-growing f32 clock.

use crate::effect::{TimeMode, TimeSettings};

/// Turns wall-clock frame times into simulation steps.
#[derive(Clone, Debug, Default)]
pub struct Stepper {
    accumulator_secs: f64,
    /// Steps dropped by the max-substeps cap since the start.
    pub dropped_steps: u64,
}

/// What one frame should simulate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepPlan {
    /// Number of steps to run this frame.
    pub steps: u32,
    /// Size of each step, seconds.
    pub dt_secs: f32,
    /// Render interpolation between the previous and the current state, 0..1.
    pub alpha: f32,
}

impl Stepper {
    /// Plans the steps for a frame that took `frame_dt_secs` of wall-clock time.
    pub fn advance(&mut self, frame_dt_secs: f64, time: &TimeSettings) -> StepPlan {
        let scaled = (frame_dt_secs.max(0.0) * time.speed as f64).min(3600.0);
        match time.mode {
            TimeMode::FixedStep => {
                let dt = time.step_secs as f64;
                self.accumulator_secs += scaled;
                // A hair of tolerance so 2 s of 1/144 s frames is exactly 240 steps of 1/120 s.
                let wanted = (self.accumulator_secs / dt + 1e-9).floor();
                self.accumulator_secs = (self.accumulator_secs - wanted * dt).max(0.0);
                let mut steps = wanted as u64;
                if steps > time.max_substeps as u64 {
                    // Drop the excess: a hitch must not snowball into a spiral of death.
                    self.dropped_steps += steps - time.max_substeps as u64;
                    steps = time.max_substeps as u64;
                }
                StepPlan {
                    steps: steps as u32,
                    dt_secs: time.step_secs,
                    alpha: (self.accumulator_secs / dt).clamp(0.0, 1.0) as f32,
                }
            }
            TimeMode::FrameDelta => {
                let dt = scaled.min(time.max_frame_dt_secs as f64) as f32;
                StepPlan {
                    steps: u32::from(dt > 0.0),
                    dt_secs: dt,
                    alpha: 1.0,
                }
            }
        }
    }

    /// Forgets accumulated time (restart).
    pub fn reset(&mut self) {
        *self = Self::default();
    }
}
