// integrators.wgsl — one step of the chosen method for (pos, vel) over dt.
//
// Contract: `integrate(pos, vel, age, life, time, dt)` returns the new (pos, vel) as a
// `State`. `INTEGRATOR` is a pipeline override constant, so
// the branch is resolved when the pipeline is built and an unused method costs nothing.
// Keep the indices in sync with `Integrator::index` in `src/effect.rs`.
#import "common.wgsl"
#import "forces.wgsl"

override INTEGRATOR: u32 = 1u;

const INTEGRATOR_EXPLICIT_EULER: u32 = 0u;
const INTEGRATOR_SEMI_IMPLICIT_EULER: u32 = 1u;
const INTEGRATOR_VELOCITY_VERLET: u32 = 2u;
const INTEGRATOR_HEUN: u32 = 3u;
const INTEGRATOR_RK4: u32 = 4u;
const INTEGRATOR_EXPONENTIAL: u32 = 5u;

struct State {
    pos: vec3<f32>,
    vel: vec3<f32>,
}

fn integrate(pos: vec3<f32>, vel: vec3<f32>, age: f32, life: f32, time: f32, dt: f32) -> State {
    switch INTEGRATOR {
        case INTEGRATOR_EXPLICIT_EULER: {
            let a = acceleration(pos, vel, age, life, time);
            return State(pos + vel * dt, vel + a * dt);
        }
        case INTEGRATOR_VELOCITY_VERLET: {
            let a0 = acceleration(pos, vel, age, life, time);
            let p1 = pos + vel * dt + 0.5 * a0 * dt * dt;
            let a1 = acceleration(p1, vel + a0 * dt, age + dt, life, time + dt);
            return State(p1, vel + 0.5 * (a0 + a1) * dt);
        }
        case INTEGRATOR_HEUN: {
            let a0 = acceleration(pos, vel, age, life, time);
            let vp = vel + a0 * dt;
            let a1 = acceleration(pos + vel * dt, vp, age + dt, life, time + dt);
            return State(pos + 0.5 * (vel + vp) * dt, vel + 0.5 * (a0 + a1) * dt);
        }
        case INTEGRATOR_RK4: {
            let h = 0.5 * dt;
            let k1v = acceleration(pos, vel, age, life, time);
            let k1x = vel;
            let k2x = vel + h * k1v;
            let k2v = acceleration(pos + h * k1x, k2x, age + h, life, time + h);
            let k3x = vel + h * k2v;
            let k3v = acceleration(pos + h * k2x, k3x, age + h, life, time + h);
            let k4x = vel + dt * k3v;
            let k4v = acceleration(pos + dt * k3x, k4x, age + dt, life, time + dt);
            let s = dt / 6.0;
            return State(pos + s * (k1x + 2.0 * k2x + 2.0 * k3x + k4x),
                         vel + s * (k1v + 2.0 * k2v + 2.0 * k3v + k4v));
        }
        case INTEGRATOR_EXPONENTIAL: {
            // v' = f - k v with f = a + k v held constant over the step.
            let k = linear_drag_k();
            let f = acceleration(pos, vel, age, life, time) + k * vel;
            let pp = exp_phi_psi(k, dt);
            let e = 1.0 - k * pp.x;
            return State(pos + vel * pp.x + f * pp.y, vel * e + f * pp.x);
        }
        default: {
            // Semi-implicit (symplectic) Euler.
            let a = acceleration(pos, vel, age, life, time);
            let v1 = vel + a * dt;
            return State(pos + v1 * dt, v1);
        }
    }
}
