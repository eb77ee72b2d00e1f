// sprite_trim.wgsl — the octagon a billboard is cut to (src/render/sprite_trim.rs, its CPU
// mirror `Trim::octagon`): the sprite's visible rectangle with its four corners cut
// diagonally where the sprite leaves them empty (a puff's round edge), both grown by the
// mip margin. No bindings: pure functions.

// Corner `k` (0..7, around the octagon, from the top edge's left end) of the octagon in
// frame texture coordinates (v down): `lo`, `hi` the rectangle grown by the margin `m`
// and cut to the frame; `trim` the rectangle before the margin; `cuts` the corners' cuts
// before it (the legs of the cut triangles at (lo, lo), (hi, lo), (hi, hi), (lo, hi);
// pack4x8unorm, frame units).
fn octagon_corner(lo: vec2<f32>, hi: vec2<f32>, trim: vec4<f32>, cuts: u32, m: f32, k: u32) -> vec2<f32> {
    let raw = unpack4x8unorm(cuts);
    // The margin moves each cut line out by m along both axes; where the frame clipped the
    // margin, the corner moved less, and the cut shrinks by the difference.
    let glo = trim.xy - m - lo;
    let ghi = hi - trim.zw - m;
    var t = max(raw + vec4<f32>(glo.x + glo.y, ghi.x + glo.y, ghi.x + ghi.y, glo.x + ghi.y), vec4<f32>(0.0));
    // Two cuts along one edge never overlap (cutting less stays conservative).
    let wh = hi - lo;
    var s = min(1.0, wh.x / max(t.x + t.y, 1e-12));
    t.x *= s;
    t.y *= s;
    s = min(1.0, wh.y / max(t.y + t.z, 1e-12));
    t.y *= s;
    t.z *= s;
    s = min(1.0, wh.x / max(t.w + t.z, 1e-12));
    t.w *= s;
    t.z *= s;
    s = min(1.0, wh.y / max(t.x + t.w, 1e-12));
    t.x *= s;
    t.w *= s;
    var p = array<vec2<f32>, 8>(
        vec2<f32>(lo.x + t.x, lo.y),
        vec2<f32>(hi.x - t.y, lo.y),
        vec2<f32>(hi.x, lo.y + t.y),
        vec2<f32>(hi.x, hi.y - t.z),
        vec2<f32>(hi.x - t.z, hi.y),
        vec2<f32>(lo.x + t.w, hi.y),
        vec2<f32>(lo.x, hi.y - t.w),
        vec2<f32>(lo.x, lo.y + t.x),
    );
    return p[k & 7u];
}
