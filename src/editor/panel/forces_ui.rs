//! The panel's Forces section: gravity, buoyancy, drag and wind, the optional force
//! modules and the collisions.

use egui::{RichText, Ui};

use crate::effect::{
    Attractor, Collisions, Effect, Falloff, FlamePull, Gusts, MAX_SPHERES, SphereCollider,
    Turbulence, Vortex,
};

use crate::editor::panel::curve_editor::param_row;
use crate::editor::panel::{drag, grid, multiplier, row_ui, vec3_ui};

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
            |ui| {
                ui.add(drag(
                    &mut f.buoyancy_m_per_s2,
                    -1000.0..=1000.0,
                    0.05,
                    " m/s²",
                ))
            },
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
            "Linear drag rate k, per second: the velocity relaxes toward the wind with time \
                constant 1/k",
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
            "Multiplies how far the particle moves each step over its life (1 = as its velocity \
                says)",
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
        gusts_ui,
    );
    module_ui(
        ui,
        "turbulence",
        "Turbulence",
        "Curl-noise turbulence (divergence-free swirls)",
        &mut f.turbulence,
        turbulence_ui,
    );
    module_ui(
        ui,
        "vortex",
        "Vortex",
        "Swirl around an axis through a point",
        &mut f.vortex,
        vortex_ui,
    );
    module_ui(
        ui,
        "attractor",
        "Attractor",
        "Point attractor (negative strength repels)",
        &mut f.attractor,
        attractor_ui,
    );
    module_ui(
        ui,
        "flame_pull",
        "Flame pull",
        "Pull toward the emitter axis, growing with age, so flames taper",
        &mut f.flame_pull,
        flame_pull_ui,
    );
}

/// The gusts' strength and frequency.
fn gusts_ui(ui: &mut Ui, g: &mut Gusts) {
    row_ui(ui, "Gust strength", "Fraction of the wind", |ui| {
        ui.add(drag(&mut g.strength, 0.0..=10.0, 0.01, "×"))
    });
    row_ui(ui, "Gust frequency", "How often gusts change, Hz", |ui| {
        ui.add(drag(&mut g.frequency_hz, 0.0..=100.0, 0.01, " Hz"))
    });
}

/// The turbulence's strength, frequency, octaves, scroll and curve over life.
fn turbulence_ui(ui: &mut Ui, t: &mut Turbulence) {
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
        |ui| ui.add(drag(&mut t.octaves, 1..=4, 0.05, "")),
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
}

/// The vortex's axis, swirl and radius.
fn vortex_ui(ui: &mut Ui, v: &mut Vortex) {
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
}

/// The attractor's position, strength, radius and falloff.
fn attractor_ui(ui: &mut Ui, a: &mut Attractor) {
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
}

/// The flame pull's strength, exponent and curve over life.
fn flame_pull_ui(ui: &mut Ui, p: &mut FlamePull) {
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
    module_ui(
        ui,
        "depth_collision",
        "Host's depth",
        "Collide with what the host's depth buffer shows (a game's world; here View → \
            Test scene): the response below applies",
        &mut col.depth_collision,
        |ui, d| {
            row_ui(
                ui,
                "Thickness",
                "How thick surfaces are taken to be: a particle further behind one than this \
                    is hidden by it and flies on, metres",
                |ui| ui.add(drag(&mut d.thickness_m, 0.0..=100.0, 0.005, " m")),
            );
            row_ui(
                ui,
                "Kill on contact",
                "Particles that touch the host's geometry die",
                |ui| ui.checkbox(&mut d.kill_on_contact, ""),
            );
        },
    );
    spheres_ui(ui, col);
    if col.any() || col.depth_collision.is_some() {
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

/// The sphere colliders: one row each (centre, radius, remove), then add, kill, stick.
fn spheres_ui(ui: &mut Ui, col: &mut Collisions) {
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
}
