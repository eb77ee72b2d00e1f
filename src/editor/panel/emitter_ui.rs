//! The panel's Emitter and Randomness sections: the emitter list, its spawn fields, its
//! shape and bursts, and the seeds.

use egui::{DragValue, RichText, Ui};

use crate::effect::{Burst, Effect, Emitter, Shape};

use crate::editor::panel::curve_editor::{ParamSpec, param_row};
use crate::editor::panel::{UI_MAX_CAPACITY, drag, grid, range_ui, row_ui, vec3_ui};

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
    crate::editor::panel::events_ui::rename_references(effect, &old_name, &new_name);
}

/// The selected emitter's own fields (name, shape, placement, spawning, bursts).
fn emitter_fields_ui(ui: &mut Ui, e: &mut Emitter) {
    grid("emitter_grid").show(ui, |ui| {
        row_ui(ui, "Name", "Unique name of this layer", |ui| {
            ui.add(egui::TextEdit::singleline(&mut e.name).desired_width(180.0))
        });
        shape_ui(ui, &mut e.shape);
        placement_rows_ui(ui, e);
        param_row(
            ui,
            "Spawn rate",
            "Continuous emission, particles per second, over the effect's time (a range or two \
                curves: one rate or blend per instance, from its seed)",
            &mut e.spawn_rate_per_sec,
            &SPAWN_RATE,
        );
        row_ui(
            ui,
            "Max spawn / s",
            "At most this many continuous spawns per second of simulated time, at any step size \
                (clips a rate curve's peaks; bursts are not capped). 0 = no cap",
            |ui| ui.add(drag(&mut e.max_spawn_per_sec, 0.0..=1e9, 10.0, "")),
        );
        row_ui(
            ui,
            "Capacity",
            "Particle slots in this emitter's ring. Keep it above rate × max lifetime, or \
                living particles are recycled. Changing it keeps the particles that fit",
            |ui| ui.add(drag(&mut e.capacity, 1..=UI_MAX_CAPACITY, 16.0, " slots")),
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
        launch_rows_ui(ui, e);
    });
    bursts_ui(ui, &mut e.bursts);
}

/// Where the emitter is: position and rotation (rows of an open grid).
fn placement_rows_ui(ui: &mut Ui, e: &mut Emitter) {
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
}

/// How particles leave: lifetime, direction, spread and speed (rows of an open grid).
fn launch_rows_ui(ui: &mut Ui, e: &mut Emitter) {
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
        "Half-angle of the cone of initial directions, degrees (a Cone shape uses its own \
            angle)",
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
            ui.add(drag(&mut b.count, 0..=UI_MAX_CAPACITY, 1.0, " particles"));
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

/// A new seed derived from the old one (deterministic, so a session can be replayed).
pub fn next_seed(seed: u32) -> u32 {
    crate::rng::pcg4d([seed, 0x9E37_79B9, 0x7F4A_7C15, 1])[0]
}

/// The effect seed, the emitter's seed offset and its spawn noise.
pub fn randomness_ui(ui: &mut Ui, effect: &mut Effect, selected: usize) {
    grid("randomness_grid").show(ui, |ui| {
        let label = ui.label("Seed").on_hover_text(
            "Master seed: every random number is a hash of the seed, the \
                emitter, the slot and the spawn counter",
        );
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
            "Added to the seed for this emitter's stream (two emitters with the same settings \
                differ by it)",
            |ui| ui.add(DragValue::new(&mut e.seed_offset).speed(1.0)),
        );
        let n = &mut e.spawn_noise;
        row_ui(
            ui,
            "Noise frequency",
            "Spatial frequency of the noise that moves spawn positions and tilts directions, \
                per metre",
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

/// The spawn rate: particles per second over the effect's time, in seconds.
const SPAWN_RATE: ParamSpec = ParamSpec {
    name: "Spawn rate curve",
    unit: " /s",
    values: 0.0..=1.0e6,
    speed: 5.0,
    t_max: 3600.0,
    t_unit: "s",
};

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
