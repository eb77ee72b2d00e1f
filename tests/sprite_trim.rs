//! The octagon billboards are cut to (`src/render/sprite_trim.rs`, `sprite_trim.wgsl`):
//! it holds every visible texel of the built-in sprites, it spares a round sprite's
//! corners, the shader builds the same corners as the CPU, and the drawn frame is the
//! rectangle's.

mod common;

use common::*;
use ignis::effect::{DrawPath, Effect, Sprite};
use ignis::testing::gpu::GpuContext;
use ignis::testing::headless::Headless;
use ignis::testing::render::sixway_maps::{PUFF_SEED, combined, puff, puff_sheet};
use ignis::testing::render::sprite_trim::{OCTAGON_SHARE, Trim, trim};
use ignis::testing::render::sprites::{TRIM_THRESHOLD, coverage, generate};
use ignis::testing::shaders::ShaderLibrary;

const PROBE: &str = r#"
#import "sprite_trim.wgsl"
// Per case: x, y: lo, z, w: hi (margined), then the trim rectangle, then (cuts, m, -, -).
@group(0) @binding(0) var<storage, read> cases: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read_write> corners: array<vec2<f32>>;

@compute @workgroup_size(1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let c = id.x;
    let a = cases[3u * c];
    let t = cases[3u * c + 1u];
    let e = cases[3u * c + 2u];
    for (var k = 0u; k < 8u; k++) {
        corners[8u * c + k] = octagon_corner(a.xy, a.zw, t, bitcast<u32>(e.x), e.y, k);
    }
}
"#;

/// The built-in sprites as the billboards cut them: (name, image, rows, columns).
fn sprites() -> Vec<(&'static str, image::Rgba32FImage, u32, u32)> {
    vec![
        ("flame sheet", generate(&Sprite::FlameSheet), 4, 4),
        ("soft disc", generate(&Sprite::SoftDisc), 1, 1),
        ("smoke puff", generate(&Sprite::SmokePuff), 1, 1),
        ("spark", generate(&Sprite::Spark), 1, 1),
        ("flame wisp", generate(&Sprite::FlameWisp), 1, 1),
        ("lit puff", combined(&puff(PUFF_SEED)), 1, 2),
        ("lit puff sheet", combined(&puff_sheet(PUFF_SEED)), 4, 8),
    ]
}

fn trim_of(img: &image::Rgba32FImage, rows: u32, cols: u32) -> Trim {
    let (c, cell) = coverage(img);
    trim(&c, cell, img.dimensions(), rows, cols, TRIM_THRESHOLD)
}

/// Whether `p` lies inside the convex polygon `poly` (corners in order), with `eps` slack.
fn inside(poly: &[[f32; 2]; 8], p: [f32; 2], eps: f32) -> bool {
    let mut sign = 0.0f32;
    for i in 0..8 {
        let (a, b) = (poly[i], poly[(i + 1) % 8]);
        let (ex, ey) = (b[0] - a[0], b[1] - a[1]);
        if ex.abs() + ey.abs() < 1e-9 {
            continue;
        }
        let cross = ex * (p[1] - a[1]) - ey * (p[0] - a[0]);
        let len = (ex * ex + ey * ey).sqrt();
        if cross.abs() / len <= eps {
            continue;
        }
        if sign == 0.0 {
            sign = cross.signum();
        } else if cross.signum() != sign {
            return false;
        }
    }
    true
}

/// Every texel above the threshold lies inside its frame's octagon, with its bilinear
/// footprint (the texel's corners grown by one texel); round sprites are spared a sixth
/// of their fill, the flame sheet less than the share that pays for the octagon.
#[test]
fn the_octagon_holds_every_visible_texel() {
    for (name, img, rows, cols) in sprites() {
        let t = trim_of(&img, rows, cols);
        let poly = t.octagon(0.0);
        let (w, h) = img.dimensions();
        let (fw, fh) = (w / cols, h / rows);
        let mut visible = 0;
        for (x, y, p) in img.enumerate_pixels() {
            if p.0.iter().all(|&c| c <= TRIM_THRESHOLD) {
                continue;
            }
            visible += 1;
            let (fx, fy) = ((x % fw) as f32, (y % fh) as f32);
            // The texel's square grown by one texel (bilinear filtering reaches it).
            for (dx, dy) in [(-1.0, -1.0), (2.0, -1.0), (-1.0, 2.0), (2.0, 2.0)] {
                let q = [
                    ((fx + dx) / fw as f32).clamp(0.0, 1.0),
                    ((fy + dy) / fh as f32).clamp(0.0, 1.0),
                ];
                assert!(
                    inside(&poly, q, 2e-3),
                    "{name}: texel ({x}, {y}) corner {q:?} outside {poly:?}"
                );
            }
        }
        assert!(visible > 100, "{name}: {visible} visible texels");
        let share = t.octagon_share();
        match name {
            "soft disc" | "smoke puff" | "lit puff" => assert!(
                share < 0.87,
                "{name}: the octagon draws {share} of the rectangle"
            ),
            "flame sheet" => assert!(share > OCTAGON_SHARE, "{name}: {share}"),
            _ => {}
        }
    }
}

/// The bounds are exactly the visible cells' texels grown by one texel, in their own
/// frame's coordinates (here a cell of 2 × 2 texels in the lower frame of a 2-row
/// flipbook): nothing looser, and a cell at the threshold or an empty sprite cuts nothing.
#[test]
fn the_trim_is_the_visible_cells_grown_by_a_texel() {
    // 16 × 16 texels in cells of 2: 8 × 8 cells, one lit at (3, 6) — texels x 6..8,
    // y 12..14, in the frame of rows 8..16.
    let mut coverage = vec![0.0f32; 64];
    coverage[6 * 8 + 3] = 0.5;
    let t = trim(&coverage, 2, (16, 16), 2, 1, 0.25);
    let (u0, v0, u1, v1) = (5.0 / 16.0, 3.0 / 8.0, 9.0 / 16.0, 7.0 / 8.0);
    assert_eq!(
        t,
        Trim {
            rect: [u0, v0, u1, v1],
            diag: [u0 + v0, u1 + v1, u0 - v1, u1 - v0],
        }
    );
    assert_eq!(trim(&coverage, 2, (16, 16), 2, 1, 0.5), Trim::WHOLE);
    assert_eq!(trim(&[0.0; 64], 2, (16, 16), 2, 1, 0.0), Trim::WHOLE);
}

/// The shader's corners (`octagon_corner`) are the CPU's (`Trim::octagon`), for every
/// built-in sprite at margins from none to most of the frame.
#[test]
fn the_shader_builds_the_cpus_octagon() {
    let ctx = gpu();
    let mut cases: Vec<[f32; 4]> = Vec::new();
    let mut want: Vec<[f32; 2]> = Vec::new();
    let mut trims: Vec<Trim> = sprites()
        .into_iter()
        .map(|(_, img, rows, cols)| trim_of(&img, rows, cols))
        .collect();
    // Shapes whose cuts overlap along an edge (scaled back to meet): a diamond around one
    // point, and a sliver along a diagonal with one corner of the frame clipped.
    trims.push(Trim {
        rect: [0.4, 0.4, 0.6, 0.6],
        diag: [1.0, 1.0, 0.0, 0.0],
    });
    trims.push(Trim {
        rect: [0.0, 0.1, 0.9, 1.0],
        diag: [0.3, 1.7, -0.2, 0.1],
    });
    for t in trims {
        for m in [0.0, 0.01, 0.05, 0.2, 0.6] {
            let lo = [(t.rect[0] - m).max(0.0), (t.rect[1] - m).max(0.0)];
            let hi = [(t.rect[2] + m).min(1.0), (t.rect[3] + m).min(1.0)];
            cases.push([lo[0], lo[1], hi[0], hi[1]]);
            cases.push(t.rect);
            cases.push([f32::from_bits(t.packed_cuts()), m, 0.0, 0.0]);
            want.extend(t.octagon(m));
        }
    }
    let got = run_probe(&ctx, &cases, want.len());
    for (i, (g, w)) in got.iter().zip(&want).enumerate() {
        assert!(
            (g[0] - w[0]).abs() < 1e-5 && (g[1] - w[1]).abs() < 1e-5,
            "case {} corner {}: GPU {g:?}, CPU {w:?}",
            i / 8,
            i % 8
        );
    }
}

fn run_probe(ctx: &GpuContext, cases: &[[f32; 4]], corners: usize) -> Vec<[f32; 2]> {
    let bytes = common::run_probe(
        ctx,
        PROBE,
        bytemuck::cast_slice(cases),
        (corners * 8) as u64,
        (cases.len() / 3) as u32,
    );
    bytemuck::cast_slice(&bytes).to_vec()
}

/// The campfire's lit smoke (a round puff) is drawn as octagons by the billboards, and
/// the frame is the one drawn with rectangles: what the octagon leaves out is below the
/// trim threshold.
#[test]
fn octagon_billboards_draw_the_rectangles_frame() {
    let ctx = gpu();
    let mut effect = Effect::default_campfire();
    effect.post.bloom = None;
    // Pale, dense smoke, so that a cut into its puffs shows against the night.
    for stop in &mut effect.emitters[0].look.color_over_life {
        stop.rgba = [0.8, 0.8, 0.8, stop.rgba[3] * 3.0];
    }
    for e in &mut effect.emitters {
        e.look.draw_path = DrawPath::Billboard;
    }
    let mut run = Headless::new(&ctx, effect, ShaderLibrary::embedded()).expect("headless");
    for _ in 0..120 {
        run.advance(1.0 / 60.0);
    }
    let octagons = run.render((320, 240)).expect("render");
    let smoke = run.player.draw_items().iter().find(|d| d.index == 0);
    assert!(
        smoke.is_some_and(|d| d.variant.octagon),
        "the smoke is drawn as octagons"
    );
    run.player.draw_resources().0.octagons = false;
    let rects = run.render((320, 240)).expect("render");
    assert!(
        run.player.draw_items().iter().all(|d| !d.variant.octagon),
        "octagons off"
    );
    let (mean, max) = image_diff(&octagons, &rects);
    assert!(
        mean < 0.005 && max <= 1,
        "octagons vs rectangles: mean {mean}, max {max}"
    );
    let lit = octagons.pixels().filter(|p| p[0] > 60).count();
    assert!(lit > 2000, "{lit} lit pixels");
}
