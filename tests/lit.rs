#![allow(dead_code)] // the host fixture serves runtime.rs too
//! Lit smoke: six-way lightmaps (generated and brought by the user), mixed by where each
//! light is — the scene's sun and ambient, the host's point lights and the effect's own
//! light — on both draw paths, against the CPU formula; a turned puff through its turned
//! frame.

mod common;
#[path = "runtime/host.rs"]
mod host;

use glam::{Mat4, Vec3, vec3};
use host::Host;
use ignis::Player;
use ignis::effect::{BlendMode, DrawPath, Effect, Lighting, Param, SixWayMaps};
use ignis::testing::render::sixway_maps::{EXTINCTION, PUFF_SEED, puff, puff_density};

/// Where the puff hangs, and the camera (looking down −Z: the sprite's back is −Z).
const SMOKE: Vec3 = Vec3::from_array(common::SMOKE);
const EYE: Vec3 = vec3(0.0, 0.5, 4.0);

/// The flat maps' six lightmaps: +X, +Y, +Z (back), −X, −Y, −Z (front).
fn flat_six() -> [f32; 6] {
    let c = |b: u8| f32::from(b) / 255.0;
    [
        c(common::FLAT_RTBA[0]),
        c(common::FLAT_RTBA[1]),
        c(common::FLAT_RTBA[2]),
        c(common::FLAT_LBFE[0]),
        c(common::FLAT_LBFE[1]),
        c(common::FLAT_LBFE[2]),
    ]
}

/// The six-way mix on the CPU: light `rgb` from `dir` (world, towards the light) on a
/// sprite facing a camera that looks down −Z (sprite axes: +X, +Y, back = −Z).
fn six_way(maps: [f32; 6], dir: Vec3, rgb: [f32; 3]) -> [f32; 3] {
    let l = dir.normalize();
    let frame = [l.x, l.y, -l.z];
    let mut response = 0.0;
    for (a, v) in frame.iter().enumerate() {
        let map = if *v > 0.0 { maps[a] } else { maps[a + 3] };
        response += v * v * map;
    }
    rgb.map(|c| c * response)
}

/// Plays `effect` for a few frames in a host that clears to black (its depth handed
/// over, so the tiles may draw), with `setup` applied to the player; reads the last frame
/// back and says whether the tiles drew it.
fn render(effect: &Effect, setup: impl FnOnce(&mut Player)) -> (host::Frame, bool) {
    let host = Host::new(EYE, SMOKE);
    let mut player = host.player(effect);
    setup(&mut player);
    player.add_instance(Mat4::IDENTITY, 1).expect("instance");
    let mut frame = None;
    for _ in 0..3 {
        player.advance(1.0 / 60.0);
        frame = Some(host.frame([0.0; 3], &[], &mut [&mut player], true));
    }
    let tiled = player.draw_items().iter().any(|d| d.tiles);
    (frame.expect("a frame"), tiled)
}

/// The pixel at the centre of the target.
fn centre(frame: &host::Frame) -> [f32; 4] {
    let (w, h) = host::SIZE;
    frame.rgba[(h / 2 * w + w / 2) as usize]
}

fn assert_close(got: [f32; 4], want: [f32; 3], what: &str) {
    for c in 0..3 {
        assert!(
            (got[c] - want[c]).abs() <= 2e-3 * want[c].max(0.05),
            "{what}: got {got:?}, want {want:?}"
        );
    }
}

/// A sun and an ambient term light a flat-mapped puff exactly as the six-way formula
/// says, on the billboards and on the tiles; the host's point light adds its inverse
/// square (windowed), through `set_lighting`.
#[test]
fn the_six_way_mix_equals_the_cpu_formula_on_both_paths() {
    let dir = tempfile::tempdir().expect("tempdir");
    let maps = common::flat_maps(dir.path());
    let sun = vec3(0.6, 0.5, -0.62);
    let lighting = Lighting {
        sun_direction: sun.to_array(),
        sun_color: [0.9, 0.8, 0.7],
        ambient: [0.1, 0.12, 0.15],
    };
    let six = flat_six();
    let lit = six_way(six, sun, lighting.sun_color);
    let mean = six.iter().sum::<f32>() / 6.0;
    let want: [f32; 3] =
        std::array::from_fn(|c| common::ALBEDO[c] * (lit[c] + lighting.ambient[c] * mean));
    for path in [DrawPath::Billboard, DrawPath::Tiles] {
        let smoke = common::still_smoke(maps.clone(), lighting.clone(), path);
        let (frame, tiled) = render(&smoke, |_| {});
        assert_eq!(tiled, path == DrawPath::Tiles, "the tiles drew it");
        assert_close(centre(&frame), want, &format!("sun and ambient, {path:?}"));
    }
    // The host's light instead: no sun, one point light 0.8 m to the right, range 4 m.
    let point = ignis::PointLight {
        position: SMOKE + vec3(0.8, 0.0, 0.0),
        color: [2.0, 1.0, 0.5],
        range_m: 4.0,
    };
    let host_light = ignis::SceneLighting {
        sun_direction: Vec3::Y,
        sun_color: [0.0; 3],
        ambient: [0.0; 3],
        point_lights: vec![point],
        own_light: 1.0,
        glow: 1.0,
    };
    let smoke = common::still_smoke(maps, lighting, DrawPath::Billboard);
    let (frame, _) = render(&smoke, |p| {
        p.set_lighting(Some(host_light.clone()));
        // What the host set is what the player reports (the six-way export puts it back
        // from there after its passes).
        assert_eq!(p.lighting(), Some(&host_light), "the player's lighting");
    });
    let (r2, range2) = (0.64f32, 16.0f32);
    let window = (1.0 - (r2 / range2).powi(2)).powi(2);
    let e = point.color.map(|c| c * window / r2);
    let lit = six_way(six, Vec3::X, e);
    let want: [f32; 3] = std::array::from_fn(|c| common::ALBEDO[c] * lit[c]);
    assert_close(centre(&frame), want, "a host point light");
}

/// A turned puff's six-way frame turns with it: spun about a quarter turn counter-clockwise
/// (2,160° a second, drawn about 2.5 steps of 1/60 s after its birth), its own −Y axis
/// faces a sun from +X, so its bottom (−Y) map lights it, not its top; and its own +X axis
/// faces a sun from above (+Y), so its right map lights it, not its left.
#[test]
fn a_turned_puff_is_lit_through_its_turned_frame() {
    let dir = tempfile::tempdir().expect("tempdir");
    let six = flat_six();
    // (towards the sun, the map facing it after the turn, the opposite one (`flat_six`'s
    // order), the tolerance: within the turn's uncertainty (±18°) the other axis's maps
    // weigh at most sin² 18° ≈ 0.1)
    for (sun, facing, opposite, tolerance) in
        [([1.0, 0.0, 0.0], 4, 1, 0.08), ([0.0, 1.0, 0.0], 0, 3, 0.12)]
    {
        let lighting = Lighting {
            sun_direction: sun,
            sun_color: [1.0, 1.0, 1.0],
            ambient: [0.0; 3],
        };
        let mut smoke =
            common::still_smoke(common::flat_maps(dir.path()), lighting, DrawPath::Billboard);
        smoke.emitters[0].look.spin_deg_per_s = Param::Constant(2160.0);
        let (frame, _) = render(&smoke, |_| {});
        let want: [f32; 3] = std::array::from_fn(|c| common::ALBEDO[c] * six[facing]);
        let got = centre(&frame);
        for c in 0..3 {
            assert!(
                (got[c] / want[c] - 1.0).abs() < tolerance,
                "sun towards {sun:?}: got {got:?}, the map facing it gives {want:?} (the \
                 opposite one {:?})",
                common::ALBEDO.map(|a| a * six[opposite])
            );
        }
    }
}

/// The effect's own light (its additive layers, measured on the GPU the same frame)
/// lights its smoke: a still fire below the puff lights it from below by its power over
/// the squared distance, in its colour — the power the effect light reports — and as
/// much with the estimate off.
#[test]
fn the_effects_own_light_lights_its_smoke_from_where_it_burns() {
    let dir = tempfile::tempdir().expect("tempdir");
    let dark = Lighting {
        sun_direction: [0.0, 1.0, 0.0],
        sun_color: [0.0; 3],
        ambient: [0.0; 3],
    };
    let mut effect = common::still_smoke(common::flat_maps(dir.path()), dark, DrawPath::Billboard);
    if let Some(l) = effect.emitters[0].look.lit.as_mut() {
        l.self_light = 1.0;
    }
    // A still, additive glow 0.6 m below the smoke, drawn first (its light is what counts).
    let mut fire = common::still_burst(2, 100.0);
    fire.name = "fire".into();
    fire.capacity = 4;
    fire.transform.position_m = (SMOKE - vec3(0.0, 0.6, 0.0)).into();
    fire.look.size_m = Param::Constant(0.3);
    fire.look.blend = BlendMode::Additive;
    fire.look.draw_path = DrawPath::Billboard;
    fire.look.color_over_life = common::flat_color([1.0, 0.5, 0.2, 1.0]);
    effect.emitters.push(fire);
    // The power the estimate reports (tested against its closed form in runtime.rs).
    let host = Host::new(EYE, SMOKE);
    let play = |estimate: bool| {
        let mut player = host.player(&effect);
        player.set_light_estimate(estimate);
        let id = player.add_instance(Mat4::IDENTITY, 1).expect("instance");
        let (mut light, mut frame) = (None, None);
        for _ in 0..6 {
            player.advance(1.0 / 60.0);
            frame = Some(host.frame([0.0; 3], &[], &mut [&mut player], true));
            let _ = host.device.poll(wgpu::PollType::wait_indefinitely());
            light = player.effect_light(id).or(light);
        }
        (frame.expect("a frame"), light)
    };
    let (frame, light) = play(true);
    let light = light.expect("the fire's light");
    // The smoke's share of its fire's light is the same whether or not the host reads
    // the estimate back.
    let (unread, none) = play(false);
    assert_eq!(none, None);
    assert!(
        unread.rgba == frame.rgba,
        "the smoke unlit without the estimate"
    );
    assert!(
        light
            .position
            .abs_diff_eq(SMOKE - vec3(0.0, 0.6, 0.0), 1e-5)
    );
    let e = light.rgb_power.map(|c| c / 0.36);
    let lit = six_way(flat_six(), -Vec3::Y, e);
    let want: [f32; 3] = std::array::from_fn(|c| common::ALBEDO[c] * lit[c]);
    // The centre pixel: the smoke over the fire's glow (the fire lies 0.6 m lower, out of
    // the centre's way: its sprite is 0.3 m wide).
    assert_close(centre(&frame), want, "lit by its own fire");
    let warm = centre(&frame);
    assert!(warm[0] > warm[1] && warm[1] > warm[2], "warm: {warm:?}");
}

/// The built-in puff lit from its right is brighter on its right; lit from behind, its
/// thin rim glows and its thick core does not (and the other way round lit from the
/// front).
#[test]
fn a_puff_is_brighter_toward_its_light_and_glows_at_the_rim_when_backlit() {
    let lighting = |dir: Vec3| Lighting {
        sun_direction: dir.to_array(),
        sun_color: [1.0; 3],
        ambient: [0.0; 3],
    };
    let (w, h) = host::SIZE;
    let luma = |p: [f32; 4]| p[0] + p[1] + p[2];
    let mean_where = |frame: &host::Frame, keep: &dyn Fn(f32, f32) -> bool| {
        let (mut sum, mut n) = (0.0f64, 0u32);
        for y in 0..h {
            for x in 0..w {
                let (dx, dy) = (x as f32 - w as f32 / 2.0, y as f32 - h as f32 / 2.0);
                if keep(dx, dy) {
                    sum += f64::from(luma(frame.rgba[(y * w + x) as usize]));
                    n += 1;
                }
            }
        }
        sum / f64::from(n.max(1))
    };
    for path in [DrawPath::Billboard, DrawPath::Tiles] {
        let right = common::still_smoke(SixWayMaps::Puff, lighting(Vec3::X), path);
        let (frame, _) = render(&right, |_| {});
        let (r, l) = (
            mean_where(&frame, &|dx, _| dx > 5.0),
            mean_where(&frame, &|dx, _| dx < -5.0),
        );
        assert!(r > 1.5 * l, "{path:?}: right {r}, left {l}");
        // Core and rim, from the puff's radius on screen (its farthest lit pixel).
        let radius = (0..w * h)
            .filter(|&i| luma(frame.rgba[i as usize]) > 1e-3)
            .map(|i| (i % w) as f32 - w as f32 / 2.0)
            .map(f32::abs)
            .fold(0.0, f32::max);
        assert!(radius > 15.0, "{path:?}: the puff is {radius} pixels wide");
        let core = |dx: f32, dy: f32| dx.hypot(dy) < 0.25 * radius;
        let rim = |dx: f32, dy: f32| (0.6 * radius..0.9 * radius).contains(&dx.hypot(dy));
        let back = common::still_smoke(SixWayMaps::Puff, lighting(-Vec3::Z), path);
        let (frame, _) = render(&back, |_| {});
        let (c, e) = (mean_where(&frame, &core), mean_where(&frame, &rim));
        assert!(e > 1.5 * c, "{path:?} back-lit: rim {e}, core {c}");
        let front = common::still_smoke(SixWayMaps::Puff, lighting(Vec3::Z), path);
        let (frame, _) = render(&front, |_| {});
        let (c, e) = (mean_where(&frame, &core), mean_where(&frame, &rim));
        assert!(c > e, "{path:?} front-lit: rim {e}, core {c}");
    }
}

/// The generated maps: the same for the same seed, another puff for another; lit from
/// the top brightest on top, from the right on the right; the coverage is the density's
/// projected opacity, integrated here independently (four times finer along the view).
#[test]
fn generated_six_way_maps_are_deterministic_lit_as_named_and_cover_as_the_density() {
    let a = puff(PUFF_SEED);
    assert_eq!(a, puff(PUFF_SEED), "bit-identical for one seed");
    assert_ne!(
        a.rtba,
        puff(PUFF_SEED + 1).rtba,
        "another seed, another puff"
    );
    let (w, h) = a.rtba.dimensions();
    // Mean of channel `c` of `img` over the covered texels where `keep`.
    let mean = |img: &image::Rgba32FImage, c: usize, keep: &dyn Fn(u32, u32) -> bool| {
        let (mut s, mut n) = (0.0f64, 0u32);
        for (x, y, p) in img.enumerate_pixels() {
            if keep(x, y) && a.rtba.get_pixel(x, y)[3] > 0.05 {
                s += f64::from(p[c]);
                n += 1;
            }
        }
        s / f64::from(n.max(1))
    };
    let (top, bottom) = (
        mean(&a.rtba, 1, &|_, y| y < h / 2),
        mean(&a.rtba, 1, &|_, y| y >= h / 2),
    );
    assert!(
        top > bottom + 0.15,
        "lit from +Y: top {top}, bottom {bottom}"
    );
    let (right, left) = (
        mean(&a.rtba, 0, &|x, _| x >= w / 2),
        mean(&a.rtba, 0, &|x, _| x < w / 2),
    );
    assert!(
        right > left + 0.15,
        "lit from +X: right {right}, left {left}"
    );
    let (lleft, lright) = (
        mean(&a.lbfe, 0, &|x, _| x < w / 2),
        mean(&a.lbfe, 0, &|x, _| x >= w / 2),
    );
    assert!(
        lleft > lright + 0.15,
        "lit from −X: left {lleft}, right {lright}"
    );
    // Coverage: 1 − exp(−σ ∫ ρ dz) over the sprite's depth [−1, 1], at the texel centres.
    let n = 4 * w;
    let mut worst = 0.0f32;
    for (x, y, p) in a.rtba.enumerate_pixels() {
        let cx = (x as f32 + 0.5) / w as f32 * 2.0 - 1.0;
        let cy = 1.0 - (y as f32 + 0.5) / h as f32 * 2.0;
        let tau: f32 = (0..n)
            .map(|k| {
                let z = (k as f32 + 0.5) / n as f32 * 2.0 - 1.0;
                puff_density(PUFF_SEED, 0.25, [cx, cy, z])
            })
            .sum::<f32>()
            * (2.0 / n as f32)
            * EXTINCTION;
        worst = worst.max((p[3] - (1.0 - (-tau).exp())).abs());
    }
    assert!(worst < 0.03, "coverage differs by {worst}");
}

/// Impossible lit settings are refused with the field named and the fix; a missing or
/// mismatched pair of maps draws the built-in puff and says which file and why.
#[test]
fn bad_lit_settings_and_missing_maps_name_the_field_or_the_file() {
    let mut effect =
        common::still_smoke(SixWayMaps::Puff, Lighting::default(), DrawPath::Billboard);
    effect.emitters[0].look.blend = BlendMode::Additive;
    if let Some(l) = effect.emitters[0].look.lit.as_mut() {
        l.albedo[1] = 1.5;
    }
    effect.lighting.sun_direction = [0.0; 3];
    let errors = effect.validate().expect_err("refused");
    let text: Vec<String> = errors.iter().map(ToString::to_string).collect();
    let has = |path: &str, what: &str| text.iter().any(|t| t.starts_with(path) && t.contains(what));
    assert!(
        has("emitters[0].look.lit", "alpha-blended layers only"),
        "{text:?}"
    );
    assert!(
        has("emitters[0].look.lit.albedo[1]", "must be ≤ 1"),
        "{text:?}"
    );
    assert!(has("lighting.sun_direction", "zero vector"), "{text:?}");

    let dir = tempfile::tempdir().expect("tempdir");
    let missing = SixWayMaps::Images {
        rtba: dir.path().join("nowhere_rtba.png").display().to_string(),
        lbfe: dir.path().join("nowhere_lbfe.png").display().to_string(),
    };
    image::RgbaImage::new(8, 8)
        .save(dir.path().join("small.png"))
        .expect("png");
    image::RgbaImage::new(16, 16)
        .save(dir.path().join("large.png"))
        .expect("png");
    let mismatched = SixWayMaps::Images {
        rtba: dir.path().join("large.png").display().to_string(),
        lbfe: dir.path().join("small.png").display().to_string(),
    };
    for (maps, file, why) in [
        (missing, "nowhere_rtba.png", "cannot read it"),
        (mismatched, "small.png", "the pair must match"),
    ] {
        let smoke = common::still_smoke(maps, Lighting::default(), DrawPath::Billboard);
        let mut errors = Vec::new();
        let (frame, _) = render(&smoke, |_| {});
        let host = Host::new(EYE, SMOKE);
        let mut player = host.player(&smoke);
        player.add_instance(Mat4::IDENTITY, 1).expect("instance");
        player.advance(1.0 / 60.0);
        let _ = host.frame([0.0; 3], &[], &mut [&mut player], true);
        errors.extend(player.sprite_errors());
        assert!(
            errors.len() == 1 && errors[0].1.contains(file) && errors[0].1.contains(why),
            "{errors:?}"
        );
        // The built-in puff is drawn instead: the smoke still shows.
        let lit = frame
            .rgba
            .iter()
            .filter(|p| p[0] + p[1] + p[2] > 1e-3)
            .count();
        assert!(lit > 100, "{lit} pixels of smoke");
    }
}
