//! The panel's Time section: the step mode, the integrator, each emitter's stability at
//! its step, and "Measure this effect" (`measure_ui.rs`).

use egui::{Color32, Ui};

use crate::effect::{Effect, Integrator, TimeMode};

use crate::editor::panel::{drag, grid, row_ui};
use crate::editor::state::Playback;

/// Time stepping, playback and the integrator of each emitter with its stability hint.
pub fn time_ui(
    ui: &mut Ui,
    effect: &mut Effect,
    playback: &mut Playback,
    selected: usize,
    measure: &mut crate::editor::panel::measure_ui::MeasurePanel,
) {
    ui.horizontal(|ui| {
        crate::editor::panel::timeline::playback_buttons_ui(ui, playback);
        if playback.is_paused {
            ui.colored_label(Color32::from_rgb(240, 200, 90), "paused");
        }
    });
    let t = &mut effect.time;
    grid("time_grid").show(ui, |ui| {
        ui.label("Mode").on_hover_text(
            "Fixed step: an accumulator runs whole steps, so the result does not depend on the \
                frame rate. Frame delta: one step per frame of the frame's duration (the 2006 \
                thesis's mode)",
        );
        ui.horizontal(|ui| {
            ui.radio_value(&mut t.mode, TimeMode::FixedStep, "Fixed step");
            ui.radio_value(&mut t.mode, TimeMode::FrameDelta, "Frame delta");
        });
        ui.end_row();
        let is_fixed = t.mode == TimeMode::FixedStep;
        let label = ui
            .label("Step size")
            .on_hover_text("Fixed step size, seconds");
        ui.horizontal(|ui| {
            ui.add_enabled(
                is_fixed,
                drag(&mut t.step_secs, 0.0001..=0.1, 0.0002, " s").min_decimals(4),
            )
            .labelled_by(label.id);
            if t.step_secs > 0.0 {
                ui.weak(format!("{:.0} Hz", 1.0 / t.step_secs));
            }
        });
        ui.end_row();
        row_ui(
            ui,
            "Max substeps",
            "At most this many fixed steps per frame; the rest of the time is dropped and \
                counted (Stats)",
            |ui| ui.add_enabled(is_fixed, drag(&mut t.max_substeps, 1..=256, 0.1, "")),
        );
        row_ui(
            ui,
            "Max frame dt",
            "Frame-delta mode: a longer frame is clamped to this step, seconds",
            |ui| {
                ui.add_enabled(
                    !is_fixed,
                    drag(&mut t.max_frame_dt_secs, 0.001..=0.5, 0.001, " s").min_decimals(3),
                )
            },
        );
        row_ui(
            ui,
            "Sim speed",
            "Simulation speed multiplier (1 = real time)",
            |ui| ui.add(drag(&mut t.speed, 0.0..=10.0, 0.01, "×").min_decimals(2)),
        );
        if let Some(e) = effect.emitters.get_mut(selected) {
            emitter_time_rows_ui(ui, e);
        }
    });
    stability_ui(ui, effect);
    crate::editor::panel::measure_ui::measure_ui(ui, measure, effect);
}

/// The selected emitter's rows (of an open grid): its integrator, closed form and state
/// size.
fn emitter_time_rows_ui(ui: &mut Ui, e: &mut crate::effect::Emitter) {
    let label = ui
        .label("Integrator")
        .on_hover_text("Integration method of the selected emitter");
    egui::ComboBox::from_id_salt("integrator")
        .selected_text(e.integrator.label())
        .width(150.0)
        .show_ui(ui, |ui| {
            for i in Integrator::ALL {
                ui.selectable_value(&mut e.integrator, i, i.label());
            }
        })
        .response
        .labelled_by(label.id);
    ui.end_row();
    row_ui(
        ui,
        "Stateless",
        "Closed form instead of steps: each particle's position is evaluated from its spawn \
            record and age (exact, cheaper). Only for constant acceleration and linear drag",
        |ui| {
            let r = ui.checkbox(&mut e.stateless, "closed form");
            if r.changed() && e.stateless {
                e.packed_state = false;
                e.tiny_state = false;
            }
            r
        },
    );
    // Three radio buttons, each named by its own text (not by the row's label).
    let tip = "Bytes stored per particle. 32 B: f32 position, velocity, age, lifetime. 20 B \
        packed: f16 velocity, 16-bit life fraction, lifetime re-derived from the spawn hash. 10 \
        B tiny: f16 position, shared-exponent velocity, age from a table of each step's births. \
        Smaller moves less memory for huge pools, at the accuracy cost `ignis bench accuracy` \
        reports (\"+ packed\", \"+ tiny\" rows). Switching restarts this emitter's particles";
    ui.label("State size").on_hover_text(tip);
    ui.horizontal(|ui| {
        let before = (e.packed_state, e.tiny_state);
        let mut size = if e.tiny_state {
            10
        } else if e.packed_state {
            20
        } else {
            32
        };
        for (bytes, text) in [(32, "32 B"), (20, "20 B packed"), (10, "10 B tiny")] {
            ui.radio_value(&mut size, bytes, text).on_hover_text(tip);
        }
        e.packed_state = size == 20;
        e.tiny_state = size == 10;
        if (e.packed_state, e.tiny_state) != before && size != 32 {
            e.stateless = false;
        }
    });
    ui.end_row();
    let blockers = e.stateless_blockers();
    if e.stateless && !blockers.is_empty() {
        ui.label("");
        ui.colored_label(
            ui.visuals().warn_fg_color,
            format!("turn off: {}", blockers.join(", ")),
        );
        ui.end_row();
    }
}

/// The step the integrators see: the fixed step, or the largest frame-delta step.
pub fn step_secs(effect: &Effect) -> f32 {
    match effect.time.mode {
        TimeMode::FixedStep => effect.time.step_secs,
        TimeMode::FrameDelta => effect.time.max_frame_dt_secs,
    }
}

/// Each emitter's stability at the step the integrator sees: how much an error grows
/// over a particle's life (`Effect::stability_warnings`, from the stiffest terms of its
/// forces) and the largest stable step.
fn stability_ui(ui: &mut Ui, effect: &Effect) {
    let step = f64::from(step_secs(effect));
    egui::Grid::new("stability_grid")
        .num_columns(3)
        .spacing([10.0, 2.0])
        .show(ui, |ui| {
            ui.weak("emitter");
            ui.weak("integrator");
            ui.weak("stability at this step").on_hover_text(
                "How much an error grows over a particle's life under the emitter's stiffest \
                    forces (drag, flame pull, attractor, vortex, turbulence), and the largest \
                    step that keeps it below 2×",
            );
            ui.end_row();
            for e in effect.emitters.iter().filter(|e| e.enabled) {
                ui.label(&e.name);
                ui.label(e.integrator.label());
                let growth = e.growth_at(step);
                if e.stateless {
                    ui.label("exact (stateless)");
                } else if growth > crate::effect::GROWTH_LIMIT {
                    let stable = crate::effect::largest_stable_step(e)
                        .map_or("none".to_owned(), |s| format!("≤ {s:.4} s"));
                    ui.colored_label(
                        ui.visuals().error_fg_color,
                        format!("unstable: ×{growth:.1e}; stable {stable}"),
                    );
                } else {
                    ui.label("stable");
                }
                ui.end_row();
            }
        });
}
