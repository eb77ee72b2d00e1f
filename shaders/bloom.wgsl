// bloom.wgsl — the glow in the HDR composite: a soft threshold while halving the HDR
// image, a chain of 2× downsamples, then tent-filtered
// upsamples added back up the chain (Jimenez 2014, "Next Generation Post Processing in
// Call of Duty: Advanced Warfare"). tonemap.wgsl adds the top of the chain to the image.
//
// Contract: group 0: 0 `src` (the level read: the HDR target for `prefilter`, a level of
// the bloom chain otherwise), 1 `samp` (linear, clamp), 2 `bloom` (BloomUniform, keep in
// sync with src/render/bloom.rs), 4 `glow` (the draft glow layer, half the HDR target's
// resolution, read by `prefilter` when GLOW is on; tonemap.wgsl adds it to the image).

struct BloomUniform {
    // x: threshold, y: knee (soft range below the threshold), zw: unused.
    params: vec4<f32>,
}

@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var samp: sampler;
@group(0) @binding(2) var<uniform> bloom: BloomUniform;
@group(0) @binding(4) var glow: texture_2d<f32>;

// Draft: the chain starts at a quarter of the resolution (a 4×4 average).
override QUARTER: bool = false;
// Draft: the large additive sprites were drawn into a half-resolution glow layer.
override GLOW: bool = false;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
}

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> VsOut {
    let uv = vec2<f32>(f32((vi << 1u) & 2u), f32(vi & 2u));
    var out: VsOut;
    out.clip = vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
    out.uv = vec2<f32>(uv.x, 1.0 - uv.y);
    return out;
}

fn hdr_at(p: vec2<i32>) -> vec3<f32> {
    let size = vec2<i32>(textureDimensions(src));
    let q = clamp(p, vec2<i32>(0), size - 1);
    return textureLoad(src, q, 0).rgb;
}

// Full resolution → half: the 2×2 average (4×4 → quarter when QUARTER), kept above a
// soft threshold (quadratic knee).
@fragment
fn prefilter(in: VsOut) -> @location(0) vec4<f32> {
    var c = vec3<f32>(0.0);
    if QUARTER {
        let p = vec2<i32>(in.clip.xy) * 4;
        for (var y = 0; y < 4; y++) {
            for (var x = 0; x < 4; x++) {
                c += hdr_at(p + vec2<i32>(x, y));
            }
        }
        c *= 1.0 / 16.0;
    } else {
        let p = vec2<i32>(in.clip.xy) * 2;
        c = 0.25 * (hdr_at(p) + hdr_at(p + vec2<i32>(1, 0)) + hdr_at(p + vec2<i32>(0, 1)) + hdr_at(p + vec2<i32>(1, 1)));
    }
    if GLOW {
        // The same block of the glow layer: 2×2 of its texels (quarter), or one.
        let size = vec2<i32>(textureDimensions(glow)) - 1;
        if QUARTER {
            let g = vec2<i32>(in.clip.xy) * 2;
            c += 0.25 * (textureLoad(glow, min(g, size), 0).rgb
                + textureLoad(glow, min(g + vec2<i32>(1, 0), size), 0).rgb
                + textureLoad(glow, min(g + vec2<i32>(0, 1), size), 0).rgb
                + textureLoad(glow, min(g + vec2<i32>(1, 1), size), 0).rgb);
        } else {
            c += textureLoad(glow, min(vec2<i32>(in.clip.xy), size), 0).rgb;
        }
    }
    let threshold = bloom.params.x;
    let knee = max(bloom.params.y, 1e-5);
    let l = max(c.r, max(c.g, c.b));
    var soft = clamp(l - threshold + knee, 0.0, 2.0 * knee);
    soft = soft * soft / (4.0 * knee);
    let w = max(soft, l - threshold) / max(l, 1e-5);
    return vec4<f32>(c * max(w, 0.0), 1.0);
}

// Halving with five bilinear taps (the dual-filter downsample).
@fragment
fn down(in: VsOut) -> @location(0) vec4<f32> {
    let t = 1.0 / vec2<f32>(textureDimensions(src));
    var c = textureSample(src, samp, in.uv).rgb * 4.0;
    c += textureSample(src, samp, in.uv + vec2<f32>(-t.x, -t.y)).rgb;
    c += textureSample(src, samp, in.uv + vec2<f32>(t.x, -t.y)).rgb;
    c += textureSample(src, samp, in.uv + vec2<f32>(-t.x, t.y)).rgb;
    c += textureSample(src, samp, in.uv + vec2<f32>(t.x, t.y)).rgb;
    return vec4<f32>(c / 8.0, 1.0);
}

// Doubling with a 3×3 tent, added (blend One + One) onto the level above.
@fragment
fn up(in: VsOut) -> @location(0) vec4<f32> {
    let t = 1.0 / vec2<f32>(textureDimensions(src));
    var c = textureSample(src, samp, in.uv).rgb * 4.0;
    c += (textureSample(src, samp, in.uv + vec2<f32>(-t.x, 0.0)).rgb
        + textureSample(src, samp, in.uv + vec2<f32>(t.x, 0.0)).rgb
        + textureSample(src, samp, in.uv + vec2<f32>(0.0, -t.y)).rgb
        + textureSample(src, samp, in.uv + vec2<f32>(0.0, t.y)).rgb) * 2.0;
    c += textureSample(src, samp, in.uv + vec2<f32>(-t.x, -t.y)).rgb
        + textureSample(src, samp, in.uv + vec2<f32>(t.x, -t.y)).rgb
        + textureSample(src, samp, in.uv + vec2<f32>(-t.x, t.y)).rgb
        + textureSample(src, samp, in.uv + vec2<f32>(t.x, t.y)).rgb;
    return vec4<f32>(c / 16.0, 1.0);
}
