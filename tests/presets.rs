//! Presets: every shipped preset loads, validates, round-trips and renders fire; malformed
//! files give located, specific errors and never panic; saving never loses work; any valid
//! effect survives save → load exactly; version-1 files keep loading; newer versions are
//! refused with a message to update.
// The editor, the `ignis` binary or the benches: the default `editor` feature.
#![cfg(feature = "editor")]

mod common;

use std::path::{Path, PathBuf};

use common::*;
use ignis::effect::{
    Attractor, BlendMode, Bloom, CURRENT_VERSION, CameraHint, Collisions, ColorStop,
    DepthCollision, Effect, Emitter, Falloff, FlamePull, Flipbook, FlipbookMode, Forces,
    GroundPlane, Gusts, Integrator, Lighting, Lit, Look, MAX_CAPACITY, Param, Post, Range, Shape,
    SixWayMaps, SpawnNoise, SphereCollider, Sprite, Streak, TimeMode, TimeSettings, Transform,
    Turbulence, Vortex,
};
use ignis::preset::{self, PresetError};
use ignis::testing::headless::Headless;
use ignis::testing::shaders::ShaderLibrary;
use proptest::prelude::*;

fn presets_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("presets")
}

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name)
}

/// The frozen version-1 campfire: the base text the malformed cases edit.
fn v1_text() -> String {
    std::fs::read_to_string(fixture("v1_campfire.ron")).expect("fixture")
}

/// `line:column` (1-based, columns in characters) of the first occurrence of `needle`.
fn pos_of(text: &str, needle: &str) -> String {
    let at = text
        .find(needle)
        .unwrap_or_else(|| panic!("{needle:?} not in the text"));
    pos_at(text, at)
}

/// `line:column` of byte offset `at`.
fn pos_at(text: &str, at: usize) -> String {
    let before = &text[..at];
    let line = before.matches('\n').count() + 1;
    let column = before.chars().rev().take_while(|&c| c != '\n').count() + 1;
    format!("{line}:{column}")
}

/// Replaces exactly one occurrence (so a case cannot silently edit nothing).
fn edit(text: &str, from: &str, to: &str) -> String {
    assert_eq!(text.matches(from).count(), 1, "{from:?} must occur once");
    text.replacen(from, to, 1)
}

const REQUIRED_PRESETS: [&str; 7] = [
    "campfire",
    "torch",
    "candle",
    "bonfire",
    "fireball",
    "spark_fountain",
    "thesis_2006",
];

/// Pixels that are lit and warm: red dominant, red ≥ green ≥ blue.
fn warm_pixels(img: &image::RgbaImage) -> usize {
    img.pixels()
        .filter(|p| p[0] > 60 && p[0] >= p[1] && p[1] >= p[2] && p[0] > p[2] + 20)
        .count()
}

/// Every file in presets/ loads, validates, survives save → load unchanged, and renders a
/// frame with warm pixels; the required library is there.
#[test]
fn every_shipped_preset_loads_round_trips_and_renders_fire() {
    let files = preset::list(&presets_dir());
    let stems: Vec<String> = files
        .iter()
        .filter_map(|p| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
        .collect();
    for name in REQUIRED_PRESETS {
        assert!(
            stems.iter().any(|s| s == name),
            "presets/{name}.ron missing"
        );
    }
    let ctx = gpu();
    let tmp = tempfile::tempdir().expect("tempdir");
    let mut names = std::collections::HashSet::new();
    for path in &files {
        let shown = path.display();
        let effect = preset::load(path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(effect.validate(), Ok(()), "{shown}");
        assert_eq!(effect.version, CURRENT_VERSION);
        assert!(names.insert(effect.name.clone()), "{shown}: name reused");
        // Round trip through a real file.
        let copy = tmp.path().join(path.file_name().expect("file name"));
        preset::save(&effect, &copy).unwrap_or_else(|e| panic!("{e}"));
        let back = preset::load(&copy).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(back, effect, "{shown}: save → load changed it");
        assert_eq!(format!("{back:?}"), format!("{effect:?}"), "{shown}: bits");
        // Renders fire: after 0.75 s (the fireball's burst is at 0.25 s) at 60 fps.
        let mut run =
            Headless::new(&ctx, effect.clone(), ShaderLibrary::embedded()).expect("headless");
        for _ in 0..45 {
            run.advance(1.0 / 60.0);
        }
        assert!(run.alive().expect("alive") > 0, "{shown}: nothing alive");
        let img = run.render((320, 240)).expect("render");
        let warm = warm_pixels(&img);
        assert!(warm > 150, "{shown}: only {warm} warm pixels");
    }
}

/// The presets differ from one another: names, emitter layouts and pictures.
#[test]
fn shipped_presets_differ() {
    let effects: Vec<Effect> = preset::list(&presets_dir())
        .iter()
        .map(|p| preset::load(p).unwrap_or_else(|e| panic!("{e}")))
        .collect();
    for (i, a) in effects.iter().enumerate() {
        for b in &effects[i + 1..] {
            assert_ne!(a.emitters, b.emitters, "{} and {}", a.name, b.name);
        }
    }
    let by_name = |n: &str| {
        effects
            .iter()
            .find(|e| e.name == n)
            .unwrap_or_else(|| panic!("no preset named {n:?}"))
    };
    // The fireball is made of bursts only, and of what their particles' events spawn.
    let fireball = by_name("fireball");
    assert!(fireball.emitters.iter().enumerate().all(|(i, e)| {
        e.spawn_rate_per_sec.is_constant(0.0) && (!e.bursts.is_empty() || fireball.event_fed(i))
    }));
    // Candles and torches taper with flame_pull.
    for n in ["candle", "torch"] {
        assert!(
            by_name(n)
                .emitters
                .iter()
                .any(|e| e.forces.flame_pull.is_some()),
            "{n} has no flame_pull"
        );
    }
    // Sparks fall: no buoyancy, gravity down, ground bounces.
    let fountain = by_name("spark fountain");
    let jets: Vec<&Emitter> = fountain
        .emitters
        .iter()
        .filter(|e| e.look.sprite == Sprite::Spark)
        .collect();
    assert!(jets.len() >= 2);
    for e in jets {
        assert!(e.forces.constant_acceleration().y < -9.0, "{}", e.name);
        assert!(e.collisions.ground.is_some(), "{}", e.name);
    }
}

/// thesis_2006.ron is the thesis's setup: explicit Euler, frame-delta time, no noise,
/// point sprites, buoyancy as negative gravity.
#[test]
fn thesis_preset_replicates_the_2006_setup() {
    let e = preset::load(&presets_dir().join("thesis_2006.ron")).expect("loads");
    assert_eq!(e.time.mode, TimeMode::FrameDelta);
    for em in &e.emitters {
        assert_eq!(em.integrator, Integrator::ExplicitEuler);
        assert_eq!(em.look.sprite, Sprite::Point);
        assert!(em.look.size_m.bounds().1 <= 0.02);
        assert_eq!(em.spawn_noise.position_amplitude_m, 0.0);
        assert_eq!(em.spawn_noise.direction_amplitude, 0.0);
        assert!(em.forces.turbulence.is_none() && em.forces.flame_pull.is_none());
        assert_eq!(em.forces.buoyancy_m_per_s2, 0.0);
        assert!(em.forces.gravity_m_per_s2[1] > 0.0, "gravity points up");
        assert_eq!(em.forces.drag_per_sec, 0.0);
    }
}

/// Mean height of the alive particles of emitter 0 after one simulated second at `fps`.
fn mean_height_after_1s(
    ctx: &ignis::testing::gpu::GpuContext,
    effect: &Effect,
    fps: u32,
) -> (f32, Vec<u8>) {
    let mut run = Headless::new(ctx, effect.clone(), ShaderLibrary::embedded()).expect("headless");
    for _ in 0..fps {
        run.advance(1.0 / fps as f64);
    }
    let particles = run.player.particles(run.instance, 0).expect("read");
    let alive: Vec<_> = particles.iter().filter(|p| p.is_alive()).collect();
    assert_eq!(alive.len(), 2000, "every burst particle alive");
    let mean = alive.iter().map(|p| p.position().y).sum::<f32>() / alive.len() as f32;
    (mean, bytemuck::cast_slice(&particles).to_vec())
}

/// Why the thesis's fixes matter: its frame-delta explicit Euler rises higher at 120 fps than
/// at 15 fps (the thesis saw small systems, at high fps, rise faster), while the same
/// particles on a fixed step end bit-identical at both frame rates.
#[test]
fn thesis_preset_is_frame_rate_dependent_and_a_fixed_step_is_not() {
    let ctx = gpu();
    let mut e = preset::load(&presets_dir().join("thesis_2006.ron")).expect("loads");
    let em = &mut e.emitters[0];
    em.spawn_rate_per_sec = ignis::effect::Param::Constant(0.0);
    em.bursts = vec![ignis::effect::Burst {
        time_secs: 0.0,
        count: 2000,
    }];
    em.max_spawn_per_sec = 0.0;
    em.lifetime_secs = Range::new(5.0, 5.0);
    let (fast, _) = mean_height_after_1s(&ctx, &e, 120);
    let (slow, _) = mean_height_after_1s(&ctx, &e, 15);
    // The burst is born at its moment and moved over its first step in closed form; from
    // then on explicit Euler under a constant acceleration a lags the exact height by
    // a·(t − dt)·dt/2 — a = 0.6 m/s², t = 1 s: 0.0187 m at 15 fps, 0.0025 m at 120 fps.
    let a = e.emitters[0].forces.constant_acceleration().y;
    let lag = |dt: f32| a * (1.0 - dt) * dt / 2.0;
    let euler_lag = lag(1.0 / 15.0) - lag(1.0 / 120.0);
    let diff = fast - slow;
    assert!(
        (diff - euler_lag).abs() < 0.05 * euler_lag,
        "120 fps {fast} m vs 15 fps {slow} m: difference {diff} m, expected {euler_lag}"
    );
    assert!(diff / fast > 0.02, "a visible difference: {}", diff / fast);
    e.time = TimeSettings {
        mode: TimeMode::FixedStep,
        step_secs: 1.0 / 120.0,
        max_substeps: 8,
        ..e.time
    };
    let (fixed_fast, bytes_fast) = mean_height_after_1s(&ctx, &e, 120);
    let (fixed_slow, bytes_slow) = mean_height_after_1s(&ctx, &e, 15);
    assert_eq!(fixed_fast, fixed_slow);
    assert!(bytes_fast == bytes_slow, "fixed step: states differ");
}

/// One malformed input: the file name, its bytes, and what the error must say.
struct Case {
    file: &'static str,
    bytes: Vec<u8>,
    expect: Vec<String>,
}

fn case(file: &'static str, text: impl Into<Vec<u8>>, expect: &[&str]) -> Case {
    Case {
        file,
        bytes: text.into(),
        expect: expect.iter().map(|s| s.to_string()).collect(),
    }
}

fn malformed_cases() -> Vec<Case> {
    let base = v1_text();
    let mut cases = Vec::new();

    // Truncated in the middle of the flames' forces.
    let cut = base.find("buoyancy_m_per_s2: 11.6").expect("flames");
    let truncated = &base[..cut];
    let open = truncated.rfind("forces: (").expect("forces") + "forces: ".len();
    cases.push(case(
        "truncated.ron",
        truncated,
        &[
            &format!(
                "truncated.ron:{}: emitters[1].forces: ",
                pos_at(truncated, truncated.trim_end().len())
            ),
            "unexpected end of file",
            &format!("`(` opened at {} is never closed", pos_at(truncated, open)),
            "truncated?",
        ],
    ));

    let t = edit(&base, "spawn_rate_per_sec: 90.0", "spawn_rate_per_s: 90.0");
    cases.push(case(
        "unknown_field.ron",
        t.clone(),
        &[&format!(
            "unknown_field.ron:{}: emitters[0].spawn_rate_per_s: unknown field \
             `spawn_rate_per_s`; did you mean `spawn_rate_per_sec`?",
            pos_of(&t, "spawn_rate_per_s:")
        )],
    ));

    let t = edit(&base, "seed: 1,", "sede: 1,");
    cases.push(case(
        "unknown_top_field.ron",
        t.clone(),
        &[&format!(
            "unknown_top_field.ron:{}: sede: unknown field `sede`; did you mean `seed`?",
            pos_of(&t, "sede")
        )],
    ));

    let t = edit(&base, "capacity: 2048", "capacity: \"lots\"");
    cases.push(case(
        "string_for_integer.ron",
        t.clone(),
        &[&format!(
            "string_for_integer.ron:{}: emitters[0].capacity: expected a whole number, found \
             `\"lots\"`",
            pos_of(&t, "\"lots\"")
        )],
    ));

    let t = edit(&base, "capacity: 2048", "capacity: 20.5");
    cases.push(case(
        "float_for_integer.ron",
        t.clone(),
        &[&format!(
            "float_for_integer.ron:{}: emitters[0].capacity: expected a whole number (this \
             field takes no fractions or exponents), found `20.5`",
            pos_of(&t, "20.5")
        )],
    ));

    let t = edit(&base, "capacity: 1024", "capacity: -5");
    cases.push(case(
        "negative_integer.ron",
        t.clone(),
        &[&format!(
            "negative_integer.ron:{}: emitters[2].capacity: expected a whole number ≥ 0, \
             found `-5`",
            pos_of(&t, "-5,")
        )],
    ));

    let t = edit(&base, "capacity: 4096", "capacity: 99999999999");
    cases.push(case(
        "huge_integer.ron",
        t.clone(),
        &[&format!(
            "huge_integer.ron:{}: emitters[1].capacity: expected a whole number in \
             0..=4294967295, found `99999999999`",
            pos_of(&t, "99999999999")
        )],
    ));

    let t = edit(&base, "spread_deg: 15.0", "spread_deg: true");
    cases.push(case(
        "bool_for_number.ron",
        t.clone(),
        &[&format!(
            "bool_for_number.ron:{}: emitters[0].spread_deg: expected a number, found `true`",
            pos_of(&t, "true")
        )],
    ));

    let t = edit(&base, "name: \"smoke\"", "name: 5");
    cases.push(case(
        "number_for_string.ron",
        t.clone(),
        &[&format!(
            "number_for_string.ron:{}: emitters[0].name: expected a string in double quotes, \
             found `5`",
            pos_of(&t, "5,\n            capacity")
        )],
    ));

    let t = edit(
        &base,
        "spawn_rate_per_sec: 2000.0",
        "spawn_rate_per_sec: -5",
    );
    cases.push(case(
        "negative_rate.ron",
        t.clone(),
        &[&format!(
            "negative_rate.ron:{}: emitters[1].spawn_rate_per_sec = -5: must be ≥ 0",
            pos_of(&t, "-5,")
        )],
    ));

    let t = edit(&base, "spawn_rate_per_sec: 40.0", "spawn_rate_per_sec: NaN");
    cases.push(case(
        "nan.ron",
        t.clone(),
        &[&format!(
            "nan.ron:{}: emitters[2].spawn_rate_per_sec = NaN: must be a finite number",
            pos_of(&t, "NaN")
        )],
    ));

    let t = edit(&base, "distance_m: 2.6", "distance_m: inf");
    cases.push(case(
        "inf.ron",
        t.clone(),
        &[&format!(
            "inf.ron:{}: camera.distance_m = inf: must be a finite number",
            pos_of(&t, "inf")
        )],
    ));

    // A curve key of a version-2 preset: the key is found in the text.
    let campfire = std::fs::read_to_string(presets_dir().join("campfire.ron")).expect("campfire");
    let t = edit(&campfire, "(0.0, 0.245)", "(0.0, -inf)");
    cases.push(case(
        "negative_inf.ron",
        t.clone(),
        &[&format!(
            "negative_inf.ron:{}: emitters[0].look.size_m.a.keys[0] = (0, -inf): a key's time \
             and value must be finite numbers",
            pos_of(&t, "(0.0, -inf)")
        )],
    ));

    let t = edit(&base, "spread_deg: 10.0", "spread_deg: 1e39");
    cases.push(case(
        "float_overflow.ron",
        t.clone(),
        &[&format!(
            "float_overflow.ron:{}: emitters[1].spread_deg = 1e39: must be a finite number \
             (1e39 does not fit in a 32-bit float",
            pos_of(&t, "1e39")
        )],
    ));

    let t = edit(&base, "spread_deg: 25.0", "spread_deg: 1e30");
    cases.push(case(
        "huge_float.ron",
        t.clone(),
        &[&format!(
            "huge_float.ron:{}: emitters[2].spread_deg = 1e30: must be ≤ 180",
            pos_of(&t, "1e30")
        )],
    ));

    let t = edit(
        &base,
        "lifetime_secs: (min: 2.5, max: 4.0)",
        "lifetime_secs: (min: 5.0, max: 4.0)",
    );
    cases.push(case(
        "min_above_max.ron",
        t.clone(),
        &[&format!(
            "min_above_max.ron:{}: emitters[0].lifetime_secs.min = 5.0: must be ≤ max (4)",
            pos_of(&t, "5.0, max")
        )],
    ));

    let t = edit(
        &base,
        "    emitters: [",
        "    post: (glow_downscale: 3),\n    emitters: [",
    );
    let at = t.find("glow_downscale: 3").expect("edited") + "glow_downscale: ".len();
    cases.push(case(
        "glow_downscale.ron",
        t.clone(),
        &[&format!(
            "glow_downscale.ron:{}: post.glow_downscale = 3: must be 1 or 2 (1 = full resolution)",
            pos_at(&t, at)
        )],
    ));

    // Two problems: both are listed, each located.
    let t = edit(
        &edit(&base, "fov_y_deg: 45.0", "fov_y_deg: 0.5"),
        "intensity: 4.0",
        "intensity: -1.0",
    );
    cases.push(case(
        "two_problems.ron",
        t.clone(),
        &[
            &format!(
                "two_problems.ron:{}: camera.fov_y_deg = 0.5: must be ≥ 1",
                pos_of(&t, "0.5")
            ),
            &format!(
                "two_problems.ron:{}: emitters[2].look.intensity = -1.0: must be ≥ 0",
                pos_of(&t, "-1.0")
            ),
        ],
    ));

    let start = base.find("    emitters: [").expect("emitters");
    let t = format!("{}    emitters: [],\n)\n", &base[..start]);
    cases.push(case(
        "no_emitters.ron",
        t.clone(),
        &[&format!(
            "no_emitters.ron:{}: emitters = []: must list at least one emitter",
            pos_of(&t, "[]")
        )],
    ));

    let t = format!("{})\n", &base[..start]);
    cases.push(case(
        "emitters_missing.ron",
        t.clone(),
        &[&format!(
            "emitters_missing.ron:{}: missing required field `emitters`",
            pos_of(&t, "(\n    version")
        )],
    ));

    let t = edit(&base, "version: 1,", "version: 999,");
    let t = edit(&t, "seed: 1,", "seed: 1, sparkle_fx: (a_future_field: 1),");
    cases.push(case(
        "future.ron",
        t.clone(),
        &[&format!(
            "future.ron:{}: version: this preset is format version 999, but this build of \
             ignis reads versions up to {CURRENT_VERSION}; update ignis to open it",
            pos_of(&t, "999")
        )],
    ));

    let t = edit(&base, "version: 1,", "version: 0,");
    cases.push(case(
        "version_zero.ron",
        t.clone(),
        &[&format!(
            "version_zero.ron:{}: version: found 0; the first preset format is version 1",
            pos_of(&t, "0,\n    name")
        )],
    ));

    let t = edit(&base, "    version: 1,\n", "");
    cases.push(case(
        "no_version.ron",
        t.clone(),
        &[&format!(
            "no_version.ron:{}: missing required field `version`",
            pos_of(&t, "(\n    name")
        )],
    ));

    let t = edit(&base, "name: \"embers\"", "name: \"flames\"");
    let second = t.rfind("\"flames\"").expect("second");
    cases.push(case(
        "duplicate_names.ron",
        t.clone(),
        &[&format!(
            "duplicate_names.ron:{}: emitters[2].name = \"flames\": duplicate emitter name; \
             names must be unique",
            pos_of(&t[..], &t[second..])
        )],
    ));

    let t = edit(&base, "seed: 1,", "seed: 1, seed: 2,");
    cases.push(case(
        "duplicate_field.ron",
        t.clone(),
        &[&format!(
            "duplicate_field.ron:{}: seed: field `seed` is given twice; keep one",
            pos_at(&t, t.find(", seed: 2").expect("second") + 2)
        )],
    ));

    let mut bytes = edit(&base, "name: \"smoke\"", "name: \"smoke\u{1}\"").into_bytes();
    let at = bytes.iter().position(|&b| b == 1).expect("marker");
    bytes[at] = 0xff;
    let before = String::from_utf8_lossy(&bytes[..at]).into_owned();
    cases.push(case(
        "not_utf8.ron",
        bytes,
        &[&format!(
            "not_utf8.ron:{}: not valid UTF-8 text (byte 0xff at offset {at})",
            pos_of(&format!("{before}X"), "X")
        )],
    ));

    let t = base
        .trim_end()
        .strip_suffix(')')
        .expect("closing paren")
        .to_owned();
    cases.push(case(
        "missing_paren.ron",
        t.clone(),
        &[&format!(
            "missing_paren.ron:{}: unexpected end of file: `(` opened at {} is never closed",
            pos_at(&t, t.trim_end().len()),
            pos_of(&t, "(\n    version")
        )],
    ));

    let t = edit(&base, "blend: Alpha", "blend: Alpah");
    cases.push(case(
        "wrong_variant.ron",
        t.clone(),
        &[&format!(
            "wrong_variant.ron:{}: emitters[0].look.blend: unknown variant `Alpah`; did you \
             mean `Alpha`? (one of `Additive`, `Alpha`)",
            pos_of(&t, "Alpah")
        )],
    ));

    let t = edit(
        &base,
        "shape: Disc(radius_m: 0.3,",
        "shape: Disk(radius_m: 0.3,",
    );
    cases.push(case(
        "wrong_shape.ron",
        t.clone(),
        &[&format!(
            "wrong_shape.ron:{}: emitters[0].shape: unknown variant `Disk`; did you mean \
             `Disc`?",
            pos_of(&t, "Disk")
        )],
    ));

    let t = edit(
        &base,
        "lifetime_secs: (min: 1.2, max: 2.6)",
        "lifetime_secs: (min: 1.2)",
    );
    cases.push(case(
        "missing_required.ron",
        t.clone(),
        &[&format!(
            "missing_required.ron:{}: emitters[2].lifetime_secs: missing required field `max`",
            pos_of(&t, "),\n            shape: Disc(radius_m: 0.25")
        )],
    ));

    let t = edit(
        &base,
        "direction: (0.0, 1.0, 0.0),\n            spread_deg: 25.0",
        "direction: (0.0, 1.0),\n            spread_deg: 25.0",
    );
    cases.push(case(
        "short_vector.ron",
        t.clone(),
        &[
            "short_vector.ron:",
            "emitters[2].direction: expected 3 values, found 2",
        ],
    ));

    let t = edit(
        &base,
        "lifetime_secs: (min: 2.5, max: 4.0)",
        "lifetime_secs: [2.5, 4.0]",
    );
    cases.push(case(
        "list_for_struct.ron",
        t.clone(),
        &[&format!(
            "list_for_struct.ron:{}: emitters[0].lifetime_secs: expected `(` opening a group of \
             fields, found `[`",
            pos_of(&t, "[2.5")
        )],
    ));

    let t = format!("{base}\n(version: 1)\n");
    cases.push(case(
        "trailing.ron",
        t.clone(),
        &[&format!(
            "trailing.ron:{}: unexpected text after the preset's closing `)`, found `(`",
            pos_of(&t, "(version: 1)")
        )],
    ));

    let t = edit(&base, "name: \"smoke\"", "name: \"smoke");
    cases.push(case(
        "unclosed_string.ron",
        t.clone(),
        &[
            "unclosed_string.ron:",
            &format!(
                "(the string starting at {} runs over several lines: is a closing `\"` missing?)",
                pos_of(&t, "\"smoke")
            ),
        ],
    ));

    let t = edit(&base, "seed: 1,", "seed: 1;");
    cases.push(case(
        "semicolon.ron",
        t.clone(),
        &[&format!(
            "semicolon.ron:{}: seed: expected `,` between values, found `;`",
            pos_of(&t, ";")
        )],
    ));

    let t = format!(
        "(version: 1, emitters: [(name: \"deep\", bursts: {}",
        "[".repeat(100_000)
    );
    cases.push(case(
        "deep_nesting.ron",
        t.clone(),
        // No stack overflow: the typed reader stops at the first bracket too many.
        &[
            "deep_nesting.ron:1:49: emitters[0].bursts[0]: expected `(` opening a group of \
             fields, found `[`",
        ],
    ));

    let t = edit(
        &base,
        "seed_offset: 3,",
        "seed_offset: 3, packed_state: true, tiny_state: true,",
    );
    cases.push(case(
        "two_layouts.ron",
        t,
        &["emitters[0].tiny_state = true: cannot be combined with `packed_state`"],
    ));

    cases.push(case("empty.ron", "", &["empty.ron:1:1: the file is empty"]));
    cases.push(case(
        "only_comments.ron",
        "// a preset\n/* nothing yet */\n",
        &["only_comments.ron:1:1: the file is empty"],
    ));
    cases.push(case(
        "unclosed_comment.ron",
        format!("/* {base}"),
        &["unclosed_comment.ron:", "a `/*` comment is never closed"],
    ));

    let t = edit(
        &base,
        "drag_per_sec: 0.8,",
        "drag_per_sec: 0.8, turbulence: (octaves: 9),",
    );
    cases.push(case(
        "bad_option.ron",
        t.clone(),
        &[&format!(
            "bad_option.ron:{}: emitters[0].forces.turbulence.octaves = 9: must be in 1..=4",
            pos_of(&t, "9), wind")
        )],
    ));
    cases
}

/// Each malformed input gives the expected error (file, line:column, field path, what was
/// expected) and no panic; the message is also what `ignis check` prints.
#[test]
fn malformed_presets_give_located_specific_errors() {
    let cases = malformed_cases();
    assert!(cases.len() >= 15);
    let dir = tempfile::tempdir().expect("tempdir");
    for c in &cases {
        let path = dir.path().join(c.file);
        std::fs::write(&path, &c.bytes).expect("write");
        let result = std::panic::catch_unwind(|| preset::load(&path));
        let Ok(result) = result else {
            panic!("{}: the loader panicked", c.file);
        };
        let err = match result {
            Ok(_) => panic!("{}: loaded without error", c.file),
            Err(e) => e,
        };
        let msg = err.to_string();
        for want in &c.expect {
            let want = want.replace(c.file, &path.display().to_string());
            assert!(
                msg.contains(&want),
                "{}:\n  got:  {msg}\n  want: {want}",
                c.file
            );
        }
        // Errors with a position report it through `position()` too.
        if msg.starts_with(&format!("{}:", path.display()))
            && let Some(p) = err.position()
        {
            assert!(msg.contains(&format!(":{p}: ")), "{}: {msg} vs {p}", c.file);
        }
    }
}

/// The typed error: a newer version is `TooNew` with both versions.
#[test]
fn future_version_is_refused_with_update_message() {
    let text = edit(&v1_text(), "version: 1,", "version: 999,");
    match preset::parse_str(&text, "future.ron") {
        Err(PresetError::TooNew {
            found,
            supported,
            line,
            column,
            ..
        }) => {
            assert_eq!((found, supported), (999, CURRENT_VERSION));
            assert_eq!((line, column), (8, 14));
        }
        other => panic!("expected TooNew, got {other:?}"),
    }
    let msg = preset::parse_str(&text, "future.ron")
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(msg.contains("update ignis"), "{msg}");
}

/// The version-1 fixture keeps loading, with the values it was written with, and means
/// the same as the fully explicit file `save` wrote from it in version 1.
#[test]
fn version_1_fixture_keeps_loading() {
    let e = preset::load(&fixture("v1_campfire.ron")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(e.version, CURRENT_VERSION);
    assert_eq!(e.name, "campfire");
    let names: Vec<&str> = e.emitters.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(names, ["smoke", "flames", "embers"]);
    assert_eq!(e.time.mode, TimeMode::FixedStep);
    assert_eq!(e.time.step_secs, 0.008333334);
    assert_eq!(e.camera.distance_m, 2.6);
    let flames = &e.emitters[1];
    assert_eq!(flames.capacity, 4096);
    assert_eq!(
        flames.spawn_rate_per_sec,
        ignis::effect::Param::Constant(2000.0)
    );
    assert_eq!(flames.forces.buoyancy_m_per_s2, 11.6);
    assert_eq!(flames.look.color_over_life.len(), 5);
    assert_eq!(e.emitters[0].look.blend, BlendMode::Alpha);
    assert_eq!(e.emitters[2].look.sprite, Sprite::Spark);
    // Fields version-1 files leave out mean what they meant in version 1.
    assert!(flames.enabled);
    assert_eq!(flames.max_spawn_per_sec, 0.0);
    assert_eq!(flames.transform.position_m, [0.0; 3]);
    assert!(flames.forces.turbulence.is_none());
    assert!(flames.collisions.ground.is_none());
    assert_eq!(flames.collisions.elasticity, 0.4);
    let saved = preset::load(&fixture("v1_campfire_saved.ron")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(saved, e);
}

/// Every shipped preset as it was in version 1 (`tests/fixtures/v1/`, frozen) migrates
/// to exactly the version-2 preset: the size's line and random factor become the curves
/// that give the same sizes, spins and rates become ranges and constants. The version-2
/// preset is the one shipped now, or, for a preset redesigned since with version-2
/// features (events, trails), its first version-2 form (`tests/fixtures/v2/`, frozen).
/// (The committed reference images, rendered from the version-1 presets, still match the
/// version-2 frames: `looks.rs`.)
/// `effect` without what shipped presets took after their migration to version 3 — lit
/// smoke, heat-haze layers, collision with the host's depth, flames at reduced resolution
/// (look and behaviour changes, not format changes: older files have none).
fn unlit(mut effect: Effect) -> Effect {
    effect.post.glow_downscale = 1;
    effect.emitters.retain(|e| e.look.heat_haze.is_none());
    for e in &mut effect.emitters {
        e.look.lit = None;
        e.collisions.depth_collision = None;
    }
    effect
}

#[test]
fn every_version_1_preset_migrates_to_the_shipped_version_2() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/v1");
    let mut n = 0;
    for path in preset::list(&dir) {
        let old = preset::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let text = std::fs::read_to_string(&path).expect("read");
        assert!(text.contains("version: 1,"), "{}", path.display());
        let name = path.file_name().expect("name");
        let frozen = fixture("v2").join(name);
        let v2 = if frozen.exists() {
            frozen
        } else {
            presets_dir().join(name)
        };
        let new = unlit(preset::load(&v2).unwrap_or_else(|e| panic!("{e}")));
        assert_eq!(old, new, "{}", path.display());
        n += 1;
    }
    assert_eq!(n, 7, "the seven presets shipped in version 1");
}

/// Every shipped preset as it was last stored in version 2 (`tests/fixtures/v2_last/`,
/// frozen) migrates to exactly the shipped version-3 preset: counts per step become rates
/// and spans at the preset's own step (a trail of 6 points every 2 steps of 1/120 s spans
/// 0.1 s; 64 children a step are 7680 a second).
#[test]
fn every_version_2_preset_migrates_to_the_shipped_version_3() {
    let dir = fixture("v2_last");
    let mut n = 0;
    for path in preset::list(&dir) {
        let text = std::fs::read_to_string(&path).expect("read");
        assert!(text.contains("version: 2,"), "{}", path.display());
        let old = preset::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let name = path.file_name().expect("name");
        let new = unlit(preset::load(&presets_dir().join(name)).unwrap_or_else(|e| panic!("{e}")));
        assert_eq!(old, new, "{}", path.display());
        // The ribbon spans the same time at the preset's step as it did.
        for (a, b) in old.emitters.iter().zip(&new.emitters) {
            if let (Some(t), Some(u)) = (&a.look.trail, &b.look.trail) {
                let step = new.time.step_secs;
                assert_eq!(t.layout(step), u.layout(step));
            }
        }
        n += 1;
    }
    assert_eq!(n, 8, "the eight presets shipped in version 2");
}

/// Saving over a preset while the write fails midway (a full disk) or the process dies
/// (a panic) leaves the old file byte for byte, and no temporary file behind.
#[test]
fn failed_save_midway_leaves_the_old_file_intact() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("torch.ron");
    let old = preset::load(&presets_dir().join("torch.ron")).expect("torch");
    preset::save(&old, &path).expect("save");
    let old_bytes = std::fs::read(&path).expect("read");

    let mut new = old.clone();
    new.name = "torch, edited".into();
    let text = format!(
        "{}{}\n",
        preset::file_header(),
        preset::to_ron(&new).expect("ron")
    );
    // The disk fills up halfway through.
    let err = preset::write_atomic_with(&path, |w| {
        w.write_all(&text.as_bytes()[..text.len() / 2])?;
        Err(std::io::Error::new(
            std::io::ErrorKind::StorageFull,
            "no space left on device",
        ))
    })
    .expect_err("must fail");
    assert_eq!(err.kind(), std::io::ErrorKind::StorageFull);
    assert_eq!(std::fs::read(&path).expect("read"), old_bytes);
    // The process dies while writing.
    let crashed = std::panic::catch_unwind(|| {
        let _ = preset::write_atomic_with(&path, |w| {
            w.write_all(&text.as_bytes()[..100])?;
            panic!("simulated crash");
        });
    });
    assert!(crashed.is_err());
    assert_eq!(std::fs::read(&path).expect("read"), old_bytes);
    let entries: Vec<_> = std::fs::read_dir(dir.path())
        .expect("dir")
        .flatten()
        .map(|e| e.file_name())
        .collect();
    assert_eq!(
        entries,
        [std::ffi::OsString::from("torch.ron")],
        "leftovers"
    );
    assert_eq!(preset::load(&path).expect("old still loads"), old);

    // A save that cannot even start (the folder is gone) creates nothing.
    let missing = dir.path().join("no/such/folder/x.ron");
    let err = preset::save(&new, &missing).expect_err("no folder");
    assert!(err.to_string().contains("not saved"), "{err}");
    assert!(!missing.exists());
    // A folder in the way is not replaced.
    let folder = dir.path().join("folder.ron");
    std::fs::create_dir(&folder).expect("mkdir");
    assert!(preset::write_atomic(&folder, b"x").is_err());
    assert!(folder.is_dir());

    // And a successful save replaces it completely.
    preset::save(&new, &path).expect("save");
    assert_eq!(preset::load(&path).expect("load"), new);
}

/// An invalid effect is refused before anything is written.
#[test]
fn saving_an_invalid_effect_refuses_and_keeps_the_file() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("candle.ron");
    let good = preset::load(&presets_dir().join("candle.ron")).expect("candle");
    preset::save(&good, &path).expect("save");
    let before = std::fs::read(&path).expect("read");
    let mut bad = good.clone();
    bad.emitters[1].spawn_rate_per_sec = ignis::effect::Param::Constant(-5.0);
    bad.emitters[0].look.size_m = ignis::effect::Param::Constant(f32::NAN);
    let err = preset::save(&bad, &path).expect_err("invalid");
    let msg = err.to_string();
    assert!(
        msg.contains("emitters[1].spawn_rate_per_sec = -5: must be ≥ 0"),
        "{msg}"
    );
    assert!(
        msg.contains("emitters[0].look.size_m = NaN: must be a finite number"),
        "{msg}"
    );
    match err {
        PresetError::Invalid {
            errors, positions, ..
        } => {
            assert_eq!(errors.len(), 2);
            assert_eq!(positions, vec![None, None]);
        }
        other => panic!("expected Invalid, got {other:?}"),
    }
    assert_eq!(std::fs::read(&path).expect("read"), before);
}

/// A file that does not load (a typo in someone's work, or a newer version) is never
/// overwritten by `save`; `save_replacing` keeps it as `.bak`.
#[test]
fn saving_never_clobbers_a_file_that_failed_to_load() {
    let dir = tempfile::tempdir().expect("tempdir");
    let effect = Effect::default_campfire();
    for (name, content) in [
        (
            "typo.ron",
            "(version: 1, emitters: [(name: \"x\", capacty: 4)])",
        ),
        ("newer.ron", "(version: 7, emitters: [], brand_new: true)"),
        ("binary.ron", "\u{0}\u{1}garbage"),
    ] {
        let path = dir.path().join(name);
        std::fs::write(&path, content).expect("write");
        let err = preset::save(&effect, &path).expect_err("must refuse");
        assert!(matches!(err, PresetError::WouldClobber { .. }), "{err}");
        assert!(err.to_string().contains("not saved"), "{err}");
        assert_eq!(std::fs::read_to_string(&path).expect("read"), content);

        preset::save_replacing(&effect, &path).expect("replace");
        assert_eq!(preset::load(&path).expect("load"), effect);
        let backup = dir.path().join(format!("{name}.bak"));
        assert_eq!(std::fs::read_to_string(&backup).expect("backup"), content);
    }
    // A file that loads is simply replaced.
    let path = dir.path().join("typo.ron");
    let mut changed = effect.clone();
    changed.seed = 99;
    preset::save(&changed, &path).expect("save over a good file");
    assert_eq!(preset::load(&path).expect("load").seed, 99);
}

/// What `save` writes is meant for people: named fields, enums by name, no `Some(…)`, no
/// struct names, a header comment, short lines, and it loads back with the same options.
#[test]
fn saved_text_is_readable() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("torch.ron");
    let effect = preset::load(&presets_dir().join("torch.ron")).expect("torch");
    preset::save(&effect, &path).expect("save");
    let text = std::fs::read_to_string(&path).expect("read");
    assert!(text.starts_with("// ignis effect preset, format version 3."));
    assert!(!text.contains("Some("), "{text}");
    assert!(!text.contains("Effect("), "{text}");
    assert!(!text.contains("#![enable"), "{text}");
    for needle in [
        "\n    version: 3,\n",
        "\n    name: \"torch\",\n",
        "mode: FixedStep",
        "shape: Disc(radius_m: 0.055, normal: (0.0, 1.0, 0.0)),",
        "gusts: (strength: 0.8, frequency_hz: 0.6),",
        "                turbulence: (\n                    strength_m_per_s2: 4.0,\n",
        "vortex: None,",
        "blend: Additive,",
        "sprite: Spark,",
        "integrator: SemiImplicitEuler,",
        "lifetime_secs: (min: 0.3, max: 0.65),",
    ] {
        assert!(text.contains(needle), "missing {needle:?} in\n{text}");
    }
    for line in text.lines() {
        assert!(line.chars().count() <= 100, "long line: {line}");
    }
    // Every field is written out: the file does not depend on this build's defaults.
    assert!(text.contains("max_spawn_per_sec: 0.0,"));
    assert!(text.contains("kill_on_sphere_contact: false,"));
    // Loads back with the loader's options, and re-saving is byte-identical.
    assert_eq!(preset::load(&path).expect("load"), effect);
    let again = dir.path().join("again.ron");
    preset::save(&preset::load(&path).expect("load"), &again).expect("save");
    assert_eq!(std::fs::read_to_string(&again).expect("read"), text);
}

/// `ignis check presets/` passes on the shipped library and names the file, line:column
/// and field of a broken preset.
#[test]
fn check_command_validates_the_library_and_reports_located_errors() {
    let stdout = run_ok(
        std::process::Command::new(env!("CARGO_BIN_EXE_ignis"))
            .arg("check")
            .arg(presets_dir()),
    );
    let count = preset::list(&presets_dir()).len();
    assert!(
        stdout.contains(&format!("checked {count} presets")),
        "{stdout}"
    );

    let dir = tempfile::tempdir().expect("tempdir");
    let text = edit(
        &v1_text(),
        "spawn_rate_per_sec: 2000.0",
        "spawn_rate_per_sec: -5",
    );
    std::fs::write(dir.path().join("bad.ron"), &text).expect("write");
    std::fs::write(dir.path().join("good.ron"), v1_text()).expect("write");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_ignis"))
        .arg("check")
        .arg(dir.path())
        .output()
        .expect("run ignis");
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    let want = format!(
        "{}:{}: emitters[1].spawn_rate_per_sec = -5: must be ≥ 0",
        dir.path().join("bad.ron").display(),
        pos_of(&text, "-5,")
    );
    assert!(stderr.contains(&want), "{stderr}\nwant: {want}");
    assert!(stderr.contains("1 of 2 checks failed"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}

// ---------------------------------------------------------------------------------------
// Property test: any effect the validator accepts serialises and reloads exactly.

/// Floats in `[lo, hi]`: uniform, the bounds, values with long or short decimal forms.
fn fl(lo: f32, hi: f32) -> BoxedStrategy<f32> {
    let awkward: Vec<f32> = [
        0.0,
        -0.0,
        0.1,
        1.0 / 3.0,
        -2.0 / 3.0,
        1e-7,
        f32::MIN_POSITIVE,
        1.000_000_1,
        0.008_333_334,
        123_456.79,
        16_777_217.0,
        3.402_823_5e6,
    ]
    .into_iter()
    .filter(|v| (lo..=hi).contains(v))
    .collect();
    let decimal = (lo..=hi).prop_map(move |v| ((v * 1000.0).round() / 1000.0).clamp(lo, hi));
    if awkward.is_empty() {
        prop_oneof![4 => lo..=hi, 2 => decimal, 1 => Just(lo), 1 => Just(hi)].boxed()
    } else {
        prop_oneof![
            4 => lo..=hi,
            2 => decimal,
            1 => Just(lo),
            1 => Just(hi),
            2 => proptest::sample::select(awkward)
        ]
        .boxed()
    }
}

fn v3(limit: f32) -> BoxedStrategy<[f32; 3]> {
    [fl(-limit, limit), fl(-limit, limit), fl(-limit, limit)].boxed()
}

fn dir3() -> BoxedStrategy<[f32; 3]> {
    v3(1e6)
        .prop_filter("a direction", |v| {
            glam::Vec3::from(*v).length_squared() >= 1e-12
        })
        .boxed()
}

fn range(lo: f32, hi: f32) -> BoxedStrategy<Range> {
    (fl(lo, hi), fl(lo, hi))
        .prop_map(|(a, b)| Range::new(a.min(b), a.max(b)))
        .boxed()
}

fn text() -> BoxedStrategy<String> {
    prop_oneof![
        "\\PC{0,16}",
        Just("quote \" backslash \\ newline \n tab \t and r#\"raw\"#".to_owned()),
        Just("Flammen über dem Lagerfeuer 🔥".to_owned()),
        Just(String::new()),
    ]
    .boxed()
}

fn shape() -> BoxedStrategy<Shape> {
    prop_oneof![
        Just(Shape::Point),
        (fl(0.0, 1e4), any::<bool>()).prop_map(|(radius_m, surface_only)| Shape::Sphere {
            radius_m,
            surface_only
        }),
        (fl(0.0, 1e4), dir3()).prop_map(|(radius_m, normal)| Shape::Disc { radius_m, normal }),
        [fl(0.0, 1e4), fl(0.0, 1e4), fl(0.0, 1e4)]
            .prop_map(|half_extents_m| Shape::Box { half_extents_m }),
        (fl(0.0, 180.0), fl(0.0, 1e4)).prop_map(|(angle_deg, radius_m)| Shape::Cone {
            angle_deg,
            radius_m
        }),
        (v3(1e6), v3(1e6)).prop_map(|(a_m, b_m)| Shape::Line { a_m, b_m }),
    ]
    .boxed()
}

/// A curve of 1..=5 keys: times in [0, t_max] (strictly increasing), values in [lo, hi].
fn curve(lo: f32, hi: f32, t_max: f32) -> BoxedStrategy<ignis::effect::Curve> {
    (
        proptest::collection::vec((fl(0.0, t_max), fl(lo, hi)), 1..=5),
        any::<bool>(),
    )
        .prop_map(|(mut keys, smooth)| {
            keys.sort_by(|a, b| a.0.total_cmp(&b.0));
            keys.dedup_by(|b, a| b.0 <= a.0);
            ignis::effect::Curve { keys, smooth }
        })
        .boxed()
}

/// A parameter in any of the four modes.
fn param(lo: f32, hi: f32, t_max: f32) -> BoxedStrategy<Param> {
    prop_oneof![
        fl(lo, hi).prop_map(Param::Constant),
        (fl(lo, hi), fl(lo, hi)).prop_map(|(a, b)| Param::Range {
            min: a.min(b),
            max: a.max(b),
        }),
        curve(lo, hi, t_max).prop_map(|c| Param::Curve {
            keys: c.keys,
            smooth: c.smooth,
        }),
        (curve(lo, hi, t_max), curve(lo, hi, t_max)).prop_map(|(a, b)| Param::TwoCurves { a, b }),
    ]
    .boxed()
}

fn forces() -> BoxedStrategy<Forces> {
    let gusts = (fl(0.0, 10.0), fl(0.0, 100.0)).prop_map(|(strength, frequency_hz)| Gusts {
        strength,
        frequency_hz,
    });
    let turbulence = (
        fl(0.0, 1e4),
        fl(0.0, 1e3),
        1u32..=4,
        fl(-1e3, 1e3),
        param(-1e3, 1e3, 1.0),
    )
        .prop_map(
            |(strength_m_per_s2, frequency_per_m, octaves, scroll_m_per_s, over_life)| Turbulence {
                strength_m_per_s2,
                frequency_per_m,
                octaves,
                scroll_m_per_s,
                over_life,
            },
        );
    let vortex = (v3(1e7), dir3(), fl(-1e4, 1e4), fl(1e-3, 1e4)).prop_map(
        |(center_m, axis, swirl_m_per_s2, radius_m)| Vortex {
            center_m,
            axis,
            swirl_m_per_s2,
            radius_m,
        },
    );
    let attractor = (
        v3(1e7),
        fl(-1e5, 1e5),
        fl(1e-3, 1e4),
        prop_oneof![
            Just(Falloff::InverseSquare),
            Just(Falloff::ConstantWithinRadius)
        ],
    )
        .prop_map(|(position_m, strength, radius_m, falloff)| Attractor {
            position_m,
            strength,
            radius_m,
            falloff,
        });
    let flame_pull = (fl(0.0, 1e4), fl(0.0, 16.0), param(0.0, 1e3, 1.0)).prop_map(
        |(strength_per_s2, exponent, over_life)| FlamePull {
            strength_per_s2,
            exponent,
            over_life,
        },
    );
    (
        (v3(1e5), fl(-1e5, 1e5), fl(0.0, 1e4), v3(1e5), fl(0.0, 1e4)),
        (
            proptest::option::of(gusts),
            proptest::option::of(turbulence),
            proptest::option::of(vortex),
            proptest::option::of(attractor),
            proptest::option::of(flame_pull),
        ),
        (param(0.0, 1e3, 1.0), param(0.0, 1e3, 1.0)),
    )
        .prop_map(
            |(
                (gravity, buoyancy, drag, wind, quadratic),
                (gusts, turbulence, vortex, attractor, flame_pull),
                (drag_over_life, speed_over_life),
            )| Forces {
                gravity_m_per_s2: gravity,
                buoyancy_m_per_s2: buoyancy,
                drag_per_sec: drag,
                wind_m_per_s: wind,
                drag_over_life,
                speed_over_life,
                quadratic_drag_per_m: quadratic,
                gusts,
                turbulence,
                vortex,
                attractor,
                flame_pull,
            },
        )
        .boxed()
}

fn collisions() -> BoxedStrategy<Collisions> {
    let ground =
        (fl(-1e7, 1e7), any::<bool>()).prop_map(|(height_m, kill_on_contact)| GroundPlane {
            height_m,
            kill_on_contact,
        });
    let sphere = (v3(1e7), fl(1e-3, 1e4))
        .prop_map(|(center_m, radius_m)| SphereCollider { center_m, radius_m });
    let depth =
        (fl(0.0, 1e3), any::<bool>()).prop_map(|(thickness_m, kill_on_contact)| DepthCollision {
            thickness_m,
            kill_on_contact,
        });
    (
        proptest::option::of(ground),
        proptest::collection::vec(sphere, 0..=4),
        fl(0.0, 1.0),
        fl(0.0, 1.0),
        fl(0.0, 1e3),
        any::<bool>(),
        any::<bool>(),
        proptest::option::of(depth),
    )
        .prop_map(
            |(ground, spheres, elasticity, friction, rest, kill, stick, depth)| Collisions {
                ground,
                spheres,
                elasticity,
                friction,
                rest_speed_m_per_s: rest,
                kill_on_sphere_contact: kill,
                stick_on_contact: stick,
                depth_collision: depth,
            },
        )
        .boxed()
}

#[allow(clippy::needless_update)] // robust to fields added to Look later
fn look() -> BoxedStrategy<Look> {
    let stop = (
        fl(0.0, 1.0),
        [fl(0.0, 1e3), fl(0.0, 1e3), fl(0.0, 1e3), fl(0.0, 1e3)],
    )
        .prop_map(|(t, rgba)| ColorStop { t, rgba });
    (
        prop_oneof![
            Just(Sprite::SoftDisc),
            Just(Sprite::Point),
            Just(Sprite::Spark),
            Just(Sprite::FlameSheet),
            "[a-z]{1,8}(/[a-z]{1,8})?\\.png".prop_map(Sprite::Image),
        ],
        param(0.0, 1e3, 1.0),
        param(0.0, 1e3, 1.0),
        proptest::collection::vec(stop, 1..=8),
        fl(0.0, 1e4),
        prop_oneof![Just(BlendMode::Additive), Just(BlendMode::Alpha)],
        (
            proptest::option::of((1u32..=64, 1u32..=64, fl(0.0, 1000.0), any::<bool>())),
            param(-1e5, 1e5, 1.0),
            fl(0.0, 360.0),
            proptest::option::of((fl(0.0, 10.0), fl(0.0, 1e3))),
        ),
    )
        .prop_map(
            |(sprite, size_m, opacity, mut stops, intensity, blend, extra)| {
                let (flip, spin_deg_per_s, rotation_random_deg, streak) = extra;
                stops.sort_by(|a, b| a.t.total_cmp(&b.t));
                // Lit smoke: alpha-blended, camera-facing sprites.
                let lit = (blend == BlendMode::Alpha && streak.is_none()).then(|| Lit {
                    maps: match (&sprite, flip.is_some()) {
                        (Sprite::Image(p), _) => SixWayMaps::Images {
                            rtba: p.clone(),
                            lbfe: format!("{p}.lbfe.png"),
                        },
                        (_, true) => SixWayMaps::PuffSheet,
                        (_, false) => SixWayMaps::Puff,
                    },
                    albedo: [0.25, 0.5, 0.75],
                    emission: intensity,
                    self_light: rotation_random_deg,
                });
                // -0.0 sorts before 0.0 but the validator compares with <, so both orders pass.
                Look {
                    sprite,
                    size_m,
                    opacity,
                    spin_deg_per_s,
                    color_over_life: stops,
                    intensity,
                    blend,
                    flipbook: flip.map(|(rows, cols, fps, over_life)| Flipbook {
                        rows,
                        cols,
                        mode: if over_life {
                            FlipbookMode::OverLife
                        } else {
                            FlipbookMode::FrameRate { fps }
                        },
                        blend_frames: over_life,
                        random_start: !over_life,
                    }),
                    rotation_random_deg,
                    streak: streak.map(|(length_secs, max_length_m)| Streak {
                        length_secs,
                        max_length_m,
                    }),
                    lit,
                    // Fields added later keep their defaults here.
                    ..Look::default()
                }
            },
        )
        .boxed()
}

#[allow(clippy::needless_update)] // robust to fields added to Emitter later
fn emitter() -> BoxedStrategy<Emitter> {
    let burst = (fl(0.0, 1e6), any::<u32>())
        .prop_map(|(time_secs, count)| ignis::effect::Burst { time_secs, count });
    let spawn_noise = (fl(0.0, 1e3), fl(0.0, 1e3), fl(0.0, 10.0), fl(-1e3, 1e3)).prop_map(
        |(frequency_per_m, position_amplitude_m, direction_amplitude, scroll_per_sec)| SpawnNoise {
            frequency_per_m,
            position_amplitude_m,
            direction_amplitude,
            scroll_per_sec,
        },
    );
    (
        (
            text(),
            any::<bool>(),
            1u32..=MAX_CAPACITY,
            fl(0.0, 1e9),
            fl(0.0, 1e9),
            proptest::collection::vec(burst, 0..3),
            range(1e-3, 1e4),
            shape(),
        ),
        (
            v3(1e7),
            v3(3600.0),
            dir3(),
            fl(0.0, 180.0),
            range(0.0, 1e5),
            forces(),
            spawn_noise,
            proptest::sample::select(Integrator::ALL.to_vec()),
            collisions(),
            any::<u32>(),
            look(),
        ),
    )
        .prop_map(
            |(
                (name, enabled, capacity, rate, cap, bursts, lifetime, shape),
                (
                    position_m,
                    rotation_deg,
                    direction,
                    spread,
                    speed,
                    forces,
                    spawn_noise,
                    integrator,
                    collisions,
                    seed_offset,
                    look,
                ),
            )| Emitter {
                name,
                enabled,
                capacity,
                spawn_rate_per_sec: ignis::effect::Param::Constant(rate),
                max_spawn_per_sec: cap,
                bursts,
                lifetime_secs: lifetime,
                shape,
                transform: Transform {
                    position_m,
                    rotation_deg,
                },
                direction,
                spread_deg: spread,
                speed_m_per_s: speed,
                forces,
                spawn_noise,
                integrator,
                collisions,
                seed_offset,
                look,
                // Fields added later keep their defaults here.
                ..Emitter::default()
            },
        )
        .boxed()
}

fn effect() -> BoxedStrategy<Effect> {
    let time = (
        prop_oneof![Just(TimeMode::FixedStep), Just(TimeMode::FrameDelta)],
        fl(1e-5, 1.0),
        1u32..=1000,
        fl(1e-5, 1.0),
        fl(0.0, 100.0),
    )
        .prop_map(
            |(mode, step_secs, max_substeps, max_frame_dt_secs, speed)| TimeSettings {
                mode,
                step_secs,
                max_substeps,
                max_frame_dt_secs,
                speed,
            },
        );
    let camera = (
        v3(1e6),
        fl(0.01, 1e5),
        fl(-3600.0, 3600.0),
        fl(-89.9, 89.9),
        fl(1.0, 170.0),
    )
        .prop_map(
            |(target_m, distance_m, yaw_deg, pitch_deg, fov_y_deg)| CameraHint {
                target_m,
                distance_m,
                yaw_deg,
                pitch_deg,
                fov_y_deg,
            },
        );
    (
        text(),
        any::<u32>(),
        time,
        camera,
        proptest::collection::vec(emitter(), 1..=3),
    )
        .prop_map(|(name, seed, time, camera, mut emitters)| {
            // Names must be unique: tag each with its index.
            for (i, e) in emitters.iter_mut().enumerate() {
                e.name = format!("{}#{i}", e.name);
            }
            Effect {
                version: CURRENT_VERSION,
                name,
                seed,
                time,
                camera,
                emitters,
                post: Post {
                    exposure: 1.5,
                    bloom: (seed % 2 == 0).then(Bloom::default),
                    alpha_downscale: 1 + seed % 4,
                    glow_downscale: 1 + seed % 2,
                },
                lighting: Lighting {
                    sun_direction: [0.3, 1.0, -0.2],
                    sun_color: [0.2, 0.25, (seed % 5) as f32],
                    ambient: [0.01, 0.02, 0.03],
                },
            }
        })
        .boxed()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    /// Any effect the validator accepts is written as RON that reloads to the very same
    /// effect: floats bit for bit (compared through `{:?}`, which tells -0.0 from 0.0),
    /// strings with quotes, backslashes, newlines and emoji, every option and variant.
    #[test]
    fn any_valid_effect_round_trips_exactly(e in effect()) {
        prop_assert_eq!(e.validate(), Ok(()));
        let text = format!("{}{}\n", preset::file_header(), preset::to_ron(&e).expect("ron"));
        let back = preset::parse_str(&text, "prop.ron");
        prop_assert!(back.is_ok(), "{}\n{}", back.err().map(|e| e.to_string()).unwrap_or_default(), text);
        let back = back.expect("checked");
        prop_assert_eq!(format!("{back:?}"), format!("{e:?}"));
        prop_assert_eq!(back, e);
        prop_assert!(!text.contains("Some("));
    }
}

/// The ```ron blocks of docs/presets.md, in order.
fn doc_ron_blocks() -> Vec<String> {
    let doc =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/presets.md"))
            .expect("docs/presets.md");
    doc.split("```ron\n")
        .skip(1)
        .filter_map(|b| b.split_once("\n```").map(|(code, _)| code.to_owned()))
        .collect()
}

/// The documentation's examples load: the minimal preset takes the documented defaults, and
/// the "every field and its default" block is exactly the code's defaults.
#[test]
fn documented_examples_and_defaults_match_the_code() {
    let blocks = doc_ron_blocks();
    assert_eq!(blocks.len(), 2, "two ```ron blocks in docs/presets.md");
    let minimal =
        preset::parse_str(&blocks[0], "docs/presets.md").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(minimal.emitters[0], Emitter::default());
    assert_eq!(minimal.time, TimeSettings::default());
    let sparks = &minimal.emitters[1];
    let turbulence = sparks.forces.turbulence.clone().expect("turbulence on");
    assert_eq!(turbulence.strength_m_per_s2, 3.0);
    assert_eq!(
        turbulence.frequency_per_m,
        Turbulence::default().frequency_per_m
    );
    assert_eq!(sparks.look.sprite, Sprite::Spark);
    assert_eq!(sparks.look.intensity, Look::default().intensity);

    let documented =
        preset::parse_str(&blocks[1], "docs/presets.md").unwrap_or_else(|e| panic!("{e}"));
    let mut expected = Effect::default();
    let e = &mut expected.emitters[0];
    e.bursts = vec![ignis::effect::Burst::default()];
    e.forces.gusts = Some(Gusts::default());
    e.forces.turbulence = Some(Turbulence::default());
    e.forces.vortex = Some(Vortex::default());
    e.forces.attractor = Some(Attractor::default());
    e.forces.flame_pull = Some(FlamePull::default());
    e.collisions.ground = Some(GroundPlane::default());
    e.collisions.spheres = vec![SphereCollider::default()];
    e.collisions.depth_collision = Some(DepthCollision::default());
    e.look.flipbook = Some(Flipbook::default());
    e.look.streak = Some(Streak::default());
    expected.post.bloom = Some(Bloom::default());
    assert_eq!(documented, expected);
}

/// Optional modules: left out or `None` = off, `()` = on with defaults, `Some(…)` accepted.
#[test]
fn optional_modules_are_written_as_groups() {
    let load = |forces: &str| {
        let text = format!("(version: 1, emitters: [(name: \"a\", forces: ({forces}))])");
        preset::parse_str(&text, "modules.ron")
            .unwrap_or_else(|e| panic!("{e}"))
            .emitters[0]
            .forces
            .clone()
    };
    assert_eq!(load("").turbulence, None);
    assert_eq!(load("turbulence: None").turbulence, None);
    assert_eq!(
        load("turbulence: ()").turbulence,
        Some(Turbulence::default())
    );
    assert_eq!(
        load("turbulence: Some((octaves: 3))").turbulence,
        Some(Turbulence {
            octaves: 3,
            ..Turbulence::default()
        })
    );
    assert_eq!(
        load("flame_pull: (exponent: 2.0)").flame_pull,
        Some(FlamePull {
            exponent: 2.0,
            ..FlamePull::default()
        })
    );
}

/// Files that are not presets at all are refused before parsing: a folder, a huge file.
#[test]
fn non_preset_files_are_refused_up_front() {
    let dir = tempfile::tempdir().expect("tempdir");
    let err = preset::load(dir.path()).expect_err("a folder");
    assert!(
        err.to_string().contains("is a folder, not a preset file"),
        "{err}"
    );
    let huge = dir.path().join("huge.ron");
    let f = std::fs::File::create(&huge).expect("create");
    f.set_len(preset::MAX_PRESET_BYTES + 1)
        .expect("sparse file");
    let err = preset::load(&huge).expect_err("too large");
    assert!(
        err.to_string().contains("is too large for a preset"),
        "{err}"
    );
    let err = preset::load(&dir.path().join("missing.ron")).expect_err("missing");
    assert!(err.to_string().contains("missing.ron: "), "{err}");
}
