// The host's own shaders for examples/embed.rs: lit geometry into an HDR target, then a
// tonemap to the window. Nothing here is ignis's.

struct Scene {
    clip_from_world: mat4x4<f32>,
    // xyz: the campfire's position (a warm point light), w: its strength.
    fire: vec4<f32>,
}
@group(0) @binding(0) var<uniform> scene: Scene;

struct Lit {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) color: vec3<f32>,
}

@vertex
fn vs_lit(@location(0) pos: vec3<f32>, @location(1) normal: vec3<f32>, @location(2) color: vec3<f32>) -> Lit {
    return Lit(scene.clip_from_world * vec4<f32>(pos, 1.0), pos, normal, color);
}

@fragment
fn fs_lit(in: Lit) -> @location(0) vec4<f32> {
    let n = normalize(in.normal);
    // Moonlight, a little sky, and the campfire's warm light falling off with distance.
    let moon = vec3<f32>(0.04, 0.05, 0.09) * max(dot(n, normalize(vec3<f32>(-0.3, 1.0, 0.4))), 0.0);
    let to_fire = scene.fire.xyz - in.world;
    let d2 = dot(to_fire, to_fire);
    let fire = vec3<f32>(1.0, 0.45, 0.15) * scene.fire.w * max(dot(n, to_fire * inverseSqrt(d2)), 0.0) / (1.0 + d2);
    return vec4<f32>(in.color * (moon + vec3<f32>(0.015, 0.015, 0.025) + fire), 1.0);
}

@group(0) @binding(0) var hdr: texture_2d<f32>;

@vertex
fn vs_full(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs_tonemap(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {
    // Narkowicz's ACES fit; the window's sRGB format encodes the result.
    let x = textureLoad(hdr, vec2<i32>(p.xy), 0).rgb;
    let c = clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), vec3<f32>(0.0), vec3<f32>(1.0));
    return vec4<f32>(c, 1.0);
}
