//! A finished sweep read against a budget: the frontier, the choice, what the scene does
//! not need — printed as a table and written as `NAME.tune.json`, `NAME.tune.md`,
//! `NAME.frontier.svg` and `NAME.tuned.ron`.

use std::path::{Path, PathBuf};

use serde::Serialize;

use super::frontier::{Budget, choose, pareto};
use super::sweep::{Measured, Sweep, SweepOptions};
use super::{Change, ImageError, TuneError};
use crate::effect::Effect;

/// The error below which a module's contribution is called invisible when the budget is
/// a frame time (an error budget uses itself), 8-bit levels.
pub const INVISIBLE_MEAN: f64 = 0.5;

/// One module of one emitter: what switching it off shows and saves.
#[derive(Clone, Debug, Serialize)]
pub struct ModuleRow {
    /// `flames: turbulence`.
    pub label: String,
    /// The image error of the effect with only this module off, against the effect as
    /// authored (what the module contributes on screen).
    pub contribution: ImageError,
    /// The frame time it saves, ms (negative: noise, or it costs nothing).
    pub saves_ms: f64,
    /// Its contribution is below the budget's error: the scene does not need it.
    pub not_needed: bool,
}

/// A sweep's results against a budget.
#[derive(Clone, Debug, Serialize)]
pub struct TuneReport {
    /// The effect's name.
    pub effect: String,
    /// The adapter it ran on.
    pub adapter: String,
    /// The sweep's options.
    pub options: SweepOptions,
    /// The budget.
    pub budget: Budget,
    /// Every candidate, the effect as authored first.
    pub results: Vec<Measured>,
    /// The frontier's candidates (indices into `results`), cheapest first.
    pub frontier: Vec<usize>,
    /// The effect as authored (an index into `results`).
    pub authored: usize,
    /// The candidate the budget chooses (`None`: no candidate is within it; see
    /// [`TuneReport::over_budget`]).
    pub chosen: Option<usize>,
    /// The reference at half its step against the reference.
    pub reference_check: Option<ImageError>,
    /// Each module's contribution.
    pub modules: Vec<ModuleRow>,
    /// Candidates that could not run, and why.
    pub skipped: Vec<(String, String)>,
}

impl TuneReport {
    /// The report of a finished sweep (an error only when the effect as authored did not
    /// run).
    pub fn new(sweep: &Sweep, budget: Budget, adapter: &str) -> Result<Self, TuneError> {
        let results = sweep.results.clone();
        let authored = results
            .iter()
            .position(|m| m.candidate.changes.is_empty())
            .ok_or_else(|| TuneError::OverBudget {
                budget,
                best: "the effect as authored did not run".into(),
            })?;
        let points: Vec<(f64, f64)> = results.iter().map(|m| (m.error.mean, m.frame_ms)).collect();
        let chosen = choose(&points, budget);
        let threshold = match budget {
            Budget::ErrorMean(e) => e,
            Budget::FrameMs(_) => INVISIBLE_MEAN,
        };
        let base = &results[authored];
        let modules = results
            .iter()
            .filter(|m| matches!(m.candidate.changes[..], [Change::ModuleOff { .. }]))
            .map(|m| ModuleRow {
                label: m.label.replace(" off", ""),
                contribution: m.vs_authored,
                saves_ms: base.frame_ms - m.frame_ms,
                not_needed: m.vs_authored.mean < threshold,
            })
            .collect();
        Ok(Self {
            effect: sweep.effect().name.clone(),
            adapter: adapter.to_owned(),
            options: sweep.options().clone(),
            budget,
            frontier: pareto(&points),
            results,
            authored,
            chosen,
            reference_check: sweep.reference_check(),
            modules,
            skipped: sweep.skipped.clone(),
        })
    }

    /// Why no candidate was chosen: the budget and the best reached (`None`: one was).
    pub fn over_budget(&self) -> Option<TuneError> {
        self.chosen
            .is_none()
            .then(|| over_budget(&self.results, self.budget))
    }

    /// The chosen candidate's effect (the authored one with its changes), as a preset;
    /// `None` when none is within the budget.
    pub fn tuned_effect(&self, authored: &Effect) -> Option<Effect> {
        let mut e = self.results[self.chosen?].candidate.apply(authored);
        // A finer step keeps playing in real time down to 30 frames a second.
        let needed = super::candidate::steps_per_frame(1.0 / 30.0, e.time.step_secs);
        e.time.max_substeps = e.time.max_substeps.max(needed);
        Some(e)
    }

    /// The frontier as a Markdown table, then the modules.
    pub fn markdown(&self) -> String {
        let mut s = self.heading();
        s.push_str(
            "| | candidate | mean error (of 255) | p99 | worst frame | update ms | frame \
            ms |\n|---|---|---|---|---|---|---|\n",
        );
        let mut rows: Vec<usize> = self.frontier.clone();
        for i in [Some(self.authored), self.chosen].into_iter().flatten() {
            if !rows.contains(&i) {
                rows.push(i);
            }
        }
        rows.sort_by(|&a, &b| {
            self.results[a]
                .frame_ms
                .total_cmp(&self.results[b].frame_ms)
        });
        for i in rows {
            s.push_str(&self.row(i));
        }
        if let Some(e) = self.over_budget() {
            s.push_str(&format!("\n{e}: no tuned preset.\n"));
        }
        s.push_str(&self.modules_markdown());
        s
    }

    fn heading(&self) -> String {
        let o = &self.options;
        let mut s = format!(
            "# {}: speed against image error\n\n{} candidates on {}, {}×{} over {} s at {} frames a second; \
             error: the 8-bit sRGB channels against the reference (RK4 at a sixteenth of the \
             candidate's step, full state, billboards). Budget: {}.\n\n",
            self.effect,
            self.results.len(),
            self.adapter,
            o.size.0,
            o.size.1,
            o.span_secs,
            o.fps,
            self.budget
        );
        if let Some(c) = &self.reference_check {
            s.push_str(&format!(
                "The finest reference against itself at half its step: {:.4}/255 mean (p99 {}); \
                 the smallest candidate error {:.4}/255.\n\n",
                c.mean,
                c.p99,
                self.results
                    .iter()
                    .map(|m| m.error.mean)
                    .fold(f64::INFINITY, f64::min)
            ));
        }
        s.push_str(
            "The frontier (no other candidate is both cheaper and more accurate), the \
            effect as authored (A) and the choice (✓):\n\n",
        );
        s
    }

    fn row(&self, i: usize) -> String {
        let m = &self.results[i];
        let mark = match (i == self.authored, Some(i) == self.chosen) {
            (true, true) => "A ✓",
            (true, false) => "A",
            (false, true) => "✓",
            _ => "",
        };
        format!(
            "| {mark} | {} | {:.3} | {} | {} ({:.2}) | {:.3} | {:.3} |\n",
            m.label,
            m.error.mean,
            m.error.p99,
            m.error.worst_frame,
            m.error.worst_frame_mean,
            m.update_ms,
            m.frame_ms
        )
    }

    fn modules_markdown(&self) -> String {
        if self.modules.is_empty() {
            return "\nNo optional modules.\n".into();
        }
        let mut s = String::from(
            "\nWhat each module contributes (the effect with only it off, against the effect as authored) and saves:\n\n\
             | module | contribution (mean of 255) | p99 | saves ms | |\n|---|---|---|---|---|\n",
        );
        for m in &self.modules {
            s.push_str(&format!(
                "| {} | {:.3} | {} | {:.3} | {} |\n",
                m.label,
                m.contribution.mean,
                m.contribution.p99,
                m.saves_ms,
                if m.not_needed { "not needed here" } else { "" }
            ));
        }
        s
    }

    /// The tuned preset's text: what changed and what it costs or saves in a comment at
    /// the top, then the preset; the over-budget error when none is chosen.
    pub fn tuned_text(&self, authored: &Effect) -> Result<String, TuneError> {
        let (Some(chosen), Some(effect)) = (self.chosen, self.tuned_effect(authored)) else {
            return Err(over_budget(&self.results, self.budget));
        };
        let (a, c) = (&self.results[self.authored], &self.results[chosen]);
        let change = if chosen == self.authored {
            "nothing: the effect as authored is the choice".to_owned()
        } else {
            c.label.clone()
        };
        let pct = 100.0 * (a.frame_ms - c.frame_ms) / a.frame_ms.max(1e-9);
        let comment = format!(
            "// Tuned by `ignis tune` for {} ({}x{}, {} s, on {}).\n// Changed: {change}.\n\
             // Image error {:.3}/255 (as authored {:.3}/255); frame {:.3} ms (as authored {:.3} ms, {pct:+.0} % saved).\n",
            self.budget,
            self.options.size.0,
            self.options.size.1,
            self.options.span_secs,
            self.adapter,
            c.error.mean,
            a.error.mean,
            c.frame_ms,
            a.frame_ms,
        );
        effect.validate().map_err(crate::PlayerError::Invalid)?;
        let ron = crate::preset::to_ron(&effect).map_err(|e| TuneError::Write {
            path: "tuned preset".into(),
            message: e.to_string(),
        })?;
        Ok(format!("{comment}{}{ron}\n", crate::preset::file_header()))
    }

    /// Writes `NAME.tune.json`, `NAME.tune.md`, `NAME.frontier.svg` and, when a candidate
    /// is within the budget, `NAME.tuned.ron` into `dir` (each file whole or not at all);
    /// returns their paths.
    pub fn write(&self, authored: &Effect, dir: &Path) -> Result<Vec<PathBuf>, TuneError> {
        let stem = crate::preset::file_stem(&self.effect);
        let tuned = match self.chosen {
            Some(_) => Some(self.tuned_text(authored)?),
            None => None,
        };
        let json = serde_json::to_string_pretty(self).map_err(|e| TuneError::Write {
            path: "json".into(),
            message: e.to_string(),
        })?;
        let svg = super::svg::frontier_svg(self);
        let mut files = vec![
            (format!("{stem}.tune.json"), json),
            (format!("{stem}.tune.md"), self.markdown()),
            (format!("{stem}.frontier.svg"), svg),
        ];
        files.extend(tuned.map(|t| (format!("{stem}.tuned.ron"), t)));
        let err = |p: &Path, e: std::io::Error| TuneError::Write {
            path: p.display().to_string(),
            message: e.to_string(),
        };
        std::fs::create_dir_all(dir).map_err(|e| err(dir, e))?;
        let mut paths = Vec::new();
        for (name, text) in files {
            let path = dir.join(name);
            crate::preset::write_atomic(&path, text.as_bytes()).map_err(|e| err(&path, e))?;
            paths.push(path);
        }
        Ok(paths)
    }
}

/// The error for a budget no candidate meets: the best reached.
fn over_budget(results: &[Measured], budget: Budget) -> TuneError {
    let best = match budget {
        Budget::ErrorMean(_) => results
            .iter()
            .min_by(|a, b| a.error.mean.total_cmp(&b.error.mean))
            .map(|m| {
                format!(
                    "the most accurate reached {:.3}/255 ({})",
                    m.error.mean, m.label
                )
            }),
        Budget::FrameMs(_) => results
            .iter()
            .min_by(|a, b| a.frame_ms.total_cmp(&b.frame_ms))
            .map(|m| format!("the cheapest takes {:.3} ms ({})", m.frame_ms, m.label)),
    };
    TuneError::OverBudget {
        budget,
        best: best.unwrap_or_else(|| "no candidate ran".into()),
    }
}
