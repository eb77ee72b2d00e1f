// clear.wgsl — zeroes the HDR target before the particles' pass (a compute pass: on the
// H100 a render pass's clear of a 4K target cost more than a millisecond).
//
// Contract: group 0 binding 0 `image` (the HDR image, Rgba16Float storage).

@group(0) @binding(0) var image: texture_storage_2d<rgba16float, write>;

@compute @workgroup_size(8, 8)
fn clear(@builtin(global_invocation_id) id: vec3<u32>) {
    if all(id.xy < textureDimensions(image)) {
        textureStore(image, vec2<i32>(id.xy), vec4<f32>(0.0));
    }
}
