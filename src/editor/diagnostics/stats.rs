//! Frame timing and simulation statistics, and the Stats section of the panel.

use std::collections::VecDeque;

use egui_plot::{Line, Plot};

use crate::SpawnStats;
use crate::effect::Effect;

/// Frames kept for the plot and the averages.
const HISTORY_FRAMES: usize = 300;

/// Counters of one emitter, read back from the GPU now and then.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EmitterStats {
    /// Alive particles after the last step (GPU counter).
    pub alive: u32,
    /// Particles killed for a non-finite position or velocity, since the start.
    pub nonfinite: u32,
    /// Slots in the pool.
    pub capacity: u32,
    /// Slots the update and the draws visit: the ring's live window.
    pub window: u32,
    /// Spawn accounting from the CPU planner.
    pub spawn: SpawnStats,
    /// Fed by events: children asked for and dropped by the per-step caps (GPU counters).
    pub events: Option<crate::runtime::EventCount>,
}

/// The last shader hot reload.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ShaderReloadStats {
    /// Files that changed.
    pub changed: Vec<String>,
    /// Entry files whose pipelines were rebuilt.
    pub rebuilt: Vec<&'static str>,
    /// Entry files whose rebuild failed (their last good pipelines keep running).
    pub failed: Vec<&'static str>,
    /// File change noticed → new pipelines in use, seconds (when nothing failed).
    pub latency_secs: Option<f32>,
}

/// What the Stats section shows.
#[derive(Clone, Debug, Default)]
pub struct Stats {
    frame_secs: VecDeque<f32>,
    cpu_secs: VecDeque<f32>,
    /// GPU time per pass from timestamp queries (empty on adapters without trustworthy
    /// timestamps, e.g. software ones).
    pub gpu_pass_ms: Vec<(&'static str, f64)>,
    /// Steps simulated in the last frame.
    pub steps_last_frame: u32,
    /// Step size of the last frame, seconds.
    pub dt_secs: f32,
    /// Steps dropped by the max-substeps cap since the start.
    pub dropped_steps: u64,
    /// Simulated time, seconds.
    pub sim_time_secs: f64,
    /// Per-emitter counters (refreshed every few frames).
    pub emitters: Vec<EmitterStats>,
    /// Frames since the GPU counters were read.
    pub counters_age_frames: u32,
    /// The adapter's name.
    pub adapter: String,
    /// Which egui painter draws the UI.
    pub ui_painter: &'static str,
    /// The last shader hot reload, if any.
    pub shader_reload: Option<ShaderReloadStats>,
    /// Size of the viewport's render target, pixels.
    pub viewport_px: (u32, u32),
}

impl Stats {
    /// Records one frame: its wall-clock interval and the CPU wall time spent recording
    /// the simulation and the render.
    pub fn push_frame(&mut self, frame_secs: f32, cpu_secs: f32) {
        for (queue, v) in [
            (&mut self.frame_secs, frame_secs),
            (&mut self.cpu_secs, cpu_secs),
        ] {
            if queue.len() == HISTORY_FRAMES {
                queue.pop_front();
            }
            queue.push_back(v);
        }
        self.counters_age_frames += 1;
    }

    /// Mean frame interval over the history, seconds (0 before the first frame).
    pub fn mean_frame_secs(&self) -> f32 {
        mean(&self.frame_secs)
    }

    /// Frames per second over the history.
    pub fn fps(&self) -> f32 {
        let m = self.mean_frame_secs();
        if m > 0.0 { 1.0 / m } else { 0.0 }
    }

    /// Mean CPU wall time of the simulation + render recording, seconds.
    pub fn mean_cpu_secs(&self) -> f32 {
        mean(&self.cpu_secs)
    }

    /// Alive particles over all emitters (as of the last readback).
    pub fn total_alive(&self) -> u64 {
        self.emitters.iter().map(|e| e.alive as u64).sum()
    }
}

fn mean(v: &VecDeque<f32>) -> f32 {
    if v.is_empty() {
        0.0
    } else {
        v.iter().sum::<f32>() / v.len() as f32
    }
}

/// Median of `values` (non-finite values ignored), 0 when empty.
pub fn median(values: &[f32]) -> f32 {
    let mut v: Vec<f32> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f32::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// The `q` quantile (0..=1, nearest rank) of `values`, 0 when empty.
pub fn percentile(values: &[f32], q: f32) -> f32 {
    let mut v: Vec<f32> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f32::total_cmp);
    let rank = ((v.len() - 1) as f32 * q.clamp(0.0, 1.0)).round() as usize;
    v[rank]
}

/// The Stats section: timings, counters per emitter and a frame-time plot.
pub fn stats_ui(ui: &mut egui::Ui, stats: &Stats, effect: &Effect) {
    timings_ui(ui, stats);
    ui.add_space(4.0);
    emitters_ui(ui, stats, effect);
    ui.add_space(4.0);
    frame_plot_ui(ui, stats);
}

/// The timings and the frame's facts: frame rate, CPU and GPU times, steps, the viewport,
/// the adapter, the UI painter and the last shader reload.
fn timings_ui(ui: &mut egui::Ui, stats: &Stats) {
    egui::Grid::new("stats_grid")
        .num_columns(2)
        .spacing([12.0, 4.0])
        .show(ui, |ui| {
            ui.label("Frame rate");
            ui.label(format!(
                "{:.1} fps ({:.2} ms)",
                stats.fps(),
                stats.mean_frame_secs() * 1e3
            ));
            ui.end_row();
            ui.label("CPU wall time").on_hover_text(
                "Wall-clock time spent on the CPU recording and submitting the simulation \
                 steps and the viewport render, mean over the plotted frames. On a software \
                 adapter this includes much of the GPU work.",
            );
            ui.label(format!("{:.2} ms", stats.mean_cpu_secs() * 1e3));
            ui.end_row();
            for (pass, ms) in &stats.gpu_pass_ms {
                ui.label(format!("GPU {pass}")).on_hover_text(
                    "GPU timestamp queries around the pass, read back a frame or two later",
                );
                ui.label(format!("{ms:.3} ms (timestamps)"));
                ui.end_row();
            }
            ui.label("Steps / frame");
            ui.label(format!(
                "{} × {:.2} ms",
                stats.steps_last_frame,
                stats.dt_secs * 1e3
            ));
            ui.end_row();
            ui.label("Dropped steps").on_hover_text(
                "Steps skipped because a frame needed more than the max substeps: \
                 the simulation ran slower than real time.",
            );
            ui.label(stats.dropped_steps.to_string());
            ui.end_row();
            ui.label("Simulated time");
            ui.label(format!("{:.2} s", stats.sim_time_secs));
            ui.end_row();
            ui.label("Viewport");
            ui.label(format!(
                "{} × {} px",
                stats.viewport_px.0, stats.viewport_px.1
            ));
            ui.end_row();
            ui.label("Adapter");
            ui.add(egui::Label::new(&stats.adapter).truncate());
            ui.end_row();
            ui.label("UI painter").on_hover_text(
                "lean: a branch-free egui painter used on software adapters, where \
                 egui-wgpu's shader is ~6× slower per pixel",
            );
            ui.label(stats.ui_painter);
            ui.end_row();
            if let Some(r) = &stats.shader_reload {
                ui.label("Shader reload").on_hover_text(format!(
                    "changed: {}\nrebuilt: {}",
                    r.changed.join(", "),
                    r.rebuilt.join(", ")
                ));
                ui.label(match (r.failed.is_empty(), r.latency_secs) {
                    (true, Some(s)) => {
                        format!("{} rebuilt in {:.0} ms", r.rebuilt.join(", "), s * 1e3)
                    }
                    _ => format!("{} failed: last good kept", r.failed.join(", ")),
                });
                ui.end_row();
            }
        });
}

/// Each emitter's live particles against its capacity, its events and what it dropped.
fn emitters_ui(ui: &mut egui::Ui, stats: &Stats, effect: &Effect) {
    for (i, e) in effect.emitters.iter().enumerate() {
        let Some(s) = stats.emitters.get(i) else {
            continue;
        };
        let fill = if s.capacity > 0 {
            s.alive as f32 / s.capacity as f32
        } else {
            0.0
        };
        ui.horizontal(|ui| {
            ui.add_sized([80.0, 18.0], egui::Label::new(&e.name).truncate());
            ui.add(
                egui::ProgressBar::new(fill)
                    .desired_width(ui.available_width())
                    .text(format!("{} / {} alive", s.alive, s.capacity)),
            )
            .on_hover_text(format!(
                "{} of {} slots in the live window (the only ones updated and drawn)\n\
                 spawned {}\ndropped by the per-step cap {}\ndropped over capacity {}\n\
                 recycled while alive {}\nkilled as non-finite {}",
                s.window,
                s.capacity,
                s.spawn.spawned,
                s.spawn.dropped_by_cap,
                s.spawn.dropped_over_capacity,
                s.spawn.recycled_alive,
                s.nonfinite
            ));
        });
        if let Some(ev) = s.events {
            ui.horizontal(|ui| {
                ui.add_space(84.0);
                let text = format!("events: {} asked, {} dropped", ev.asked, ev.dropped);
                if ev.dropped > 0 {
                    ui.colored_label(ui.visuals().warn_fg_color, text)
                        .on_hover_text(
                            "Dropped: a step's events asked for more children than their cap \
                         per step — raise the parent's event cap (Events section).",
                        );
                } else {
                    ui.weak(text);
                }
            });
        }
        let dropped = s.spawn.dropped_by_cap + s.spawn.dropped_over_capacity;
        if dropped > 0 || s.spawn.recycled_alive > 0 || s.nonfinite > 0 {
            ui.horizontal(|ui| {
                ui.add_space(84.0);
                ui.colored_label(
                    ui.visuals().warn_fg_color,
                    format!(
                        "{dropped} spawns dropped, {} recycled alive, {} non-finite",
                        s.spawn.recycled_alive, s.nonfinite
                    ),
                )
                .on_hover_text(
                    "Recycled: the ring of slots wrapped onto particles still alive — raise \
                     the capacity above rate × max lifetime. Dropped: a step asked for more \
                     spawns than the per-step cap or the capacity.",
                );
            });
        }
    }
}

/// The frame-time and CPU-time plot over the last frames.
fn frame_plot_ui(ui: &mut egui::Ui, stats: &Stats) {
    // Spikes (start-up, a resize) are clipped so they do not flatten the rest.
    let frames: Vec<f32> = stats.frame_secs.iter().map(|s| s * 1e3).collect();
    let y_max = (percentile(&frames, 0.95) * 1.5).max(34.0) as f64;
    let series = |v: &VecDeque<f32>| -> Vec<[f64; 2]> {
        v.iter()
            .enumerate()
            .map(|(i, s)| [i as f64, (*s as f64 * 1e3).min(y_max)])
            .collect()
    };
    let frame_ms = series(&stats.frame_secs);
    let cpu_ms = series(&stats.cpu_secs);
    Plot::new("frame_time_plot")
        .height(110.0)
        .allow_drag(false)
        .allow_zoom(false)
        .allow_scroll(false)
        .allow_boxed_zoom(false)
        .show_x(false)
        .include_y(0.0)
        .include_y(y_max)
        .include_x(0.0)
        .include_x(HISTORY_FRAMES as f64)
        .y_axis_label("ms")
        .legend(egui_plot::Legend::default())
        .show(ui, |plot| {
            plot.line(Line::new("frame", frame_ms).color(egui::Color32::from_rgb(255, 170, 60)));
            plot.line(
                Line::new("CPU wall time", cpu_ms).color(egui::Color32::from_rgb(110, 170, 255)),
            );
        });
}
