// lit.wgsl — lit smoke: six-way lighting (the convention of Unity's Six Way shader and
// EmberGen's six-way export). A lit sprite holds how it looks lit from each axis of its
// own frame — +X right, +Y top, +Z back (away from the viewer), and −X, −Y, −Z — in two
// maps side by side in one texture: RTBA on the left (alpha: coverage), LBFE on the right
// (alpha: the emissive mask), premultiplied by the coverage (src/render/sixway_maps.rs).
// Each light adds its colour to the axes it shines along, weighted by the squares of its
// direction's components in the sprite's frame (they sum to one); ambient light adds a
// sixth of itself to every axis. Computed once per particle (`sixway_axes`), mixed per
// pixel (`sixway_rgb`).
//
// Contract: the including file sets `lit` (the instance's `LitUniform`) with `look`.
#import "look.wgsl"

var<private> lit: LitUniform;

// The light reaching a particle along each axis: x, y, z the positive axes (right, top,
// back), then the negative ones (left, bottom, front) — each rgb.
struct SixWay {
    pos: array<vec3<f32>, 3>,
    neg: array<vec3<f32>, 3>,
}

// Adds light of colour `rgb` from direction `l` (unit, towards the light, in the sprite's
// frame).
fn add_light(s: ptr<function, SixWay>, l: vec3<f32>, rgb: vec3<f32>) {
    let w = l * l;
    for (var a = 0; a < 3; a++) {
        if l[a] > 0.0 {
            (*s).pos[a] += rgb * w[a];
        } else {
            (*s).neg[a] += rgb * w[a];
        }
    }
}

// Light of colour `rgb` from every direction.
fn add_ambient(s: ptr<function, SixWay>, rgb: vec3<f32>) {
    for (var a = 0; a < 3; a++) {
        (*s).pos[a] += rgb / 6.0;
        (*s).neg[a] += rgb / 6.0;
    }
}

// The six-way light of a particle at `pos` (simulation space) whose sprite lies along
// `x_axis` and `y_axis` (unit, the world's directions of its frame's +X and +Y), times
// `gain` (the albedo and the particle's opacity).
fn sixway_axes(pos: vec3<f32>, x_axis: vec3<f32>, y_axis: vec3<f32>, gain: vec3<f32>) -> SixWay {
    var s: SixWay;
    let frame = transpose(mat3x3<f32>(x_axis, y_axis, cross(y_axis, x_axis)));
    add_light(&s, frame * lit.sun_dir.xyz, lit.sun_color.rgb);
    add_ambient(&s, lit.ambient.rgb);
    // The effect's own light: its power over the squared distance, the part within its
    // spread from every direction (a particle inside the flames is lit all round).
    let to_fire = lit.self_pos.xyz - pos;
    let d2 = dot(to_fire, to_fire);
    let spread2 = lit.self_pos.w;
    if lit.self_rgb.w > 0.0 && lit.sun_dir.w > 0.0 {
        let e = lit.self_rgb.rgb * (lit.sun_dir.w / max(d2 + spread2, 1e-4));
        let around = spread2 / max(d2 + spread2, 1e-12);
        add_ambient(&s, e * around);
        if d2 > 1e-12 {
            add_light(&s, frame * (to_fire * inverseSqrt(d2)), e * (1.0 - around));
        }
    }
    for (var k = 0u; k < min(u32(lit.sun_color.w), 4u); k++) {
        let p = lit.points[2u * k];
        let to_light = p.xyz - pos;
        let r2 = max(dot(to_light, to_light), 0.01);
        // Inverse square, windowed smoothly to zero at the range.
        let x = r2 / max(p.w * p.w, 1e-6);
        let window = clamp(1.0 - x * x, 0.0, 1.0);
        let e = lit.points[2u * k + 1u].rgb * (window * window / r2);
        add_light(&s, frame * (to_light * inverseSqrt(r2)), e);
    }
    for (var a = 0; a < 3; a++) {
        s.pos[a] *= gain;
        s.neg[a] *= gain;
    }
    return s;
}

// The six axes' light in five vec4s (for a flat varying or a tile sprite's fields).
fn pack_sixway(s: SixWay) -> array<vec4<f32>, 5> {
    return array<vec4<f32>, 5>(
        vec4<f32>(s.pos[0], s.pos[1].r),
        vec4<f32>(s.pos[1].gb, s.pos[2].rg),
        vec4<f32>(s.pos[2].b, s.neg[0]),
        vec4<f32>(s.neg[1], s.neg[2].r),
        vec4<f32>(s.neg[2].gb, 0.0, 0.0),
    );
}

// The lit colour (premultiplied) of texels `rtba` and `lbfe` under packed light `l`.
fn sixway_rgb(l: array<vec4<f32>, 5>, rtba: vec4<f32>, lbfe: vec4<f32>) -> vec3<f32> {
    return l[0].rgb * rtba.r + vec3<f32>(l[0].a, l[1].rg) * rtba.g + vec3<f32>(l[1].ba, l[2].r) * rtba.b
        + l[2].gba * lbfe.r + l[3].rgb * lbfe.g + vec3<f32>(l[3].a, l[4].rg) * lbfe.b;
}

// Texture coordinates of the RTBA map (the left half) from a sprite's coordinates.
fn rtba_uv(uv: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(uv.x * 0.5, uv.y);
}

// ... and of the LBFE map (the right half).
fn lbfe_uv(uv: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(uv.x * 0.5 + 0.5, uv.y);
}
