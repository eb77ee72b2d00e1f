// bloom.wgsl — the glow in the HDR composite: a soft threshold while halving the HDR
// image, a chain of 2× downsamples, then tent-filtered
// upsamples added back up the chain (Jimenez 2014, "Next Generation Post Processing in
// Call of Duty: Advanced Warfare"). tonemap.wgsl adds the top of the chain to the image.
//
// Compute passes, one invocation per pixel written (the H100 runs full-screen fragment
// passes on a sliver of its chip: each cost ~0.3 ms at 1080p).
//
// Contract: group 0: 0 `src` (the level read: the HDR target for `prefilter`, a level of
// the bloom chain otherwise), 1 `samp` (linear, clamp), 2 `bloom` (BloomUniform, keep in
// sync with src/render/bloom.rs), 3 `dst` (the level written), 4 `glow` (the draft glow
// layer, half the HDR target's resolution, read by `prefilter` when GLOW is on;
// tonemap.wgsl adds it to the image), 5 `below` (`up`: the down level it adds to).

struct BloomUniform {
    // x: threshold, y: knee (soft range below the threshold), zw: unused.
    params: vec4<f32>,
}

@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var samp: sampler;
@group(0) @binding(2) var<uniform> bloom: BloomUniform;
// The level written.
@group(0) @binding(3) var dst: texture_storage_2d<rgba16float, write>;
@group(0) @binding(4) var glow: texture_2d<f32>;
// `up`: the down level the upsampled light is added to.
@group(0) @binding(5) var below: texture_2d<f32>;

// Draft: the chain starts at a quarter of the resolution (a 4×4 average).
override QUARTER: bool = false;
// Draft: the large additive sprites were drawn into a half-resolution glow layer.
override GLOW: bool = false;

fn hdr_at(p: vec2<i32>) -> vec3<f32> {
    let size = vec2<i32>(textureDimensions(src));
    let q = clamp(p, vec2<i32>(0), size - 1);
    return textureLoad(src, q, 0).rgb;
}

// Whether invocation `id` is a pixel of the level written.
fn in_dst(id: vec3<u32>) -> bool {
    return all(id.xy < textureDimensions(dst));
}

// The texture coordinates of pixel `id`'s centre in the level written.
fn dst_uv(id: vec3<u32>) -> vec2<f32> {
    return (vec2<f32>(id.xy) + 0.5) / vec2<f32>(textureDimensions(dst));
}

fn tap(uv: vec2<f32>) -> vec3<f32> {
    return textureSampleLevel(src, samp, uv, 0.0).rgb;
}

// Full resolution → half: the 2×2 average (4×4 → quarter when QUARTER), kept above a
// soft threshold (quadratic knee).
@compute @workgroup_size(8, 8)
fn prefilter(@builtin(global_invocation_id) id: vec3<u32>) {
    if !in_dst(id) {
        return;
    }
    let at = vec2<i32>(id.xy);
    var c = vec3<f32>(0.0);
    if QUARTER {
        let p = at * 4;
        for (var y = 0; y < 4; y++) {
            for (var x = 0; x < 4; x++) {
                c += hdr_at(p + vec2<i32>(x, y));
            }
        }
        c *= 1.0 / 16.0;
    } else {
        let p = at * 2;
        c = 0.25 * (hdr_at(p) + hdr_at(p + vec2<i32>(1, 0)) + hdr_at(p + vec2<i32>(0, 1)) + hdr_at(p + vec2<i32>(1, 1)));
    }
    if GLOW {
        // The same block of the glow layer: 2×2 of its texels (quarter), or one.
        let size = vec2<i32>(textureDimensions(glow)) - 1;
        if QUARTER {
            let g = at * 2;
            c += 0.25 * (textureLoad(glow, min(g, size), 0).rgb
                + textureLoad(glow, min(g + vec2<i32>(1, 0), size), 0).rgb
                + textureLoad(glow, min(g + vec2<i32>(0, 1), size), 0).rgb
                + textureLoad(glow, min(g + vec2<i32>(1, 1), size), 0).rgb);
        } else {
            c += textureLoad(glow, min(at, size), 0).rgb;
        }
    }
    let threshold = bloom.params.x;
    let knee = max(bloom.params.y, 1e-5);
    let l = max(c.r, max(c.g, c.b));
    var soft = clamp(l - threshold + knee, 0.0, 2.0 * knee);
    soft = soft * soft / (4.0 * knee);
    let w = max(soft, l - threshold) / max(l, 1e-5);
    textureStore(dst, at, vec4<f32>(c * max(w, 0.0), 1.0));
}

// Halving with five bilinear taps (the dual-filter downsample).
@compute @workgroup_size(8, 8)
fn down(@builtin(global_invocation_id) id: vec3<u32>) {
    if !in_dst(id) {
        return;
    }
    let uv = dst_uv(id);
    let t = 1.0 / vec2<f32>(textureDimensions(src));
    var c = tap(uv) * 4.0;
    c += tap(uv + vec2<f32>(-t.x, -t.y));
    c += tap(uv + vec2<f32>(t.x, -t.y));
    c += tap(uv + vec2<f32>(-t.x, t.y));
    c += tap(uv + vec2<f32>(t.x, t.y));
    textureStore(dst, vec2<i32>(id.xy), vec4<f32>(c / 8.0, 1.0));
}

// Doubling with a 3×3 tent, added to the down level of the same size.
@compute @workgroup_size(8, 8)
fn up(@builtin(global_invocation_id) id: vec3<u32>) {
    if !in_dst(id) {
        return;
    }
    let uv = dst_uv(id);
    let t = 1.0 / vec2<f32>(textureDimensions(src));
    var c = tap(uv) * 4.0;
    c += (tap(uv + vec2<f32>(-t.x, 0.0)) + tap(uv + vec2<f32>(t.x, 0.0)) + tap(uv + vec2<f32>(0.0, -t.y)) + tap(uv + vec2<f32>(0.0, t.y))) * 2.0;
    c += tap(uv + vec2<f32>(-t.x, -t.y)) + tap(uv + vec2<f32>(t.x, -t.y)) + tap(uv + vec2<f32>(-t.x, t.y)) + tap(uv + vec2<f32>(t.x, t.y));
    let base = textureLoad(below, vec2<i32>(id.xy), 0);
    textureStore(dst, vec2<i32>(id.xy), vec4<f32>(base.rgb + c / 16.0, base.a));
}
