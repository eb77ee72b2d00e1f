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

// The same refraction by compute, for a target with storage usage in `rgba16float` (the
// editor's and `ignis render`'s HDR target): GPUs run compute on every SM, while a
// full-screen draw runs on the few that rasterise. Every pixel is written (the target
// need not hold the image: the editor refracts into a second HDR image).
@group(0) @binding(3) var target_image: texture_storage_2d<rgba16float, write>;

@compute @workgroup_size(8, 8)
fn cs_main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(scene_color);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let uv = (vec2<f32>(id.xy) + 0.5) / vec2<f32>(size);
    let offset = textureSampleLevel(distortion, scene_sampler, uv, 0.0).xy;
    textureStore(target_image, id.xy, textureSampleLevel(scene_color, scene_sampler, uv + offset, 0.0));
}
