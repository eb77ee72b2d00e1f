//! The editor's UI logic, driven through egui_kittest (no window, no GPU for the UI), and
//! the path from a widget to the GPU simulation (headless `GpuSim`).
// The editor, the `ignis` binary or the benches: the default `editor` feature.
#![cfg(feature = "editor")]

mod common;

use egui::{Key, Modifiers, Role};
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable as _;

use ignis::effect::Effect;
use ignis::testing::editor::EditorState;
use ignis::testing::editor::panel::panel_ui;
use ignis::testing::editor::panel::viewport::viewport_ui;
use ignis::testing::gpu::GpuContext;
use ignis::testing::gpu::types::Particle;
use ignis::testing::render::OrbitCamera;
use ignis::testing::shaders::ShaderLibrary;
use ignis::testing::sim::GpuSim;
use ignis::{Player, PlayerSettings};

/// The side panel over an editor state, as the window runs it (UI, then end of frame).
fn panel_harness(state: EditorState) -> Harness<'static, EditorState> {
    Harness::builder()
        .with_size(egui::vec2(440.0, 1800.0))
        .build_ui_state(
            |ui, state: &mut EditorState| {
                panel_ui(ui, state);
                state.end_frame(ui.ctx());
            },
            state,
        )
}

fn campfire_state() -> EditorState {
    EditorState::new(Effect::default_campfire(), "test")
}

/// Index of the emitter called `name` in the default campfire.
fn emitter_index(effect: &Effect, name: &str) -> usize {
    effect
        .emitters
        .iter()
        .position(|e| e.name == name)
        .unwrap_or_else(|| panic!("no emitter {name}"))
}

fn open_section(harness: &mut Harness<'_, EditorState>, title: &str) {
    harness.get_by_label_contains(title).click_accesskit();
    harness.run();
}

#[test]
fn a_widget_edits_the_effect_and_the_running_copy() {
    let mut harness = panel_harness(campfire_state());
    assert_eq!(harness.state().selected, 0);
    let before = harness.state().effect.emitters[0]
        .spawn_rate_per_sec
        .clone();
    // The smoke spawns from the flames' death events; its own rate (unused while it is
    // fed) is still a field the panel edits.
    assert_eq!(before, ignis::effect::Param::Constant(0.0));

    harness
        .get_by_label("Spawn rate")
        .set_value_accesskit(500.0);
    harness.run();

    let state = harness.state();
    assert_eq!(
        state.effect.emitters[0].spawn_rate_per_sec,
        ignis::effect::Param::Constant(500.0)
    );
    assert_eq!(
        state.running.emitters[0].spawn_rate_per_sec,
        ignis::effect::Param::Constant(500.0)
    );
    assert!(state.validation_errors.is_empty());
    assert_eq!(state.history.undo_len(), 1);
}

#[test]
fn undo_and_redo_restore_the_effect_with_the_keyboard() {
    let mut harness = panel_harness(campfire_state());
    let original = harness.state().effect.clone();
    harness
        .get_by_label("Spawn rate")
        .set_value_accesskit(500.0);
    harness.run();
    harness.get_by_label("Capacity").set_value_accesskit(4096.0);
    harness.run();
    assert_eq!(harness.state().history.undo_len(), 2);

    harness.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    harness.run();
    assert_eq!(harness.state().effect.emitters[0].capacity, 512);
    assert_eq!(
        harness.state().effect.emitters[0].spawn_rate_per_sec,
        ignis::effect::Param::Constant(500.0)
    );
    harness.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    harness.run();
    assert_eq!(harness.state().effect, original);
    assert_eq!(
        harness.state().running,
        original,
        "undo reaches the simulation"
    );

    harness.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
    harness.run();
    assert_eq!(
        harness.state().effect.emitters[0].spawn_rate_per_sec,
        ignis::effect::Param::Constant(500.0)
    );
    assert_eq!(harness.state().effect.emitters[0].capacity, 512);
    assert_eq!(harness.state().history.redo_len(), 1);
}

#[test]
fn one_drag_is_one_undo_step() {
    let mut harness = panel_harness(campfire_state());
    let original = harness.state().effect.clone();
    let rect = harness.get_by_label("Spawn rate").rect();
    let start = rect.center();
    harness.hover_at(start);
    harness.run();
    harness.drag_at(start);
    harness.run();
    for k in 1..=10 {
        harness.hover_at(start + egui::vec2(8.0 * k as f32, 0.0));
        harness.run();
        // Nothing is recorded while the button is down.
        assert_eq!(harness.state().history.undo_len(), 0);
    }
    harness.drop_at(start + egui::vec2(80.0, 0.0));
    harness.run();
    let rate = harness.state().effect.emitters[0]
        .spawn_rate_per_sec
        .clone();
    assert!(
        rate.bounds().0 > 90.0,
        "the drag changed the rate ({rate:?})"
    );
    assert_eq!(harness.state().history.undo_len(), 1, "one drag, one step");
    assert!(harness.state_mut().undo());
    harness.run();
    assert_eq!(harness.state().effect, original);
}

#[test]
fn an_invalid_effect_is_shown_and_the_last_valid_one_keeps_running() {
    let mut harness = panel_harness(campfire_state());
    // Each component is in range on its own; together they make a zero direction.
    for node in harness.get_all_by_label("Direction") {
        node.set_value_accesskit(0.0);
    }
    harness.run();
    let state = harness.state();
    assert_eq!(state.effect.emitters[0].direction, [0.0, 0.0, 0.0]);
    assert!(
        state
            .validation_errors
            .iter()
            .any(|e| e.path == "emitters[0].direction"),
        "{:?}",
        state.validation_errors
    );
    assert_eq!(state.running.emitters[0].direction, [0.0, 1.0, 0.0]);
    harness
        .get_by_label_contains("the last valid effect keeps running")
        .hover();

    // Fixing it applies it again.
    harness
        .get_all_by_label("Direction")
        .next()
        .expect("x")
        .set_value_accesskit(1.0);
    harness.run();
    assert!(harness.state().validation_errors.is_empty());
    assert_eq!(
        harness.state().running.emitters[0].direction,
        [1.0, 0.0, 0.0]
    );
}

#[test]
fn a_light_that_failed_to_build_is_named_in_the_panel() {
    let mut harness = panel_harness(campfire_state());
    assert!(
        harness
            .query_by_label_contains("light on the scene is off")
            .is_none()
    );
    harness.state_mut().light_error =
        Some("light.wgsl: expected `;`, found `}` (line 12)".to_string());
    harness.run();
    harness.get_by_label_contains("light on the scene is off");
    harness.get_by_label_contains("light.wgsl: expected");
    harness.state_mut().light_error = None;
    harness.run();
    assert!(
        harness
            .query_by_label_contains("light on the scene is off")
            .is_none()
    );
}

#[test]
fn widgets_clamp_out_of_range_values() {
    let mut harness = panel_harness(campfire_state());
    harness.get_by_label("Spread").set_value_accesskit(1.0e9);
    harness.run();
    harness.get_by_label("Spawn rate").set_value_accesskit(-5.0);
    harness.run();
    harness.get_by_label("Spread").set_value_accesskit(f64::NAN);
    harness.run();
    let state = harness.state();
    let e = &state.effect.emitters[0];
    assert_eq!(e.spawn_rate_per_sec, ignis::effect::Param::Constant(0.0));
    assert!(e.spread_deg.is_finite() && (0.0..=180.0).contains(&e.spread_deg));
    assert!(state.effect.validate().is_ok());
}

#[test]
fn new_seed_and_noise_are_bound_to_the_effect() {
    let mut harness = panel_harness(campfire_state());
    open_section(&mut harness, "Randomness");
    let seed = harness.state().effect.seed;
    harness.get_by_label("New seed").click_accesskit();
    harness.run();
    assert_ne!(harness.state().effect.seed, seed);
    assert_eq!(harness.state().running.seed, harness.state().effect.seed);
    harness
        .get_by_label("Scroll speed")
        .set_value_accesskit(4.0);
    harness.run();
    assert_eq!(
        harness.state().effect.emitters[0]
            .spawn_noise
            .scroll_per_sec,
        4.0
    );
}

#[test]
fn emitters_can_be_added_duplicated_reordered_and_removed() {
    let mut harness = panel_harness(campfire_state());
    harness.get_by_label("Duplicate").click_accesskit();
    harness.run();
    let names: Vec<String> = harness
        .state()
        .effect
        .emitters
        .iter()
        .map(|e| e.name.clone())
        .collect();
    assert_eq!(
        names,
        ["smoke", "smoke copy", "flames", "embers", "heat haze"]
    );
    assert_eq!(harness.state().selected, 1);
    assert!(harness.state().validation_errors.is_empty());

    harness.get_by_label("Down").click_accesskit();
    harness.run();
    assert_eq!(harness.state().effect.emitters[2].name, "smoke copy");
    assert_eq!(harness.state().selected, 2);

    harness.get_by_label("Solo").click_accesskit();
    harness.run();
    let enabled: Vec<bool> = harness
        .state()
        .effect
        .emitters
        .iter()
        .map(|e| e.enabled)
        .collect();
    assert_eq!(enabled, [false, false, true, false, false]);

    harness.get_by_label("Remove").click_accesskit();
    harness.run();
    assert_eq!(harness.state().effect.emitters.len(), 4);
    harness.get_by_label("All on").click_accesskit();
    harness.run();
    assert!(harness.state().effect.emitters.iter().all(|e| e.enabled));
    assert!(harness.state().effect.validate().is_ok());
}

#[test]
fn colour_stops_can_be_added_and_removed_and_stay_sorted() {
    let mut harness = panel_harness(campfire_state());
    open_section(&mut harness, "Look");
    let count = harness.state().effect.emitters[0]
        .look
        .color_over_life
        .len();
    harness.get_by_label("Add stop").click_accesskit();
    harness.run();
    let stops = &harness.state().effect.emitters[0].look.color_over_life;
    assert_eq!(stops.len(), count + 1);
    assert!(stops.windows(2).all(|w| w[0].t <= w[1].t));
    // A stop's t cannot pass its neighbour.
    harness
        .get_all_by_label("Stop 1")
        .next()
        .expect("t")
        .set_value_accesskit(0.99);
    harness.run();
    let stops = &harness.state().effect.emitters[0].look.color_over_life;
    assert!(stops[0].t <= stops[1].t);
    assert!(harness.state().validation_errors.is_empty());
    // The slider comes first, then its number field.
    harness
        .get_all_by_label("Exposure")
        .next()
        .expect("slider")
        .set_value_accesskit(2.0);
    harness.run();
    assert_eq!(harness.state().view.exposure, 2.0);
}

#[test]
fn time_settings_and_the_drag_stability_hint() {
    let mut harness = panel_harness(campfire_state());
    harness.get_by_label("Frame delta").click_accesskit();
    harness.run();
    assert_eq!(
        harness.state().effect.time.mode,
        ignis::effect::TimeMode::FrameDelta
    );
    harness.get_by_label("Sim speed").set_value_accesskit(0.5);
    harness.run();
    assert_eq!(harness.state().running.time.speed, 0.5);
    assert!(harness.query_by_label_contains("unstable").is_none());

    // k·dt = 300 /s × 0.1 s = 30, far past the Euler methods' limit of 2: the Time
    // section's row says so, and the header names the field and a stable step as the
    // edit is made.
    open_section(&mut harness, "Forces");
    harness.get_by_label("Drag").set_value_accesskit(300.0);
    harness.run();
    assert!(harness.query_by_label_contains("unstable: ×").is_some());
    let warnings = harness.state().effect.stability_warnings();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    let text = warnings[0].to_string();
    assert!(
        text.starts_with("emitters[0].forces.drag_per_sec: "),
        "{text}"
    );
    assert!(text.contains("a step of at most"), "{text}");
    assert!(
        harness.query_by_label(&text).is_some(),
        "the header shows {text}"
    );
    harness.get_by_label("Pause").click_accesskit();
    harness.run();
    assert!(harness.state().playback.is_paused);
}

#[test]
fn playback_keys_work_only_when_no_text_field_has_focus() {
    let mut harness = panel_harness(campfire_state());
    harness.key_press(Key::Space);
    harness.key_press(Key::Period);
    harness.key_press(Key::R);
    harness.key_press(Key::F);
    harness.run();
    let p = harness.state().playback.clone();
    assert!(p.is_paused && p.step_requested && p.restart_requested);
    assert!(harness.state().frame_requested);

    let mut harness = panel_harness(campfire_state());
    harness.get_by_label("Name").focus();
    harness.run();
    harness.key_press(Key::Space);
    harness.run();
    assert!(!harness.state().playback.is_paused);
}

// ---------------------------------------------------------------------------------------
// From a widget to the GPU.

struct Twin {
    edited: GpuSim,
    reference: GpuSim,
}

const DT_SECS: f32 = 1.0 / 120.0;

fn twin_sims(ctx: &GpuContext, effect: &Effect, steps: u32) -> Twin {
    let make = || {
        let mut sim = GpuSim::new(ctx, ShaderLibrary::discover(None), effect).expect("sim");
        sim.step(effect, DT_SECS, steps).expect("step");
        sim
    };
    Twin {
        edited: make(),
        reference: make(),
    }
}

fn alive(particles: &[Particle]) -> usize {
    particles.iter().filter(|p| p.is_alive()).count()
}

#[test]
fn a_panel_edit_reaches_the_gpu_on_the_next_step_without_a_reset() {
    let ctx = GpuContext::headless().expect("a GPU adapter (lavapipe is fine)");
    let state = campfire_state();
    let flames = emitter_index(&state.effect, "flames");
    let mut twin = twin_sims(&ctx, &state.running, 90);
    let before = twin.edited.read_particles(flames).expect("read");
    assert!(alive(&before) > 500);

    // Select the flames and set their buoyancy to 0 through the panel.
    let mut harness = panel_harness(state);
    harness
        .get_by_role_and_label(Role::Button, "flames")
        .click_accesskit();
    harness.run();
    open_section(&mut harness, "Forces");
    harness.get_by_label("Buoyancy").set_value_accesskit(0.0);
    harness.run();
    let state = harness.into_state();
    assert_eq!(state.running.emitters[flames].forces.buoyancy_m_per_s2, 0.0);
    let reference_effect = Effect::default_campfire();
    let buoyancy = reference_effect.emitters[flames].forces.buoyancy_m_per_s2;
    assert!(
        buoyancy > 5.0,
        "the campfire's flames rise ({buoyancy} m/s²)"
    );

    // The very next step uses it: particles alive before and after differ in vertical
    // velocity by exactly buoyancy × dt (same state, same drag, same step).
    twin.edited.step(&state.running, DT_SECS, 1).expect("step");
    twin.reference
        .step(&reference_effect, DT_SECS, 1)
        .expect("step");
    let edited = twin.edited.read_particles(flames).expect("read");
    let reference = twin.reference.read_particles(flames).expect("read");
    let mut dv = Vec::new();
    for ((b, e), r) in before.iter().zip(&edited).zip(&reference) {
        if b.is_alive() && e.is_alive() && r.is_alive() && e.pos_age[3] > b.pos_age[3] {
            dv.push(r.velocity().y - e.velocity().y);
        }
    }
    assert!(dv.len() > 500, "{} particles compared", dv.len());
    let expected = buoyancy * DT_SECS;
    for d in &dv {
        assert!((d - expected).abs() < 1e-3, "Δv_y {d}, expected {expected}");
    }
    // No reset: the particles that were alive are still there.
    assert!(alive(&edited) as f32 > 0.9 * alive(&before) as f32);

    // And the flame stops rising: lower mean height after half a second.
    twin.edited.step(&state.running, DT_SECS, 60).expect("step");
    twin.reference
        .step(&reference_effect, DT_SECS, 60)
        .expect("step");
    let mean_y = |ps: &[Particle]| {
        let alive: Vec<f32> = ps
            .iter()
            .filter(|p| p.is_alive())
            .map(|p| p.position().y)
            .collect();
        alive.iter().sum::<f32>() / alive.len().max(1) as f32
    };
    let (y_edited, y_reference) = (
        mean_y(&twin.edited.read_particles(flames).expect("read")),
        mean_y(&twin.reference.read_particles(flames).expect("read")),
    );
    assert!(
        y_edited + 0.1 < y_reference,
        "mean height {y_edited} m without buoyancy vs {y_reference} m with"
    );
}

#[test]
fn a_smaller_capacity_keeps_the_particles_that_fit() {
    let ctx = GpuContext::headless().expect("a GPU adapter (lavapipe is fine)");
    let state = campfire_state();
    let flames = emitter_index(&state.effect, "flames");
    let mut sim = GpuSim::new(&ctx, ShaderLibrary::discover(None), &state.running).expect("sim");
    sim.step(&state.running, DT_SECS, 90).expect("step");
    let before = sim.read_particles(flames).expect("read");

    let mut harness = panel_harness(state);
    harness
        .get_by_role_and_label(Role::Button, "flames")
        .click_accesskit();
    harness.run();
    harness.get_by_label("Capacity").set_value_accesskit(1024.0);
    harness.run();
    let state = harness.into_state();
    assert_eq!(state.running.emitters[flames].capacity, 1024);
    sim.sync(&state.running).expect("sync");
    let after = sim.read_particles(flames).expect("read");
    assert_eq!(after.len(), 1024);
    assert_eq!(&after[..], &before[..1024]);
}

#[test]
fn reordering_emitters_moves_their_particles_along() {
    let ctx = GpuContext::headless().expect("a GPU adapter (lavapipe is fine)");
    let mut state = campfire_state();
    // A rate of its own for the smoke: unused while the flames' events feed it, the rate
    // its copy (which no event names) spawns at.
    for effect in [&mut state.effect, &mut state.running] {
        effect.emitters[0].spawn_rate_per_sec = ignis::effect::Param::Constant(90.0);
    }
    // The editor's player: one instance with a simulation of its own.
    let settings = PlayerSettings {
        batch_instances: false,
        ..PlayerSettings::new(wgpu::TextureFormat::Rgba16Float)
    };
    let mut player =
        Player::new(&ctx.device, &ctx.queue, &state.running, settings).expect("player");
    let id = player
        .add_instance(glam::Mat4::IDENTITY, state.running.seed)
        .expect("instance");
    common::play_steps(&ctx, &mut player, 60);
    let smoke = player.particles(id, 0).expect("read");
    let flames = player.particles(id, 1).expect("read");
    let spawned = |p: &Player, e: usize| p.emitter_stats(id).expect("stats")[e].spawn.spawned;
    let spawned_smoke = spawned(&player, 0);

    // Move the smoke down one place, then duplicate the flames.
    let mut harness = panel_harness(state);
    harness.get_by_label("Down").click_accesskit();
    harness.run();
    harness.get_by_label("Duplicate").click_accesskit();
    harness.run();
    let state = harness.into_state();
    let names: Vec<&str> = state
        .running
        .emitters
        .iter()
        .map(|e| e.name.as_str())
        .collect();
    assert_eq!(
        names,
        ["flames", "smoke", "smoke copy", "embers", "heat haze"]
    );

    player.set_effect(&state.running).expect("the edit");
    assert_eq!(player.particles(id, 0).expect("read"), flames);
    assert_eq!(player.particles(id, 1).expect("read"), smoke);
    assert_eq!(alive(&player.particles(id, 2).expect("read")), 0);
    assert_eq!(spawned(&player, 1), spawned_smoke);
    common::play_steps(&ctx, &mut player, 30);
    assert!(
        alive(&player.particles(id, 2).expect("read")) > 0,
        "the copy spawns"
    );
}

#[test]
fn force_modules_and_colliders_are_switched_and_edited_in_the_panel() {
    let mut harness = panel_harness(campfire_state());
    open_section(&mut harness, "Forces");
    assert!(
        harness.state().effect.emitters[0]
            .forces
            .turbulence
            .is_none()
    );
    harness.get_by_label("Turbulence").click_accesskit();
    harness.run();
    assert!(
        harness.state().running.emitters[0]
            .forces
            .turbulence
            .is_some()
    );
    harness.get_by_label("Octaves").set_value_accesskit(9.0);
    harness.run();
    let t = harness.state().effect.emitters[0]
        .forces
        .turbulence
        .clone()
        .expect("on");
    assert_eq!(t.octaves, 4, "clamped to the 1..=4 the shader supports");

    harness.get_by_label("Add sphere").click_accesskit();
    harness.run();
    harness.get_by_label("Ground plane").click_accesskit();
    harness.run();
    let col = &harness.state().running.emitters[0].collisions;
    assert_eq!(col.spheres.len(), 1);
    assert!(col.ground.is_some());
    harness.get_by_label("Elasticity").set_value_accesskit(0.9);
    harness.run();
    assert_eq!(
        harness.state().running.emitters[0].collisions.elasticity,
        0.9
    );

    // The host's depth: on with its defaults, its thickness edited, then off.
    harness.get_by_label("Host's depth").click_accesskit();
    harness.run();
    harness.get_by_label("Thickness").set_value_accesskit(0.05);
    harness.run();
    let depth = &harness.state().running.emitters[0]
        .collisions
        .depth_collision;
    assert_eq!(depth.as_ref().map(|d| d.thickness_m), Some(0.05));
    harness.get_by_label("Host's depth").click_accesskit();
    harness.run();
    let col = &harness.state().running.emitters[0].collisions;
    assert!(col.depth_collision.is_none());

    harness.get_by_label("Turbulence").click_accesskit();
    harness.run();
    assert!(
        harness.state().running.emitters[0]
            .forces
            .turbulence
            .is_none()
    );
    assert!(harness.state().validation_errors.is_empty());
}

#[test]
fn an_effect_the_gpu_refused_is_not_offered_again_until_it_changes() {
    let mut state = campfire_state();
    let good = state.running.clone();
    state.effect.emitters[0].capacity = 4_000_000;
    assert!(state.apply());
    // The frame loop's sync failed (say, a device limit): back to the last good effect.
    state.reject_running(&good, "capacity over the device limit".into());
    assert_eq!(state.running, good);
    assert!(!state.apply(), "the same effect is not retried every frame");
    assert!(state.gpu_rejected.is_some());
    // Undoing to what runs clears the message.
    assert!(state.undo());
    assert!(!state.apply());
    assert!(state.gpu_rejected.is_none());
    state.effect.emitters[0].capacity = 8192;
    assert!(state.apply());
    assert!(state.gpu_rejected.is_none());
    assert_eq!(state.running.emitters[0].capacity, 8192);
}

// ---------------------------------------------------------------------------------------
// The viewport's camera input.

struct ViewportHarnessState {
    editor: EditorState,
    camera: OrbitCamera,
    size_px: (u32, u32),
}

fn viewport_harness() -> Harness<'static, ViewportHarnessState> {
    let editor = campfire_state();
    let camera = OrbitCamera::from_hint(&editor.effect.camera);
    Harness::builder()
        .with_size(egui::vec2(800.0, 450.0))
        // Frames 1/60 s apart, so two clicks can make a double-click (kittest's default
        // step is 0.25 s).
        .with_step_dt(1.0 / 60.0)
        .with_max_steps(120)
        .build_ui_state(
            |ui, s: &mut ViewportHarnessState| {
                let out = viewport_ui(ui, &mut s.camera, &mut s.editor, None);
                s.size_px = out.size_px;
                s.editor.end_frame(ui.ctx());
            },
            ViewportHarnessState {
                editor,
                camera,
                size_px: (0, 0),
            },
        )
}

fn drag(
    harness: &mut Harness<'_, ViewportHarnessState>,
    button: egui::PointerButton,
    modifiers: Modifiers,
) {
    let start = egui::pos2(400.0, 225.0);
    // As egui-winit reports held modifiers.
    harness.event(egui::Event::ModifiersChanged(modifiers));
    harness.hover_at(start);
    harness.run();
    harness.event(egui::Event::PointerButton {
        pos: start,
        button,
        pressed: true,
        modifiers,
    });
    harness.run();
    for k in 1..=5 {
        harness.hover_at(start + egui::vec2(10.0 * k as f32, 6.0 * k as f32));
        harness.run();
    }
    harness.event(egui::Event::PointerButton {
        pos: start + egui::vec2(50.0, 30.0),
        button,
        pressed: false,
        modifiers,
    });
    harness.run();
    harness.event(egui::Event::ModifiersChanged(Modifiers::NONE));
    harness.run();
}

/// View ▸ Inspect in the viewport: hovering reports where the pointer is, a click asks to
/// pin the particle under it, and the player picks (as the editor's frame does) a campfire
/// particle that lies under that pointer.
#[test]
fn inspect_follows_the_pointer_and_a_click_pins_the_particle_under_it() {
    let mut harness = viewport_harness();
    harness.state_mut().editor.view.inspect = true;
    harness.run();
    let (w, h) = harness.state().size_px;
    let at = egui::pos2(400.0, 300.0);
    harness.hover_at(at);
    harness.run();
    let p = harness.state().editor.inspect.pointer.expect("the pointer");
    let expected = [(at.x - 8.0) / w as f32, (at.y - 8.0) / h as f32];
    assert!(
        (p[0] - expected[0]).abs() < 1e-3 && (p[1] - expected[1]).abs() < 1e-3,
        "pointer {p:?}, expected {expected:?}"
    );
    assert!(!harness.state().editor.inspect.pin_requested);
    for pressed in [true, false] {
        harness.event(egui::Event::PointerButton {
            pos: at,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: Modifiers::NONE,
        });
        harness.run();
    }
    assert!(harness.state().editor.inspect.pin_requested, "a click pins");
    // The player's pick at that pointer, with the viewport's camera.
    let ctx = ignis::testing::gpu::GpuContext::headless().expect("an adapter");
    let effect = harness.state().editor.running.clone();
    let mut run = ignis::testing::headless::Headless::new(&ctx, effect, ShaderLibrary::embedded())
        .expect("headless");
    for _ in 0..60 {
        run.advance(1.0 / 60.0);
    }
    run.render((w, h)).expect("render");
    let view = harness.state().camera.view((w, h));
    let pixel = glam::Vec2::new(p[0] * w as f32, p[1] * h as f32);
    let info = run
        .player
        .pick_particle(run.instance, &view, pixel, 8.0)
        .expect("pick")
        .expect("a particle under the pointer");
    let clip = view.clip_from_world_mat4() * info.position_m.extend(1.0);
    let ndc = clip.truncate() / clip.w;
    let px = glam::Vec2::new(
        (ndc.x * 0.5 + 0.5) * w as f32,
        (0.5 - ndc.y * 0.5) * h as f32,
    );
    assert!(
        px.distance(pixel) <= 8.5,
        "picked at {px}, pointer at {pixel}"
    );
    assert!(info.age_secs <= info.lifetime_secs, "{info:?}");
}

#[test]
fn the_viewport_orbits_pans_zooms_and_frames() {
    let mut harness = viewport_harness();
    harness.run();
    // The render target follows the viewport's size (render scale 1 here; the harness
    // keeps an 8-point margin).
    assert_eq!(harness.state().size_px, (784, 434));
    let start = harness.state().camera.clone();

    drag(&mut harness, egui::PointerButton::Primary, Modifiers::NONE);
    let orbited = harness.state().camera.clone();
    assert_ne!(orbited.yaw, start.yaw, "drag orbits");
    assert_ne!(orbited.pitch, start.pitch);
    assert_eq!(orbited.target, start.target);

    drag(&mut harness, egui::PointerButton::Middle, Modifiers::NONE);
    let panned = harness.state().camera.clone();
    assert_ne!(panned.target, orbited.target, "middle-drag pans");
    assert_eq!(panned.yaw, orbited.yaw);

    drag(&mut harness, egui::PointerButton::Primary, Modifiers::SHIFT);
    let shift_panned = harness.state().camera.clone();
    assert_ne!(shift_panned.target, panned.target, "shift-drag pans");
    assert_eq!(shift_panned.yaw, panned.yaw);

    harness.hover_at(egui::pos2(400.0, 225.0));
    harness.event(egui::Event::MouseWheel {
        unit: egui::MouseWheelUnit::Line,
        delta: egui::vec2(0.0, 3.0),
        phase: egui::TouchPhase::Move,
        source: egui::MouseWheelSource::Unknown,
        modifiers: Modifiers::NONE,
    });
    harness.run();
    assert!(
        harness.state().camera.distance < shift_panned.distance,
        "scrolling up zooms in"
    );
    // Nothing here touched the effect.
    assert_eq!(harness.state().editor.history.undo_len(), 0);

    let center = egui::pos2(400.0, 225.0);
    harness.hover_at(center);
    harness.run();
    for _ in 0..2 {
        for pressed in [true, false] {
            harness.event(egui::Event::PointerButton {
                pos: center,
                button: egui::PointerButton::Primary,
                pressed,
                modifiers: Modifiers::NONE,
            });
            harness.step();
        }
    }
    harness.run();
    assert!(
        harness.state().editor.frame_requested,
        "double-click frames"
    );
}

#[test]
fn stateless_mode_is_offered_and_its_blockers_are_named() {
    let mut harness = panel_harness(campfire_state());
    harness.get_by_label("Stateless").click_accesskit();
    harness.run();
    assert!(harness.state().running.emitters[0].stateless);
    assert!(harness.query_by_label_contains("turn off:").is_none());

    // Turbulence needs per-step state: the panel says so and validation refuses it.
    open_section(&mut harness, "Forces");
    harness.get_by_label("Turbulence").click_accesskit();
    harness.run();
    // Named next to the checkbox and in the validation message.
    assert_eq!(
        harness
            .query_all_by_label_contains("turn off: turbulence")
            .count(),
        2
    );
    assert!(!harness.state().validation_errors.is_empty());
    assert!(
        harness.state().running.emitters[0]
            .forces
            .turbulence
            .is_none()
    );
}

#[test]
fn presets_are_saved_and_loaded_from_the_header() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("my_fire.ron");
    let mut harness = panel_harness(campfire_state());
    harness
        .get_by_label("Spawn rate")
        .set_value_accesskit(321.0);
    harness.run();
    harness.state_mut().preset_path = path.display().to_string();
    harness.get_by_label("Save").click_accesskit();
    harness.run();
    assert!(
        matches!(harness.state().preset_message, Some(Ok(_))),
        "{:?}",
        harness.state().preset_message
    );
    let saved = ignis::preset::load(&path).expect("a valid preset on disk");
    assert_eq!(saved, harness.state().effect);

    // Change it, then load the file back: one undo step, and the running effect follows.
    harness.get_by_label("Spawn rate").set_value_accesskit(7.0);
    harness.run();
    let undo_before = harness.state().history.undo_len();
    harness.get_by_label("Load").click_accesskit();
    harness.run();
    // Unsaved edits: the load asks first.
    assert_eq!(
        harness.state().effect.emitters[0].spawn_rate_per_sec,
        ignis::effect::Param::Constant(7.0)
    );
    harness.get_by_label("Discard edits").click_accesskit();
    harness.run();
    assert_eq!(
        harness.state().effect.emitters[0].spawn_rate_per_sec,
        ignis::effect::Param::Constant(321.0)
    );
    assert_eq!(
        harness.state().running.emitters[0].spawn_rate_per_sec,
        ignis::effect::Param::Constant(321.0)
    );
    assert_eq!(harness.state().history.undo_len(), undo_before + 1);

    // A missing file is reported, not fatal.
    harness.state_mut().preset_path = dir.path().join("nope.ron").display().to_string();
    harness.get_by_label("Load").click_accesskit();
    harness.run();
    assert!(matches!(harness.state().preset_message, Some(Err(_))));
    assert_eq!(
        harness.state().effect.emitters[0].spawn_rate_per_sec,
        ignis::effect::Param::Constant(321.0)
    );
}

#[test]
fn the_library_opens_the_shipped_presets() {
    let mut harness = panel_harness(campfire_state());
    harness.state_mut().preset_path = "presets/campfire.ron".into();
    harness.run();
    harness.get_by_label("Library").click_accesskit();
    harness.run();
    harness
        .get_by_role_and_label(Role::Button, "torch")
        .click_accesskit();
    harness.run();
    let state = harness.state();
    assert!(
        state.preset_path.ends_with("torch.ron"),
        "{}",
        state.preset_path
    );
    let torch = ignis::preset::load(std::path::Path::new("presets/torch.ron")).expect("torch");
    assert_eq!(state.effect, torch);
    assert_eq!(state.running, torch);
}

/// The preset workflow: a dirty marker after an edit, Revert back to the saved effect,
/// Save-as name validation, a confirm before a load discards edits, and an external edit
/// of the loaded preset re-applied (or held for confirmation while there are edits).
#[test]
fn preset_workflow_dirty_revert_confirm_and_external_reload() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("fire.ron");
    let mut state = campfire_state();
    assert!(!state.is_dirty());

    // Save-as validation.
    state.preset_path = dir.path().join("bad name!.ron").display().to_string();
    state.save_preset();
    assert!(matches!(&state.preset_message, Some(Err(m)) if m.contains("letters, digits")));
    state.preset_path = dir.path().join("fire.txt").display().to_string();
    state.save_preset();
    assert!(matches!(&state.preset_message, Some(Err(m)) if m.contains(".ron")));

    // Edit → dirty → save → clean.
    state.effect.seed = 77;
    assert!(state.is_dirty());
    state.preset_path = path.display().to_string();
    state.save_preset();
    assert!(
        matches!(&state.preset_message, Some(Ok(_))),
        "{:?}",
        state.preset_message
    );
    assert!(!state.is_dirty());
    assert_eq!(state.loaded_path.as_deref(), Some(path.as_path()));

    // Edit → revert.
    state.effect.seed = 78;
    state.revert();
    assert_eq!(state.effect.seed, 77);
    assert!(!state.is_dirty());

    // A load with unsaved edits asks first; "keep editing" keeps them.
    state.effect.seed = 79;
    state.request_load();
    assert_eq!(
        state.pending,
        Some(ignis::testing::editor::state::PendingAction::Load)
    );
    assert_eq!(state.effect.seed, 79);
    state.pending = None;

    // External edit while clean: re-applied at once.
    state.revert();
    let mut on_disk = state.effect.clone();
    on_disk.seed = 1234;
    ignis::preset::save(&on_disk, &path).expect("external save");
    state.preset_changed_on_disk();
    assert_eq!(state.effect.seed, 1234);
    assert!(!state.is_dirty());

    // External edit while dirty: held until confirmed.
    state.effect.seed = 5;
    on_disk.seed = 4321;
    ignis::preset::save(&on_disk, &path).expect("external save");
    state.preset_changed_on_disk();
    assert_eq!(
        state.pending,
        Some(ignis::testing::editor::state::PendingAction::ExternalReload)
    );
    assert_eq!(state.effect.seed, 5);
    state.confirm_pending();
    assert_eq!(state.effect.seed, 4321);

    // A broken external edit loses nothing: an error, the effect stays.
    std::fs::write(&path, "(version: 1, emitters: [").expect("write");
    state.preset_changed_on_disk();
    assert_eq!(state.effect.seed, 4321);
    assert!(matches!(&state.preset_message, Some(Err(m)) if m.contains("fire.ron")));
}

/// The mouse collider: with the toggle on, hovering the viewport puts a sphere under the
/// pointer (on the plane through the orbit target facing the camera); the simulated copy of
/// the effect gets it, the edited effect does not; off, nothing.
#[test]
fn mouse_collider_follows_the_pointer() {
    let mut harness = viewport_harness();
    harness.hover_at(egui::pos2(400.0, 225.0));
    harness.run();
    assert_eq!(harness.state().editor.mouse_point, None, "off by default");
    harness.state_mut().editor.view.mouse_collider = true;
    harness.hover_at(egui::pos2(400.0, 225.0));
    harness.run();
    let centre = harness
        .state()
        .editor
        .mouse_point
        .expect("a point under the pointer");
    // The viewport's centre looks at the orbit target.
    assert!(
        (centre - harness.state().camera.target).length() < 0.05,
        "{centre}"
    );
    harness.hover_at(egui::pos2(600.0, 225.0));
    harness.run();
    let right = harness.state().editor.mouse_point.expect("point");
    assert!(right.x > centre.x + 0.2, "{right} vs {centre}");
    let state = &harness.state().editor;
    let simulated =
        ignis::testing::editor::state::with_mouse_collider(&state.effect, state.mouse_point);
    for (e, s) in state.effect.emitters.iter().zip(&simulated.emitters) {
        assert_eq!(s.collisions.spheres.len(), e.collisions.spheres.len() + 1);
        assert_eq!(
            s.collisions.spheres.last().expect("sphere").center_m,
            right.to_array()
        );
    }
    assert!(
        state
            .effect
            .emitters
            .iter()
            .all(|e| e.collisions.spheres.is_empty())
    );
}

/// Ctrl+drag in the viewport moves the selected emitter's sphere collider with the pointer
/// (rightwards drag → +x for the default camera), and the camera does not orbit.
#[test]
fn ctrl_drag_moves_a_sphere_collider() {
    let mut harness = viewport_harness();
    let before_camera = harness.state().camera.clone();
    {
        let s = &mut harness.state_mut().editor;
        let target = s.effect.camera.target_m;
        s.effect.emitters[s.selected].collisions.spheres = vec![ignis::effect::SphereCollider {
            center_m: target,
            radius_m: 0.2,
        }];
    }
    let start_x = harness.state().editor.effect.emitters[harness.state().editor.selected]
        .collisions
        .spheres[0]
        .center_m[0];
    drag(
        &mut harness,
        egui::PointerButton::Primary,
        Modifiers::COMMAND,
    );
    let s = &harness.state().editor;
    let moved = s.effect.emitters[s.selected].collisions.spheres[0].center_m;
    assert!(
        moved[0] > start_x + 0.1,
        "collider did not follow the drag: {moved:?}"
    );
    assert_eq!(harness.state().camera, before_camera, "the camera orbited");
}

#[test]
fn look_controls_toggle_flipbook_streak_bloom_and_the_gradient_bar_adds_stops() {
    let mut harness = panel_harness(campfire_state());
    open_section(&mut harness, "Look");
    let stops = harness.state().effect.emitters[0]
        .look
        .color_over_life
        .clone();
    // A click in the middle of the bar inserts a stop there, coloured as the gradient.
    harness
        .get_by_label("Gradient (click to add a stop)")
        .click();
    harness.run();
    let after = &harness.state().effect.emitters[0].look.color_over_life;
    assert_eq!(after.len(), stops.len() + 1);
    assert!(after.windows(2).all(|w| w[0].t <= w[1].t));
    let added = after
        .iter()
        .find(|s| !stops.contains(s))
        .expect("a new stop");
    assert!((added.t - 0.5).abs() < 0.05, "added at {}", added.t);
    let want = ignis::testing::render::look_bake::sample_gradient(&stops, added.t);
    for (got, want) in added.rgba.iter().zip(want) {
        assert!((got - want).abs() < 1e-5);
    }

    // Smoke (emitter 0) has no flipbook, streak or bloom yet.
    assert!(harness.state().effect.emitters[0].look.flipbook.is_none());
    harness.get_by_label("animate").click_accesskit();
    harness.run();
    assert!(harness.state().effect.emitters[0].look.flipbook.is_some());
    harness.get_by_label("stretch").click_accesskit();
    harness.run();
    assert!(harness.state().effect.emitters[0].look.streak.is_some());
    let had_bloom = harness.state().effect.post.bloom.is_some();
    harness.get_by_label("glow").click_accesskit();
    harness.run();
    assert_eq!(harness.state().effect.post.bloom.is_some(), !had_bloom);
    assert!(harness.state().validation_errors.is_empty());
    assert!(harness.state().effect.validate().is_ok());
}

#[test]
fn state_sizes_are_offered_and_exclude_stateless() {
    let mut harness = panel_harness(campfire_state());
    harness.get_by_label("20 B packed").click_accesskit();
    harness.run();
    let e = &harness.state().effect.emitters[0];
    assert!(e.packed_state && !e.tiny_state && !e.stateless);
    harness.get_by_label("10 B tiny").click_accesskit();
    harness.run();
    let e = &harness.state().effect.emitters[0];
    assert!(e.tiny_state && !e.packed_state, "one layout at a time");
    assert!(harness.state().effect.validate().is_ok());
    harness.get_by_label("Stateless").click_accesskit();
    harness.run();
    let e = &harness.state().effect.emitters[0];
    assert!(
        e.stateless && !e.packed_state && !e.tiny_state,
        "turning stateless on turns the compact layouts off"
    );
    harness.get_by_label("32 B").click_accesskit();
    harness.run();
    assert!(harness.state().effect.validate().is_ok());
}

/// Merely showing the Look section edits nothing (a colour with alpha 0 used to lose its
/// RGB in egui's colour button round trip, marking the preset unsaved).
#[test]
fn opening_the_look_section_edits_nothing() {
    for (i, name) in ["smoke", "flames", "embers"].iter().enumerate() {
        let mut state = campfire_state();
        state.selected = emitter_index(&state.effect, name);
        state.open_sections = Some(vec!["look".to_owned()]);
        let before = state.effect.clone();
        let mut harness = panel_harness(state);
        harness.run();
        harness.run();
        let after = &harness.state().effect;
        assert_eq!(
            after.emitters[i].look, before.emitters[i].look,
            "{name}: showing the Look section changed the look (egui colour round trip)"
        );
        assert_eq!(
            *after, before,
            "{name}: showing the Look section changed the effect"
        );
    }
}

/// One UI frame for the retained-image test: a side panel showing `panel_text` and a
/// central area whose content moves with `n`. Returns egui's output and the central
/// rectangle.
fn retained_test_frame(
    egui_ctx: &egui::Context,
    n: u32,
    panel_text: &str,
) -> (egui::FullOutput, egui::Rect) {
    let raw = egui::RawInput {
        screen_rect: Some(egui::Rect::from_min_size(
            egui::Pos2::ZERO,
            egui::vec2(480.0, 270.0),
        )),
        ..Default::default()
    };
    let mut live = egui::Rect::NOTHING;
    let out = egui_ctx.run_ui(raw, |ui| {
        egui::Panel::right("panel").show(ui, |ui| {
            ui.label(panel_text);
            let _ = ui.button("A button");
        });
        egui::CentralPanel::no_frame().show(ui, |ui| {
            let (rect, _) = ui.allocate_exact_size(ui.available_size(), egui::Sense::hover());
            live = rect;
            let p = ui.painter_at(rect);
            let c = rect.min + egui::vec2(30.0 + 17.0 * n as f32, 40.0 + 9.0 * n as f32);
            p.circle_filled(c, 25.0, egui::Color32::from_rgb(240, 120, 30));
            // Fixed text: new glyphs (or sub-pixel variants) would change egui's atlas.
            p.text(
                rect.min + egui::vec2(8.0, 8.0),
                egui::Align2::LEFT_TOP,
                "viewport",
                egui::FontId::monospace(12.0),
                egui::Color32::WHITE,
            );
        });
    });
    (out, live)
}

/// The retained window image (software adapters): repainting only the viewport over
/// last frame's image gives exactly the pixels of a full repaint, and a panel change
/// (or the first frame) repaints in full.
#[test]
fn retained_ui_repaints_match_full_repaints() {
    use ignis::testing::editor::window::retained::{Repaint, RetainedUi};
    use ignis::testing::editor::window::screenshot::{Screenshot, read_back};
    use ignis::testing::editor::window::ui_painter::UiPainter;

    let ctx = GpuContext::headless().expect("a GPU adapter (lavapipe is fine)");
    let format = wgpu::TextureFormat::Rgba8Unorm;
    let mut painter = UiPainter::new(&ctx.device, format, true);
    let egui_ctx = egui::Context::default();
    let background = egui::Color32::from_rgb(9, 9, 11);
    let clear = wgpu::Color {
        r: 9.0 / 255.0,
        g: 9.0 / 255.0,
        b: 11.0 / 255.0,
        a: 1.0,
    };
    let full_target = ignis::testing::gpu::texture_2d(
        &ctx.device,
        "test::full",
        (480, 270),
        1,
        format,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
    );
    let mut retained = RetainedUi::default();
    let paint =
        |painter: &mut UiPainter, target: &wgpu::Texture, jobs: &[egui::ClippedPrimitive], load| {
            let screen = egui_wgpu::ScreenDescriptor {
                size_in_pixels: [480, 270],
                pixels_per_point: 1.0,
            };
            let mut enc = ctx.device.create_command_encoder(&Default::default());
            let extra = painter.prepare(&ctx.device, &ctx.queue, &mut enc, jobs, &screen);
            let view = target.create_view(&Default::default());
            painter.paint(&mut enc, &view, jobs, &screen, load);
            let shot = Screenshot::record(
                &ctx,
                &mut enc,
                target,
                std::env::temp_dir().join("unused.png"),
            );
            ctx.queue.submit(extra.into_iter().chain([enc.finish()]));
            read_back(&ctx, shot).expect("reading the image back")
        };
    let frames = [
        (0, "Panel A"),
        (1, "Panel A"),
        (2, "Panel A"),
        (3, "Panel B"),
        (4, "Panel B"),
    ];
    let mut kinds = Vec::new();
    for (n, text) in frames {
        let (out, live) = retained_test_frame(&egui_ctx, n, text);
        for (id, deltas) in &out.textures_delta.set {
            for delta in deltas {
                painter.update_texture(&ctx.device, &ctx.queue, *id, delta);
            }
        }
        let changed = !out.textures_delta.set.is_empty() || !out.textures_delta.free.is_empty();
        let jobs = egui_ctx.tessellate(out.shapes, 1.0);
        let image = retained
            .image(&ctx.device, (480, 270), format)
            .texture
            .clone();
        let plan = retained.plan(&jobs, live, [480, 270], changed, background, None);
        let got = match &plan {
            Repaint::Full => paint(&mut painter, &image, &jobs, wgpu::LoadOp::Clear(clear)),
            Repaint::Live(live_jobs) => paint(&mut painter, &image, live_jobs, wgpu::LoadOp::Load),
        };
        kinds.push(matches!(plan, Repaint::Live(_)));
        let want = paint(
            &mut painter,
            &full_target,
            &jobs,
            wgpu::LoadOp::Clear(clear),
        );
        let differing = got
            .pixels()
            .zip(want.pixels())
            .filter(|(a, b)| a != b)
            .count();
        assert_eq!(
            differing, 0,
            "frame {n}: the retained image differs from a full repaint in {differing} pixels"
        );
    }
    // The first frames repaint in full (egui sizes the panel, fills its font atlas); then
    // only the panel text change (frame 3) does.
    assert_eq!(kinds, [false, false, true, false, true]);
}

/// Steps the export the panel asks for, with the panel drawn between steps, until it
/// ends; returns whether the Cancel button and a progress bar showed while it ran.
fn run_export(harness: &mut Harness<'_, EditorState>, ctx: &GpuContext) -> (bool, u32) {
    let mut running = None;
    let (mut saw_cancel, mut frames) = (false, 0);
    loop {
        {
            let state = harness.state_mut();
            let effect = state.running.clone();
            ignis::testing::editor::panel::export_ui::drive(
                ctx,
                &effect,
                None,
                &mut state.export,
                &mut running,
                std::time::Duration::from_millis(1),
            );
        }
        // The panel asks for frames while an export runs: one step each.
        harness.step();
        frames += 1;
        if running.is_none() {
            return (saw_cancel, frames);
        }
        saw_cancel |= harness.query_by_label("Cancel").is_some();
    }
}

/// The Export section exports the running effect with its settings through the same
/// code as `ignis export`: a progress bar and Cancel while it runs, the files and a
/// preview of the atlas after; Cancel drops an export and writes nothing.
#[test]
fn the_export_section_exports_with_progress_and_cancels() {
    let ctx = common::gpu();
    let dir = tempfile::tempdir().expect("tempdir");
    let mut state = campfire_state();
    state.export.out_dir = dir.path().join("book").display().to_string();
    state.export.cols = 2;
    state.export.rows = 2;
    state.export.settings.frame_size = (32, 32);
    let mut harness = panel_harness(state);
    open_section(&mut harness, "Export");
    harness.get_by_label("Start export").click_accesskit();
    harness.run();
    assert!(harness.state().export.start_requested);
    let (saw_cancel, frames) = run_export(&mut harness, &ctx);
    assert!(
        saw_cancel && frames > 3,
        "no progress shown ({frames} frames)"
    );
    let message = harness.state().export.message.clone();
    assert!(
        matches!(&message, Some(Ok(m)) if m.contains("wrote 2 files")),
        "{message:?}"
    );
    let atlas = image::open(dir.path().join("book/campfire_color.png")).expect("atlas");
    assert_eq!((atlas.width(), atlas.height()), (64, 64));
    assert!(dir.path().join("book/campfire.json").exists());
    assert!(
        harness.query_by_role(Role::Image).is_some(),
        "no preview of the atlas"
    );

    // A sequence cancelled after its first step leaves no file behind.
    let seq = dir.path().join("seq");
    harness.state_mut().export.sequence = true;
    harness.state_mut().export.out_dir = seq.display().to_string();
    harness.get_by_label("Start export").click_accesskit();
    harness.step();
    let mut running = None;
    let state = harness.state_mut();
    let effect = state.running.clone();
    let step = |state: &mut EditorState, running: &mut Option<_>| {
        ignis::testing::editor::panel::export_ui::drive(
            &ctx,
            &effect,
            None,
            &mut state.export,
            running,
            std::time::Duration::from_millis(1),
        )
    };
    for _ in 0..150 {
        step(state, &mut running);
    }
    assert!(
        running.is_some(),
        "the export ended before it was cancelled"
    );
    state.export.cancel_requested = true;
    step(state, &mut running);
    assert!(running.is_none());
    let message = state.export.message.clone();
    assert!(
        matches!(&message, Some(Err(m)) if m.contains("cancelled")),
        "{message:?}"
    );
    let left: Vec<_> = std::fs::read_dir(&seq)
        .map(|d| d.flatten().map(|e| e.file_name()).collect())
        .unwrap_or_default();
    assert!(left.is_empty(), "a cancelled export left {left:?}");
}

/// The timeline: a click on the bar asks for a seek to that time (in whole steps of the
/// effect's clock), the step back to one step before the current time; a restart clears.
#[test]
fn the_timeline_seeks_in_whole_steps() {
    use ignis::testing::editor::panel::timeline::{span_secs, timeline_ui};
    let mut state = campfire_state();
    state.stats.sim_time_secs = 1.0;
    let mut harness = Harness::builder()
        .with_size(egui::vec2(900.0, 40.0))
        .build_ui_state(|ui, state: &mut EditorState| timeline_ui(ui, state), state);
    harness.run();
    let bar = harness.get_by_label("Timeline").rect();
    harness.state_mut().playback.seek_to = None;
    let at = bar.left_center() + egui::vec2(bar.width() * 0.5, 0.0);
    harness.hover_at(at);
    harness.run();
    harness.drag_at(at);
    harness.run();
    harness.drop_at(at);
    harness.run();
    let step = f64::from(harness.state().running.time.step_secs);
    let span = span_secs(&harness.state().running);
    let t = harness.state().playback.seek_to.expect("a seek");
    assert!(
        (t - span / 2.0).abs() < span / 50.0,
        "seek to {t}, span {span}"
    );
    assert!(
        ((t / step) - (t / step).round()).abs() < 1e-6,
        "{t} is a whole step"
    );
    harness.state_mut().playback.seek_to = None;
    harness.get_by_label("Step back").click();
    harness.run();
    let back = harness.state().playback.seek_to.expect("a step back");
    assert!((back - (1.0 - step)).abs() < 1e-9, "{back}");
    // The loop region starts as the whole span.
    harness.get_by_label("Loop").click();
    harness.run();
    assert_eq!(harness.state().playback.loop_region, Some((0.0, span)));
}

/// The size curve editor: dragging a key moves it (one undo step; the running effect
/// follows), a click away from the keys adds one where it is, a right-click deletes one.
#[test]
fn the_curve_editor_drags_adds_and_deletes_keys() {
    use ignis::effect::Param;
    use ignis::testing::editor::panel::curve_editor::{View, plot_area};
    let mut harness = panel_harness(campfire_state());
    open_section(&mut harness, "Look");
    // Let the section's opening animation settle: the plot must stay where it is found.
    for _ in 0..30 {
        harness.run();
    }
    let size = |h: &Harness<'_, EditorState>| h.state().effect.emitters[0].look.size_m.clone();
    let before = size(&harness);
    let Param::TwoCurves { a, .. } = &before else {
        panic!("the campfire smoke's size is two curves: {before:?}");
    };
    let rect = plot_area(harness.get_by_label("Size curve").rect());
    let view = View::fit(&before, &ignis::testing::editor::panel::look_ui::SIZE);
    // Row a's last key, (1.0, 0.91): drag it down by 20 points.
    let key = a.keys[1];
    let start = view.to_screen(rect, key);
    harness.hover_at(start);
    harness.run();
    harness.drag_at(start);
    harness.run();
    for k in 1..=4 {
        harness.hover_at(start + egui::vec2(-3.0 * k as f32, 5.0 * k as f32));
        harness.run();
    }
    harness.drop_at(start + egui::vec2(-12.0, 20.0));
    harness.run();
    let after = size(&harness);
    let Param::TwoCurves { a: moved, b } = &after else {
        panic!("still two curves: {after:?}");
    };
    let want = view.from_screen(rect, start + egui::vec2(-12.0, 20.0));
    assert!(
        (moved.keys[1].1 - want.1).abs() < 1e-3,
        "{:?} vs {want:?}",
        moved.keys[1]
    );
    assert!(
        (moved.keys[1].0 - want.0).abs() < 1e-3,
        "{:?} vs {want:?}",
        moved.keys[1]
    );
    assert!(
        moved.keys[1].1 < key.1 - 0.05,
        "the key moved down: {:?}",
        moved.keys[1]
    );
    assert_eq!(moved.keys[0], a.keys[0], "the other key stays");
    assert_eq!(b, &before.rows()[1], "the other curve stays");
    assert_eq!(harness.state().running.emitters[0].look.size_m, after);
    assert_eq!(harness.state().history.undo_len(), 1, "one drag, one step");

    // A click in the middle, away from the keys, adds a key to the nearer curve there.
    let rect = plot_area(harness.get_by_label("Size curve").rect());
    let view = View::fit(&after, &ignis::testing::editor::panel::look_ui::SIZE);
    let mid = view.to_screen(rect, (0.5, moved.eval(0.5) as f32));
    harness.hover_at(mid);
    harness.run();
    for pressed in [true, false] {
        harness.event(egui::Event::PointerButton {
            pos: mid,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: Modifiers::NONE,
        });
        harness.run();
    }
    let added = size(&harness).rows()[0].clone();
    assert_eq!(added.keys.len(), 3, "{added:?}");
    assert!((added.keys[1].0 - 0.5).abs() < 0.02, "{added:?}");

    // A right-click on it deletes it again.
    for pressed in [true, false] {
        harness.event(egui::Event::PointerButton {
            pos: mid,
            button: egui::PointerButton::Secondary,
            pressed,
            modifiers: Modifiers::NONE,
        });
        harness.run();
    }
    assert_eq!(size(&harness).rows()[0].keys.len(), 2);
    assert!(harness.state().validation_errors.is_empty());
}

/// The Events section: an event added to the embers (its first choice of child is the
/// smoke), its chance edited live, undone with the keyboard; an event that would close a
/// cycle (smoke → flames, whose deaths feed the smoke) is refused by validation while the
/// last valid effect keeps running.
#[test]
fn events_are_added_edited_validated_and_undone_in_the_panel() {
    let mut state = campfire_state();
    let embers = emitter_index(&state.effect, "embers");
    state.selected = embers;
    state.open_sections = Some(vec!["events".to_owned()]);
    let mut harness = panel_harness(state);
    harness.run();
    harness.get_by_label("Add event").click_accesskit();
    harness.run();
    let events = &harness.state().effect.emitters[embers].events;
    assert_eq!(events.len(), 1);
    assert_eq!(events[0].emitter, "smoke");
    assert_eq!(events[0].trigger, ignis::effect::Trigger::Death);
    harness.get_by_label("Chance").set_value_accesskit(0.25);
    harness.run();
    let s = harness.state();
    assert_eq!(s.effect.emitters[embers].events[0].probability, 0.25);
    assert_eq!(s.running.emitters[embers].events[0].probability, 0.25);
    assert!(s.validation_errors.is_empty(), "{:?}", s.validation_errors);
    assert_eq!(s.running.event_sources(0), [(1, 0), (embers, 0)]);
    harness.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    harness.run();
    harness.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    harness.run();
    assert!(harness.state().effect.emitters[embers].events.is_empty());

    let mut state = campfire_state();
    state.selected = emitter_index(&state.effect, "smoke");
    state.open_sections = Some(vec!["events".to_owned()]);
    let mut harness = panel_harness(state);
    harness.run();
    harness.get_by_label("Add event").click_accesskit();
    harness.run();
    let s = harness.state();
    assert_eq!(s.effect.emitters[0].events[0].emitter, "flames");
    assert!(
        s.validation_errors
            .iter()
            .any(|e| e.problem.contains("cycle")),
        "{:?}",
        s.validation_errors
    );
    assert!(
        s.running.emitters[0].events.is_empty(),
        "the last valid effect runs"
    );
}

/// The trail's mode in the panel: a ribbon turned on for the campfire's smoke (fed by the
/// flames' deaths) is switched to a ribbon per parent, which runs live; its points row goes
/// away; undo restores the ribbon through its own positions.
#[test]
fn the_trail_mode_is_chosen_in_the_panel() {
    use ignis::effect::TrailMode;
    let mut state = campfire_state();
    let smoke = emitter_index(&state.effect, "smoke");
    state.selected = smoke;
    state.open_sections = Some(vec!["look".to_owned()]);
    let mut harness = panel_harness(state);
    harness.run();
    harness.get_by_label("ribbon").click_accesskit();
    harness.run();
    let trail = harness.state().effect.emitters[smoke].look.trail.clone();
    assert_eq!(trail.map(|t| t.mode), Some(TrailMode::History));
    assert!(harness.query_all_by_label("Trail points").next().is_some());
    harness.get_by_label("Trail mode").click_accesskit();
    harness.run();
    harness
        .get_by_label("a ribbon per parent")
        .click_accesskit();
    harness.run();
    let s = harness.state();
    let mode = |e: &ignis::Effect| e.emitters[smoke].look.trail.as_ref().map(|t| t.mode);
    assert_eq!(mode(&s.effect), Some(TrailMode::PerParent));
    assert_eq!(mode(&s.running), Some(TrailMode::PerParent), "runs live");
    assert!(s.validation_errors.is_empty(), "{:?}", s.validation_errors);
    assert!(harness.query_all_by_label("Trail points").next().is_none());
    harness.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    harness.run();
    assert_eq!(mode(&harness.state().effect), Some(TrailMode::History));
}

/// Steps the measurement the panel asks for, with the panel drawn between steps, until it
/// ends or `stop_after` frames have run; returns whether the progress bar and Cancel
/// showed while it ran.
fn run_measure(
    harness: &mut Harness<'_, EditorState>,
    ctx: &GpuContext,
    running: &mut Option<ignis::tune::Sweep>,
    stop_after: Option<u32>,
) -> bool {
    let (mut saw_cancel, mut frames) = (false, 0);
    loop {
        {
            let state = harness.state_mut();
            let effect = state.running.clone();
            ignis::testing::editor::panel::measure_ui::drive(
                ctx,
                &effect,
                None,
                &mut state.measure,
                running,
                std::time::Duration::from_millis(1),
            );
        }
        harness.step();
        frames += 1;
        if running.is_none() || stop_after.is_some_and(|n| frames >= n) {
            return saw_cancel;
        }
        saw_cancel |= harness.query_by_label("Cancel measurement").is_some()
            && harness.state().measure.progress.is_some();
    }
}

/// Time ▸ Measure this effect: a measurement shows its progress and cancels; a small one
/// completes with a frontier whose rows apply a candidate's settings as one edit, which
/// one undo takes back.
#[test]
fn the_time_section_measures_the_effect_and_applies_a_frontier_point() {
    let ctx = common::gpu();
    let mut state = EditorState::new(Effect::default(), "test");
    state.measure.size = (48, 27);
    state.measure.span_secs = 0.3;
    let mut harness = panel_harness(state);
    harness.get_by_label("Measure").click_accesskit();
    harness.run();
    let mut running = None;
    assert!(run_measure(&mut harness, &ctx, &mut running, Some(5)));
    harness.get_by_label("Cancel measurement").click_accesskit();
    // The progress bar asks for frames until the sweep is dropped: step, not run.
    harness.step();
    run_measure(&mut harness, &ctx, &mut running, None);
    assert!(running.is_none());
    let message = harness.state().measure.message.clone();
    assert!(
        matches!(&message, Some(Err(m)) if m.contains("cancelled")),
        "{message:?}"
    );
    assert!(harness.state().measure.report.is_none());

    harness.get_by_label("Measure").click_accesskit();
    harness.run();
    run_measure(&mut harness, &ctx, &mut running, None);
    let report = harness.state().measure.report.clone().expect("a report");
    assert!(
        report.results.len() > 25,
        "{} candidates",
        report.results.len()
    );
    // A frontier point that changes the effect: its row applies it.
    let before = harness.state().effect.clone();
    let i = *report
        .frontier
        .iter()
        .find(|&&i| report.results[i].candidate.apply(&before) != before)
        .expect("a frontier point that changes the effect");
    let label = report.results[i].label.clone();
    harness.get_by_label(&label).click_accesskit();
    harness.run();
    let after = harness.state().effect.clone();
    assert_eq!(after, report.results[i].candidate.apply(&before), "{label}");
    assert_ne!(after, before);
    harness.get_by_label("Undo").click_accesskit();
    harness.run();
    assert_eq!(
        harness.state().effect,
        before,
        "one undo restores the effect"
    );
}

/// Look ▸ Lit (six-way) switches a smoke layer's lighting off and back on (with the
/// defaults), each an undo step, and a streak turns it off (a lit layer faces the
/// camera); View ▸ Fire lights grid is a view setting, not an edit.
#[test]
fn the_lit_rows_switch_lit_smoke_and_the_view_lights_the_grid() {
    let mut harness = panel_harness(campfire_state());
    open_section(&mut harness, "Look");
    let lit = |h: &Harness<'_, EditorState>| h.state().effect.emitters[0].look.lit.clone();
    assert!(lit(&harness).is_some(), "the campfire's smoke is lit");
    let undos = harness.state().history.undo_len();
    harness.get_by_label("Lit (six-way)").click_accesskit();
    harness.run();
    assert_eq!(lit(&harness), None);
    harness.get_by_label("Lit (six-way)").click_accesskit();
    harness.run();
    assert_eq!(lit(&harness), Some(ignis::effect::Lit::default()));
    assert!(
        harness.state().history.undo_len() >= undos + 2,
        "each switch is an undo step"
    );
    harness.get_by_label("stretch").click_accesskit();
    harness.run();
    assert_eq!(lit(&harness), None, "a streak is not lit");
    assert!(harness.state().effect.validate().is_ok());

    harness.get_by_label("View").click_accesskit();
    harness.run();
    let effect = harness.state().effect.clone();
    assert!(harness.state().view.fire_lights_grid);
    harness.get_by_label("Fire lights grid").click_accesskit();
    harness.run();
    assert!(!harness.state().view.fire_lights_grid);
    assert_eq!(
        harness.state().effect,
        effect,
        "a view setting edits nothing"
    );
}

/// Export ▸ Six-way passes asks the export for the lit smoke's six-way lightmaps.
#[test]
fn the_export_section_asks_for_the_sixway_passes() {
    let mut harness = panel_harness(campfire_state());
    open_section(&mut harness, "Export");
    assert!(!harness.state().export.settings.passes.sixway);
    harness.get_by_label("Six-way passes").click_accesskit();
    harness.run();
    assert!(harness.state().export.settings.passes.sixway);
    let names = harness.state().export.settings.passes.names();
    assert!(
        names.contains(&"sixway_rtba") && names.contains(&"sixway_lbfe"),
        "{names:?}"
    );
}

/// The timeline bar paints where the state says: the played part and the playhead at
/// now / span of the bar's width, each burst's marker at its time, the loop region over
/// its span; the bar fills its row but for 8 px; Pause and Play toggle the playback.
#[test]
fn the_timeline_bar_paints_the_playhead_bursts_and_loop_where_they_are() {
    use egui::epaint::Shape;
    use ignis::testing::editor::panel::timeline::{span_secs, timeline_ui};
    let mut state = campfire_state();
    state.running.emitters[0].bursts.push(ignis::effect::Burst {
        time_secs: 0.75,
        count: 10,
    });
    state.stats.sim_time_secs = 1.0;
    state.playback.loop_region = Some((0.5, 1.5));
    // Where the row the bar is in ends.
    let row_end = std::rc::Rc::new(std::cell::Cell::new(0.0f32));
    let row = row_end.clone();
    let mut harness = Harness::builder()
        .with_size(egui::vec2(900.0, 40.0))
        .build_ui_state(
            move |ui, state: &mut EditorState| {
                row.set(ui.max_rect().right());
                timeline_ui(ui, state);
            },
            state,
        );
    harness.run();
    let bar = harness.get_by_label("Timeline").rect();
    let span = span_secs(&harness.state().running).max(1.0);
    let x_of = |t: f64| bar.left() + (t / span) as f32 * bar.width();
    let shapes: Vec<Shape> = harness
        .output()
        .shapes
        .iter()
        .map(|c| c.shape.clone())
        .collect();
    let lines = |color: egui::Color32| -> Vec<f32> {
        let at = |s: &Shape| match s {
            Shape::LineSegment { points, stroke } if stroke.color == color => Some(points[0].x),
            _ => None,
        };
        shapes.iter().filter_map(at).collect()
    };
    let rects = |fill: egui::Color32| -> Vec<egui::Rect> {
        let at = |s: &Shape| match s {
            Shape::Rect(r) if r.fill == fill => Some(r.rect),
            _ => None,
        };
        shapes.iter().filter_map(at).collect()
    };
    let near = |a: f32, b: f32| (a - b).abs() < 0.01;
    let playhead = lines(egui::Color32::WHITE);
    assert!(
        playhead.len() == 1 && near(playhead[0], x_of(1.0)),
        "playhead at {playhead:?}, want {}",
        x_of(1.0)
    );
    let bursts = lines(egui::Color32::from_rgb(240, 150, 60));
    assert!(
        bursts.iter().any(|&x| near(x, x_of(0.75))),
        "burst markers at {bursts:?}, want one at {}",
        x_of(0.75)
    );
    let played = rects(egui::Color32::from_rgb(120, 70, 30));
    assert!(
        played.len() == 1
            && near(played[0].left(), bar.left())
            && near(played[0].right(), x_of(1.0)),
        "played part {played:?}"
    );
    let region = rects(egui::Color32::from_rgb(45, 60, 80));
    assert!(
        region.len() == 1
            && near(region[0].left(), x_of(0.5))
            && near(region[0].right(), x_of(1.5)),
        "loop region {region:?}, want {} – {}",
        x_of(0.5),
        x_of(1.5)
    );
    // The bar ends 8 px before its row.
    assert!(
        near(row_end.get() - 8.0, bar.right()),
        "the bar ends at {}, its row at {}",
        bar.right(),
        row_end.get()
    );
    assert!(!harness.state().playback.is_paused);
    harness.get_by_label("Pause").click();
    harness.run();
    assert!(harness.state().playback.is_paused, "Pause pauses");
    harness.get_by_label("Play").click();
    harness.run();
    assert!(!harness.state().playback.is_paused, "Play plays");
}
