// forces.wgsl — the acceleration acting on an alive particle. A designer hook.
//
// Contract: `acceleration(pos, vel, age, life, time)` returns the acceleration in m/s² of
// a particle at world position `pos` (m) with velocity `vel` (m/s), age and lifetime in
// seconds, at simulated time `time` (s, wrapped every 4096 s). It must be a pure function:
// integrators call it 1 (Euler) to 4 (RK4) times per step with predicted states. `params`
// (SimParams) holds the preset's values. Return `vec3<f32>(0.0)` to switch every force off.
// On tiny state (state_tiny.wgsl) `life` is exact only where the flame pull is on or the
// particle is within a step of the lifetime range's minimum; elsewhere it is 3.4e38 (the
// lifetime hash is skipped) — a force that reads `life` should be a module like the pull.
//
// Modules are pipeline override constants: a module that is off is resolved away when
// the pipeline is built and costs nothing. Keep `MOD_*` in sync with `Modules` in
// `src/sim/modules.rs`.
//
// `over_life` (update.wgsl) holds the particle's over-life multipliers for this step: y
// scales both drags, z the turbulence, w the flame pull (1 when the emitter has none).
//
// The exponential integrator assumes the drag part is `-k (vel - wind)` with
// k = `linear_drag_k()` and treats the rest (`acceleration + k·vel`) as constant over a
// step; it is exact when that rest is constant.
#import "common.wgsl"
#import "noise.wgsl"

override MOD_DRAG: bool = true;
override MOD_GUSTS: bool = false;
override MOD_QUADRATIC_DRAG: bool = false;
override MOD_TURBULENCE: bool = false;
override MOD_VORTEX: bool = false;
override MOD_ATTRACTOR: bool = false;
override MOD_FLAME_PULL: bool = false;

fn linear_drag_k() -> f32 {
    return select(0.0, params.accel_drag.w * over_life.y, MOD_DRAG);
}

// Wind, optionally modulated by smooth 1-D noise in time (gusts).
fn wind_at(time: f32) -> vec3<f32> {
    var wind = params.wind_time.xyz;
    // module-begin (lines up to module-end are removed for the bench's bare pipeline)
    if MOD_GUSTS {
        let g = params.gusts_qdrag_pull;
        let n = value_noise3(vec3<f32>(time * g.y, 0.5, 0.5), params.seed ^ 0x6057u) * 2.0 - 1.0;
        wind = wind * (1.0 + g.x * n);
    }
    // module-end
    return wind;
}

// Curl-noise turbulence: divergence-free, seeded, scrolling upward in time.
fn turbulence_accel(pos: vec3<f32>, time: f32) -> vec3<f32> {
    let t = params.turbulence;
    let p = (pos - vec3<f32>(0.0, t.w * time, 0.0)) * t.y;
    // The curl carries a factor of the frequency; divide it out so `strength` is m/s².
    return t.x * curl_noise(p, params.seed ^ params.emitter_salt, u32(t.z)) / 1.5;
}

// Swirl around an axis: tangential acceleration with a Gaussian falloff in distance.
fn vortex_accel(pos: vec3<f32>) -> vec3<f32> {
    let axis = params.vortex_axis.xyz;
    let r = pos - params.vortex_center.xyz;
    let radial = r - axis * dot(r, axis);
    let d = length(radial);
    if d < 1e-6 {
        return vec3<f32>(0.0);
    }
    let falloff = exp(-(d * d) / max(1e-6, params.vortex_center.w * params.vortex_center.w));
    return params.vortex_axis.w * falloff * cross(axis, radial / d);
}

// Latta's two falloffs. Inverse square with Plummer softening ε = radius:
// a = s·d / (|d|² + ε²)^{3/2} (s in m³/s², like G·M); or a constant |a| = s (m/s²) within
// the radius and zero outside. Negative s repels.
fn attractor_accel(pos: vec3<f32>) -> vec3<f32> {
    let to = params.attractor.xyz - pos;
    let r2 = dot(to, to);
    let radius = params.attractor_b.x;
    if params.attractor_b.y > 0.5 {
        if r2 > radius * radius || r2 < 1e-12 {
            return vec3<f32>(0.0);
        }
        return params.attractor.w * to * inverseSqrt(r2);
    }
    let soft = r2 + radius * radius;
    return params.attractor.w * to / (soft * sqrt(soft));
}

// Pull toward the emitter axis that grows with normalised age, so flames taper to a tip.
fn flame_pull_accel(pos: vec3<f32>, age: f32, life: f32) -> vec3<f32> {
    let r = pos - params.axis_origin.xyz;
    let axis = params.axis_dir.xyz;
    let radial = r - axis * dot(r, axis);
    let t = clamp(age / max(life, 1e-6), 0.0, 1.0);
    return -params.gusts_qdrag_pull.w * pow(t, params.attractor_b.z) * radial;
}

fn acceleration(pos: vec3<f32>, vel: vec3<f32>, age: f32, life: f32, time: f32) -> vec3<f32> {
    var a = params.accel_drag.xyz;
    let wind = wind_at(time);
    if MOD_DRAG {
        a -= params.accel_drag.w * over_life.y * (vel - wind);
    }
    // module-begin
    if MOD_QUADRATIC_DRAG {
        let rel = vel - wind;
        a -= params.gusts_qdrag_pull.z * over_life.y * length(rel) * rel;
    }
    if MOD_TURBULENCE {
        a += turbulence_accel(pos, time) * over_life.z;
    }
    if MOD_VORTEX {
        a += vortex_accel(pos);
    }
    if MOD_ATTRACTOR {
        a += attractor_accel(pos);
    }
    if MOD_FLAME_PULL {
        a += flame_pull_accel(pos, age, life) * over_life.w;
    }
    // module-end
    return a;
}
