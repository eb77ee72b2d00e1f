// billboard.wgsl — pass 2: camera-facing quads, one instance per slot (vertex pulling).
//
// Contract:
// - group 0: binding 0 `camera` (CameraUniform), 1 `look` (LookUniform) — keep in sync
//   with `src/gpu/types.rs`.
// - group 1: binding 0 `prev` (state before the last step), 1 `cur` (state after it).
// - Dead slots emit a degenerate quad outside the clip volume: no fragments, unlike the
//   2006 thesis whose dead particles piled up at the origin.
// - The fragment output is premultiplied: additive blending adds it, alpha blending
//   composites it "over".
// Hook: `particle_color(t, rnd)` decides colour and alpha at normalised age t.
#import "common.wgsl"

struct CameraUniform {
    clip_from_world: mat4x4<f32>,
    // xyz: camera right (world), w: interpolation alpha between prev and cur.
    right_alpha: vec4<f32>,
    // xyz: camera up (world), w: unused.
    up: vec4<f32>,
}

struct LookUniform {
    // The emitter's simulation space → clip, composed in f64 on the CPU so effects far
    // from the world origin render without f32 jitter.
    clip_from_sim: mat4x4<f32>,
    colors: array<vec4<f32>, 8>,
    // Stop positions, four per vec4.
    stops: array<vec4<f32>, 2>,
    // size start (m), size end (m), intensity, stop count.
    size_intensity: vec4<f32>,
    // x: sprite kind, y: blend (0 additive, 1 alpha), zw: unused.
    sprite_blend: vec4<u32>,
}

@group(0) @binding(0) var<uniform> camera: CameraUniform;
@group(0) @binding(1) var<uniform> look: LookUniform;
@group(1) @binding(0) var<storage, read> prev: array<Particle>;
@group(1) @binding(1) var<storage, read> cur: array<Particle>;

override INTERPOLATE: bool = true;

const SPRITE_SOFT_DISC: u32 = 0u;
const SPRITE_POINT: u32 = 1u;
const SPRITE_SPARK: u32 = 2u;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) color: vec4<f32>,
}

fn stop_t(i: u32) -> f32 {
    return look.stops[i / 4u][i % 4u];
}

// Colour and alpha at normalised age t (piecewise-linear gradient, clamped at the ends).
fn particle_color(t: f32) -> vec4<f32> {
    let count = u32(look.size_intensity.w);
    if t <= stop_t(0u) {
        return look.colors[0];
    }
    for (var i = 1u; i < count; i++) {
        let t1 = stop_t(i);
        if t <= t1 {
            let t0 = stop_t(i - 1u);
            let f = select(1.0, (t - t0) / (t1 - t0), t1 > t0);
            return mix(look.colors[i - 1u], look.colors[i], f);
        }
    }
    return look.colors[count - 1u];
}

@vertex
fn vs_main(@builtin(vertex_index) vi: u32, @builtin(instance_index) slot: u32) -> VsOut {
    var out: VsOut;
    let p = cur[slot];
    if !is_alive(p) {
        out.clip = vec4<f32>(2.0, 2.0, 2.0, 1.0);
        out.uv = vec2<f32>(0.0);
        out.color = vec4<f32>(0.0);
        return out;
    }
    var pos = p.pos_age.xyz;
    var age = p.pos_age.w;
    if INTERPOLATE {
        // Render between the last two steps; only when the slot holds the same particle.
        let q = prev[slot];
        if is_alive(q) && q.pos_age.w < p.pos_age.w {
            let a = camera.right_alpha.w;
            pos = mix(q.pos_age.xyz, pos, a);
            age = mix(q.pos_age.w, age, a);
        }
    }
    let t = clamp(age / p.vel_life.w, 0.0, 1.0);
    let size = mix(look.size_intensity.x, look.size_intensity.y, t);
    // Two triangles: 0 1 2, 2 1 3 over the corners (-1,-1) (1,-1) (-1,1) (1,1).
    let corner_index = array<u32, 6>(0u, 1u, 2u, 2u, 1u, 3u)[vi];
    let corner = vec2<f32>(f32(corner_index & 1u), f32(corner_index >> 1u)) * 2.0 - 1.0;
    let world = pos + (camera.right_alpha.xyz * corner.x + camera.up.xyz * corner.y) * (0.5 * size);
    out.clip = look.clip_from_sim * vec4<f32>(world, 1.0);
    out.uv = corner;
    out.color = particle_color(t);
    return out;
}

fn sprite_coverage(uv: vec2<f32>) -> f32 {
    let r2 = dot(uv, uv);
    if r2 >= 1.0 {
        return 0.0;
    }
    switch look.sprite_blend.x {
        case SPRITE_POINT: {
            return select(0.0, 1.0, r2 < 0.25);
        }
        case SPRITE_SPARK: {
            return min(1.0, exp(-r2 * 14.0) * 1.5 + 0.25 * (1.0 - r2) * (1.0 - r2));
        }
        default: {
            let f = 1.0 - r2;
            return f * f;
        }
    }
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
