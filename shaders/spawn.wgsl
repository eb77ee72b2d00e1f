// spawn.wgsl — where and how a particle is born. A designer hook.
//
// Contract: `spawn_particle(slot, key)` returns the new particle in world space, with
// age 0 and its own lifetime. `key` is the spawn's random stream (rng.wgsl); draw
// blocks with `rand_block(key, n)` — block 0: shape, 1: direction/speed/lifetime,
// 2: spare for your own use. Everything else comes from `params` (SimParams).
// Mirrored in `src/sim/cpu_reference.rs` (`spawn_particle`).
#import "common.wgsl"
#import "rng.wgsl"
#import "noise.wgsl"

// An orthonormal basis around unit n (Duff et al. 2017, branchless).
fn basis_around(n: vec3<f32>) -> mat3x3<f32> {
    let s = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    let t = vec3<f32>(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    let bt = vec3<f32>(b, s + n.y * n.y * a, -n.y);
    return mat3x3<f32>(t, bt, n);
}

// A direction uniformly distributed in the spherical cap of half-angle `half` around `axis`.
fn cap_direction(axis: vec3<f32>, half: f32, u: f32, v: f32) -> vec3<f32> {
    let cos_t = 1.0 - u * (1.0 - cos(half));
    let sin_t = sqrt(max(0.0, 1.0 - cos_t * cos_t));
    let phi = TAU * v;
    let m = basis_around(axis);
    return m * vec3<f32>(cos(phi) * sin_t, sin(phi) * sin_t, cos_t);
}

// A point on the emitter shape, in emitter space.
fn sample_shape(r: vec4<f32>) -> vec3<f32> {
    let a = params.shape_a;
    let b = params.shape_b;
    switch params.shape_kind {
        case SHAPE_SPHERE: {
            // a.x = radius, a.y = 1 for surface only.
            let z = 2.0 * r.x - 1.0;
            let rho = sqrt(max(0.0, 1.0 - z * z));
            let phi = TAU * r.y;
            let dir = vec3<f32>(rho * cos(phi), z, rho * sin(phi));
            let radius = select(a.x * pow(r.z, 1.0 / 3.0), a.x, a.y > 0.5);
            return dir * radius;
        }
        case SHAPE_DISC: {
            // a.x = radius, b.xyz = unit normal.
            let rad = a.x * sqrt(r.x);
            let phi = TAU * r.y;
            let m = basis_around(b.xyz);
            return m * vec3<f32>(rad * cos(phi), rad * sin(phi), 0.0);
        }
        case SHAPE_BOX: {
            // a.xyz = half extents.
            return (2.0 * r.xyz - 1.0) * a.xyz;
        }
        case SHAPE_CONE: {
            // a.y = base radius; base disc is normal to the emitter direction.
            let rad = a.y * sqrt(r.x);
            let phi = TAU * r.y;
            let m = basis_around(params.direction_spread.xyz);
            return m * vec3<f32>(rad * cos(phi), rad * sin(phi), 0.0);
        }
        case SHAPE_LINE: {
            // a.xyz, b.xyz = endpoints.
            return mix(a.xyz, b.xyz, r.x);
        }
        default: {
            return vec3<f32>(0.0);
        }
    }
}

fn spawn_particle(slot: u32, key: vec4<u32>) -> Particle {
    let r0 = unorm4(rand_block(key, 0u));
    let r1 = unorm4(rand_block(key, 1u));
    var local_pos = sample_shape(r0);

    // The spread: a cone's own angle replaces `spread_deg`.
    var half = params.direction_spread.w;
    if params.shape_kind == SHAPE_CONE {
        half = params.shape_a.x;
    }
    var axis = params.direction_spread.xyz;

    // Noise-based seeding: a smooth, seeded field scrolling in time tilts the direction
    // and nudges the position, so the flame flickers coherently.
    let n = params.noise;
    if n.y > 0.0 || n.z > 0.0 {
        let q = local_pos * n.x + vec3<f32>(0.0, 0.0, params.wind_time.w * n.w);
        let w = value_noise3_vec(q, params.seed ^ params.emitter_salt);
        local_pos += w * n.y;
        axis = normalize(axis + w * n.z);
    }

    let dir = cap_direction(axis, half, r1.x, r1.y);
    let speed = mix(params.speed_life.x, params.speed_life.y, r1.z);
    // (= mix(life min, life max, r1.w); the packed state re-derives it the same way.)
    let life = spawn_life(key, params.speed_life.z, params.speed_life.w);

    let world_pos = (params.world_from_emitter * vec4<f32>(local_pos, 1.0)).xyz;
    let world_vel = (params.world_from_emitter * vec4<f32>(dir * speed, 0.0)).xyz;
    return Particle(vec4<f32>(world_pos, 0.0), vec4<f32>(world_vel, life));
}
