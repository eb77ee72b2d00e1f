//! The automatic draw-path choice never trades the image away: for every shipped preset
//! and the peers' dense sphere of 3-px sparks, under the software profile and under the
//! GPU profile (tiles and dense splats allowed), the image with each emitter on the path
//! the automatic choice picks is within 1/255 mean of the image with every emitter on the
//! billboards. All on the real adapter (lavapipe in CI).

mod common;

use common::{gpu, image_diff, total_light};
use ignis::effect::{DrawPath, Effect};
use ignis::testing::gpu::{AdapterProfile, GpuContext};
use ignis::testing::headless::Headless;
use ignis::testing::shaders::ShaderLibrary;

const SIZE: (u32, u32) = (192, 144);

/// `effect` after a second at 60 fps, on the automatic path (`auto`) or with every
/// emitter on the billboards; the image and the number of items off the billboards.
fn render(ctx: &GpuContext, effect: &Effect, auto: bool) -> (image::RgbaImage, usize) {
    let mut effect = effect.clone();
    // Every layer at full resolution: a reduced one is the billboards' on every path.
    effect.post.alpha_downscale = 1;
    effect.post.glow_downscale = 1;
    for e in &mut effect.emitters {
        e.look.draw_path = if auto {
            DrawPath::Auto
        } else {
            DrawPath::Billboard
        };
    }
    let mut run = Headless::new(ctx, effect, ShaderLibrary::embedded()).expect("headless");
    for _ in 0..60 {
        run.advance(1.0 / 60.0);
    }
    let img = run.render(SIZE).expect("render");
    let off = run
        .player
        .draw_items()
        .iter()
        .filter(|d| d.splat || d.tiles);
    (img, off.count())
}

/// The shipped presets and the dense sphere (`bench/scenes/sphere_1m.ron` at a twentieth
/// of its count, so that its sprites stay dense at the test's size).
fn effects() -> Vec<(String, Effect)> {
    let paths = common::shipped_preset_paths();
    let mut out: Vec<(String, Effect)> = paths
        .iter()
        .map(|p| {
            (
                p.display().to_string(),
                ignis::preset::load(p).expect("preset"),
            )
        })
        .collect();
    let mut sphere = ignis::preset::load("bench/scenes/sphere_1m.ron".as_ref()).expect("scene");
    let e = &mut sphere.emitters[0];
    e.capacity /= 20;
    e.spawn_rate_per_sec = ignis::effect::Param::Constant(e.capacity as f32 / 2.0);
    e.look.intensity *= 4.0;
    out.push(("dense 3-px sphere".into(), sphere));
    out
}

/// Every effect under `profile`: the automatic path's image within 1/255 mean of the
/// billboards'; returns the number of items off the billboards.
fn auto_matches_billboards(profile: AdapterProfile) -> usize {
    let ctx = gpu().with_profile(Some(profile));
    let mut off_billboards = 0;
    for (what, effect) in effects() {
        let (reference, _) = render(&ctx, &effect, false);
        let (auto, off) = render(&ctx, &effect, true);
        off_billboards += off;
        assert!(
            total_light(&reference) > 1e3,
            "{what}: almost nothing drawn"
        );
        let (mean, max) = image_diff(&reference, &auto);
        eprintln!(
            "{what} ({profile:?}): {off} items off the billboards, mean {mean:.3}/255, max {max}/255"
        );
        assert!(
            mean <= 1.0,
            "{what} ({profile:?}): the automatic path differs from the billboards by \
             {mean:.3}/255 mean"
        );
    }
    off_billboards
}

/// The software profile: the splat takes the dense sphere (and the thesis's points).
#[test]
fn the_automatic_path_draws_the_billboards_image_under_the_software_profile() {
    let off = auto_matches_billboards(AdapterProfile::SOFTWARE);
    assert!(off >= 1, "{off} items left the billboards");
}

/// The GPU profile: the splat and the tiles take their share.
#[test]
fn the_automatic_path_draws_the_billboards_image_under_the_gpu_profile() {
    let off = auto_matches_billboards(AdapterProfile::GPU);
    assert!(off >= 2, "{off} items left the billboards");
}
