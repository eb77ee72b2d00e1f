//! The side panel: one collapsible section per concern (the Emitter, Forces and Time
//! sections have files of their own: `emitter_ui.rs`, `forces_ui.rs`, `time_ui.rs`), and
//! the small widgets they share. Every widget is bound to a field of the
//! [`Effect`](crate::effect::Effect) (or of the editor's view settings); no parameter lives
//! in a widget.
//!
//! Ranges are clamped by the widgets themselves (`DragValue::range`), so typing or
//! dragging cannot produce a NaN or an out-of-range value; whatever still fails
//! [`Effect::validate`](crate::effect::Effect::validate) is shown at the top and the last
//! valid effect keeps running.

pub mod curve_editor;
pub mod emitter_ui;
pub mod events_ui;
pub mod export_ui;
pub mod forces_ui;
pub mod lighting_ui;
pub mod look_ui;
pub mod measure_ui;
pub mod time_ui;
pub mod timeline;
pub mod viewport;

use std::ops::RangeInclusive;

use egui::{Color32, DragValue, Response, RichText, Ui};

use crate::effect::Range;

use crate::editor::diagnostics::stats::stats_ui;
use crate::editor::panel::curve_editor::ParamSpec;
use crate::editor::panel::emitter_ui::{emitter_ui, randomness_ui};
use crate::editor::panel::forces_ui::forces_ui;
use crate::editor::panel::look_ui::look_ui;
use crate::editor::panel::time_ui::time_ui;
use crate::editor::state::{EditorState, ViewSettings};

/// Default width of the side panel, points.
pub const PANEL_WIDTH: f32 = 370.0;

/// Largest capacity the panel offers (2^22 slots, 128 MiB per state buffer).
pub const UI_MAX_CAPACITY: u32 = 1 << 22;

/// The whole side panel: header (undo/redo, errors) and the sections.
pub fn panel_ui(ui: &mut Ui, state: &mut EditorState) {
    header_ui(ui, state);
    ui.separator();
    // A one-shot request to open exactly these sections (`ignis edit --sections`).
    let force = state.open_sections.take();
    let open = |id: &str| force.as_ref().map(|v| v.iter().any(|s| s == id));
    egui::ScrollArea::vertical()
        .auto_shrink([false, false])
        .show(ui, |ui| {
            effect_sections_ui(ui, state, &open);
            tool_sections_ui(ui, state, &open);
        });
}

/// The sections that edit the effect: emitter, randomness, forces, events, time, look.
fn effect_sections_ui(ui: &mut Ui, state: &mut EditorState, open: &dyn Fn(&str) -> Option<bool>) {
    let name = state
        .effect
        .emitters
        .get(state.selected)
        .map(|e| e.name.clone())
        .unwrap_or_default();
    section_ui(
        ui,
        "emitter",
        "Emitter",
        "",
        (true, open("emitter")),
        |ui| {
            emitter_ui(ui, &mut state.effect, &mut state.selected);
        },
    );
    // The selected emitter's randomness, forces and events: the same section each.
    type EmitterSection = fn(&mut Ui, &mut crate::effect::Effect, usize);
    let sections: [(&str, &str, EmitterSection); 3] = [
        ("randomness", "Randomness", randomness_ui),
        ("forces", "Forces", forces_ui),
        (
            "events",
            "Events",
            crate::editor::panel::events_ui::events_ui,
        ),
    ];
    for (id, title, body) in sections {
        section_ui(ui, id, title, &name, (false, open(id)), |ui| {
            body(ui, &mut state.effect, state.selected);
        });
    }
    section_ui(ui, "time", "Time", "", (true, open("time")), |ui| {
        time_ui(
            ui,
            &mut state.effect,
            &mut state.playback,
            state.selected,
            &mut state.measure,
        );
    });
    section_ui(ui, "look", "Look", &name, (false, open("look")), |ui| {
        let sprite_error = state
            .sprite_errors
            .iter()
            .find(|(i, _)| *i == state.selected)
            .map(|(_, e)| e.as_str());
        look_ui(
            ui,
            &mut state.effect,
            state.selected,
            &mut state.view,
            sprite_error,
        );
    });
}

/// The sections around the effect: view, stats, export.
fn tool_sections_ui(ui: &mut Ui, state: &mut EditorState, open: &dyn Fn(&str) -> Option<bool>) {
    section_ui(ui, "view", "View", "", (false, open("view")), |ui| {
        view_ui(ui, &mut state.view, &mut state.frame_requested);
        ui.separator();
        ui.label("Scene light (lit smoke; saved with the preset)");
        crate::editor::panel::lighting_ui::lighting_ui(ui, &mut state.effect.lighting);
    });
    section_ui(ui, "stats", "Stats", "", (true, open("stats")), |ui| {
        stats_ui(ui, &state.stats, &state.running);
        crate::editor::diagnostics::emitter_cost::emitter_cost_ui(
            ui,
            &mut state.cost_probe,
            &state.emitter_costs,
            &state.running,
            !state.stats.gpu_pass_ms.is_empty(),
        );
    });
    section_ui(ui, "export", "Export", "", (false, open("export")), |ui| {
        crate::editor::panel::export_ui::export_ui(ui, &mut state.export);
    });
}

/// A collapsible section with a stable id (its title may name the selected emitter).
fn section_ui(
    ui: &mut Ui,
    id: &str,
    title: &str,
    emitter: &str,
    (default_open, force_open): (bool, Option<bool>),
    add: impl FnOnce(&mut Ui),
) {
    let text = if emitter.is_empty() {
        RichText::new(title).strong()
    } else {
        RichText::new(format!("{title}  ·  {emitter}")).strong()
    };
    egui::CollapsingHeader::new(text)
        .id_salt(id)
        .default_open(default_open)
        .open(force_open)
        .show(ui, add);
}

/// Title, undo/redo, the preset file and the messages: what failed, and what keeps running.
pub fn header_ui(ui: &mut Ui, state: &mut EditorState) {
    title_ui(ui, state);
    undo_ui(ui, state);
    preset_file_ui(ui, state);
    preset_library_ui(ui, state);
    match &state.preset_message {
        Some(Ok(msg)) => {
            ui.colored_label(Color32::from_rgb(130, 200, 130), msg);
        }
        Some(Err(msg)) => {
            ui.colored_label(ui.visuals().error_fg_color, msg);
        }
        None => {}
    }
    problems_ui(ui, state);
}

/// The title: the effect's name, its file and whether it has unsaved edits.
fn title_ui(ui: &mut Ui, state: &EditorState) {
    ui.horizontal(|ui| {
        ui.heading(
            RichText::new("ignis")
                .strong()
                .color(Color32::from_rgb(255, 150, 60)),
        );
        ui.label(RichText::new(&state.effect.name).strong());
        ui.weak(&state.source);
        if state.is_dirty() {
            ui.colored_label(Color32::from_rgb(255, 190, 90), "* unsaved")
                .on_hover_text("The effect differs from the last loaded or saved preset");
        }
    });
}

/// Undo and redo, and how many steps each has.
fn undo_ui(ui: &mut Ui, state: &mut EditorState) {
    ui.horizontal(|ui| {
        let undo = ui
            .add_enabled(state.history.undo_len() > 0, egui::Button::new("Undo"))
            .on_hover_text("Undo the last edit (Ctrl+Z)");
        if undo.clicked() {
            state.undo();
        }
        let redo = ui
            .add_enabled(state.history.redo_len() > 0, egui::Button::new("Redo"))
            .on_hover_text("Redo (Ctrl+Shift+Z)");
        if redo.clicked() {
            state.redo();
        }
        ui.weak(format!(
            "{} undo · {} redo",
            state.history.undo_len(),
            state.history.redo_len()
        ));
    });
}

/// The preset path with Save, Load and Revert, and the question a pending load or an
/// outside change asks before unsaved edits are discarded.
fn preset_file_ui(ui: &mut Ui, state: &mut EditorState) {
    ui.horizontal(|ui| {
        let label = ui.label("Preset");
        ui.add(
            egui::TextEdit::singleline(&mut state.preset_path)
                .desired_width(ui.available_width() - 104.0)
                .hint_text("presets/name.ron"),
        )
        .labelled_by(label.id)
        .on_hover_text("The RON preset file Save writes and Load reads");
        if ui
            .button("Save")
            .on_hover_text(
                "Write the edited effect (valid effects only; atomic: a crash never \
                leaves half a file)",
            )
            .clicked()
        {
            state.save_preset();
        }
        if ui
            .button("Load")
            .on_hover_text(
                "Replace the effect with this preset (undoable; asks first when \
                there are unsaved edits)",
            )
            .clicked()
        {
            state.request_load();
        }
    });
    ui.horizontal(|ui| {
        if ui
            .add_enabled(state.is_dirty(), egui::Button::new("Revert"))
            .on_hover_text("Back to the last loaded or saved preset (undoable)")
            .clicked()
        {
            state.revert();
        }
        ui.weak("Save writes the path above: edit it to save as a new preset");
    });
    if let Some(pending) = state.pending.clone() {
        error_box_ui(ui, |ui| {
            ui.label(
                RichText::new(match pending {
                    crate::editor::state::PendingAction::Load => {
                        "Discard the unsaved edits and load the preset?"
                    }
                    crate::editor::state::PendingAction::ExternalReload => {
                        "The preset changed on disk. Reload it and discard the unsaved edits?"
                    }
                })
                .strong(),
            );
            ui.horizontal(|ui| {
                if ui.button("Discard edits").clicked() {
                    state.confirm_pending();
                }
                if ui.button("Keep editing").clicked() {
                    state.pending = None;
                }
            });
        });
    }
}

/// What keeps the edit from running: invalid fields, a shader error, a stopped
/// simulation, a lost device, an effect the GPU refused.
fn problems_ui(ui: &mut Ui, state: &mut EditorState) {
    if !state.validation_errors.is_empty() {
        error_box_ui(ui, |ui| {
            ui.label(RichText::new("Not applied: the last valid effect keeps running.").strong());
            for e in state.validation_errors.iter().take(6) {
                ui.label(e.to_string());
            }
            if state.validation_errors.len() > 6 {
                ui.label(format!("… and {} more", state.validation_errors.len() - 6));
            }
        });
    }
    // Valid but unstable at its step: shown as the edit is made, before it plays out.
    let unstable = state.effect.stability_warnings();
    if !unstable.is_empty() {
        egui::Frame::group(ui.style())
            .fill(Color32::from_rgb(64, 50, 18))
            .stroke(egui::Stroke::new(1.0, Color32::from_rgb(220, 170, 60)))
            .show(ui, |ui| {
                ui.set_width(ui.available_width());
                ui.label(RichText::new("Unstable at this step: particles will blow up.").strong());
                for w in &unstable {
                    ui.label(w.to_string());
                }
            });
    }
    if !state.shader_errors.is_empty() {
        error_box_ui(ui, |ui| {
            ui.label(RichText::new("Shader error: the last good pipeline keeps running.").strong());
            for e in &state.shader_errors {
                ui.label(RichText::new(e).monospace().size(11.0));
            }
        });
    }
    if let Some(err) = &state.light_error {
        error_box_ui(ui, |ui| {
            ui.label(RichText::new("The fire's light on the scene is off.").strong());
            ui.label(RichText::new(err).monospace().size(11.0));
        });
    }
    if let Some(err) = &state.sim_error {
        error_box_ui(ui, |ui| {
            ui.label(RichText::new("The simulation stopped (paused).").strong());
            ui.label(err);
        });
    }
    if let Some(notice) = state.device_notice.clone() {
        error_box_ui(ui, |ui| {
            ui.label(notice);
            if ui.button("Dismiss").clicked() {
                state.device_notice = None;
            }
        });
    }
    if let Some((_, reason)) = &state.gpu_rejected {
        error_box_ui(ui, |ui| {
            ui.label(
                RichText::new("The GPU refused this effect; the last one keeps running.").strong(),
            );
            ui.label(reason);
        });
    }
}

/// Opens a preset from the folder of the current preset path (or `presets/`); the
/// folder is listed only while the list is open.
fn preset_library_ui(ui: &mut Ui, state: &mut EditorState) {
    let path = std::path::PathBuf::from(state.preset_path.trim());
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .map_or_else(|| std::path::PathBuf::from("presets"), |d| d.to_path_buf());
    let mut chosen = None;
    ui.horizontal(|ui| {
        let label = ui.label("Library");
        egui::ComboBox::from_id_salt("preset_library")
            .selected_text(format!("{}/", dir.display()))
            .width(ui.available_width() - 8.0)
            .show_ui(ui, |ui| {
                let files = crate::preset::list(&dir);
                if files.is_empty() {
                    ui.weak("no .ron presets here");
                }
                for file in files {
                    let name = file
                        .file_stem()
                        .map(|n| n.to_string_lossy().into_owned())
                        .unwrap_or_default();
                    if ui.selectable_label(file == path, name).clicked() {
                        chosen = Some(file);
                    }
                }
            })
            .response
            .labelled_by(label.id)
            .on_hover_text("Open a preset from this folder (undoable)");
    });
    if let Some(file) = chosen {
        state.preset_path = file.display().to_string();
        state.request_load();
    }
}

pub(crate) fn error_box_ui(ui: &mut Ui, add: impl FnOnce(&mut Ui)) {
    egui::Frame::group(ui.style())
        .fill(Color32::from_rgb(70, 24, 24))
        .stroke(egui::Stroke::new(1.0, Color32::from_rgb(200, 80, 70)))
        .show(ui, |ui| {
            ui.set_width(ui.available_width());
            add(ui);
        });
}

// ---------------------------------------------------------------------------------------
// Small widget helpers.

/// A job's progress bar (done of total), while it runs; frames keep coming meanwhile.
pub(crate) fn progress_ui(ui: &mut Ui, progress: Option<(usize, usize)>) {
    if let Some((done, total)) = progress {
        let f = done as f32 / total.max(1) as f32;
        ui.add(egui::ProgressBar::new(f).show_percentage());
        ui.ctx().request_repaint();
    }
}

/// A job's outcome: its message, or its error in the error colour.
pub(crate) fn outcome_ui(ui: &mut Ui, outcome: Option<&Result<String, String>>) {
    match outcome {
        Some(Ok(m)) => {
            ui.label(m);
        }
        Some(Err(m)) => {
            ui.colored_label(ui.visuals().error_fg_color, m);
        }
        None => {}
    }
}

/// A labelled grid row: the label names the widget for accessibility (and tests) and
/// both carry the tooltip.
pub(crate) fn row_ui(
    ui: &mut Ui,
    label: &str,
    tip: &str,
    add: impl FnOnce(&mut Ui) -> Response,
) -> Response {
    let label = ui.label(label).on_hover_text(tip);
    let response = add(ui).labelled_by(label.id).on_hover_text(tip);
    ui.end_row();
    response
}

/// A multiplier over the particle's life.
pub(crate) fn multiplier(name: &'static str) -> ParamSpec {
    ParamSpec {
        name,
        unit: "×",
        values: 0.0..=100.0,
        speed: 0.01,
        t_max: 1.0,
        t_unit: "of life",
    }
}

/// A drag value clamped to `range`, shown with at most four decimals.
pub(crate) fn drag<'a, N: egui::emath::Numeric>(
    v: &'a mut N,
    range: RangeInclusive<N>,
    speed: f64,
    suffix: &str,
) -> DragValue<'a> {
    DragValue::new(v)
        .range(range)
        .speed(speed)
        .suffix(suffix.to_owned())
        .max_decimals(4)
}

/// Three drag values side by side (x, y, z) in one row; the returned response is their
/// union (changed when any changed).
pub(crate) fn vec3_ui(
    ui: &mut Ui,
    label: &str,
    tip: &str,
    v: &mut [f32; 3],
    range: RangeInclusive<f32>,
    speed: f64,
    suffix: &str,
) -> Response {
    let label = ui.label(label).on_hover_text(tip);
    let response = ui
        .horizontal(|ui| {
            let mut union: Option<Response> = None;
            for (c, axis) in v.iter_mut().zip(["x ", "y ", "z "]) {
                let r = ui
                    .add(
                        drag(c, range.clone(), speed, suffix)
                            .prefix(axis)
                            .min_decimals(2),
                    )
                    .labelled_by(label.id);
                union = Some(match union {
                    Some(u) => u | r,
                    None => r,
                });
            }
            union
        })
        .inner;
    ui.end_row();
    response.unwrap_or(label)
}

/// A `[min, max]` pair whose widgets keep min ≤ max.
pub(crate) fn range_ui(
    ui: &mut Ui,
    label: &str,
    tip: &str,
    r: &mut Range,
    limits: RangeInclusive<f32>,
    speed: f64,
    suffix: &str,
) -> Response {
    let label = ui.label(label).on_hover_text(tip);
    let response = ui
        .horizontal(|ui| {
            let max = r.max;
            let a = ui
                .add(
                    drag(&mut r.min, *limits.start()..=max, speed, suffix)
                        .prefix("min ")
                        .min_decimals(2),
                )
                .labelled_by(label.id);
            let min = r.min;
            let b = ui
                .add(
                    drag(&mut r.max, min..=*limits.end(), speed, suffix)
                        .prefix("max ")
                        .min_decimals(2),
                )
                .labelled_by(label.id);
            a | b
        })
        .inner
        .on_hover_text(tip);
    ui.end_row();
    response
}

pub(crate) fn grid(id: &str) -> egui::Grid {
    egui::Grid::new(id)
        .num_columns(2)
        .spacing([10.0, 5.0])
        .min_col_width(96.0)
}

// ---------------------------------------------------------------------------------------
// View.

/// Viewport options: grid, gizmos, render scale, camera.
pub fn view_ui(ui: &mut Ui, view: &mut ViewSettings, frame_requested: &mut bool) {
    grid("view_grid").show(ui, |ui| {
        row_ui(
            ui,
            "Ground grid",
            "Draw the y = 0 grid (0.5 m cells)",
            |ui| ui.checkbox(&mut view.show_grid, ""),
        );
        row_ui(
            ui,
            "Fire lights grid",
            "The grid is lit by the effect's own light (its additive particles, measured on the \
                GPU each frame): it flickers with the flames",
            |ui| ui.checkbox(&mut view.fire_lights_grid, ""),
        );
        row_ui(
            ui,
            "Test scene",
            "Draw a ground, a box and a step into the viewport's depth, as a game's world: \
                emitters with depth collision bounce off them, soft edges and occlusion \
                show against them (the props are the viewport's, not the preset's)",
            |ui| ui.checkbox(&mut view.test_scene, ""),
        );
        row_ui(
            ui,
            "Heat haze",
            "Refract the viewport by the effect's heat-haze layers (best seen over the test \
                scene)",
            |ui| ui.checkbox(&mut view.heat_haze, ""),
        );
        row_ui(
            ui,
            "Mouse collider",
            "A sphere collider follows the pointer over the viewport: push the fire around",
            |ui| ui.checkbox(&mut view.mouse_collider, ""),
        );
        row_ui(
            ui,
            "Inspect",
            "Show the particle under the pointer — its slot, age, lifetime, position, velocity \
                and the forces on it now; click one to pin it",
            |ui| ui.checkbox(&mut view.inspect, ""),
        );
        row_ui(
            ui,
            "State view",
            "The selected emitter's state buffer as images, one texel per slot: position, \
                velocity and age as colours",
            |ui| ui.checkbox(&mut view.state_view, ""),
        );
        row_ui(
            ui,
            "Shape gizmos",
            "Draw every emitter's spawn shape as a wireframe",
            |ui| ui.checkbox(&mut view.show_gizmos, ""),
        );
        row_ui(
            ui,
            "Render scale",
            "Render the viewport at this fraction of its pixel size and upscale it (faster on \
                slow GPUs)",
            |ui| ui.add(egui::Slider::new(&mut view.render_scale, 0.25..=1.0).fixed_decimals(2)),
        );
        row_ui(
            ui,
            "Draft glow",
            "Draw large additive sprites (flame tongues) at half the render resolution and \
                alpha-blended layers (smoke) at half their own: a quarter of their fill, \
                slightly softer (on by default on software adapters)",
            |ui| ui.checkbox(&mut view.draft, ""),
        );
    });
    ui.horizontal(|ui| {
        if ui
            .button("Frame effect")
            .on_hover_text("Centre the camera on the particles (F, or double-click the viewport)")
            .clicked()
        {
            *frame_requested = true;
        }
    });
    ui.weak("Drag: orbit · Shift/middle/right-drag: pan · Wheel: zoom · Double-click: frame");
}
