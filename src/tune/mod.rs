//! `ignis tune`: the speed–accuracy trade measured on the designer's own effect.
//!
//! Every candidate setting — each integrator at each step, each state layout, each
//! optional module of each emitter switched off, each draw path, then combinations along
//! the frontier — is played over the effect's span and its frames compared with a
//! converged reference (RK4 at a sixteenth of the effect's step, full state, billboards):
//! the image error a designer would see, next to what the candidate costs on this
//! adapter. [`Sweep`] does the work a frame at a time; [`TuneReport`] holds the frontier,
//! the choice within a budget and what the scene does not need, and writes the table, the
//! JSON, the SVG plot and the tuned preset.

mod candidate;
pub mod cli;
mod frontier;
mod image_error;
mod report;
pub(crate) mod svg;
mod sweep;

pub use candidate::{
    Candidate, Change, Module, RATES, REFERENCE_DIVISOR, StateChoice, StepChoice, axes, reference,
    reference_step,
};
pub use frontier::{Budget, choose, pareto};
pub use image_error::{ErrorAccumulator, ImageError, Rgb, rgb_of};
pub use report::{ModuleRow, TuneReport};
pub use sweep::{Measured, Sweep, SweepOptions, measure_against_reference, measure_pair};

/// Why a tune could not run or choose.
#[derive(Debug, thiserror::Error)]
pub enum TuneError {
    /// An option is out of range (the option's name and why).
    #[error("{option}: {message}")]
    Option {
        /// The option, as the command line spells it (`--span`).
        option: String,
        /// What is wrong and what is allowed.
        message: String,
    },
    /// The effect could not be played.
    #[error(transparent)]
    Player(#[from] crate::PlayerError),
    /// A frame could not be read back.
    #[error(transparent)]
    Sim(#[from] crate::sim::SimError),
    /// No candidate is within the budget.
    #[error("no candidate is within {budget}: {best}")]
    OverBudget {
        /// The budget.
        budget: Budget,
        /// The best reached.
        best: String,
    },
    /// A result file could not be written.
    #[error("{path}: {message}")]
    Write {
        /// The file.
        path: String,
        /// What went wrong.
        message: String,
    },
}

/// Runs `sweep` to its end, calling `progress(done, total)` after each frame of work.
pub fn run_sweep(
    sweep: &mut Sweep,
    mut progress: impl FnMut(usize, usize),
) -> Result<(), TuneError> {
    while !sweep.step()? {
        let (done, total) = sweep.progress();
        progress(done, total);
    }
    Ok(())
}

impl Budget {
    /// Refuses a budget that is not a positive finite number, naming its option.
    pub fn check(self) -> Result<Self, TuneError> {
        let (option, v) = match self {
            Budget::ErrorMean(e) => ("--budget-error", e),
            Budget::FrameMs(ms) => ("--budget-ms", ms),
        };
        if v.is_finite() && v > 0.0 {
            Ok(self)
        } else {
            Err(TuneError::Option {
                option: option.into(),
                message: format!("{v} must be a positive number"),
            })
        }
    }
}
