// forces.wgsl — the acceleration acting on an alive particle. A designer hook.
//
// Contract: `acceleration(pos, vel, age_secs)` returns the acceleration in m/s² at world
// position `pos` (m) with velocity `vel` (m/s) for a particle of age `age_secs`. It must
// be a pure function: integrators call it 1 (Euler) to 4 (RK4) times per step with
// predicted states. `params` (SimParams) holds the preset's values. Return
// `vec3<f32>(0.0)` to switch every force off.
//
// The exponential integrator assumes the drag part is `-k (vel - wind)` with
// k = params.accel_drag.w and treats the rest (`acceleration + k·vel`) as constant over
// a step; it is exact when that rest is constant.
#import "common.wgsl"

fn acceleration(pos: vec3<f32>, vel: vec3<f32>, age_secs: f32) -> vec3<f32> {
    let k = params.accel_drag.w;
    return params.accel_drag.xyz - k * (vel - params.wind_time.xyz);
}
