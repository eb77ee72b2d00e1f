//! The tile rasteriser (`tiles.wgsl`) draws what the billboards draw: each look module
//! with both paths forced agrees within 1/255 mean and 8/255 max, every shipped preset
//! within 1/255 mean with at most 0.01 % of channels over 8/255 (a rotated sprite's edge
//! through a pixel centre; measured on lavapipe: at most 0.005/255 mean); sprites smaller than a
//! pixel cover the rasteriser's pixels; sprites crossing tile borders, larger than the screen, behind the camera,
//! piled hundreds deep on one tile, or thousands over several bins whose lists overflow keep
//! all their light, as do two and sixteen emitters over different bins; every frame starts
//! from empty tiles; a target wider in bins than tall scans every bin, and one of more bins
//! than the tiles hold goes to the billboards; a record the bench
//! stops before the shade leaves the fire to the billboards; lit flipbooks blend their
//! frames alike on both paths; binning is deterministic; the
//! automatic choice follows the adapter profile. All on the real adapter (lavapipe in CI).

mod common;

use common::{gpu, image_diff, share_off, total_light};
use ignis::effect::{
    BlendMode, DrawPath, Effect, Flipbook, FlipbookMode, Lighting, Param, Range, Shape, SixWayMaps,
    Sprite, Streak,
};
use ignis::testing::gpu::{AdapterProfile, GpuContext};
use ignis::testing::headless::Headless;
use ignis::testing::render::TileStages;
use ignis::testing::shaders::ShaderLibrary;

const SIZE: (u32, u32) = (192, 144);

/// `effect` with every emitter forced onto `path` (but those on the splat), after
/// `frames` frames at 60 fps.
fn render(ctx: &GpuContext, effect: &Effect, path: DrawPath, frames: u32) -> image::RgbaImage {
    render_at(ctx, effect, path, frames, SIZE)
}

/// [`render`] at `size` pixels.
fn render_at(
    ctx: &GpuContext,
    effect: &Effect,
    path: DrawPath,
    frames: u32,
    size: (u32, u32),
) -> image::RgbaImage {
    let mut images = render_frames(ctx, effect, path, &[frames], size);
    images.pop().expect("one image")
}

/// [`render_at`] after each of `frames` (ascending) frames, all from one run.
fn render_frames(
    ctx: &GpuContext,
    effect: &Effect,
    path: DrawPath,
    frames: &[u32],
    size: (u32, u32),
) -> Vec<image::RgbaImage> {
    let mut effect = full_resolution(effect.clone());
    for e in &mut effect.emitters {
        if e.look.draw_path != DrawPath::Splat {
            e.look.draw_path = path;
        }
    }
    let wanted = effect
        .emitters
        .iter()
        .any(|e| e.look.draw_path == DrawPath::Tiles && e.look.streak.is_none());
    let mut run = Headless::new(ctx, effect, ShaderLibrary::embedded()).expect("headless");
    let mut played = 0;
    let mut images = Vec::new();
    for &at in frames {
        assert!(at >= played, "frames ascending: {frames:?}");
        for _ in played..at {
            run.advance(1.0 / 60.0);
        }
        played = at;
        images.push(run.render(size).expect("render"));
        let tiled = run.player.draw_items().iter().filter(|d| d.tiles).count();
        if wanted {
            assert!(tiled > 0, "no emitter took the tiles");
        } else {
            assert_eq!(tiled, 0, "{path:?}: an emitter took the tiles");
        }
    }
    images
}

/// `effect` with its smoke and flames drawn at full resolution: a layer the composite
/// reduces is drawn by the billboards whatever its path
/// (`a_reduced_blended_layer_is_drawn_by_the_billboards_whatever_the_path`).
fn full_resolution(mut effect: Effect) -> Effect {
    effect.post.alpha_downscale = 1;
    effect.post.glow_downscale = 1;
    effect
}

/// The shipped preset `presets/<name>.ron`.
fn shipped(name: &str) -> Effect {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("presets/{name}.ron"));
    ignis::preset::load(&path).expect("a shipped preset")
}

/// Both paths of `effect` agree within 1/255 mean and 8/255 max.
/// Every layer at full resolution in both ([`full_resolution`]).
fn paths_agree(ctx: &GpuContext, what: &str, effect: &Effect, frames: u32) {
    paths_agree_at(ctx, what, effect, &[frames]);
}

/// [`paths_agree`] after each of `frames` (ascending), each path played once.
fn paths_agree_at(ctx: &GpuContext, what: &str, effect: &Effect, frames: &[u32]) {
    let compared = compare_paths_at(ctx, what, effect, frames);
    for (frames, (mean, max)) in frames.iter().zip(compared) {
        assert!(
            mean <= 1.0 && max <= 8,
            "{what} after {frames} frames: tiles differ from billboards by {mean:.3}/255 \
             mean, {max}/255 max"
        );
    }
}

/// Both paths' images of `effect` after each of `frames` (ascending) frames, each path
/// played once: the mean and max difference in 8-bit levels per frame, as
/// [`paths_agree`] renders them (the share of channels over 8/255 is printed).
fn compare_paths_at(
    ctx: &GpuContext,
    what: &str,
    effect: &Effect,
    frames: &[u32],
) -> Vec<(f64, u8)> {
    let a = render_frames(ctx, effect, DrawPath::Billboard, frames, SIZE);
    let b = render_frames(ctx, effect, DrawPath::Tiles, frames, SIZE);
    let compared = frames.iter().zip(a.iter().zip(&b));
    compared
        .map(|(frames, (a, b))| {
            let what = format!("{what} after {frames} frames");
            assert!(
                total_light(a) > 1e3,
                "{what}: the billboards drew almost nothing"
            );
            let (mean, max) = image_diff(a, b);
            let off = share_off(a, b);
            if std::env::var_os("IGNIS_SAVE_TILE_IMAGES").is_some() {
                let stem = what.replace(['/', ' ', ','], "_");
                let _ = a.save(format!("target/tiles-{stem}-billboard.png"));
                let _ = b.save(format!("target/tiles-{stem}-tiles.png"));
            }
            // image_diff's mean is in 8-bit levels. The tiles cover the rasteriser's
            // pixels (see `sprites_smaller_than_a_pixel_cover_the_rasterisers_pixels`).
            eprintln!(
                "{what}: mean {mean:.3}/255, max {max}/255, {:.4} % of channels over 8/255",
                100.0 * off
            );
            (mean, max)
        })
        .collect()
}

/// Every shipped preset draws alike on both paths: within 1/255 mean and 8/255 max, at
/// two frames (the torch's turned flames over 25 frames: below).
#[test]
fn every_shipped_preset_draws_alike_with_tiles_and_billboards() {
    let ctx = gpu();
    for path in common::shipped_preset_paths() {
        let mut effect = ignis::preset::load(&path).expect("shipped preset loads");
        // Particles smaller than a few pixels are the splat's (a sub-pixel quad covers a
        // pixel centre or not by the rasteriser's snapping): they keep their own path.
        let mut run =
            Headless::new(&ctx, effect.clone(), ShaderLibrary::embedded()).expect("headless");
        run.render(SIZE).expect("render");
        for d in run.player.draw_items() {
            if d.size_px < ignis::effect::SPLAT_BELOW_PX {
                effect.emitters[d.index].look.draw_path = DrawPath::Splat;
            }
        }
        // Both frames from one run of each path.
        paths_agree_at(&ctx, &path.display().to_string(), &effect, &[60, 69]);
    }
}

/// The torch's flames, turned at random, over 25 frames: every frame within 1/255 mean
/// and 8/255 max. A rotated sprite's edge through a pixel centre (to the rasteriser's
/// 1/256-pixel grid) is an exact tie the rasteriser settles by its top-left rule over two
/// triangles; the tiles settle it with the same edge functions, exactly, wherever the uv
/// test cannot tell (with the uv test alone, about half these frames had a pixel up to
/// 25/255 off).
#[test]
fn rotated_sprites_edges_match_the_rasteriser_in_every_frame() {
    let ctx = gpu();
    let mut effect = shipped("torch");
    effect.post.alpha_downscale = 1;
    let frames = 50..75;
    let draw = |path: DrawPath| {
        let mut effect = effect.clone();
        for e in &mut effect.emitters {
            e.look.draw_path = path;
        }
        let mut run = Headless::new(&ctx, effect, ShaderLibrary::embedded()).expect("headless");
        let mut images = Vec::new();
        for frame in 0..frames.end {
            run.advance(1.0 / 60.0);
            if frames.contains(&frame) {
                images.push(run.render(SIZE).expect("render"));
            }
        }
        images
    };
    let (billboards, tiles) = (draw(DrawPath::Billboard), draw(DrawPath::Tiles));
    let mut worst = (0.0, 0u8);
    for (frame, (a, b)) in frames.zip(billboards.iter().zip(&tiles)) {
        let (mean, max) = image_diff(a, b);
        eprintln!("torch frame {frame}: mean {mean:.4}/255, max {max}/255");
        // Within the 8/255, and as close as measured (1/255: the fourth
        // corner's texel filtering): a tie settled by the wrong rule reads 4/255.
        assert!(
            mean <= 1.0 && max <= 2,
            "torch frame {frame}: tiles differ from billboards by {mean:.3}/255 mean, \
             {max}/255 max"
        );
        worst = (f64::max(worst.0, mean), worst.1.max(max));
    }
    assert!(
        total_light(&billboards[0]) > 1e3,
        "the torch drew almost nothing"
    );
    eprintln!(
        "torch, frames 50..75: worst mean {:.4}/255, worst max {}/255",
        worst.0, worst.1
    );
}

/// The campfire's flames with one look module on at a time.
fn flames() -> Effect {
    let mut effect = Effect::default_campfire();
    effect.emitters.retain(|e| e.name == "flames");
    effect.drop_dangling_events();
    effect
}

#[test]
fn each_look_module_draws_alike_with_tiles_and_billboards() {
    let ctx = gpu();
    type Module = (&'static str, fn(&mut ignis::effect::Look));
    let modules: [Module; 5] = [
        ("plain", |l| {
            l.flipbook = None;
            l.sprite = Sprite::SoftDisc;
            l.soft_ground_m = 0.0;
        }),
        ("flipbook, blended frames", |l| {
            l.sprite = Sprite::FlameSheet;
            l.flipbook = Some(Flipbook {
                rows: 4,
                cols: 4,
                mode: FlipbookMode::OverLife,
                blend_frames: true,
                random_start: true,
            });
        }),
        ("soft ground", |l| {
            l.soft_ground_m = 0.3;
        }),
        ("rotation and spin", |l| {
            l.flipbook = None;
            l.sprite = Sprite::SmokePuff;
            l.rotation_random_deg = 180.0;
            l.spin_deg_per_s = Param::Constant(90.0);
        }),
        ("alpha blending, sorted", |l| {
            l.flipbook = None;
            l.sprite = Sprite::SmokePuff;
            l.blend = BlendMode::Alpha;
            l.intensity = 1.0;
        }),
    ];
    for (what, set) in modules {
        let mut effect = flames();
        set(&mut effect.emitters[0].look);
        paths_agree(&ctx, what, &effect, 45);
    }
}

/// Streaks are slivers a pixel or two wide: they stay billboards even when the tiles are
/// asked for (the others still take them).
#[test]
fn streaks_stay_billboards() {
    let ctx = gpu();
    let mut effect = full_resolution(Effect::default_campfire());
    for e in &mut effect.emitters {
        e.look.draw_path = DrawPath::Tiles;
    }
    effect.emitters[0].look.streak = Some(Streak {
        length_secs: 0.05,
        max_length_m: 0.3,
    });
    // A lit layer faces the camera: the streaked smoke is drawn unlit.
    effect.emitters[0].look.lit = None;
    let mut run = Headless::new(&ctx, effect, ShaderLibrary::embedded()).expect("headless");
    for _ in 0..20 {
        run.advance(1.0 / 60.0);
    }
    run.render(SIZE).expect("render");
    let items = run.player.draw_items();
    assert!(items.iter().any(|d| d.index == 0 && !d.tiles && !d.splat));
    assert!(
        items.iter().any(|d| d.tiles),
        "the other emitters took the tiles"
    );
}

/// Many small sprites take the tiles on a GPU whatever their fill: 20,000 sprites of 5 px
/// thrown out of one point (500,000 px of fill, under `TILES_MIN_FILL_PX`) are past
/// `TILES_MIN_QUADS` and on the tiles, and their light agrees with the billboards'; 16,000
/// stay billboards.
#[test]
fn many_small_sprites_take_the_tiles_though_their_fill_is_light() {
    let base = gpu();
    let ctx = base.clone().with_profile(Some(AdapterProfile::GPU));
    let size_m = (5.0 / common::px_per_m_at_3m(SIZE.1)) as f32;
    let thrown = |count: u32| {
        let mut effect = pile(count as f32, size_m, [0.0; 3]);
        let e = &mut effect.emitters[0];
        e.capacity = count;
        e.spread_deg = 180.0;
        e.speed_m_per_s = Range::new(0.5, 1.0);
        e.look.intensity = 0.01;
        effect
    };
    let on_tiles = |count: u32| {
        let mut run =
            Headless::new(&ctx, thrown(count), ShaderLibrary::embedded()).expect("headless");
        for _ in 0..6 {
            run.advance(1.0 / 60.0);
        }
        run.render(SIZE).expect("render");
        let items = run.player.draw_items();
        let d = items.first().expect("a draw");
        assert!(d.size_px >= 4.9 && d.size_px <= 5.1, "{} px", d.size_px);
        assert!(!d.splat, "{count} sprites splatted");
        d.tiles
    };
    const {
        assert!(ignis::effect::TILES_MIN_QUADS > 16_000 && ignis::effect::TILES_MIN_QUADS <= 20_000)
    };
    assert!(on_tiles(20_000), "20,000 small sprites stayed billboards");
    assert!(!on_tiles(16_000), "16,000 small sprites took the tiles");
    light_agrees(&base, "20,000 sprites of 5 px", &thrown(20_000));
}

/// Still particles on the camera's axis: `count` of them, `size_m` wide, at `at`.
fn pile(count: f32, size_m: f32, at: [f32; 3]) -> Effect {
    let mut e = common::still_burst(count as u32, 1.0);
    e.capacity = 4096;
    e.transform.position_m = at;
    e.look.sprite = Sprite::SoftDisc;
    e.look.flipbook = None;
    e.look.size_m = Param::Constant(size_m);
    e.look.opacity = Param::Constant(1.0);
    e.look.spin_deg_per_s = Param::Constant(0.0);
    e.look.intensity = 4.0 / count;
    e.look.color_over_life = Effect::default_campfire().emitters[0]
        .look
        .color_over_life
        .clone();
    e.look.soft_ground_m = 0.0;
    let mut effect = common::bare_effect(e);
    effect.post.bloom = None;
    effect.camera.target_m = [0.0, 0.0, 0.0];
    effect.camera.distance_m = 3.0;
    effect.camera.pitch_deg = 0.0;
    effect.camera.yaw_deg = 0.0;
    effect
}

/// The light of both paths agrees within 1 % and the images as `paths_agree` asks.
fn light_agrees(ctx: &GpuContext, what: &str, effect: &Effect) {
    // 0.1 s: the pile is born (10 × count per second).
    let a = render(ctx, effect, DrawPath::Billboard, 6);
    let b = render(ctx, effect, DrawPath::Tiles, 6);
    images_agree(what, &a, &b);
}

/// The billboards' image `a` and the tiles' `b`: some light drawn, the same light within
/// 1 %, and within 1/255 mean and 8/255 max.
fn images_agree(what: &str, a: &image::RgbaImage, b: &image::RgbaImage) {
    let (la, lb) = (total_light(a), total_light(b));
    eprintln!("{what}: light {la} (billboards), {lb} (tiles)");
    assert!(la > 1e3, "{what}: nothing drawn");
    assert!((la - lb).abs() <= 0.01 * la, "{what}: light {la} vs {lb}");
    let (mean, max) = image_diff(a, b);
    assert!(
        mean <= 1.0 && max <= 8,
        "{what}: {mean:.3}/255 mean, {max}/255 max"
    );
}

#[test]
fn sprites_across_tile_borders_and_larger_than_the_screen_keep_their_light() {
    let ctx = gpu();
    // Off the tile grid's lines by a fraction of a pixel, ~40 px wide: it crosses borders.
    light_agrees(
        &ctx,
        "across borders",
        &pile(1.0, 0.37, [0.013, 0.021, 0.0]),
    );
    // 12 m wide at 3 m: every pixel of the target is inside it.
    light_agrees(&ctx, "larger than the screen", &pile(1.0, 12.0, [0.0; 3]));
}

#[test]
fn a_tile_with_more_sprites_than_a_workgroup_keeps_every_sprite() {
    let ctx = gpu();
    // 3000 sprites on the same tiles: twelve chunks of the shade's 256 list entries, 47
    // batches of its sprite cache (the last one partial), hits carried from chunk to chunk.
    let effect = pile(3000.0, 0.5, [0.0; 3]);
    // The billboards draw every sprite: a dropped chunk of 256 would take a twelfth of the
    // light, a dropped batch of 64 two percent.
    light_agrees(&ctx, "3000 deep", &effect);
}

#[test]
fn two_emitters_over_different_bins_each_keep_their_light() {
    let ctx = gpu();
    // Two items of one chunk, one on each side of the 128-px bins' border at x = 128: the
    // right one's sprites start a block of their own, and the bin it covers must be added
    // to its shade (the bin scan finds a block's item by searching the items' first
    // sprites), not to the left one's.
    let mut effect = pile(40.0, 0.2, [-0.9, 0.0, 0.0]);
    let mut right = effect.emitters[0].clone();
    right.name = "right".into();
    right.transform.position_m = [0.9, 0.1, 0.0];
    right.look.size_m = Param::Constant(0.3);
    effect.emitters.push(right);
    light_agrees(&ctx, "two emitters", &effect);
}

/// Four items in one chunk: a dim sprite larger than the screen first (item 0 shades every
/// tile, filling the resolve's list of shaded tiles), then three bright piles in the first
/// bin. Each item's shade finds its bins in a list of its own after the shaded tiles, and
/// the bin scan finds a block's item by searching four items' first sprites: every pile
/// keeps its light.
#[test]
fn four_emitters_in_one_chunk_each_keep_their_light() {
    let ctx = gpu();
    let effect = piles_over_the_screen(&[[-0.8, 0.5, 0.0], [-0.3, -0.4, 0.0], [-1.2, 0.0, 0.0]]);
    // The piles show over the large sprite: losing one would be far over 8/255.
    let mut first_only = effect.clone();
    first_only.emitters.truncate(1);
    let with = render(&ctx, &effect, DrawPath::Billboard, 6);
    let without = render(&ctx, &first_only, DrawPath::Billboard, 6);
    let (_, max) = image_diff(&with, &without);
    assert!(total_light(&without) > 1e3, "the large sprite drew nothing");
    assert!(max > 32, "the piles barely show: {max}/255");
    light_agrees(&ctx, "four emitters", &effect);
}

#[test]
fn every_frame_starts_from_tiles_no_sprite_has_shaded() {
    let ctx = gpu();
    // 12 m wide at 3 m: every tile of the target is shaded in every frame, the last ones
    // included. Each frame's tiles must start empty and be listed for the resolve again:
    // a flag left from the frame before adds to the last frame's sum and hides the tile.
    let effect = pile(1.0, 12.0, [0.0; 3]);
    paths_agree_at(&ctx, "every tile, frame after frame", &effect, &[6, 7, 8]);
}

/// The bench's stage stops (`TileStages`, which time the tiles' stages apart): a record
/// stopped after the projection or the binning leaves the fire to the billboards, a whole
/// record draws it on the tiles.
#[test]
fn a_record_stopped_before_the_shade_leaves_the_fire_to_the_billboards() {
    let ctx = gpu();
    let mut run = played_on_tiles(&ctx, pile(1.0, 12.0, [0.0; 3]));
    for (stages, drawn) in [
        (TileStages::Project, false),
        (TileStages::Bin, false),
        (TileStages::All, true),
    ] {
        run.player.tile_pass().expect("tiles").set_stages(stages);
        let light = total_light(&run.render(SIZE).expect("render"));
        let tiles = run.player.tile_pass().expect("tiles").drawn();
        assert_eq!(tiles, drawn, "{stages:?}: the tiles drawn");
        let on_tiles = run.player.draw_items().iter().any(|d| d.tiles);
        assert_eq!(on_tiles, drawn, "{stages:?}: the item left on the tiles");
        assert!(light > 1e3, "{stages:?}: no fire ({light})");
    }
}

#[test]
fn sixteen_emitters_in_one_chunk_each_keep_their_light() {
    let ctx = gpu();
    // Each item of a chunk lists its bins in its own place: sixteen items over the 2 × 2
    // bins of the target.
    let at = |k: usize| {
        [
            -1.0 + 0.5 * (k % 5) as f32,
            -0.5 + 0.5 * (k / 5) as f32,
            0.0,
        ]
    };
    let effect = piles_over_the_screen(&(0..15).map(at).collect::<Vec<_>>());
    light_agrees(&ctx, "sixteen emitters", &effect);
    // The last pile shows: losing it would be far over 8/255.
    let mut but_last = effect.clone();
    but_last.emitters.pop();
    let with = render(&ctx, &effect, DrawPath::Tiles, 6);
    let without = render(&ctx, &but_last, DrawPath::Billboard, 6);
    assert!(
        image_diff(&with, &without).1 > 32,
        "the last pile barely shows"
    );
}

#[test]
fn a_target_of_more_bins_across_than_down_scans_every_bin() {
    let ctx = gpu();
    // 384 × 256 pixels: 3 × 2 bins of 128 (six, where 3 + 2 is five), every one under
    // the sprite.
    let effect = pile(1.0, 12.0, [0.0; 3]);
    let a = render_at(&ctx, &effect, DrawPath::Billboard, 6, (384, 256));
    let b = render_at(&ctx, &effect, DrawPath::Tiles, 6, (384, 256));
    images_agree("3 × 2 bins", &a, &b);
}

#[test]
fn a_target_of_more_bins_than_the_tiles_hold_is_drawn_by_the_billboards() {
    let ctx = gpu();
    // 8192 × 4224 pixels: 64 × 33 = 2112 bins of 128, over the 2048 the tiles hold.
    let mut run = played_on_tiles(&ctx, full_resolution(pile(1.0, 0.5, [0.0; 3])));
    let image = run.render((8192, 4224)).expect("render");
    let tiled = run.player.draw_items().iter().any(|d| d.tiles);
    assert!(!tiled, "a target of 2112 bins left on the tiles");
    assert!(total_light(&image) > 1e3, "the billboards drew nothing");
    // The same effect at 1920 × 1080 stays on the tiles.
    run.render((1920, 1080)).expect("render");
    assert!(run.player.draw_items().iter().any(|d| d.tiles));
}

/// `effect`'s one emitter asked onto the tiles, played 6 frames (0.1 s: a pile is born).
fn played_on_tiles(ctx: &GpuContext, mut effect: Effect) -> Headless {
    effect.emitters[0].look.draw_path = DrawPath::Tiles;
    let mut run = Headless::new(ctx, effect, ShaderLibrary::embedded()).expect("headless");
    for _ in 0..6 {
        run.advance(1.0 / 60.0);
    }
    run
}

/// A sprite larger than the screen (faint), then a bright pile 0.25 m wide at each of `at`,
/// each its own emitter.
fn piles_over_the_screen(at: &[[f32; 3]]) -> Effect {
    let mut effect = pile(1.0, 12.0, [0.0; 3]);
    effect.emitters[0].capacity = 16;
    effect.emitters[0].look.intensity = 0.5;
    for (k, &at) in at.iter().enumerate() {
        let mut e = pile(1.0, 0.25, at).emitters.remove(0);
        e.name = format!("pile {k}");
        e.capacity = 16;
        e.look.intensity = 8.0;
        effect.emitters.push(e);
    }
    effect
}

#[test]
fn lit_flipbooks_blend_their_frames_alike_on_both_paths() {
    let ctx = gpu();
    // The built-in 4 × 4 six-way sheet, its frames blended over life: a few puffs each
    // between two frames at frames 20 and 31, lit once from the sides of each map (right,
    // top, back; then left, below, front).
    for sun_direction in [[1.0, 0.5, -0.7], [-1.0, -0.5, 0.7]] {
        let lighting = Lighting {
            sun_direction,
            sun_color: [3.0, 3.0, 3.0],
            ..Lighting::default()
        };
        let mut effect = common::still_smoke(SixWayMaps::PuffSheet, lighting, DrawPath::Billboard);
        let e = &mut effect.emitters[0];
        e.capacity = 16;
        e.bursts[0].count = 5;
        e.lifetime_secs = Range::new(0.9, 1.3);
        e.spread_deg = 60.0;
        e.speed_m_per_s = Range::new(0.2, 0.4);
        e.look.size_m = Param::Constant(0.9);
        e.look.flipbook = Some(Flipbook {
            rows: 4,
            cols: 4,
            mode: FlipbookMode::OverLife,
            blend_frames: true,
            random_start: false,
        });
        let what = format!("lit flipbook, sun towards {sun_direction:?}");
        paths_agree_at(&ctx, &what, &effect, &[20, 31]);
    }
}

/// A lit item's sprites are followed by their six-way records, and the rest of its last
/// block is filled with empty sprites. When the item shrinks within the block (500 puffs,
/// then 200 in another place: the buffers are kept), that rest holds the larger frame's
/// sprites until it is filled: the tiles still draw the billboards' image, not the
/// earlier frame's puffs as well.
#[test]
fn a_lit_item_that_shrinks_leaves_none_of_its_earlier_sprites() {
    let ctx = gpu();
    let sun = Lighting {
        sun_color: [3.0, 3.0, 3.0],
        ..Lighting::default()
    };
    let mut effect = common::still_smoke(SixWayMaps::PuffSheet, sun, DrawPath::Billboard);
    let e = &mut effect.emitters[0];
    (e.capacity, e.bursts[0].count) = (500, 500);
    e.shape = Shape::Sphere {
        radius_m: 0.6,
        surface_only: false,
    };
    e.look.size_m = Param::Constant(0.08);
    shrinks_leaving_none(&ctx, "puffs", &effect, 200, 0.8);
}

/// An unlit item that shrinks within its last block when it holds more than a block's
/// worth (2000 discs, then 1500 elsewhere: two blocks of 1024 both times, so the buffers
/// are kept) has the rest of that block filled with empty sprites too: the tiles do not
/// draw the earlier frame's discs 1500..2000 again.
#[test]
fn an_item_of_several_blocks_that_shrinks_leaves_none_of_its_earlier_sprites() {
    let ctx = gpu();
    let mut effect = pile(2000.0, 0.1, [-0.6, 0.0, 0.0]);
    let e = &mut effect.emitters[0];
    e.capacity = 2000;
    e.shape = Shape::Sphere {
        radius_m: 0.3,
        surface_only: false,
    };
    e.look.intensity = 0.03;
    shrinks_leaving_none(&ctx, "discs", &effect, 1500, 1.2);
}

/// `effect` (one emitter, one burst) drawn on both paths after 0.1 s, then again 0.1 s after
/// its capacity and burst are cut to `count` and it is moved `shift_m` along x: the tiles
/// draw the billboards' light and image both times.
fn shrinks_leaving_none(ctx: &GpuContext, what: &str, effect: &Effect, count: u32, shift_m: f32) {
    let frames = |path: DrawPath| {
        let mut effect = full_resolution(effect.clone());
        effect.emitters[0].look.draw_path = path;
        let mut run = Headless::new(ctx, effect, ShaderLibrary::embedded()).expect("headless");
        for _ in 0..6 {
            run.advance(1.0 / 60.0);
        }
        let before = run.render(SIZE).expect("render");
        run.edit(|e| {
            let e = &mut e.emitters[0];
            (e.capacity, e.bursts[0].count) = (count, count);
            e.transform.position_m[0] += shift_m;
        })
        .expect("edit");
        for _ in 0..6 {
            run.advance(1.0 / 60.0);
        }
        let tiled = run.player.draw_items().iter().any(|d| d.tiles);
        assert_eq!(tiled, path == DrawPath::Tiles, "{what}: {path:?}");
        (before, run.render(SIZE).expect("render"))
    };
    let (bill, tiles) = (frames(DrawPath::Billboard), frames(DrawPath::Tiles));
    for (when, a, b) in [("before", &bill.0, &tiles.0), ("after", &bill.1, &tiles.1)] {
        let (mean, max) = image_diff(a, b);
        let (la, lb) = (total_light(a), total_light(b));
        assert!(la > 1e3, "{what} {when}: the billboards drew little ({la})");
        assert!(
            (la - lb).abs() <= 0.01 * la,
            "{what} {when} shrinking: light {la} (billboards) vs {lb} (tiles)"
        );
        assert!(
            mean <= 1.0 && max <= 8,
            "{what} {when} shrinking: {mean:.3}/255 mean, {max}/255 max"
        );
    }
}

/// A host whose projection is turned against its view (a canted display): the clip w
/// varies across the camera-facing quads, so the tiles map them projectively (the depth
/// from the sprite's z and w rows). They draw the billboards' image.
#[test]
fn a_projection_turned_against_the_view_draws_projective_sprites_alike() {
    let ctx = gpu();
    let dir = tempfile::tempdir().expect("tempdir");
    let view = glam::camera::rh::view::look_at_mat4(
        glam::Vec3::new(0.0, 0.0, 3.0),
        glam::Vec3::ZERO,
        glam::Vec3::Y,
    );
    let aspect = SIZE.0 as f32 / SIZE.1 as f32;
    // Turned 0.3 rad about the view's y and 0.25 about its x: w takes some of the camera's
    // right and of its up axis.
    let proj = glam::camera::rh::proj::directx::perspective(0.8, aspect, 0.05, 50.0)
        * glam::Mat4::from_rotation_y(0.3)
        * glam::Mat4::from_rotation_x(0.25);
    let camera = ignis::Camera::new(view, proj, SIZE);
    let disc = full_resolution(pile(1.0, 0.5, [0.0; 3]));
    // A sprite its trim cuts on two sides, about 50 px wide: the map's constant column is
    // taken at the cut quad's first corner.
    let mut cornered = full_resolution(pile(1.0, 1.0, [0.0; 3]));
    cornered.emitters[0].look.sprite = common::cornered_sprite(dir.path());
    for (what, effect) in [("a disc", disc), ("a cut sprite", cornered)] {
        let draw = |path: DrawPath| {
            let mut effect = effect.clone();
            effect.emitters[0].look.draw_path = path;
            let mut run = Headless::new(&ctx, effect, ShaderLibrary::embedded()).expect("headless");
            for _ in 0..6 {
                run.advance(1.0 / 60.0);
            }
            // Only this camera draws: no camera-facing frame fills the sprites' rows first.
            let image = run
                .composite
                .render_image(&run.ctx, &mut run.player, &camera)
                .expect("render");
            let tiled = run.player.draw_items().iter().any(|d| d.tiles);
            assert_eq!(tiled, path == DrawPath::Tiles, "{what}: {path:?}");
            image
        };
        let (a, b) = (draw(DrawPath::Billboard), draw(DrawPath::Tiles));
        images_agree(&format!("turned projection, {what}"), &a, &b);
    }
}

/// A lit item's six-way records (after its sprites) and the rest of its last block are
/// empty sprites, bounds (1, 1, 0, 0), which no bin lists: 600 lit puffs take 1,200
/// records of two blocks, the padding the rest of the second.
#[test]
fn lit_records_and_block_padding_are_empty_sprites() {
    let ctx = gpu();
    let sun = Lighting {
        sun_color: [3.0, 3.0, 3.0],
        ..Lighting::default()
    };
    let mut effect = common::still_smoke(SixWayMaps::PuffSheet, sun, DrawPath::Tiles);
    let e = &mut effect.emitters[0];
    (e.capacity, e.bursts[0].count) = (600, 600);
    e.shape = Shape::Sphere {
        radius_m: 0.6,
        surface_only: false,
    };
    e.look.size_m = Param::Constant(0.08);
    let mut run =
        Headless::new(&ctx, full_resolution(effect), ShaderLibrary::embedded()).expect("headless");
    run.advance(1.0 / 60.0);
    run.render(SIZE).expect("render");
    let quads = run.player.draw_items()[0].width as usize;
    assert!(quads > 512, "{quads} quads");
    let bounds = run
        .player
        .tile_pass()
        .expect("the tiles")
        .read_sprite_bounds(&run.ctx)
        .expect("read back");
    assert!(bounds.len() >= 2048, "{} sprites", bounds.len());
    let drawn = bounds[..quads].iter().filter(|b| b[0] <= b[2]).count();
    assert!(
        drawn > quads / 2,
        "only {drawn} of {quads} puffs have pixels"
    );
    for (i, b) in bounds.iter().enumerate().take(2048).skip(quads) {
        assert_eq!(*b, [1, 1, 0, 0], "sprite {i} of {quads} quads");
    }
}

/// A sprite turned by a few hundredths of a degree has corners that snap to a shape the
/// upright test must reject: its left and right edges vertical on the 1/256-pixel grid, and
/// one or both of its bottom and top edges a grid step lower at their right ends. The tiles
/// light the rasteriser's pixels, the dipping edge's row included (its centres a fraction
/// of a step inside it), not the half-open box of two corners. On a 193×145 target: a white
/// square 4 px wide (half-size 512.5/256 px), 1/512 px right of the middle pixel centre,
/// both edges dipping; and one 4.5 px wide (576.25/256), 128.25 grid steps right and 192.25
/// below, its top edge level on the grid and its bottom edge dipping.
#[test]
fn a_nearly_upright_sprite_lights_the_rasterisers_pixels() {
    let ctx = gpu();
    let dir = tempfile::tempdir().expect("tempdir");
    let [billboard, tiles] = nearly_upright_pixels(&ctx, dir.path(), 512.5, (0.5, 0.0));
    // The design: the bottom edge dips below the centres of row 74 (x 95..=98).
    assert!(
        billboard.len() >= 24 && (95..99).all(|x| billboard.contains(&(x, 74))),
        "the corners are not where the test puts them: {billboard:?}"
    );
    assert_eq!(tiles, billboard, "the tiles' pixels (both edges dipping)");
    let [billboard, tiles] = nearly_upright_pixels(&ctx, dir.path(), 576.25, (128.25, -192.25));
    // The design: columns 95..=98 of rows 71..=75, row 75 lit inside the dipping edge only.
    let designed: Pixels = (71..76)
        .flat_map(|y| (95..99).map(move |x| (x, y)))
        .collect();
    assert_eq!(
        billboard, designed,
        "the corners are not where the test puts them"
    );
    assert_eq!(tiles, billboard, "the tiles' pixels (a level top edge)");
}

/// The pixels an image's light is in, row by row.
type Pixels = Vec<(u32, u32)>;

/// The pixels the billboards and the tiles light for a white square of half-size
/// `half_steps` grid steps (1/256 px) at `at_steps` (right, up) from the middle pixel centre
/// of a 193×145 target, turned after 1 s of spin so that its horizontal edges fall by a
/// quarter of a step across it.
fn nearly_upright_pixels(
    ctx: &GpuContext,
    dir: &std::path::Path,
    half_steps: f64,
    at_steps: (f64, f64),
) -> [Pixels; 2] {
    let size = (193, 145);
    let px_per_m = common::px_per_m_at_3m(size.1);
    let m = |steps: f64| (steps / 256.0 / px_per_m) as f32;
    let turn_deg = (-(0.25f64 / half_steps).asin()).to_degrees();
    let mut effect = pile(
        1.0,
        2.0 * m(half_steps),
        [m(at_steps.0), m(at_steps.1), 0.0],
    );
    let e = &mut effect.emitters[0];
    e.lifetime_secs = Range::new(10.0, 10.0);
    e.look.sprite = common::white_sprite(dir);
    // The turn is reached at an age of 1 s (60 frames); up to twice it snaps alike.
    e.look.spin_deg_per_s = Param::Constant(turn_deg as f32);
    e.look.intensity = 0.5;
    e.look.color_over_life = common::flat_color([1.0; 4]);
    let lit = |path| common::lit_pixels(&render_at(ctx, &effect, path, 60, size));
    [lit(DrawPath::Billboard), lit(DrawPath::Tiles)]
}

/// The ground fade of a turned sprite whose quad its trim cuts: one flame tongue of the
/// 4 × 4 sheet (its tongues fill the middle of each frame: cut on the left), and a white
/// square cut on the left and at the bottom, 1.2 m wide (about 70 px at 3 m: the 6 px mip
/// margin keeps the cut), turned 45° by 0.1 s of spin, 0.2 m above a ground that fades it
/// over 0.5 m. The fade's argument is affine in the frame's coordinates, its constant term
/// taken at the cut quad's first corner: the tiles fade it as the billboards do.
#[test]
fn a_turned_sprite_cut_by_its_trim_fades_towards_the_ground_alike() {
    let ctx = gpu();
    let dir = tempfile::tempdir().expect("tempdir");
    let mut effect = pile(1.0, 1.2, [0.0, 0.2, 0.0]);
    let look = &mut effect.emitters[0].look;
    look.spin_deg_per_s = Param::Constant(450.0);
    look.soft_ground_m = 0.5;
    look.intensity = 1.0;
    look.color_over_life = common::flat_color([1.0, 0.6, 0.3, 1.0]);
    let mut tongue = effect.clone();
    let look = &mut tongue.emitters[0].look;
    look.sprite = Sprite::FlameSheet;
    look.flipbook = Some(Flipbook {
        rows: 4,
        cols: 4,
        mode: FlipbookMode::OverLife,
        blend_frames: false,
        random_start: false,
    });
    let mut square = effect;
    square.emitters[0].look.sprite = common::cornered_sprite(dir.path());
    light_agrees(&ctx, "a turned tongue cut on the left", &tongue);
    light_agrees(&ctx, "a turned square cut on two sides", &square);
}

#[test]
fn sprites_behind_the_camera_draw_nothing() {
    let ctx = gpu();
    // The camera is 3 m out on +z looking at the origin: 5 m out is behind it.
    let mut effect = pile(1.0, 0.5, [0.0, 0.0, 5.0]);
    effect.emitters[0].look.intensity = 50.0;
    let img = render(&ctx, &effect, DrawPath::Tiles, 6);
    assert_eq!(total_light(&img), 0.0, "light from behind the camera");
    let bill = render(&ctx, &effect, DrawPath::Billboard, 6);
    assert_eq!(img, bill);
}

#[test]
fn tiles_are_deterministic_and_the_automatic_choice_follows_the_profile() {
    let base = gpu();
    let effect = full_resolution(Effect::default_campfire());
    let a = render(&base, &effect, DrawPath::Tiles, 30);
    let b = render(&base, &effect, DrawPath::Tiles, 30);
    assert_eq!(a, b, "the same frame twice differs");
    let chosen_for = |effect: &Effect, profile: AdapterProfile| {
        let ctx = base.clone().with_profile(Some(profile));
        let mut run =
            Headless::new(&ctx, effect.clone(), ShaderLibrary::embedded()).expect("headless");
        for _ in 0..30 {
            run.advance(1.0 / 60.0);
        }
        // Large enough that the flames' and smoke's fill passes TILES_MIN_FILL_PX.
        run.render((960, 540)).expect("render");
        let items = run.player.draw_items();
        items
            .iter()
            .map(|d| (d.index, d.tiles, d.splat))
            .collect::<Vec<_>>()
    };
    let chosen = |profile: AdapterProfile| chosen_for(&effect, profile);
    let gpu_choice = chosen(AdapterProfile::GPU);
    assert_eq!(
        gpu_choice,
        chosen(AdapterProfile::GPU),
        "the choice changed"
    );
    // On a GPU profile the large flames and smoke take the tiles (the embers are streaks);
    // a software profile keeps billboards.
    let names: Vec<&str> = effect.emitters.iter().map(|e| e.name.as_str()).collect();
    for (i, tiles, _) in &gpu_choice {
        if ["flames", "smoke"].contains(&names[*i]) {
            assert!(
                tiles,
                "{} did not take the tiles: {gpu_choice:?}",
                names[*i]
            );
        }
    }
    // As shipped, the campfire's smoke and flames are drawn at reduced resolution: by the
    // billboards on either profile.
    let shipped = chosen_for(&Effect::default_campfire(), AdapterProfile::GPU);
    assert!(
        shipped.iter().all(|(_, t, _)| !t),
        "a reduced layer took the tiles: {shipped:?}"
    );
    // A runtime host's batch of instances is judged by the fill of all of them: the torch's
    // smoke and flame tongues take the tiles as one draw of both instances, its sparks (streaks)
    // and small heads stay billboards.
    let ctx = base.clone().with_profile(Some(AdapterProfile::GPU));
    let settings = ignis::PlayerSettings {
        batch_instances: true,
        ..ignis::testing::composite::Composite::player_settings()
    };
    let torch = ignis::preset::load("presets/torch.ron".as_ref()).expect("torch");
    let torch_names: Vec<String> = torch.emitters.iter().map(|e| e.name.clone()).collect();
    let mut run = Headless::with_settings(&ctx, torch, ShaderLibrary::embedded(), settings)
        .expect("headless");
    // A second torch beside the first: a batch of two.
    let beside = glam::Mat4::from_translation(glam::vec3(0.5, 0.0, 0.0));
    run.player.add_instance(beside, 2).expect("instance");
    for _ in 0..30 {
        run.advance(1.0 / 60.0);
    }
    run.render((960, 540)).expect("render");
    let items: Vec<(&str, bool, u32)> = run
        .player
        .draw_items()
        .iter()
        .map(|d| (torch_names[d.index].as_str(), d.tiles, d.members))
        .collect();
    for &(name, tiles, members) in &items {
        assert_eq!(members, 2, "{name} is not one draw of the batch: {items:?}");
        let heavy = ["smoke", "flame"].contains(&name);
        assert_eq!(tiles, heavy, "{name} on the wrong path: {items:?}");
    }
    assert!(
        chosen(AdapterProfile::SOFTWARE).iter().all(|(_, t, _)| !t),
        "a software profile took the tiles"
    );
}

/// 5000 sprites thrown out of one point across a bin border: five blocks of sprites over
/// two bins, listed block after block (long enough lists for tile lists). Their light agrees with the billboards', and it
/// stays the very same image when the bins' lists are given too little room (bins shaded
/// from the sprites directly, none lost) and when the tiles' own lists are (tiles shaded
/// from their bins' lists).
#[test]
fn many_sprites_over_several_bins_and_blocks_keep_their_light_when_lists_overflow() {
    let ctx = gpu();
    let mut effect = pile(5000.0, 0.5, [0.55, 0.0, 0.0]);
    effect.emitters[0].capacity = 8192;
    effect.emitters[0].spread_deg = 180.0;
    effect.emitters[0].speed_m_per_s = Range::new(0.5, 1.0);
    light_agrees(&ctx, "5000 over two bins", &effect);
    effect.emitters[0].look.draw_path = DrawPath::Tiles;
    let image = |list_capacity: Option<u32>, tile_list_capacity: Option<u32>| {
        let mut run =
            Headless::new(&ctx, effect.clone(), ShaderLibrary::embedded()).expect("headless");
        let tiles = run.player.tile_pass().expect("the tiles");
        tiles.set_list_capacity(list_capacity);
        tiles.set_tile_list_capacity(tile_list_capacity);
        for _ in 0..6 {
            run.advance(1.0 / 60.0);
        }
        run.render(SIZE).expect("render")
    };
    // Each bin lists all 5000: room for 6000 fits the first bin, not the second.
    let fitted = image(None, None);
    assert!(total_light(&fitted) > 1e3);
    assert!(image(Some(6000), None) == fitted, "one bin overflowing");
    assert!(image(Some(1), None) == fitted, "every bin overflowing");
    // The tiles' own lists: without them every tile filters its bin's list; with room for
    // fewer entries than both bins' tile lists take, the bins past it do.
    assert!(image(None, Some(0)) == fitted, "no tile lists");
    assert!(
        image(None, Some(8000)) == fitted,
        "tile lists short of room"
    );
}

/// `effect`, every emitter on the tiles, after `frames` frames, drawn at `size` once per
/// (bins' lists' capacity, tiles' lists' capacity) of `capacities`, all from one run. Every
/// draw starts from new, zeroed tile buffers (setting the tiles' lists' capacity drops them).
fn images_with_capacities(
    ctx: &GpuContext,
    effect: &Effect,
    frames: u32,
    size: (u32, u32),
    capacities: &[(Option<u32>, Option<u32>)],
) -> Vec<image::RgbaImage> {
    let mut effect = effect.clone();
    for e in &mut effect.emitters {
        e.look.draw_path = DrawPath::Tiles;
    }
    let mut run = Headless::new(ctx, effect, ShaderLibrary::embedded()).expect("headless");
    for _ in 0..frames {
        run.advance(1.0 / 60.0);
    }
    capacities
        .iter()
        .map(|&(lists, tile_lists)| {
            let tiles = run.player.tile_pass().expect("the tiles");
            tiles.set_list_capacity(lists);
            tiles.set_tile_list_capacity(tile_lists);
            let image = run.render(size).expect("render");
            assert!(
                run.player.draw_items().iter().all(|d| d.tiles),
                "an emitter left the tiles"
            );
            image
        })
        .collect()
}

/// Each of `images` (named) is `reference`, drawn with no tile lists (every tile filters
/// its bin's list), bit for bit.
fn all_as_bin_lists(
    what: &str,
    reference: &image::RgbaImage,
    images: &[(&str, &image::RgbaImage)],
) {
    assert!(total_light(reference) > 1e4, "{what}: almost nothing drawn");
    for (name, image) in images {
        let (mean, max) = image_diff(reference, image);
        assert!(
            *image == reference,
            "{what}, {name}: the tiles' lists differ from the bins' by {mean:.4}/255 mean, \
             {max}/255 max"
        );
    }
}

/// 20 000 sprites strewn over the whole of a 256×256 target: each of its four bins lists
/// over 5000 of them (every bin has tile lists, the first and the last too), and every tile
/// of every bin, its corners too, has a list of its own, each a different one. The tiles'
/// lists give the bins' lists' image bit for bit: as sized; with room to spare (the chunks'
/// places far apart); with the bins' lists packed close (the chunks' places right after
/// their counts); and with room for some bins' tile lists only (the rest shaded from their
/// bin lists, nothing read past the room).
#[test]
fn tile_lists_of_every_bin_and_tile_give_the_bin_lists_image() {
    let ctx = gpu();
    // ±1.2 m at 3 m covers the target; 0.15 m sprites are about 15 px, some 70 over each
    // pixel, each one's light seen in 8 bits.
    let mut effect = pile(20_000.0, 0.15, [0.0; 3]);
    let e = &mut effect.emitters[0];
    e.capacity = 32_768;
    e.shape = Shape::Box {
        half_extents_m: [1.2, 1.2, 0.0],
    };
    e.look.intensity = 0.02;
    let draws: [(&str, Option<u32>, Option<u32>); 6] = [
        ("no tile lists", None, Some(0)),
        ("as sized", None, None),
        ("room to spare", Some(1 << 18), Some(1 << 22)),
        ("bins' lists packed close", Some(28_000), Some(1 << 22)),
        // About 70 000 tile list entries in all, 17 000 a bin: room for one or two bins'
        // lists, then for three.
        ("room for some bins' tile lists", None, Some(32_768)),
        ("room for more bins' tile lists", None, Some(65_536)),
    ];
    let capacities: Vec<_> = draws.iter().map(|&(_, l, t)| (l, t)).collect();
    let images = images_with_capacities(&ctx, &effect, 6, (256, 256), &capacities);
    let named: Vec<(&str, &image::RgbaImage)> =
        draws.iter().map(|d| d.0).zip(&images).skip(1).collect();
    all_as_bin_lists("20 000 over every bin", &images[0], &named);
}

/// Bins' lists of more than 65 536 entries take more than 256 chunks of the tile lists'
/// passes, whose workgroups then run two rows deep: 70 000 sprites of 4 px over the top two
/// bins of a 256×256 target, and a second emitter's stack of 100 in the bottom-right bin
/// (too few for tile lists: the last bin, shaded from its bin list). The tiles' lists give
/// the bins' lists' image bit for bit: every chunk is counted and written, once, and no
/// workgroup past the last chunk writes anything.
#[test]
fn tile_lists_over_more_than_256_chunks_give_the_bin_lists_image() {
    let ctx = gpu();
    // The top half: 0.62 m up, ±0.56 m (pixels 6..122 down), ±1.2 m across; 0.04 m is
    // 4 px, some 40 sprites over each pixel. About 71 000 entries: 278 chunks.
    let mut effect = pile(70_000.0, 0.04, [0.0, 0.62, 0.0]);
    let e = &mut effect.emitters[0];
    e.capacity = 1 << 17;
    e.shape = Shape::Box {
        half_extents_m: [1.2, 0.56, 0.0],
    };
    e.look.intensity = 0.02;
    // 100 sprites on one spot around pixel (192, 192): the tiles it covers list 100 each.
    let mut stack = pile(100.0, 0.12, [0.62, -0.62, 0.0]).emitters.remove(0);
    stack.name = "stack".into();
    effect.emitters.push(stack);
    let images = images_with_capacities(
        &ctx,
        &effect,
        6,
        (256, 256),
        &[(None, Some(0)), (None, None)],
    );
    all_as_bin_lists(
        "70 000 over two bins",
        &images[0],
        &[("as sized", &images[1])],
    );
}

/// A dozen bins (a 400×272 target, four by three) and 5000 sprites in the sixth (pixels
/// 128..255 both ways), clear of its top row of tiles: the tile lists' places per bin, per
/// tile and per chunk keep apart whatever the bins. The tiles' lists give the bins' lists'
/// image bit for bit.
#[test]
fn tile_lists_among_a_dozen_bins_give_the_bin_lists_image() {
    let ctx = gpu();
    // 109 px a metre at 3 m: thrown out of pixel (192, 190), 0.2 m (22 px) sprites reach
    // pixels 170..214 across and 168..212 down.
    let mut effect = pile(5000.0, 0.2, [-0.073, -0.494, 0.0]);
    let e = &mut effect.emitters[0];
    e.capacity = 8192;
    e.spread_deg = 180.0;
    e.speed_m_per_s = Range::new(0.5, 1.0);
    e.look.intensity = 0.05;
    let images = images_with_capacities(
        &ctx,
        &effect,
        6,
        (400, 272),
        &[(None, Some(0)), (None, None)],
    );
    all_as_bin_lists(
        "5000 in one of twelve bins",
        &images[0],
        &[("as sized", &images[1])],
    );
}

/// The fireball's debris leaves alpha-blended smoke lines (ribbons, which only the
/// billboards draw): they stay billboards, drawn behind the tiles' blended layers, and the
/// smoke puffs keep the tiles.
#[test]
fn alpha_blended_ribbons_leave_the_other_blended_layers_their_tiles() {
    let ctx = gpu();
    let mut effect = shipped("fireball");
    for e in &mut effect.emitters {
        e.look.draw_path = DrawPath::Tiles;
    }
    let mut run = Headless::new(&ctx, effect, ShaderLibrary::embedded()).expect("headless");
    for _ in 0..60 {
        run.advance(1.0 / 60.0);
    }
    run.render(SIZE).expect("render");
    let item = |name: &str| {
        let i = run
            .effect()
            .emitters
            .iter()
            .position(|e| e.name == name)
            .expect("emitter");
        run.player
            .draw_items()
            .iter()
            .find(|d| d.index == i)
            .map(|d| (d.blend, d.tiles, d.trail.is_some()))
    };
    assert_eq!(item("smoke"), Some((BlendMode::Alpha, true, false)));
    assert_eq!(item("debris smoke"), Some((BlendMode::Alpha, false, true)));
}

/// The editor's and renders' own HDR image takes the tiles by compute (`resolve_over`)
/// where the adapter can read and write it in place: the image is the one the resolve's
/// draw gives, over alpha-blended billboards (the fireball's smoke lines stay billboards,
/// drawn under the tiles) and on their own (the torch).
#[test]
fn the_compute_resolve_composites_what_the_resolve_draw_does() {
    let ctx = gpu();
    for name in ["fireball", "torch"] {
        let mut effect = shipped(name);
        for e in &mut effect.emitters {
            e.look.draw_path = DrawPath::Tiles;
        }
        let image = |compute: bool| {
            let mut run =
                Headless::new(&ctx, effect.clone(), ShaderLibrary::embedded()).expect("headless");
            let tiles = run.player.tile_pass().expect("the tiles");
            tiles.set_compute_resolve(compute);
            for _ in 0..60 {
                run.advance(1.0 / 60.0);
            }
            let image = run.render(SIZE).expect("render");
            let tiles = run.player.tile_pass().expect("the tiles");
            assert_eq!(
                tiles.can_resolve_into(SIZE),
                compute,
                "{name}: the compute resolve was {}used",
                if compute { "not " } else { "" }
            );
            (image, run.player.recorded_commands())
        };
        common::compute_resolve_replaces_the_draw(name, &image(false), &image(true));
    }
}

/// Half-opaque dark smoke over the editor's test scene: the ground behind the tiles shows
/// through as the billboards let it (what was drawn × the puffs' transmittance, plus their
/// colour), by the resolve's draw and by the compute resolve alike. Over the cleared target
/// of the other tests nothing is behind the tiles, and their coverage is never seen.
#[test]
fn alpha_blended_tiles_over_the_test_scene_let_it_show_as_the_billboards_do() {
    let ctx = gpu();
    // Four still puffs on one spot (transmittance 1/16 at their middle), seen from 25° up:
    // the dark ground fills the image behind them.
    let mut effect = full_resolution(pile(4.0, 0.5, [0.0; 3]));
    effect.camera.pitch_deg = 25.0;
    let e = &mut effect.emitters[0];
    e.look.blend = BlendMode::Alpha;
    e.look.opacity = Param::Constant(0.5);
    e.look.intensity = 1.0;
    e.look.color_over_life = common::flat_color([0.05, 0.05, 0.05, 1.0]);
    let draw = |path: DrawPath, compute: bool| {
        let mut effect = effect.clone();
        effect.emitters[0].look.draw_path = path;
        let mut run = Headless::new(&ctx, effect, ShaderLibrary::embedded()).expect("headless");
        run.composite.test_scene = true;
        run.player
            .tile_pass()
            .expect("the tiles")
            .set_compute_resolve(compute);
        for _ in 0..6 {
            run.advance(1.0 / 60.0);
        }
        let image = run.render(SIZE).expect("render");
        let tiled = run.player.draw_items().iter().any(|d| d.tiles);
        assert_eq!(tiled, path == DrawPath::Tiles, "{path:?}");
        // Tiled smoke is composited with the light layer (the tiles' resolve); no blended
        // billboard is left to draw.
        let layers = match path {
            DrawPath::Tiles => ignis::Layers::LIGHT,
            _ => ignis::Layers::BLENDED,
        };
        assert_eq!(run.player.drawn_layers(), layers, "{path:?}");
        let tiles = run.player.tile_pass().expect("the tiles");
        assert_eq!(
            tiles.can_resolve_into(SIZE),
            compute,
            "compute resolve {compute}"
        );
        image
    };
    let billboards = draw(DrawPath::Billboard, false);
    let drawn = draw(DrawPath::Tiles, false);
    let computed = draw(DrawPath::Tiles, true);
    assert!(total_light(&billboards) > 1e4, "the scene was not drawn");
    let (mean, max) = image_diff(&billboards, &drawn);
    eprintln!("smoke over the scene: {mean:.3}/255 mean, {max}/255 max");
    assert!(
        mean <= 1.0 && max <= 8,
        "over the scene: tiles differ from billboards by {mean:.3}/255 mean, {max}/255 max"
    );
    common::resolves_agree("smoke over the test scene", &drawn, &computed);
}

/// Three emitters piled on the middle of a 256×256 target — a whole number of bins across
/// (as 1280 and 1920 are), where rounding the bins up must not add a column — each over all
/// four bins: the tiles draw the billboards' light, every bin shaded in its place; and the
/// same image, bit for bit, when every bin's list overflows (each item shaded from its own
/// sprites only: the second's run ends at its last sprite, not in the third's).
#[test]
fn emitters_over_every_bin_of_a_whole_bins_target_keep_their_light_when_lists_overflow() {
    let ctx = gpu();
    let size = (256, 256);
    // 0.5 m at 3 m is about 50 px around pixel (128, 128), where the four bins meet; 20
    // sprites an emitter, a block each.
    let mut effect = pile(20.0, 0.5, [0.0; 3]);
    effect.emitters[0].look.intensity = 0.05;
    for name in ["second", "third"] {
        let mut e = effect.emitters[0].clone();
        e.name = name.into();
        effect.emitters.push(e);
    }
    let billboards = render_at(&ctx, &effect, DrawPath::Billboard, 6, size);
    let tiles = images_with_capacities(&ctx, &effect, 6, size, &[(None, None), (Some(1), None)]);
    let (la, lb) = (total_light(&billboards), total_light(&tiles[0]));
    eprintln!("256 wide: light {la} (billboards), {lb} (tiles)");
    assert!(la > 1e3, "nothing drawn");
    assert!((la - lb).abs() <= 0.01 * la, "256 wide: light {la} vs {lb}");
    let (mean, max) = image_diff(&billboards, &tiles[0]);
    assert!(
        mean <= 1.0 && max <= 8,
        "256 wide: tiles differ from billboards by {mean:.3}/255 mean, {max}/255 max"
    );
    let (mean, max) = image_diff(&tiles[0], &tiles[1]);
    assert!(
        tiles[1] == tiles[0],
        "every bin overflowing: the image differs by {mean:.4}/255 mean, {max}/255 max"
    );
}

/// Sprites of a pixel or a few — the thesis preset's hard-edged points at 320×180 —
/// light the pixels the rasteriser lights: the tiles place the quads' corners on its
/// 1/256-pixel grid, and an upright quad covers the centres in its half-open pixel box
/// (the top-left rule). Testing the uv box of the exact corners instead, single pixels
/// differed by up to 66/255 here (69/255 with the corners snapped).
#[test]
fn sprites_smaller_than_a_pixel_cover_the_rasterisers_pixels() {
    let ctx = gpu();
    let mut effect = shipped("thesis_2006");
    effect.post.alpha_downscale = 1;
    let size = (320, 180);
    let a = render_at(&ctx, &effect, DrawPath::Billboard, 90, size);
    let b = render_at(&ctx, &effect, DrawPath::Tiles, 90, size);
    assert!(total_light(&a) > 1e3, "the billboards drew almost nothing");
    let (mean, max) = image_diff(&a, &b);
    eprintln!("sub-pixel points: mean {mean:.4}/255, max {max}/255");
    assert!(
        mean <= 0.05 && max <= 8,
        "sub-pixel points differ by {mean:.4}/255 mean, {max}/255 max"
    );
}

/// A frame whose sprites exceed a chunk of the tile buffers is drawn chunk after chunk,
/// each shaded over what the ones before it left, an emitter larger than a chunk in
/// pieces: the bonfire (lit smoke, flames, embers) and the fireball drawn in chunks of 2048
/// sprites give the image of one chunk bit for bit (every sprite is blended in the same
/// order, rounded to f16 after each as before), also when every bin's list overflows.
#[test]
fn a_frame_drawn_in_chunks_is_the_frame_drawn_at_once() {
    let ctx = gpu();
    for name in ["bonfire", "fireball"] {
        let mut effect = shipped(name);
        effect.post.alpha_downscale = 1;
        for e in &mut effect.emitters {
            e.look.draw_path = DrawPath::Tiles;
        }
        // One run, its particles drawn again after 60 frames with other chunk sizes.
        let mut run =
            Headless::new(&ctx, effect.clone(), ShaderLibrary::embedded()).expect("headless");
        for _ in 0..60 {
            run.advance(1.0 / 60.0);
        }
        let image = |run: &mut Headless, chunk: Option<u32>, lists: Option<u32>| {
            let tiles = run.player.tile_pass().expect("the tiles");
            tiles.set_chunk_sprites(chunk);
            tiles.set_list_capacity(lists);
            run.render(SIZE).expect("render")
        };
        let whole = image(&mut run, None, None);
        let again = image(&mut run, None, None);
        assert!(again == whole, "{name}: drawn again, the same image");
        let items = run.player.draw_items().iter().filter(|d| d.tiles);
        let quads: u32 = items.map(|d| d.width * d.members).sum();
        assert!(quads > 2 * 2048, "{name}: {quads} quads fit two chunks");
        assert!(total_light(&whole) > 1e3, "{name}: almost nothing drawn");
        // In chunks, and in chunks whose every bin list overflows (shaded from the
        // chunk's sprites directly).
        for lists in [None, Some(1)] {
            let chunked = image(&mut run, Some(2048), lists);
            let (mean, max) = image_diff(&whole, &chunked);
            assert!(
                whole == chunked,
                "{name}, lists {lists:?}: in chunks the image differs by {mean:.4}/255 mean, \
                 {max}/255 max"
            );
        }
    }
}

/// Tiny sprites above one chunk's count — the peers' dense sphere of 3-px sparks, drawn in
/// chunks of 4096 sprites at a small target — keep the billboards' image (1/255 mean,
/// 8/255 max), every light kept.
#[test]
fn tiny_sprites_beyond_a_chunk_draw_the_billboards_image() {
    let ctx = gpu();
    let mut effect =
        ignis::preset::load("bench/scenes/sphere_1m.ron".as_ref()).expect("the bench scene");
    let e = &mut effect.emitters[0];
    e.capacity = 40_000;
    e.spawn_rate_per_sec = Param::Constant(20_000.0);
    e.look.intensity = 0.1;
    e.look.size_m = Param::Constant(0.0092 * 3.0 * 1080.0 / f32::from(SIZE.1 as u16) / 3.0);
    let billboards = render(&ctx, &effect, DrawPath::Billboard, 90);
    effect.emitters[0].look.draw_path = DrawPath::Tiles;
    let mut run = Headless::new(&ctx, effect, ShaderLibrary::embedded()).expect("headless");
    run.player
        .tile_pass()
        .expect("the tiles")
        .set_chunk_sprites(Some(4096));
    for _ in 0..90 {
        run.advance(1.0 / 60.0);
    }
    let tiles = run.render(SIZE).expect("render");
    let d = &run.player.draw_items()[0];
    assert!(
        d.tiles && d.width * d.members > 6 * 4096,
        "{} quads",
        d.width
    );
    assert!(d.size_px > 2.0 && d.size_px < 4.0, "{} px", d.size_px);
    let (mean, max) = image_diff(&billboards, &tiles);
    eprintln!("sphere in chunks: mean {mean:.3}/255, max {max}/255");
    assert!(total_light(&billboards) > 1e4);
    assert!(
        mean <= 1.0 && max <= 8,
        "tiles in chunks differ by {mean:.3}/255 mean, {max}/255 max"
    );
}

/// A blended layer drawn at reduced resolution (`post.alpha_downscale`) is drawn by the
/// billboards whatever path its emitters ask for (the tiles resolve at the target's full
/// size): the campfire with its smoke forced onto the tiles draws the billboards' image,
/// bit for bit; at full resolution the tiles take the smoke.
#[test]
fn a_reduced_blended_layer_is_drawn_by_the_billboards_whatever_the_path() {
    let ctx = gpu();
    let image = |downscale: u32, path: DrawPath| {
        let mut effect = shipped("campfire");
        effect.post.alpha_downscale = downscale;
        for e in &mut effect.emitters {
            if e.look.blend == BlendMode::Alpha {
                e.look.draw_path = path;
            }
        }
        let mut run = Headless::new(&ctx, effect, ShaderLibrary::embedded()).expect("headless");
        for _ in 0..60 {
            run.advance(1.0 / 60.0);
        }
        let img = run.render(SIZE).expect("render");
        let tiled = run.player.draw_items().iter().filter(|d| d.tiles).count();
        (img, tiled)
    };
    let (billboards, _) = image(4, DrawPath::Billboard);
    let (tiles, tiled) = image(4, DrawPath::Tiles);
    assert_eq!(tiled, 0, "a reduced blended emitter took the tiles");
    assert!(
        total_light(&billboards) > 1e3,
        "the campfire drew almost nothing"
    );
    assert!(billboards == tiles, "the reduced smoke differs by its path");
    assert!(
        image(1, DrawPath::Tiles).1 > 0,
        "full-resolution smoke left the tiles"
    );
}
