//! Rendering on a real adapter: warm fire above the emitter, black elsewhere, dead
//! particles invisible, deterministic PNGs, `ignis render` end to end.
// The editor, the `ignis` binary or the benches: the default `editor` feature.
#![cfg(feature = "editor")]

mod common;

use common::*;
use glam::Vec3;
use ignis::effect::Effect;
use ignis::testing::headless::Headless;
use ignis::testing::shaders::ShaderLibrary;

const SIZE: (u32, u32) = (320, 240);

fn campfire_after(
    ctx: &ignis::testing::gpu::GpuContext,
    secs: f64,
    seed: u32,
) -> (Headless, image::RgbaImage) {
    let mut effect = Effect::default_campfire();
    effect.seed = seed;
    // Bloom's glow reaches every corner a little; it is tested in tests/looks.rs.
    effect.post.bloom = None;
    let mut run = Headless::new(ctx, effect, ShaderLibrary::embedded()).expect("headless");
    let frames = (secs * 60.0) as u32;
    for _ in 0..frames {
        run.advance(1.0 / 60.0);
    }
    let img = run.render(SIZE).expect("render");
    (run, img)
}

fn project(run: &Headless, p: Vec3) -> (f32, f32) {
    let clip = run.camera.clip_from_world(SIZE.0 as f32 / SIZE.1 as f32) * p.extend(1.0);
    let ndc = clip.truncate() / clip.w;
    (
        (ndc.x * 0.5 + 0.5) * SIZE.0 as f32,
        (0.5 - ndc.y * 0.5) * SIZE.1 as f32,
    )
}

fn mean_rgb(img: &image::RgbaImage, x0: u32, y0: u32, x1: u32, y1: u32) -> [f32; 3] {
    let mut s = [0.0f32; 3];
    let mut n = 0.0;
    for y in y0..y1 {
        for x in x0..x1 {
            let p = img.get_pixel(x, y);
            for c in 0..3 {
                s[c] += p[c] as f32;
            }
            n += 1.0;
        }
    }
    s.map(|v| v / n)
}

/// The default campfire: warm (red > green > blue, bright) just above the emitter,
/// black in the top corners far from it.
#[test]
fn default_frame_is_warm_above_the_emitter_and_black_far_away() {
    let ctx = gpu();
    let (run, img) = campfire_after(&ctx, 2.0, 1);
    let (ex, ey) = project(&run, Vec3::new(0.0, 0.35, 0.0));
    let (ex, ey) = (ex as u32, ey as u32);
    let warm = mean_rgb(&img, ex - 12, ey - 12, ex + 12, ey + 12);
    assert!(warm[0] > 150.0, "flame not bright: {warm:?}");
    assert!(
        warm[0] > warm[1] && warm[1] > warm[2],
        "flame not warm: {warm:?}"
    );
    for (x0, y0) in [
        (0, 0),
        (SIZE.0 - 24, 0),
        (0, SIZE.1 - 24),
        (SIZE.0 - 24, SIZE.1 - 24),
    ] {
        let c = mean_rgb(&img, x0, y0, x0 + 24, y0 + 24);
        assert!(
            c.iter().all(|&v| v < 3.0),
            "corner ({x0},{y0}) not black: {c:?}"
        );
    }
    // Beside the fire, 1.3 m to either side at flame height, stays black.
    for side in [-1.3f32, 1.3] {
        let (sx, sy) = project(&run, Vec3::new(side, 0.3, 0.0));
        assert!(
            sx > 10.0 && sx + 10.0 < SIZE.0 as f32,
            "the side probe is off-screen"
        );
        let c = mean_rgb(
            &img,
            sx as u32 - 10,
            sy as u32 - 10,
            sx as u32 + 10,
            sy as u32 + 10,
        );
        assert!(
            c.iter().all(|&v| v < 3.0),
            "beside the fire ({side} m): {c:?}"
        );
    }
    img.save(std::env::temp_dir().join("ignis_test_campfire.png"))
        .expect("save");
}

/// Nothing alive ⇒ a fully black frame (dead slots produce no fragments — unlike the
/// 2006 thesis, whose dead particles piled up at the origin).
#[test]
fn all_dead_frame_is_black() {
    let ctx = gpu();
    // Before any step: every slot is zero (dead).
    let mut run = Headless::new(&ctx, Effect::default_campfire(), ShaderLibrary::embedded())
        .expect("headless");
    let img = run.render(SIZE).expect("render");
    assert!(
        img.pixels().all(|p| p[0] == 0 && p[1] == 0 && p[2] == 0),
        "fresh pools drew something"
    );
    // After every particle died: lifetimes ≤ 4 s, spawning stopped.
    for _ in 0..60 {
        run.advance(1.0 / 60.0);
    }
    run.edit(|fx| {
        for e in &mut fx.emitters {
            e.spawn_rate_per_sec = ignis::effect::Param::Constant(0.0);
        }
    })
    .expect("edit");
    for _ in 0..(5 * 60) {
        run.advance(1.0 / 60.0);
    }
    assert_eq!(run.alive().expect("alive"), 0);
    let img = run.render(SIZE).expect("render");
    let lit = img
        .pixels()
        .filter(|p| p[0] > 0 || p[1] > 0 || p[2] > 0)
        .count();
    assert_eq!(lit, 0, "{lit} pixels lit with no particle alive");
}

/// Same seed ⇒ identical PNG bytes; a different seed ⇒ a different image.
#[test]
fn deterministic_frames_for_a_seed() {
    let ctx = gpu();
    let (_, a) = campfire_after(&ctx, 1.0, 3);
    let (_, b) = campfire_after(&ctx, 1.0, 3);
    let (_, c) = campfire_after(&ctx, 1.0, 4);
    assert!(a.as_raw() == b.as_raw(), "same seed, different pixels");
    let diff = a
        .as_raw()
        .iter()
        .zip(c.as_raw())
        .filter(|(x, y)| x != y)
        .count();
    assert!(diff > 1000, "different seeds differ in only {diff} bytes");
}

/// `ignis render` writes the requested PNG frames and prints its summary.
#[test]
fn render_command_writes_pngs() {
    let dir = tempfile::tempdir().expect("tempdir");
    let stdout = run_ok(
        std::process::Command::new(env!("CARGO_BIN_EXE_ignis"))
            .args(["render", "--frames", "5", "--size", "160x120"])
            .args(["--fps", "30", "--out"])
            .arg(dir.path()),
    );
    assert!(stdout.contains("rendered 5 frames"), "{stdout}");
    for f in 0..5 {
        let path = dir.path().join(format!("frame_{f:04}.png"));
        let img = image::open(&path).expect("png").to_rgba8();
        assert_eq!(img.dimensions(), (160, 120));
    }
    assert!(!dir.path().join("frame_0005.png").exists());
    // The last frame shows fire.
    let img = image::open(dir.path().join("frame_0004.png"))
        .expect("png")
        .to_rgba8();
    assert!(
        img.pixels().any(|p| p[0] > 200),
        "no bright pixel in the last frame"
    );
}

/// Bad arguments: a clear error and a non-zero exit, no panic.
#[test]
fn render_command_rejects_bad_input() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_ignis"))
        .args(["render", "--size", "0x10"])
        .output()
        .expect("run ignis");
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("size"));
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_ignis"))
        .args(["render", "no/such/preset.ron"])
        .output()
        .expect("run ignis");
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("no/such/preset.ron"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
}

/// The automatic choice splats small additive particles however few they are on a
/// software profile; a GPU profile splats them only where the emitter has a live quad
/// per `SPLAT_PX_PER_QUAD` pixels of the target (the splat clears and resolves the whole
/// target): the thesis preset's points half a second in splat at 480×270 under both, and
/// at 1920×1080 only under the software profile.
#[test]
fn a_gpu_profile_splats_only_dense_small_particles() {
    use ignis::testing::gpu::AdapterProfile;
    let base = gpu();
    let splats = |profile: AdapterProfile, size: (u32, u32)| {
        let ctx = base.clone().with_profile(Some(profile));
        let effect = ignis::preset::load("presets/thesis_2006.ron".as_ref()).expect("thesis");
        let mut run = Headless::new(&ctx, effect, ShaderLibrary::embedded()).expect("headless");
        for _ in 0..30 {
            run.advance(1.0 / 60.0);
        }
        run.render(size).expect("render");
        let items = run.player.draw_items();
        assert_eq!(items.len(), 1, "{items:?}");
        assert!(
            items[0].size_px < ignis::effect::SPLAT_BELOW_PX,
            "the points project small: {items:?}"
        );
        items[0].splat
    };
    let (small, full) = ((480, 270), (1920, 1080));
    assert!(splats(AdapterProfile::SOFTWARE, small));
    assert!(splats(AdapterProfile::SOFTWARE, full));
    assert!(splats(AdapterProfile::GPU, small));
    assert!(!splats(AdapterProfile::GPU, full), "sparse points splatted");
}

/// A stateless emitter draws the same fire as the stateful exponential integrator (exact
/// for the same forces): the draw passes evaluate its spawn records in closed form.
#[test]
fn stateless_emitter_renders_like_the_stateful_one() {
    let ctx = gpu();
    let render = |stateless: bool| {
        let mut effect = Effect::default_campfire();
        effect.emitters.retain(|e| e.name == "flames");
        effect.drop_dangling_events();
        let e = &mut effect.emitters[0];
        e.integrator = ignis::effect::Integrator::Exponential;
        // Closed form: constant acceleration and linear drag only.
        e.forces.turbulence = None;
        e.forces.flame_pull = None;
        e.stateless = stateless;
        let mut run = Headless::new(&ctx, effect, ShaderLibrary::embedded()).expect("headless");
        for _ in 0..45 {
            run.advance(1.0 / 60.0);
        }
        run.render(SIZE).expect("render")
    };
    let (a, b) = (render(false), render(true));
    let lit = a.pixels().filter(|p| p[0] > 50).count();
    assert!(lit > 500, "stateful frame nearly empty");
    let diff: f64 = a
        .as_raw()
        .iter()
        .zip(b.as_raw())
        .map(|(x, y)| (*x as f64 - *y as f64).abs())
        .sum::<f64>()
        / a.as_raw().len() as f64;
    assert!(diff < 1.0, "mean pixel difference {diff}");
}

/// The GPU bitonic sort equals a CPU sort of the same keys: random keys, sizes that are
/// not powers of two, many equal keys, and the extremes.
#[test]
fn gpu_sort_equals_cpu_sort() {
    let ctx = gpu();
    let mut sort = ignis::testing::render::sort::SortPass::new(&ctx, &ShaderLibrary::embedded())
        .expect("sort");
    let mut state = 0x9E37_79B9u32;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state
    };
    // The split network (workgroup-memory blocks) at every size, the plain one at some.
    let sizes = [
        (1usize, 0u32),
        (2, 0),
        (3, 0),
        (1000, 0),
        (1023, 7),
        (4096, 0),
        (5000, 3),
        (77_777, 1000),
    ];
    let plain = [(1000usize, 0u32), (5000, 3), (77_777, 1000)];
    let cases = sizes
        .iter()
        .map(|&(n, m)| (n, m, true))
        .chain(plain.iter().map(|&(n, m)| (n, m, false)));
    for (n, modulo, split) in cases {
        sort.split_network = split;
        let keys: Vec<u32> = (0..n)
            .map(|_| if modulo > 0 { next() % modulo } else { next() })
            .collect();
        let (gpu_keys, gpu_idx) = sort.sort_keys(&ctx, &keys).expect("sort");
        let mut cpu = keys.clone();
        cpu.sort_unstable();
        assert_eq!(gpu_keys, cpu, "n = {n}, split network {split}");
        // The indices are a permutation that carries each key with it.
        let mut seen = vec![false; n];
        for (k, i) in gpu_keys.iter().zip(&gpu_idx) {
            assert_eq!(keys[*i as usize], *k);
            assert!(!seen[*i as usize], "index {i} twice");
            seen[*i as usize] = true;
        }
    }
    let extremes = vec![u32::MAX, 0, u32::MAX - 1, 1, 0];
    assert_eq!(
        sort.sort_keys(&ctx, &extremes).expect("sort").0,
        vec![0, 0, 1, u32::MAX - 1, u32::MAX]
    );
}

/// Draws and the sort visit only each emitter's live window of the ring (the slots that
/// can hold a living particle) — the frame is the one drawing every slot gives, also after
/// the lifetimes were shortened mid-run (older particles keep their longer lives), and the
/// windows are much shorter than the pools.
#[test]
fn live_window_draws_what_the_whole_pool_draws() {
    let ctx = gpu();
    let mut effect = Effect::default_campfire();
    effect.post.bloom = None;
    // Live windows are the planner's: the smoke at a rate of its own (fed by the flames'
    // events, the GPU fills its ring and every slot is visited).
    for e in &mut effect.emitters {
        e.events.clear();
    }
    effect.emitters[0].spawn_rate_per_sec = ignis::effect::Param::Constant(90.0);
    let bounds: Vec<f32> = effect
        .emitters
        .iter()
        .map(|e| e.spawn_rate_per_sec.bounds().1 * (e.lifetime_secs.max + 2.0 / 60.0))
        .collect();
    let mut run = Headless::new(&ctx, effect, ShaderLibrary::embedded()).expect("headless");
    for f in 0..150 {
        if f == 120 {
            // An edit: every emitter's lifetimes shortened to a tenth.
            run.edit(|fx| {
                for e in &mut fx.emitters {
                    e.lifetime_secs.min *= 0.1;
                    e.lifetime_secs.max *= 0.1;
                }
            })
            .expect("edit");
        }
        run.advance(1.0 / 60.0);
    }
    let compare = |run: &mut Headless| {
        run.player.draw_resources().0.live_window_only = true;
        let windowed = run.render(SIZE).expect("render");
        run.player.draw_resources().0.live_window_only = false;
        let whole = run.render(SIZE).expect("render");
        run.player.draw_resources().0.live_window_only = true;
        let (mean, max) = image_diff(&windowed, &whole);
        let lit = windowed.pixels().filter(|p| p[0] > 40).count();
        (mean, max, lit)
    };
    let (mean, max, lit) = compare(&mut run);
    assert!(lit > 500, "only {lit} lit pixels: nothing to compare");
    // Additive light adds up in another order: f16 rounding at most.
    assert!(
        mean < 0.02 && max <= 2,
        "window vs whole pool: mean {mean}, max {max}"
    );
    // Every particle alive now lies in its emitter's window, and the windows are short.
    assert_eq!(bounds.len(), run.effect().emitters.len());
    for (i, bound) in bounds.iter().enumerate() {
        let (alive, len) = alive_in_window(&run, i, &format!("emitter {i}"));
        // At most rate × (the longest lifetime alive) plus two steps of spawns.
        assert!(
            (len as f32) <= *bound && len >= alive as u32,
            "emitter {i}: window {len} for {alive} alive (bound {bound})",
        );
    }
    // Later, once the long-lived particles died, the window shrinks to the new lifetimes.
    for _ in 0..300 {
        run.advance(1.0 / 60.0);
    }
    let (mean, max, _) = compare(&mut run);
    assert!(mean < 0.02 && max <= 2, "after: mean {mean}, max {max}");
    let smoke = window(&run, 0).1;
    // 90/s × 0.4 s = 36 spawns can be alive; the batch granularity adds a few steps.
    assert!(
        smoke <= 60,
        "smoke window {smoke} after the lifetimes shortened"
    );
}

/// Every alive slot of emitter `i` lies in its live window; returns (alive, window length).
fn alive_in_window(run: &Headless, i: usize, when: &str) -> (usize, u32) {
    let (first, len, cap) = window(run, i);
    let particles = run.player.particles(run.instance, i).expect("read");
    for (slot, p) in particles.iter().enumerate() {
        if p.is_alive() {
            let offset = (slot as u32 + cap - first) % cap;
            assert!(
                offset < len,
                "{when}: alive slot {slot} outside {first}+{len} (capacity {cap})"
            );
        }
    }
    (alive_of(&particles), len)
}

/// Emitter `i`'s visited window: (first slot, length, capacity).
fn window(run: &Headless, i: usize) -> (u32, u32, u32) {
    let s = run.player.emitter_stats(run.instance).expect("instance")[i];
    (s.first_visited, s.visited, s.capacity)
}

/// Live windows across the edits that move particles or stop the clock: a capacity change
/// after the ring wrapped (kept particles sit at their old slots until they die), and an
/// emitter disabled for longer than its lifetime, then enabled again (its frozen particles
/// live on from where they stopped).
#[test]
fn live_windows_survive_capacity_changes_and_disabled_emitters() {
    let ctx = gpu();
    let e = ignis::effect::Emitter {
        capacity: 1000,
        spawn_rate_per_sec: ignis::effect::Param::Constant(600.0),
        lifetime_secs: ignis::effect::Range::new(0.5, 1.0),
        ..plain_emitter()
    };
    let mut run = Headless::new(&ctx, bare_effect(e), ShaderLibrary::embedded()).expect("run");
    for _ in 0..200 {
        run.advance(1.0 / 60.0);
    }
    alive_in_window(&run, 0, "before the capacity change");
    // Wrapped several times: the kept slots do not match the new ring positions.
    run.edit(|fx| fx.emitters[0].capacity = 1500).expect("edit");
    let mut alive_after = Vec::new();
    for f in 0..90 {
        run.advance(1.0 / 60.0);
        let (alive, _) = alive_in_window(&run, 0, &format!("frame {f} after the capacity change"));
        alive_after.push(alive);
    }
    // The kept particles aged and died (nothing froze): steady state is rate × mean life.
    let last = *alive_after.last().expect("frames") as f32;
    assert!((last - 450.0).abs() < 60.0, "{last} alive after the change");
    let (_, len) = alive_in_window(&run, 0, "steady");
    assert!(
        len < 1500,
        "the window shrank back from the whole pool: {len}"
    );

    // Disabled for 2 s (longer than any lifetime), then enabled again.
    let (before, _) = alive_in_window(&run, 0, "before disabling");
    run.edit(|fx| fx.emitters[0].enabled = false).expect("edit");
    for _ in 0..120 {
        run.advance(1.0 / 60.0);
    }
    run.edit(|fx| fx.emitters[0].enabled = true).expect("edit");
    run.advance(1.0 / 60.0);
    let (resumed, _) = alive_in_window(&run, 0, "first frame after enabling");
    // One step later most frozen particles are still alive (and drawn).
    assert!(
        resumed as f32 > 0.8 * before as f32,
        "{resumed} alive after resuming, {before} before"
    );
    for f in 0..90 {
        run.advance(1.0 / 60.0);
        alive_in_window(&run, 0, &format!("frame {f} after enabling"));
    }
}

/// Many billboards (more than 65536 quads) in a window that wraps: the draw covers every
/// particle once — the billboards carry the splat's light, as in
/// `billboard_and_splat_paths_agree`, and a window wrapping past the capacity changes nothing.
#[test]
fn billboards_beyond_one_draw_carry_all_their_light() {
    use ignis::effect::DrawPath;
    let ctx = gpu();
    let render = |path: DrawPath| {
        let mut effect = Effect::default_campfire();
        effect.post.bloom = None;
        effect.emitters.retain(|e| e.name == "flames");
        effect.drop_dangling_events();
        let e = &mut effect.emitters[0];
        e.capacity = 150_000;
        e.spawn_rate_per_sec = ignis::effect::Param::Constant(120_000.0);
        e.lifetime_secs = ignis::effect::Range::new(0.8, 1.0);
        e.look.size_m = ignis::effect::Param::Curve {
            keys: vec![(0.0, 0.012), (1.0, 0.008)],
            smooth: false,
        };
        e.look.intensity = 0.08;
        e.look.draw_path = path;
        let mut run = Headless::new(&ctx, effect, ShaderLibrary::embedded()).expect("headless");
        run.composite.exposure = 0.5;
        // 1.5 s: the ring has wrapped, so the window crosses the end of the pool.
        for _ in 0..90 {
            run.advance(1.0 / 60.0);
        }
        let w = window(&run, 0);
        (run.render(SIZE).expect("render"), w)
    };
    let ((a, w), (b, _)) = (render(DrawPath::Billboard), render(DrawPath::Splat));
    assert!(
        w.1 > 65_536 * 3 / 2,
        "window {w:?}: more than one draw's worth"
    );
    assert!(
        w.0 + w.1 > 150_000,
        "window {w:?} should wrap past the capacity"
    );
    let (la, lb) = (total_light(&a), total_light(&b));
    assert!(la > 1e5, "billboards drew almost nothing: {la}");
    assert!(
        (la - lb).abs() / la < 0.10,
        "total light differs: billboard {la}, splat {lb}"
    );
}

/// Draft quality (the editor's default on software adapters): the flame tongues drawn at
/// half resolution and added before the bloom, and the bloom from a quarter-resolution
/// chain, look like the full-resolution frame — the same light within 3 % (measured
/// 0.46/255 mean, 1.5 % less light: a 4×4 average clips less above the threshold), a
/// little softer — while the thin embers stay in the full-resolution pass. So do the
/// flames of `post.glow_downscale: 2` (the shipped campfire's), at full quality.
#[test]
fn draft_glow_layer_renders_like_full_resolution() {
    let ctx = gpu();
    let mut effect = Effect::default_campfire();
    assert_eq!(
        effect.post.glow_downscale, 2,
        "the shipped campfire's flames"
    );
    effect.post.glow_downscale = 1;
    let mut run = Headless::new(&ctx, effect, ShaderLibrary::embedded()).expect("headless");
    for _ in 0..150 {
        run.advance(1.0 / 60.0);
    }
    let full = run.render(SIZE).expect("render");
    let unreduced = run.composite.reduced_layers(run.effect());
    assert!(!unreduced.contains(ignis::Layers::GLOW), "{unreduced:?}");
    // The flames are glow, the streaked embers and the alpha smoke are not.
    let glow: Vec<&str> = run
        .player
        .draw_items()
        .iter()
        .filter(|d| d.is_glow())
        .map(|d| run.effect().emitters[d.index].name.as_str())
        .collect();
    assert_eq!(glow, ["flames"]);
    for draft in [false, true] {
        run.composite.draft = draft;
        run.edit(|e| e.post.glow_downscale = if draft { 1 } else { 2 })
            .expect("edit");
        assert!(
            run.composite
                .reduced_layers(run.effect())
                .contains(ignis::Layers::GLOW)
        );
        let reduced = run.render(SIZE).expect("render");
        let (mean, max) = image_diff(&full, &reduced);
        let (lf, lr) = (total_light(&full), total_light(&reduced));
        assert!(mean > 0.0, "draft {draft}: no other path taken");
        assert!(
            mean < 1.0 && (lr / lf - 1.0).abs() < 0.03,
            "draft {draft} vs full: mean {mean} (max {max}), light {lr} vs {lf}"
        );
    }
}

/// Opacity multiplies a particle's contribution as its colour's alpha does: at opacity
/// 0.5 an emitter renders as itself with its colour's alpha halved, additive or blended.
#[test]
fn opacity_multiplies_like_the_colours_alpha() {
    let ctx = gpu();
    let render = |effect: Effect| {
        let mut run = Headless::new(&ctx, effect, ShaderLibrary::embedded()).expect("headless");
        for _ in 0..30 {
            run.advance(1.0 / 60.0);
        }
        run.render((96, 72)).expect("render")
    };
    for blend in [
        ignis::effect::BlendMode::Additive,
        ignis::effect::BlendMode::Alpha,
    ] {
        let mut e = plain_emitter();
        e.spawn_rate_per_sec = ignis::effect::Param::Constant(200.0);
        e.speed_m_per_s = ignis::effect::Range::new(0.3, 0.6);
        e.spread_deg = 60.0;
        e.look.blend = blend;
        e.look.color_over_life = flat_color([1.0, 0.6, 0.3, 0.5]);
        let halved_alpha = bare_effect(e.clone());
        e.look.color_over_life = flat_color([1.0, 0.6, 0.3, 1.0]);
        e.look.opacity = ignis::effect::Param::Constant(0.5);
        let half_opacity = bare_effect(e);
        let (a, b) = (render(halved_alpha), render(half_opacity));
        assert!(total_light(&a) > 1e4, "{blend:?}: almost nothing drawn");
        assert_eq!(
            image_diff(&a, &b),
            (0.0, 0),
            "{blend:?}: opacity 0.5 against alpha 0.5"
        );
    }
}

/// The campfire without its bloom (whose own draft setting aside, draft changes only the
/// reduced layers), played 1.5 s.
fn campfire_without_bloom(ctx: &ignis::testing::gpu::GpuContext) -> Headless {
    let mut effect = Effect::default_campfire();
    effect.post.bloom = None;
    let mut run = Headless::new(ctx, effect, ShaderLibrary::embedded()).expect("headless");
    for _ in 0..90 {
        run.advance(1.0 / 60.0);
    }
    run
}

/// The layers [`Composite::draw_particles`] draws apart (into targets of their own, added
/// in the tonemap) are exactly those reduced and drawn: the blended one at
/// `post.alpha_downscale` > 1 or in draft, the glow at `glow_downscale` > 1 or in draft,
/// and no layer the player has nothing in.
#[test]
fn only_reduced_layers_are_drawn_apart() {
    use ignis::Layers;
    let ctx = gpu();
    let mut run = campfire_without_bloom(&ctx);
    let layered = |run: &mut Headless, draft: bool, alpha: u32, glow: u32| {
        run.composite.draft = draft;
        run.edit(|e| (e.post.alpha_downscale, e.post.glow_downscale) = (alpha, glow))
            .expect("edit");
        let camera = run.camera.view(SIZE);
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        let Headless {
            composite, player, ..
        } = run;
        composite.record_player(&mut enc, player, &camera, None);
        let layered = composite.draw_particles(&ctx, &mut enc, player, &camera);
        ctx.queue.submit([enc.finish()]);
        layered
    };
    assert_eq!(layered(&mut run, false, 1, 1), Layers::NONE);
    assert_eq!(layered(&mut run, false, 2, 1), Layers::BLENDED);
    assert_eq!(layered(&mut run, false, 1, 2), Layers::GLOW);
    assert_eq!(
        layered(&mut run, true, 1, 1),
        Layers::BLENDED | Layers::GLOW
    );
    // Without its smoke the campfire has no blended layer to draw apart.
    run.edit(|e| {
        e.emitters
            .retain(|m| m.look.blend == ignis::effect::BlendMode::Additive);
        e.emitters.iter_mut().for_each(|m| m.events.clear());
    })
    .expect("edit");
    assert_eq!(layered(&mut run, false, 2, 2), Layers::GLOW);
}

/// Draft halves the blended layer's resolution again: the campfire in draft at
/// `alpha_downscale` 2 is the frame at 4, and not the frame at 2.
#[test]
fn draft_halves_the_blended_layers_resolution_again() {
    let ctx = gpu();
    let mut run = campfire_without_bloom(&ctx);
    let mut frame = |draft: bool, alpha: u32| {
        run.composite.draft = draft;
        run.edit(|e| (e.post.alpha_downscale, e.post.glow_downscale) = (alpha, 2))
            .expect("edit");
        run.render(SIZE).expect("render")
    };
    let (draft_2, at_4, at_2) = (frame(true, 2), frame(false, 4), frame(false, 2));
    assert_eq!(
        image_diff(&draft_2, &at_4),
        (0.0, 0),
        "draft at 2 against 4"
    );
    assert!(image_diff(&draft_2, &at_2).0 > 0.0, "draft at 2 against 2");
}

/// The adapter profile changes how the frame is made (render scale, draft layers, the UI
/// painter), never what the player draws: the
/// campfire renders the same frame and keeps the same particles under either profile.
/// (The draw path the automatic choice takes is the profile's `tile_raster` and
/// `splat_dense_only`; `tests/tiles.rs` holds the tiles to the billboards' image.)
#[test]
fn both_adapter_profiles_render_the_same_frame() {
    use ignis::testing::gpu::AdapterProfile;
    let render = |profile: AdapterProfile| {
        let ctx = gpu().with_profile(Some(profile));
        let mut effect = Effect::default_campfire();
        effect.post.bloom = None;
        let mut run = Headless::new(&ctx, effect, ShaderLibrary::embedded()).expect("headless");
        for _ in 0..45 {
            run.advance(1.0 / 60.0);
        }
        (
            run.render(SIZE).expect("render"),
            run.alive().expect("alive"),
        )
    };
    let (gpu_frame, gpu_alive) = render(AdapterProfile {
        tile_raster: false,
        splat_dense_only: false,
        ..AdapterProfile::GPU
    });
    let (soft_frame, soft_alive) = render(AdapterProfile::SOFTWARE);
    assert_eq!(gpu_alive, soft_alive, "the same particles");
    let (mean, max) = image_diff(&gpu_frame, &soft_frame);
    let lit = gpu_frame.pixels().filter(|p| p[0] > 40).count();
    assert!(lit > 500, "{lit} lit pixels");
    assert!(
        mean < 0.02 && max <= 2,
        "gpu vs software profile: mean {mean}, max {max}"
    );
}

/// `ignis bench presets --pipelined`'s frames: the parts of each frame in one submission,
/// frames back to back. They draw what the frames timed part by part draw (the same image
/// after the same frames), and the pass timer labels all four parts.
#[test]
fn pipelined_frames_draw_what_timed_frames_draw_and_time_every_part() {
    use ignis::testing::gpu::timer::{GpuTimer, PassTimer};
    let ctx = gpu();
    let effect = Effect::default_campfire();
    let mut apart = Headless::new(&ctx, effect.clone(), ShaderLibrary::embedded()).expect("run");
    let mut pipelined = Headless::new(&ctx, effect, ShaderLibrary::embedded()).expect("run");
    let camera = apart.camera.view(SIZE);
    let timer = GpuTimer::new(&ctx);
    let mut pass_timer = PassTimer::new_even_on_cpu(&ctx).expect("lavapipe has timestamps");
    for _ in 0..12 {
        apart.timed_frame(&timer, 1.0 / 60.0, &camera);
        pipelined.pipelined_frame(&mut pass_timer, 1.0 / 60.0, &camera);
    }
    let _ = ctx.device.poll(wgpu::PollType::wait_indefinitely());
    pass_timer.poll(&ctx);
    assert!(
        pass_timer.completed >= 4,
        "{} frames timed",
        pass_timer.completed
    );
    let labels: Vec<&str> = pass_timer.latest.iter().map(|s| s.0).collect();
    assert_eq!(labels, ["update", "record", "draw", "composite"]);
    assert!(
        pass_timer
            .latest
            .iter()
            .all(|s| s.1 >= 0.0 && s.1.is_finite())
    );
    // The display images the last frames left.
    let shown = |run: &Headless| {
        use ignis::testing::gpu::TextureReadback;
        let ldr = &run.composite.targets_ref().expect("targets").ldr;
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        let readback = TextureReadback::record(&ctx.device, &mut enc, ldr, "shown");
        ctx.queue.submit([enc.finish()]);
        let bytes = ignis::testing::sim::gpu_sim::map_read(&ctx, &readback.buffer).expect("read");
        readback.rows(&bytes).expect("rows").concat()
    };
    let (a, b) = (shown(&apart), shown(&pipelined));
    assert!(
        a.iter().map(|&v| u64::from(v)).sum::<u64>() > 1e5 as u64,
        "almost nothing drawn"
    );
    assert!(a == b, "pipelined frames drew another image");
}

/// One run rendered at one size, then another, then the first again gives at each size the
/// image a fresh run gives: the composite's targets follow the frame's size.
#[test]
fn the_composite_follows_the_frames_size() {
    let ctx = gpu();
    let played = || {
        let mut run = Headless::new(&ctx, Effect::default_campfire(), ShaderLibrary::embedded())
            .expect("headless");
        for _ in 0..20 {
            run.advance(1.0 / 60.0);
        }
        run
    };
    let mut run = played();
    for size in [(96, 72), (64, 48), (96, 72)] {
        let image = run.render(size).expect("render");
        assert_eq!(image.dimensions(), size);
        let fresh = played().render(size).expect("render");
        assert!(image == fresh, "{size:?}: not the image a fresh run gives");
    }
}

/// The preset's exposure scales the light before the tonemap as the view's does: an
/// additive effect at exposure 2 renders as itself with twice the intensity (no bloom, whose
/// threshold is not linear).
#[test]
fn a_presets_exposure_multiplies_the_light() {
    let ctx = gpu();
    let mut e = plain_emitter();
    e.spawn_rate_per_sec = ignis::effect::Param::Constant(200.0);
    e.speed_m_per_s = ignis::effect::Range::new(0.3, 0.6);
    e.spread_deg = 60.0;
    e.look.intensity = 0.5;
    let mut effect = bare_effect(e);
    effect.post.bloom = None;
    let render = |effect: Effect| {
        let mut run = Headless::new(&ctx, effect, ShaderLibrary::embedded()).expect("headless");
        for _ in 0..30 {
            run.advance(1.0 / 60.0);
        }
        run.render((96, 72)).expect("render")
    };
    let mut exposed = effect.clone();
    exposed.post.exposure = 2.0;
    let mut brighter = effect;
    brighter.emitters[0].look.intensity = 1.0;
    let (a, b) = (render(exposed), render(brighter));
    assert!(total_light(&a) > 1e4, "almost nothing drawn");
    let (mean, max) = image_diff(&a, &b);
    assert!(
        mean < 0.1 && max <= 2,
        "{mean:.3}/255 mean, {max}/255 max apart"
    );
}
