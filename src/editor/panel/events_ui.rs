//! The Events section: which emitters the selected emitter's particles spawn, on what
//! trigger, how many, and what they inherit. Every widget is bound to a field of the
//! effect's [`Event`]s; validation, undo and the live update are the panel's as for any
//! other edit.

use egui::{DragValue, Ui};

use crate::effect::{
    CountRange, Effect, Event, MAX_CHILDREN_PER_EVENT, MAX_EVENTS_PER_EMITTER, Trigger,
};

use crate::editor::panel::drag;

/// The Events section of emitter `selected`.
pub fn events_ui(ui: &mut Ui, effect: &mut Effect, selected: usize) {
    let others: Vec<String> = effect
        .emitters
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != selected)
        .map(|(_, e)| e.name.clone())
        .collect();
    let parents: Vec<String> = effect
        .event_sources(selected)
        .iter()
        .map(|&(p, _)| effect.emitters[p].name.clone())
        .collect();
    if !parents.is_empty() {
        ui.weak(format!(
            "Spawns from the events of {} (its own rate and bursts are not used).",
            parents.join(", ")
        ));
    }
    let Some(e) = effect.emitters.get_mut(selected) else {
        return;
    };
    let mut remove = None;
    for (k, ev) in e.events.iter_mut().enumerate() {
        ui.push_id(("event", k), |ui| {
            event_grid_ui(ui, ev, &others);
            if ui.button("Remove event").clicked() {
                remove = Some(k);
            }
        });
        ui.separator();
    }
    if let Some(k) = remove {
        e.events.remove(k);
    }
    if others.is_empty() {
        ui.weak("Add a second emitter to spawn its particles from this one's events.");
    } else if e.events.len() < MAX_EVENTS_PER_EMITTER
        && ui
            .button("Add event")
            .on_hover_text(
                "Spawn particles of another emitter when this one's die, collide, \
                are born, or while they live",
            )
            .clicked()
    {
        e.events.push(Event {
            emitter: others[0].clone(),
            ..Event::default()
        });
    }
}

/// One event's fields.
fn event_grid_ui(ui: &mut Ui, ev: &mut Event, others: &[String]) {
    egui::Grid::new("event_grid")
        .num_columns(2)
        .spacing([10.0, 5.0])
        .min_col_width(96.0)
        .show(ui, |ui| {
            let label = ui
                .label("Spawn")
                .on_hover_text("The emitter whose particles this event spawns");
            egui::ComboBox::from_id_salt("event_target")
                .selected_text(ev.emitter.as_str())
                .show_ui(ui, |ui| {
                    for name in others {
                        ui.selectable_value(&mut ev.emitter, name.clone(), name.as_str());
                    }
                })
                .response
                .labelled_by(label.id);
            ui.end_row();
            let label = ui.label("When").on_hover_text(
                "Death: the step a particle dies. \
                Collision: each impact on the ground or a sphere faster than the rest speed. \
                Birth: the step it is born. Over life: at a rate while it lives",
            );
            egui::ComboBox::from_id_salt("event_trigger")
                .selected_text(ev.trigger.label())
                .show_ui(ui, |ui| {
                    for t in Trigger::ALL {
                        ui.selectable_value(&mut ev.trigger, t, t.label());
                    }
                })
                .response
                .labelled_by(label.id);
            ui.end_row();
            if ev.trigger == Trigger::OverLife {
                let label = ui
                    .label("Rate")
                    .on_hover_text("Children per second per living particle");
                ui.add(drag(&mut ev.rate_per_sec, 0.0..=1000.0, 0.1, " /s"))
                    .labelled_by(label.id);
            } else {
                let label = ui
                    .label("Count")
                    .on_hover_text("Children per event: each event draws a count in this range");
                ui.horizontal(|ui| {
                    count_ui(ui, &mut ev.count);
                })
                .response
                .labelled_by(label.id);
                ui.end_row();
                let label = ui
                    .label("Chance")
                    .on_hover_text("The chance that an event spawns at all (1 = every event)");
                ui.add(drag(&mut ev.probability, 0.0..=1.0, 0.002, "").max_decimals(3))
                    .labelled_by(label.id);
            }
            ui.end_row();
            let label = ui.label("Inherit velocity").on_hover_text(
                "The fraction of the \
                parent's velocity a child starts with, on top of its own spawn speed",
            );
            ui.add(drag(&mut ev.inherit_velocity, -10.0..=10.0, 0.01, ""))
                .labelled_by(label.id);
            ui.end_row();
            ui.label("Inherit colour").on_hover_text(
                "Multiply the child's colour by the \
                parent's colour at the event (a white child gradient takes the parent's colour)",
            );
            ui.checkbox(&mut ev.inherit_color, "parent's colour");
            ui.end_row();
            let label = ui.label("Cap / s").on_hover_text(
                "At most this many children per \
                second of simulated time, at any step size; the rest are dropped and counted in \
                Stats",
            );
            ui.add(drag(&mut ev.max_per_sec, 1.0..=1e8, 10.0, ""))
                .labelled_by(label.id);
            ui.end_row();
        });
}

/// The min and max of a count range (min ≤ max kept while dragging either).
fn count_ui(ui: &mut Ui, count: &mut CountRange) {
    let max = MAX_CHILDREN_PER_EVENT;
    if ui
        .add(DragValue::new(&mut count.min).range(0..=max).prefix("min "))
        .changed()
    {
        count.max = count.max.max(count.min);
    }
    if ui
        .add(DragValue::new(&mut count.max).range(0..=max).prefix("max "))
        .changed()
    {
        count.min = count.min.min(count.max);
    }
}

/// After emitter `old` was renamed to `new`, the events that named it follow.
pub fn rename_references(effect: &mut Effect, old: &str, new: &str) {
    if old == new {
        return;
    }
    for ev in effect.emitters.iter_mut().flat_map(|e| e.events.iter_mut()) {
        if ev.emitter == old {
            ev.emitter = new.to_owned();
        }
    }
}
