// look.wgsl — how a particle looks, shared by both draw paths (billboards and the
// compute splat) so they render the same fire. A designer hook: `particle_color`.
//
// Contract: the including file declares `camera: CameraUniform` and `look: LookUniform`
// (keep both in sync with `src/gpu/types.rs`).
#import "common.wgsl"

struct CameraUniform {
    clip_from_world: mat4x4<f32>,
    // xyz: camera right (world), w: interpolation alpha between prev and cur.
    right_alpha: vec4<f32>,
    // xyz: camera up (world), w: unused.
    up: vec4<f32>,
    // xy: target size in pixels, z: pixels per unit of (size / clip w), w: unused.
    viewport: vec4<f32>,
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
    // x: ∫ sprite coverage over the unit quad (for the splat's energy), y: 1 for a
    // stateless emitter, zw: unused.
    extra: vec4<f32>,
    // Stateless emitters: xyz constant acceleration, w linear drag k.
    motion_a: vec4<f32>,
    // Stateless emitters: xyz wind, w render time on the 4096 s clock.
    motion_b: vec4<f32>,
}

override INTERPOLATE: bool = true;

const SPRITE_SOFT_DISC: u32 = 0u;
const SPRITE_POINT: u32 = 1u;
const SPRITE_SPARK: u32 = 2u;

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

// Coverage of the sprite at uv ∈ [-1, 1]² (keep in sync with `sprite_integral` in
// `src/render/billboard.rs`).
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

// Position and age to draw: between the last two steps when interpolating, and only when
// the slot still holds the same particle.
fn draw_state(p: Particle, q: Particle) -> vec4<f32> {
    var pos = p.pos_age.xyz;
    var age = p.pos_age.w;
    if INTERPOLATE {
        if is_alive(q) && q.pos_age.w < p.pos_age.w {
            let a = camera.right_alpha.w;
            pos = mix(q.pos_age.xyz, pos, a);
            age = mix(q.pos_age.w, age, a);
        }
    }
    return vec4<f32>(pos, age);
}

// A particle as drawn: position, age, lifetime, alive.
struct Drawn {
    pos: vec3<f32>,
    age: f32,
    life: f32,
    alive: bool,
}

// The particle in slot state `p` (previous state `q`) as drawn. Stateless emitters store
// spawn records (x0, birth time; v0, lifetime) and are evaluated here in closed form:
// x(t) = x0 + v0·φ + (a + k·wind)·ψ, φ = (1 − e^{−kt})/k, ψ = (t − φ)/k (exact for constant
// acceleration with linear drag, the only forces stateless mode allows).
fn drawn(p: Particle, q: Particle) -> Drawn {
    if look.extra.y > 0.5 {
        let life = p.vel_life.w;
        var age = look.motion_b.w - p.pos_age.w;
        if age < 0.0 {
            age += 4096.0;
        }
        let k = look.motion_a.w;
        let pp = exp_phi_psi(k, age);
        let c = look.motion_a.xyz + k * look.motion_b.xyz;
        let pos = p.pos_age.xyz + p.vel_life.xyz * pp.x + c * pp.y;
        return Drawn(pos, age, life, life > 0.0 && age < life);
    }
    let s = draw_state(p, q);
    return Drawn(s.xyz, s.w, p.vel_life.w, is_alive(p));
}

// Normalised age and billboard size of a drawn state.
fn age_fraction(age: f32, life: f32) -> f32 {
    return clamp(age / life, 0.0, 1.0);
}

fn size_at(t: f32) -> f32 {
    return mix(look.size_intensity.x, look.size_intensity.y, t);
}
