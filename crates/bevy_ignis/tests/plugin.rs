//! The plugin in a headless Bevy app on a real adapter (lavapipe in CI): the fire in
//! Bevy's frame against its reversed-Z depth, instances that come and go, hot reload.

mod common;

use bevy::prelude::*;
use bevy_ignis::IgnisEffect;
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
