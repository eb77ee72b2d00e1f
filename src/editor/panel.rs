//! The side panel: one collapsible section per concern. Every widget is bound to a field
//! of the [`Effect`] (or of the editor's view settings); no parameter lives in a widget.
//!
//! Ranges are clamped by the widgets themselves (`DragValue::range`), so typing or
//! dragging cannot produce a NaN or an out-of-range value; whatever still fails
//! [`Effect::validate`] is shown at the top and the last valid effect keeps running.

use std::ops::RangeInclusive;

use egui::{Color32, DragValue, Response, RichText, Ui};

use crate::effect::{
    Burst, Collisions, Effect, Emitter, Falloff, Integrator, MAX_SPHERES, Range, Shape,
    SphereCollider, TimeMode,
};

use super::curve_editor::{ParamSpec, param_row};
use super::look::look_ui;
use super::state::{EditorState, Playback, ViewSettings};
use super::stats::stats_ui;

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
            section_ui(
                ui,
                "randomness",
                "Randomness",
                &name,
                (false, open("randomness")),
                |ui| {
                    randomness_ui(ui, &mut state.effect, state.selected);
                },
            );
            section_ui(
                ui,
                "forces",
                "Forces",
                &name,
                (false, open("forces")),
                |ui| {
                    forces_ui(ui, &mut state.effect, state.selected);
                },
            );
            section_ui(
                ui,
                "events",
                "Events",
                &name,
                (false, open("events")),
                |ui| {
                    super::events_ui::events_ui(ui, &mut state.effect, state.selected);
                },
            );
            section_ui(ui, "time", "Time", "", (true, open("time")), |ui| {
                time_ui(ui, &mut state.effect, &mut state.playback, state.selected);
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
            section_ui(ui, "view", "View", "", (false, open("view")), |ui| {
                view_ui(ui, &mut state.view, &mut state.frame_requested);
            });
            section_ui(ui, "stats", "Stats", "", (true, open("stats")), |ui| {
                stats_ui(ui, &state.stats, &state.running);
                super::emitter_cost::emitter_cost_ui(
                    ui,
                    &mut state.cost_probe,
                    &state.emitter_costs,
                    &state.running,
                    !state.stats.gpu_pass_ms.is_empty(),
                );
            });
            section_ui(ui, "export", "Export", "", (false, open("export")), |ui| {
                super::export_ui::export_ui(ui, &mut state.export);
            });
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

/// Title, undo/redo and the validation message.
pub fn header_ui(ui: &mut Ui, state: &mut EditorState) {
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
            .on_hover_text("Write the edited effect (valid effects only; atomic: a crash never leaves half a file)")
            .clicked()
        {
            state.save_preset();
        }
        if ui
            .button("Load")
            .on_hover_text("Replace the effect with this preset (undoable; asks first when there are unsaved edits)")
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
                    super::state::PendingAction::Load => {
                        "Discard the unsaved edits and load the preset?"
                    }
                    super::state::PendingAction::ExternalReload => {
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
    if !state.shader_errors.is_empty() {
        error_box_ui(ui, |ui| {
            ui.label(RichText::new("Shader error: the last good pipeline keeps running.").strong());
            for e in &state.shader_errors {
                ui.label(RichText::new(e).monospace().size(11.0));
            }
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

fn error_box_ui(ui: &mut Ui, add: impl FnOnce(&mut Ui)) {
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

/// The spawn rate: particles per second over the effect's time, in seconds.
const SPAWN_RATE: ParamSpec = ParamSpec {
    name: "Spawn rate curve",
    unit: " /s",
    values: 0.0..=1.0e6,
    speed: 5.0,
    t_max: 3600.0,
    t_unit: "s",
};

/// A multiplier over the particle's life.
fn multiplier(name: &'static str) -> ParamSpec {
    ParamSpec {
        name,
        unit: "×",
        values: 0.0..=100.0,
        speed: 0.01,
        t_max: 1.0,
        t_unit: "of life",
    }
}

/// A float drag value clamped to `range`.
fn drag<'a>(v: &'a mut f32, range: RangeInclusive<f32>, speed: f64, suffix: &str) -> DragValue<'a> {
    DragValue::new(v)
        .range(range)
        .speed(speed)
        .suffix(suffix.to_owned())
        .max_decimals(4)
}

/// Three drag values side by side (x, y, z) in one row; the returned response is their
/// union (changed when any changed).
fn vec3_ui(
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
fn range_ui(
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

fn grid(id: &str) -> egui::Grid {
    egui::Grid::new(id)
        .num_columns(2)
        .spacing([10.0, 5.0])
        .min_col_width(96.0)
}

/// A name not used by any emitter of `effect`, starting from `base`.
pub fn unique_name(effect: &Effect, base: &str) -> String {
    if !effect.emitters.iter().any(|e| e.name == base) {
        return base.to_owned();
    }
    (2..)
        .map(|k| format!("{base} {k}"))
        .find(|n| !effect.emitters.iter().any(|e| e.name == *n))
        .unwrap_or_else(|| base.to_owned())
}

// ---------------------------------------------------------------------------------------
// Emitter.

/// The emitter list (select, mute, solo, add, duplicate, remove, reorder) and the
/// selected emitter's spawning parameters.
pub fn emitter_ui(ui: &mut Ui, effect: &mut Effect, selected: &mut usize) {
    emitter_list_ui(ui, effect, selected);
    ui.separator();
    let Some(old_name) = effect.emitters.get(*selected).map(|e| e.name.clone()) else {
        ui.label("No emitter: add one.");
        return;
    };
    emitter_fields_ui(ui, &mut effect.emitters[*selected]);
    // Events name their children: a renamed emitter keeps its parents' events.
    let new_name = effect.emitters[*selected].name.clone();
    super::events_ui::rename_references(effect, &old_name, &new_name);
}

/// The selected emitter's own fields (name, shape, placement, spawning, bursts).
fn emitter_fields_ui(ui: &mut Ui, e: &mut Emitter) {
    grid("emitter_grid").show(ui, |ui| {
        row_ui(
ui, "Name", "Unique name of this layer", |ui| {
            ui.add(egui::TextEdit::singleline(&mut e.name).desired_width(180.0))
        });
        shape_ui(ui, &mut e.shape);
        vec3_ui(
            ui,
            "Position",
            "Emitter origin in the world, metres",
            &mut e.transform.position_m,
            -100.0..=100.0,
            0.01,
            " m",
        );
        vec3_ui(
            ui,
            "Rotation",
            "Emitter rotation, degrees (applied X, then Y, then Z)",
            &mut e.transform.rotation_deg,
            -360.0..=360.0,
            0.5,
            "°",
        );
        param_row(
            ui,
            "Spawn rate",
            "Continuous emission, particles per second, over the effect's time (a range or two curves: one rate or blend per instance, from its seed)",
            &mut e.spawn_rate_per_sec,
            &SPAWN_RATE,
        );
        row_ui(
ui,
            "Max spawn / step",
            "At most this many spawns per step, so a long step cannot cause a burst. 0 = automatic (the rate at a 1/15 s step)",
            |ui| ui.add(DragValue::new(&mut e.max_spawn_per_step).range(0..=UI_MAX_CAPACITY).speed(1.0)),
        );
        row_ui(
ui,
            "Capacity",
            "Particle slots in this emitter's ring. Keep it above rate × max lifetime, or living particles are recycled. Changing it keeps the particles that fit",
            |ui| {
                ui.add(
                    DragValue::new(&mut e.capacity)
                        .range(1..=UI_MAX_CAPACITY)
                        .speed(16.0)
                        .suffix(" slots"),
                )
            },
        );
        let needed = e.spawn_rate_per_sec.bounds().1 * e.lifetime_secs.max;
        if needed > e.capacity as f32 * 1.02 {
            ui.label("");
            ui.colored_label(
                ui.visuals().warn_fg_color,
                format!("rate × max lifetime ≈ {needed:.0} > capacity"),
            );
            ui.end_row();
        }
        range_ui(
            ui,
            "Lifetime",
            "Each particle draws its lifetime from this range, seconds",
            &mut e.lifetime_secs,
            0.001..=1000.0,
            0.01,
            " s",
        );
        vec3_ui(
            ui,
            "Direction",
            "Initial direction in emitter space (normalised on use; must not be zero)",
            &mut e.direction,
            -1.0..=1.0,
            0.01,
            "",
        );
        row_ui(
ui,
            "Spread",
            "Half-angle of the cone of initial directions, degrees (a Cone shape uses its own angle)",
            |ui| ui.add(drag(&mut e.spread_deg, 0.0..=180.0, 0.2, "°")),
        );
        range_ui(
            ui,
            "Speed",
            "Initial speed range, metres per second",
            &mut e.speed_m_per_s,
            0.0..=1000.0,
            0.01,
            " m/s",
        );
    });
    bursts_ui(ui, &mut e.bursts);
}

fn emitter_list_ui(ui: &mut Ui, effect: &mut Effect, selected: &mut usize) {
    let n = effect.emitters.len();
    for i in 0..n {
        ui.horizontal(|ui| {
            let e = &mut effect.emitters[i];
            ui.checkbox(&mut e.enabled, "")
                .on_hover_text("Enabled (unchecked = muted: neither simulated nor drawn)");
            let text = if e.enabled {
                RichText::new(&e.name)
            } else {
                RichText::new(&e.name).weak().strikethrough()
            };
            if ui.selectable_label(*selected == i, text).clicked() {
                *selected = i;
            }
            ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
                ui.weak(format!("{} · {}", e.look.sprite.label(), e.shape.label()));
            });
        });
    }
    ui.horizontal_wrapped(|ui| {
        if ui
            .small_button("Add")
            .on_hover_text("Add a default emitter after the selected one")
            .clicked()
        {
            let e = Emitter {
                name: unique_name(effect, "emitter"),
                ..Emitter::default()
            };
            let at = (*selected + 1).min(n);
            effect.emitters.insert(at, e);
            *selected = at;
        }
        if ui
            .add_enabled(n > 0, egui::Button::new("Duplicate").small())
            .on_hover_text("Copy the selected emitter")
            .clicked()
            && let Some(src) = effect.emitters.get(*selected)
        {
            let mut e = src.clone();
            e.name = unique_name(effect, &format!("{} copy", src.name));
            effect.emitters.insert(*selected + 1, e);
            *selected += 1;
        }
        if ui
            .add_enabled(n > 1, egui::Button::new("Remove").small())
            .on_hover_text("Remove the selected emitter (an effect keeps at least one)")
            .clicked()
            && *selected < n
        {
            effect.emitters.remove(*selected);
            // Events that fed the removed emitter go with it.
            effect.drop_dangling_events();
            *selected = selected.saturating_sub(1).min(n - 2);
        }
        if ui
            .add_enabled(*selected > 0, egui::Button::new("Up").small())
            .on_hover_text("Draw earlier (layers are drawn in order within a blend mode)")
            .clicked()
        {
            effect.emitters.swap(*selected, *selected - 1);
            *selected -= 1;
        }
        if ui
            .add_enabled(*selected + 1 < n, egui::Button::new("Down").small())
            .on_hover_text("Draw later")
            .clicked()
        {
            effect.emitters.swap(*selected, *selected + 1);
            *selected += 1;
        }
        if ui
            .small_button("Solo")
            .on_hover_text("Enable only the selected emitter")
            .clicked()
        {
            for (i, e) in effect.emitters.iter_mut().enumerate() {
                e.enabled = i == *selected;
            }
        }
        if ui
            .small_button("All on")
            .on_hover_text("Enable every emitter")
            .clicked()
        {
            for e in &mut effect.emitters {
                e.enabled = true;
            }
        }
    });
}

/// Shape picker and the selected shape's dimensions (grid rows).
fn shape_ui(ui: &mut Ui, shape: &mut Shape) {
    let label = ui
        .label("Shape")
        .on_hover_text("Where particles are born, in emitter space");
    egui::ComboBox::from_id_salt("shape_kind")
        .selected_text(shape.label())
        .width(120.0)
        .show_ui(ui, |ui| {
            for s in Shape::all_defaults() {
                let is_current = s.kind_index() == shape.kind_index();
                if ui.selectable_label(is_current, s.label()).clicked() && !is_current {
                    *shape = carry_size(shape, s);
                }
            }
        })
        .response
        .labelled_by(label.id);
    ui.end_row();
    match shape {
        Shape::Point => {}
        Shape::Sphere {
            radius_m,
            surface_only,
        } => {
            row_ui(ui, "Radius", "Sphere radius, metres", |ui| {
                ui.add(drag(radius_m, 0.0..=100.0, 0.005, " m"))
            });
            row_ui(
                ui,
                "Surface only",
                "Spawn on the surface instead of the volume",
                |ui| ui.checkbox(surface_only, ""),
            );
        }
        Shape::Disc { radius_m, normal } => {
            row_ui(ui, "Radius", "Disc radius, metres", |ui| {
                ui.add(drag(radius_m, 0.0..=100.0, 0.005, " m"))
            });
            vec3_ui(
                ui,
                "Normal",
                "Disc normal in emitter space (normalised on use; must not be zero)",
                normal,
                -1.0..=1.0,
                0.01,
                "",
            );
        }
        Shape::Box { half_extents_m } => {
            vec3_ui(
                ui,
                "Half extents",
                "Half the box size along each axis, metres",
                half_extents_m,
                0.0..=100.0,
                0.005,
                " m",
            );
        }
        Shape::Cone {
            angle_deg,
            radius_m,
        } => {
            row_ui(
                ui,
                "Cone angle",
                "Half-angle of the directions, degrees (replaces Spread)",
                |ui| ui.add(drag(angle_deg, 0.0..=180.0, 0.2, "°")),
            );
            row_ui(ui, "Base radius", "Radius of the base disc, metres", |ui| {
                ui.add(drag(radius_m, 0.0..=100.0, 0.005, " m"))
            });
        }
        Shape::Line { a_m, b_m } => {
            vec3_ui(
                ui,
                "Start",
                "First endpoint, metres",
                a_m,
                -100.0..=100.0,
                0.01,
                " m",
            );
            vec3_ui(
                ui,
                "End",
                "Second endpoint, metres",
                b_m,
                -100.0..=100.0,
                0.01,
                " m",
            );
        }
    }
}

/// Switches shape kind keeping the size when both kinds have a radius.
fn carry_size(old: &Shape, mut new: Shape) -> Shape {
    let old_radius = match old {
        Shape::Sphere { radius_m, .. }
        | Shape::Disc { radius_m, .. }
        | Shape::Cone { radius_m, .. } => Some(*radius_m),
        _ => None,
    };
    if let Some(r) = old_radius {
        match &mut new {
            Shape::Sphere { radius_m, .. }
            | Shape::Disc { radius_m, .. }
            | Shape::Cone { radius_m, .. } => *radius_m = r,
            _ => {}
        }
    }
    new
}

fn bursts_ui(ui: &mut Ui, bursts: &mut Vec<Burst>) {
    ui.horizontal(|ui| {
        ui.label("Bursts")
            .on_hover_text("One-shot bursts at a simulated time (they fire again after a restart)");
        if ui.small_button("Add burst").clicked() {
            let t = bursts.last().map_or(0.0, |b| b.time_secs + 0.5);
            bursts.push(Burst {
                time_secs: t,
                count: 200,
            });
        }
    });
    let mut remove = None;
    for (k, b) in bursts.iter_mut().enumerate() {
        ui.horizontal(|ui| {
            ui.add_space(12.0);
            ui.add(
                drag(&mut b.time_secs, 0.0..=1.0e5, 0.01, " s")
                    .prefix("at ")
                    .min_decimals(2),
            );
            ui.add(
                DragValue::new(&mut b.count)
                    .range(0..=UI_MAX_CAPACITY)
                    .speed(1.0)
                    .suffix(" particles"),
            );
            if ui
                .small_button("x")
                .on_hover_text("Remove this burst")
                .clicked()
            {
                remove = Some(k);
            }
        });
    }
    if let Some(k) = remove {
        bursts.remove(k);
    }
}

// ---------------------------------------------------------------------------------------
// Randomness.

/// A new seed derived from the old one (deterministic, so a session can be replayed).
pub fn next_seed(seed: u32) -> u32 {
    crate::rng::pcg4d([seed, 0x9E37_79B9, 0x7F4A_7C15, 1])[0]
}

/// The effect seed, the emitter's seed offset and its spawn noise.
pub fn randomness_ui(ui: &mut Ui, effect: &mut Effect, selected: usize) {
    grid("randomness_grid").show(ui, |ui| {
        let label = ui
            .label("Seed")
            .on_hover_text("Master seed: every random number is a hash of the seed, the emitter, the slot and the spawn counter");
        ui.horizontal(|ui| {
            ui.add(DragValue::new(&mut effect.seed).speed(1.0))
                .labelled_by(label.id);
            if ui
                .button("New seed")
                .on_hover_text("Derive a new seed from this one")
                .clicked()
            {
                effect.seed = next_seed(effect.seed);
            }
        });
        ui.end_row();
        let Some(e) = effect.emitters.get_mut(selected) else {
            return;
        };
        row_ui(
ui,
            "Seed offset",
            "Added to the seed for this emitter's stream (two emitters with the same settings differ by it)",
            |ui| ui.add(DragValue::new(&mut e.seed_offset).speed(1.0)),
        );
        let n = &mut e.spawn_noise;
        row_ui(
ui,
            "Noise frequency",
            "Spatial frequency of the noise that moves spawn positions and tilts directions, per metre",
            |ui| ui.add(drag(&mut n.frequency_per_m, 0.0..=100.0, 0.02, " /m")),
        );
        row_ui(
ui,
            "Position amplitude",
            "How far the noise moves spawn positions, metres",
            |ui| ui.add(drag(&mut n.position_amplitude_m, 0.0..=10.0, 0.002, " m")),
        );
        row_ui(
ui,
            "Direction amplitude",
            "How far the noise tilts the initial direction (fraction of the direction vector)",
            |ui| ui.add(drag(&mut n.direction_amplitude, 0.0..=10.0, 0.005, "")),
        );
        row_ui(
ui,
            "Scroll speed",
            "How fast the noise field scrolls in time (flicker rate), per second",
            |ui| ui.add(drag(&mut n.scroll_per_sec, -100.0..=100.0, 0.02, " /s")),
        );
    });
}

// ---------------------------------------------------------------------------------------
// Forces.

/// Gravity, buoyancy, drag and wind of the selected emitter.
pub fn forces_ui(ui: &mut Ui, effect: &mut Effect, selected: usize) {
    let Some(e) = effect.emitters.get_mut(selected) else {
        return;
    };
    let f = &mut e.forces;
    grid("forces_grid").show(ui, |ui| {
        row_ui(
ui,
            "Buoyancy",
            "Upward acceleration of hot gas along +Y, m/s² (the 2006 thesis's negative gravity)",
            |ui| ui.add(drag(&mut f.buoyancy_m_per_s2, -1000.0..=1000.0, 0.05, " m/s²")),
        );
        vec3_ui(
            ui,
            "Gravity m/s²",
            "Gravity, m/s²",
            &mut f.gravity_m_per_s2,
            -1000.0..=1000.0,
            0.05,
            "",
        );
        row_ui(
ui,
            "Drag",
            "Linear drag rate k, per second: the velocity relaxes toward the wind with time constant 1/k",
            |ui| ui.add(drag(&mut f.drag_per_sec, 0.0..=1000.0, 0.01, " /s")),
        );
        param_row(
            ui,
            "Drag over life",
            "Multiplies both drags over the particle's life (1 = unchanged)",
            &mut f.drag_over_life,
            &multiplier("Drag over life curve"),
        );
        param_row(
            ui,
            "Speed over life",
            "Multiplies how far the particle moves each step over its life (1 = as its velocity says)",
            &mut f.speed_over_life,
            &multiplier("Speed over life curve"),
        );
        vec3_ui(
            ui,
            "Wind m/s",
            "The flow velocity drag pulls toward, m/s",
            &mut f.wind_m_per_s,
            -100.0..=100.0,
            0.01,
            "",
        );
    });
    let accel = f.constant_acceleration();
    let text = if f.drag_per_sec > 0.0 {
        let terminal = accel / f.drag_per_sec + glam::Vec3::from(f.wind_m_per_s);
        format!(
            "Net constant acceleration {:+.2} m/s² up; terminal velocity ({:.2}, {:.2}, {:.2}) m/s",
            accel.y, terminal.x, terminal.y, terminal.z
        )
    } else {
        format!("Net constant acceleration {:+.2} m/s² up; no drag", accel.y)
    };
    ui.weak(text);
    ui.add_space(4.0);
    force_modules_ui(ui, f);
    ui.add_space(4.0);
    collisions_ui(ui, &mut e.collisions);
}

/// An optional module: a checkbox that creates it with its defaults or removes it, and
/// its fields when present.
fn module_ui<T: Default>(
    ui: &mut Ui,
    id: &str,
    label: &str,
    tip: &str,
    slot: &mut Option<T>,
    body: impl FnOnce(&mut Ui, &mut T),
) {
    let mut is_on = slot.is_some();
    if ui.checkbox(&mut is_on, label).on_hover_text(tip).changed() {
        *slot = is_on.then(T::default);
    }
    if let Some(module) = slot {
        ui.indent(id, |ui| grid(id).show(ui, |ui| body(ui, module)));
    }
}

/// Quadratic drag and the optional force modules (each costs nothing when off).
fn force_modules_ui(ui: &mut Ui, f: &mut crate::effect::Forces) {
    grid("quadratic_drag_grid").show(ui, |ui| {
        row_ui(
            ui,
            "Quadratic drag",
            "a = −c·|v − wind|·(v − wind), per metre; 0 = off",
            |ui| ui.add(drag(&mut f.quadratic_drag_per_m, 0.0..=100.0, 0.005, " /m")),
        );
    });
    module_ui(
        ui,
        "gusts",
        "Gusts",
        "Noise-modulated wind strength",
        &mut f.gusts,
        |ui, g| {
            row_ui(ui, "Gust strength", "Fraction of the wind", |ui| {
                ui.add(drag(&mut g.strength, 0.0..=10.0, 0.01, "×"))
            });
            row_ui(ui, "Gust frequency", "How often gusts change, Hz", |ui| {
                ui.add(drag(&mut g.frequency_hz, 0.0..=100.0, 0.01, " Hz"))
            });
        },
    );
    module_ui(
        ui,
        "turbulence",
        "Turbulence",
        "Curl-noise turbulence (divergence-free swirls)",
        &mut f.turbulence,
        |ui, t| {
            row_ui(ui, "Turb. strength", "Typical acceleration, m/s²", |ui| {
                ui.add(drag(&mut t.strength_m_per_s2, 0.0..=1000.0, 0.02, " m/s²"))
            });
            row_ui(
                ui,
                "Turb. frequency",
                "Spatial frequency, per metre",
                |ui| ui.add(drag(&mut t.frequency_per_m, 0.0..=100.0, 0.02, " /m")),
            );
            row_ui(
                ui,
                "Octaves",
                "Each octave doubles the frequency and halves the amplitude",
                |ui| ui.add(DragValue::new(&mut t.octaves).range(1..=4).speed(0.05)),
            );
            row_ui(
                ui,
                "Turb. scroll",
                "Upward scroll of the field, m/s",
                |ui| ui.add(drag(&mut t.scroll_m_per_s, -100.0..=100.0, 0.01, " m/s")),
            );
            param_row(
                ui,
                "Turb. over life",
                "Multiplies the turbulence over the particle's life (1 = unchanged)",
                &mut t.over_life,
                &multiplier("Turbulence over life curve"),
            );
        },
    );
    module_ui(
        ui,
        "vortex",
        "Vortex",
        "Swirl around an axis through a point",
        &mut f.vortex,
        |ui, v| {
            vec3_ui(
                ui,
                "Vortex centre",
                "A point on the axis, world metres",
                &mut v.center_m,
                -1000.0..=1000.0,
                0.01,
                " m",
            );
            vec3_ui(
                ui,
                "Vortex axis",
                "Axis direction (normalised on use; not zero)",
                &mut v.axis,
                -1.0..=1.0,
                0.01,
                "",
            );
            row_ui(
                ui,
                "Swirl",
                "Tangential acceleration near the axis, m/s² (sign = spin)",
                |ui| ui.add(drag(&mut v.swirl_m_per_s2, -1000.0..=1000.0, 0.02, " m/s²")),
            );
            row_ui(
                ui,
                "Vortex radius",
                "Falloff radius R: a·exp(−d²/R²), metres",
                |ui| ui.add(drag(&mut v.radius_m, 0.001..=1000.0, 0.005, " m")),
            );
        },
    );
    module_ui(
        ui,
        "attractor",
        "Attractor",
        "Point attractor (negative strength repels)",
        &mut f.attractor,
        |ui, a| {
            vec3_ui(
                ui,
                "Attractor position",
                "World metres",
                &mut a.position_m,
                -1000.0..=1000.0,
                0.01,
                " m",
            );
            row_ui(
                ui,
                "Attractor strength",
                "m³/s² (inverse square) or m/s² (constant); negative repels",
                |ui| ui.add(drag(&mut a.strength, -1000.0..=1000.0, 0.01, "")),
            );
            row_ui(
                ui,
                "Attractor radius",
                "Softening radius (inverse square) or range (constant), metres",
                |ui| ui.add(drag(&mut a.radius_m, 0.001..=1000.0, 0.005, " m")),
            );
            let label = ui.label("Falloff");
            egui::ComboBox::from_id_salt("attractor_falloff")
                .selected_text(falloff_label(a.falloff))
                .show_ui(ui, |ui| {
                    for f in [Falloff::InverseSquare, Falloff::ConstantWithinRadius] {
                        ui.selectable_value(&mut a.falloff, f, falloff_label(f));
                    }
                })
                .response
                .labelled_by(label.id);
            ui.end_row();
        },
    );
    module_ui(
        ui,
        "flame_pull",
        "Flame pull",
        "Pull toward the emitter axis, growing with age, so flames taper",
        &mut f.flame_pull,
        |ui, p| {
            row_ui(ui, "Pull strength", "Per second squared", |ui| {
                ui.add(drag(&mut p.strength_per_s2, 0.0..=1000.0, 0.05, " /s²"))
            });
            row_ui(
                ui,
                "Pull exponent",
                "Growth with normalised age (1 = linear)",
                |ui| ui.add(drag(&mut p.exponent, 0.0..=16.0, 0.01, "")),
            );
            param_row(
                ui,
                "Pull over life",
                "Multiplies the pull over the particle's life (1 = unchanged)",
                &mut p.over_life,
                &multiplier("Pull over life curve"),
            );
        },
    );
}

fn falloff_label(f: Falloff) -> &'static str {
    match f {
        Falloff::InverseSquare => "inverse square",
        Falloff::ConstantWithinRadius => "constant within radius",
    }
}

/// Ground plane and sphere colliders of the selected emitter.
fn collisions_ui(ui: &mut Ui, col: &mut Collisions) {
    ui.label(RichText::new("Collisions").strong());
    module_ui(
        ui,
        "ground",
        "Ground plane",
        "An infinite horizontal plane particles bounce on",
        &mut col.ground,
        |ui, g| {
            row_ui(ui, "Ground height", "Height of the plane, metres", |ui| {
                ui.add(drag(&mut g.height_m, -1000.0..=1000.0, 0.01, " m"))
            });
            row_ui(
                ui,
                "Kill on ground",
                "Particles that touch the ground die",
                |ui| ui.checkbox(&mut g.kill_on_contact, ""),
            );
        },
    );
    let mut remove = None;
    for (k, sphere) in col.spheres.iter_mut().enumerate() {
        ui.horizontal(|ui| {
            ui.label(format!("Sphere {}", k + 1));
            for (c, axis) in sphere.center_m.iter_mut().zip(["x ", "y ", "z "]) {
                ui.add(
                    drag(c, -1000.0..=1000.0, 0.01, "")
                        .prefix(axis)
                        .min_decimals(2),
                );
            }
            ui.add(drag(&mut sphere.radius_m, 0.001..=1000.0, 0.005, " m").prefix("r "));
            if ui
                .small_button("x")
                .on_hover_text("Remove this sphere")
                .clicked()
            {
                remove = Some(k);
            }
        });
    }
    if let Some(k) = remove {
        col.spheres.remove(k);
    }
    ui.horizontal(|ui| {
        if ui
            .add_enabled(
                col.spheres.len() < MAX_SPHERES,
                egui::Button::new("Add sphere").small(),
            )
            .on_hover_text(format!("A sphere collider (at most {MAX_SPHERES})"))
            .clicked()
        {
            col.spheres.push(SphereCollider::default());
        }
        ui.checkbox(&mut col.kill_on_sphere_contact, "kill on contact")
            .on_hover_text("Particles that touch a sphere die (smoke into a wall)");
        ui.checkbox(&mut col.stick_on_contact, "stick")
            .on_hover_text("Particles stop where they touch a collider and stay there");
    });
    if col.any() {
        grid("collision_grid").show(ui, |ui| {
            row_ui(
                ui,
                "Elasticity",
                "Normal restitution: 0 stops, 1 bounces perfectly",
                |ui| ui.add(drag(&mut col.elasticity, 0.0..=1.0, 0.005, "")),
            );
            row_ui(ui, "Friction", "Tangential loss per contact, 0..1", |ui| {
                ui.add(drag(&mut col.friction, 0.0..=1.0, 0.005, ""))
            });
            row_ui(
                ui,
                "Rest speed",
                "Below this normal speed after a bounce the particle rests, m/s",
                |ui| {
                    ui.add(drag(
                        &mut col.rest_speed_m_per_s,
                        0.0..=100.0,
                        0.001,
                        " m/s",
                    ))
                },
            );
        });
    }
}

// ---------------------------------------------------------------------------------------
// Time.

/// Time stepping, playback and the integrator of each emitter with its stability hint.
pub fn time_ui(ui: &mut Ui, effect: &mut Effect, playback: &mut Playback, selected: usize) {
    ui.horizontal(|ui| {
        super::timeline::playback_buttons_ui(ui, playback);
        if playback.is_paused {
            ui.colored_label(Color32::from_rgb(240, 200, 90), "paused");
        }
    });
    let t = &mut effect.time;
    grid("time_grid").show(ui, |ui| {
        ui.label("Mode").on_hover_text(
            "Fixed step: an accumulator runs whole steps, so the result does not depend on the frame rate. Frame delta: one step per frame of the frame's duration (the 2006 thesis's mode)",
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
            "At most this many fixed steps per frame; the rest of the time is dropped and counted (Stats)",
            |ui| ui.add_enabled(is_fixed, DragValue::new(&mut t.max_substeps).range(1..=256).speed(0.1)),
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
                "Closed form instead of steps: each particle's position is evaluated from its spawn record and age (exact, cheaper). Only for constant acceleration and linear drag",
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
            let tip = "Bytes stored per particle. 32 B: f32 position, velocity, age, lifetime. 20 B packed: f16 velocity, 16-bit life fraction, lifetime re-derived from the spawn hash. 10 B tiny: f16 position, shared-exponent velocity, age from a table of each step's births. Smaller moves less memory for huge pools, at the accuracy cost `ignis bench accuracy` reports (\"+ packed\", \"+ tiny\" rows). Switching restarts this emitter's particles";
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
    });
    if let Some(e) = effect.emitters.get(selected) {
        measured_ui(ui, e.integrator, step_secs(effect));
    }
    stability_ui(ui, effect);
}

/// The step the integrators see: the fixed step, or the largest frame-delta step.
pub fn step_secs(effect: &Effect) -> f32 {
    match effect.time.mode {
        TimeMode::FixedStep => effect.time.step_secs,
        TimeMode::FrameDelta => effect.time.max_frame_dt_secs,
    }
}

/// What the accuracy bench measured for `integrator` near `dt_secs` (the committed H100
/// results embedded in the binary), cached because the figures are parsed from JSON.
fn measured_ui(ui: &mut Ui, integrator: Integrator, dt_secs: f32) {
    type Cache = Option<((Integrator, u32), Vec<super::measured::Measured>)>;
    static CACHE: std::sync::Mutex<Cache> = std::sync::Mutex::new(None);
    let key = (integrator, dt_secs.to_bits());
    let figures = match CACHE.lock() {
        Ok(mut cache) => {
            if cache.as_ref().is_none_or(|(k, _)| *k != key) {
                let figures = super::measured::measured_for(integrator, dt_secs as f64);
                *cache = Some((key, figures));
            }
            cache.as_ref().map(|(_, f)| f.clone()).unwrap_or_default()
        }
        Err(_) => Vec::new(),
    };
    if figures.is_empty() {
        return;
    }
    ui.weak(format!(
        "{} as measured (H100, T = 2 s):",
        integrator.label()
    ))
    .on_hover_text(
        "From the committed accuracy bench (bench/results/accuracy-nvidia-h100-80gb.json): \
             RMS position error relative to the reference solution after 2 s, and the update \
             cost per particle and step, at the measured step nearest to this one",
    );
    for m in figures {
        ui.weak(format!(
            "  {}: error {:.1e} at dt {:.4} s, {:.2} ns/particle-step",
            m.scene, m.rms_rel_error, m.dt_secs, m.cost_ns
        ));
    }
}

/// k·dt of the step the integrator sees (the worst case in frame-delta mode).
pub fn drag_times_dt(effect: &Effect, emitter: &Emitter) -> f32 {
    emitter.forces.drag_per_sec * step_secs(effect)
}

/// The drag stability hint for every emitter: k·dt against the integrator's limit.
fn stability_ui(ui: &mut Ui, effect: &Effect) {
    egui::Grid::new("stability_grid")
        .num_columns(3)
        .spacing([10.0, 2.0])
        .show(ui, |ui| {
            ui.weak("emitter");
            ui.weak("integrator");
            ui.weak("drag·dt / limit")
                .on_hover_text("Linear drag v' = −k·v is stable for k·dt below the method's limit; above it the velocity oscillates and grows");
            ui.end_row();
            for e in &effect.emitters {
                let kdt = drag_times_dt(effect, e);
                ui.label(&e.name);
                ui.label(e.integrator.label());
                match e.integrator.drag_stability_limit() {
                    Some(limit) if kdt > limit => {
                        ui.colored_label(
                            ui.visuals().error_fg_color,
                            format!("{kdt:.3} > {limit:.3}: unstable"),
                        );
                    }
                    Some(limit) => {
                        ui.label(format!("{kdt:.3} / {limit:.3}"));
                    }
                    None => {
                        ui.label(format!("{kdt:.3} / ∞"));
                    }
                }
                ui.end_row();
            }
        });
}

// ---------------------------------------------------------------------------------------
// View.

/// Viewport options: grid, gizmos, render scale, camera.
pub fn view_ui(ui: &mut Ui, view: &mut ViewSettings, frame_requested: &mut bool) {
    grid("view_grid").show(ui, |ui| {
        row_ui(
ui, "Ground grid", "Draw the y = 0 grid (0.5 m cells)", |ui| {
            ui.checkbox(&mut view.show_grid, "")
        });
        row_ui(
            ui,
            "Mouse collider",
            "A sphere collider follows the pointer over the viewport: push the fire around",
            |ui| ui.checkbox(&mut view.mouse_collider, ""),
        );
        row_ui(
            ui,
            "Inspect",
            "Show the particle under the pointer — its slot, age, lifetime, position, velocity and the forces on it now; click one to pin it",
            |ui| ui.checkbox(&mut view.inspect, ""),
        );
        row_ui(
            ui,
            "State view",
            "The selected emitter's state buffer as images, one texel per slot: position, velocity and age as colours",
            |ui| ui.checkbox(&mut view.state_view, ""),
        );
        row_ui(
ui, "Shape gizmos", "Draw every emitter's spawn shape as a wireframe", |ui| {
            ui.checkbox(&mut view.show_gizmos, "")
        });
        row_ui(
ui,
            "Render scale",
            "Render the viewport at this fraction of its pixel size and upscale it (faster on slow GPUs)",
            |ui| ui.add(egui::Slider::new(&mut view.render_scale, 0.25..=1.0).fixed_decimals(2)),
        );
        row_ui(
            ui,
            "Draft glow",
            "Draw large additive sprites (flame tongues) at half the render resolution and alpha-blended layers (smoke) at half their own: a quarter of their fill, slightly softer (on by default on software adapters)",
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
