// curves.wgsl — reading baked curve rows (src/effect/curve.rs): a parameter in any of its
// four modes (constant, range, curve, two curves) is two rows A and B of CURVE_WIDTH
// texels, four parameters to a texel; its value at t for a particle's random number u is
// mix(A(t), B(t), u). A row is read like the colour ramp: the two texels around
// t · (CURVE_WIDTH − 1), blended linearly (exact at texel centres). Plumbing, not a hook.

// Texels per row (keep in sync with `CURVE_WIDTH` in src/effect/curve.rs).
const CURVE_WIDTH: u32 = 1024u;

// The two texels around normalised time t and the weight of the second.
struct CurveTexels {
    i: u32,
    j: u32,
    f: f32,
}

fn curve_texels(t: f32) -> CurveTexels {
    let x = clamp(t, 0.0, 1.0) * f32(CURVE_WIDTH - 1u);
    let i = min(u32(x), CURVE_WIDTH - 1u);
    return CurveTexels(i, min(i + 1u, CURVE_WIDTH - 1u), x - f32(i));
}
