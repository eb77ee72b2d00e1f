//! Collision with the host's depth buffer: a host draws planes into its depth, the player
//! is handed that depth, and sparks fired at the planes stop, rebound with the preset's
//! restitution and take the plane's normal; a reversed-Z host gives the same particles;
//! what leaves the screen or passes behind geometry flies on; fast sparks do not tunnel
//! through a wall thinner than their step; hits fire collision events; the same depth and
//! seed give the same particles.

mod common;
#[allow(dead_code)]
#[path = "runtime/host.rs"]
mod host;

use common::*;
use glam::{Vec3, vec3};
use host::{Host, HostKind, Quad};
use ignis::effect::{
    Burst, Collisions, CountRange, DepthCollision, Effect, Emitter, Event, Range, Shape, Trigger,
};
use ignis::testing::gpu::types::Particle;
use ignis::{InstanceId, Player};

const EYE: Vec3 = vec3(0.0, 1.0, 4.0);
const TARGET: Vec3 = vec3(0.0, 0.5, 0.0);
const THICKNESS: f32 = 0.1;

/// A quad through `center` spanned by `u` and `v` (half sizes included).
fn quad(center: Vec3, u: Vec3, v: Vec3) -> Quad {
    Quad(
        [
            center - u - v,
            center + u - v,
            center + u + v,
            center - u + v,
        ],
        [0.5, 0.5, 0.5],
    )
}

/// `count` sparks in a box of half extents `half` at `at`, all at `velocity`, no forces,
/// colliding with the host's depth (restitution `elasticity`, no friction).
fn sparks(count: u32, at: [f32; 3], half: [f32; 3], velocity: [f32; 3], elasticity: f32) -> Effect {
    let (at, velocity) = (Vec3::from(at), Vec3::from(velocity));
    let speed = velocity.length();
    let e = Emitter {
        name: "sparks".into(),
        capacity: 1024,
        spawn_rate_per_sec: ignis::effect::Param::Constant(0.0),
        bursts: vec![Burst {
            time_secs: 0.0,
            count,
        }],
        lifetime_secs: Range::new(10.0, 10.0),
        shape: Shape::Box {
            half_extents_m: half,
        },
        direction: (velocity / speed).to_array(),
        speed_m_per_s: Range::new(speed, speed),
        collisions: Collisions {
            elasticity,
            friction: 0.0,
            rest_speed_m_per_s: 0.0,
            depth_collision: Some(DepthCollision {
                thickness_m: THICKNESS,
                kill_on_contact: false,
            }),
            ..Collisions::default()
        },
        ..plain_emitter()
    };
    let effect = bare_effect(Emitter {
        transform: ignis::effect::Transform {
            position_m: at.to_array(),
            ..Default::default()
        },
        ..e
    });
    effect.validate().expect("valid");
    effect
}

/// Runs `frames` host frames of 1/60 s: the host draws `quads` into its depth, the player
/// steps against it (or against nothing when `depth` is false); `each` sees emitter 0's
/// particles (positions in the world) after every frame.
fn run(
    host: &Host,
    quads: &[Quad],
    player: &mut Player,
    frames: u32,
    depth: bool,
    mut each: impl FnMut(&[Particle]),
) -> (InstanceId, Vec<Particle>) {
    let view = host.depth.create_view(&Default::default());
    let instance = player
        .add_instance(glam::Mat4::IDENTITY, 0)
        .expect("instance");
    let origin = player.effect().emitters[0].transform.position_m;
    let mut last = Vec::new();
    for _ in 0..frames {
        let mut enc = host.device.create_command_encoder(&Default::default());
        host.draw_opaque(&mut enc, [0.0; 3], quads, |_| {});
        player.advance(1.0 / 60.0);
        player
            .record(&mut enc, &host.camera, depth.then_some(&view))
            .expect("record");
        host.queue.submit([enc.finish()]);
        last = alive(player.particles(instance, 0).expect("particles"));
        for p in &mut last {
            // Simulation space is relative to the emitter's position.
            for (c, o) in p.pos_age.iter_mut().zip(origin) {
                *c += o;
            }
        }
        each(&last);
    }
    (instance, last)
}

fn alive(p: Vec<Particle>) -> Vec<Particle> {
    p.into_iter()
        .filter(|p| p.pos_age[3] < p.vel_life[3])
        .collect()
}

fn pos(p: &Particle) -> Vec3 {
    Vec3::from_slice(&p.pos_age[..3])
}

fn vel(p: &Particle) -> Vec3 {
    Vec3::from_slice(&p.vel_life[..3])
}

/// `effect` played `frames` frames against the wall: the particles at the end, and the
/// lowest z any particle reached in any frame (how far behind the wall it got).
fn at_the_wall(host: &Host, effect: &Effect, frames: u32) -> (Vec<Particle>, f32) {
    let mut deepest = f32::MAX;
    let (_, last) = run(
        host,
        &[wall()],
        &mut host.player(effect),
        frames,
        true,
        |p| {
            deepest = p.iter().map(|p| pos(p).z).fold(deepest, f32::min);
        },
    );
    (last, deepest)
}

/// The wall the sparks are fired at: the plane z = 0 facing the camera.
fn wall() -> Quad {
    quad(Vec3::ZERO, Vec3::X * 3.0, Vec3::Y * 3.0)
}

/// Sparks fired at a wall in the host's depth never end behind it by more than the
/// thickness and come back at the restitution × their speed; handed no depth, they fly
/// through.
#[test]
fn sparks_stop_at_the_host_depth_and_rebound_with_the_restitution() {
    let host = Host::new(EYE, TARGET);
    let effect = sparks(
        200,
        [0.0, 0.5, 1.51],
        [0.6, 0.4, 0.0],
        [0.0, 0.0, -3.0],
        0.5,
    );
    let (last, deepest) = at_the_wall(&host, &effect, 60);
    assert_eq!(last.len(), 200);
    assert!(deepest >= -THICKNESS, "a spark reached z = {deepest}");
    for p in &last {
        // Fired at 3 m/s, hit after 0.5 s, back at 1.5 m/s for the rest of the second. The
        // normal comes from depths 3 cm apart whose f32 steps are 2e-5 m at 4 m with
        // ordinary Z: a few steps tilt it by up to ~2e-3.
        assert!(
            vel(p).abs_diff_eq(vec3(0.0, 0.0, 1.5), 5e-3),
            "{:?}",
            vel(p)
        );
        // They reach the wall 0.4 into a step (the player's first frame runs one step of
        // 1/120 s, the others two: 119 in all): on at 1.5 m/s for the 58 whole steps
        // after the contact's, 0.725 m. The contact is refined to the surface, not left at
        // the step's start (1.5 cm in front).
        assert!((pos(p).z - 0.725).abs() < 0.004, "{:?}", pos(p));
    }
    let mut blind = host.player(&effect);
    let (_, through) = run(&host, &[wall()], &mut blind, 60, false, |_| {});
    assert!(
        through.iter().all(|p| pos(p).z < -1.4),
        "without the depth they fly on"
    );
}

/// The host's depth as hosts hand it over: multisampled (4×: the runtime's single-sample
/// copy is what the sparks collide with) and a depth-stencil format (its depth aspect):
/// the sparks stop at the wall and come back at the restitution as with a plain host.
#[test]
fn msaa_and_depth_stencil_hosts_stop_sparks_alike() {
    let kinds = [
        HostKind {
            color: wgpu::TextureFormat::Rgba16Float,
            samples: 4,
            ..HostKind::default()
        },
        HostKind {
            depth: wgpu::TextureFormat::Depth24PlusStencil8,
            ..HostKind::default()
        },
    ];
    let effect = sparks(100, [0.0, 0.5, 1.5], [0.6, 0.4, 0.0], [0.0, 0.0, -3.0], 0.5);
    for kind in kinds {
        let what = format!("{kind:?}");
        let host = Host::of(kind, EYE, TARGET);
        let (last, deepest) = at_the_wall(&host, &effect, 60);
        assert_eq!(last.len(), 100, "{what}");
        assert!(
            deepest >= -THICKNESS,
            "{what}: a spark reached z = {deepest}"
        );
        for p in &last {
            let v = vel(p);
            assert!(v.abs_diff_eq(vec3(0.0, 0.0, 1.5), 2e-2), "{what}: {v}");
        }
    }
}

/// Sparks that start a step just behind the wall (5 cm, within the thickness: the depth's
/// rounding or the host's geometry moving) are put back on its surface, and fly on from
/// there.
#[test]
fn sparks_starting_just_behind_a_surface_are_put_back_on_it() {
    let host = Host::new(EYE, TARGET);
    let effect = sparks(
        100,
        [0.0, 0.5, -0.05],
        [0.6, 0.4, 0.0],
        [0.0, 0.0, 0.3],
        0.5,
    );
    let (last, _) = at_the_wall(&host, &effect, 10);
    assert_eq!(last.len(), 100);
    for p in &last {
        // On the surface at the first step, then 9 frames (plus the rest of the first) on
        // at 0.3 m/s.
        assert!((0.035..0.05).contains(&pos(p).z), "{:?}", pos(p));
    }
}

/// A step seen from above: its top (y = 0.25) left of x = 0, the floor (y = 0) right of
/// it. Sparks dropped on both sides of the edge bounce straight up: at the pixels beside
/// the edge the normal is built from the neighbour on the same surface (the nearer depth),
/// not across the jump.
#[test]
fn beside_an_edge_the_normal_comes_from_the_same_surface() {
    let host = Host::new(vec3(0.0, 3.0, 0.3), Vec3::ZERO);
    let top = quad(vec3(-1.0, 0.25, 0.0), Vec3::X, Vec3::Z * 2.0);
    let floor = quad(vec3(1.0, 0.0, 0.0), Vec3::X, Vec3::Z * 2.0);
    let face = quad(vec3(0.0, 0.125, 0.0), Vec3::Z * 2.0, Vec3::Y * 0.125);
    let effect = sparks(400, [0.0, 0.6, 0.0], [0.1, 0.0, 0.3], [0.0, -3.0, 0.0], 1.0);
    all_bounce_straight_up(&host, &[top, floor, face], &effect, 400);
}

/// A floor (y = 0, x > 0) meeting a 45° ramp that rises towards −x, seen from above: the
/// crease at x = 0 runs down the image's middle, between two pixel columns. Sparks
/// dropped onto the floor's first column beside it bounce straight up: the normal is
/// built around the contact pixel's own centre, not a neighbour's on the ramp.
#[test]
fn beside_a_crease_the_normal_is_the_contact_pixels_own() {
    let host = Host::new(vec3(0.0, 3.0, 0.3), Vec3::ZERO);
    let floor = quad(vec3(1.0, 0.0, 0.0), Vec3::X, Vec3::Z * 2.0);
    let ramp = quad(
        vec3(-0.25, 0.25, 0.0),
        vec3(0.25, -0.25, 0.0),
        Vec3::Z * 2.0,
    );
    // x from 4 to 20 mm: inside the column right of the crease (2.4 cm wide here).
    let effect = sparks(
        200,
        [0.012, 0.6, 0.0],
        [0.008, 0.0, 0.3],
        [0.0, -3.0, 0.0],
        1.0,
    );
    all_bounce_straight_up(&host, &[floor, ramp], &effect, 200);
}

/// `effect`'s `count` sparks, dropped on `quads` at 3 m/s, all bounce straight up (16
/// frames).
fn all_bounce_straight_up(host: &Host, quads: &[Quad], effect: &Effect, count: usize) {
    let (_, last) = run(host, quads, &mut host.player(effect), 16, true, |_| {});
    assert_eq!(last.len(), count);
    for p in &last {
        let v = vel(p);
        assert!(v.y > 2.9, "{} did not bounce: {v}", pos(p));
        assert!(v.x.abs() < 0.02 && v.z.abs() < 0.02, "{}: {v}", pos(p));
    }
}

/// A plane tilted towards the camera: a perfectly elastic bounce reflects each spark
/// about the plane's normal, which the depth around the contact gives to 1e-3.
fn tilted_run(kind: HostKind) -> Vec<Particle> {
    let host = Host::of(kind, EYE, TARGET);
    let n = vec3(0.0, 0.5, 1.0).normalize();
    let along = vec3(0.0, n.z, -n.y);
    let plane = quad(vec3(0.0, 0.5, 0.0), Vec3::X * 3.0, along * 3.0);
    let effect = sparks(100, [0.0, 0.6, 1.5], [0.5, 0.2, 0.0], [0.0, 0.0, -3.0], 1.0);
    let mut player = host.player(&effect);
    let (_, last) = run(&host, &[plane], &mut player, 45, true, |_| {});
    assert_eq!(last.len(), 100);
    let fired = vec3(0.0, 0.0, -3.0);
    for p in &last {
        let normal = (vel(p) - fired).normalize();
        assert!(normal.abs_diff_eq(n, 1e-3), "normal {normal} for {n}");
        assert!((vel(p).length() - 3.0).abs() < 1e-3);
    }
    last
}

#[test]
fn the_normal_of_a_tilted_plane_is_exact_and_reversed_z_gives_the_same_sparks() {
    let ordinary = tilted_run(HostKind::default());
    let reversed = tilted_run(HostKind {
        reversed_z: true,
        ..HostKind::default()
    });
    for (a, b) in ordinary.iter().zip(&reversed) {
        assert!(pos(a).abs_diff_eq(pos(b), 5e-3), "{} vs {}", pos(a), pos(b));
        assert!(vel(a).abs_diff_eq(vel(b), 5e-3), "{} vs {}", vel(a), vel(b));
    }
}

/// Sparks leaving the screen sideways cross the wall's plane off screen and fly on;
/// sparks passing 1 m behind a panel (more than the thickness) are hidden, not hit: both
/// end exactly where sparks handed no depth do.
#[test]
fn off_screen_and_behind_geometry_sparks_fly_on() {
    let host = Host::new(EYE, TARGET);
    let wide = quad(Vec3::ZERO, Vec3::X * 40.0, Vec3::Y * 3.0);
    let off = sparks(
        50,
        [-1.0, 0.5, 1.0],
        [0.1, 0.1, 0.0],
        [-6.0, 0.0, -1.5],
        0.5,
    );
    let panel = quad(vec3(0.0, 0.5, 2.0), Vec3::X * 0.4, Vec3::Y * 0.5);
    let behind = sparks(50, [-1.5, 0.5, 1.0], [0.05, 0.2, 0.0], [3.0, 0.0, 0.0], 0.5);
    let mut ends = Vec::new();
    for (effect, quad, frames) in [(&off, &wide, 72), (&behind, &panel, 60)] {
        let quads = std::slice::from_ref(quad);
        let (_, seen) = run(&host, quads, &mut host.player(effect), frames, true, |_| {});
        let (_, free) = run(
            &host,
            quads,
            &mut host.player(effect),
            frames,
            false,
            |_| {},
        );
        assert_eq!(seen.len(), 50);
        assert!(seen == free, "a spark was stopped");
        ends.push(seen);
    }
    // The first crossed the wall's plane (off screen), the second passed the panel.
    assert!(ends[0].iter().all(|p| pos(p).z < -0.7));
    assert!(ends[1].iter().all(|p| pos(p).x > 1.3));
}

/// Sparks at 60 m/s travel 0.5 m a step (1/120 s); the wall in the depth is a single
/// surface (thinner than any step), and none gets through it, nor through a post it crosses
/// obliquely.
#[test]
fn fast_sparks_do_not_tunnel_through_a_thin_wall() {
    let host = Host::new(EYE, TARGET);
    let effect = sparks(
        200,
        [0.0, 0.5, 1.7],
        [0.6, 0.4, 0.0],
        [0.0, 0.0, -60.0],
        0.2,
    );
    let (last, deepest) = at_the_wall(&host, &effect, 6);
    assert_eq!(last.len(), 200);
    assert!(deepest >= -THICKNESS, "a spark reached z = {deepest}");
    assert!(
        last.iter().all(|p| vel(p).z > 11.9),
        "every spark rebounded"
    );
    // A post 0.2 m wide crossed at 45°: a step starts in front of it and ends beside it,
    // over the background; only the march along the step finds the post between.
    let post = quad(Vec3::ZERO, Vec3::X * 0.1, Vec3::Y * 2.0);
    let effect = sparks(
        100,
        [0.6, 0.5, 0.6],
        [0.02, 0.3, 0.0],
        [-30.0, 0.0, -30.0],
        0.2,
    );
    let mut player = host.player(&effect);
    let (_, last) = run(&host, &[post], &mut player, 4, true, |_| {});
    assert_eq!(last.len(), 100);
    assert!(
        last.iter().all(|p| vel(p).z > 5.9 && pos(p).z > 0.0),
        "every spark rebounded off the post"
    );
}

/// Parents falling 0.3 m onto a floor in the host's depth: each impact spawns one child,
/// resting parents spawn no more — 50 children for 50 parents, as on the analytic ground.
#[test]
fn depth_hits_fire_collision_events_once_per_impact() {
    let host = Host::new(EYE, TARGET);
    let mut effect = sparks(50, [0.0, 0.3, 0.0], [0.0; 3], [0.0, -1e-6, 0.0], 0.0);
    let parent = &mut effect.emitters[0];
    parent.lifetime_secs = Range::new(3.0, 3.0);
    parent.forces.gravity_m_per_s2 = [0.0, -9.81, 0.0];
    parent.collisions.rest_speed_m_per_s = 0.5;
    parent.events = vec![Event {
        trigger: Trigger::Collision,
        emitter: "child".into(),
        count: CountRange { min: 1, max: 1 },
        ..Event::default()
    }];
    effect.emitters.push(Emitter {
        name: "child".into(),
        capacity: 4096,
        lifetime_secs: Range::new(50.0, 100.0),
        ..plain_emitter()
    });
    effect.validate().expect("valid");
    let floor = quad(Vec3::ZERO, Vec3::X * 3.0, Vec3::Z * 3.0);
    let mut player = host.player(&effect);
    let (id, parents) = run(&host, &[floor], &mut player, 120, true, |_| {});
    assert_eq!(parents.len(), 50);
    assert!(
        parents.iter().all(|p| pos(p).y.abs() < 0.01),
        "resting on the floor"
    );
    let children = alive(player.particles(id, 1).expect("read"));
    assert_eq!(children.len(), 50, "one impact each");
}

/// The same host depth and seed give bit-identical particles.
#[test]
fn the_same_depth_and_seed_give_the_same_particles() {
    let host = Host::new(EYE, TARGET);
    let effect = sparks(
        200,
        [0.0, 0.5, 1.5],
        [0.6, 0.4, 0.2],
        [0.3, -0.5, -3.0],
        0.5,
    );
    let runs: Vec<Vec<Particle>> = (0..2)
        .map(|_| {
            run(
                &host,
                &[wall()],
                &mut host.player(&effect),
                50,
                true,
                |_| {},
            )
            .1
        })
        .collect();
    assert_eq!(runs[0].len(), 200);
    assert!(runs[0] == runs[1], "two runs differ");
}

/// The editor's test scene: its props are drawn into the composite's image and their
/// depth is handed to the player, so sparks fired at the box bounce off it (and fly on
/// with the scene off).
#[test]
fn the_test_scene_gives_the_viewport_a_depth_to_collide_with() {
    let ctx = gpu();
    let effect = sparks(50, [-0.8, 0.3, 0.0], [0.0, 0.1, 0.1], [-3.0, 0.0, 0.0], 0.5);
    let run = |scene: bool| {
        let mut h = ignis::testing::headless::Headless::new(
            &ctx,
            effect.clone(),
            ignis::testing::shaders::ShaderLibrary::embedded(),
        )
        .expect("headless");
        h.composite.test_scene = scene;
        let mut image = None;
        for _ in 0..40 {
            h.advance(1.0 / 60.0);
            image = Some(h.render((160, 120)).expect("render"));
        }
        let p = alive(h.player.particles(h.instance, 0).expect("read"));
        (p, image.expect("an image"))
    };
    let (bounced, shown) = run(true);
    assert_eq!(bounced.len(), 50);
    assert!(
        bounced.iter().all(|p| vel(p).x > 1.4),
        "bounced off the box"
    );
    let (through, bare) = run(false);
    assert!(through.iter().all(|p| vel(p).x < -2.9), "no scene: flew on");
    let lit = |img: &image::RgbaImage| img.pixels().filter(|p| p[0] > 20).count();
    assert!(
        lit(&shown) > lit(&bare) + 2000,
        "the props are drawn: {} lit pixels against {}",
        lit(&shown),
        lit(&bare)
    );
}
