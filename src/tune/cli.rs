//! `ignis tune`'s arguments, checked before anything runs.

use std::path::{Path, PathBuf};

use super::{Budget, SweepOptions, TuneError};
use crate::effect::Effect;

/// `ignis tune PRESET`: the speed–accuracy trade on the effect, and the cheapest
/// settings within a budget.
#[derive(Debug, clap::Args)]
pub struct TuneArgs {
    /// The preset file.
    pub preset: PathBuf,
    /// The most image error allowed: the mean over every 8-bit sRGB channel, pixel and
    /// frame (default 0.5). The cheapest candidate within it is chosen.
    #[arg(long, conflicts_with = "budget_ms")]
    pub budget_error: Option<f64>,
    /// The most frame time allowed on this adapter, ms. The most accurate candidate within
    /// it is chosen.
    #[arg(long)]
    pub budget_ms: Option<f64>,
    /// The span played from the start, seconds (default: the effect's last burst plus its
    /// longest lifetime, 1 to 8 s).
    #[arg(long)]
    pub span: Option<f64>,
    /// The image size, WxH.
    #[arg(long, default_value = "960x540", value_parser = crate::export::cli::parse_pair)]
    pub size: (u32, u32),
    /// Frames per simulated second, each one rendered and compared.
    #[arg(long, default_value_t = 30.0)]
    pub fps: f64,
    /// Frames timed after the span for each candidate (the median is its cost).
    #[arg(long, default_value_t = 10)]
    pub cost_frames: usize,
    /// The fixed steps tried, in steps per second (the finest's reference sets most of
    /// the sweep's time).
    #[arg(long, value_delimiter = ',', default_values_t = super::RATES)]
    pub rates: Vec<u32>,
    /// Skip playing the reference at half its step (the check that it has converged).
    #[arg(long)]
    pub no_reference_check: bool,
    /// Output folder.
    #[arg(long, default_value = "tune")]
    pub out: PathBuf,
}

impl TuneArgs {
    /// The budget asked for (checked).
    pub fn budget(&self) -> Result<Budget, TuneError> {
        match (self.budget_error, self.budget_ms) {
            (_, Some(ms)) => Budget::FrameMs(ms),
            (e, None) => Budget::ErrorMean(e.unwrap_or(0.5)),
        }
        .check()
    }

    /// The sweep's options for `effect` (checked).
    pub fn options(&self, effect: &Effect) -> Result<SweepOptions, TuneError> {
        let natural = SweepOptions::for_effect(effect);
        let opts = SweepOptions {
            span_secs: self.span.unwrap_or(natural.span_secs),
            size: self.size,
            fps: self.fps,
            cost_frames: self.cost_frames.max(1),
            check_reference: !self.no_reference_check,
            asset_dir: self.preset.parent().map(Path::to_path_buf),
            rates: self.rates.clone(),
        };
        opts.check()?;
        Ok(opts)
    }
}
