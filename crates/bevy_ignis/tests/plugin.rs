//! The plugin in a headless Bevy app on a real adapter (lavapipe in CI): the fire in
//! Bevy's frame against its reversed-Z depth, instances that come and go, hot reload.

mod common;

use bevy::prelude::*;
use bevy_ignis::{IgnisEffect, ignis};
use common::SIZE;

/// The eye and target of the occlusion scene.
const EYE: Vec3 = Vec3::new(0.0, 0.8, 3.0);
const LOOK_AT: Vec3 = Vec3::new(0.0, 0.6, 0.0);

/// A frame of the campfire scene: an unlit grey ground, an unlit blue wall over the
/// left half of the fire when `wall`, the fire when `fire`; 60 frames in.
fn scene_frame(fire: bool, wall: bool) -> Vec<[u8; 4]> {
    let mut app = common::app(&common::presets(), false);
    let target = common::camera(&mut app, EYE, LOOK_AT);
    let preset = common::load(&mut app, "campfire.ron");
    let world = app.world_mut();
    let ground = world
        .resource_mut::<Assets<Mesh>>()
        .add(Plane3d::default().mesh().size(20.0, 20.0));
    let slab = world
        .resource_mut::<Assets<Mesh>>()
        .add(Cuboid::new(3.0, 4.0, 0.1));
    let mut materials = world.resource_mut::<Assets<StandardMaterial>>();
    let unlit = |c| StandardMaterial {
        base_color: c,
        unlit: true,
        ..default()
    };
    let grey = materials.add(unlit(Color::srgb(0.2, 0.2, 0.2)));
    let blue = materials.add(unlit(Color::srgb(0.1, 0.2, 0.5)));
    world.spawn((Mesh3d(ground), MeshMaterial3d(grey)));
    if wall {
        world.spawn((
            Mesh3d(slab),
            MeshMaterial3d(blue),
            Transform::from_xyz(-1.5, 1.0, 1.2),
        ));
    }
    if fire {
        world.spawn(IgnisEffect::new(preset, 3));
    }
    common::run(&mut app, 60);
    let image = common::capture(&mut app, &target);
    if fire {
        let players = common::players(&app);
        assert_eq!(
            players.players.len(),
            1,
            "one player for the one preset and view"
        );
        for vp in players.players.values() {
            assert_eq!(vp.last_error, None, "the view's depth was refused");
        }
    }
    image
}

fn differs(a: [u8; 4], b: [u8; 4], by: u8) -> bool {
    (0..3).any(|c| a[c].abs_diff(b[c]) > by)
}

/// Bevy's depth (reversed Z, 4× MSAA by default) hides the fire exactly where a mesh
/// covers it: every pixel inside the wall is the frame without fire; fire shows beside
/// it, and would show behind it without the wall.
#[test]
fn a_mesh_in_front_hides_the_fire_exactly() {
    let walled = scene_frame(false, true);
    let bare = scene_frame(false, false);
    let with_fire = scene_frame(true, true);
    let no_wall = scene_frame(true, false);
    let w = SIZE.0 as usize;
    let is_wall = |i: usize| differs(walled[i], bare[i], 8);
    // Inside: the pixel and its neighbours are wall (MSAA blends the edges).
    let inside = |i: usize| {
        [i.wrapping_sub(1), i + 1, i.wrapping_sub(w), i + w]
            .iter()
            .all(|&j| j < walled.len() && is_wall(j))
            && is_wall(i)
    };
    let (mut wall_px, mut behind, mut beside) = (0, 0, 0);
    for i in 0..walled.len() {
        if inside(i) {
            wall_px += 1;
            assert_eq!(
                with_fire[i], walled[i],
                "pixel {i} inside the wall shows fire"
            );
            behind += usize::from(differs(no_wall[i], walled[i], 20));
        } else if !is_wall(i) {
            beside += usize::from(differs(with_fire[i], walled[i], 20));
        }
    }
    assert!(wall_px > 5000, "the wall covers {wall_px} pixels");
    assert!(
        behind > 150,
        "only {behind} wall pixels would show fire without it"
    );
    assert!(
        beside > 150,
        "only {beside} pixels beside the wall show fire"
    );
}

/// The particles of every instance of the torch, by seed, after `frames` frames; the
/// instances with seeds in `despawned` are despawned after `despawn_at` frames (`None`:
/// they are never spawned).
fn torch_particles(
    seeds: std::ops::Range<u32>,
    despawned: &[u32],
    despawn_at: Option<u32>,
    frames: u32,
) -> Vec<(u32, Vec<Vec<ignis::testing::gpu::types::Particle>>)> {
    let mut app = common::app(&common::presets(), false);
    common::camera(&mut app, Vec3::new(0.0, 3.0, 12.0), Vec3::ZERO);
    let preset = common::load(&mut app, "torch.ron");
    let mut entities = Vec::new();
    for seed in seeds {
        if despawn_at.is_none() && despawned.contains(&seed) {
            continue;
        }
        let at = Transform::from_xyz((seed % 10) as f32 - 5.0, 0.0, (seed / 10) as f32 * -2.0);
        let e = app
            .world_mut()
            .spawn((IgnisEffect::new(preset.clone(), seed), at))
            .id();
        entities.push((seed, e));
    }
    let first = despawn_at.unwrap_or(0);
    common::run(&mut app, first);
    for (seed, e) in &entities {
        if despawned.contains(seed) {
            app.world_mut().despawn(*e);
        }
    }
    common::run(&mut app, frames - first);
    let vp = common::players(&app).any_of(preset.id()).expect("a player");
    let emitters = vp.player.effect().emitters.len();
    let mut out = Vec::new();
    for (seed, e) in entities.iter().filter(|(s, _)| !despawned.contains(s)) {
        let (id, _) = vp.instances[e];
        let particles = (0..emitters)
            .map(|em| vp.player.particles(id, em).expect("readback"))
            .collect();
        out.push((*seed, particles));
    }
    out
}

/// 50 torches, 25 despawned after 20 frames: the other 25 are bit-identical to a run
/// where the 25 never existed.
#[test]
fn despawned_instances_leave_the_others_untouched() {
    let despawned: Vec<u32> = (1..=50).filter(|s| s % 2 == 0).collect();
    let kept = torch_particles(1..51, &despawned, Some(20), 50);
    let alone = torch_particles(1..51, &despawned, None, 50);
    assert_eq!(kept.len(), 25);
    let mut alive = 0;
    for ((seed, a), (seed_b, b)) in kept.iter().zip(&alone) {
        assert_eq!(seed, seed_b);
        for (em, (pa, pb)) in a.iter().zip(b).enumerate() {
            alive += pa.iter().filter(|p| p.is_alive()).count();
            let (ba, bb): (&[u8], &[u8]) = (bytemuck::cast_slice(pa), bytemuck::cast_slice(pb));
            assert!(ba == bb, "torch {seed}, emitter {em}: particles differ");
        }
    }
    assert!(alive > 25 * 20, "only {alive} particles alive");
}

/// Pixels where green clearly leads red: the edited (green) fire.
fn green_pixels(image: &[[u8; 4]]) -> usize {
    image
        .iter()
        .filter(|p| p[1] > p[0].saturating_add(40))
        .count()
}

/// Updates `app` (waiting for the file watcher between frames) until `done` holds.
fn until(app: &mut bevy::app::App, what: &str, mut done: impl FnMut(&mut bevy::app::App) -> bool) {
    for _ in 0..400 {
        app.update();
        if done(app) {
            return;
        }
        std::thread::sleep(std::time::Duration::from_millis(25));
    }
    panic!("timed out waiting for {what}");
}

/// An edited preset written over the loaded file reaches the running effect within a
/// few frames (its fire turns green on screen); a broken file leaves the last good
/// effect playing, and the asset server reports the error.
#[test]
fn an_edited_preset_hot_reloads_and_a_broken_one_keeps_the_last_good() {
    let dir = common::temp_presets("torch.ron", str::to_owned);
    let file = dir.path().join("torch.ron");
    let mut app = common::app(dir.path(), true);
    let target = common::camera(&mut app, Vec3::new(0.0, 1.3, 2.5), Vec3::new(0.0, 1.3, 0.0));
    let preset = common::load(&mut app, "torch.ron");
    app.world_mut().spawn(IgnisEffect::new(preset.clone(), 5));
    common::run(&mut app, 30);
    let before = common::capture(&mut app, &target);
    assert!(
        green_pixels(&before) < 10,
        "{} green pixels before",
        green_pixels(&before)
    );

    let original = std::fs::read_to_string(&file).expect("read");
    let green = stops_to_green(&original);
    assert_ne!(green, original);
    std::fs::write(&file, &green).expect("write");
    let id = preset.id();
    until(&mut app, "the edit to reach the player", |app| {
        common::players(app).any_of(id).is_some_and(|vp| {
            let stops = &vp.player.effect().emitters[0].look.color_over_life;
            stops.iter().all(|s| s.rgba[0] == 0.0)
        })
    });
    common::run(&mut app, 30);
    let after = common::capture(&mut app, &target);
    assert!(
        green_pixels(&after) > 100,
        "{} green pixels after",
        green_pixels(&after)
    );

    std::fs::write(&file, "(version: 3, emitters: [ broken").expect("write");
    until(&mut app, "the broken file's error", |app| {
        let server = app.world().resource::<AssetServer>();
        matches!(
            server.load_state(&preset),
            bevy::asset::LoadState::Failed(_)
        )
    });
    if let bevy::asset::LoadState::Failed(e) =
        app.world().resource::<AssetServer>().load_state(&preset)
    {
        assert!(e.to_string().contains("torch.ron"), "{e}");
    }
    common::run(&mut app, 20);
    let kept = common::capture(&mut app, &target);
    assert!(
        green_pixels(&kept) > 100,
        "the last good effect stopped: {}",
        green_pixels(&kept)
    );
}

/// `text` with every colour stop's red and blue zeroed and green full (alpha kept).
fn stops_to_green(text: &str) -> String {
    let mut out = String::new();
    let mut rest = text;
    while let Some(at) = rest.find("rgba: (") {
        let (head, tail) = rest.split_at(at + "rgba: (".len());
        out.push_str(head);
        let mut parts = tail.splitn(4, ',');
        let (_, _, _) = (parts.next(), parts.next(), parts.next());
        let remainder = parts.next().unwrap_or("");
        out.push_str("0.0, 1.0, 0.0,");
        rest = remainder;
    }
    out.push_str(rest);
    out
}

/// `IgnisSeek` moves the preset's instances to the time asked (a cut-scene's jump), and
/// is removed once applied.
#[test]
fn a_seek_moves_the_effect_to_the_time_asked() {
    let mut app = common::app(&common::presets(), false);
    common::camera(&mut app, Vec3::new(0.0, 1.3, 2.5), Vec3::new(0.0, 1.3, 0.0));
    let preset = common::load(&mut app, "torch.ron");
    let entity = app
        .world_mut()
        .spawn(IgnisEffect::new(preset.clone(), 5))
        .id();
    common::run(&mut app, 20);
    let time = |app: &bevy::app::App| {
        let vp = common::players(app).any_of(preset.id()).expect("player");
        vp.player.time_secs(vp.instances[&entity].0).expect("time")
    };
    let before = time(&app);
    app.world_mut()
        .entity_mut(entity)
        .insert(bevy_ignis::IgnisSeek(2.0));
    app.update();
    let after = time(&app);
    assert!(before < 0.5, "{before} s before the seek");
    // The seek, then at most this frame's 1/60 s (the steps it has recorded).
    assert!(
        (2.0..=2.0 + 1.0 / 60.0 + 1e-9).contains(&after),
        "{after} s after seeking to 2 s"
    );
    assert!(app.world().get::<bevy_ignis::IgnisSeek>(entity).is_none());
}

/// `IgnisLight` gives the effect a point light that follows the flames: placed among
/// them, warm, and flickering from frame to frame as the particles do.
#[test]
fn the_campfire_lights_the_scene_with_a_flickering_light() {
    let mut app = common::app(&common::presets(), false);
    common::camera(&mut app, EYE, LOOK_AT);
    let preset = common::load(&mut app, "campfire.ron");
    let fire = app
        .world_mut()
        .spawn((
            IgnisEffect::new(preset, 3),
            bevy_ignis::IgnisLight::default(),
            Transform::from_xyz(2.0, 0.0, -1.0),
        ))
        .id();
    common::run(&mut app, 40);
    let mut intensities = Vec::new();
    for _ in 0..30 {
        app.update();
        let world = app.world_mut();
        let mut lights =
            world.query::<(&bevy_ignis::IgnisLightOf, &PointLight, &GlobalTransform)>();
        let found: Vec<_> = lights.iter(world).collect();
        assert_eq!(found.len(), 1, "one light for the one lit effect");
        let (of, light, at) = found[0];
        assert_eq!(of.0, fire);
        let p = at.translation();
        assert!(
            (p.x - 2.0).abs() < 0.5 && (p.z + 1.0).abs() < 0.5,
            "light at {p}"
        );
        assert!(p.y > 0.1 && p.y < 1.5, "light at {p}");
        let c = light.color.to_linear();
        assert!(c.red >= c.green && c.green > c.blue, "warm: {c:?}");
        intensities.push(f64::from(light.intensity));
    }
    let mean = intensities.iter().sum::<f64>() / intensities.len() as f64;
    let sd = (intensities.iter().map(|i| (i - mean).powi(2)).sum::<f64>()
        / intensities.len() as f64)
        .sqrt();
    eprintln!("campfire light in Bevy: {mean:.0} ± {sd:.0} lm");
    assert!(mean > 10_000.0 && sd / mean > 0.01, "{mean} ± {sd} lm");
    app.world_mut()
        .entity_mut(fire)
        .remove::<bevy_ignis::IgnisLight>();
    common::run(&mut app, 3);
    let world = app.world_mut();
    let left = world
        .query::<&bevy_ignis::IgnisLightOf>()
        .iter(world)
        .count();
    assert_eq!(left, 0, "the light goes with the component");
}

/// Soft edges against Bevy's depth: the torch's flames (soft distance 0.8 m here) fade
/// where they come near a wall just behind them, against the same flames before an empty
/// background (the preset's own ground fade is the same in both). Measured: 0.46 of the
/// light; 0.77 with the soft distance 0 (what the wall hides, and sRGB's clipping).
#[test]
fn flames_fade_where_they_meet_bevys_geometry() {
    let dir = common::temp_presets("torch.ron", |t| {
        t.replace("look: (", "look: (soft_ground_m: 0.8, ")
    });
    let frame = |wall: bool, fire: bool| {
        let mut app = common::app(dir.path(), false);
        let target = common::camera(&mut app, Vec3::new(0.0, 1.3, 2.0), Vec3::new(0.0, 1.3, 0.0));
        let preset = common::load(&mut app, "torch.ron");
        let world = app.world_mut();
        let slab = world
            .resource_mut::<Assets<Mesh>>()
            .add(Cuboid::new(4.0, 4.0, 0.1));
        let blue = world
            .resource_mut::<Assets<StandardMaterial>>()
            .add(StandardMaterial {
                base_color: Color::srgb(0.05, 0.05, 0.1),
                unlit: true,
                ..default()
            });
        if wall {
            world.spawn((
                Mesh3d(slab),
                MeshMaterial3d(blue),
                Transform::from_xyz(0.0, 1.5, -0.3),
            ));
        }
        if fire {
            world.spawn(IgnisEffect::new(preset, 5));
        }
        common::run(&mut app, 60);
        common::capture(&mut app, &target)
    };
    let light = |with: &[[u8; 4]], without: &[[u8; 4]]| -> f64 {
        with.iter()
            .zip(without)
            .map(|(a, b)| {
                (0..3)
                    .map(|c| f64::from(a[c].saturating_sub(b[c])))
                    .sum::<f64>()
            })
            .sum()
    };
    let before_wall = light(&frame(true, true), &frame(true, false));
    let before_nothing = light(&frame(false, true), &frame(false, false));
    eprintln!("flame light before the wall {before_wall:.0}, before nothing {before_nothing:.0}");
    assert!(before_nothing > 2000.0, "the torch shows: {before_nothing}");
    assert!(
        before_wall < 0.6 * before_nothing && before_wall > 0.02 * before_nothing,
        "before the wall {before_wall}, before nothing {before_nothing}"
    );
}

/// Two cameras see one simulation: one player for the preset (the same target kind), its
/// clock advanced once a frame — as with one camera — and each view draws the fire from
/// its own side.
#[test]
fn two_cameras_draw_one_simulation() {
    let run = |cameras: usize| {
        let mut app = common::app(&common::presets(), false);
        let targets: Vec<_> = [Vec3::new(0.0, 1.3, 2.5), Vec3::new(2.5, 1.3, 0.0)]
            .into_iter()
            .take(cameras)
            .map(|eye| common::camera(&mut app, eye, Vec3::new(0.0, 1.2, 0.0)))
            .collect();
        let preset = common::load(&mut app, "torch.ron");
        let torch = app
            .world_mut()
            .spawn(IgnisEffect::new(preset.clone(), 5))
            .id();
        common::run(&mut app, 30);
        app.world_mut().resource_mut::<Time<Virtual>>().pause();
        let players = common::players(&app);
        assert_eq!(players.players.len(), 1, "one player for both views");
        let vp = players.any_of(preset.id()).expect("player");
        let time = vp.player.time_secs(vp.instances[&torch].0).expect("time");
        let images: Vec<_> = targets
            .iter()
            .map(|t| common::capture(&mut app, t))
            .collect();
        (time, images)
    };
    let (one, _) = run(1);
    let (two, images) = run(2);
    assert_eq!(
        one, two,
        "two views advanced the clock differently from one"
    );
    for (k, image) in images.iter().enumerate() {
        let lit = image.iter().filter(|p| p[0] > 120).count();
        assert!(lit > 100, "view {k}: only {lit} lit pixels");
    }
    assert_ne!(images[0], images[1], "both views drew the same image");
}
