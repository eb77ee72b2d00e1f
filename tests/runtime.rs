//! The runtime as a host uses it: a test host with its own colour and depth targets and
//! its own opaque geometry, and `ignis::Player`s drawing inside its render pass.
//! Occlusion by the host's depth, soft edges against it, instances that add up and stay
//! independent, and a runtime-only build without the editor's crates.

mod common;
#[path = "runtime/host.rs"]
mod host;

use glam::{DVec3, Mat4, Vec3, vec3};
use host::{Frame, Host, HostKind, Quad, SIZE};
use ignis::effect::{BlendMode, ColorStop, Effect, Sprite};
use ignis::testing::shaders::ShaderLibrary;
use ignis::testing::sim::{GpuSim, Stepper};
use ignis::{InstanceId, Player, PlayerSettings};

fn preset(name: &str) -> Effect {
    let path = format!("{}/presets/{name}.ron", env!("CARGO_MANIFEST_DIR"));
    ignis::preset::load(path.as_ref()).expect("shipped preset")
}

/// The campfire without events or trails (its smoke at 90 a second of its own), so that
/// its instances batch.
fn batchable_campfire() -> Effect {
    let mut effect = preset("campfire");
    for e in &mut effect.emitters {
        e.events.clear();
        e.look.trail = None;
    }
    effect.emitters[0].spawn_rate_per_sec = ignis::effect::Param::Constant(90.0);
    assert!(ignis::testing::sim::batch::batchable(&effect));
    effect
}

fn advance(players: &mut [&mut Player], host: &Host, frames: u32) {
    for _ in 0..frames {
        let mut enc = host.device.create_command_encoder(&Default::default());
        for p in players.iter_mut() {
            p.advance(1.0 / 60.0);
            p.record(&mut enc, &host.camera, None).expect("record");
        }
        host.queue.submit([enc.finish()]);
    }
}

fn differs(a: [f32; 4], b: [f32; 4], by: f32) -> bool {
    (0..3).any(|c| (a[c] - b[c]).abs() > by)
}

#[test]
fn host_geometry_in_front_hides_the_fire_exactly() {
    hides_the_fire_exactly(&preset("campfire"), false);
}

/// The compute splat (small additive particles) tests the host's depth at every pixel it
/// lights; without the depth view the player draws billboards, which the pass tests.
#[test]
fn host_geometry_hides_splatted_particles_exactly() {
    let mut effect = preset("campfire");
    for e in &mut effect.emitters {
        if e.look.blend == BlendMode::Additive {
            e.look.draw_path = ignis::effect::DrawPath::Splat;
        }
    }
    hides_the_fire_exactly(&effect, true);
    hides_the_fire_exactly(&effect, false);
}

/// One white additive particle living 10 s, forced onto the splat.
fn one_white_splat() -> ignis::effect::Emitter {
    let mut e = common::still_burst(1, 10.0);
    e.look.color_over_life = common::flat_color([1.0, 1.0, 1.0, 1.0]);
    e.look.blend = BlendMode::Additive;
    e.look.draw_path = ignis::effect::DrawPath::Splat;
    e
}

/// A large sprite forced onto the splat (its integrated light at its centre) in front of
/// a wall is tested at its own depth: a 0.3 m disc 3 m from the camera, a wall 1 m behind
/// it, the disc's centre shows its light over the wall as it does with no wall.
#[test]
fn a_large_splatted_sprite_in_front_of_a_wall_shows() {
    let mut e = one_white_splat();
    e.transform.position_m = [0.0, 0.5, 0.0];
    e.look.sprite = Sprite::SoftDisc;
    e.look.size_m = ignis::effect::Param::Constant(0.3);
    let effect = common::bare_effect(e);
    let host = Host::new(vec3(0.0, 0.5, 3.0), vec3(0.0, 0.5, 0.0));
    let mut fire = host.player(&effect);
    fire.add_instance(host.place(Mat4::IDENTITY), 3)
        .expect("instance");
    advance(&mut [&mut fire], &host, 30);
    let wall = Quad(
        [
            vec3(-3.0, -2.0, -1.0),
            vec3(3.0, -2.0, -1.0),
            vec3(3.0, 3.0, -1.0),
            vec3(-3.0, 3.0, -1.0),
        ],
        [0.2, 0.3, 0.4],
    );
    let bg = [0.05, 0.04, 0.03];
    let host_only = host.frame(bg, std::slice::from_ref(&wall), &mut [], true);
    let with_fire = host.frame(bg, std::slice::from_ref(&wall), &mut [&mut fire], true);
    assert!(
        fire.draw_items().iter().any(|d| d.splat),
        "the disc was splatted"
    );
    let lit = (0..host_only.rgba.len())
        .filter(|&i| differs(with_fire.rgba[i], host_only.rgba[i], 0.01))
        .count();
    assert!(
        (1..=4).contains(&lit),
        "{lit} pixels of the wall lit by the disc's centre (1 to 4 expected)"
    );
}

/// A long, thin streak forced onto the splat (under 2 px wide, its pixel box wider than
/// the footprint's 8 px) is added as its integrated light in one tap: the pixel its head
/// is in, and no other.
#[test]
fn a_thin_splatted_streak_lights_the_pixel_its_head_is_in() {
    let mut e = one_white_splat();
    // 0.4 px below the middle row's top edge.
    e.transform.position_m = [-0.3, 0.49, 0.0];
    e.direction = [1.0, 0.0, 0.0];
    e.spread_deg = 0.0;
    e.speed_m_per_s = ignis::effect::Range::new(1.0, 1.0);
    // 1.2 px wide, 0.3 m (12 px) long, 3 m from the camera.
    e.look.size_m = ignis::effect::Param::Constant(0.03);
    e.look.streak = Some(ignis::effect::Streak {
        length_secs: 0.3,
        max_length_m: 1.0,
    });
    let origin = Vec3::from(e.transform.position_m);
    let effect = common::bare_effect(e);
    let host = Host::new(vec3(0.0, 0.5, 3.0), vec3(0.0, 0.5, 0.0));
    let mut fire = host.player(&effect);
    let id = fire
        .add_instance(host.place(Mat4::IDENTITY), 3)
        .expect("instance");
    let bg = [0.05, 0.04, 0.03];
    let dark = host.frame(bg, &[], &mut [], true);
    for frames in [23, 7] {
        advance(&mut [&mut fire], &host, frames);
        let frame = host.frame(bg, &[], &mut [&mut fire], true);
        assert!(
            fire.draw_items().iter().any(|d| d.splat),
            "the streak was splatted"
        );
        let p = fire.particles(id, 0).expect("particles")[0];
        let at = host.pixel_of(Vec3::from_slice(&p.pos_age[..3]) + origin);
        let inside = (at - at.round()).abs();
        assert!(inside.min_element() > 0.05, "{at}: not near a pixel's edge");
        let head = at.floor();
        let lit: Vec<(u32, u32)> = (0..dark.rgba.len())
            .filter(|&i| differs(frame.rgba[i], dark.rgba[i], 0.01))
            .map(|i| (i as u32 % SIZE.0, i as u32 / SIZE.0))
            .collect();
        assert_eq!(lit, [(head.x as u32, head.y as u32)], "the head at {head}");
    }
}

/// The tile rasteriser tests the host's depth at every pixel it shades, as the splat.
#[test]
fn host_geometry_hides_tiled_particles_exactly() {
    let mut effect = preset("campfire");
    for e in &mut effect.emitters {
        e.look.draw_path = ignis::effect::DrawPath::Tiles;
    }
    hides_the_fire_exactly(&effect, true);
    hides_the_fire_exactly(&effect, false);
}

/// An opaque wall between the camera and the left half of `effect`: the pixels behind it
/// are exactly the host's, and fire shows beside it. `depth`: the host hands its depth
/// over.
fn hides_the_fire_exactly(effect: &Effect, depth: bool) {
    hides_the_fire_in(HostKind::default(), effect, depth);
}

/// [`hides_the_fire_exactly`] in a host of `kind` (a multisampled host's wall edges are
/// partly covered: only pixels inside the wall must be exactly the host's). Returns the
/// frame with wall and fire.
fn hides_the_fire_in(kind: HostKind, effect: &Effect, depth: bool) -> Frame {
    let (eye, target) = (vec3(0.0, 0.7, 3.0), vec3(0.0, 0.5, 0.0));
    let host = Host::of(kind, eye, target);
    let mut fire = host.player(effect);
    fire.add_instance(host.place(Mat4::IDENTITY), 3)
        .expect("instance");
    advance(&mut [&mut fire], &host, 90);
    let wall = wall();
    let bg = [0.05, 0.04, 0.03];
    let host_only = host.frame(bg, std::slice::from_ref(&wall), &mut [], depth);
    let with_fire = host.frame(bg, std::slice::from_ref(&wall), &mut [&mut fire], depth);
    let no_wall = host.frame(bg, &[], &mut [&mut fire], depth);
    let is_wall = |i: usize| !differs(host_only.rgba[i], [0.2, 0.3, 0.4, 1.0], 1e-3);
    let (w, n) = (SIZE.0 as usize, host_only.rgba.len());
    let inside = |i: usize| {
        host.kind.samples == 1
            || [i.wrapping_sub(1), i + 1, i.wrapping_sub(w), i + w]
                .iter()
                .all(|&j| j >= n || is_wall(j))
    };
    let (mut wall_px, mut fire_behind, mut fire_beside) = (0, 0, 0);
    for i in 0..n {
        if is_wall(i) && inside(i) {
            wall_px += 1;
            assert_eq!(
                with_fire.rgba[i], host_only.rgba[i],
                "pixel {i} behind the wall is not exactly the host's (depth view: {depth})"
            );
            fire_behind += usize::from(differs(no_wall.rgba[i], host_only.rgba[i], 0.05));
        } else if !is_wall(i) {
            fire_beside += usize::from(differs(with_fire.rgba[i], host_only.rgba[i], 0.05));
        }
    }
    assert!(wall_px > 4000, "the wall covers {wall_px} pixels");
    assert!(
        fire_behind > 150,
        "only {fire_behind} wall pixels would show fire without it"
    );
    assert!(
        fire_beside > 150,
        "only {fire_beside} pixels beside the wall hold fire"
    );
    let splatted = fire.draw_items().iter().any(|d| d.splat);
    let wants_splat = effect
        .emitters
        .iter()
        .any(|e| e.look.draw_path == ignis::effect::DrawPath::Splat);
    assert_eq!(splatted, wants_splat && depth, "the splat ran");
    let tiled = fire.draw_items().iter().any(|d| d.tiles);
    let wants_tiles = effect
        .emitters
        .iter()
        .any(|e| e.look.draw_path == ignis::effect::DrawPath::Tiles);
    let tiles_fit = ignis::testing::render::TilePass::supported(&host.device);
    assert_eq!(tiled, wants_tiles && depth && tiles_fit, "the tiles ran");
    with_fire
}

/// The wall of [`hides_the_fire_in`]: x from −3 to 0 m, 1.2 m in front of the fire.
fn wall() -> Quad {
    Quad(
        [
            vec3(-3.0, -1.0, 1.2),
            vec3(0.0, -1.0, 1.2),
            vec3(0.0, 3.0, 1.2),
            vec3(-3.0, 3.0, 1.2),
        ],
        [0.2, 0.3, 0.4],
    )
}

/// A hard-edged disc on the tiles (no soft edges, whose fade alone hides a soft layer
/// behind the host's geometry whatever the depth test): the tiles' own depth test hides its
/// half behind the wall in an ordinary and a reversed_z host; and a host that asks for no
/// depth test (`CompareFunction::Always`, its depth still handed over) sees all of it, over
/// the wall and beside it, as the billboards draw it.
#[test]
fn hard_tiled_sprites_obey_ordinary_reversed_z_and_always_hosts() {
    use ignis::effect::DrawPath;
    let disc = |path: DrawPath| {
        let mut e = still_disc(0.0);
        e.emitters[0].look.draw_path = path;
        e
    };
    let reversed = HostKind {
        reversed_z: true,
        ..HostKind::default()
    };
    for kind in [HostKind::default(), reversed] {
        hides_the_fire_in(kind, &disc(DrawPath::Tiles), true);
    }
    let host = Host::new(vec3(0.0, 0.7, 3.0), vec3(0.0, 0.5, 0.0));
    let settings = PlayerSettings {
        depth_compare: wgpu::CompareFunction::Always,
        ..host.settings()
    };
    let (bg, walls) = ([0.05, 0.04, 0.03], [wall()]);
    let host_only = host.frame(bg, &walls, &mut [], true);
    let [bill, tiles] = [DrawPath::Billboard, DrawPath::Tiles].map(|path| {
        let mut fire =
            Player::new(&host.device, &host.queue, &disc(path), settings.clone()).expect("player");
        fire.add_instance(host.place(Mat4::IDENTITY), 3)
            .expect("instance");
        advance(&mut [&mut fire], &host, 90);
        let frame = host.frame(bg, &walls, &mut [&mut fire], true);
        let tiled = fire.draw_items().iter().any(|d| d.tiles);
        assert_eq!(tiled, path == DrawPath::Tiles, "{path:?}: the tiles ran");
        frame
    });
    let is_wall = |i: usize| !differs(host_only.rgba[i], [0.2, 0.3, 0.4, 1.0], 1e-3);
    let lit = |on_wall: bool| {
        (0..tiles.rgba.len())
            .filter(|&i| is_wall(i) == on_wall && differs(tiles.rgba[i], host_only.rgba[i], 0.05))
            .count()
    };
    let (over, beside) = (lit(true), lit(false));
    assert!(
        over > 150 && beside > 150,
        "Always: the tiles lit {over} pixels over the wall, {beside} beside it"
    );
    let mean = mean_difference(&bill, &tiles);
    assert!(
        mean < 1.0 / 255.0,
        "Always: the tiles differ from the billboards by {mean}"
    );
}

/// In frame-delta mode a record runs one step of every frame advanced since the last one:
/// frames of 10 ms and 20 ms advanced before one record make one step of 30 ms.
#[test]
fn frame_delta_frames_advanced_before_a_record_join_its_one_step() {
    let host = Host::new(vec3(0.0, 0.7, 3.0), vec3(0.0, 0.5, 0.0));
    let mut effect = still_disc(0.0);
    effect.time.mode = ignis::effect::TimeMode::FrameDelta;
    effect.time.max_frame_dt_secs = 0.1;
    let mut fire = host.player(&effect);
    let id = fire.add_instance(Mat4::IDENTITY, 3).expect("instance");
    fire.advance(0.01);
    fire.advance(0.02);
    let mut enc = host.device.create_command_encoder(&Default::default());
    fire.record(&mut enc, &host.camera, None).expect("record");
    host.queue.submit([enc.finish()]);
    let clock = fire.clock_stats();
    assert_eq!(clock.steps, 1, "{clock:?}");
    assert!((clock.step_secs - 0.03).abs() < 1e-6, "{clock:?}");
    let t = fire.time_secs(id).expect("time");
    assert!((t - 0.03).abs() < 1e-6, "simulated {t} s");
}

/// One still, additive disc at (0, 0.2, 0), 1 m wide: its lower part crosses the ground.
fn still_disc(soft_m: f32) -> Effect {
    let mut e = common::plain_emitter();
    e.capacity = 16;
    e.spawn_rate_per_sec = ignis::effect::Param::Constant(4.0);
    e.lifetime_secs = ignis::effect::Range::new(100.0, 100.0);
    e.transform.position_m = [0.0, 0.2, 0.0];
    e.look.sprite = Sprite::SoftDisc;
    e.look.flipbook = None;
    e.look.streak = None;
    e.look.size_m = ignis::effect::Param::Constant(1.0);
    e.look.rotation_random_deg = 0.0;
    e.look.spin_deg_per_s = ignis::effect::Param::Constant(0.0);
    e.look.blend = BlendMode::Additive;
    e.look.intensity = 1.0;
    e.look.color_over_life = vec![
        ColorStop {
            t: 0.0,
            rgba: [0.25, 0.2, 0.15, 1.0],
        },
        ColorStop {
            t: 1.0,
            rgba: [0.25, 0.2, 0.15, 1.0],
        },
    ];
    e.look.soft_ground_m = soft_m;
    common::bare_effect(e)
}

#[test]
fn soft_edges_fade_over_the_soft_distance_from_the_host_depth() {
    soft_edges_fade(HostKind::default(), ignis::effect::DrawPath::Billboard);
    soft_edges_fade(HostKind::default(), ignis::effect::DrawPath::Tiles);
}

/// A disc crossing the host's ground, drawn by `path`: it fades as the depth says.
/// Returns the soft frame.
fn soft_edges_fade(kind: HostKind, path: ignis::effect::DrawPath) -> Frame {
    let (eye, target) = (vec3(0.0, 0.6, 2.5), vec3(0.0, 0.15, 0.0));
    let host = Host::of(kind, eye, target);
    let soft_m = 0.4;
    let disc = |soft_m| {
        let mut e = still_disc(soft_m);
        e.emitters[0].look.draw_path = path;
        e
    };
    let mut hard = host.player(&disc(0.0));
    let mut soft = host.player(&disc(soft_m));
    let at = host.place(Mat4::IDENTITY);
    hard.add_instance(at, 1).expect("instance");
    soft.add_instance(at, 1).expect("instance");
    advance(&mut [&mut hard, &mut soft], &host, 60);
    // A black ground at y = 0 that writes depth.
    let ground = Quad(
        [
            vec3(-5.0, 0.0, 5.0),
            vec3(5.0, 0.0, 5.0),
            vec3(5.0, 0.0, -5.0),
            vec3(-5.0, 0.0, -5.0),
        ],
        [0.0; 3],
    );
    let a = host.frame(
        [0.0; 3],
        std::slice::from_ref(&ground),
        &mut [&mut hard],
        true,
    );
    let b = host.frame(
        [0.0; 3],
        std::slice::from_ref(&ground),
        &mut [&mut soft],
        true,
    );
    if a.depth.is_empty() {
        return b; // a multisampled depth: compared with a single-sample host's frame
    }
    let particle = host.distance_of(eye, target, vec3(0.0, 0.2, 0.0));
    let (mut faded, mut worst) = (0, 0.0f32);
    for i in 0..a.rgba.len() {
        let scene = host.distance_at_depth(a.depth[i]);
        let fade = ((scene - particle) / f64::from(soft_m)).clamp(0.0, 1.0) as f32;
        for c in 0..3 {
            let expected = a.rgba[i][c] * fade;
            let err = (b.rgba[i][c] - expected).abs();
            worst = worst.max(err);
            assert!(
                err <= 1.0 / 255.0,
                "pixel {i} channel {c}: {} where hard × fade = {} × {fade} = {expected}",
                b.rgba[i][c],
                a.rgba[i][c]
            );
        }
        faded += usize::from(a.rgba[i][0] > 0.05 && (0.1..0.9).contains(&fade));
    }
    assert!(faded > 100, "only {faded} lit pixels are within the fade");
    eprintln!("soft edges ({path:?}): {faded} pixels in the fade, worst error {worst:.5}");
    b
}

/// The torch's additive layers (its smoke is alpha-blended: not a sum).
fn additive_torch() -> Effect {
    let mut torch = preset("torch");
    torch
        .emitters
        .retain(|e| e.look.blend == BlendMode::Additive);
    torch.drop_dangling_events();
    torch
}

#[test]
fn instances_add_up_and_stay_independent() {
    // Batched instances (full state), and one simulation per instance (tiny state).
    let mut tiny = additive_torch();
    for e in &mut tiny.emitters {
        e.tiny_state = true;
    }
    for effect in [additive_torch(), tiny] {
        instances_add_up(&effect);
    }
}

fn instances_add_up(effect: &Effect) {
    let (eye, target) = (vec3(0.0, 1.3, 3.0), vec3(0.0, 1.0, 0.0));
    let host = Host::new(eye, target);
    // One behind the other, so that their light overlaps on screen.
    let left = Mat4::from_translation(vec3(-0.02, 0.0, 0.0));
    let right =
        Mat4::from_rotation_translation(glam::Quat::from_rotation_y(0.5), vec3(0.03, 0.05, -0.4));
    let mut both = host.player(effect);
    let mut only_a = host.player(effect);
    let mut only_b = host.player(effect);
    let a = both.add_instance(left, 1).expect("instance");
    let b = both.add_instance(right, 2).expect("instance");
    let a_alone = only_a.add_instance(left, 1).expect("instance");
    only_b.add_instance(right, 2).expect("instance");
    advance(&mut [&mut both, &mut only_a, &mut only_b], &host, 60);
    let sum = host.frame([0.0; 3], &[], &mut [&mut both], false);
    let fa = host.frame([0.0; 3], &[], &mut [&mut only_a], false);
    let fb = host.frame([0.0; 3], &[], &mut [&mut only_b], false);
    let (mut lit, mut worst, mut total) = (0, 0.0f32, 0.0f64);
    for i in 0..sum.rgba.len() {
        for c in 0..3 {
            let expected = fa.rgba[i][c] + fb.rgba[i][c];
            let err = (sum.rgba[i][c] - expected).abs();
            worst = worst.max(err);
            total += f64::from(err);
        }
        lit += usize::from(fa.rgba[i][0] > 0.05 && fb.rgba[i][0] > 0.05);
    }
    let mean = total / (sum.rgba.len() * 3) as f64;
    eprintln!("instances: {lit} pixels lit by both, error mean {mean:.6} max {worst:.5}");
    assert!(lit > 50, "the instances overlap on only {lit} pixels");
    assert!(
        mean <= 1.0 / 255.0 && worst <= 1.0 / 255.0,
        "mean {mean}, max {worst}"
    );

    // Removing an instance leaves the other's particles bit-identical to a player that
    // never had it.
    assert!(both.remove_instance(b));
    assert!(!both.remove_instance(b), "a removed handle is refused");
    let c = both.add_instance(right, 9).expect("instance");
    assert_ne!(b, c);
    assert!(
        !both.set_transform(b, left),
        "the old handle does not reach the new instance"
    );
    advance(&mut [&mut both, &mut only_a], &host, 45);
    for e in 0..effect.emitters.len() {
        let kept = both.particles(a, e).expect("read");
        let alone = only_a.particles(a_alone, e).expect("read");
        assert!(
            kept.iter().any(|p| p.is_alive()),
            "emitter {e} has particles"
        );
        assert_eq!(
            bytemuck::cast_slice::<_, u8>(&kept),
            bytemuck::cast_slice::<_, u8>(&alone),
            "emitter {e} of the kept instance differs from the instance alone"
        );
    }
    assert_eq!(both.instance_count(), 2);
}

#[test]
fn a_batched_instance_steps_exactly_as_a_simulation_of_its_own() {
    let (eye, target) = (vec3(0.0, 1.0, 4.0), vec3(0.0, 0.5, 0.0));
    let host = Host::new(eye, target);
    let effect = batchable_campfire();
    let mut player = host.player(&effect);
    let places = [
        Mat4::from_translation(vec3(-1.0, 0.0, 0.0)),
        Mat4::from_rotation_translation(glam::Quat::from_rotation_y(1.0), vec3(1.0, 0.2, -0.5)),
        Mat4::from_translation(vec3(0.0, 0.0, -2.0)),
    ];
    let ids: Vec<_> = (0..3)
        .map(|k| {
            player
                .add_instance(places[k], 10 + k as u32)
                .expect("instance")
        })
        .collect();
    // A slot freed and taken again mid-run: the newcomer starts from an empty segment.
    advance(&mut [&mut player], &host, 20);
    assert!(player.remove_instance(ids[1]));
    let late = player.add_instance(places[1], 77).expect("instance");
    let first = own_simulation(&host, &player, ids[0], 0, 50);
    let newcomer = own_simulation(&host, &player, late, 20, 30);
    advance(&mut [&mut player], &host, 30);
    for (id, sim) in [(ids[0], &first), (late, &newcomer)] {
        assert_steps_as_its_own(&player, id, sim);
    }
}

/// A batch's buffers grow when an instance finds them full: 3 instances play 20 frames,
/// 15 more come (18: buffers for 16 grow to 32), and after 30 more frames the first and
/// the last step bit for bit as simulations of their own. Until its first record a new
/// instance beyond the old buffers has no particle.
#[test]
fn a_batch_that_grows_keeps_its_instances_stepping_as_their_own() {
    let host = Host::new(vec3(0.0, 1.0, 4.0), vec3(0.0, 0.5, 0.0));
    let effect = batchable_campfire();
    let mut player = host.player(&effect);
    let place = |k: u32| Mat4::from_translation(vec3(k as f32 * 0.2 - 1.8, 0.0, -(k as f32) * 0.1));
    let first = player.add_instance(place(0), 10).expect("instance");
    for k in 1..3 {
        player.add_instance(place(k), 10 + k).expect("instance");
    }
    advance(&mut [&mut player], &host, 20);
    let late: Vec<_> = (3..18)
        .map(|k| player.add_instance(place(k), 10 + k).expect("instance"))
        .collect();
    let last = late[late.len() - 1];
    for e in 0..effect.emitters.len() {
        let unrecorded = player.particles(last, e).expect("read");
        assert!(unrecorded.iter().all(|p| !p.is_alive()), "emitter {e}");
    }
    let own_first = own_simulation(&host, &player, first, 0, 50);
    let own_last = own_simulation(&host, &player, last, 20, 30);
    advance(&mut [&mut player], &host, 30);
    for (id, sim) in [(first, &own_first), (last, &own_last)] {
        assert_steps_as_its_own(&player, id, sim);
    }
}

/// Instance `id`'s own simulation, stepped as `player`'s clock stepped it from frame
/// `from` for `frames` frames (a clock's steps per frame depend on its history: it is
/// replayed).
fn own_simulation(host: &Host, player: &Player, id: InstanceId, from: u32, frames: u32) -> GpuSim {
    let ctx = ignis::testing::gpu::GpuContext::from_device(&host.device, &host.queue);
    let placed = player.instance_effect(id).expect("instance").clone();
    let mut sim = GpuSim::new(&ctx, ShaderLibrary::embedded(), &placed).expect("sim");
    let mut stepper = Stepper::default();
    for frame in 0..from + frames {
        let plan = stepper.advance(1.0 / 60.0, &placed.time);
        if frame >= from {
            sim.step(&placed, plan.dt_secs, plan.steps).expect("step");
        }
    }
    sim
}

/// Every emitter of instance `id` in `player` holds `sim`'s particles, bit for bit.
fn assert_steps_as_its_own(player: &Player, id: InstanceId, sim: &GpuSim) {
    for e in 0..player.effect().emitters.len() {
        let batched = player.particles(id, e).expect("read");
        let alone = sim.read_particles(e).expect("read");
        assert!(
            alone.iter().any(|p| p.is_alive()),
            "emitter {e} has particles"
        );
        let differ: Vec<usize> = (0..alone.len())
            .filter(|&k| bytemuck::bytes_of(&batched[k]) != bytemuck::bytes_of(&alone[k]))
            .collect();
        assert!(
            differ.is_empty(),
            "{id:?}, emitter {e}: {} of {} slots differ from the instance's own simulation, \
             first {:?}: {:?} vs {:?}",
            differ.len(),
            alone.len(),
            differ.first(),
            differ.first().map(|&k| batched[k]),
            differ.first().map(|&k| alone[k]),
        );
    }
}

#[test]
fn large_pools_batch_as_many_instances_as_a_binding_holds() {
    // 2^20 slots of 32 bytes per instance: the test host's device has wgpu's default
    // limits (128 MiB per storage binding), which hold four, and a batch allocates at most
    // 64 MiB of state (an instance's two buffers here): each instance has a batch.
    let host = Host::new(vec3(0.0, 1.0, 4.0), vec3(0.0, 0.5, 0.0));
    let mut effect = still_disc(0.0);
    effect.emitters[0].capacity = 1 << 20;
    let mut player = host.player(&effect);
    let ids: Vec<_> = (0..5)
        .map(|k| player.add_instance(Mat4::from_translation(vec3(k as f32, 0.0, 0.0)), k))
        .collect::<Result<_, _>>()
        .expect("instances");
    // 40 frames: 2/3 s at 4 spawns per second.
    advance(&mut [&mut player], &host, 40);
    for id in ids {
        let particles = player.particles(id, 0).expect("read");
        assert_eq!(particles.len(), 1 << 20);
        assert_eq!(
            particles.iter().filter(|p| p.is_alive()).count(),
            2,
            "{id:?}"
        );
    }
}

#[test]
fn a_moving_instance_spawns_where_it_is_and_keeps_world_motion() {
    let (eye, target) = (vec3(0.0, 1.0, 4.0), vec3(0.0, 0.5, 0.0));
    let host = Host::new(eye, target);
    let mut fire = host.player(&preset("campfire"));
    let id = fire.add_instance(Mat4::IDENTITY, 5).expect("instance");
    advance(&mut [&mut fire], &host, 30);
    let moved = Mat4::from_translation(vec3(2.0, 0.0, 0.0));
    assert!(fire.set_transform(id, moved));
    assert_eq!(fire.transform(id), Some(moved));
    // The flames (emitter 1): the newest are born around x = 2, the older ones stay.
    advance(&mut [&mut fire], &host, 6);
    let flames = fire.particles(id, 1).expect("read");
    let alive: Vec<DVec3> = flames
        .iter()
        .filter(|p| p.is_alive())
        .map(|p| {
            DVec3::new(
                p.pos_age[0].into(),
                p.pos_age[1].into(),
                p.pos_age[2].into(),
            )
        })
        .collect();
    let near_new = alive.iter().filter(|p| (p.x - 2.0).abs() < 0.6).count();
    let near_old = alive.iter().filter(|p| p.x.abs() < 0.6).count();
    assert!(near_new > 10, "{near_new} flames near the new place");
    assert!(
        near_old > 10,
        "{near_old} flames still rise where they were born"
    );
}

#[test]
fn the_runtime_build_pulls_in_no_editor_crates() {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = std::process::Command::new(cargo)
        .args([
            "tree",
            "--offline",
            "--locked",
            "--no-default-features",
            "--edges",
            "normal",
            "--prefix",
            "none",
        ])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("running cargo tree");
    let tree = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "cargo tree failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(tree.lines().any(|l| l.starts_with("wgpu ")), "{tree}");
    for banned in ["egui", "winit", "clap", "plotters", "notify", "egui-wgpu"] {
        let found: Vec<&str> = tree
            .lines()
            .filter(|l| l.split(' ').next() == Some(banned))
            .collect();
        assert!(found.is_empty(), "the runtime pulls in {banned}: {found:?}");
    }
}

/// Live edits of a batched player: a parameter edit keeps every instance's particles; an
/// edit that resizes a pool restarts the instances (their shared buffers are laid out by
/// the pools), which then play the new effect; an invalid effect is refused and changes
/// nothing.
#[test]
fn edits_reach_every_batched_instance() {
    let host = Host::new(vec3(0.0, 1.0, 4.0), vec3(0.0, 0.5, 0.0));
    let effect = preset("torch");
    let mut player = host.player(&effect);
    let ids = [0.0, 2.0].map(|x| {
        player
            .add_instance(Mat4::from_translation(vec3(x, 0.0, 0.0)), 5)
            .expect("instance")
    });
    advance(&mut [&mut player], &host, 30);
    let alive = |p: &Player| -> Vec<u32> {
        ids.iter()
            .map(|id| {
                p.count_particles(*id)
                    .expect("count")
                    .iter()
                    .map(|c| c.alive)
                    .sum()
            })
            .collect()
    };
    let before: Vec<_> = ids
        .iter()
        .map(|id| player.particles(*id, 0).expect("read"))
        .collect();
    assert!(
        alive(&player).iter().all(|n| *n > 0),
        "{:?}",
        alive(&player)
    );

    let mut brighter = effect.clone();
    brighter.emitters[0].spawn_rate_per_sec = brighter.emitters[0].spawn_rate_per_sec.scaled(2.0);
    brighter.emitters[0].look.intensity *= 1.5;
    player.set_effect(&brighter).expect("a parameter edit");
    for (id, b) in ids.iter().zip(&before) {
        assert_eq!(
            &player.particles(*id, 0).expect("read"),
            b,
            "particles kept"
        );
        let placed = player.instance_effect(*id).expect("there");
        assert_eq!(
            placed.emitters[0].spawn_rate_per_sec,
            brighter.emitters[0].spawn_rate_per_sec
        );
    }

    let mut invalid = brighter.clone();
    invalid.emitters[0].lifetime_secs = ignis::effect::Range::new(-1.0, 1.0);
    assert!(matches!(
        player.set_effect(&invalid),
        Err(ignis::PlayerError::Invalid(_))
    ));
    assert_eq!(player.effect(), &brighter, "a refused edit changes nothing");

    let mut larger = brighter.clone();
    larger.emitters[0].capacity *= 2;
    player.set_effect(&larger).expect("a pool edit");
    assert_eq!(alive(&player), [0, 0], "the instances restarted");
    advance(&mut [&mut player], &host, 30);
    assert!(
        alive(&player).iter().all(|n| *n > 0),
        "{:?}",
        alive(&player)
    );
    let stats = player.emitter_stats(ids[1]).expect("there");
    assert_eq!(stats[0].capacity, larger.emitters[0].capacity);
}

/// A batch's smoke is sorted together: an instance added to a batch that already draws
/// sorted smoke shows its own smoke (the sort's buffers grow with the batch, and the draw
/// follows them), and the smoke of every instance is drawn once.
#[test]
fn an_instance_added_to_a_sorted_batch_shows_its_smoke() {
    let host = Host::new(vec3(0.0, 1.5, 4.0), vec3(0.0, 1.2, 0.0));
    let mut smoke = preset("torch");
    smoke.emitters.retain(|e| e.look.blend == BlendMode::Alpha);
    assert!(!smoke.emitters.is_empty(), "the torch has smoke");
    // Without its flames the lit smoke has only the dim night: drawn unlit, it shows.
    for e in &mut smoke.emitters {
        e.look.lit = None;
    }
    let at = |x: f32| Mat4::from_translation(vec3(x, 0.0, 0.0));
    let mut player = host.player(&smoke);
    player.add_instance(at(-1.2), 1).expect("instance");
    player.add_instance(at(0.0), 2).expect("instance");
    advance(&mut [&mut player], &host, 90);
    let bg = [0.0; 3];
    // Pixels of the right third of the frame that hold smoke.
    let right_third = |f: &Frame| {
        (0..f.rgba.len())
            .filter(|i| (i % SIZE.0 as usize) * 3 / SIZE.0 as usize == 2)
            .filter(|i| differs(f.rgba[*i], [0.0, 0.0, 0.0, 1.0], 0.01))
            .count()
    };
    let before = host.frame(bg, &[], &mut [&mut player], false);
    assert_eq!(right_third(&before), 0, "nothing is drawn on the right yet");
    player.add_instance(at(1.2), 3).expect("instance");
    advance(&mut [&mut player], &host, 90);
    let after = host.frame(bg, &[], &mut [&mut player], false);
    let shown = right_third(&after);
    assert!(
        shown > 100,
        "the new instance's smoke covers only {shown} pixels"
    );
}

/// A frame runs every step it needs, on both sides of the parameter ring's 32 steps: a
/// preset whose step needs 16, 40 or 72 steps a frame plays at real time (nothing dropped),
/// batched and with a simulation of its own, and its particles are bit-identical to a
/// simulation stepped that many steps in separate submissions. (Steps of 2^-10 and 2^-12
/// s: frames of whole steps, exactly.)
#[test]
fn a_frame_runs_every_step_it_needs_beyond_one_chunk() {
    let host = Host::new(vec3(0.0, 1.0, 4.0), vec3(0.0, 0.5, 0.0));
    let ctx = ignis::testing::gpu::GpuContext::from_device(&host.device, &host.queue);
    for (effect, label) in [
        (batchable_campfire(), "batched"),
        (preset("campfire"), "own"),
    ] {
        for (steps_per_frame, step) in [
            (16u32, 1.0 / 1024.0),
            (40, 1.0 / 4096.0),
            (72, 1.0 / 4096.0),
        ] {
            let mut effect = effect.clone();
            effect.time.step_secs = step;
            effect.time.max_substeps = 128;
            let frame_secs = f64::from(steps_per_frame) * f64::from(step);
            let mut player = host.player(&effect);
            let id = player.add_instance(Mat4::IDENTITY, 3).expect("instance");
            let frames = 6;
            for _ in 0..frames {
                let mut enc = host.device.create_command_encoder(&Default::default());
                player.advance(frame_secs);
                player.record(&mut enc, &host.camera, None).expect("record");
                host.queue.submit([enc.finish()]);
            }
            let stats = player.clock_stats();
            assert_eq!(
                (stats.steps, stats.dropped_steps),
                (steps_per_frame, 0),
                "{label}, {steps_per_frame} steps a frame"
            );
            let time = player.time_secs(id).expect("instance");
            assert_eq!(
                time,
                f64::from(frames) * frame_secs,
                "{label}, {steps_per_frame} steps a frame"
            );
            let placed = player.instance_effect(id).expect("instance").clone();
            let mut sim = GpuSim::new(&ctx, ShaderLibrary::embedded(), &placed).expect("sim");
            for _ in 0..frames {
                sim.step(&placed, step, steps_per_frame).expect("step");
            }
            let flames = sim.read_particles(1).expect("read");
            assert!(
                flames.iter().any(|p| p.is_alive()),
                "{label}: the flames live"
            );
            for e in 0..effect.emitters.len() {
                let played = player.particles(id, e).expect("read");
                let alone = sim.read_particles(e).expect("read");
                assert!(
                    bytemuck::cast_slice::<_, u8>(&played) == bytemuck::cast_slice::<_, u8>(&alone),
                    "{label}, {steps_per_frame} steps a frame: emitter {e} differs"
                );
            }
        }
    }
}

// Hosts as others write them (each fixture a `HostKind`): the player fits them or says
// why not, and never draws nothing without an error.

/// Reversed-Z (near = 1, cleared to 0, `GreaterEqual`), a host that keeps only
/// `proj * view` and the eye: occlusion exact on every draw path, soft edges as the
/// depth says.
#[test]
fn reversed_z_hosts_hide_and_soften_the_fire() {
    let kind = HostKind {
        reversed_z: true,
        view_proj_only: true,
        ..HostKind::default()
    };
    for path in ALL_PATHS {
        hides_the_fire_in(kind.clone(), &on_path(path), true);
    }
    soft_edges_fade(kind.clone(), ignis::effect::DrawPath::Billboard);
    soft_edges_fade(kind, ignis::effect::DrawPath::Tiles);
}

/// Every draw path: the billboards, and the splat's and the tiles' own depth tests.
const ALL_PATHS: [ignis::effect::DrawPath; 3] = [
    ignis::effect::DrawPath::Billboard,
    ignis::effect::DrawPath::Splat,
    ignis::effect::DrawPath::Tiles,
];

/// The campfire with its additive layers on `path` (the splat's and the tiles' own
/// depth tests, or billboards).
fn on_path(path: ignis::effect::DrawPath) -> Effect {
    let mut effect = preset("campfire");
    for e in &mut effect.emitters {
        if e.look.blend == BlendMode::Additive || path == ignis::effect::DrawPath::Tiles {
            e.look.draw_path = path;
        }
    }
    effect
}

/// A host with MSAA 4× colour (`Rgba16Float`, which every adapter multisamples) and depth.
fn msaa_host() -> HostKind {
    HostKind {
        color: wgpu::TextureFormat::Rgba16Float,
        samples: 4,
        ..HostKind::default()
    }
}

/// MSAA 4× colour and depth: the player draws into the multisampled pass and samples a
/// single-sample copy of the depth; the fire is hidden inside the wall on every path, and
/// soft edges match a single-sample host's within 1/255.
#[test]
fn msaa_hosts_get_occlusion_and_soft_edges() {
    let msaa = msaa_host();
    for path in ALL_PATHS {
        hides_the_fire_in(msaa.clone(), &on_path(path), true);
    }
    let single = HostKind {
        color: wgpu::TextureFormat::Rgba16Float,
        ..HostKind::default()
    };
    let path = ignis::effect::DrawPath::Billboard;
    let (a, b) = (soft_edges_fade(single, path), soft_edges_fade(msaa, path));
    let mean = mean_difference(&a, &b);
    let lit = a.rgba.iter().filter(|p| p[0] > 0.05).count();
    assert!(lit > 500, "{lit} lit pixels");
    assert!(
        mean < 1.0 / 255.0,
        "MSAA soft edges differ by {mean} on average"
    );
}

/// A host whose depth needs the copy to one sample (MSAA) while that copy's shader is
/// broken: the frame is recorded without the host's depth, and the error says which
/// shader failed and where.
#[test]
fn a_broken_depth_copy_shader_is_named_in_the_error() {
    let host = Host::of(msaa_host(), vec3(0.0, 0.7, 3.0), vec3(0.0, 0.5, 0.0));
    let dir = common::shader_folder(&[("depth_resolve.wgsl", "fn broken(")]);
    let settings = PlayerSettings {
        shader_dir: Some(dir.path().to_path_buf()),
        ..host.settings()
    };
    let effect = preset("campfire");
    let mut fire = Player::new(&host.device, &host.queue, &effect, settings).expect("player");
    fire.add_instance(host.place(Mat4::IDENTITY), 3)
        .expect("instance");
    let mut enc = host.device.create_command_encoder(&Default::default());
    let error = (fire.record(&mut enc, &host.camera, Some(&host.depth_view)))
        .expect_err("no depth copy without its shader")
        .to_string();
    assert!(
        error.contains("the depth copy's shader failed") && error.contains("depth_resolve.wgsl"),
        "{error}"
    );
}

/// The mean absolute difference of two frames' colour channels.
fn mean_difference(a: &Frame, b: &Frame) -> f64 {
    let sum: f64 = (a.rgba.iter().zip(&b.rgba))
        .map(|(p, q)| (0..3).map(|c| f64::from((p[c] - q[c]).abs())).sum::<f64>())
        .sum();
    sum / (3 * a.rgba.len()) as f64
}

/// A depth-stencil host (`Depth24PlusStencil8`): its depth aspect is sampled.
#[test]
fn depth_stencil_hosts_hide_the_fire() {
    let kind = HostKind {
        depth: wgpu::TextureFormat::Depth24PlusStencil8,
        ..HostKind::default()
    };
    for path in ALL_PATHS {
        hides_the_fire_in(kind.clone(), &on_path(path), true);
    }
}

/// A z-up host tells the player so: the same scene turned into its world draws the same
/// image as the y-up host's, the fire rising along +Z, and the player reports positions
/// in the host's world.
#[test]
fn z_up_hosts_see_the_preset_upright() {
    let effect = on_path(ignis::effect::DrawPath::Billboard);
    let y_up = hides_the_fire_in(HostKind::default(), &effect, true);
    let kind = HostKind {
        z_up: true,
        ..HostKind::default()
    };
    let z_up = hides_the_fire_in(kind.clone(), &effect, true);
    let mean = mean_difference(&y_up, &z_up);
    assert!(
        mean < 0.2 / 255.0,
        "the z-up image differs by {mean} on average"
    );
    let host = Host::of(kind, Vec3::ONE, Vec3::ZERO);
    let mut fire = host.player(&effect);
    let id = fire
        .add_instance(host.place(Mat4::IDENTITY), 3)
        .expect("instance");
    advance(&mut [&mut fire], &host, 60);
    let positions = fire.particle_positions(id).expect("positions");
    let mean_up = positions.iter().map(|p| p.z).sum::<f32>() / positions.len() as f32;
    let mean_y = positions.iter().map(|p| p.y.abs()).sum::<f32>() / positions.len() as f32;
    assert!(
        mean_up > 0.3 && mean_y < 0.3,
        "mean height {mean_up} m, |y| {mean_y} m"
    );
    assert!(
        (fire.transform(id).expect("instance") - host.place(Mat4::IDENTITY))
            .abs_diff_eq(Mat4::ZERO, 1e-6)
    );
}

/// A device with WebGPU's downlevel limits: `Player::new` returns an error naming the
/// limit, both values and the fix; with `ignis::required_limits()` the fire plays.
#[test]
fn downlevel_devices_get_an_error_naming_each_limit() {
    let (device, queue) = host::host_device(Some(wgpu::Limits::downlevel_defaults()));
    let settings = PlayerSettings::new(host::COLOR);
    let err = Player::new(&device, &queue, &preset("campfire"), settings)
        .err()
        .expect("downlevel limits refused");
    let message = err.to_string();
    assert!(
        matches!(&err, ignis::PlayerError::DeviceLimits(m) if m.len() == 1),
        "{message}"
    );
    for part in [
        "max_storage_buffers_per_shader_stage is 4 on this device, ignis needs 8",
        "required_limits()",
    ] {
        assert!(message.contains(part), "{message:?} lacks {part:?}");
    }
    let kind = HostKind {
        limits: Some(ignis::required_limits()),
        ..HostKind::default()
    };
    hides_the_fire_in(kind, &preset("campfire"), true);
}

/// A depth the player cannot sample is an error naming the fix, and the fire still
/// shows: a transient attachment (the host draws the particles in its one pass, tested
/// by that pass's depth), a depth without `TEXTURE_BINDING`, a player made for another
/// depth format.
#[test]
fn a_depth_the_player_cannot_sample_is_an_error_and_the_fire_still_shows() {
    let (eye, target) = (vec3(0.0, 0.7, 3.0), vec3(0.0, 0.5, 0.0));
    let transient = HostKind {
        transient_depth: true,
        ..HostKind::default()
    };
    let host = Host::of(transient, eye, target);
    let mut fire = host.player(&preset("campfire"));
    fire.add_instance(Mat4::IDENTITY, 3).expect("instance");
    advance(&mut [&mut fire], &host, 90);
    let depth = host.depth.create_view(&Default::default());
    let mut enc = host.device.create_command_encoder(&Default::default());
    fire.advance(1.0 / 60.0);
    let err = fire.record(&mut enc, &host.camera, Some(&depth)).err();
    let message = err.map(|e| e.to_string()).unwrap_or_default();
    assert!(message.contains("TRANSIENT_ATTACHMENT"), "{message:?}");
    host.draw_opaque(&mut enc, [0.0; 3], &[wall()], |pass| fire.draw(pass));
    let frame = host.read_back(enc);
    let lit = |f: &Frame, left: bool| {
        (0..f.rgba.len())
            .filter(|i| (i % (SIZE.0 as usize) < (SIZE.0 as usize) / 2) == left)
            .filter(|&i| f.rgba[i][0] > 0.25 && differs(f.rgba[i], [0.2, 0.3, 0.4, 1.0], 1e-3))
            .count()
    };
    assert!(
        lit(&frame, false) > 150,
        "{} fire pixels beside the wall",
        lit(&frame, false)
    );
    assert_eq!(lit(&frame, true), 0, "fire drawn over the wall");

    // A sampleable-looking host whose depth lacks TEXTURE_BINDING, and a player made for
    // Depth24Plus handed a Depth32Float.
    let host = Host::new(eye, target);
    let plain = host.device.create_texture(&wgpu::TextureDescriptor {
        label: None,
        size: host.depth.size(),
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: host::DEPTH,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
        view_formats: &[],
    });
    let mut fire = host.player(&preset("campfire"));
    let mut other = Player::new(
        &host.device,
        &host.queue,
        &preset("campfire"),
        PlayerSettings {
            depth_format: Some(wgpu::TextureFormat::Depth24Plus),
            ..host.settings()
        },
    )
    .expect("player");
    let mut enc = host.device.create_command_encoder(&Default::default());
    let view = plain.create_view(&Default::default());
    let err = fire.record(&mut enc, &host.camera, Some(&view)).err();
    let message = err.map(|e| e.to_string()).unwrap_or_default();
    assert!(message.contains("without TEXTURE_BINDING"), "{message:?}");
    let depth = host.depth.create_view(&Default::default());
    let err = other.record(&mut enc, &host.camera, Some(&depth)).err();
    let message = err.map(|e| e.to_string()).unwrap_or_default();
    assert!(
        message.contains("Depth32Float") && message.contains("Depth24Plus"),
        "{message:?}"
    );
}

/// Records `frames` frames of every player and waits for the GPU after each, so that the
/// light estimate's readbacks complete (a host's frames do this over time).
fn advance_and_wait(players: &mut [&mut Player], host: &Host, frames: u32) {
    for _ in 0..frames {
        advance(players, host, 1);
        let _ = host.device.poll(wgpu::PollType::wait_indefinitely());
    }
}

/// The effect's light is where its light is: still particles at one point give a light
/// there (in the host's world: the instance's place, a z-up world turned), of their colour,
/// with no spread; its power adds up per particle, goes as the sprite's area and the
/// intensity. A second instance of the batch, younger, has its own light at its own place.
#[test]
fn the_effect_light_sits_on_the_particles_with_their_colour_and_power() {
    let lit = |kind: HostKind, size_m: f32, intensity: f32| {
        let host = Host::of(kind, vec3(0.0, 1.0, 4.0), vec3(0.0, 0.5, 0.0));
        let mut disc = still_disc(0.0);
        disc.emitters[0].look.size_m = ignis::effect::Param::Constant(size_m);
        disc.emitters[0].look.intensity = intensity;
        let mut player = host.player(&disc);
        player.set_light_estimate(true);
        let id = player
            .add_instance(Mat4::from_translation(vec3(1.0, 2.0, 3.0)), 1)
            .expect("instance");
        advance_and_wait(&mut [&mut player], &host, 30);
        // Added later, so it has fewer particles than the first (its own sums, not the
        // first's at its place).
        let other = player
            .add_instance(Mat4::from_translation(vec3(-2.0, 0.5, 1.0)), 2)
            .expect("instance");
        advance_and_wait(&mut [&mut player], &host, 30);
        let alive = |id| player.count_particles(id).expect("count")[0].alive;
        let light = |id| player.effect_light(id).expect("a light");
        let second = (light(other), alive(other));
        ((light(id), alive(id)), second)
    };
    let ((light, alive), (other, other_alive)) = lit(HostKind::default(), 1.0, 1.0);
    assert!(alive >= 3, "{alive} particles alive");
    assert!(
        other_alive >= 1 && other_alive < alive,
        "{other_alive} of {alive}"
    );
    assert!(
        other.position.abs_diff_eq(vec3(-2.0, 0.7, 1.0), 1e-5),
        "{other:?}"
    );
    // Its power is its own particles' (read two frames behind their count): a whole
    // number of the first's particles, fewer than the first's.
    let each = light.power / alive as f32;
    let particles = other.power / each;
    assert!(
        (particles - particles.round()).abs() < 1e-3
            && particles.round() >= 1.0
            && particles.round() < alive as f32,
        "{light:?} of {alive}, {other:?} of {other_alive}"
    );
    let [r, g, b] = light.color;
    assert!(
        (r - 1.0).abs() < 1e-6 && (g - 0.8).abs() < 1e-5 && (b - 0.6).abs() < 1e-5,
        "{light:?}"
    );
    assert!(light.radius_m < 1e-2, "{light:?}");
    let luma =
        0.2126 * light.rgb_power[0] + 0.7152 * light.rgb_power[1] + 0.0722 * light.rgb_power[2];
    assert!((light.power - luma).abs() < 1e-5 * luma, "{light:?}");
    let ((bigger, _), _) = lit(HostKind::default(), 2.0, 1.0);
    let ((brighter, _), _) = lit(HostKind::default(), 1.0, 300.0);
    assert!(
        (bigger.power / light.power - 4.0).abs() < 1e-4,
        "{bigger:?}"
    );
    assert!(
        (brighter.power / light.power - 300.0).abs() < 1e-2,
        "{brighter:?}"
    );
    // Still no spread, whatever the power (the brighter one's is well over 1): the spread
    // is the power-weighted mean square distance about the centre, not scaled by it.
    for l in [&bigger, &brighter] {
        assert!(l.radius_m < 1e-2, "{l:?}");
    }
    // A z-up host on the least device the player takes.
    let z_up = HostKind {
        z_up: true,
        limits: Some(ignis::required_limits()),
        ..HostKind::default()
    };
    let ((turned, _), _) = lit(z_up, 1.0, 1.0);
    assert!(
        turned.position.abs_diff_eq(vec3(1.0, 2.0, 3.2), 1e-5),
        "{turned:?}"
    );
}

/// The light's centre and spread sum every workgroup's partials: a crowd of still
/// particles on a 0.5 m sphere over several workgroups an instance (256 slots each), and a
/// younger second instance of the batch, have their lights at their particles' centres,
/// with centre and spread on that sphere (|centre − origin|² + spread² = 0.25 m²).
#[test]
fn a_crowd_over_several_workgroups_has_its_light_at_its_particles_centre() {
    let host = Host::new(vec3(0.0, 1.0, 4.0), vec3(0.0, 0.5, 0.0));
    let mut disc = still_disc(0.0);
    disc.emitters[0].capacity = 1024;
    disc.emitters[0].spawn_rate_per_sec = ignis::effect::Param::Constant(600.0);
    disc.emitters[0].shape = ignis::effect::Shape::Sphere {
        radius_m: 0.5,
        surface_only: true,
    };
    let mut player = host.player(&disc);
    player.set_light_estimate(true);
    let place = |p: &mut Player, at: Vec3, seed| {
        p.add_instance(Mat4::from_translation(at), seed)
            .expect("instance")
    };
    let first = place(&mut player, vec3(1.0, 2.0, 3.0), 1);
    advance_and_wait(&mut [&mut player], &host, 30);
    let second = place(&mut player, vec3(-2.0, 0.5, 1.0), 2);
    advance_and_wait(&mut [&mut player], &host, 30);
    for (id, origin, least) in [
        (first, vec3(1.0, 2.2, 3.0), 513),
        (second, vec3(-2.0, 0.7, 1.0), 257),
    ] {
        let at = player.particle_positions(id).expect("positions");
        assert!(at.len() >= least, "{} particles", at.len());
        let centre = at.iter().sum::<Vec3>() / at.len() as f32;
        let light = player.effect_light(id).expect("a light");
        // Read two frames behind the particles: a few births fewer.
        let on_sphere = light.position.distance_squared(origin) + light.radius_m.powi(2);
        assert!(
            light.position.distance(centre) < 0.01 && (on_sphere - 0.25).abs() < 1e-3,
            "{light:?} against {centre}: {on_sphere} m²"
        );
    }
}

/// The campfire's light flickers as its flames do, from where they burn, two frames behind
/// the simulation, and costs nothing unless asked for.
#[test]
fn the_campfire_light_flickers_from_its_flames() {
    let host = Host::new(vec3(0.0, 1.0, 4.0), vec3(0.0, 0.5, 0.0));
    let mut fire = host.player(&preset("campfire"));
    let id = fire.add_instance(Mat4::IDENTITY, 3).expect("instance");
    advance_and_wait(&mut [&mut fire], &host, 30);
    assert_eq!(fire.effect_light(id), None, "no light without the estimate");
    fire.set_light_estimate(true);
    // A frame's sums are copied in its record, mapped at the next, read at the one after.
    advance_and_wait(&mut [&mut fire], &host, 2);
    assert_eq!(
        fire.effect_light(id),
        None,
        "read before the GPU could map it"
    );
    advance(&mut [&mut fire], &host, 1);
    assert!(
        fire.effect_light(id).is_some(),
        "the light arrives two frames later"
    );
    let mut powers = Vec::new();
    for _ in 0..40 {
        advance_and_wait(&mut [&mut fire], &host, 1);
        let light = fire.effect_light(id).expect("light");
        assert!(
            light.position.y > 0.1 && light.position.y < 1.5,
            "{light:?}"
        );
        assert!(
            light.position.x.abs() < 0.5 && light.position.z.abs() < 0.5,
            "{light:?}"
        );
        assert!(
            light.color[0] == 1.0 && light.color[2] < light.color[1],
            "warm: {light:?}"
        );
        powers.push(f64::from(light.power));
    }
    let mean = powers.iter().sum::<f64>() / powers.len() as f64;
    let sd = (powers.iter().map(|p| (p - mean).powi(2)).sum::<f64>() / powers.len() as f64).sqrt();
    eprintln!("campfire light: power {mean:.4} ± {sd:.4}");
    assert!(mean > 0.0 && sd / mean > 0.01, "no flicker: {mean} ± {sd}");
    fire.set_light_estimate(false);
    assert_eq!(fire.effect_light(id), None, "the estimate turned off");
}

/// Off, the estimate records nothing for an effect without lit layers (the torch's
/// flames and sparks): a frame's dispatches grow while it is on, and shrink back after.
#[test]
fn the_light_estimate_records_nothing_while_off() {
    let host = Host::new(vec3(0.0, 1.0, 4.0), vec3(0.0, 0.5, 0.0));
    let mut flames = preset("torch");
    flames
        .emitters
        .retain(|e| e.look.blend == BlendMode::Additive && e.look.lit.is_none());
    let mut fire = host.player(&flames);
    fire.add_instance(Mat4::IDENTITY, 3).expect("instance");
    advance_and_wait(&mut [&mut fire], &host, 10);
    let off = fire.recorded_commands();
    fire.set_light_estimate(true);
    advance_and_wait(&mut [&mut fire], &host, 1);
    let on = fire.recorded_commands();
    assert!(on.dispatches > off.dispatches, "on {on:?}, off {off:?}");
    fire.set_light_estimate(false);
    advance_and_wait(&mut [&mut fire], &host, 1);
    assert_eq!(fire.recorded_commands(), off, "off again");
}

/// An instance whose particles emit no light (every layer at intensity 0) has no effect
/// light while the estimate is on: `None`, not a light at 0 / 0.
#[test]
fn an_instance_whose_particles_emit_nothing_has_no_effect_light() {
    let host = Host::new(vec3(0.0, 1.0, 4.0), vec3(0.0, 0.5, 0.0));
    let mut dark = preset("campfire");
    for e in &mut dark.emitters {
        e.look.intensity = 0.0;
    }
    let mut fire = host.player(&dark);
    let id = fire.add_instance(Mat4::IDENTITY, 3).expect("instance");
    fire.set_light_estimate(true);
    advance_and_wait(&mut [&mut fire], &host, 6);
    let counts = fire.count_particles(id).expect("count");
    assert!(counts.iter().any(|c| c.alive > 0), "{counts:?}");
    assert_eq!(fire.effect_light(id), None);
    assert_eq!(fire.light_estimate_error(), None);
}

/// A broken `light.wgsl` in the player's shader folder: the estimate says why it has no
/// light (naming the file) and the fire plays on; fixed and reloaded, the light comes.
#[test]
fn a_broken_light_shader_is_named_and_a_fixed_one_brings_the_light_back() {
    let host = Host::new(vec3(0.0, 1.0, 4.0), vec3(0.0, 0.5, 0.0));
    let dir = common::shader_folder(&[("light.wgsl", "fn broken(")]);
    let settings = PlayerSettings {
        shader_dir: Some(dir.path().to_path_buf()),
        ..host.settings()
    };
    let mut fire =
        Player::new(&host.device, &host.queue, &preset("campfire"), settings).expect("player");
    let id = fire.add_instance(Mat4::IDENTITY, 3).expect("instance");
    fire.set_light_estimate(true);
    advance_and_wait(&mut [&mut fire], &host, 4);
    assert_eq!(fire.effect_light(id), None);
    let error = fire
        .light_estimate_error()
        .expect("the light's error")
        .to_string();
    assert!(error.contains("light.wgsl"), "{error}");
    assert!(
        fire.count_particles(id)
            .expect("count")
            .iter()
            .any(|c| c.alive > 0),
        "the fire plays on"
    );
    let good = ignis::testing::shaders::EMBEDDED
        .iter()
        .find(|(name, _)| *name == "light.wgsl")
        .expect("light.wgsl")
        .1;
    std::fs::write(dir.path().join("light.wgsl"), good).expect("write");
    fire.reload_shader(dir.path(), "light.wgsl")
        .expect("the fixed shader builds");
    assert_eq!(fire.light_estimate_error(), None);
    advance_and_wait(&mut [&mut fire], &host, 4);
    assert!(fire.effect_light(id).is_some(), "the light is back");
}

/// Every shader a player builds reloads from a host's folder: a broken one is refused and
/// named, the good one builds again. The depth copy (an MSAA host's) and the haze are
/// built at their first use; the depth copy is built here, the haze in `tests/haze.rs`.
#[test]
fn every_player_shader_reloads_and_a_broken_one_is_named() {
    let host = Host::of(msaa_host(), vec3(0.0, 0.7, 3.0), vec3(0.0, 0.5, 0.0));
    let mut fire = host.player(&preset("campfire"));
    fire.add_instance(host.place(Mat4::IDENTITY), 3)
        .expect("instance");
    assert!(fire.tile_pass().is_some(), "this adapter has the tiles");
    let mut enc = host.device.create_command_encoder(&Default::default());
    (fire.record(&mut enc, &host.camera, Some(&host.depth_view))).expect("record");
    host.queue.submit([enc.finish()]);
    let good = common::shader_folder(&[]);
    let player_shaders = ignis::PLAYER_SHADERS
        .iter()
        .filter(|e| **e != "haze_apply.wgsl");
    for entry in player_shaders {
        let broken = common::shader_folder(&[(entry, "fn broken(")]);
        let Err(err) = fire.reload_shader(broken.path(), entry) else {
            panic!("a broken {entry} is refused");
        };
        assert!(err.to_string().contains(entry), "{entry}: {err}");
        fire.reload_shader(good.path(), entry)
            .unwrap_or_else(|e| panic!("{entry} builds again: {e}"));
    }
    // Not a player's shader (the host's composite reloads it): nothing to rebuild.
    let broken = common::shader_folder(&[("bloom.wgsl", "fn broken(")]);
    fire.reload_shader(broken.path(), "bloom.wgsl")
        .expect("the player ignores a shader it does not build");
}

/// A new seed changes the particles born from then on, in a batch and in a simulation of
/// the instance's own, alike (a packed pool's lives, drawn from the seed, included); the
/// same seed again changes nothing, and a removed instance's seed cannot be set.
#[test]
fn a_new_seed_changes_the_particles_born_from_then_on() {
    let host = Host::new(vec3(0.0, 1.0, 4.0), vec3(0.0, 0.5, 0.0));
    let mut torch = preset("torch");
    for e in &mut torch.emitters {
        e.packed_state = !e.stateless && !e.tiny_state;
    }
    let reseeded = |batched: bool| {
        let settings = PlayerSettings {
            batch_instances: batched,
            ..host.settings()
        };
        let make = || {
            let mut p =
                Player::new(&host.device, &host.queue, &torch, settings.clone()).expect("player");
            let id = p.add_instance(Mat4::IDENTITY, 3).expect("instance");
            (p, id)
        };
        let (mut kept, k) = make();
        let (mut same, s) = make();
        let (mut changed, c) = make();
        advance_and_wait(&mut [&mut kept, &mut same, &mut changed], &host, 10);
        assert!(same.set_seed(s, 3));
        assert!(changed.set_seed(c, 9));
        advance_and_wait(&mut [&mut kept, &mut same, &mut changed], &host, 10);
        let of = |p: &Player, id| -> Vec<_> {
            (0..torch.emitters.len())
                .map(|e| p.particles(id, e).expect("particles"))
                .collect()
        };
        assert_eq!(
            of(&same, s),
            of(&kept, k),
            "batched {batched}: the same seed"
        );
        let new = of(&changed, c);
        assert_ne!(new, of(&kept, k), "batched {batched}: a new seed");
        assert!(changed.remove_instance(c));
        assert!(
            !changed.set_seed(c, 5),
            "batched {batched}: a removed instance"
        );
        new
    };
    assert_eq!(
        reseeded(true),
        reseeded(false),
        "batched and on its own alike"
    );
}

/// An edit that a simulation of its own refuses (a pool over the device's limit) leaves
/// every instance as it was, the ones that took the edit before the refusal and the ones
/// that never saw it: each emitter keeps its pool, though the edit also reordered them.
#[test]
fn a_refused_edit_leaves_every_own_instance_as_it_was() {
    let host = Host::new(vec3(0.0, 1.0, 4.0), vec3(0.0, 0.5, 0.0));
    let settings = PlayerSettings {
        batch_instances: false,
        ..host.settings()
    };
    let torch = preset("torch");
    let mut player = Player::new(&host.device, &host.queue, &torch, settings).expect("player");
    let ids = [(0.0, 5), (2.0, 6), (-2.0, 7)].map(|(x, seed)| {
        player
            .add_instance(Mat4::from_translation(vec3(x, 0.0, 0.0)), seed)
            .expect("instance")
    });
    advance_and_wait(&mut [&mut player], &host, 30);
    let pools = |p: &Player| -> Vec<Vec<_>> {
        let all = ids
            .iter()
            .flat_map(|id| (0..torch.emitters.len()).map(move |e| (*id, e)));
        all.map(|(id, e)| p.particles(id, e).expect("particles"))
            .collect()
    };
    let before = pools(&player);
    let mut refused = torch.clone();
    refused.emitters.reverse();
    let limit = host.device.limits().max_storage_buffer_binding_size;
    refused.emitters[0].capacity = u32::try_from(limit / 32 + 1).expect("a valid capacity");
    assert!(
        refused.validate().is_ok(),
        "valid, only over the device's limit"
    );
    let err = player
        .set_effect(&refused)
        .expect_err("over the device's limit");
    assert!(err.to_string().contains(&refused.emitters[0].name), "{err}");
    assert_eq!(player.effect(), &torch, "a refused edit changes nothing");
    assert!(pools(&player) == before, "every instance keeps its pools");
    advance_and_wait(&mut [&mut player], &host, 2);
    for id in ids {
        let alive: u32 = player
            .count_particles(id)
            .expect("count")
            .iter()
            .map(|c| c.alive)
            .sum();
        assert!(alive > 0, "the instance plays on");
    }
}

/// A switched-off emitter is counted as empty, batched or on its own, though its pool
/// keeps the particles it had (switched back on, they play on).
#[test]
fn a_switched_off_emitter_counts_no_particles() {
    let host = Host::new(vec3(0.0, 1.0, 4.0), vec3(0.0, 0.5, 0.0));
    for batched in [true, false] {
        let settings = PlayerSettings {
            batch_instances: batched,
            ..host.settings()
        };
        let torch = preset("torch");
        let mut player = Player::new(&host.device, &host.queue, &torch, settings).expect("player");
        let id = player.add_instance(Mat4::IDENTITY, 3).expect("instance");
        advance_and_wait(&mut [&mut player], &host, 30);
        let mut off = torch.clone();
        off.emitters[0].enabled = false;
        player.set_effect(&off).expect("switched off");
        let counts = player.count_particles(id).expect("count");
        assert_eq!(
            counts[0],
            ignis::ParticleCount::default(),
            "batched {batched}"
        );
        assert!(
            counts[1..].iter().all(|c| c.alive > 0),
            "batched {batched}: {counts:?}"
        );
        let kept = player.particles(id, 0).expect("particles");
        assert!(
            kept.iter().any(|p| p.is_alive()),
            "batched {batched}: the pool keeps them"
        );
        let alive: u32 = counts.iter().map(|c| c.alive).sum();
        let positions = player.particle_positions(id).expect("positions");
        assert_eq!(
            positions.len(),
            alive as usize,
            "batched {batched}: positions"
        );
    }
}

/// Edits play alike batched and on their own: an emitter switched to another integrator
/// (a pipeline the player had not built) moves its particles by it in both, bit for bit;
/// a pool edit keeps an own instance's particles (batched ones restart).
#[test]
fn edits_play_alike_batched_and_on_their_own() {
    let host = Host::new(vec3(0.0, 1.0, 4.0), vec3(0.0, 0.5, 0.0));
    let torch = preset("torch");
    let mut other = torch.clone();
    other.emitters[0].integrator = match torch.emitters[0].integrator {
        ignis::effect::Integrator::Rk4 => ignis::effect::Integrator::Heun,
        _ => ignis::effect::Integrator::Rk4,
    };
    let player = |batched: bool| {
        let settings = PlayerSettings {
            batch_instances: batched,
            ..host.settings()
        };
        let mut p = Player::new(&host.device, &host.queue, &torch, settings).expect("player");
        let ids = [(0.0, 4), (1.0, 5)].map(|(x, seed)| {
            (p.add_instance(Mat4::from_translation(vec3(x, 0.0, 0.0)), seed)).expect("instance")
        });
        (p, ids)
    };
    let ((mut batched, b), (mut own, o)) = (player(true), player(false));
    let pools = |p: &Player, ids: [ignis::InstanceId; 2]| -> Vec<Vec<_>> {
        let all = ids
            .into_iter()
            .flat_map(|id| (0..torch.emitters.len()).map(move |e| (id, e)));
        all.map(|(id, e)| p.particles(id, e).expect("particles"))
            .collect()
    };
    advance_and_wait(&mut [&mut batched, &mut own], &host, 10);
    batched.set_effect(&other).expect("batched edit");
    own.set_effect(&other).expect("own edit");
    advance_and_wait(&mut [&mut batched, &mut own], &host, 10);
    assert!(
        pools(&batched, b) == pools(&own, o),
        "the new integrator, batched and own"
    );

    let mut larger = other.clone();
    larger.emitters[0].capacity *= 2;
    let alive = |p: &Player, id| p.count_particles(id).expect("count")[0].alive;
    let before = alive(&own, o[0]);
    own.set_effect(&larger).expect("own pool edit");
    assert!(
        before > 0 && alive(&own, o[0]) == before,
        "kept: {before} before"
    );
    batched.set_effect(&larger).expect("batched pool edit");
    assert_eq!(alive(&batched, b[0]), 0, "batched instances restart");
}

/// Frames advanced without a record add their steps up to the preset's `max_substeps`;
/// the excess is dropped and counted, as the stepper counts its own.
#[test]
fn steps_of_frames_not_recorded_join_up_to_the_cap_and_the_rest_are_counted_dropped() {
    let host = Host::new(vec3(0.0, 1.0, 4.0), vec3(0.0, 0.5, 0.0));
    let (_, mut player, id) = timed_torch(&host, |t| {
        t.step_secs = 1.0 / 128.0;
        t.max_substeps = 5;
    });
    // Two steps a frame: 2, 4, then 6 asked of a cap of 5 (1 dropped), then 7 (2 more).
    for _ in 0..4 {
        player.advance(2.0 / 128.0);
    }
    record_now(&mut player, &host);
    let stats = player.clock_stats();
    assert_eq!((stats.steps, stats.dropped_steps), (5, 3));
    assert_eq!(player.time_secs(id), Some(5.0 / 128.0));
}

/// An edit from fixed steps to frame deltas between an advance that planned no step and
/// the next: the frame-delta step is that frame's delta alone.
#[test]
fn a_frame_delta_step_after_a_fixed_step_edit_is_the_frames_delta() {
    let host = Host::new(vec3(0.0, 1.0, 4.0), vec3(0.0, 0.5, 0.0));
    let (effect, mut player, id) = timed_torch(&host, |t| {
        t.mode = ignis::effect::TimeMode::FixedStep;
        t.step_secs = 1.0 / 64.0;
        t.max_frame_dt_secs = 0.25;
    });
    player.advance(1.0 / 256.0);
    let mut delta = effect.clone();
    delta.time.mode = ignis::effect::TimeMode::FrameDelta;
    player.set_effect(&delta).expect("frame deltas");
    player.advance(1.0 / 32.0);
    record_now(&mut player, &host);
    assert_eq!(player.time_secs(id), Some(1.0 / 32.0));
}

/// A frame-by-frame step of a frame-delta effect is a 60 Hz frame (or the preset's
/// largest delta, when smaller).
#[test]
fn a_frame_delta_step_is_a_60_hz_frame() {
    let host = Host::new(vec3(0.0, 1.0, 4.0), vec3(0.0, 0.5, 0.0));
    let (_, mut player, id) = timed_torch(&host, |t| {
        t.mode = ignis::effect::TimeMode::FrameDelta;
        t.max_frame_dt_secs = 0.25;
    });
    player.step();
    record_now(&mut player, &host);
    assert_eq!(player.time_secs(id), Some(f64::from(1.0f32 / 60.0)));
}

/// The torch with its time settings changed by `time`, and a player of it with one
/// instance.
fn timed_torch(
    host: &Host,
    time: impl FnOnce(&mut ignis::effect::TimeSettings),
) -> (Effect, Player, ignis::InstanceId) {
    let mut effect = preset("torch");
    time(&mut effect.time);
    let mut player = host.player(&effect);
    let id = player.add_instance(Mat4::IDENTITY, 3).expect("instance");
    (effect, player, id)
}

/// Records what the player planned (no advance), and submits it.
fn record_now(player: &mut Player, host: &Host) {
    let mut enc = host.device.create_command_encoder(&Default::default());
    player.record(&mut enc, &host.camera, None).expect("record");
    host.queue.submit([enc.finish()]);
}
