// tonemap.wgsl — HDR (linear, Rgba16Float) → display (sRGB target does the encoding).
//
// Contract: group 0 binding 0 `hdr` texture, binding 1 `tone` (x: exposure, y: bloom
// intensity), binding 3 `bloom_tex` + 4 `bloom_samp` (level 0 of the bloom chain, read only when
// BLOOM is on), binding 5 `alpha_tex` (the alpha-blended layers at reduced resolution,
// read only when LOW_ALPHA is on), binding 6 `glow_tex` (the draft glow layer at half
// resolution, read only when GLOW is on: upsampled here instead of in a pass of its own).
// A full-screen triangle; the ACES fit by Krzysztof Narkowicz maps HDR to [0, 1].

struct ToneUniform {
    // x: exposure multiplier, y: bloom intensity, zw: unused.
    exposure: vec4<f32>,
}

@group(0) @binding(0) var hdr: texture_2d<f32>;
@group(0) @binding(1) var<uniform> tone: ToneUniform;
@group(0) @binding(3) var bloom_tex: texture_2d<f32>;
@group(0) @binding(4) var bloom_samp: sampler;
// The alpha-blended layers drawn at reduced resolution (read only when LOW_ALPHA is on).
@group(0) @binding(5) var alpha_tex: texture_2d<f32>;
// The draft glow layer (read only when GLOW is on).
@group(0) @binding(6) var glow_tex: texture_2d<f32>;

override BLOOM: bool = false;
override LOW_ALPHA: bool = false;
override GLOW: bool = false;

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((vi << 1u) & 2u), f32(vi & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

fn aces(x: vec3<f32>) -> vec3<f32> {
    let a = 2.51;
    let b = 0.03;
    let c = 2.43;
    let d = 0.59;
    let e = 0.14;
    return clamp((x * (a * x + b)) / (x * (c * x + d) + e), vec3<f32>(0.0), vec3<f32>(1.0));
}

@fragment
fn fs_main(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    var c = textureLoad(hdr, vec2<i32>(frag.xy), 0).rgb;
    let uv = frag.xy / vec2<f32>(textureDimensions(hdr));
    if GLOW {
        // Bilinear, as the pass that added it to the HDR image did.
        c += textureSampleLevel(glow_tex, bloom_samp, uv, 0.0).rgb;
    }
    if LOW_ALPHA {
        // Premultiplied smoke over black, under the additive light: it simply adds.
        c += textureSampleLevel(alpha_tex, bloom_samp, uv, 0.0).rgb;
    }
    if BLOOM {
        c += tone.exposure.y * textureSampleLevel(bloom_tex, bloom_samp, uv, 0.0).rgb;
    }
    return vec4<f32>(aces(c * tone.exposure.x), 1.0);
}
