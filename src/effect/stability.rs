//! Numerical stability at the extremes, from the settings alone (on the CPU): each
//! emitter's stiffest terms linearised into the test problem `x'' = −ω²·x − k·x'` — linear
//! and quadratic drag give the damping rate `k`; the flame pull, an attracting point, a
//! vortex and turbulence give the spring `ω²` — and each integrator's one-step map of that
//! problem (the formulas of `shaders/integrators.wgsl`) tells how much an error grows over
//! a particle's longest life. An emitter is **unstable** when that growth exceeds
//! [`GROWTH_LIMIT`]: its particles visibly blow up (or jitter) within their lives.
//!
//! The warning names the dominant field and the largest step that would be stable; the
//! editor shows it as the edit is made and `ignis check` prints it.

use super::{Attractor, Effect, Emitter, Falloff, Integrator, TimeMode};

/// An emitter is unstable when an error may grow by more than this over the longest
/// lifetime of its particles.
pub const GROWTH_LIMIT: f64 = 2.0;

/// The linearised stiffness of an emitter: the test problem `x'' = −ω²·x − k·x'`.
#[derive(Clone, Debug, PartialEq)]
pub struct Stiffness {
    /// The damping rate k, 1/s (linear drag, and quadratic drag linearised at the
    /// emitter's fastest speed).
    pub damping_per_sec: f64,
    /// The spring ω², 1/s² (flame pull, attractor, vortex, turbulence).
    pub spring_per_s2: f64,
    /// The field that contributes most, as a path under the emitter (`forces.drag_per_sec`).
    pub dominant_field: &'static str,
}

/// An emitter that is unstable at its step.
#[derive(Clone, Debug, PartialEq)]
pub struct StabilityWarning {
    /// The emitter's index.
    pub emitter: usize,
    /// The field that contributes most to the stiffness, with its path
    /// (`emitters[2].forces.drag_per_sec`).
    pub field: String,
    /// The integrator.
    pub integrator: Integrator,
    /// The step it was checked at, seconds.
    pub step_secs: f64,
    /// How much an error grows over the emitter's longest lifetime at that step.
    pub growth: f64,
    /// The largest step that is stable with this integrator (`None`: none is, e.g.
    /// repelling forces that any method follows apart).
    pub stable_step_secs: Option<f64>,
}

impl std::fmt::Display for StabilityWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}: {} is unstable at a {} step (an error grows {:.3e}× over a particle's life)",
            self.field,
            self.integrator.label(),
            secs_label(self.step_secs),
            self.growth
        )?;
        match self.stable_step_secs {
            Some(s) => write!(
                f,
                "; a step of at most {} is stable, or lower the value, or use the exponential \
                    integrator",
                secs_label(s)
            ),
            None => write!(f, "; lower the value"),
        }
    }
}

/// A step for people: `1/120 s` where it is one, else seconds.
fn secs_label(s: f64) -> String {
    let per = 1.0 / s;
    if (per - per.round()).abs() < 1e-3 * per {
        format!("1/{} s", per.round())
    } else {
        format!("{s:.5} s (1/{per:.0} s)")
    }
}

impl Emitter {
    /// The linearised stiffness of this emitter's forces.
    pub fn stiffness(&self) -> Stiffness {
        let f = &self.forces;
        let drag_life = f64::from(f.drag_over_life.bounds().1.max(0.0));
        let linear = f64::from(f.drag_per_sec.max(0.0)) * drag_life;
        let wind = glam::Vec3::from(f.wind_m_per_s).length()
            * (1.0 + f.gusts.as_ref().map_or(0.0, |g| g.strength.abs()));
        let speed = f64::from(self.speed_m_per_s.max.abs() + wind);
        // d/dv of c·|v|·v is 2c|v|.
        let quadratic = 2.0 * f64::from(f.quadratic_drag_per_m.max(0.0)) * speed * drag_life;
        let springs = [
            (
                "forces.flame_pull.strength_per_s2",
                f.flame_pull.as_ref().map_or(0.0, |p| {
                    f64::from(p.strength_per_s2.max(0.0))
                        * f64::from(p.over_life.bounds().1.max(0.0))
                }),
            ),
            (
                "forces.attractor.strength",
                f.attractor.as_ref().map_or(0.0, attractor_spring),
            ),
            (
                "forces.vortex.swirl_m_per_s2",
                f.vortex.as_ref().map_or(0.0, |v| {
                    f64::from(v.swirl_m_per_s2.abs()) / f64::from(v.radius_m.max(1e-3))
                }),
            ),
            (
                "forces.turbulence.strength_m_per_s2",
                // A curl-noise field's gradient: strength × frequency, each octave the
                // same (twice the frequency, half the amplitude).
                f.turbulence.as_ref().map_or(0.0, |t| {
                    f64::from(t.strength_m_per_s2.abs())
                        * f64::from(t.frequency_per_m.abs())
                        * f64::from(t.octaves.max(1))
                        * f64::from(t.over_life.bounds().1.max(0.0))
                }),
            ),
        ];
        let spring: f64 = springs.iter().map(|s| s.1).sum();
        let (spring_field, strongest) = springs
            .iter()
            .copied()
            .fold(("", 0.0), |a, s| if s.1 > a.1 { s } else { a });
        let damping = linear + quadratic;
        // Which term sets the step: compare the rates they impose (k against ω).
        let dominant_field = if strongest.sqrt() > damping / 2.0 {
            spring_field
        } else if quadratic > linear {
            "forces.quadratic_drag_per_m"
        } else {
            "forces.drag_per_sec"
        };
        Stiffness {
            damping_per_sec: damping,
            spring_per_s2: spring,
            dominant_field,
        }
    }

    /// How much an error grows over this emitter's longest lifetime at steps of
    /// `step_secs` with its integrator (1 or less: it decays).
    pub fn growth_at(&self, step_secs: f64) -> f64 {
        let s = self.stiffness();
        lifetime_growth(
            self.integrator,
            s.spring_per_s2,
            s.damping_per_sec,
            step_secs,
            f64::from(self.lifetime_secs.max),
        )
    }
}

/// The spring of an attractor: an attracting inverse-square point's pull near its centre
/// (s/ε³, Plummer-softened); a constant pull within a radius has no linear part.
fn attractor_spring(a: &Attractor) -> f64 {
    match a.falloff {
        Falloff::InverseSquare if a.strength > 0.0 => {
            f64::from(a.strength) / f64::from(a.radius_m.max(1e-3)).powi(3)
        }
        _ => 0.0,
    }
}

impl Effect {
    /// The emitters that are unstable at the effect's step (the fixed step, or in
    /// frame-delta mode its largest step), each with the field to change and the step
    /// that would be stable. Stateless emitters are exact and never listed.
    pub fn stability_warnings(&self) -> Vec<StabilityWarning> {
        let step = f64::from(match self.time.mode {
            TimeMode::FixedStep => self.time.step_secs,
            TimeMode::FrameDelta => self.time.max_frame_dt_secs,
        });
        self.emitters
            .iter()
            .enumerate()
            .filter(|(_, e)| e.enabled && !e.stateless)
            .filter_map(|(i, e)| {
                let growth = e.growth_at(step);
                (growth > GROWTH_LIMIT).then(|| StabilityWarning {
                    emitter: i,
                    field: format!("emitters[{i}].{}", e.stiffness().dominant_field),
                    integrator: e.integrator,
                    step_secs: step,
                    growth,
                    stable_step_secs: largest_stable_step(e),
                })
            })
            .collect()
    }
}

/// The largest step at which `e` is stable (growth ≤ [`GROWTH_LIMIT`] over its life):
/// scanned down from 1 s on a fine logarithmic grid, then bisected.
pub fn largest_stable_step(e: &Emitter) -> Option<f64> {
    let stable = |dt: f64| e.growth_at(dt) <= GROWTH_LIMIT;
    let grid = |k: u32| 10f64.powf(-(f64::from(k) / 100.0));
    // The first stable step of the grid from 1 s down to 10 µs.
    let k = (0..=500).find(|&k| stable(grid(k)))?;
    if k == 0 {
        return Some(1.0);
    }
    let (mut lo, mut hi) = (grid(k), grid(k - 1));
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if stable(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(lo)
}

/// How much an error grows over `life` seconds at steps of `dt` for the test problem
/// `x'' = −ω²·x − k·x'`: the spectral radius of one step's map, to the power of the steps
/// in a life.
pub fn lifetime_growth(method: Integrator, omega2: f64, k: f64, dt: f64, life: f64) -> f64 {
    let rho = spectral_radius(step_map(method, omega2, k, dt));
    let steps = (life / dt).max(1.0);
    if rho <= 1.0 {
        rho.powf(steps)
    } else {
        (steps * rho.ln()).min(700.0).exp()
    }
}

/// One step of `method` on `x'' = −ω²·x − k·x'` as a 2×2 matrix over (x, v): the images
/// of (1, 0) and (0, 1) (the formulas of `integrate` in `shaders/integrators.wgsl`).
fn step_map(method: Integrator, omega2: f64, k: f64, dt: f64) -> [[f64; 2]; 2] {
    let acc = |x: f64, v: f64| -omega2 * x - k * v;
    let step = |x: f64, v: f64| -> (f64, f64) {
        match method {
            Integrator::ExplicitEuler => (x + v * dt, v + acc(x, v) * dt),
            Integrator::SemiImplicitEuler => {
                let v1 = v + acc(x, v) * dt;
                (x + v1 * dt, v1)
            }
            Integrator::VelocityVerlet => {
                let a0 = acc(x, v);
                let p1 = x + v * dt + 0.5 * a0 * dt * dt;
                let a1 = acc(p1, v + a0 * dt);
                (p1, v + 0.5 * (a0 + a1) * dt)
            }
            Integrator::Heun => {
                let a0 = acc(x, v);
                let vp = v + a0 * dt;
                let a1 = acc(x + v * dt, vp);
                (x + 0.5 * (v + vp) * dt, v + 0.5 * (a0 + a1) * dt)
            }
            Integrator::Rk4 => {
                let h = 0.5 * dt;
                let (k1x, k1v) = (v, acc(x, v));
                let k2x = v + h * k1v;
                let k2v = acc(x + h * k1x, k2x);
                let k3x = v + h * k2v;
                let k3v = acc(x + h * k2x, k3x);
                let k4x = v + dt * k3v;
                let k4v = acc(x + dt * k3x, k4x);
                let s = dt / 6.0;
                (
                    x + s * (k1x + 2.0 * k2x + 2.0 * k3x + k4x),
                    v + s * (k1v + 2.0 * k2v + 2.0 * k3v + k4v),
                )
            }
            Integrator::Exponential => {
                // Drag exactly, the rest (the spring) as a constant force over the step.
                let f = -omega2 * x;
                let (phi, psi) = if k * dt < 1e-9 {
                    (dt, 0.5 * dt * dt)
                } else {
                    let phi = (1.0 - (-k * dt).exp()) / k;
                    (phi, (dt - phi) / k)
                };
                (x + v * phi + f * psi, v * (1.0 - k * phi) + f * phi)
            }
        }
    };
    let (a, c) = step(1.0, 0.0);
    let (b, d) = step(0.0, 1.0);
    [[a, b], [c, d]]
}

/// The largest |eigenvalue| of a 2×2 matrix.
fn spectral_radius(m: [[f64; 2]; 2]) -> f64 {
    let t = m[0][0] + m[1][1];
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    let disc = t * t / 4.0 - det;
    if disc < 0.0 {
        det.abs().sqrt()
    } else {
        let r = disc.sqrt();
        (t / 2.0 + r).abs().max((t / 2.0 - r).abs())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pure_drag_is_stable_below_two_over_k_for_euler_types() {
        // The velocity's factor |1 − k·dt| ≤ 1: k·dt ≤ 2 (the closed form), for the
        // explicit and semi-implicit Euler methods alike (the position's is 1).
        for m in [Integrator::ExplicitEuler, Integrator::SemiImplicitEuler] {
            let r = spectral_radius(step_map(m, 0.0, 100.0, 0.019));
            assert!((r - 1.0).abs() < 1e-12, "{m:?}: {r}");
            let r = spectral_radius(step_map(m, 0.0, 100.0, 0.021));
            assert!((r - 1.1).abs() < 1e-12, "{m:?}: {r}");
        }
        // The exponential integrator is exact for drag: e^{−k·dt} (and 1 for the position).
        let m = step_map(Integrator::Exponential, 0.0, 100.0, 0.1);
        assert!((m[1][1] - (-10.0f64).exp()).abs() < 1e-12);
        assert!((spectral_radius(m) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn a_spring_needs_omega_dt_below_two_with_symplectic_euler() {
        // Semi-implicit Euler on x'' = −ω²x: stable iff ω·dt ≤ 2.
        let m = Integrator::SemiImplicitEuler;
        assert!(spectral_radius(step_map(m, 100.0, 0.0, 0.199)) <= 1.0 + 1e-12);
        assert!(spectral_radius(step_map(m, 100.0, 0.0, 0.201)) > 1.0);
        // Explicit Euler grows on any spring: √(1 + ω²dt²).
        let r = spectral_radius(step_map(Integrator::ExplicitEuler, 100.0, 0.0, 0.01));
        assert!((r - 1.01f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn the_stable_step_is_where_the_growth_crosses_the_limit() {
        let mut e = Emitter::default();
        e.forces.drag_per_sec = 300.0;
        e.forces.flame_pull = None;
        e.forces.turbulence = None;
        e.integrator = Integrator::SemiImplicitEuler;
        let s = largest_stable_step(&e).expect("a stable step");
        assert!(e.growth_at(s) <= GROWTH_LIMIT && e.growth_at(s * 1.001) > GROWTH_LIMIT);
        // Just above 2/k: the growth |1 − k·dt|^(life/dt) reaches 2 over 1.4 s.
        assert!(s > 2.0 / 300.0 && s < 2.01 / 300.0, "{s}");
        assert_eq!(e.stiffness().dominant_field, "forces.drag_per_sec");
    }
}
