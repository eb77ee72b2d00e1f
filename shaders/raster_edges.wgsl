// raster_edges.wgsl — which pixel centres the rasteriser lights for a quad drawn as two
// triangles (0 1 2, 2 1 3) over corners on its 1/256-pixel grid: the edge functions
// evaluated exactly in integers, ties settled by the top-left rule (Vulkan's, lavapipe's
// and NVIDIA's). The tile rasteriser asks it where its uv test cannot tell (a rotated
// sprite's edge within a sliver of a pixel centre). No bindings: pure functions.

// Coordinates this large (1/256-pixel units: 8192 pixels; their differences stay under
// 2^22) leave the exact products' limbs: such quads keep the uv test.
const RASTER_EXACT_LIMIT: i32 = 2097152;

// The sign (-1, 0, 1) of a.x · b.y − a.y · b.x, exactly, for |components| < 2^22: each
// factor split into 11-bit limbs (v = hi · 2048 + lo, 0 ≤ lo < 2048), the partial sums
// carried up from the low limb, so that no i32 overflows.
fn cross_sign(a: vec2<i32>, b: vec2<i32>) -> i32 {
    let ah = a >> vec2<u32>(11u);
    let al = a & vec2<i32>(2047);
    let bh = b >> vec2<u32>(11u);
    let bl = b & vec2<i32>(2047);
    let t2 = ah.x * bh.y - ah.y * bh.x;
    let t1 = ah.x * bl.y + al.x * bh.y - ah.y * bl.x - al.y * bh.x;
    let t0 = al.x * bl.y - al.y * bl.x;
    // The value is u2 · 2^22 + r1 · 2^11 + r0 with 0 ≤ r1, r0 < 2^11.
    let u1 = t1 + (t0 >> 11u);
    let u2 = t2 + (u1 >> 11u);
    if u2 != 0 {
        return sign(u2);
    }
    return select(0, 1, (u1 & 2047) != 0 || (t0 & 2047) != 0);
}

// Whether the edge from `a` to `b` of a triangle wound so that its area is positive (x
// right, y down) is a top edge (horizontal, the triangle below it) or a left edge.
fn top_left(a: vec2<i32>, b: vec2<i32>) -> bool {
    let d = b - a;
    return (d.y == 0 && d.x > 0) || d.y < 0;
}

// Whether the triangle (a, b, c) lights the pixel centre `p` (all 1/256-pixel units).
fn triangle_covers(a: vec2<i32>, b_in: vec2<i32>, c_in: vec2<i32>, p: vec2<i32>) -> bool {
    let area = cross_sign(b_in - a, c_in - a);
    if area == 0 {
        return false;
    }
    // Wound to a positive area.
    let b = select(c_in, b_in, area > 0);
    let c = select(b_in, c_in, area > 0);
    let e0 = cross_sign(b - a, p - a);
    let e1 = cross_sign(c - b, p - b);
    let e2 = cross_sign(a - c, p - c);
    return (e0 > 0 || (e0 == 0 && top_left(a, b)))
        && (e1 > 0 || (e1 == 0 && top_left(b, c)))
        && (e2 > 0 || (e2 == 0 && top_left(c, a)));
}

// Whether a quad with corners `c01` = (p0, p1) and `c23` = (p2, p3) (pixels × 256, on the
// grid) lights the pixel centre `pc` (pixels): 1 yes, 0 no, -1 out of the exact range.
fn quad_covers(c01: vec4<f32>, c23: vec4<f32>, pc: vec2<f32>) -> i32 {
    let p = pc * 256.0;
    let lim = f32(RASTER_EXACT_LIMIT);
    if any(abs(c01) >= vec4<f32>(lim)) || any(abs(c23) >= vec4<f32>(lim)) || any(abs(p) >= vec2<f32>(lim)) {
        return -1;
    }
    let p0 = vec2<i32>(c01.xy);
    let p1 = vec2<i32>(c01.zw);
    let p2 = vec2<i32>(c23.xy);
    let p3 = vec2<i32>(c23.zw);
    let q = vec2<i32>(p);
    return select(0, 1, triangle_covers(p0, p1, p2, q) || triangle_covers(p2, p1, p3, q));
}
