// test_scene.wgsl — the editor's test scene: opaque grey props (the ground, a box, a step)
// drawn into the HDR target and a depth buffer before the particles, so that depth
// collision, soft edges and occlusion can be seen while designing.
//
// Contract: group 0 binding 0 `scene` (clip_from_world, the sun's direction and the
// light's strength); vertex buffer 0: position (world, m), normal. Writes linear HDR
// colour (alpha 1) and depth (ordinary Z, cleared to 1).

struct Scene {
    clip_from_world: mat4x4<f32>,
    // xyz: towards the sun (unit), w: the light's strength (HDR).
    sun: vec4<f32>,
}

@group(0) @binding(0) var<uniform> scene: Scene;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
}

@vertex
fn vs_main(@location(0) pos: vec3<f32>, @location(1) normal: vec3<f32>) -> VsOut {
    return VsOut(scene.clip_from_world * vec4<f32>(pos, 1.0), pos, normal);
}

@fragment
fn fs_main(v: VsOut) -> @location(0) vec4<f32> {
    let n = normalize(v.normal);
    // A 0.5 m checker on every face, so motion over the props reads.
    let cell = floor(v.world * 2.0 + n * 0.25);
    let checker = select(0.85, 1.0, (i32(cell.x + cell.y + cell.z) & 1) == 0);
    // The ground dark, the props lighter and warmer, so their edges read.
    let ground = v.world.y < 1e-3 && n.y > 0.5;
    let albedo = select(vec3<f32>(0.42, 0.36, 0.3), vec3<f32>(0.1), ground);
    let light = 0.3 + 0.7 * max(dot(n, scene.sun.xyz), 0.0);
    return vec4<f32>(albedo * checker * light * scene.sun.w, 1.0);
}
