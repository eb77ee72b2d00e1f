//! The compute splat draws what the billboards draw: a sprite small enough for the splat
//! adds, at every pixel centre it covers, the texel the billboard's fragment would add
//! there. Every shipped preset's small additive emitters, 3-px flames (flipbook, blended
//! frames, ground fade) and a dense 3-px sphere of sparks agree with the billboards within
//! 1/255 mean; a large sprite forced onto the splat keeps its integrated light. All on the
//! real adapter (lavapipe in CI).

mod common;

use common::{gpu, image_diff, share_off, total_light};
use ignis::effect::{BlendMode, DrawPath, Effect, Param, Range, Shape, Sprite};
use ignis::testing::gpu::{GpuContext, INT64_ATOMICS};
use ignis::testing::headless::Headless;
use ignis::testing::shaders::ShaderLibrary;

const SIZE: (u32, u32) = (192, 144);

/// `effect` after `frames` frames at 60 fps at `size`, with the emitters in `splat` on
/// the splat and every other on the billboards.
fn render(
    ctx: &GpuContext,
    effect: &Effect,
    splat: &[usize],
    frames: u32,
    size: (u32, u32),
) -> image::RgbaImage {
    let mut effect = effect.clone();
    // The blended layer at full resolution: the comparison is the additive light's.
    effect.post.alpha_downscale = 1;
    for (i, e) in effect.emitters.iter_mut().enumerate() {
        e.look.draw_path = if splat.contains(&i) {
            DrawPath::Splat
        } else {
            DrawPath::Billboard
        };
    }
    let mut run = Headless::new(ctx, effect, ShaderLibrary::embedded()).expect("headless");
    for _ in 0..frames {
        run.advance(1.0 / 60.0);
    }
    let img = run.render(size).expect("render");
    for d in run.player.draw_items() {
        assert_eq!(d.splat, splat.contains(&d.index), "emitter {}", d.index);
    }
    img
}

/// The additive emitters of `effect` whose sprites the automatic choice would splat at
/// `size` (smaller than `SPLAT_BELOW_PX`) after `frames` frames.
fn small_additive(ctx: &GpuContext, effect: &Effect, frames: u32, size: (u32, u32)) -> Vec<usize> {
    let mut run = Headless::new(ctx, effect.clone(), ShaderLibrary::embedded()).expect("headless");
    for _ in 0..frames {
        run.advance(1.0 / 60.0);
    }
    run.render(size).expect("render");
    let mut small: Vec<usize> = run
        .player
        .draw_items()
        .iter()
        .filter(|d| d.blend == BlendMode::Additive && d.size_px < ignis::effect::SPLAT_BELOW_PX)
        .filter(|d| effect.emitters[d.index].look.streak.is_none())
        .filter(|d| effect.emitters[d.index].look.trail.is_none())
        .map(|d| d.index)
        .collect();
    small.sort_unstable();
    small.dedup();
    small
}

/// The splat's and the billboards' images of `effect` (the `splat` emitters on the
/// splat) agree within 1/255 mean, and no more than 0.2 % of the channels differ by more
/// than 8/255 (a tilted sprite's edge through a pixel centre: the rasteriser's
/// snapping); returns the mean.
fn splat_agrees(what: &str, effect: &Effect, splat: &[usize], size: (u32, u32)) -> f64 {
    splat_agrees_on(&gpu(), what, effect, splat, size)
}

/// [`splat_agrees`] on the device of `ctx`.
fn splat_agrees_on(
    ctx: &GpuContext,
    what: &str,
    effect: &Effect,
    splat: &[usize],
    size: (u32, u32),
) -> f64 {
    let a = render(ctx, effect, &[], 60, size);
    let b = render(ctx, effect, splat, 60, size);
    assert!(
        total_light(&a) > 1e3,
        "{what}: the billboards drew almost nothing"
    );
    let (mean, max) = image_diff(&a, &b);
    let off = share_off(&a, &b);
    if std::env::var_os("IGNIS_SAVE_SPLAT_IMAGES").is_some() {
        let stem = what.replace(['/', ' ', ','], "_");
        let _ = a.save(format!("target/splat-{stem}-billboard.png"));
        let _ = b.save(format!("target/splat-{stem}-splat.png"));
    }
    let light = (total_light(&a), total_light(&b));
    eprintln!(
        "{what}: mean {mean:.3}/255, max {max}/255, {:.3} % over 8/255; light {:.0} / {:.0}",
        100.0 * off,
        light.0,
        light.1
    );
    assert!(
        mean <= 1.0 && off <= 0.002,
        "{what}: the splat differs from the billboards by {mean:.3}/255 mean, \
         {:.3} % of channels over 8/255",
        100.0 * off
    );
    mean
}

/// Every shipped preset at the test's size.
#[test]
fn every_shipped_preset_splats_its_small_sprites_as_the_billboards_draw_them() {
    // The thesis's points.
    presets_splat_alike(SIZE, 1);
}

/// At half the test's size, where more of each effect is small.
#[test]
fn every_shipped_preset_splats_alike_at_half_the_size() {
    // The thesis's points, the bonfire's and the torch's small light.
    presets_splat_alike((SIZE.0 / 2, SIZE.1 / 2), 3);
}

/// Every shipped preset's small additive emitters splat as the billboards draw them at
/// `size`; at least `expected` emitters are splatted.
///
/// At a quarter of the test's size (48×36) the others agree as well (candle 0.27/255,
/// gas flare 0.31, spark fountain 0.002, torch 0.44) but the bonfire does not: its whole
/// fire piles hundreds of sprites on each pixel, and lavapipe's blending rounds the f16
/// target toward zero at every one, so its billboards lose 7 % of the light that the
/// splat's fixed-point sum keeps (2.55/255 mean). GPUs round to nearest.
fn presets_splat_alike(size: (u32, u32), expected: usize) {
    let ctx = gpu();
    let (mut splatted, mut failed) = (0, Vec::new());
    for path in common::shipped_preset_paths() {
        let effect = ignis::preset::load(&path).expect("shipped preset loads");
        let small = small_additive(&ctx, &effect, 60, size);
        if small.is_empty() {
            continue;
        }
        splatted += small.len();
        let what = format!("{} at {}x{}", path.display(), size.0, size.1);
        if std::panic::catch_unwind(|| splat_agrees(&what, &effect, &small, size)).is_err() {
            failed.push(what);
        }
    }
    assert!(failed.is_empty(), "{failed:?}");
    assert!(
        splatted >= expected,
        "only {splatted} small additive emitters splatted"
    );
}

/// The campfire's flames at about 3 px: a blended flipbook with a ground fade.
#[test]
fn three_pixel_flames_splat_as_the_billboards_draw_them() {
    let mut effect = Effect::default_campfire();
    effect.emitters.retain(|e| e.name == "flames");
    effect.drop_dangling_events();
    let e = &mut effect.emitters[0];
    e.look.size_m = Param::Curve {
        keys: vec![(0.0, 0.03), (1.0, 0.02)],
        smooth: false,
    };
    e.look.intensity = 0.6;
    assert!(e.look.flipbook.is_some() && e.look.soft_ground_m > 0.0);
    splat_agrees("3-px flames", &effect, &[0], SIZE);
}

/// `look` as a plain soft disc: no flipbook, streak or trail.
fn plain_disc(look: &mut ignis::effect::Look) {
    look.sprite = Sprite::SoftDisc;
    look.flipbook = None;
    look.streak = None;
    look.trail = None;
}

/// One still white additive particle living 10 s, a plain look, seen by the orbit camera
/// 3 m out on +z (45°), with `look` applied.
fn one_still(look: impl FnOnce(&mut ignis::effect::Look)) -> Effect {
    let mut e = common::still_burst(1, 10.0);
    plain_disc(&mut e.look);
    e.look.soft_ground_m = 0.0;
    e.look.blend = BlendMode::Additive;
    e.look.color_over_life = common::flat_color([1.0; 4]);
    look(&mut e.look);
    let mut effect = common::bare_effect(e);
    effect.camera.target_m = [0.0; 3];
    effect.camera.distance_m = 3.0;
    effect.camera.pitch_deg = 0.0;
    effect.camera.yaw_deg = 0.0;
    effect
}

/// An upright sprite whose edges pass through pixel centres splats the rasteriser's pixels:
/// the centres in the half-open box of its corners (the top-left rule: its left column and
/// top row, not its right column or bottom row). A white square 4 px wide, centred on the
/// middle pixel centre of a 193×145 target, lights the 4×4 pixels its billboard lights.
#[test]
fn an_upright_sprite_on_pixel_centres_splats_the_rasterisers_pixels() {
    let ctx = gpu();
    let dir = tempfile::tempdir().expect("tempdir");
    let size = (193, 145);
    let effect = one_still(|look| {
        look.sprite = common::white_sprite(dir.path());
        look.size_m = Param::Constant((4.0 / common::px_per_m_at_3m(size.1)) as f32);
        look.intensity = 0.5;
    });
    let expected: Vec<(u32, u32)> = (70..74)
        .flat_map(|y| (94..98).map(move |x| (x, y)))
        .collect();
    let billboard = common::lit_pixels(&render(&ctx, &effect, &[], 10, size));
    assert_eq!(billboard, expected, "the billboard's pixels");
    let splat = common::lit_pixels(&render(&ctx, &effect, &[0], 10, size));
    assert_eq!(splat, expected, "the splat's pixels");
}

/// A streak's depth comes from its projective map (clip z over clip w across the quad): a
/// still streaked spark forced onto the splat is clipped by the depth range as the
/// billboards clip it. The orbit camera 3 m out sees to 400 m: sparks of about 4 px 300 m
/// out draw on both paths, 1 km out on neither.
#[test]
fn a_splatted_streak_beyond_the_far_plane_draws_nothing() {
    let ctx = gpu();
    let spark = |distance_m: f32| {
        let mut effect = one_still(|look| {
            look.streak = Some(ignis::effect::Streak {
                length_secs: 0.01,
                max_length_m: 0.01,
            });
            look.size_m = Param::Constant(0.024 * distance_m);
            look.intensity = 1.0;
        });
        effect.emitters[0].transform.position_m = [0.0, 0.0, 3.0 - distance_m];
        effect
    };
    let near = spark(300.0);
    let (a, b) = (
        render(&ctx, &near, &[], 10, SIZE),
        render(&ctx, &near, &[0], 10, SIZE),
    );
    let (la, lb) = (total_light(&a), total_light(&b));
    assert!(
        la > 100.0 && lb > 0.5 * la,
        "300 m: light {la} (billboards), {lb} (splat)"
    );
    let far = spark(1000.0);
    let (a, b) = (
        render(&ctx, &far, &[], 10, SIZE),
        render(&ctx, &far, &[0], 10, SIZE),
    );
    assert_eq!(total_light(&a), 0.0, "billboards past the far plane");
    assert_eq!(total_light(&b), 0.0, "the splat past the far plane");
}

/// A dense sphere of 3-px sparks at the test's size: 24000 in a 1 m sphere, 2 s lives,
/// gravity and drag, a soft disc.
fn dense_sphere(ctx: &GpuContext) -> Effect {
    let mut effect = Effect::default_campfire();
    effect.emitters.retain(|e| e.name == "embers");
    effect.drop_dangling_events();
    let e = &mut effect.emitters[0];
    e.capacity = 24_000;
    e.spawn_rate_per_sec = Param::Constant(12_000.0);
    e.lifetime_secs = Range::new(2.0, 2.0);
    e.shape = Shape::Sphere {
        radius_m: 1.0,
        surface_only: false,
    };
    e.speed_m_per_s = Range::new(0.0, 0.3);
    e.forces.gravity_m_per_s2 = [0.0, -0.5, 0.0];
    e.forces.drag_per_sec = 0.5;
    plain_disc(&mut e.look);
    e.look.intensity = 0.05;
    e.look.size_m = Param::Constant(0.02);
    // Scaled so that the sprites project at 3 px.
    let mut run = Headless::new(ctx, effect.clone(), ShaderLibrary::embedded()).expect("headless");
    run.advance(1.0 / 60.0);
    run.render(SIZE).expect("render");
    let px = run.player.draw_items()[0].size_px;
    effect.emitters[0].look.size_m = Param::Constant(0.02 * 3.0 / px);
    assert_eq!(small_additive(ctx, &effect, 1, SIZE), [0], "{px} px");
    effect
}

/// Light fainter than one unit of the accumulation per pixel keeps its energy: the dense
/// sphere at 1/400 of its intensity adds under a third of a unit (1/2048 packed, 1/4096 in
/// u32) at a pixel per sprite, rounded up or down by a dither; at an exposure that shows it
/// both accumulations give the billboards' total light within 10 % (the billboards' f16
/// sums are exact at these levels; the dithered units are noise, which the tonemap's
/// concave curve turns into a few percent less light: measured −6.7 % packed). Rounded
/// without the dither, nearly all of it would be lost.
#[test]
fn light_fainter_than_a_unit_keeps_its_energy_on_both_accumulations() {
    let ctx = gpu();
    let narrow = GpuContext::headless_without(INT64_ATOMICS).expect("a device");
    let mut effect = dense_sphere(&ctx);
    effect.emitters[0].look.intensity /= 400.0;
    effect.post.exposure = 100.0;
    effect.post.bloom = None;
    let reference = total_light(&render(&ctx, &effect, &[], 60, SIZE));
    assert!(reference > 1e5, "the billboards' light: {reference}");
    for (what, device) in [("u64", &ctx), ("3 × u32", &narrow)] {
        let light = total_light(&render(device, &effect, &[0], 60, SIZE));
        eprintln!("faint sphere, {what}: light {light:.0} against {reference:.0}");
        assert!(
            (light - reference).abs() < 0.10 * reference,
            "{what}: faint light {light:.0} against the billboards' {reference:.0}"
        );
    }
}

/// A dense sphere of 3-px sparks (the peers' workload, scaled to the test's target): a
/// 1 m sphere, 2 s lives, gravity and drag, a soft disc. On a device with 64-bit atomics
/// (one per lit pixel: lavapipe has them) and on one without (three u32 per pixel).
#[test]
fn a_dense_sphere_of_three_pixel_sparks_splats_as_the_billboards_draw_it() {
    let ctx = gpu();
    let narrow = GpuContext::headless_without(INT64_ATOMICS).expect("a device");
    assert!(
        ctx.device.features().contains(INT64_ATOMICS),
        "lavapipe has 64-bit atomics"
    );
    assert!(!narrow.device.features().contains(INT64_ATOMICS));
    let effect = dense_sphere(&ctx);
    splat_agrees_on(&ctx, "dense 3-px sphere, u64", &effect, &[0], SIZE);
    splat_agrees_on(&narrow, "dense 3-px sphere, 3 × u32", &effect, &[0], SIZE);
}

/// Instances of one preset share the splat's dispatch (workgroup z is the instance):
/// three dense spheres side by side, batched into one draw, splat as the billboards draw
/// them.
#[test]
fn batched_instances_splat_as_the_billboards_draw_them() {
    let ctx = gpu();
    let mut effect = dense_sphere(&ctx);
    effect.emitters[0].capacity /= 3;
    effect.emitters[0].spawn_rate_per_sec = Param::Constant(4_000.0);
    let image = |splat: bool| {
        let mut effect = effect.clone();
        effect.emitters[0].look.draw_path = if splat {
            DrawPath::Splat
        } else {
            DrawPath::Billboard
        };
        let mut run = Headless::new(&ctx, effect, ShaderLibrary::embedded()).expect("headless");
        for (k, x) in [-1.6f32, 1.6].into_iter().enumerate() {
            let at = ignis::glam::Mat4::from_translation(ignis::glam::Vec3::new(x, 0.3, 0.0));
            run.player
                .add_instance(at, k as u32 + 7)
                .expect("an instance");
        }
        for _ in 0..60 {
            run.advance(1.0 / 60.0);
        }
        let img = run.render(SIZE).expect("render");
        let d = &run.player.draw_items()[0];
        assert_eq!(
            (d.members, d.splat),
            (3, splat),
            "one draw of three instances"
        );
        img
    };
    let (a, b) = (image(false), image(true));
    let (mean, max) = image_diff(&a, &b);
    eprintln!("three spheres: mean {mean:.3}/255, max {max}/255");
    assert!(total_light(&a) > 1e4);
    assert!(
        mean <= 1.0 && share_off(&a, &b) <= 0.002,
        "{mean:.3}/255, max {max}"
    );
}

/// Streaks (quads stretched along the velocity: a projective map) forced onto the splat
/// add their footprint as the billboards draw them: the dense sphere's sparks with tails
/// of a centimetre at most (a pixel or two: their boxes stay within the footprint's 8 px).
#[test]
fn small_streaks_forced_onto_the_splat_draw_their_footprint() {
    let ctx = gpu();
    let mut effect = dense_sphere(&ctx);
    let e = &mut effect.emitters[0];
    e.speed_m_per_s = Range::new(0.5, 1.0);
    e.look.streak = Some(ignis::effect::Streak {
        length_secs: 0.01,
        max_length_m: 0.01,
    });
    splat_agrees_on(&ctx, "small streaks", &effect, &[0], SIZE);
}

/// The editor's and renders' own HDR image takes the splat's light by compute
/// (`resolve_add`) where the adapter can read and write it in place: the image the
/// resolve's draw gives (the thesis's points; the spark fountain's sparks and glow).
#[test]
fn the_compute_resolve_adds_what_the_resolve_draw_does() {
    let ctx = gpu();
    for name in ["thesis_2006", "spark_fountain"] {
        let path = format!("presets/{name}.ron");
        let mut effect = ignis::preset::load(path.as_ref()).expect("shipped preset");
        for e in &mut effect.emitters {
            if e.look.blend == BlendMode::Additive && e.look.heat_haze.is_none() {
                e.look.draw_path = DrawPath::Splat;
            }
        }
        let image = |compute: bool| {
            let mut run =
                Headless::new(&ctx, effect.clone(), ShaderLibrary::embedded()).expect("headless");
            run.player.splat_pass().set_compute_resolve(compute);
            for _ in 0..60 {
                run.advance(1.0 / 60.0);
            }
            let image = run.render(SIZE).expect("render");
            let used = run.player.splat_pass().can_resolve_into(SIZE);
            assert_eq!(used, compute, "{name}: compute resolve used: {used}");
            assert!(run.player.draw_items().iter().any(|d| d.splat), "{name}");
            (image, run.player.recorded_commands())
        };
        common::compute_resolve_replaces_the_draw(name, &image(false), &image(true));
    }
}

/// One large sprite forced onto the splat adds its integrated light at the four pixels
/// nearest its centre, bilinearly: a single 0.3 m disc at the orbit's target (tens of
/// pixels: past the footprint's 8) lights a 2×2 block around the billboard's centre of
/// light, its own centre within 0.35 px of it (8-bit sRGB shifts a centre of
/// four bilinear weights by a fraction of a pixel; a tap a pixel off moves it by one).
#[test]
fn one_large_sprite_forced_onto_the_splat_lights_the_four_pixels_at_its_centre() {
    let ctx = gpu();
    let mut effect = one_large_disc();
    // The disc a fraction of a pixel off the target's pixel corner: unequal weights.
    effect.camera.target_m = [0.011, 0.007, 0.0];
    effect.camera.pitch_deg = 0.0;
    effect.post.bloom = None;
    let a = render(&ctx, &effect, &[], 90, SIZE);
    let b = render(&ctx, &effect, &[0], 90, SIZE);
    let lit: Vec<(u32, u32)> = b
        .enumerate_pixels()
        .filter(|(_, _, p)| p[0] > 0 || p[1] > 0 || p[2] > 0)
        .map(|(x, y, _)| (x, y))
        .collect();
    assert!(!lit.is_empty() && lit.len() <= 4, "lit pixels {lit:?}");
    let (x0, y0) = (lit.iter().map(|p| p.0).min(), lit.iter().map(|p| p.1).min());
    let (x0, y0) = (x0.unwrap_or(0), y0.unwrap_or(0));
    assert!(
        lit.iter().all(|&(x, y)| x <= x0 + 1 && y <= y0 + 1),
        "not a 2×2 block: {lit:?}"
    );
    let ca = centroid(&a);
    let inside = |c: f64, lo: u32| c >= f64::from(lo) && c <= f64::from(lo) + 1.0;
    assert!(
        inside(ca.0, x0) && inside(ca.1, y0),
        "the billboard's centre {ca:?} is not among the lit pixels {lit:?}"
    );
    let cb = centroid(&b);
    let d = ((ca.0 - cb.0).powi(2) + (ca.1 - cb.1).powi(2)).sqrt();
    eprintln!("one large sprite: centres {ca:?} and {cb:?} ({d:.3} px), lit {lit:?}");
    assert!(d < 0.35, "centres {ca:?} and {cb:?}");
}

/// A large sprite forced onto the splat fades towards the ground by its centre's height,
/// as the billboards fade its middle: 0.1 m above a ground that fades sprites over 0.4 m,
/// its light is a quarter of the unfaded disc's (after the display's encoding, between
/// 0.3 and 0.8 of it).
#[test]
fn a_large_splatted_sprite_fades_towards_the_ground_by_its_centre() {
    let ctx = gpu();
    let mut bright = one_large_disc();
    bright.camera.pitch_deg = 0.0;
    bright.post.bloom = None;
    let mut faded = bright.clone();
    faded.emitters[0].collisions.ground = Some(ignis::effect::GroundPlane {
        height_m: -0.1,
        kill_on_contact: false,
    });
    faded.emitters[0].look.soft_ground_m = 0.4;
    let a = total_light(&render(&ctx, &bright, &[0], 90, SIZE));
    let b = total_light(&render(&ctx, &faded, &[0], 90, SIZE));
    assert!(
        a > 0.0 && b > 0.3 * a && b < 0.8 * a,
        "light: unfaded {a}, faded {b}"
    );
}

/// One still 0.3 m disc at the origin (tens of pixels: past the footprint's 8), dim and
/// additive, born in the first second and living 10 s.
fn one_large_disc() -> Effect {
    let mut e = common::plain_emitter();
    e.capacity = 1;
    e.spawn_rate_per_sec = Param::Constant(1.0);
    e.lifetime_secs = Range::new(10.0, 10.0);
    plain_disc(&mut e.look);
    e.look.soft_ground_m = 0.0;
    e.look.size_m = Param::Constant(0.3);
    e.look.intensity = 0.05;
    e.look.blend = BlendMode::Additive;
    common::bare_effect(e)
}

/// The light-weighted centre of `img` in pixels.
fn centroid(img: &image::RgbaImage) -> (f64, f64) {
    let (mut sx, mut sy, mut total) = (0.0, 0.0, 0.0);
    for (x, y, p) in img.enumerate_pixels() {
        let l = f64::from(p[0]) + f64::from(p[1]) + f64::from(p[2]);
        sx += l * f64::from(x);
        sy += l * f64::from(y);
        total += l;
    }
    (sx / total, sy / total)
}

/// A sprite larger than the footprint's limit, forced onto the splat, adds its integrated
/// light at its centre (a few pixels, not its footprint): the campfire's flames (tens of
/// pixels) keep their light where the billboards put it — centroids within 3 px — though
/// the points saturate the display (no bloom here; a third of the light or more is left).
#[test]
fn large_sprites_forced_onto_the_splat_keep_their_light_at_their_centres() {
    let ctx = gpu();
    let mut effect = Effect::default_campfire();
    effect.emitters.retain(|e| e.name == "flames");
    effect.drop_dangling_events();
    effect.post.bloom = None;
    let a = render(&ctx, &effect, &[], 60, SIZE);
    let b = render(&ctx, &effect, &[0], 60, SIZE);
    let (la, lb) = (total_light(&a), total_light(&b));
    assert!(la > 1e5, "billboards drew almost nothing: {la}");
    assert!(
        lb > la / 3.0 && lb < la,
        "light: billboard {la}, splat {lb}"
    );
    let (ca, cb) = (centroid(&a), centroid(&b));
    let d = ((ca.0 - cb.0).powi(2) + (ca.1 - cb.1).powi(2)).sqrt();
    assert!(d < 3.0, "centroids {ca:?} and {cb:?}");
    let (mean, _) = image_diff(&a, &b);
    assert!(
        mean > 1.0,
        "large sprites took their footprint: {mean:.3}/255"
    );
}

/// A frame whose only particles are splatted reports its light layer drawn (a host's
/// composite reads it to know there is light to add); before any record, nothing is.
#[test]
fn a_frame_of_splatted_light_alone_reports_the_light_layer_drawn() {
    let ctx = gpu();
    let mut effect = one_still(|look| look.draw_path = DrawPath::Splat);
    effect.post.alpha_downscale = 1;
    let mut run = Headless::new(&ctx, effect, ShaderLibrary::embedded()).expect("headless");
    assert_eq!(
        run.player.drawn_layers(),
        ignis::Layers::NONE,
        "nothing recorded"
    );
    run.advance(1.0 / 60.0);
    run.render(SIZE).expect("render");
    let items = run.player.draw_items();
    assert!(items.iter().all(|d| d.splat), "every emitter splatted");
    assert_eq!(run.player.drawn_layers(), ignis::Layers::LIGHT);
}
