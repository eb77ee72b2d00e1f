// depth_resolve.wgsl — a single-sample copy of a host's multisampled depth buffer, for
// the passes that sample the host's depth (soft edges, the splat's and the tiles' depth
// test): each pixel takes its first sample (a full-screen triangle writes it as depth).
//
// Contract: group 0 binding 0 `host_depth` (texture_depth_multisampled_2d, the host's
// depth aspect); the target is a Depth32Float attachment of the same size.

@group(0) @binding(0) var host_depth: texture_depth_multisampled_2d;

@vertex
fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs(@builtin(position) at: vec4<f32>) -> @builtin(frag_depth) f32 {
    return textureLoad(host_depth, vec2<i32>(at.xy), 0);
}
