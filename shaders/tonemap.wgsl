// tonemap.wgsl — HDR (linear, Rgba16Float) → display (sRGB target does the encoding).
//
// Contract: group 0 binding 0 `hdr` texture, binding 1 `tone` (x: exposure).
// A full-screen triangle; the ACES fit by Krzysztof Narkowicz maps HDR to [0, 1].

struct ToneUniform {
    // x: exposure multiplier, yzw: unused.
    exposure: vec4<f32>,
}

@group(0) @binding(0) var hdr: texture_2d<f32>;
@group(0) @binding(1) var<uniform> tone: ToneUniform;

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
    let c = textureLoad(hdr, vec2<i32>(frag.xy), 0).rgb;
    return vec4<f32>(aces(c * tone.exposure.x), 1.0);
}
