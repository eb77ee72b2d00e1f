//! Numerical stability at the extremes, convergence orders and frame-rate independence,
//! on a real adapter.
// The editor, the `ignis` binary or the benches: the default `editor` feature.
#![cfg(feature = "editor")]

mod common;

use common::*;
use glam::Vec3;
use ignis::effect::{Effect, Emitter, Integrator, Range, Transform};
use ignis::testing::bench::accuracy::{self, Scene};
use ignis::testing::gpu::types::Particle;
use ignis::testing::shaders::ShaderLibrary;
use ignis::testing::sim::{EffectPlanner, GpuSim};

/// A pool of `n` particles at the origin with velocity `v0`, lifetime 1e4 s.
fn moving(n: usize, v0: Vec3) -> Vec<Particle> {
    vec![
        Particle {
            pos_age: [0.0, 0.0, 0.0, 0.0],
            vel_life: [v0.x, v0.y, v0.z, 1e4],
        };
        n
    ]
}

/// Pure linear drag, rate 0: runs `steps` steps from `initial` and returns the state.
fn run_drag(
    ctx: &ignis::testing::gpu::GpuContext,
    integrator: Integrator,
    k: f32,
    accel: f32,
    dt: f32,
    steps: u32,
    initial: &[Particle],
) -> (Vec<Particle>, u32) {
    let mut e = Emitter {
        capacity: initial.len() as u32,
        spawn_rate_per_sec: ignis::effect::Param::Constant(0.0),
        integrator,
        lifetime_secs: Range::new(1e4, 1e4),
        ..plain_emitter()
    };
    e.forces.drag_per_sec = k;
    e.forces.gravity_m_per_s2 = [0.0, -accel, 0.0];
    let effect = bare_effect(e);
    let mut sim = GpuSim::new(ctx, ShaderLibrary::embedded(), &effect).expect("sim");
    sim.write_particles(0, initial).expect("write");
    sim.step(&effect, dt, steps).expect("step");
    (
        sim.read_particles(0).expect("read"),
        sim.read_counters(0).expect("counters")[1],
    )
}

/// Each integrator behaves as its stability bound for linear drag predicts: stable just
/// below k·dt = bound (explicit/semi-implicit Euler, Verlet, Heun: 2; RK4: ≈ 2.785),
/// divergent just above; the exponential integrator is stable at any k·dt.
#[test]
fn drag_stability_bounds_are_exact() {
    let ctx = gpu();
    let dt = 0.01;
    for integrator in Integrator::ALL {
        let Some(bound) = integrator.drag_stability_limit() else {
            continue;
        };
        for (factor, stable) in [(0.97f32, true), (1.03, false)] {
            let k = bound * factor / dt;
            let (state, _) = run_drag(&ctx, integrator, k, 0.0, dt, 400, &moving(64, Vec3::X));
            let speed = state[0].velocity().length();
            if stable {
                assert!(
                    state[0].is_alive() && speed <= 1.0,
                    "{integrator:?} at k·dt = {}: |v| = {speed}",
                    k * dt
                );
            } else {
                assert!(
                    !state[0].is_alive() || speed > 10.0,
                    "{integrator:?} at k·dt = {} did not diverge: |v| = {speed}",
                    k * dt
                );
            }
        }
    }
}

/// The exponential integrator stays finite and bounded for dt from 1e-5 s to 1 s, drag up
/// to 1000/s, acceleration up to 1e4 m/s² and speeds up to 1e4 m/s.
#[test]
fn exponential_integrator_is_stable_across_the_range() {
    let ctx = gpu();
    for dt in [1e-5f32, 1e-3, 0.1, 1.0] {
        for k in [0.0f32, 1.0, 100.0, 1000.0] {
            for accel in [0.0f32, 1e4] {
                let v0 = Vec3::new(1e4, 0.0, -1e4);
                let steps = 50;
                let (state, killed) = run_drag(
                    &ctx,
                    Integrator::Exponential,
                    k,
                    accel,
                    dt,
                    steps,
                    &moving(16, v0),
                );
                assert_eq!(killed, 0);
                let t = dt * steps as f32;
                // |v| never exceeds max(|v0|, terminal speed) (+ a·t when k = 0).
                let terminal = if k > 0.0 { accel / k } else { accel * t };
                let bound =
                    v0.length().max(terminal) * 1.0001 + accel * t * (k == 0.0) as u8 as f32;
                for p in &state {
                    assert!(p.is_alive() && p.position().is_finite() && p.velocity().is_finite());
                    assert!(
                        p.velocity().length() <= bound,
                        "dt {dt} k {k} a {accel}: |v| = {} > {bound}",
                        p.velocity().length()
                    );
                }
            }
        }
    }
}

/// What escapes (explicit Euler at k·dt = 5, speed 1e4) becomes non-finite, is killed and
/// counted — and a stable emitter next to it is untouched.
#[test]
fn nonfinite_guard_kills_and_counts_without_poisoning_others() {
    let ctx = gpu();
    let mut bad = Emitter {
        name: "unstable".into(),
        capacity: 100,
        spawn_rate_per_sec: ignis::effect::Param::Constant(0.0),
        integrator: Integrator::ExplicitEuler,
        ..plain_emitter()
    };
    bad.forces.drag_per_sec = 500.0;
    let good = Emitter {
        name: "stable".into(),
        capacity: 100,
        spawn_rate_per_sec: ignis::effect::Param::Constant(0.0),
        ..plain_emitter()
    };
    let effect = Effect {
        emitters: vec![bad, good],
        ..Effect::default()
    };
    let mut sim = GpuSim::new(&ctx, ShaderLibrary::embedded(), &effect).expect("sim");
    sim.write_particles(0, &moving(100, Vec3::new(1e4, 0.0, 0.0)))
        .expect("write");
    sim.write_particles(1, &moving(100, Vec3::new(1.0, 0.0, 0.0)))
        .expect("write");
    sim.step(&effect, 0.01, 100).expect("step");
    let [alive, killed] = sim.read_counters(0).expect("counters");
    assert_eq!(
        (alive, killed),
        (0, 100),
        "every unstable particle is killed and counted"
    );
    assert!(
        sim.read_particles(0)
            .expect("read")
            .iter()
            .all(|p| !p.is_alive() && p.position().is_finite())
    );
    let good_state = sim.read_particles(1).expect("read");
    assert_eq!(sim.read_counters(1).expect("counters"), [100, 0]);
    for p in good_state {
        assert!((p.position().x - 1.0).abs() < 1e-4, "{p:?}");
    }
}

/// Every shipped preset's integrators are stable at a one-second step for their drag, and
/// a run of one-second steps stays finite.
#[test]
fn shipped_presets_survive_one_second_steps() {
    let ctx = gpu();
    let dir = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/presets"));
    let presets = ignis::preset::list(dir);
    assert!(!presets.is_empty());
    for path in presets {
        let loaded = ignis::preset::load(&path).expect("preset loads");
        // As shipped, and with every stateful emitter on the tiny 10-byte state.
        let mut tiny = loaded.clone();
        for e in &mut tiny.emitters {
            e.tiny_state = !e.stateless;
        }
        for effect in [loaded, tiny] {
            for e in &effect.emitters {
                if let Some(bound) = e.integrator.drag_stability_limit() {
                    assert!(
                        e.forces.drag_per_sec * 1.0 < bound,
                        "{}: {} k·dt at dt = 1 s is {}",
                        path.display(),
                        e.name,
                        e.forces.drag_per_sec
                    );
                }
            }
            let sim = run_gpu(&ctx, &effect, 1.0, 20);
            for i in 0..effect.emitters.len() {
                assert_eq!(
                    sim.read_counters(i).expect("counters")[1],
                    0,
                    "{}: {}: non-finite kills",
                    path.display(),
                    effect.emitters[i].name
                );
                assert!(
                    sim.read_particles(i)
                        .expect("read")
                        .iter()
                        .all(|p| p.position().is_finite())
                );
            }
        }
    }
}

/// 1e5 m from the origin the motion resolves exactly as at the origin: positions are kept
/// relative to the emitter (f32 at 1e5 would otherwise quantise to 8 mm), and the image
/// rendered with the camera moved along is the same.
#[test]
fn far_from_the_origin_motion_still_resolves() {
    let ctx = gpu();
    let near = Effect::default_campfire();
    let mut far = near.clone();
    let offset = [1e5f32, 0.0, -1e5];
    let shift = |p: &mut [f32; 3]| *p = (Vec3::from(*p) + Vec3::from(offset)).to_array();
    for e in &mut far.emitters {
        shift(&mut e.transform.position_m);
    }
    shift(&mut far.camera.target_m);
    let run = |effect: Effect| {
        let mut h = headless_after(&ctx, effect, 60);
        let img = h.render((160, 120)).expect("render");
        let state: Vec<Vec<Particle>> = (0..3)
            .map(|i| h.player.particles(h.instance, i).expect("read"))
            .collect();
        (img, state)
    };
    let (img_near, s_near) = run(near);
    let (img_far, s_far) = run(far);
    assert_eq!(s_near, s_far, "relative states must be identical");
    let diff: f64 = img_near
        .as_raw()
        .iter()
        .zip(img_far.as_raw())
        .map(|(a, b)| (*a as f64 - *b as f64).abs())
        .sum::<f64>()
        / img_near.as_raw().len() as f64;
    assert!(diff < 1.0, "mean pixel difference {diff}");
    // And the motion is real: particles moved centimetres per step, far below f32's 8 mm
    // spacing at 1e5 m — yet they are spread out, not snapped to a grid.
    let xs: std::collections::HashSet<u32> = s_far[1]
        .iter()
        .filter(|p| p.is_alive())
        .map(|p| p.pos_age[0].to_bits())
        .collect();
    assert!(xs.len() > 1000);
}

/// 10^6 steps of a looping emitter: spawn counts exact, time exact (f64 sum of steps),
/// the noise clock wrapped, the RNG key stream never repeating.
#[test]
fn a_million_steps_do_not_drift() {
    let e = Emitter {
        spawn_rate_per_sec: ignis::effect::Param::Constant(333.3),
        capacity: 2048,
        ..plain_emitter()
    };
    let effect = bare_effect(e);
    let mut planner = EffectPlanner::default();
    let dt = 1.0f32 / 120.0;
    let steps = 1_000_000u64;
    let mut first_keys = std::collections::HashSet::new();
    let mut last = None;
    for s in 0..steps {
        let p = planner.plan_step(&effect, dt)[0].expect("enabled");
        assert!((0.0..4096.0).contains(&p.wind_time[3]));
        if s < 2000 || s >= steps - 2000 {
            let base = (p.spawn_base_hi as u64) << 32 | p.spawn_base_lo as u64;
            for i in 0..p.spawn_count as u64 {
                let key = ignis::testing::rng::spawn_key(
                    p.seed,
                    p.emitter_salt,
                    ((base + i) % 2048) as u32,
                    base + i,
                );
                if s < 2000 {
                    first_keys.insert(key);
                } else {
                    assert!(
                        !first_keys.contains(&key),
                        "RNG key repeated at spawn {}",
                        base + i
                    );
                }
            }
        }
        last = Some(p);
    }
    let t = planner.time_secs;
    assert!(
        (t - steps as f64 * dt as f64).abs() < 1e-6,
        "time drifted: {t}"
    );
    let spawned = planner.emitters[0].stats.spawned as f64;
    assert!(
        (spawned - 333.3f32 as f64 * t).abs() <= 1.0,
        "spawned {spawned} vs {}",
        333.3f32 as f64 * t
    );
    assert!(last.is_some());
}

/// Long GPU run: ages stay within lifetimes, the alive count stays at rate × lifetime.
#[test]
fn long_gpu_run_keeps_ages_and_counts() {
    let ctx = gpu();
    let e = Emitter {
        spawn_rate_per_sec: ignis::effect::Param::Constant(400.0),
        capacity: 512,
        ..plain_emitter()
    };
    let effect = bare_effect(e);
    let sim = run_gpu(&ctx, &effect, 1.0 / 120.0, 20_000);
    let state = sim.read_particles(0).expect("read");
    let alive: Vec<&Particle> = state.iter().filter(|p| p.is_alive()).collect();
    assert!(
        (alive.len() as f64 - 400.0).abs() <= 1.0,
        "{} alive",
        alive.len()
    );
    assert!(
        alive
            .iter()
            .all(|p| p.pos_age[3] >= 0.0 && p.pos_age[3] < 1.0)
    );
}

/// Tiny-state ages stay exact late in a run: past 10⁵ s on the emitter's clock, where an f32
/// time has 8 ms steps, the ages from the birth table (double-single times) still match the
/// full state's summed ones, and the same particles are alive.
#[test]
fn tiny_ages_stay_exact_late_in_a_run() {
    let ctx = gpu();
    let e = Emitter {
        spawn_rate_per_sec: ignis::effect::Param::Constant(400.0),
        capacity: 1024,
        lifetime_secs: ignis::effect::Range::new(0.5, 1.0),
        ..plain_emitter()
    };
    let full = bare_effect(e);
    let mut tiny = full.clone();
    tiny.emitters[0].tiny_state = true;
    let run = |effect: &Effect| {
        let mut sim = GpuSim::new(&ctx, ShaderLibrary::embedded(), effect).expect("sim");
        // 1000 steps of 100 s (every particle dies within its step), then 1 s of 1/120 s.
        sim.step(effect, 100.0, 1000).expect("step");
        sim.step(effect, 1.0 / 120.0, 120).expect("step");
        sim.read_particles(0).expect("read")
    };
    let (a, b) = (run(&full), run(&tiny));
    let mut alive = 0;
    for (slot, (p, q)) in a.iter().zip(&b).enumerate() {
        assert_eq!(p.is_alive(), q.is_alive(), "slot {slot}: {p:?} vs {q:?}");
        if p.is_alive() {
            alive += 1;
            assert!(
                (p.pos_age[3] - q.pos_age[3]).abs() < 1e-4,
                "slot {slot}: age {} vs {}",
                p.pos_age[3],
                q.pos_age[3]
            );
        }
    }
    // About 300 born in the last second (400/s, lives of 0.5–1 s), and a few of the
    // last 100 s step's 1024 (no spawn cap: spread over the step, those born in its last
    // second may live on).
    assert!((290..=330).contains(&alive), "{alive} alive");
}

/// Capacity 1, capacities that are not multiples of the 256-wide workgroup, and zero
/// rate: exact counts, nothing non-finite.
#[test]
fn odd_capacities_and_zero_rate() {
    let ctx = gpu();
    for (capacity, rate) in [
        (1u32, 1000.0f32),
        (255, 100.0),
        (257, 200.0),
        (1000, 0.0),
        (1000, 500.0),
    ] {
        let e = Emitter {
            capacity,
            spawn_rate_per_sec: ignis::effect::Param::Constant(rate),
            ..plain_emitter()
        };
        let sim = run_gpu(&ctx, &bare_effect(e), 1.0 / 120.0, 240);
        let state = sim.read_particles(0).expect("read");
        assert_eq!(state.len(), capacity as usize);
        assert!(
            state
                .iter()
                .all(|p| p.position().is_finite() && p.velocity().is_finite())
        );
        let expected = (rate as f64).min(capacity as f64);
        let alive = alive_of(&state) as f64;
        assert!(
            (alive - expected).abs() <= 1.0,
            "capacity {capacity} rate {rate}: {alive} alive, expected {expected}"
        );
        assert_eq!(sim.read_counters(0).expect("counters")[0] as f64, alive);
    }
}

/// Convergence orders on scene 1 (closed form, the accuracy bench's scene, T = 2 s): each
/// within ±0.3 of theory (1, 1, 2, 2, 4); the exponential integrator at rounding level.
/// RK4's error is below f32 rounding (≈1e-7) at the bench's steps, so its order is
/// measured at dt = 1/8 … 1/4 s, where the error is 1e-6 … 2e-5.
#[test]
fn convergence_orders_match_theory() {
    let ctx = gpu();
    let (k, t) = (1.5f32, 2.0f64);
    let setup = accuracy::setup_scene(&ctx, Scene::ClosedForm, 256).expect("setup");
    let e = accuracy::scene_emitter(Scene::ClosedForm, Integrator::Rk4, 256);
    let a = e.forces.constant_acceleration().as_dvec3();
    let wind = Vec3::from(e.forces.wind_m_per_s).as_dvec3();
    let reference: Vec<glam::DVec3> = setup
        .initial
        .iter()
        .map(|p| {
            accuracy::exact_state(
                p.position().as_dvec3(),
                p.velocity().as_dvec3(),
                a,
                k as f64,
                wind,
                t,
            )
            .0
        })
        .collect();
    let dts = [1.0 / 240.0, 1.0 / 120.0, 1.0 / 60.0, 1.0 / 30.0, 1.0 / 15.0];
    let measure = |integrator: Integrator, dt: f64| -> f64 {
        let mut e = accuracy::scene_emitter(Scene::ClosedForm, integrator, 256);
        e.bursts.clear();
        e.forces.drag_per_sec = k;
        let effect = bare_effect(e);
        let mut sim = GpuSim::new(&ctx, ShaderLibrary::embedded(), &effect).expect("sim");
        sim.write_particles(0, &setup.initial).expect("write");
        sim.step(&effect, dt as f32, (t / dt).round() as u32)
            .expect("step");
        let fin = sim.read_particles(0).expect("read");
        let sum: f64 = setup
            .initial
            .iter()
            .zip(&fin)
            .zip(&reference)
            .map(|((p0, p1), r)| {
                ((p1.position().as_dvec3() - *r).length()
                    / (*r - p0.position().as_dvec3()).length())
                .powi(2)
            })
            .sum();
        (sum / fin.len() as f64).sqrt()
    };
    for (integrator, order) in [
        (Integrator::ExplicitEuler, 1.0),
        (Integrator::SemiImplicitEuler, 1.0),
        (Integrator::VelocityVerlet, 2.0),
        (Integrator::Heun, 2.0),
        (Integrator::Rk4, 4.0),
    ] {
        let steps: &[f64] = if integrator == Integrator::Rk4 {
            &[1.0 / 8.0, 1.0 / 6.0, 1.0 / 5.0, 1.0 / 4.0]
        } else {
            &dts
        };
        let errs: Vec<(f64, f64)> = steps
            .iter()
            .map(|dt| (*dt, measure(integrator, *dt)))
            .collect();
        eprintln!("{integrator:?}: {errs:?}");
        let measured = slope(&errs);
        assert!(
            (measured - order).abs() <= 0.3,
            "{integrator:?}: order {measured:.2}, theory {order} ({errs:?})"
        );
    }
    for dt in dts {
        let err = measure(Integrator::Exponential, dt);
        assert!(err < 1e-5, "exponential at dt {dt}: {err}");
    }
}

/// Least-squares slope of log error vs log dt over all points (every point here must be
/// at least 5× above the f32 rounding floor).
fn slope(points: &[(f64, f64)]) -> f64 {
    assert!(
        points.iter().all(|p| p.1 > 5e-7 && p.1.is_finite()),
        "points near the f32 floor: {points:?}"
    );
    let n = points.len() as f64;
    let (mx, my) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), p| (a + p.0.ln() / n, b + p.1.ln() / n));
    let sxy: f64 = points
        .iter()
        .map(|p| (p.0.ln() - mx) * (p.1.ln() - my))
        .sum();
    let sxx: f64 = points.iter().map(|p| (p.0.ln() - mx).powi(2)).sum();
    sxy / sxx
}

/// Fixed step: the default campfire's final state is bit-identical whatever the frame
/// rate (30, 60, 144, 240 fps and a jittered sequence).
#[test]
fn fixed_step_is_frame_rate_independent() {
    let ctx = gpu();
    let hashes = accuracy::fixed_step_hashes(&ctx).expect("runs");
    for w in hashes.windows(2) {
        assert_eq!(
            (w[0].1, w[0].2),
            (w[1].1, w[1].2),
            "{} vs {}",
            w[0].0,
            w[1].0
        );
    }
    let _ = Transform::default();
}

/// The stability warning agrees with the GPU on both sides of its boundary: under a drag
/// of 240/s, explicit and semi-implicit Euler at k·dt = 1.85 are called stable and their
/// particles' velocities decay on the GPU; at k·dt = 2.18 they are called unstable — the
/// warning names the drag and a step that would be stable — and the velocities blow up.
#[test]
fn the_stability_warning_agrees_with_the_gpu_on_both_sides() {
    let ctx = gpu();
    for integrator in [Integrator::ExplicitEuler, Integrator::SemiImplicitEuler] {
        for (step, unstable) in [(1.0 / 130.0, false), (1.0 / 110.0, true)] {
            let e = Emitter {
                spawn_rate_per_sec: ignis::effect::Param::Constant(200.0),
                speed_m_per_s: ignis::effect::Range::new(1.0, 1.0),
                integrator,
                forces: ignis::effect::Forces {
                    drag_per_sec: 240.0,
                    ..plain_emitter().forces
                },
                ..plain_emitter()
            };
            let mut effect = bare_effect(e);
            effect.time.step_secs = step;
            let warnings = effect.stability_warnings();
            assert_eq!(
                !warnings.is_empty(),
                unstable,
                "{integrator:?} at {step}: {warnings:?}"
            );
            if let Some(w) = warnings.first() {
                assert_eq!(w.field, "emitters[0].forces.drag_per_sec");
                let stable = w.stable_step_secs.expect("a stable step");
                // Just past k·dt = 2: where (k·dt − 1)^(life/dt) reaches 2 over 1 s.
                let growth = (240.0 * stable - 1.0).powf(1.0 / stable);
                assert!((growth - 2.0).abs() < 1e-6, "{stable}: growth {growth}");
                assert!(stable > 2.0 / 240.0 && stable < 2.01 / 240.0, "{stable}");
                let text = w.to_string();
                assert!(
                    text.contains("drag_per_sec") && text.contains("stable"),
                    "{text}"
                );
            }
            let sim = run_gpu(&ctx, &effect, step, (0.5 / step) as u32);
            let fastest = sim
                .read_particles(0)
                .expect("read")
                .iter()
                .filter(|p| p.is_alive())
                .map(|p| {
                    let v = p.vel_life;
                    let s = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                    if s.is_finite() { s } else { f32::INFINITY }
                })
                .fold(0.0f32, f32::max);
            if unstable {
                assert!(fastest > 1e3, "{integrator:?} at {step}: fastest {fastest}");
            } else {
                assert!(fastest < 1.0, "{integrator:?} at {step}: fastest {fastest}");
            }
        }
    }
}

/// `ignis check` reports an emitter that is unstable at its step (a warning: the preset
/// is valid), naming the field and the stable step.
#[test]
fn ignis_check_warns_of_an_unstable_emitter() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("stiff.ron");
    let mut effect = bare_effect(Emitter {
        forces: ignis::effect::Forces {
            drag_per_sec: 300.0,
            ..plain_emitter().forces
        },
        ..plain_emitter()
    });
    effect.time.step_secs = 1.0 / 100.0;
    ignis::preset::save(&effect, &path).expect("save");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_ignis"))
        .arg("check")
        .arg(&path)
        .output()
        .expect("run ignis");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "a warning is not a failure: {stderr}");
    assert!(
        stderr.contains("WARN") && stderr.contains("emitters[0].forces.drag_per_sec"),
        "{stderr}"
    );
    assert!(stderr.contains("a step of at most"), "{stderr}");
}
