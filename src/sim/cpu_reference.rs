//! A CPU reference of the update pass: the same hash, the same maths, in Rust f32.
//! Keep in sync with `shaders/update.wgsl`, `spawn.wgsl`, `forces.wgsl`,
//! `integrators.wgsl` and `noise.wgsl`.

use glam::{DVec3, Mat3, Mat4, Vec3, Vec4};

use crate::effect::{Emitter, Integrator};
use crate::gpu::types::{Particle, SimParams};
use crate::rng;
use crate::sim::modules::Modules;
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
    /// Modules compiled in (the GPU's `MOD_*` constants).
    pub modules: Modules,
    /// The over-life curves baked (rows A and B; read with `Modules::CURVES`).
    pub over_life: [Vec<[f32; 4]>; 2],
}

/// A particle's over-life multipliers for a step (`over_life_at` in update.wgsl): the
/// baked rows at normalised age `t`, blended by the particle's random numbers.
pub fn over_life_at(
    rows: &[Vec<[f32; 4]>; 2],
    t: f32,
    params: &SimParams,
    slot: u32,
    life: f32,
) -> [f32; 4] {
    let u = rng::unorm4(rng::pcg4d([
        slot,
        life.to_bits(),
        params.emitter_salt,
        params.seed ^ 0x5C0,
    ]));
    crate::effect::lookup_blend(rows, t, u)
}

impl CpuSim {
    /// An empty pool of `capacity` dead slots.
    pub fn new(capacity: u32, integrator: Integrator) -> Self {
        Self {
            particles: vec![Particle::default(); capacity as usize],
            integrator,
            nonfinite_killed: 0,
            modules: Modules::DRAG,
            over_life: [Vec::new(), Vec::new()],
        }
    }

    /// A pool configured like the GPU pipeline for emitter `e`.
    pub fn for_emitter(e: &Emitter) -> Self {
        Self {
            modules: Modules::of(e),
            over_life: crate::sim::modules::bake_over_life(e),
            ..Self::new(e.capacity, e.integrator)
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
                let curves = self.modules.contains(Modules::CURVES);
                let forces = Forces {
                    params,
                    modules: self.modules,
                    over_life: if curves {
                        over_life_at(&self.over_life, 0.0, params, slot, q.vel_life[3])
                    } else {
                        [1.0; 4]
                    },
                };
                let k = forces.linear_drag_k() as f32;
                let (phi, psi) = exp_phi_psi(k, age0);
                let c = Vec3::from_slice(&params.accel_drag[..3])
                    + k * Vec3::from_slice(&params.wind_time[..3]);
                let v0 = q.velocity();
                let x = if curves {
                    q.position() + (v0 * phi + c * psi) * forces.over_life[0]
                } else {
                    q.position() + v0 * phi + c * psi
                };
                let v = v0 * (1.0 - k * phi) + c * phi;
                q.pos_age = [x.x, x.y, x.z, age0];
                q.vel_life = [v.x, v.y, v.z, q.vel_life[3]];
                *p = q;
            } else if p.is_alive() {
                let life = p.vel_life[3];
                let curves = self.modules.contains(Modules::CURVES);
                let forces = Forces {
                    params,
                    modules: self.modules,
                    over_life: if curves {
                        over_life_at(&self.over_life, p.pos_age[3] / life, params, slot, life)
                    } else {
                        [1.0; 4]
                    },
                };
                let (mut x, mut v) = integrate(
                    self.integrator,
                    &forces,
                    p.position(),
                    p.velocity(),
                    p.pos_age[3],
                    life,
                    params.wind_time[3],
                    params.dt_secs,
                );
                if curves {
                    x = p.position() + (x - p.position()) * forces.over_life[0];
                }
                let mut age = p.pos_age[3] + params.dt_secs;
                if self.modules.contains(Modules::COLLISIONS) {
                    let c = collide(params, p.position(), x, v);
                    x = c.0;
                    v = c.1;
                    if c.2 {
                        age = life;
                    }
                }
                if x.is_finite() && v.is_finite() {
                    *p = Particle {
                        pos_age: [x.x, x.y, x.z, age],
                        vel_life: [v.x, v.y, v.z, life],
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

/// The trilinear form's coefficients from a cell's eight corner values `h(dx, dy, dz)`:
/// `[k0, …, k7]` with value = k0 + k1·u + k2·v + k3·w + k4·uv + k5·vw + k6·wu + k7·uvw, in
/// the operations and order `value_noise3` and `curl_octave` (noise.wgsl) use.
fn trilinear<T>(h: impl Fn(i32, i32, i32) -> T) -> [T; 8]
where
    T: Copy + std::ops::Add<Output = T> + std::ops::Sub<Output = T> + std::ops::Neg<Output = T>,
{
    let (a, b, cc, d) = (h(0, 0, 0), h(1, 0, 0), h(0, 1, 0), h(1, 1, 0));
    let (e, ff, g, hh) = (h(0, 0, 1), h(1, 0, 1), h(0, 1, 1), h(1, 1, 1));
    [
        a,
        b - a,
        cc - a,
        e - a,
        a - b - cc + d,
        a - cc - e + g,
        a - b - e + ff,
        -a + b + cc - d + e - ff - g + hh,
    ]
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
    // The same polynomial form as `value_noise3` in noise.wgsl, in f32.
    let [a, k1, k2, k3, k4, k5, k6, k7] = trilinear(h);
    a + k1 * ux + k2 * uy + k3 * uz + k4 * ux * uy + k5 * uy * uz + k6 * uz * ux + k7 * ux * uy * uz
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

/// The force model of forces.wgsl for one step's parameters and module set, evaluated in
/// f64 (the f32 reference rounds the result; the accuracy bench uses it as is).
pub struct Forces<'a> {
    /// The step's parameter block.
    pub params: &'a SimParams,
    /// Modules compiled in.
    pub modules: Modules,
    /// The particle's over-life multipliers for the step: x speed (applied by the caller
    /// to the step's displacement), y both drags, z turbulence, w flame pull.
    pub over_life: [f32; 4],
}

fn d3(v: [f32; 4]) -> DVec3 {
    DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64)
}

impl Forces<'_> {
    /// The linear drag rate k the exponential integrator uses.
    pub fn linear_drag_k(&self) -> f64 {
        if self.modules.contains(Modules::DRAG) {
            (self.params.accel_drag[3] * self.over_life[1]) as f64
        } else {
            0.0
        }
    }

    /// `acceleration` in forces.wgsl, in f64.
    pub fn acceleration(&self, pos: DVec3, vel: DVec3, age: f64, life: f64, time: f64) -> DVec3 {
        let p = self.params;
        let m = self.modules;
        let mut a = d3(p.accel_drag);
        let mut wind = d3(p.wind_time);
        if m.contains(Modules::GUSTS) {
            let g = p.gusts_qdrag_pull;
            let n = value_noise3_f64(DVec3::new(time * g[1] as f64, 0.5, 0.5), p.seed ^ 0x6057)
                * 2.0
                - 1.0;
            wind *= 1.0 + g[0] as f64 * n;
        }
        let s = self.over_life.map(f64::from);
        if m.contains(Modules::DRAG) {
            a -= p.accel_drag[3] as f64 * s[1] * (vel - wind);
        }
        if m.contains(Modules::QUADRATIC_DRAG) {
            let rel = vel - wind;
            a -= p.gusts_qdrag_pull[2] as f64 * s[1] * rel.length() * rel;
        }
        if m.contains(Modules::TURBULENCE) {
            let t = p.turbulence;
            let q = (pos - DVec3::new(0.0, t[3] as f64 * time, 0.0)) * t[1] as f64;
            a += t[0] as f64 * curl_noise(q, p.seed ^ p.emitter_salt, t[2] as u32) / 1.5 * s[2];
        }
        if m.contains(Modules::VORTEX) {
            let axis = d3(p.vortex_axis);
            let r = pos - d3(p.vortex_center);
            let radial = r - axis * r.dot(axis);
            let d = radial.length();
            if d >= 1e-6 {
                let rr = p.vortex_center[3] as f64;
                let falloff = (-(d * d) / (rr * rr).max(1e-6)).exp();
                a += p.vortex_axis[3] as f64 * falloff * axis.cross(radial / d);
            }
        }
        if m.contains(Modules::ATTRACTOR) {
            let to = d3(p.attractor) - pos;
            let r2 = to.length_squared();
            let radius = p.attractor_b[0] as f64;
            let s = p.attractor[3] as f64;
            if p.attractor_b[1] > 0.5 {
                if r2 <= radius * radius && r2 >= 1e-12 {
                    a += s * to / r2.sqrt();
                }
            } else {
                let soft = r2 + radius * radius;
                a += s * to / (soft * soft.sqrt());
            }
        }
        if m.contains(Modules::FLAME_PULL) {
            let r = pos - d3(p.axis_origin);
            let axis = d3(p.axis_dir);
            let radial = r - axis * r.dot(axis);
            let t = (age / life.max(1e-6)).clamp(0.0, 1.0);
            a -= p.gusts_qdrag_pull[3] as f64 * t.powf(p.attractor_b[2] as f64) * radial * s[3];
        }
        a
    }

    fn acc32(&self, x: Vec3, v: Vec3, age: f32, life: f32, time: f32) -> Vec3 {
        self.acceleration(
            x.as_dvec3(),
            v.as_dvec3(),
            age as f64,
            life as f64,
            time as f64,
        )
        .as_vec3()
    }
}

/// `value_noise3` in noise.wgsl, in f64.
pub fn value_noise3_f64(p: DVec3, seed: u32) -> f64 {
    let cell = p.floor();
    let f = p - cell;
    let c = [cell.x as i32, cell.y as i32, cell.z as i32];
    let h =
        |dx: i32, dy: i32, dz: i32| rng::hash_cell([c[0] + dx, c[1] + dy, c[2] + dz], seed) as f64;
    let u = DVec3::new(fade64(f.x), fade64(f.y), fade64(f.z));
    let [a, k1, k2, k3, k4, k5, k6, k7] = trilinear(h);
    a + k1 * u.x
        + k2 * u.y
        + k3 * u.z
        + k4 * u.x * u.y
        + k5 * u.y * u.z
        + k6 * u.z * u.x
        + k7 * u.x * u.y * u.z
}

fn fade64(t: f64) -> f64 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

fn fade64_deriv(t: f64) -> f64 {
    30.0 * t * t * (t * (t - 2.0) + 1.0)
}

/// `curl_octave` in noise.wgsl, in f64: the curl of a vector potential whose three
/// channels are value noise on one lattice (`rng::hash_cell3`).
fn curl_octave(p: DVec3, seed: u32) -> DVec3 {
    let cell = p.floor();
    let f = p - cell;
    let c = [cell.x as i32, cell.y as i32, cell.z as i32];
    let h = |dx: i32, dy: i32, dz: i32| {
        DVec3::from(rng::hash_cell3([c[0] + dx, c[1] + dy, c[2] + dz], seed).map(f64::from))
    };
    let u = DVec3::new(fade64(f.x), fade64(f.y), fade64(f.z));
    let du = DVec3::new(fade64_deriv(f.x), fade64_deriv(f.y), fade64_deriv(f.z));
    let [_, k1, k2, k3, k4, k5, k6, k7] = trilinear(h);
    let dx = du.x * (k1 + k4 * u.y + k6 * u.z + k7 * u.y * u.z);
    let dy = du.y * (k2 + k4 * u.x + k5 * u.z + k7 * u.x * u.z);
    let dz = du.z * (k3 + k5 * u.y + k6 * u.x + k7 * u.x * u.y);
    DVec3::new(dy.z - dz.y, dz.x - dx.z, dx.y - dy.x)
}

/// `curl_noise` in noise.wgsl, in f64.
pub fn curl_noise(p: DVec3, seed: u32, octaves: u32) -> DVec3 {
    let mut sum = DVec3::ZERO;
    let mut freq = 1.0;
    let mut amp = 1.0;
    for o in 0..octaves {
        sum += amp * freq * curl_octave(p * freq, seed.wrapping_add(o));
        freq *= 2.0;
        amp *= 0.5;
    }
    sum
}

/// `collide` in collide.wgsl: (position, velocity, killed).
pub fn collide(params: &SimParams, old: Vec3, pos_in: Vec3, vel_in: Vec3) -> (Vec3, Vec3, bool) {
    let bounce = |vel: Vec3, n: Vec3| -> Vec3 {
        if params.collide_c[0] > 0.5 {
            return Vec3::ZERO;
        }
        let vn = vel.dot(n);
        if vn >= 0.0 {
            return vel;
        }
        let tangent = (vel - vn * n) * (1.0 - params.ground[2]).max(0.0);
        let mut out_n = -vn * params.ground[1];
        if out_n < params.collide_b[0] {
            out_n = 0.0;
        }
        tangent + out_n * n
    };
    let (mut pos, mut vel) = (pos_in, vel_in);
    let count = (params.collide_b[1] as u32).min(4);
    for s in &params.spheres[..count as usize] {
        let center = Vec3::new(s[0], s[1], s[2]);
        let d = pos - old;
        let f = old - center;
        let r2 = s[3] * s[3];
        let a = d.dot(d);
        let b = f.dot(d);
        let c = f.dot(f) - r2;
        let mut hit = (pos - center).length_squared() < r2;
        let mut t_hit = 1.0;
        if a > 1e-12 && c > 0.0 {
            let disc = b * b - a * c;
            if disc >= 0.0 {
                let t = (-b - disc.sqrt()) / a;
                if (0.0..=1.0).contains(&t) {
                    hit = true;
                    t_hit = t;
                }
            }
        }
        if hit {
            if params.collide_b[2] > 0.5 {
                return (pos, vel, true);
            }
            let contact = if c > 0.0 { old + d * t_hit } else { pos };
            let n = contact - center;
            let len = n.length();
            let n = if len > 1e-6 { n / len } else { Vec3::Y };
            pos = center + n * (s[3] * 1.0001);
            vel = bounce(vel, n);
        }
    }
    if params.collide_b[3] > 0.5 && pos.y < params.ground[0] {
        if params.ground[3] > 0.5 {
            return (pos, vel, true);
        }
        pos.y = params.ground[0];
        vel = bounce(vel, Vec3::Y);
    }
    (pos, vel, false)
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

/// `integrate` in integrators.wgsl (f32 state, forces evaluated as the GPU does).
#[allow(clippy::too_many_arguments)]
pub fn integrate(
    method: Integrator,
    forces: &Forces<'_>,
    x: Vec3,
    v: Vec3,
    age: f32,
    life: f32,
    time: f32,
    dt: f32,
) -> (Vec3, Vec3) {
    // Ages and times advance together within a step, as in the shader.
    let acc = |x: Vec3, v: Vec3, a: f32| forces.acc32(x, v, a, life, time + (a - age));
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
            let k = forces.linear_drag_k() as f32;
            let f = acc(x, v, age) + k * v;
            let (phi, psi) = exp_phi_psi(k, dt);
            let e = 1.0 - k * phi;
            (x + v * phi + f * psi, v * e + f * phi)
        }
    }
}

/// A stateless emitter's spawn record evaluated at `now` (seconds on the 4096 s clock),
/// as `drawn` in look.wgsl does: the particle's current position, age and velocity.
pub fn evaluate_stateless(record: &Particle, e: &Emitter, now: f32) -> Particle {
    let life = record.vel_life[3];
    let mut age = now - record.pos_age[3];
    if age < 0.0 {
        age += 4096.0;
    }
    let k = e.forces.drag_per_sec;
    let (phi, psi) = exp_phi_psi(k, age);
    let c = e.forces.constant_acceleration() + k * Vec3::from(e.forces.wind_m_per_s);
    let x = record.position() + record.velocity() * phi + c * psi;
    // v(t) = v0·e^{−kt} + c·φ, with e^{−kt} = 1 − k·φ.
    let v = record.velocity() * (1.0 - k * phi) + c * phi;
    let alive_age = if life > 0.0 && age < life { age } else { life };
    Particle {
        pos_age: [x.x, x.y, x.z, alive_age],
        vel_life: [v.x, v.y, v.z, life],
    }
}
