// tonemap.wgsl — HDR (linear, Rgba16Float) → display (8-bit, sRGB-encoded here), a compute
// pass (full-screen fragment passes run on a sliver of the H100).
//
// Contract: group 0 binding 0 `hdr` texture, binding 1 `tone` (x: exposure, y: bloom
// intensity), binding 3 `bloom_tex` + 4 `bloom_samp` (level 0 of the bloom chain, read only when
// BLOOM is on), binding 5 `alpha_tex` (the alpha-blended layers at reduced resolution,
// read only when LOW_ALPHA is on), binding 6 `glow_tex` (the draft glow layer at half
// resolution, read only when GLOW is on: upsampled here instead of in a pass of its own).
// binding 7 `display`. The ACES fit by Krzysztof Narkowicz maps HDR to [0, 1].

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
// The display image (8-bit unorm, sRGB-encoded values).
@group(0) @binding(7) var display: texture_storage_2d<rgba8unorm, write>;

override BLOOM: bool = false;
override LOW_ALPHA: bool = false;
override GLOW: bool = false;

fn aces(x: vec3<f32>) -> vec3<f32> {
    let a = 2.51;
    let b = 0.03;
    let c = 2.43;
    let d = 0.59;
    let e = 0.14;
    return clamp((x * (a * x + b)) / (x * (c * x + d) + e), vec3<f32>(0.0), vec3<f32>(1.0));
}

// sRGB encoding of a linear value in [0, 1] (the display image is 8-bit unorm holding
// sRGB-encoded values: a storage texture cannot be an sRGB format).
fn srgb(x: vec3<f32>) -> vec3<f32> {
    let lo = x * 12.92;
    let hi = 1.055 * pow(x, vec3<f32>(1.0 / 2.4)) - 0.055;
    return select(hi, lo, x <= vec3<f32>(0.0031308));
}

// One invocation per pixel of the display image.
@compute @workgroup_size(8, 8)
fn tonemap(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(hdr);
    if any(id.xy >= size) {
        return;
    }
    let frag = vec2<f32>(id.xy) + 0.5;
    var c = textureLoad(hdr, vec2<i32>(id.xy), 0).rgb;
    let uv = frag / vec2<f32>(size);
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
    textureStore(display, vec2<i32>(id.xy), vec4<f32>(srgb(aces(c * tone.exposure.x)), 1.0));
}
