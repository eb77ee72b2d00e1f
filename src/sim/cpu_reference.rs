//! A CPU reference of the update pass: the same hash, the same maths, in Rust f32.
//! Keep in sync with `shaders/update.wgsl`, `spawn.wgsl`, `forces.wgsl`,
//! `integrators.wgsl` and `noise.wgsl`.

use glam::{Mat3, Mat4, Vec3, Vec4};

use crate::effect::Integrator;
use crate::gpu::types::{Particle, SimParams};
use crate::rng;
use crate::sim::planner::mix;

/// A CPU particle pool stepped with exactly the GPU's inputs.
#[derive(Clone, Debug)]
pub struct CpuSim {
    /// The current state, one entry per slot.
    pub particles: Vec<Particle>,
    /// Integration method (the GPU's `INTEGRATOR` constant).
    pub integrator: Integrator,
    /// Particles killed by the non-finite guard.
    pub nonfinite_killed: u64,
}

impl CpuSim {
    /// An empty pool of `capacity` dead slots.
    pub fn new(capacity: u32, integrator: Integrator) -> Self {
        Self {
            particles: vec![Particle::default(); capacity as usize],
            integrator,
            nonfinite_killed: 0,
        }
    }

    /// One step with the block the GPU gets.
    pub fn step(&mut self, params: &SimParams) {
        let cap = params.capacity;
        for slot in 0..cap.min(self.particles.len() as u32) {
            let p = &mut self.particles[slot as usize];
            let rel = (slot + cap - params.spawn_head) % cap;
            if rel < params.spawn_count {
                let index = ((params.spawn_base_hi as u64) << 32 | params.spawn_base_lo as u64)
                    + rel as u64;
                let key = rng::spawn_key(params.seed, params.emitter_salt, slot, index);
                let mut q = spawn_particle(params, key);
                let f = (params.spawn_frac0 + rel as f32 * params.spawn_frac_step).clamp(0.0, 1.0);
                let age0 = (1.0 - f) * params.dt_secs;
                let pos = q.position() + q.velocity() * age0;
                q.pos_age = [pos.x, pos.y, pos.z, age0];
                *p = q;
            } else if p.is_alive() {
                let (x, v) = integrate(
                    self.integrator,
                    params,
                    p.position(),
                    p.velocity(),
                    p.pos_age[3],
                    params.dt_secs,
                );
                let age = p.pos_age[3] + params.dt_secs;
                if x.is_finite() && v.is_finite() {
                    *p = Particle {
                        pos_age: [x.x, x.y, x.z, age],
                        vel_life: [v.x, v.y, v.z, p.vel_life[3]],
                    };
                } else {
                    *p = Particle::default();
                    self.nonfinite_killed += 1;
                }
            }
        }
    }

    /// Number of alive slots.
    pub fn alive(&self) -> usize {
        self.particles.iter().filter(|p| p.is_alive()).count()
    }
}

/// `basis_around` in spawn.wgsl (Duff et al. 2017).
pub fn basis_around(n: Vec3) -> Mat3 {
    let s = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    let t = Vec3::new(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    let bt = Vec3::new(b, s + n.y * n.y * a, -n.y);
    Mat3::from_cols(t, bt, n)
}

/// `cap_direction` in spawn.wgsl.
pub fn cap_direction(axis: Vec3, half: f32, u: f32, v: f32) -> Vec3 {
    let cos_t = 1.0 - u * (1.0 - half.cos());
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let phi = std::f32::consts::TAU * v;
    basis_around(axis) * Vec3::new(phi.cos() * sin_t, phi.sin() * sin_t, cos_t)
}

/// `sample_shape` in spawn.wgsl.
pub fn sample_shape(params: &SimParams, r: [f32; 4]) -> Vec3 {
    let a = Vec4::from(params.shape_a);
    let b = Vec4::from(params.shape_b);
    let tau = std::f32::consts::TAU;
    match params.shape_kind {
        1 => {
            let z = 2.0 * r[0] - 1.0;
            let rho = (1.0 - z * z).max(0.0).sqrt();
            let phi = tau * r[1];
            let dir = Vec3::new(rho * phi.cos(), z, rho * phi.sin());
            let radius = if a.y > 0.5 {
                a.x
            } else {
                a.x * r[2].powf(1.0 / 3.0)
            };
            dir * radius
        }
        2 => {
            let rad = a.x * r[0].sqrt();
            let phi = tau * r[1];
            basis_around(b.truncate()) * Vec3::new(rad * phi.cos(), rad * phi.sin(), 0.0)
        }
        3 => (2.0 * Vec3::new(r[0], r[1], r[2]) - 1.0) * a.truncate(),
        4 => {
            let rad = a.y * r[0].sqrt();
            let phi = tau * r[1];
            let axis = Vec4::from(params.direction_spread).truncate();
            basis_around(axis) * Vec3::new(rad * phi.cos(), rad * phi.sin(), 0.0)
        }
        5 => a.truncate().lerp(b.truncate(), r[0]),
        _ => Vec3::ZERO,
    }
}

fn fade(t: f32) -> f32 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

/// `value_noise3` in noise.wgsl.
pub fn value_noise3(p: Vec3, seed: u32) -> f32 {
    let cell = p.floor();
    let f = p - cell;
    let c = [cell.x as i32, cell.y as i32, cell.z as i32];
    let h = |dx: i32, dy: i32, dz: i32| rng::hash_cell([c[0] + dx, c[1] + dy, c[2] + dz], seed);
    let (ux, uy, uz) = (fade(f.x), fade(f.y), fade(f.z));
    let x00 = mix(h(0, 0, 0), h(1, 0, 0), ux);
    let x10 = mix(h(0, 1, 0), h(1, 1, 0), ux);
    let x01 = mix(h(0, 0, 1), h(1, 0, 1), ux);
    let x11 = mix(h(0, 1, 1), h(1, 1, 1), ux);
    mix(mix(x00, x10, uy), mix(x01, x11, uy), uz)
}

/// `value_noise3_vec` in noise.wgsl.
pub fn value_noise3_vec(p: Vec3, seed: u32) -> Vec3 {
    Vec3::new(
        value_noise3(p, seed),
        value_noise3(p + Vec3::new(31.416, 47.853, 12.793), seed),
        value_noise3(p + Vec3::new(-17.231, 5.117, 63.941), seed),
    ) * 2.0
        - 1.0
}

/// `spawn_particle` in spawn.wgsl (age 0, before the sub-step drift).
pub fn spawn_particle(params: &SimParams, key: [u32; 4]) -> Particle {
    let r0 = rng::unorm4(rng::rand_block(key, 0));
    let r1 = rng::unorm4(rng::rand_block(key, 1));
    let mut local = sample_shape(params, r0);
    let ds = Vec4::from(params.direction_spread);
    let half = if params.shape_kind == 4 {
        params.shape_a[0]
    } else {
        ds.w
    };
    let mut axis = ds.truncate();
    let n = params.noise;
    if n[1] > 0.0 || n[2] > 0.0 {
        let q = local * n[0] + Vec3::new(0.0, 0.0, params.wind_time[3] * n[3]);
        let w = value_noise3_vec(q, params.seed ^ params.emitter_salt);
        local += w * n[1];
        axis = (axis + w * n[2]).normalize();
    }
    let dir = cap_direction(axis, half, r1[0], r1[1]);
    let speed = mix(params.speed_life[0], params.speed_life[1], r1[2]);
    let life = mix(params.speed_life[2], params.speed_life[3], r1[3]);
    let m = Mat4::from_cols_array_2d(&params.world_from_emitter);
    let pos = m.transform_point3(local);
    let vel = m.transform_vector3(dir * speed);
    Particle {
        pos_age: [pos.x, pos.y, pos.z, 0.0],
        vel_life: [vel.x, vel.y, vel.z, life],
    }
}

/// `acceleration` in forces.wgsl.
pub fn acceleration(params: &SimParams, _pos: Vec3, vel: Vec3, _age: f32) -> Vec3 {
    let k = params.accel_drag[3];
    Vec3::from_slice(&params.accel_drag[..3]) - k * (vel - Vec3::from_slice(&params.wind_time[..3]))
}

/// `exp_phi_psi` in integrators.wgsl: phi = (1 − e^{−k dt})/k, psi = (dt − phi)/k.
pub fn exp_phi_psi(k: f32, dt: f32) -> (f32, f32) {
    let z = k * dt;
    if z < 0.5 {
        let phi = dt
            * (1.0
                + z * (-1.0 / 2.0
                    + z * (1.0 / 6.0
                        + z * (-1.0 / 24.0
                            + z * (1.0 / 120.0
                                + z * (-1.0 / 720.0 + z * (1.0 / 5040.0 - z / 40320.0)))))));
        let psi = dt
            * dt
            * (1.0 / 2.0
                + z * (-1.0 / 6.0
                    + z * (1.0 / 24.0
                        + z * (-1.0 / 120.0
                            + z * (1.0 / 720.0
                                + z * (-1.0 / 5040.0 + z * (1.0 / 40320.0 - z / 362880.0)))))));
        return (phi, psi);
    }
    let phi = (1.0 - (-z).exp()) / k;
    (phi, (dt - phi) / k)
}

/// `integrate` in integrators.wgsl.
pub fn integrate(
    method: Integrator,
    params: &SimParams,
    x: Vec3,
    v: Vec3,
    age: f32,
    dt: f32,
) -> (Vec3, Vec3) {
    let acc = |x: Vec3, v: Vec3, age: f32| acceleration(params, x, v, age);
    match method {
        Integrator::ExplicitEuler => {
            let a = acc(x, v, age);
            (x + v * dt, v + a * dt)
        }
        Integrator::SemiImplicitEuler => {
            let v1 = v + acc(x, v, age) * dt;
            (x + v1 * dt, v1)
        }
        Integrator::VelocityVerlet => {
            let a0 = acc(x, v, age);
            let p1 = x + v * dt + 0.5 * a0 * dt * dt;
            let a1 = acc(p1, v + a0 * dt, age + dt);
            (p1, v + 0.5 * (a0 + a1) * dt)
        }
        Integrator::Heun => {
            let a0 = acc(x, v, age);
            let vp = v + a0 * dt;
            let a1 = acc(x + v * dt, vp, age + dt);
            (x + 0.5 * (v + vp) * dt, v + 0.5 * (a0 + a1) * dt)
        }
        Integrator::Rk4 => {
            let h = 0.5 * dt;
            let k1v = acc(x, v, age);
            let k1x = v;
            let k2x = v + h * k1v;
            let k2v = acc(x + h * k1x, k2x, age + h);
            let k3x = v + h * k2v;
            let k3v = acc(x + h * k2x, k3x, age + h);
            let k4x = v + dt * k3v;
            let k4v = acc(x + dt * k3x, k4x, age + dt);
            let s = dt / 6.0;
            (
                x + s * (k1x + 2.0 * k2x + 2.0 * k3x + k4x),
                v + s * (k1v + 2.0 * k2v + 2.0 * k3v + k4v),
            )
        }
        Integrator::Exponential => {
            let k = params.accel_drag[3];
            let f = acc(x, v, age) + k * v;
            let (phi, psi) = exp_phi_psi(k, dt);
            let e = 1.0 - k * phi;
            (x + v * phi + f * psi, v * e + f * phi)
        }
    }
}
