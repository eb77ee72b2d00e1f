//! Force modules and colliders on a real adapter: curl noise is divergence-free and the GPU
//! field matches the CPU one, vortex/attractor match their formulas, an attractor orbit
//! stays circular, colliders never let a particle through, bounces follow elasticity and
//! friction, resting particles do not jitter, and a module that is off is bit-identical
//! to a pipeline built without its code.

mod common;

use common::*;
use glam::{DVec3, Vec3};
use ignis::Camera;
use ignis::effect::*;
use ignis::testing::gpu::GpuContext;
use ignis::testing::gpu::types::Particle;
use ignis::testing::headless::Headless;
use ignis::testing::shaders::ShaderLibrary;
use ignis::testing::sim::cpu_reference::{Forces as CpuForces, curl_noise};
use ignis::testing::sim::{GpuSim, Modules};

fn particle(pos: Vec3, vel: Vec3) -> Particle {
    Particle {
        pos_age: [pos.x, pos.y, pos.z, 0.0],
        vel_life: [vel.x, vel.y, vel.z, 1e4],
    }
}

/// A force-free emitter (no gravity, drag or noise), rate 0: add the module under test.
fn quiet(integrator: Integrator) -> Emitter {
    Emitter {
        spawn_rate_per_sec: ignis::effect::Param::Constant(0.0),
        capacity: 256,
        integrator,
        ..plain_emitter()
    }
}

/// Runs `steps` from `initial` and returns the final state.
fn run_from(e: &Emitter, initial: &[Particle], dt: f32, steps: u32) -> Vec<Particle> {
    let ctx = gpu();
    let effect = bare_effect(Emitter {
        capacity: initial.len() as u32,
        ..e.clone()
    });
    let mut sim = GpuSim::new(&ctx, ShaderLibrary::embedded(), &effect).expect("sim");
    sim.write_particles(0, initial).expect("write");
    sim.step(&effect, dt, steps).expect("step");
    sim.read_particles(0).expect("read")
}

/// Curl noise: the finite-difference divergence is ≪ the field's magnitude × frequency.
#[test]
fn curl_noise_is_divergence_free() {
    let h = 1e-4;
    let mut max_div: f64 = 0.0;
    let mut mean_mag = 0.0;
    let n = 2000;
    for i in 0..n {
        let p = DVec3::new(
            (i as f64 * 0.37).sin() * 3.0,
            (i as f64 * 0.11).cos() * 3.0,
            i as f64 * 0.013,
        );
        let f = |q: DVec3| curl_noise(q, 7, 2);
        let div = (f(p + DVec3::X * h).x - f(p - DVec3::X * h).x + f(p + DVec3::Y * h).y
            - f(p - DVec3::Y * h).y
            + f(p + DVec3::Z * h).z
            - f(p - DVec3::Z * h).z)
            / (2.0 * h);
        max_div = max_div.max(div.abs());
        mean_mag += f(p).length() / n as f64;
    }
    assert!(mean_mag > 0.1, "field too weak: {mean_mag}");
    assert!(
        max_div < 1e-5 * mean_mag,
        "divergence {max_div} vs magnitude {mean_mag}"
    );
}

/// Curl noise equals the curl of its potential taken independently: ψ's three channels
/// interpolated from `hash_cell3`'s lattice values (quintic fade, written here as nested
/// lerps), differentiated by central differences, summed over octaves (seed + octave,
/// amplitude ½ and frequency 2 per octave).
#[test]
fn curl_noise_is_the_curl_of_its_potential() {
    let fade = |t: f64| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
    let potential = |p: DVec3, seed: u32| -> DVec3 {
        let cell = p.floor();
        let f = p - cell;
        let lattice = |dx: i32, dy: i32, dz: i32| {
            let c = [cell.x as i32 + dx, cell.y as i32 + dy, cell.z as i32 + dz];
            DVec3::from(ignis::testing::rng::hash_cell3(c, seed).map(f64::from))
        };
        let (u, v, w) = (fade(f.x), fade(f.y), fade(f.z));
        let x0 = |dy, dz| lattice(0, dy, dz).lerp(lattice(1, dy, dz), u);
        let y0 = |dz| x0(0, dz).lerp(x0(1, dz), v);
        y0(0).lerp(y0(1), w)
    };
    let curl = |p: DVec3, seed: u32| -> DVec3 {
        let h = 1e-5;
        let d = |axis: DVec3| {
            (potential(p + axis * h, seed) - potential(p - axis * h, seed)) / (2.0 * h)
        };
        let (dx, dy, dz) = (d(DVec3::X), d(DVec3::Y), d(DVec3::Z));
        DVec3::new(dy.z - dz.y, dz.x - dx.z, dx.y - dy.x)
    };
    let mut worst: f64 = 0.0;
    for i in 0..500 {
        let p = DVec3::new(
            (i as f64 * 0.37).sin() * 5.0,
            (i as f64 * 0.11).cos() * 5.0 - 0.5,
            i as f64 * 0.021 - 4.0,
        );
        let expected = curl(p, 11) + 0.5 * 2.0 * curl(p * 2.0, 12);
        let got = curl_noise(p, 11, 2);
        worst = worst.max((got - expected).length() / expected.length().max(0.1));
    }
    assert!(worst < 1e-5, "curl noise vs the potential's curl: {worst}");
}

/// The GPU's turbulence acceleration (read from one explicit Euler step: Δv/dt) equals the
/// CPU field at the same points.
#[test]
fn gpu_turbulence_matches_cpu_field() {
    let mut e = quiet(Integrator::ExplicitEuler);
    e.forces.turbulence = Some(Turbulence {
        strength_m_per_s2: 2.0,
        frequency_per_m: 1.7,
        octaves: 3,
        scroll_m_per_s: 0.0,
        ..Turbulence::default()
    });
    let initial: Vec<Particle> = (0..256)
        .map(|i| {
            particle(
                Vec3::new(
                    (i as f32 * 0.731).sin(),
                    (i as f32 * 0.377).cos() + 1.0,
                    i as f32 * 0.01,
                ),
                Vec3::ZERO,
            )
        })
        .collect();
    let dt = 1e-3;
    let out = run_from(&e, &initial, dt, 1);
    // The CPU field with the same parameter block.
    let effect = bare_effect(e.clone());
    let mut planner = ignis::testing::sim::EffectPlanner::default();
    let params = planner.plan_step(&effect, dt)[0].expect("enabled");
    let forces = CpuForces {
        params: &params,
        modules: Modules::of(&e),
        over_life: [1.0; 4],
    };
    let mut worst: f64 = 0.0;
    for (p0, p1) in initial.iter().zip(&out) {
        let gpu_a = (p1.velocity() - p0.velocity()).as_dvec3() / dt as f64;
        let cpu_a = forces.acceleration(p0.position().as_dvec3(), DVec3::ZERO, 0.0, 1e4, 0.0);
        assert!(cpu_a.length() > 1e-3);
        worst = worst.max((gpu_a - cpu_a).length() / cpu_a.length().max(0.1));
    }
    // Δv is rounded to f32 at |v| ≈ 2e-3 (ulp ≈ 2e-10) and divided by dt: 1e-3 relative.
    assert!(
        worst < 2e-3,
        "GPU vs CPU turbulence: worst relative difference {worst}"
    );
}

/// Vortex and attractor accelerations match their formulas at sampled radii.
#[test]
fn vortex_and_attractor_match_their_formulas() {
    let dt = 1e-3;
    // Vortex about +Y through the origin: a = s·exp(−d²/R²)·(axis × r̂).
    let mut e = quiet(Integrator::ExplicitEuler);
    let (s, r) = (3.0f32, 0.5f32);
    e.forces.vortex = Some(Vortex {
        center_m: [0.0; 3],
        axis: [0.0, 1.0, 0.0],
        swirl_m_per_s2: s,
        radius_m: r,
    });
    let radii = [0.1f32, 0.3, 0.5, 0.8, 1.2];
    let initial: Vec<Particle> = radii
        .iter()
        .map(|d| particle(Vec3::new(*d, 0.2, 0.0), Vec3::ZERO))
        .collect();
    let out = run_from(&e, &initial, dt, 1);
    for (d, p) in radii.iter().zip(&out) {
        let a = p.velocity() / dt;
        let expected = Vec3::Y.cross(Vec3::X) * s * (-(d * d) / (r * r)).exp();
        assert!(
            (a - expected).length() < 1e-3 * s,
            "vortex at {d}: {a} vs {expected}"
        );
    }
    // Attractor, softened inverse square: a = S·d/(|d|² + ε²)^{3/2}.
    for (falloff, strength) in [
        (Falloff::InverseSquare, 2.0f32),
        (Falloff::ConstantWithinRadius, 1.5),
    ] {
        let mut e = quiet(Integrator::ExplicitEuler);
        let eps = 0.2f32;
        e.forces.attractor = Some(Attractor {
            position_m: [0.0, 1.0, 0.0],
            strength,
            radius_m: eps,
            falloff,
        });
        let dists = [0.05f32, 0.15, 0.5, 1.0, 2.0];
        let initial: Vec<Particle> = dists
            .iter()
            .map(|d| particle(Vec3::new(*d, 1.0, 0.0), Vec3::ZERO))
            .collect();
        let out = run_from(&e, &initial, dt, 1);
        for (d, p) in dists.iter().zip(&out) {
            let a = p.velocity() / dt;
            let expected = match falloff {
                Falloff::InverseSquare => -Vec3::X * strength * d / (d * d + eps * eps).powf(1.5),
                Falloff::ConstantWithinRadius => {
                    if *d <= eps {
                        -Vec3::X * strength
                    } else {
                        Vec3::ZERO
                    }
                }
            };
            assert!(
                (a - expected).length() < 1e-3 * expected.length().max(1.0),
                "{falloff:?} at {d}: {a} vs {expected}"
            );
        }
    }
}

/// A particle on a circular orbit around an inverse-square attractor, launched at the
/// matching speed, stays on the circle (RK4, 1/240 s, 2 orbits): radius error < 1e-4.
#[test]
fn attractor_orbit_stays_circular() {
    let mut e = quiet(Integrator::Rk4);
    let (s, eps, r) = (4.0f32, 0.01f32, 0.8f32);
    e.forces.attractor = Some(Attractor {
        position_m: [0.0, 0.0, 0.0],
        strength: s,
        radius_m: eps,
        falloff: Falloff::InverseSquare,
    });
    let speed = (s * r * r / (r * r + eps * eps).powf(1.5)).sqrt();
    let period = std::f32::consts::TAU * r / speed;
    let dt = 1.0 / 240.0;
    let steps = (2.0 * period / dt) as u32;
    let out = run_from(
        &e,
        &[particle(Vec3::new(r, 0.0, 0.0), Vec3::new(0.0, 0.0, speed))],
        dt,
        steps,
    );
    let radius = out[0].position().length();
    assert!(
        (radius - r).abs() < 1e-4,
        "after {steps} steps radius {radius} (want {r})"
    );
}

/// No particle ends below the ground, even at 1000 m/s (16 m per step); none passes
/// through a sphere at speeds where a naive end-point test tunnels.
#[test]
fn colliders_never_let_particles_through() {
    let mut e = quiet(Integrator::SemiImplicitEuler);
    e.collisions = Collisions {
        ground: Some(GroundPlane {
            height_m: 0.0,
            kill_on_contact: false,
        }),
        elasticity: 0.5,
        friction: 0.1,
        ..Collisions::default()
    };
    e.forces.gravity_m_per_s2 = [0.0, -9.81, 0.0];
    let initial: Vec<Particle> = (0..256)
        .map(|i| {
            particle(
                Vec3::new(i as f32 * 0.01, 1.0, 0.0),
                Vec3::new(0.3, -1000.0 - i as f32, 0.0),
            )
        })
        .collect();
    let ctx = gpu();
    let effect = bare_effect(Emitter {
        capacity: 256,
        ..e.clone()
    });
    let mut sim = GpuSim::new(&ctx, ShaderLibrary::embedded(), &effect).expect("sim");
    sim.write_particles(0, &initial).expect("write");
    for _ in 0..60 {
        sim.step(&effect, 1.0 / 60.0, 1).expect("step");
        for p in sim.read_particles(0).expect("read") {
            assert!(p.position().y >= 0.0, "below ground: {p:?}");
        }
    }
    // A sphere of radius 0.2 at x = 2: particles at 100 m/s cross 1.67 m per step, so the
    // end point of a step is never inside it — only the segment test catches them.
    let mut e = quiet(Integrator::SemiImplicitEuler);
    e.collisions = Collisions {
        spheres: vec![SphereCollider {
            center_m: [2.0, 0.0, 0.0],
            radius_m: 0.2,
        }],
        elasticity: 1.0,
        friction: 0.0,
        rest_speed_m_per_s: 0.0,
        ..Collisions::default()
    };
    let initial: Vec<Particle> = (0..64)
        .map(|i| {
            particle(
                Vec3::new(0.0, (i as f32 - 32.0) * 0.005, 0.0),
                Vec3::new(100.0, 0.0, 0.0),
            )
        })
        .collect();
    let effect = bare_effect(Emitter { capacity: 64, ..e });
    let mut sim = GpuSim::new(&ctx, ShaderLibrary::embedded(), &effect).expect("sim");
    sim.write_particles(0, &initial).expect("write");
    for _ in 0..3 {
        sim.step(&effect, 1.0 / 60.0, 1).expect("step");
        for p in sim.read_particles(0).expect("read") {
            let d = (p.position() - Vec3::new(2.0, 0.0, 0.0)).length();
            assert!(d >= 0.2 * (1.0 - 1e-4), "inside the sphere: {p:?}");
        }
    }
    for (p0, p) in initial.iter().zip(sim.read_particles(0).expect("read")) {
        // Aimed at the core (|y| ≤ 0.1): bounced straight back, never through.
        if p0.position().y.abs() <= 0.1 {
            assert!(
                p.position().x < 2.0 && p.velocity().x < 0.0,
                "tunnelled: {p:?} (from {p0:?})"
            );
        }
    }
}

/// Bounces follow elasticity (normal speed × e) and friction (tangential × (1 − f)).
#[test]
fn bounce_follows_elasticity_and_friction() {
    let (elasticity, friction) = (0.6f32, 0.25f32);
    let mut e = quiet(Integrator::SemiImplicitEuler);
    e.collisions = Collisions {
        ground: Some(GroundPlane {
            height_m: 0.0,
            kill_on_contact: false,
        }),
        elasticity,
        friction,
        rest_speed_m_per_s: 0.0,
        ..Collisions::default()
    };
    let v0 = Vec3::new(2.0, -3.0, 1.0);
    let out = run_from(
        &e,
        &[particle(Vec3::new(0.0, 0.01, 0.0), v0)],
        1.0 / 60.0,
        1,
    );
    let v = out[0].velocity();
    assert!(
        (v.y - 3.0 * elasticity).abs() < 1e-5,
        "normal speed {} (want {})",
        v.y,
        3.0 * elasticity
    );
    assert!(
        (v.x - 2.0 * (1.0 - friction)).abs() < 1e-5 && (v.z - 1.0 * (1.0 - friction)).abs() < 1e-5,
        "tangent {v}"
    );
    // Normal kinetic energy scales by e².
    let ratio = (v.y * v.y) / (v0.y * v0.y);
    assert!((ratio - elasticity * elasticity).abs() < 1e-5);
    // Kill on contact.
    e.collisions.ground = Some(GroundPlane {
        height_m: 0.0,
        kill_on_contact: true,
    });
    let out = run_from(
        &e,
        &[particle(Vec3::new(0.0, 0.01, 0.0), v0)],
        1.0 / 60.0,
        1,
    );
    assert!(!out[0].is_alive());
}

/// Particles resting on the ground under gravity do not jitter: height and vertical speed
/// stay exactly zero step after step.
#[test]
fn resting_particles_do_not_jitter() {
    let mut e = quiet(Integrator::SemiImplicitEuler);
    e.forces.gravity_m_per_s2 = [0.0, -9.81, 0.0];
    e.collisions = Collisions {
        ground: Some(GroundPlane {
            height_m: 0.0,
            kill_on_contact: false,
        }),
        elasticity: 0.5,
        friction: 0.5,
        rest_speed_m_per_s: 0.2,
        ..Collisions::default()
    };
    let ctx = gpu();
    let effect = bare_effect(Emitter { capacity: 32, ..e });
    let mut sim = GpuSim::new(&ctx, ShaderLibrary::embedded(), &effect).expect("sim");
    sim.write_particles(
        0,
        &vec![particle(Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.5, 0.0, 0.0)); 32],
    )
    .expect("write");
    for _ in 0..100 {
        sim.step(&effect, 1.0 / 120.0, 1).expect("step");
        for p in sim.read_particles(0).expect("read") {
            assert_eq!(p.position().y, 0.0, "hovering: {p:?}");
            assert_eq!(p.velocity().y, 0.0, "jitter: {p:?}");
        }
    }
}

/// Every module off ⇒ the state is bit-identical to a pipeline built from source with the
/// module code deleted (for every integrator).
#[test]
fn modules_off_are_bit_identical_to_a_pipeline_without_them() {
    let ctx = gpu();
    for integrator in Integrator::ALL {
        let effect = bare_effect(Emitter {
            integrator,
            capacity: 2000,
            spawn_rate_per_sec: ignis::effect::Param::Constant(900.0),
            ..Emitter::default()
        });
        let mut states = Vec::new();
        for lib in [
            ShaderLibrary::embedded(),
            ShaderLibrary::embedded().without_modules().expect("bare"),
        ] {
            let mut sim = GpuSim::new(&ctx, lib, &effect).expect("sim");
            sim.step(&effect, 1.0 / 120.0, 120).expect("step");
            states.push(sim.read_particles(0).expect("read"));
        }
        assert!(states[0].iter().filter(|p| p.is_alive()).count() > 500);
        assert_eq!(
            states[0], states[1],
            "{integrator:?}: compiled-out modules changed the result"
        );
    }
}

/// Stateless mode (closed form from spawn records) and the stateful exponential integrator
/// (exact for the same forces) give the same particles within f32 rounding; stateless is
/// refused, with the reason, when a module needs state.
#[test]
fn stateless_matches_stateful_and_is_refused_when_ineligible() {
    let ctx = gpu();
    let mut base = Emitter {
        capacity: 3000,
        spawn_rate_per_sec: ignis::effect::Param::Constant(1500.0),
        lifetime_secs: Range::new(0.8, 1.6),
        integrator: Integrator::Exponential,
        ..Emitter::default()
    };
    base.forces.wind_m_per_s = [0.6, 0.0, -0.2];
    let stateful = bare_effect(base.clone());
    let stateless = bare_effect(Emitter {
        stateless: true,
        ..base.clone()
    });
    assert!(Modules::of(&stateless.emitters[0]).contains(Modules::STATELESS));
    let mut a = GpuSim::new(&ctx, ShaderLibrary::embedded(), &stateful).expect("sim");
    let mut b = GpuSim::new(&ctx, ShaderLibrary::embedded(), &stateless).expect("sim");
    a.step(&stateful, 1.0 / 120.0, 150).expect("step");
    b.step(&stateless, 1.0 / 120.0, 150).expect("step");
    let now = b.planner.time_secs.rem_euclid(4096.0) as f32;
    let full = a.read_particles(0).expect("read");
    let records = b.read_particles(0).expect("read");
    let mut compared = 0;
    let mut worst: f32 = 0.0;
    for (s, r) in full.iter().zip(&records) {
        let e =
            ignis::testing::sim::cpu_reference::evaluate_stateless(r, &stateless.emitters[0], now);
        assert_eq!(s.is_alive(), e.is_alive(), "{s:?} vs {e:?}");
        if s.is_alive() {
            worst = worst.max((s.position() - e.position()).length());
            compared += 1;
        }
    }
    assert!(compared > 1000, "{compared}");
    assert!(
        worst < 2e-5,
        "stateless vs stateful: worst position difference {worst} m"
    );

    // Not eligible with turbulence: validation names the blocker, and the pipeline stays
    // stateful.
    let mut bad = Emitter {
        stateless: true,
        ..base
    };
    bad.forces.turbulence = Some(Turbulence::default());
    assert!(!Modules::of(&bad).contains(Modules::STATELESS));
    let err = bare_effect(bad).validate().expect_err("refused");
    assert!(
        err.iter()
            .any(|e| e.path.ends_with("stateless") && e.problem.contains("turbulence")),
        "{err:?}"
    );
}

/// Stick on contact: a particle that reaches the ground (under gravity) or a sphere (no
/// forces) stops where it touches and stays there.
#[test]
fn stick_on_contact_stops_particles_where_they_touch() {
    let mut e = quiet(Integrator::SemiImplicitEuler);
    e.collisions = Collisions {
        ground: Some(GroundPlane {
            height_m: 0.0,
            kill_on_contact: false,
        }),
        spheres: vec![SphereCollider {
            center_m: [2.0, 0.5, 0.0],
            radius_m: 0.3,
        }],
        stick_on_contact: true,
        ..Collisions::default()
    };
    let initial = [
        particle(Vec3::new(0.0, 0.05, 0.0), Vec3::new(1.0, -2.0, 0.0)),
        particle(Vec3::new(1.0, 0.5, 0.0), Vec3::new(10.0, 0.0, 0.0)),
    ];
    let out = run_from(&e, &initial, 1.0 / 60.0, 30);
    let d = (out[1].position() - Vec3::new(2.0, 0.5, 0.0)).length();
    assert!(
        (d - 0.3).abs() < 1e-3 && out[1].velocity() == Vec3::ZERO,
        "{:?} at {d}",
        out[1]
    );
    e.forces.gravity_m_per_s2 = [0.0, -9.81, 0.0];
    let out = run_from(&e, &initial, 1.0 / 60.0, 30);
    assert_eq!(out[0].position().y, 0.0, "{:?}", out[0]);
    assert_eq!(out[0].velocity(), Vec3::ZERO);
}

/// `effect` played headless for `frames` frames at 60 fps (the player the Inspect view
/// reads).
fn played(ctx: &GpuContext, effect: Effect, frames: u32) -> Headless {
    let mut run = Headless::new(ctx, effect, ShaderLibrary::embedded()).expect("headless");
    for _ in 0..frames {
        run.advance(1.0 / 60.0);
    }
    run
}

/// Where `p` (world, metres) lands on `camera`'s 640×480 screen, in pixels.
fn pixel_of(camera: &Camera, p: Vec3) -> glam::Vec2 {
    let clip = camera.clip_from_world_mat4() * p.extend(1.0);
    let ndc = clip.truncate() / clip.w;
    glam::Vec2::new((ndc.x + 1.0) * 320.0, (1.0 - ndc.y) * 240.0)
}

/// The Inspect view's look inside: the particle under a pixel is found (the nearest one
/// projected within the radius), and the forces reported on it are the force model's —
/// the constant part, the drag toward the wind from its own velocity, and their sum.
#[test]
fn an_inspected_particle_reports_its_state_and_the_forces_on_it() {
    let ctx = gpu();
    let mut e = plain_emitter();
    e.capacity = 256;
    e.spawn_rate_per_sec = ignis::effect::Param::Constant(50.0);
    e.speed_m_per_s = Range::new(1.0, 2.0);
    e.spread_deg = 30.0;
    e.forces.gravity_m_per_s2 = [0.0, -9.81, 0.0];
    e.forces.buoyancy_m_per_s2 = 4.0;
    e.forces.drag_per_sec = 1.5;
    e.forces.wind_m_per_s = [0.5, 0.0, 0.0];
    e.transform.position_m = [3.0, 1.0, -2.0];
    let run = played(&ctx, bare_effect(e), 30);
    let camera = run.camera.view((640, 480));
    let particles = run.player.particles(run.instance, 0).expect("particles");
    let (slot, p) = particles
        .iter()
        .enumerate()
        .find(|(_, p)| p.is_alive())
        .expect("a living particle");
    let info = run
        .player
        .inspect_particle(run.instance, 0, slot as u32)
        .expect("inspect")
        .expect("alive");
    assert_eq!((info.emitter, info.slot), (0, slot as u32));
    assert_eq!(info.age_secs, p.pos_age[3]);
    assert_eq!(info.lifetime_secs, p.vel_life[3]);
    assert_eq!(info.velocity_m_per_s, p.velocity());
    // Positions are reported in the world (the pool is relative to the emitter).
    assert!((info.position_m - (p.position() + Vec3::new(3.0, 1.0, -2.0))).length() < 1e-5);
    let force = |name: &str| {
        info.forces
            .iter()
            .find(|(n, _)| *n == name)
            .unwrap_or_else(|| panic!("no {name} in {:?}", info.forces))
            .1
    };
    let constant = Vec3::new(0.0, -9.81 + 4.0, 0.0);
    let drag = -1.5 * (p.velocity() - Vec3::new(0.5, 0.0, 0.0));
    assert!((force("gravity + buoyancy") - constant).length() < 1e-5);
    assert!((force("drag") - drag).length() < 1e-4, "{:?}", info.forces);
    assert!((force("total") - (constant + drag)).length() < 1e-4);
    assert_eq!(info.forces.len(), 3, "{:?}", info.forces);
    // Picking: the pixel the particle projects to finds it; far from every particle, none.
    let pixel = pixel_of(&camera, info.position_m);
    let picked = run
        .player
        .pick_particle(run.instance, &camera, pixel, 0.5)
        .expect("pick")
        .expect("the particle under its pixel");
    assert_eq!(picked.slot, slot as u32);
    let none = run
        .player
        .pick_particle(run.instance, &camera, glam::Vec2::new(-500.0, -500.0), 8.0)
        .expect("pick");
    assert!(none.is_none());
}

/// The forces the Inspect view reports carry the particle's over-life multipliers at its
/// age: drag over life a line from 0 to 2 over a 2 s life scales a 1.5/s drag by
/// age (s) at every living particle.
#[test]
fn inspected_forces_carry_the_over_life_multipliers_at_the_particles_age() {
    let ctx = gpu();
    let mut e = plain_emitter();
    e.capacity = 256;
    e.spawn_rate_per_sec = Param::Constant(50.0);
    e.lifetime_secs = Range::new(2.0, 2.0);
    e.speed_m_per_s = Range::new(1.0, 1.0);
    e.spread_deg = 30.0;
    e.forces.drag_per_sec = 1.5;
    e.forces.wind_m_per_s = [0.5, 0.0, 0.0];
    e.forces.drag_over_life = Param::Curve {
        keys: vec![(0.0, 0.0), (1.0, 2.0)],
        smooth: false,
    };
    let run = played(&ctx, bare_effect(e), 45);
    let particles = run.player.particles(run.instance, 0).expect("particles");
    let mut checked = 0;
    for (slot, p) in particles.iter().enumerate().filter(|(_, p)| p.is_alive()) {
        let info = run
            .player
            .inspect_particle(run.instance, 0, slot as u32)
            .expect("inspect")
            .expect("alive");
        let drag = info
            .forces
            .iter()
            .find(|(n, _)| *n == "drag")
            .expect("drag")
            .1;
        // The line's value at age / life: 2 · age / 2 s.
        let multiplier = info.age_secs / info.lifetime_secs * 2.0;
        let expected = -1.5 * multiplier * (p.velocity() - Vec3::new(0.5, 0.0, 0.0));
        assert!(
            (drag - expected).length() < 1e-4 * (1.0 + expected.length()),
            "age {} s: drag {drag} against {expected}",
            info.age_secs
        );
        checked += 1;
    }
    assert!(checked >= 20, "{checked} particles checked");
}

/// Particles at the same distance from the pointer: the pick is the first of them (the
/// lowest slot of the first emitter), whatever else is in the pool.
#[test]
fn a_pick_among_equally_near_particles_is_the_first_slot() {
    let ctx = gpu();
    let mut e = plain_emitter();
    e.capacity = 64;
    e.spawn_rate_per_sec = Param::Constant(60.0);
    // Every particle sits still at the emitter: all at one pixel.
    let run = played(&ctx, bare_effect(e), 20);
    let particles = run.player.particles(run.instance, 0).expect("particles");
    let alive: Vec<usize> = (0..particles.len())
        .filter(|&s| particles[s].is_alive())
        .collect();
    assert!(alive.len() >= 10, "{} alive", alive.len());
    let camera = run.camera.view((640, 480));
    let pixel = pixel_of(&camera, Vec3::ZERO);
    let picked = run
        .player
        .pick_particle(
            run.instance,
            &camera,
            pixel + glam::Vec2::new(1.5, 0.0),
            4.0,
        )
        .expect("pick")
        .expect("a particle near the pointer");
    assert_eq!(picked.slot as usize, alive[0], "alive slots {alive:?}");
}

/// The pick is the nearest particle within the radius, not the first or the last found:
/// with a radius that holds many moving particles, the one nearest the pointer (found
/// here from the positions read back) is the one picked.
#[test]
fn a_pick_within_a_wide_radius_is_the_nearest_particle() {
    let ctx = gpu();
    let mut e = plain_emitter();
    e.capacity = 256;
    e.spawn_rate_per_sec = Param::Constant(60.0);
    e.speed_m_per_s = Range::new(0.5, 2.0);
    e.spread_deg = 60.0;
    let run = played(&ctx, bare_effect(e), 40);
    let camera = run.camera.view((640, 480));
    let particles = run.player.particles(run.instance, 0).expect("particles");
    let pixels: Vec<(usize, glam::Vec2)> = (particles.iter().enumerate())
        .filter(|(_, p)| p.is_alive())
        .map(|(s, p)| (s, pixel_of(&camera, p.position())))
        .collect();
    // A pointer off the crowd's middle, so that the nearest is neither first nor last.
    let mean = pixels.iter().map(|(_, q)| *q).sum::<glam::Vec2>() / pixels.len() as f32;
    let pointer = mean + glam::Vec2::new(7.0, -5.0);
    let near = |r: f32| {
        pixels
            .iter()
            .filter(|(_, q)| q.distance(pointer) <= r)
            .count()
    };
    assert!(near(400.0) >= 20, "{} within the radius", near(400.0));
    let (nearest, _) = (pixels.iter())
        .min_by(|a, b| a.1.distance(pointer).total_cmp(&b.1.distance(pointer)))
        .expect("particles");
    let picked = run
        .player
        .pick_particle(run.instance, &camera, pointer, 400.0)
        .expect("pick")
        .expect("a particle within the radius");
    assert_eq!(picked.slot as usize, *nearest);
}

/// A switched-off emitter is not drawn, and its particles are not picked: still particles
/// of two emitters 1 m apart, the second switched off, and nothing under its pixel.
#[test]
fn a_switched_off_emitters_particles_are_not_picked() {
    let ctx = gpu();
    let mut a = plain_emitter();
    a.capacity = 64;
    a.spawn_rate_per_sec = Param::Constant(60.0);
    a.transform.position_m = [-0.5, 0.0, 0.0];
    let mut b = a.clone();
    b.name = "second".into();
    b.transform.position_m = [0.5, 0.0, 0.0];
    let mut effect = bare_effect(a);
    effect.emitters.push(b);
    let mut run = played(&ctx, effect.clone(), 20);
    let camera = run.camera.view((640, 480));
    let pixel = pixel_of(&camera, Vec3::new(0.5, 0.0, 0.0));
    let pick = |run: &Headless| {
        (run.player.pick_particle(run.instance, &camera, pixel, 4.0)).expect("pick")
    };
    assert_eq!(pick(&run).map(|p| p.emitter), Some(1), "on, it is picked");
    effect.emitters[1].enabled = false;
    run.player.set_effect(&effect).expect("edit");
    run.advance(1.0 / 60.0);
    assert_eq!(pick(&run), None, "switched off");
}

/// Over-life multipliers against their closed forms: speed over life 2 moves a particle
/// twice its velocity's distance (its velocity unchanged by it), and drag over life 0
/// switches a 3/s drag off — a half second's displacement of every living particle is
/// exactly its velocity's, doubled; tripled after the multiplier is edited to 3.
#[test]
fn over_life_multipliers_scale_motion_as_their_closed_forms() {
    let ctx = gpu();
    let mut e = plain_emitter();
    e.capacity = 256;
    e.spawn_rate_per_sec = Param::Constant(60.0);
    e.lifetime_secs = Range::new(10.0, 10.0);
    e.speed_m_per_s = Range::new(1.0, 1.0);
    e.forces.drag_per_sec = 3.0;
    e.forces.drag_over_life = Param::Constant(0.0);
    e.forces.speed_over_life = Param::Constant(2.0);
    let effect = bare_effect(e);
    let mut sim = GpuSim::new(&ctx, ShaderLibrary::embedded(), &effect).expect("sim");
    sim.step(&effect, 1.0 / 60.0, 30).expect("step");
    let before = sim.read_particles(0).expect("read");
    sim.step(&effect, 1.0 / 60.0, 30).expect("step");
    let after = sim.read_particles(0).expect("read");
    let mut compared = 0;
    for (a, b) in before.iter().zip(&after).filter(|(a, _)| a.is_alive()) {
        let v = a.velocity();
        let moved = b.position() - a.position();
        assert!(
            (v.length() - 1.0).abs() < 1e-5 && b.velocity() == v,
            "{a:?} → {b:?}"
        );
        assert!((moved - 2.0 * v * 0.5).length() < 1e-4, "{a:?} → {b:?}");
        compared += 1;
    }
    assert!(compared >= 25, "{compared} compared");
    // Edited to 3 while playing: the baked multipliers follow the edit.
    let mut faster = effect.clone();
    faster.emitters[0].forces.speed_over_life = Param::Constant(3.0);
    sim.step(&faster, 1.0 / 60.0, 30).expect("step");
    let last = sim.read_particles(0).expect("read");
    for (b, c) in after.iter().zip(&last).filter(|(b, _)| b.is_alive()) {
        let moved = c.position() - b.position();
        assert!(
            (moved - 3.0 * b.velocity() * 0.5).length() < 1e-4,
            "{b:?} → {c:?}"
        );
    }
}
