//! `ignis bench accuracy`: the speed/accuracy trade of every integrator, measured.
//!
//! Scene 1 (closed form): constant acceleration with linear drag toward a wind; the exact
//! solution is known. Scene 2 (turbulent): scene 1 plus curl-noise turbulence; the
//! reference is RK4 in f64 on the CPU at dt/64. Each run spawns one burst, reads the state
//! after the spawn step as the initial condition, runs T = 2 s on the GPU and compares.

use glam::DVec3;
use serde::Serialize;

use crate::PlayerError;
use crate::effect::{
    Burst, Effect, Emitter, Integrator, Param, Range, Shape, SpawnNoise, TimeMode, Turbulence,
};
use crate::gpu::GpuContext;
use crate::gpu::timer::{GpuTimer, median};
use crate::gpu::types::{Particle, StateLayout};
use crate::headless::Headless;
use crate::shaders::ShaderLibrary;
use crate::sim::cpu_reference::Forces;
use crate::sim::{GpuSim, Modules, SimError};

/// The step sizes measured (seconds).
pub const DTS: [f64; 6] = [
    1.0 / 480.0,
    1.0 / 240.0,
    1.0 / 120.0,
    1.0 / 60.0,
    1.0 / 30.0,
    1.0 / 15.0,
];
/// Simulated duration of each run (seconds).
pub const T_SECS: f64 = 2.0;

/// The two scenes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Scene {
    /// Constant acceleration + linear drag: exact solution.
    ClosedForm,
    /// Plus curl-noise turbulence: f64 RK4 reference at dt/64.
    Turbulent,
}

impl Scene {
    /// Table label.
    pub fn label(self) -> &'static str {
        match self {
            Scene::ClosedForm => "scene 1: gravity + buoyancy + linear drag (exact)",
            Scene::Turbulent => "scene 2: + curl-noise turbulence (f64 RK4 at dt/64)",
        }
    }
}

/// The emitter of a scene: one burst of `n` particles with random velocities.
pub fn scene_emitter(scene: Scene, integrator: Integrator, n: u32) -> Emitter {
    let mut e = Emitter {
        name: "bench".into(),
        capacity: n,
        spawn_rate_per_sec: Param::Constant(0.0),
        max_spawn_per_sec: 0.0,
        bursts: vec![Burst {
            time_secs: 0.0,
            count: n,
        }],
        lifetime_secs: Range::new(1000.0, 1000.0),
        shape: Shape::Sphere {
            radius_m: 0.2,
            surface_only: false,
        },
        spread_deg: 60.0,
        speed_m_per_s: Range::new(0.5, 3.0),
        spawn_noise: SpawnNoise {
            position_amplitude_m: 0.0,
            direction_amplitude: 0.0,
            ..SpawnNoise::default()
        },
        integrator,
        ..Emitter::default()
    };
    e.forces.gravity_m_per_s2 = [0.0, -9.81, 0.0];
    e.forces.buoyancy_m_per_s2 = 11.0;
    e.forces.drag_per_sec = 1.5;
    e.forces.wind_m_per_s = [0.5, 0.0, 0.2];
    if scene == Scene::Turbulent {
        e.forces.turbulence = Some(Turbulence {
            strength_m_per_s2: 3.0,
            frequency_per_m: 1.5,
            octaves: 2,
            scroll_m_per_s: 0.5,
            ..Turbulence::default()
        });
    }
    e
}

/// The exact solution of x'' = c − k x' from (x0, v0) after t (c = a + k·wind).
pub fn exact_state(x0: DVec3, v0: DVec3, a: DVec3, k: f64, wind: DVec3, t: f64) -> (DVec3, DVec3) {
    let c = a + k * wind;
    if k == 0.0 {
        return (x0 + v0 * t + 0.5 * a * t * t, v0 + a * t);
    }
    let vt = c / k;
    let e = (-k * t).exp();
    (x0 + vt * t + (v0 - vt) * (1.0 - e) / k, vt + (v0 - vt) * e)
}

/// RK4 in f64 on the CPU from `t0` over `t` with `substeps` steps.
#[allow(clippy::too_many_arguments)]
pub fn reference_rk4(
    forces: &Forces<'_>,
    x0: DVec3,
    v0: DVec3,
    age0: f64,
    life: f64,
    t0: f64,
    t: f64,
    substeps: u32,
) -> DVec3 {
    let h = t / substeps as f64;
    let (mut x, mut v) = (x0, v0);
    for i in 0..substeps {
        let time = t0 + i as f64 * h;
        let age = age0 + i as f64 * h;
        let acc =
            |x: DVec3, v: DVec3, dt: f64| forces.acceleration(x, v, age + dt, life, time + dt);
        let k1v = acc(x, v, 0.0);
        let k1x = v;
        let k2x = v + 0.5 * h * k1v;
        let k2v = acc(x + 0.5 * h * k1x, k2x, 0.5 * h);
        let k3x = v + 0.5 * h * k2v;
        let k3v = acc(x + 0.5 * h * k2x, k3x, 0.5 * h);
        let k4x = v + h * k3v;
        let k4v = acc(x + h * k3x, k4x, h);
        x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
        v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
    }
    x
}

/// One measured (scene, integrator, dt) point.
#[derive(Clone, Debug, Serialize)]
pub struct ErrorPoint {
    /// Scene.
    pub scene: Scene,
    /// Integrator label.
    pub integrator: String,
    /// Step size, seconds.
    pub dt_secs: f64,
    /// RMS over particles of |x − x_ref| / |x_ref − x0|.
    pub rms_rel_error: f64,
    /// Max over particles of the same.
    pub max_rel_error: f64,
}

/// A scene's fixed initial condition and its reference solution at T.
pub struct SceneSetup {
    /// The scene.
    pub scene: Scene,
    /// Initial particles (born by the GPU spawn code, then frozen).
    pub initial: Vec<Particle>,
    /// Reference positions at `T_SECS`.
    pub reference: Vec<DVec3>,
}

/// Spawns the scene's particles once and computes the reference: the closed form for
/// scene 1, RK4 in f64 at (smallest dt)/64 for scene 2 (so at dt/64 or finer for every
/// measured dt), on all CPU cores.
pub fn setup_scene(ctx: &GpuContext, scene: Scene, n: u32) -> Result<SceneSetup, SimError> {
    let e = scene_emitter(scene, Integrator::Rk4, n);
    let effect = Effect {
        emitters: vec![e.clone()],
        ..Effect::default()
    };
    let mut sim = GpuSim::new(ctx, ShaderLibrary::embedded(), &effect)?;
    sim.step(&effect, 1e-4, 1)?;
    let mut initial = sim.read_particles(0)?;
    for p in &mut initial {
        p.pos_age[3] = 0.0;
    }
    let mut probe = sim.planner.clone();
    let params = probe.plan_step(&effect, 1e-4)[0].unwrap_or_default();
    let forces = Forces {
        params: &params,
        modules: Modules::of(&e),
        over_life: [1.0; 4],
    };
    let a = e.forces.constant_acceleration().as_dvec3();
    let wind = glam::Vec3::from(e.forces.wind_m_per_s).as_dvec3();
    let k = e.forces.drag_per_sec as f64;
    let fine = (T_SECS / DTS[0]).round() as u32 * 64;
    let solve = |p: &Particle| -> DVec3 {
        let x0 = p.position().as_dvec3();
        let v0 = p.velocity().as_dvec3();
        match scene {
            Scene::ClosedForm => exact_state(x0, v0, a, k, wind, T_SECS).0,
            Scene::Turbulent => reference_rk4(
                &forces,
                x0,
                v0,
                0.0,
                p.vel_life[3] as f64,
                0.0,
                T_SECS,
                fine,
            ),
        }
    };
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get());
    let chunk = initial.len().div_ceil(threads).max(1);
    let reference = std::thread::scope(|s| {
        let handles: Vec<_> = initial
            .chunks(chunk)
            .map(|c| s.spawn(move || c.iter().map(solve).collect::<Vec<_>>()))
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().unwrap_or_default())
            .collect::<Vec<_>>()
    });
    Ok(SceneSetup {
        scene,
        initial,
        reference,
    })
}

/// Runs `integrator` at `dt` from the scene's initial state for T = 2 s on the GPU and
/// measures the error against the reference.
pub fn measure_error(
    ctx: &GpuContext,
    setup: &SceneSetup,
    integrator: Integrator,
    dt: f64,
) -> Result<ErrorPoint, SimError> {
    let mut e = scene_emitter(setup.scene, integrator, setup.initial.len() as u32);
    e.bursts.clear();
    let effect = Effect {
        emitters: vec![e],
        ..Effect::default()
    };
    let mut sim = GpuSim::new(ctx, ShaderLibrary::embedded(), &effect)?;
    sim.write_particles(0, &setup.initial)?;
    let steps = (T_SECS / dt).round() as u32;
    sim.step(&effect, dt as f32, steps)?;
    let fin = sim.read_particles(0)?;
    Ok(error_point(setup, integrator, dt, &fin))
}

/// As [`measure_error`] with a compact state (packed 20 bytes or tiny 10): the same burst
/// spawns the same initial state (compact from its first store on), then the same steps.
pub fn measure_error_compact(
    ctx: &GpuContext,
    setup: &SceneSetup,
    integrator: Integrator,
    dt: f64,
    layout: StateLayout,
) -> Result<ErrorPoint, SimError> {
    let mut e = scene_emitter(setup.scene, integrator, setup.initial.len() as u32);
    set_layout(&mut e, layout);
    let effect = Effect {
        emitters: vec![e],
        ..Effect::default()
    };
    let mut sim = GpuSim::new(ctx, ShaderLibrary::embedded(), &effect)?;
    // The spawn step of `setup_scene` (its positions are the initial state).
    sim.step(&effect, 1e-4, 1)?;
    let steps = (T_SECS / dt).round() as u32;
    sim.step(&effect, dt as f32, steps)?;
    let fin = sim.read_particles(0)?;
    let mut p = error_point(setup, integrator, dt, &fin);
    p.integrator = compact_label(integrator, layout);
    Ok(p)
}

/// Sets an emitter's state layout.
fn set_layout(e: &mut crate::effect::Emitter, layout: StateLayout) {
    e.packed_state = layout == StateLayout::Packed;
    e.tiny_state = layout == StateLayout::Tiny;
}

/// "`<integrator>`", "`<integrator>` + packed" or "`<integrator>` + tiny".
pub fn compact_label(integrator: Integrator, layout: StateLayout) -> String {
    let suffix = match layout {
        StateLayout::Full => "",
        StateLayout::Packed => " + packed",
        StateLayout::Tiny => " + tiny",
    };
    format!("{}{suffix}", integrator.label())
}

fn error_point(
    setup: &SceneSetup,
    integrator: Integrator,
    dt: f64,
    fin: &[Particle],
) -> ErrorPoint {
    let mut sum = 0.0;
    let mut max: f64 = 0.0;
    for ((p0, p1), x_ref) in setup.initial.iter().zip(fin).zip(&setup.reference) {
        let x0 = p0.position().as_dvec3();
        let travelled = (*x_ref - x0).length().max(1e-9);
        let err = (p1.position().as_dvec3() - *x_ref).length() / travelled;
        let err = if err.is_finite() && p1.is_alive() {
            err
        } else {
            f64::INFINITY
        };
        sum += err * err;
        max = max.max(err);
    }
    ErrorPoint {
        scene: setup.scene,
        integrator: integrator.label().to_owned(),
        dt_secs: dt,
        rms_rel_error: (sum / setup.initial.len().max(1) as f64).sqrt(),
        max_rel_error: max,
    }
}

/// Least-squares slope of log(error) against log(dt) over the points in the asymptotic
/// range (1e-5 < error < 0.3: above the f32 floor, below the pre-asymptotic regime).
pub fn convergence_order(points: &[(f64, f64)]) -> Option<f64> {
    let pts: Vec<(f64, f64)> = points
        .iter()
        .filter(|(_, e)| *e > 1e-5 && *e < 0.3 && e.is_finite())
        .map(|(dt, e)| (dt.ln(), e.ln()))
        .collect();
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    Some(sxy / sxx)
}

/// Cost of one update step per particle, in nanoseconds (median of `repeats`).
pub fn measure_cost(
    ctx: &GpuContext,
    scene: Scene,
    integrator: Integrator,
    capacity: u32,
    repeats: usize,
    layout: StateLayout,
) -> Result<f64, SimError> {
    let mut e = scene_emitter(scene, integrator, capacity);
    set_layout(&mut e, layout);
    let effect = Effect {
        emitters: vec![e],
        ..Effect::default()
    };
    let mut sim = GpuSim::new(ctx, ShaderLibrary::embedded(), &effect)?;
    sim.step(&effect, 1.0 / 60.0, 2)?;
    let timer = GpuTimer::new(ctx);
    let steps = 8;
    let mut samples = Vec::new();
    for _ in 0..repeats {
        let plans = sim.plan(&effect, 1.0 / 60.0, steps);
        let ms = timer.time(ctx, |enc| sim.record(enc, &effect, &plans));
        samples.push(ms * 1e6 / (steps as f64 * capacity as f64));
    }
    Ok(median(&mut samples))
}

/// The frame sequences: constant 30, 60, 144, 240 fps and a jittered one, each 2 s long.
pub fn frame_sequences() -> Vec<(String, Vec<f64>)> {
    let mut v: Vec<(String, Vec<f64>)> = [30.0, 60.0, 144.0, 240.0]
        .iter()
        .map(|fps| {
            (
                format!("{fps} fps"),
                vec![1.0 / fps; (T_SECS * fps).round() as usize],
            )
        })
        .collect();
    // Jitter: frame times in [1/240, 1/30] from a fixed LCG, trimmed to sum to 2 s.
    let mut state = 0x2545_F491_u64;
    let mut frames = Vec::new();
    let mut total = 0.0;
    while total < T_SECS {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        let u = (state >> 11) as f64 / (1u64 << 53) as f64;
        let dt = (1.0 / 240.0 + u * (1.0 / 30.0 - 1.0 / 240.0)).min(T_SECS - total);
        frames.push(dt);
        total += dt;
    }
    v.push(("jittered 30–240 fps".into(), frames));
    v
}

fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ *b as u64).wrapping_mul(0x0100_0000_01b3)
    })
}

/// The default campfire in fixed-step mode over every frame sequence: state hashes.
/// Played through the runtime's [`crate::Player`], as `ignis render` plays it.
pub fn fixed_step_hashes(ctx: &GpuContext) -> Result<Vec<(String, u64, u64)>, PlayerError> {
    let mut out = Vec::new();
    for (name, frames) in frame_sequences() {
        let mut effect = Effect::default_campfire();
        effect.time.mode = TimeMode::FixedStep;
        let step_secs = f64::from(effect.time.step_secs);
        let mut run = Headless::new(ctx, effect, ShaderLibrary::embedded())?;
        for dt in &frames {
            run.advance(*dt);
        }
        let mut bytes = Vec::new();
        for i in 0..run.effect().emitters.len() {
            let particles = run.player.particles(run.instance, i)?;
            bytes.extend_from_slice(bytemuck::cast_slice(&particles));
        }
        let time = run.player.time_secs(run.instance).unwrap_or_default();
        out.push((name, fnv1a(&bytes), (time / step_secs).round() as u64));
    }
    Ok(out)
}

/// Scene 1 with explicit Euler in frame-delta mode (the 2006 thesis's setup) for every
/// frame sequence: error against the exact solution and divergence between frame rates.
pub fn frame_delta_divergence(
    ctx: &GpuContext,
    n: u32,
) -> Result<Vec<(String, f64, Vec<DVec3>)>, SimError> {
    let e = scene_emitter(Scene::ClosedForm, Integrator::ExplicitEuler, n);
    let a = e.forces.constant_acceleration().as_dvec3();
    let wind = glam::Vec3::from(e.forces.wind_m_per_s).as_dvec3();
    let k = e.forces.drag_per_sec as f64;
    let mut out = Vec::new();
    for (name, frames) in frame_sequences() {
        let effect = Effect {
            emitters: vec![e.clone()],
            ..Effect::default()
        };
        let mut sim = GpuSim::new(ctx, ShaderLibrary::embedded(), &effect)?;
        // The burst is born in the first frame's step; measure from its end.
        sim.step(&effect, frames[0] as f32, 1)?;
        let initial = sim.read_particles(0)?;
        let mut t = 0.0;
        for dt in &frames[1..] {
            sim.step(&effect, *dt as f32, 1)?;
            t += dt;
        }
        let fin = sim.read_particles(0)?;
        let mut sum = 0.0;
        let mut count = 0;
        let mut positions = Vec::new();
        for (p0, p1) in initial.iter().zip(&fin) {
            let x0 = p0.position().as_dvec3();
            let x_ref = exact_state(x0, p0.velocity().as_dvec3(), a, k, wind, t).0;
            let err = (p1.position().as_dvec3() - x_ref).length() / (x_ref - x0).length().max(1e-9);
            sum += err * err;
            count += 1;
            positions.push(p1.position().as_dvec3());
        }
        out.push((name, (sum / count.max(1) as f64).sqrt(), positions));
    }
    Ok(out)
}

mod report;
pub use report::{AccuracyOptions, run};
