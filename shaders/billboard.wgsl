// billboard.wgsl — pass 2, large particles: camera-facing quads, one instance per slot
// (vertex pulling from the state buffer the update pass just wrote).
//
// Contract:
// - group 0: binding 0 `camera` (CameraUniform), 1 `look` (LookUniform, dynamic offset
//   per emitter) — keep in sync with `src/gpu/types.rs`.
// - group 1: binding 0 `prev` (state before the last step), 1 `cur` (state after it).
// - Dead slots emit a degenerate quad outside the clip volume: no fragments, unlike the
//   2006 thesis whose dead particles piled up at the origin.
// - The fragment output is premultiplied: additive blending adds it, alpha blending
//   composites it "over". The look itself lives in look.wgsl (shared with splat.wgsl).
#import "common.wgsl"
#import "look.wgsl"

@group(0) @binding(0) var<uniform> camera: CameraUniform;
@group(0) @binding(1) var<uniform> look: LookUniform;
@group(1) @binding(0) var<storage, read> prev: array<Particle>;
@group(1) @binding(1) var<storage, read> cur: array<Particle>;
// Back-to-front slot order (sort.wgsl), read only by the alpha-blended pipeline.
@group(1) @binding(2) var<storage, read> order: array<u32>;

override SORTED: bool = false;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) color: vec4<f32>,
}

@vertex
fn vs_main(@builtin(vertex_index) vi: u32, @builtin(instance_index) instance: u32) -> VsOut {
    var out: VsOut;
    var slot = instance;
    if SORTED {
        slot = order[instance];
    }
    let d = drawn(cur[slot], prev[slot]);
    if !d.alive {
        out.clip = vec4<f32>(2.0, 2.0, 2.0, 1.0);
        out.uv = vec2<f32>(0.0);
        out.color = vec4<f32>(0.0);
        return out;
    }
    let t = age_fraction(d.age, d.life);
    let size = size_at(t);
    // Two triangles: 0 1 2, 2 1 3 over the corners (-1,-1) (1,-1) (-1,1) (1,1).
    let corner_index = array<u32, 6>(0u, 1u, 2u, 2u, 1u, 3u)[vi];
    let corner = vec2<f32>(f32(corner_index & 1u), f32(corner_index >> 1u)) * 2.0 - 1.0;
    let world = d.pos + (camera.right_alpha.xyz * corner.x + camera.up.xyz * corner.y) * (0.5 * size);
    out.clip = look.clip_from_sim * vec4<f32>(world, 1.0);
    out.uv = corner;
    out.color = particle_color(t);
    return out;
}

@fragment
fn fs_main(in: VsOut) -> @location(0) vec4<f32> {
    let cov = sprite_coverage(in.uv);
    let a = in.color.a * cov;
    var rgb = in.color.rgb * a;
    if look.sprite_blend.y == 0u {
        rgb = rgb * look.size_intensity.z;
    }
    return vec4<f32>(rgb, a);
}
