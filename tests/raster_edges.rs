//! The rasteriser's decision as the tiles evaluate it (`shaders/raster_edges.wgsl`): the
//! pixel centres a quad of two triangles on the 1/256-pixel grid lights, with its edge
//! functions in 11-bit limbs, against the same rule in 64-bit integers here — ties on
//! every kind of edge, quads either way round, corners far apart, and the range the
//! limbs hold. (That the rule is the rasteriser's own is `tests/tiles.rs`'s
//! `rotated_sprites_edges_match_the_rasteriser_in_every_frame`.)

mod common;

use common::gpu;
use ignis::testing::gpu::GpuContext;

const PROBE: &str = r#"
#import "raster_edges.wgsl"
// Per case: corners 0 and 1, corners 2 and 3 (pixels × 256), the pixel centre (pixels).
@group(0) @binding(0) var<storage, read> cases: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read_write> covers: array<i32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let c = id.x;
    if c >= arrayLength(&covers) {
        return;
    }
    covers[c] = quad_covers(cases[3u * c], cases[3u * c + 1u], cases[3u * c + 2u].xy);
}
"#;

/// The exact limit of the limbs (1/256-pixel units).
const LIMIT: i64 = 1 << 21;

fn cross(a: [i64; 2], b: [i64; 2]) -> i64 {
    a[0] * b[1] - a[1] * b[0]
}

fn sub(a: [i64; 2], b: [i64; 2]) -> [i64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

/// A top edge (horizontal, the triangle below it) or a left edge, for a triangle of
/// positive area (x right, y down).
fn top_left(a: [i64; 2], b: [i64; 2]) -> bool {
    let d = sub(b, a);
    (d[1] == 0 && d[0] > 0) || d[1] < 0
}

fn triangle(a: [i64; 2], b: [i64; 2], c: [i64; 2], p: [i64; 2]) -> bool {
    let area = cross(sub(b, a), sub(c, a));
    if area == 0 {
        return false;
    }
    let (b, c) = if area > 0 { (b, c) } else { (c, b) };
    [(a, b), (b, c), (c, a)].iter().all(|&(u, v)| {
        let e = cross(sub(v, u), sub(p, u));
        e > 0 || (e == 0 && top_left(u, v))
    })
}

/// The rule in 64-bit integers: 1 lit, 0 not, -1 out of the limbs' range.
fn reference(q: [[i64; 2]; 4], p: [i64; 2]) -> i32 {
    if q.iter()
        .chain([&p])
        .any(|c| c[0].abs() >= LIMIT || c[1].abs() >= LIMIT)
    {
        return -1;
    }
    i32::from(triangle(q[0], q[1], q[2], p) || triangle(q[2], q[1], q[3], p))
}

/// Quads and pixels: (corners in 1/256 px, pixel x, pixel y).
fn cases() -> Vec<([[i64; 2]; 4], i64, i64)> {
    let mut out = Vec::new();
    // Ties on each kind of edge: a horizontal top and bottom, vertical sides, diagonals
    // down-right and up-right, each through pixel centres (256 k + 128), both windings.
    let shapes: [[[i64; 2]; 4]; 5] = [
        [[128, 384], [1664, 384], [128, 1408], [1664, 1408]],
        [[1664, 384], [128, 384], [1664, 1408], [128, 1408]],
        [[896, 128], [1664, 896], [128, 896], [896, 1664]],
        [[128, 128], [1152, 128], [640, 1152], [1664, 1152]],
        [[640, 100], [1700, 640], [100, 1180], [1160, 1720]],
    ];
    for q in shapes {
        for y in 0..8 {
            for x in 0..8 {
                out.push((q, x, y));
            }
        }
    }
    // Turned quads far from the origin and large (products past 2^24, under 2^44).
    let mut s = 0x9e37_79b9u32;
    let mut next = move || {
        s ^= s << 13;
        s ^= s >> 17;
        s ^= s << 5;
        i64::from(s % 2_000_000) - 1_000_000
    };
    for _ in 0..200 {
        let (cx, cy) = (next(), next());
        let (ux, uy) = (next() / 4, next() / 4);
        let q = [
            [cx, cy],
            [cx + ux, cy + uy],
            [cx - uy, cy + ux],
            [cx + ux - uy, cy + uy + ux + next() % 3],
        ];
        let (px, py) = (
            (cx + ux / 2 - uy / 2).div_euclid(256),
            (cy + uy / 2 + ux / 2).div_euclid(256),
        );
        for d in -2..=2 {
            out.push((q, px + d, py - d));
        }
    }
    // Beyond the limbs' range: refused, never guessed.
    out.push(([[LIMIT, 0], [0, 0], [0, 256], [256, 256]], 0, 0));
    out.push(([[0, 0], [256, 0], [0, 256], [256, -LIMIT - 5]], 0, 0));
    out.push(([[0, 0], [256, 0], [0, 256], [256, 256]], 8192, 0));
    out
}

/// Every case's answer on the GPU is the 64-bit rule's, and the ties and the refusals
/// are among them.
#[test]
fn the_tiles_exact_edges_are_the_64_bit_rule() {
    let ctx = gpu();
    let cases = cases();
    let mut input: Vec<[f32; 4]> = Vec::new();
    for (q, x, y) in &cases {
        let f = |c: [i64; 2]| [c[0] as f32, c[1] as f32];
        let ([a, b], [c, d]) = ([f(q[0]), f(q[1])], [f(q[2]), f(q[3])]);
        input.push([a[0], a[1], b[0], b[1]]);
        input.push([c[0], c[1], d[0], d[1]]);
        input.push([*x as f32 + 0.5, *y as f32 + 0.5, 0.0, 0.0]);
    }
    let got = run_probe(&ctx, &input, cases.len());
    let mut ties = 0;
    for (i, ((q, x, y), g)) in cases.iter().zip(&got).enumerate() {
        let p = [256 * x + 128, 256 * y + 128];
        let want = reference(*q, p);
        let on_edge = [(0, 1), (1, 3), (3, 2), (2, 0)].iter().any(|&(a, b)| {
            let e = cross(sub(q[b], q[a]), sub(p, q[a]));
            e == 0 && want >= 0
        });
        ties += usize::from(on_edge);
        assert_eq!(*g, want, "case {i}: quad {q:?}, pixel ({x}, {y})");
    }
    assert!(ties > 50, "{ties} pixel centres on an edge");
    assert_eq!(got.iter().filter(|&&g| g < 0).count(), 3, "refused cases");
    assert!(got.contains(&1) && got.contains(&0));
}

fn run_probe(ctx: &GpuContext, input: &[[f32; 4]], n: usize) -> Vec<i32> {
    let bytes = common::run_probe(
        ctx,
        PROBE,
        bytemuck::cast_slice(input),
        (n * 4) as u64,
        n.div_ceil(64) as u32,
    );
    bytemuck::cast_slice(&bytes).to_vec()
}
