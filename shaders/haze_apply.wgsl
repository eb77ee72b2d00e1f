// haze_apply.wgsl — heat haze's refraction: the frame's colour (a copy) sampled where the
// distortion target says, into the frame's colour. One full-screen triangle.
//
// Contract: group 0: binding 0 `scene_color` (the copy, the target's size), 1
// `distortion` (the summed offsets in uv units, rg; billboard.wgsl HAZE; smaller than the
// target, sampled bilinearly), 2 a linear clamped sampler. A pixel with no offset samples
// its own texel's centre: unchanged.

@group(0) @binding(0) var scene_color: texture_2d<f32>;
@group(0) @binding(1) var distortion: texture_2d<f32>;
@group(0) @binding(2) var scene_sampler: sampler;

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs_main(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let uv = frag.xy / vec2<f32>(textureDimensions(scene_color));
    let offset = textureSampleLevel(distortion, scene_sampler, uv, 0.0).xy;
    return textureSampleLevel(scene_color, scene_sampler, uv + offset, 0.0);
}
