//! The core simulation on a real adapter: GPU against the CPU reference, exact spawn
//! counts, shapes, determinism, capacity limits.

mod common;

use common::*;
use glam::{Mat4, Vec3};
use ignis::effect::{Burst, Effect, Emitter, Integrator, Range, Shape, TimeMode, Transform};
use ignis::testing::gpu::GpuError;
use ignis::testing::shaders::ShaderLibrary;
use ignis::testing::sim::{GpuSim, SimError, Stepper};

/// GPU and CPU agree after 240 steps for every integrator, with spawning, noise, drag,
/// wind and a transformed disc emitter. Tolerance: 2e-5 absolute + 2e-5 relative on
/// positions and velocities (GPU sin/cos/exp/pow differ from Rust's in the last bits).
#[test]
fn gpu_matches_cpu_reference_for_every_integrator() {
    let ctx = gpu();
    for integrator in Integrator::ALL {
        let mut e = Emitter {
            capacity: 1500,
            spawn_rate_per_sec: ignis::effect::Param::Constant(700.0),
            lifetime_secs: Range::new(0.5, 1.6),
            integrator,
            transform: Transform {
                position_m: [0.3, 0.1, -0.2],
                rotation_deg: [10.0, 30.0, 0.0],
            },
            ..Emitter::default()
        };
        e.forces.wind_m_per_s = [0.4, 0.0, 0.2];
        let effect = bare_effect(e);
        let (gpu_state, cpu) = run_gpu_and_cpu(&ctx, &effect, 1.0 / 120.0, 240);
        assert_eq!(gpu_state.len(), cpu.particles.len());
        let mut alive = 0;
        let mut max_err: f32 = 0.0;
        for (slot, (g, c)) in gpu_state.iter().zip(&cpu.particles).enumerate() {
            assert_eq!(
                g.is_alive(),
                c.is_alive(),
                "{integrator:?}: slot {slot} alive differs: gpu {g:?} cpu {c:?}"
            );
            if !c.is_alive() {
                continue;
            }
            alive += 1;
            for (a, b) in g
                .pos_age
                .iter()
                .chain(&g.vel_life)
                .zip(c.pos_age.iter().chain(&c.vel_life))
            {
                let err = (a - b).abs();
                max_err = max_err.max(err);
                assert!(
                    err <= 2e-5 + 2e-5 * b.abs(),
                    "{integrator:?}: slot {slot}: gpu {g:?} vs cpu {c:?}"
                );
            }
        }
        assert!(alive > 500, "{integrator:?}: only {alive} alive");
        eprintln!("{integrator:?}: {alive} alive, max |gpu - cpu| = {max_err:e}");
    }
}

/// Every optional module at once (turbulence, vortex, attractor, flame pull, gusts,
/// quadratic drag, ground and sphere colliders): GPU and CPU still agree. The tolerance is
/// looser (2e-4) because the CPU evaluates the noise in f64 and rounds, while the GPU
/// works in f32 throughout; bounces amplify small differences at the contact.
#[test]
fn gpu_matches_cpu_reference_with_every_module() {
    use ignis::effect::*;
    let ctx = gpu();
    // Each integrator, then with every over-life multiplier on: the two-stage integrators
    // (Verlet, Heun) evaluate their second acceleration at the predicted position,
    // velocity, age and time, which the position-, velocity-, age- and time-dependent
    // modules here all see.
    for (integrator, curves) in [
        (Integrator::ExplicitEuler, false),
        (Integrator::SemiImplicitEuler, false),
        (Integrator::Rk4, false),
        (Integrator::Exponential, false),
        (Integrator::SemiImplicitEuler, true),
        (Integrator::VelocityVerlet, true),
        (Integrator::Heun, true),
        (Integrator::Exponential, true),
    ] {
        let mut e = Emitter {
            capacity: 1200,
            spawn_rate_per_sec: ignis::effect::Param::Constant(600.0),
            lifetime_secs: Range::new(0.5, 1.6),
            integrator,
            ..Emitter::default()
        };
        let f = &mut e.forces;
        f.quadratic_drag_per_m = 0.3;
        f.gusts = Some(Gusts::default());
        f.turbulence = Some(Turbulence::default());
        f.vortex = Some(Vortex::default());
        f.attractor = Some(Attractor {
            falloff: Falloff::ConstantWithinRadius,
            radius_m: 0.8,
            ..Attractor::default()
        });
        f.flame_pull = Some(FlamePull::default());
        if curves {
            f.speed_over_life = Param::Curve {
                keys: vec![(0.0, 1.5), (0.5, 0.6), (1.0, 1.0)],
                smooth: true,
            };
            f.drag_over_life = Param::Range { min: 0.5, max: 2.0 };
            f.turbulence = Some(Turbulence {
                over_life: Param::TwoCurves {
                    a: Curve::line(0.0, 2.0),
                    b: Curve {
                        keys: vec![(0.0, 1.0), (0.3, 3.0), (1.0, 0.5)],
                        smooth: true,
                    },
                },
                ..Turbulence::default()
            });
            f.flame_pull = Some(FlamePull {
                over_life: Param::Constant(2.0),
                ..FlamePull::default()
            });
        }
        e.collisions.ground = Some(GroundPlane {
            height_m: -0.05,
            kill_on_contact: false,
        });
        e.collisions.spheres = vec![SphereCollider {
            center_m: [0.0, 1.0, 0.0],
            radius_m: 0.2,
        }];
        e.forces.gravity_m_per_s2 = [0.0, -9.81, 0.0];
        e.forces.buoyancy_m_per_s2 = 9.0;
        let effect = bare_effect(e);
        let (gpu_state, cpu) = run_gpu_and_cpu(&ctx, &effect, 1.0 / 120.0, 180);
        let mut worst: f32 = 0.0;
        let mut alive = 0;
        let mut bad = 0;
        for (g, c) in gpu_state.iter().zip(&cpu.particles) {
            assert_eq!(g.is_alive(), c.is_alive());
            if !c.is_alive() {
                continue;
            }
            alive += 1;
            let err = (g.position() - c.position()).length();
            worst = worst.max(err);
            if err > 2e-4 {
                bad += 1;
            }
        }
        eprintln!(
            "{integrator:?} (curves {curves}): {alive} alive, worst position error {worst:e}, \
                {bad} beyond 2e-4"
        );
        assert!(alive > 300);
        // Allow a handful of contact-amplified outliers, never a systematic mismatch.
        assert!(
            bad * 100 <= alive,
            "{integrator:?}: {bad} of {alive} beyond 2e-4 (worst {worst})"
        );
    }
}

/// After t seconds, alive = rate × min(t, lifetime) within ±1 (sub-step emission makes
/// this exact even when rate × dt is not an integer), and the GPU's own alive counter
/// agrees with the readback.
#[test]
fn exact_spawn_counts_over_time() {
    let ctx = gpu();
    for (rate, dt) in [
        (1000.0f32, 1.0f32 / 120.0),
        (333.0, 1.0 / 60.0),
        (50.0, 1.0 / 240.0),
    ] {
        let e = Emitter {
            spawn_rate_per_sec: ignis::effect::Param::Constant(rate),
            lifetime_secs: Range::new(1.0, 1.0),
            ..plain_emitter()
        };
        let effect = bare_effect(e);
        let mut sim = GpuSim::new(&ctx, ShaderLibrary::embedded(), &effect).expect("sim");
        let mut steps_done = 0u32;
        for t in [0.25f64, 0.5, 1.0, 1.5, 3.0] {
            let target = (t / dt as f64).round() as u32;
            sim.step(&effect, dt, target - steps_done).expect("step");
            steps_done = target;
            let t_sim = sim.planner.time_secs;
            let expected = rate as f64 * t_sim.min(1.0);
            let state = sim.read_particles(0).expect("read");
            let alive = alive_of(&state) as f64;
            let counter = sim.read_counters(0).expect("counters")[0] as f64;
            assert_eq!(alive, counter, "GPU alive counter disagrees with the state");
            assert!(
                (alive - expected).abs() <= 1.0,
                "rate {rate} dt {dt} t {t_sim}: alive {alive}, expected {expected} ± 1"
            );
            let spawned = sim.planner.emitters[0].stats.spawned as f64;
            assert!(
                (spawned - rate as f64 * t_sim).abs() <= 1.0,
                "spawned {spawned} at t {t_sim}"
            );
        }
    }
}

/// The spawn cap is a rate: it drops the excess and counts it, and allows the same number
/// at any step size — a full bucket of a tenth of a second's worth, then the rate (a cap
/// counted per step would change with the step); a huge frame-delta step spawns no more
/// than the bucket and the cap's share of it.
#[test]
fn spawn_cap_per_second_is_enforced_counted_and_independent_of_the_step() {
    let ctx = gpu();
    let e = Emitter {
        spawn_rate_per_sec: ignis::effect::Param::Constant(12_000.0),
        max_spawn_per_sec: 2400.0,
        ..plain_emitter()
    };
    let mut effect = bare_effect(e);
    for (dt, steps) in [
        (1.0 / 30.0, 5),
        (1.0 / 60.0, 10),
        (1.0 / 120.0, 20),
        (1.0 / 240.0, 40),
    ] {
        let sim = run_gpu(&ctx, &effect, dt, steps);
        let stats = sim.planner.emitters[0].stats;
        assert_eq!(stats.spawned, 640, "240 + 2400/s × 1/6 s at dt {dt}");
        assert_eq!(
            stats.dropped_by_cap,
            2000 - 640,
            "12000/s × 1/6 s requested"
        );
        assert_eq!(alive_of(&sim.read_particles(0).expect("read")), 640);
    }

    // Frame-delta mode with a one-second hitch: dt is clamped to max_frame_dt_secs and the
    // cap bounds the burst to its bucket and its share of the clamped step.
    effect.time.mode = TimeMode::FrameDelta;
    effect.time.max_frame_dt_secs = 0.1;
    let mut stepper = Stepper::default();
    let plan = stepper.advance(1.0, &effect.time);
    assert_eq!((plan.steps, plan.dt_secs), (1, 0.1));
    let sim = run_gpu(&ctx, &effect, plan.dt_secs, plan.steps);
    assert_eq!(
        sim.planner.emitters[0].stats.spawned, 480,
        "240 + 2400/s × 0.1 s"
    );
}

/// Too small a pool: the overwrite of still-alive particles is counted, never silent.
#[test]
fn capacity_exhaustion_is_reported() {
    let ctx = gpu();
    let e = Emitter {
        capacity: 100,
        spawn_rate_per_sec: ignis::effect::Param::Constant(1000.0),
        ..plain_emitter()
    };
    let sim = run_gpu(&ctx, &bare_effect(e), 1.0 / 120.0, 120);
    let stats = sim.planner.emitters[0].stats;
    assert_eq!(stats.spawned, 1000);
    // Everything beyond the first 100 spawns overwrote a particle younger than 1 s.
    assert_eq!(stats.recycled_alive, 900, "{stats:?}");
    assert_eq!(alive_of(&sim.read_particles(0).expect("read")), 100);
    // Enough capacity: nothing recycled.
    let ok = Emitter {
        capacity: 1200,
        ..plain_emitter()
    };
    let sim = run_gpu(&ctx, &bare_effect(ok), 1.0 / 120.0, 240);
    assert_eq!(sim.planner.emitters[0].stats.recycled_alive, 0);
}

/// A capacity beyond the device's storage-binding limit fails with the limit's name.
#[test]
fn capacity_beyond_device_limit_names_the_limit() {
    let ctx = gpu();
    let too_big = (ctx.max_capacity() + 1).min(ignis::effect::MAX_CAPACITY as u64) as u32;
    let e = Emitter {
        capacity: too_big.max(ctx.max_capacity() as u32 + 1),
        ..plain_emitter()
    };
    if (e.capacity as u64) <= ctx.max_capacity() {
        panic!("device allows more than MAX_CAPACITY; test needs a larger capacity");
    }
    match GpuSim::new(&ctx, ShaderLibrary::embedded(), &bare_effect(e)) {
        Err(SimError::Gpu(err @ GpuError::CapacityTooLarge { .. })) => {
            let msg = err.to_string();
            assert!(
                msg.contains("max_storage_buffer_binding_size") || msg.contains("max_buffer_size"),
                "{msg}"
            );
            assert!(msg.contains("lower the capacity"), "{msg}");
        }
        Err(other) => panic!("wrong error: {other}"),
        Ok(_) => panic!("capacity {} accepted beyond the limit", too_big),
    }
}

fn spawn_once(
    ctx: &ignis::testing::gpu::GpuContext,
    e: Emitter,
) -> Vec<ignis::testing::gpu::types::Particle> {
    let sim = run_gpu(ctx, &bare_effect(e), 1.0 / 120.0, 1);
    // Positions are stored relative to the emitter's simulation origin.
    let origin = sim.planner.emitters[0].origin().as_vec3();
    sim.read_particles(0)
        .expect("read")
        .into_iter()
        .filter(|p| p.is_alive())
        .map(|mut p| {
            for k in 0..3 {
                p.pos_age[k] += origin[k];
            }
            p
        })
        .collect()
}

/// Every shape: all spawned positions lie inside/on the shape under its transform.
#[test]
fn every_shape_spawns_inside_itself() {
    let ctx = gpu();
    let transform = Transform {
        position_m: [1.0, 2.0, -3.0],
        rotation_deg: [20.0, 45.0, -10.0],
    };
    let emitter_from_world = transform.world_from_emitter().inverse();
    type Inside = Box<dyn Fn(Vec3) -> bool>;
    let cases: Vec<(Shape, Inside)> = vec![
        (Shape::Point, Box::new(|p: Vec3| p.length() < 1e-5)),
        (
            Shape::Sphere {
                radius_m: 0.5,
                surface_only: false,
            },
            Box::new(|p: Vec3| p.length() <= 0.5 + 1e-5),
        ),
        (
            Shape::Sphere {
                radius_m: 0.5,
                surface_only: true,
            },
            Box::new(|p: Vec3| (p.length() - 0.5).abs() < 1e-5),
        ),
        (
            Shape::Disc {
                radius_m: 0.4,
                normal: [0.0, 0.0, 1.0],
            },
            Box::new(|p: Vec3| p.z.abs() < 1e-5 && p.truncate().length() <= 0.4 + 1e-5),
        ),
        (
            Shape::Box {
                half_extents_m: [0.1, 0.2, 0.3],
            },
            Box::new(|p: Vec3| {
                p.x.abs() <= 0.1 + 1e-5 && p.y.abs() <= 0.2 + 1e-5 && p.z.abs() <= 0.3 + 1e-5
            }),
        ),
        (
            Shape::Cone {
                angle_deg: 20.0,
                radius_m: 0.25,
            },
            // Base disc normal to the direction (+Y here).
            Box::new(|p: Vec3| {
                p.y.abs() < 1e-5 && Vec3::new(p.x, 0.0, p.z).length() <= 0.25 + 1e-5
            }),
        ),
        (
            Shape::Line {
                a_m: [-0.5, 0.0, 0.0],
                b_m: [0.5, 0.2, 0.0],
            },
            Box::new(|p: Vec3| {
                let a = Vec3::new(-0.5, 0.0, 0.0);
                let d = Vec3::new(1.0, 0.2, 0.0);
                let t = (p - a).dot(d) / d.length_squared();
                (-1e-5..=1.0 + 1e-5).contains(&t) && (a + d * t - p).length() < 1e-5
            }),
        ),
    ];
    for (shape, inside) in cases {
        let e = Emitter {
            capacity: 4000,
            spawn_rate_per_sec: ignis::effect::Param::Constant(3000.0 * 120.0),
            max_spawn_per_sec: 3000.0 * 120.0,
            shape: shape.clone(),
            transform: transform.clone(),
            ..plain_emitter()
        };
        let born = spawn_once(&ctx, e);
        assert_eq!(born.len(), 3000, "{shape:?}");
        let mut extent: f32 = 0.0;
        for p in &born {
            let local = emitter_from_world.transform_point3(p.position());
            assert!(inside(local), "{shape:?}: {local} is outside");
            extent = extent.max(local.length());
        }
        if !matches!(shape, Shape::Point) {
            assert!(
                extent > 0.2,
                "{shape:?}: spawns do not cover the shape (max extent {extent})"
            );
        }
    }
}

/// Directions stay within the spread cone and fill it; a cone shape uses its own angle.
#[test]
fn direction_spread_is_respected() {
    let ctx = gpu();
    for (shape, spread, direction) in [
        (Shape::Point, 20.0f32, [0.0, 1.0, 0.0]),
        (Shape::Point, 60.0, [1.0, 1.0, 0.0]),
        (
            Shape::Cone {
                angle_deg: 35.0,
                radius_m: 0.1,
            },
            35.0,
            [0.0, 0.0, 1.0],
        ),
    ] {
        let e = Emitter {
            capacity: 4000,
            spawn_rate_per_sec: ignis::effect::Param::Constant(3000.0 * 120.0),
            max_spawn_per_sec: 3000.0 * 120.0,
            shape: shape.clone(),
            direction,
            spread_deg: if matches!(shape, Shape::Cone { .. }) {
                5.0
            } else {
                spread
            },
            speed_m_per_s: Range::new(1.0, 2.0),
            ..plain_emitter()
        };
        let axis = Vec3::from(direction).normalize();
        let born = spawn_once(&ctx, e);
        let mut max_angle: f32 = 0.0;
        for p in &born {
            let v = p.velocity();
            let speed = v.length();
            assert!((0.999..=2.001).contains(&speed), "speed {speed}");
            let angle = v.normalize().dot(axis).clamp(-1.0, 1.0).acos().to_degrees();
            assert!(angle <= spread + 0.01, "{shape:?}: {angle}° > {spread}°");
            max_angle = max_angle.max(angle);
        }
        assert!(
            max_angle > spread * 0.95,
            "{shape:?}: cone not filled (max {max_angle}°)"
        );
    }
}

/// Same seed ⇒ byte-identical state; another seed ⇒ different state.
#[test]
fn deterministic_state_for_a_seed() {
    let ctx = gpu();
    let effect = Effect::default_campfire();
    let run = |seed: u32| {
        let mut e = effect.clone();
        e.seed = seed;
        let sim = run_gpu(&ctx, &e, 1.0 / 120.0, 150);
        (0..e.emitters.len())
            .flat_map(|i| {
                bytemuck::cast_slice::<_, u8>(&sim.read_particles(i).expect("read")).to_vec()
            })
            .collect::<Vec<u8>>()
    };
    let a = run(7);
    let b = run(7);
    let c = run(8);
    assert!(a == b, "same seed gave different bytes");
    assert!(a != c, "different seeds gave the same bytes");
}

/// Bursts fire once at their time, in full.
#[test]
fn bursts_fire_once() {
    let ctx = gpu();
    let e = Emitter {
        spawn_rate_per_sec: ignis::effect::Param::Constant(0.0),
        bursts: vec![
            Burst {
                time_secs: 0.1,
                count: 500,
            },
            Burst {
                time_secs: 0.5,
                count: 200,
            },
        ],
        ..plain_emitter()
    };
    let sim = run_gpu(&ctx, &bare_effect(e), 1.0 / 120.0, 120);
    assert_eq!(sim.planner.emitters[0].stats.spawned, 700);
    // Lifetime 1 s: at t = 1 s the first burst (t = 0.1) is still alive, all 700 are.
    assert_eq!(alive_of(&sim.read_particles(0).expect("read")), 700);
}

/// The world transform maps the local spawn point to the emitter's position.
#[test]
fn point_emitter_spawns_at_its_transform() {
    let ctx = gpu();
    let e = Emitter {
        transform: Transform {
            position_m: [5.0, -2.0, 1.5],
            rotation_deg: [0.0, 90.0, 0.0],
        },
        ..plain_emitter()
    };
    let born = spawn_once(&ctx, e);
    assert!(!born.is_empty());
    for p in born {
        assert!((p.position() - Vec3::new(5.0, -2.0, 1.5)).length() < 1e-5);
    }
    let m = Transform {
        position_m: [0.0; 3],
        rotation_deg: [0.0, 90.0, 0.0],
    }
    .world_from_emitter();
    assert!((m.transform_vector3(Vec3::X) - Vec3::new(0.0, 0.0, -1.0)).length() < 1e-6);
    let _ = Mat4::IDENTITY;
}

/// The editor's pass timer: timestamps around real passes come back asynchronously
/// through the ring, labelled, without a blocking wait in the frame.
#[test]
fn pass_timer_reports_labelled_spans() {
    let ctx = gpu();
    let Some(mut timer) = ignis::testing::gpu::timer::PassTimer::new_even_on_cpu(&ctx) else {
        panic!("the adapter lacks timestamp queries inside encoders (lavapipe has them)");
    };
    let effect = Effect::default_campfire();
    let mut sim = GpuSim::new(&ctx, ShaderLibrary::embedded(), &effect).expect("sim");
    for _frame in 0..6 {
        assert!(timer.begin_frame() || !timer.latest.is_empty());
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        let plans = sim.plan(&effect, 1.0 / 120.0, 2);
        timer.scope(&mut enc, "update", |enc| sim.record(enc, &effect, &plans));
        timer.scope(&mut enc, "nothing", |_| ());
        timer.end_frame(&mut enc);
        ctx.queue.submit([enc.finish()]);
        timer.after_submit();
        std::thread::sleep(std::time::Duration::from_millis(20));
        timer.poll(&ctx);
    }
    let labels: Vec<&str> = timer.latest.iter().map(|s| s.0).collect();
    assert_eq!(labels, vec!["update", "nothing"]);
    assert!(timer.latest.iter().all(|s| s.1 >= 0.0 && s.1.is_finite()));
}

/// A fountain for comparing state layouts: random speeds (1–3 m/s) and lifetimes
/// (0.5–1.5 s), a 30° spread, gravity, buoyancy, linear drag and wind.
fn fountain() -> Emitter {
    let mut e = plain_emitter();
    e.lifetime_secs = ignis::effect::Range::new(0.5, 1.5);
    e.speed_m_per_s = ignis::effect::Range::new(1.0, 3.0);
    e.spread_deg = 30.0;
    e.forces.gravity_m_per_s2 = [0.0, -9.81, 0.0];
    e.forces.buoyancy_m_per_s2 = 12.0;
    e.forces.drag_per_sec = 1.2;
    e.forces.wind_m_per_s = [0.3, 0.0, 0.0];
    e
}

/// Runs `e` on the full state and with `compact` applied (which must validate), `steps`
/// steps of `dt` each: (full, compact).
fn run_full_and_compact(
    ctx: &ignis::testing::gpu::GpuContext,
    e: Emitter,
    compact: impl Fn(&mut Emitter),
    dt: f32,
    steps: u32,
) -> (GpuSim, GpuSim) {
    let full = bare_effect(e);
    let mut other = full.clone();
    compact(&mut other.emitters[0]);
    assert!(other.validate().is_ok());
    (
        run_gpu(ctx, &full, dt, steps),
        run_gpu(ctx, &other, dt, steps),
    )
}

/// The packed 20-byte state follows the full state: the same slots alive, lifetimes
/// re-derived exactly, ages within the unorm16 step, positions and velocities within
/// f16 rounding accumulated over the run; the alive count and the rendered frame agree.
#[test]
fn packed_state_follows_the_full_state() {
    let ctx = gpu();
    let (dt, steps) = (1.0 / 120.0, 240);
    let mut e = fountain();
    e.capacity = 3000;
    e.spawn_rate_per_sec = ignis::effect::Param::Constant(2000.0);
    let (a, b) = run_full_and_compact(&ctx, e, |e| e.packed_state = true, dt, steps);
    let pa = a.read_particles(0).expect("full");
    let pb = b.read_particles(0).expect("packed");
    assert_eq!(pa.len(), pb.len());
    let mut worst_pos = 0.0f32;
    let mut worst_vel = 0.0f32;
    let mut worst_age = 0.0f32;
    let mut alive = 0;
    let mut borderline = 0;
    for (slot, (p, q)) in pa.iter().zip(&pb).enumerate() {
        if p.is_alive() != q.is_alive() {
            // Only a particle at the end of its life may die one step apart: the life
            // fraction is rounded (dithered) to 1/65535 each step.
            let (life, age) = (
                p.vel_life[3].max(q.vel_life[3]),
                p.pos_age[3].max(q.pos_age[3]),
            );
            assert!(
                (life - age).abs() <= dt + life * (age / dt + 1.0) / 65535.0,
                "slot {slot}: {p:?} vs {q:?}"
            );
            borderline += 1;
            continue;
        }
        if !p.is_alive() {
            continue;
        }
        alive += 1;
        let life = p.vel_life[3];
        assert!(
            (q.vel_life[3] - life).abs() <= 1e-6 * life,
            "slot {slot}: lifetime {} re-derived as {}",
            life,
            q.vel_life[3]
        );
        // Each step rounds the life fraction to 1/65535 (dithered: < one step each time).
        let rounding_steps = (p.pos_age[3] / dt).ceil() + 1.0;
        worst_age = worst_age.max((q.pos_age[3] - p.pos_age[3]).abs() / life);
        assert!(
            (q.pos_age[3] - p.pos_age[3]).abs() <= life * rounding_steps / 65535.0 + 1e-6,
            "slot {slot}: age {} vs {}",
            p.pos_age[3],
            q.pos_age[3]
        );
        worst_pos = worst_pos.max((q.position() - p.position()).length());
        worst_vel = worst_vel.max((q.velocity() - p.velocity()).length());
    }
    println!(
        "packed vs full after {steps} steps: worst |Δx| {worst_pos:.2e} m, |Δv| {worst_vel:.2e} \
            m/s, |Δage|/life {worst_age:.2e}, {borderline} of {alive} at the end of life differ \
            in liveness"
    );
    assert!(alive > 1500, "{alive} alive");
    assert!(
        borderline * 100 <= alive,
        "{borderline} liveness mismatches"
    );
    // f16 velocity with dithered rounding: a random walk of ≤ 180 steps of ≤ one f16 step
    // (2⁻⁹ m/s at 2–4 m/s): √180 · 2⁻⁹ ≈ 0.026 m/s is a 1σ bound per component, and
    // the worst of 2000 particles stays under it; positions integrate the same walk.
    assert!(worst_vel < 0.03, "velocity deviation {worst_vel} m/s");
    assert!(worst_pos < 0.03, "position deviation {worst_pos} m");
    assert!(worst_pos > 0.0, "packing must round something");
    let (ca, cb) = (
        a.read_counters(0).expect("count")[0],
        b.read_counters(0).expect("count")[0],
    );
    assert!(ca.abs_diff(cb) <= borderline as u32, "alive {ca} vs {cb}");
}

/// The tiny 10-byte state follows the full state: ages exact (from the birth table, not
/// accumulated), lifetimes re-derived exactly, so the same slots alive; positions and
/// velocities within the dithered f16 / shared-exponent rounding accumulated over the run.
#[test]
fn tiny_state_follows_the_full_state() {
    let ctx = gpu();
    let (dt, steps) = (1.0 / 120.0, 240);
    let mut e = fountain();
    e.capacity = 3001;
    e.spawn_rate_per_sec = ignis::effect::Param::Constant(1200.0);
    // An uneven birth table: bursts between the steady steps (the lookup's guess from the
    // mean rate misses, its search must not).
    e.bursts = vec![
        Burst {
            time_secs: 0.8,
            count: 400,
        },
        Burst {
            time_secs: 1.5,
            count: 300,
        },
    ];
    let (a, b) = run_full_and_compact(&ctx, e, |e| e.tiny_state = true, dt, steps);
    let pa = a.read_particles(0).expect("full");
    let pb = b.read_particles(0).expect("tiny");
    assert_eq!(pa.len(), pb.len());
    let (mut alive, mut borderline) = (0, 0);
    let (mut sum_pos2, mut sum_vel2, mut worst_pos, mut worst_vel, mut worst_age) =
        (0.0f64, 0.0f64, 0.0f32, 0.0f32, 0.0f32);
    for (slot, (p, q)) in pa.iter().zip(&pb).enumerate() {
        if p.is_alive() != q.is_alive() {
            // Only where f32 age sums and the exact age straddle the lifetime.
            let (life, age) = (
                p.vel_life[3].max(q.vel_life[3]),
                p.pos_age[3].max(q.pos_age[3]),
            );
            assert!((life - age).abs() <= 1e-4, "slot {slot}: {p:?} vs {q:?}");
            borderline += 1;
            continue;
        }
        if !p.is_alive() {
            continue;
        }
        alive += 1;
        assert!(
            (q.vel_life[3] - p.vel_life[3]).abs() <= 1e-6 * p.vel_life[3],
            "slot {slot}: lifetime"
        );
        // The full state sums dt each step in f32; the tiny age is t − birth.
        worst_age = worst_age.max((q.pos_age[3] - p.pos_age[3]).abs());
        let dx = (q.position() - p.position()).length();
        let dv = (q.velocity() - p.velocity()).length();
        sum_pos2 += f64::from(dx * dx);
        sum_vel2 += f64::from(dv * dv);
        worst_pos = worst_pos.max(dx);
        worst_vel = worst_vel.max(dv);
    }
    let rms_pos = (sum_pos2 / alive as f64).sqrt();
    let rms_vel = (sum_vel2 / alive as f64).sqrt();
    println!(
        "tiny vs full after {steps} steps: |Δx| rms {rms_pos:.2e} worst {worst_pos:.2e} m, |Δv| \
            rms {rms_vel:.2e} worst {worst_vel:.2e} m/s, |Δage| {worst_age:.2e} s, {borderline} \
            of {alive} differ in liveness"
    );
    assert!(alive > 1500, "{alive} alive");
    assert!(borderline <= 2, "{borderline} liveness mismatches");
    assert!(worst_age < 1e-4, "age deviation {worst_age} s");
    // Velocity: 8 significant bits of the largest component (≤ 2⁻⁶ m/s at 2–4 m/s),
    // dithered each step: a random walk damped by the drag; positions integrate it.
    assert!(rms_vel < 0.05, "velocity rms deviation {rms_vel} m/s");
    assert!(rms_pos < 0.03, "position rms deviation {rms_pos} m");
    assert!(
        worst_vel < 0.25 && worst_pos < 0.15,
        "worst {worst_vel} m/s, {worst_pos} m"
    );
    assert!(worst_pos > 0.0, "tiny state must round something");
    let (ca, cb) = (
        a.read_counters(0).expect("count")[0],
        b.read_counters(0).expect("count")[0],
    );
    assert!(ca.abs_diff(cb) <= borderline as u32, "alive {ca} vs {cb}");
}

/// The tiny state's birth table outgrows its first size (1024 steps) with small steps and
/// long lives, and a capacity change restarts the tiny pool cleanly: the alive set matches
/// the full state's before, and after the restart only particles born since are alive.
#[test]
fn tiny_birth_table_grows_and_restarts() {
    let ctx = gpu();
    let mut e = plain_emitter();
    e.capacity = 4000;
    e.spawn_rate_per_sec = ignis::effect::Param::Constant(1500.0);
    e.lifetime_secs = ignis::effect::Range::new(1.5, 2.5);
    e.speed_m_per_s = ignis::effect::Range::new(0.5, 1.0);
    e.spread_deg = 20.0;
    let full = bare_effect(e);
    let mut tiny = full.clone();
    tiny.emitters[0].tiny_state = true;
    let dt = 1.0 / 1000.0;
    let mut a = run_gpu(&ctx, &full, dt, 2600);
    let mut b = run_gpu(&ctx, &tiny, dt, 2600);
    let alive = |sim: &GpuSim| alive_of(&sim.read_particles(0).expect("read"));
    let (na, nb) = (alive(&a), alive(&b));
    assert!(na > 2500, "{na} alive");
    assert!(na.abs_diff(nb) <= 2, "full {na} vs tiny {nb}");
    // Every step spawns 1–2: about 2000 live batches, beyond the first table's 1024.
    let mut grown = tiny.clone();
    grown.emitters[0].capacity = 5000;
    let mut full_grown = full.clone();
    full_grown.emitters[0].capacity = 5000;
    b.step(&grown, dt, 10).expect("step");
    a.step(&full_grown, dt, 10).expect("step");
    let after = alive(&b);
    assert!(
        (14..=16).contains(&after),
        "after the restart {after} alive (15 born)"
    );
    b.step(&grown, dt, 500).expect("step");
    let later = alive(&b);
    assert!(
        (760..=765).contains(&later),
        "{later} alive 0.51 s after the restart"
    );
    assert_eq!(b.read_counters(0).expect("count")[0] as usize, later);
}

/// Packed and full state draw the same frame (both draw paths read packed state).
#[test]
fn packed_state_renders_like_the_full_state() {
    compact_state_renders_like_the_full_state(|e| e.packed_state = true, 0.05);
}

/// Tiny and full state draw nearly the same frame (both draw paths and the sort read tiny
/// state; the turbulent flames amplify the rounding, so the bound is looser).
#[test]
fn tiny_state_renders_like_the_full_state() {
    compact_state_renders_like_the_full_state(|e| e.tiny_state = true, 0.2);
}

fn compact_state_renders_like_the_full_state(set: impl Fn(&mut Emitter), max_mean: f64) {
    let ctx = gpu();
    let mut full = ignis::effect::Effect::default_campfire();
    full.post.bloom = None;
    // Stateless emitters keep no state to pack: every emitter steps its pool.
    for e in &mut full.emitters {
        e.stateless = false;
    }
    let mut packed = full.clone();
    for e in &mut packed.emitters {
        set(e);
    }
    let render = |effect: ignis::effect::Effect| {
        let mut run = headless_after(&ctx, effect, 60);
        (
            run.render((240, 180)).expect("render"),
            run.alive().expect("alive"),
        )
    };
    let (a, alive_a) = render(full);
    let (b, alive_b) = render(packed);
    assert_eq!(alive_a, alive_b);
    let (mean, _) = image_diff(&a, &b);
    println!("mean |difference| {mean:.3}");
    assert!(mean < max_mean, "mean |difference| {mean}");
    assert!(
        a.pixels().filter(|p| p[0] > 100).count() > 500,
        "fire drawn"
    );
}

/// Tiny state between two steps: frames at 50 fps over 20 Hz steps draw each particle
/// between its state before the last step and after it, where the state before is the
/// same particle one step younger (for a particle born in the last step, its slot's last
/// occupant: not drawn between). Fast sparks kept in tiny state draw the full state's
/// frame, their ages from the birth table as the draw reads it.
#[test]
fn tiny_state_draws_between_steps_like_the_full_state() {
    let ctx = gpu();
    let mut e = common::plain_emitter();
    e.stateless = false;
    e.capacity = 2048;
    e.spawn_rate_per_sec = ignis::effect::Param::Constant(2000.0);
    e.lifetime_secs = ignis::effect::Range::new(0.8, 0.8);
    e.speed_m_per_s = ignis::effect::Range::new(3.0, 3.0);
    e.spread_deg = 40.0;
    e.look.size_m = ignis::effect::Param::Constant(0.15);
    e.look.intensity = 0.05;
    let mut full = bare_effect(e);
    full.time.step_secs = 1.0 / 20.0;
    let mut tiny = full.clone();
    tiny.emitters[0].tiny_state = true;
    // 0.74 s: the last frame 0.8 of the way from the step before to the last.
    let render = |effect: ignis::effect::Effect| {
        headless_frames(&ctx, effect, 37, 1.0 / 50.0)
            .render((160, 120))
            .expect("render")
    };
    let (a, b) = (render(full), render(tiny));
    let (mean, max) = image_diff(&a, &b);
    println!("tiny between steps: mean |difference| {mean:.4}, max {max}");
    assert!(common::total_light(&a) > 1e4, "the sparks drew little");
    // Measured 0.135/255 mean, 8/255 max (the tiny state's rounding); drawn at the last
    // step's state instead, 1.14 and 58.
    assert!(
        mean < 0.3 && max <= 16,
        "tiny between steps: {mean:.4}/255 mean, {max}/255 max"
    );
}

/// The update visits only the ring's live window (plus the step's spawns): with random and
/// then equal lifetimes, a rate change and lifetimes shortened and then lengthened mid-run, the GPU
/// keeps exactly the CPU reference's alive set (the CPU visits every slot), and the
/// windows stay far shorter than the pool.
#[test]
fn update_window_skips_only_dead_slots() {
    let ctx = gpu();
    let e = Emitter {
        capacity: 8192,
        spawn_rate_per_sec: ignis::effect::Param::Constant(900.0),
        lifetime_secs: Range::new(0.2, 1.0),
        ..plain_emitter()
    };
    let mut effect = bare_effect(e);
    let mut sim = GpuSim::new(&ctx, ShaderLibrary::embedded(), &effect).expect("sim");
    let mut planner = ignis::testing::sim::EffectPlanner::default();
    let mut cpu = ignis::testing::sim::CpuSim::for_emitter(&effect.emitters[0]);
    let dt = 1.0 / 90.0;
    let mut longest = 0;
    for step in 0..400 {
        match step {
            100 => {
                // Equal lifetimes: the youngest of a batch dies last, exactly at the bound.
                effect.emitters[0].spawn_rate_per_sec = ignis::effect::Param::Constant(2500.0);
                effect.emitters[0].lifetime_secs = Range::new(0.4, 0.4);
            }
            180 => effect.emitters[0].lifetime_secs = Range::new(0.05, 0.1),
            300 => effect.emitters[0].lifetime_secs = Range::new(0.5, 2.0),
            _ => {}
        }
        let plan = planner.plan_step(&effect, dt);
        let p = plan[0].expect("enabled");
        longest = longest.max(p.update_window[1]);
        if step == 299 {
            // 2500/s × 0.1 s lifetimes: ~250 spawns alive, plus a few steps' margin.
            assert!(p.update_window[1] < 400, "window {:?}", p.update_window);
        }
        cpu.step(&p);
        sim.record_and_submit(&effect, &[plan]);
        if step % 7 == 0 {
            let gpu = sim.read_particles(0).expect("read");
            for (slot, (g, c)) in gpu.iter().zip(&cpu.particles).enumerate() {
                assert_eq!(
                    g.is_alive(),
                    c.is_alive(),
                    "step {step}, slot {slot}: GPU {g:?} vs CPU {c:?}"
                );
            }
        }
    }
    // Lengthening the lifetimes makes the window conservative (packed state re-derives
    // lifetimes from the current range), still far from the 8192 slots.
    assert!(longest < 4096, "longest update window {longest}");
}

/// A planner given a revision builds each emitter's step-independent block once and
/// patches it per step: the blocks equal those built anew every step, and a new revision
/// (an edit, a move, a new seed) takes effect at once.
#[test]
fn revised_plans_equal_plans_built_anew() {
    let mut effect = ignis::Effect::default_campfire();
    let (mut cached, mut fresh) = (
        ignis::testing::sim::EffectPlanner::default(),
        ignis::testing::sim::EffectPlanner::default(),
    );
    let mut revision = 1;
    for step in 0..300 {
        match step {
            60 => effect.seed = 99,
            120 => effect.emitters[0].transform.position_m = [1.5, 0.2, -3.0],
            200 => effect.emitters[1].forces.drag_per_sec += 0.5,
            _ => {}
        }
        if matches!(step, 60 | 120 | 200) {
            revision += 1;
        }
        let dt = if step % 3 == 0 {
            1.0 / 90.0
        } else {
            1.0 / 144.0
        };
        let expected = fresh.plan_step(&effect, dt);
        let mut got = vec![None; effect.emitters.len()];
        cached.plan_step_with(&effect, Some(revision), dt, |i, p| got[i] = p.copied());
        for (i, (g, e)) in got.iter().zip(&expected).enumerate() {
            let bytes = |p: &Option<ignis::testing::gpu::types::SimParams>| {
                p.map(|p| bytemuck::bytes_of(&p).to_vec())
            };
            assert_eq!(bytes(g), bytes(e), "step {step}, emitter {i}");
        }
    }
}
