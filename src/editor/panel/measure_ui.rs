//! The Time section's "Measure this effect": the sweep of `ignis tune` run in the editor's
//! frame loop a slice at a time ([`drive`]), with a progress bar and Cancel, then a chart
//! of image error against frame time — every candidate, the frontier, the effect as it was
//! measured and the choice within the budget. Clicking a point (or a frontier row's Apply)
//! applies that candidate's settings to the effect as one undoable edit.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use egui::{Color32, Ui};
use egui_plot::{Line, MarkerShape, Plot, PlotPoint, Points};

use crate::effect::Effect;
use crate::gpu::GpuContext;
use crate::tune::{Budget, Sweep, SweepOptions, TuneReport};

/// The Measure controls, the sweep's progress and its last result.
pub struct MeasurePanel {
    /// The error budget the choice is made within (mean of 255).
    pub budget_error: f64,
    /// The image size the frames are compared at.
    pub size: (u32, u32),
    /// The span measured, seconds (0: the effect's natural span).
    pub span_secs: f64,
    /// Measure pressed: the frame loop starts a sweep of the running effect.
    pub start_requested: bool,
    /// Cancel pressed: the frame loop drops the sweep.
    pub cancel_requested: bool,
    /// Frames of work done and in all, while a sweep runs.
    pub progress: Option<(usize, usize)>,
    /// The last sweep's report.
    pub report: Option<TuneReport>,
    /// The outcome of the last sweep, or why it stopped.
    pub message: Option<Result<String, String>>,
    /// A candidate the user picked (an index into the report's results), applied to the
    /// effect by [`apply_pick`].
    pub pick: Option<usize>,
}

impl Default for MeasurePanel {
    fn default() -> Self {
        Self {
            budget_error: 0.5,
            size: (320, 180),
            span_secs: 0.0,
            start_requested: false,
            cancel_requested: false,
            progress: None,
            report: None,
            message: None,
            pick: None,
        }
    }
}

impl MeasurePanel {
    /// Whether a sweep runs.
    pub fn is_running(&self) -> bool {
        self.progress.is_some()
    }

    /// The sweep's options for `effect`.
    pub fn options(&self, effect: &Effect, asset_dir: Option<PathBuf>) -> SweepOptions {
        let natural = SweepOptions::for_effect(effect);
        SweepOptions {
            span_secs: if self.span_secs > 0.0 {
                self.span_secs
            } else {
                natural.span_secs
            },
            size: self.size,
            fps: 30.0,
            cost_frames: 5,
            check_reference: false,
            asset_dir,
            rates: natural.rates,
        }
    }
}

/// Starts, steps (for up to `budget` of wall time), cancels and finishes the sweep
/// `running` of `effect` as `panel` asks; call once per editor frame.
pub fn drive(
    ctx: &GpuContext,
    effect: &Effect,
    asset_dir: Option<PathBuf>,
    panel: &mut MeasurePanel,
    running: &mut Option<Sweep>,
    budget: Duration,
) {
    if std::mem::take(&mut panel.cancel_requested) && running.take().is_some() {
        panel.progress = None;
        panel.message = Some(Err("measurement cancelled".into()));
    }
    if std::mem::take(&mut panel.start_requested) && running.is_none() {
        match Sweep::new(ctx, effect, panel.options(effect, asset_dir)) {
            Ok(s) => {
                *running = Some(s);
                panel.progress = Some((0, 1));
                panel.message = None;
            }
            Err(e) => panel.message = Some(Err(e.to_string())),
        }
    }
    let Some(sweep) = running.as_mut() else {
        return;
    };
    let start = Instant::now();
    loop {
        match sweep.step() {
            Ok(false) => panel.progress = Some(sweep.progress()),
            Ok(true) => {
                finish(ctx, sweep, panel);
                *running = None;
                return;
            }
            Err(e) => {
                panel.message = Some(Err(e.to_string()));
                panel.progress = None;
                *running = None;
                return;
            }
        }
        if start.elapsed() >= budget {
            return;
        }
    }
}

fn finish(ctx: &GpuContext, sweep: &Sweep, panel: &mut MeasurePanel) {
    panel.progress = None;
    match TuneReport::new(sweep, Budget::ErrorMean(panel.budget_error), &ctx.info.name) {
        Ok(r) => {
            panel.message = Some(match r.chosen {
                Some(c) => Ok(format!(
                    "{} candidates; within {}/255 the cheapest is {}",
                    r.results.len(),
                    panel.budget_error,
                    r.results[c].label
                )),
                None => Err(r.over_budget().map(|e| e.to_string()).unwrap_or_default()),
            });
            panel.report = Some(r);
        }
        Err(e) => panel.message = Some(Err(e.to_string())),
    }
}

/// Applies the picked candidate's settings to `effect` (one edit: the undo history
/// records it as one step). Returns whether anything changed.
pub fn apply_pick(panel: &mut MeasurePanel, effect: &mut Effect) -> bool {
    let (Some(i), Some(report)) = (panel.pick.take(), panel.report.as_ref()) else {
        return false;
    };
    let Some(m) = report.results.get(i) else {
        return false;
    };
    let next = m.candidate.apply(effect);
    let changed = next != *effect;
    *effect = next;
    changed
}

/// The Measure block: controls, progress, the chart and the frontier's rows.
pub fn measure_ui(ui: &mut Ui, panel: &mut MeasurePanel, effect: &mut Effect) {
    ui.separator();
    ui.strong("Measure this effect").on_hover_text(
        "Play every integrator × step, state size, module switched off and draw \
            path against a converged reference (RK4 at a sixteenth of the step) and compare the \
            frames: image error against frame time on this GPU (`ignis tune` on the command \
            line)",
    );
    controls_ui(ui, panel);
    if let Some(report) = &panel.report {
        let mut pick = None;
        chart_ui(ui, report, &mut pick);
        frontier_rows_ui(ui, report, &mut pick);
        if pick.is_some() {
            panel.pick = pick;
        }
    }
    apply_pick(panel, effect);
}

fn controls_ui(ui: &mut Ui, panel: &mut MeasurePanel) {
    let running = panel.is_running();
    ui.add_enabled_ui(!running, |ui| {
        ui.horizontal(|ui| {
            let l = ui.label("Budget");
            ui.add(
                egui::DragValue::new(&mut panel.budget_error)
                    .range(0.01..=50.0)
                    .speed(0.01)
                    .suffix(" /255"),
            )
            .labelled_by(l.id);
            let l = ui.label("Span");
            ui.add(
                egui::DragValue::new(&mut panel.span_secs)
                    .range(0.0..=30.0)
                    .speed(0.05)
                    .custom_formatter(|v, _| {
                        if v == 0.0 {
                            "natural".into()
                        } else {
                            format!("{v:.2} s")
                        }
                    }),
            )
            .labelled_by(l.id);
        });
    });
    ui.horizontal(|ui| {
        if running {
            if ui.button("Cancel measurement").clicked() {
                panel.cancel_requested = true;
            }
        } else if ui.button("Measure").clicked() {
            panel.start_requested = true;
        }
        crate::editor::panel::progress_ui(ui, panel.progress);
    });
    crate::editor::panel::outcome_ui(ui, panel.message.as_ref());
}

/// The chart: log10 of the frame time (x) and of the error (y); hovering a point names
/// its settings and figures, clicking it picks it.
fn chart_ui(ui: &mut Ui, report: &TuneReport, pick: &mut Option<usize>) {
    let xy = |i: usize| {
        let m = &report.results[i];
        [m.frame_ms.max(1e-4).log10(), m.error.mean.max(1e-3).log10()]
    };
    let all: Vec<[f64; 2]> = (0..report.results.len()).map(xy).collect();
    let front: Vec<[f64; 2]> = report.frontier.iter().map(|&i| xy(i)).collect();
    let labels: Vec<String> = report
        .results
        .iter()
        .map(|m| format!("{}\n{:.3}/255, {:.2} ms", m.label, m.error.mean, m.frame_ms))
        .collect();
    let response = Plot::new("measure_plot")
        .height(180.0)
        .allow_drag(false)
        .allow_zoom(false)
        .allow_scroll(false)
        .x_axis_label("frame ms")
        .y_axis_label("error /255")
        .x_axis_formatter(|m, _| power_of_ten(m.value))
        .y_axis_formatter(|m, _| power_of_ten(m.value))
        .label_formatter(|h| {
            let p = match h {
                egui_plot::HoverPosition::NearDataPoint { position, .. } => position,
                egui_plot::HoverPosition::Elsewhere { position } => position,
            };
            Some(nearest_label(&all, &labels, p))
        })
        .show(ui, |plot| {
            plot.points(
                Points::new("candidates", all.clone())
                    .radius(2.5)
                    .color(Color32::GRAY),
            );
            plot.line(Line::new("frontier", front.clone()).color(Color32::from_rgb(90, 150, 255)));
            plot.points(
                Points::new("measured as", vec![xy(report.authored)])
                    .shape(MarkerShape::Diamond)
                    .radius(6.0)
                    .color(Color32::WHITE),
            );
            if let Some(c) = report.chosen {
                plot.points(
                    Points::new("chosen", vec![xy(c)])
                        .shape(MarkerShape::Circle)
                        .radius(6.0)
                        .color(Color32::from_rgb(255, 120, 60)),
                );
            }
        });
    if response.response.clicked()
        && let Some(pos) = response.response.interact_pointer_pos()
    {
        // The candidate nearest the click on screen, within 10 points.
        *pick = (0..all.len())
            .map(|i| {
                let p = response
                    .transform
                    .position_from_point(&PlotPoint::new(all[i][0], all[i][1]));
                (i, p.distance(pos))
            })
            .filter(|(_, d)| *d <= 10.0)
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(i, _)| i);
    }
}

/// A logarithmic axis's mark as the value it stands for (`-1` → `0.1`).
fn power_of_ten(log10: f64) -> String {
    let v = 10f64.powf(log10);
    if v >= 10.0 {
        format!("{v:.0}")
    } else {
        let digits = (-log10.floor()).max(0.0) as usize + 1;
        format!("{v:.digits$}")
    }
}

/// The hover text of the candidate nearest `p` (plot coordinates).
fn nearest_label(all: &[[f64; 2]], labels: &[String], p: &PlotPoint) -> String {
    all.iter()
        .enumerate()
        .min_by(|a, b| {
            let d = |q: &[f64; 2]| (q[0] - p.x).powi(2) + (q[1] - p.y).powi(2);
            d(a.1).total_cmp(&d(b.1))
        })
        .and_then(|(i, _)| labels.get(i).cloned())
        .unwrap_or_default()
}

/// The frontier as rows, cheapest first; clicking a row's settings applies them.
fn frontier_rows_ui(ui: &mut Ui, report: &TuneReport, pick: &mut Option<usize>) {
    egui::Grid::new("measure_frontier")
        .num_columns(3)
        .spacing([8.0, 2.0])
        .show(ui, |ui| {
            ui.weak("frontier (click to apply)");
            ui.weak("error /255");
            ui.weak("frame ms");
            ui.end_row();
            for &i in &report.frontier {
                let m = &report.results[i];
                let chosen = Some(i) == report.chosen;
                if ui
                    .selectable_label(chosen, &m.label)
                    .on_hover_text("Apply these settings to the effect (one undo step)")
                    .clicked()
                {
                    *pick = Some(i);
                }
                ui.label(format!("{:.3}", m.error.mean));
                ui.label(format!("{:.2}", m.frame_ms));
                ui.end_row();
            }
        });
}
