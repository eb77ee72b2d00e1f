//! The perf bench's module and sort tables: each optional module's and each sort's cost at the bench's sizes.

use super::*;

/// Update cost with each optional module on, with every module compiled out by its
/// override constant, and with the module code removed from the source.
pub(super) fn module_costs(
    ctx: &GpuContext,
    opts: &PerfOptions,
) -> Result<Vec<(String, f64, f64)>, SimError> {
    let n = opts.module_capacity.min(ctx.max_capacity() as u32);
    // The flames without their own optional modules (turbulence, flame pull): each row
    // below switches one on.
    let base = lean_effect(&scaled_campfire(n as u64, n as u64));
    let timer = GpuTimer::new(ctx);
    let mut plain = base.clone();
    for e in &mut plain.emitters {
        e.spawn_noise.position_amplitude_m = 0.0;
        e.spawn_noise.direction_amplitude = 0.0;
    }
    let variants = module_variants(&plain)?;
    let samples = time_variants(ctx, opts, &variants, &plain, &timer)?;
    let rows = variants
        .iter()
        .zip(samples)
        .map(|((name, _, _), mut s)| {
            let best = s.iter().copied().fold(f64::INFINITY, f64::min);
            (name.clone(), median(&mut s), best)
        })
        .collect();
    Ok(rows)
}

/// Rounds over the module table's variants (see `time_variants`).
pub(super) const MODULE_ROUNDS: usize = 8;

/// A row of the module table: its name, the effect and the shader library it runs on.
type Variant = (String, Effect, ShaderLibrary);

/// The module table's rows: the bare and compiled-out baselines, then each module on.
fn module_variants(plain: &Effect) -> Result<Vec<Variant>, SimError> {
    let bare_lib = ShaderLibrary::embedded()
        .without_modules()
        .map_err(SimError::Shader)?;
    let mut variants: Vec<Variant> = vec![
        (
            "bare: module code removed from the source".to_owned(),
            plain.clone(),
            bare_lib,
        ),
        (
            "every optional module compiled out (override constants)".to_owned(),
            plain.clone(),
            ShaderLibrary::embedded(),
        ),
    ];
    type Switch = Box<dyn Fn(&mut Emitter)>;
    let on: Vec<(&str, Switch)> = vec![
        (
            "gusts on",
            Box::new(|e: &mut Emitter| e.forces.gusts = Some(Default::default())),
        ),
        (
            "quadratic drag on",
            Box::new(|e: &mut Emitter| e.forces.quadratic_drag_per_m = 0.2),
        ),
        (
            "turbulence on (2 octaves)",
            Box::new(|e: &mut Emitter| e.forces.turbulence = Some(Default::default())),
        ),
        (
            "vortex on",
            Box::new(|e: &mut Emitter| e.forces.vortex = Some(Default::default())),
        ),
        (
            "attractor on",
            Box::new(|e: &mut Emitter| e.forces.attractor = Some(Default::default())),
        ),
        (
            "flame pull on",
            Box::new(|e: &mut Emitter| e.forces.flame_pull = Some(Default::default())),
        ),
        (
            "stateless mode (spawn records only, closed form when drawn)",
            Box::new(|e: &mut Emitter| e.stateless = true),
        ),
        (
            "collisions on (ground + 1 sphere)",
            Box::new(|e: &mut Emitter| {
                e.collisions.ground = Some(Default::default());
                e.collisions.spheres = vec![Default::default()];
            }),
        ),
        (
            "depth collision on (a 1080p host depth: a plane through the flames' axis)",
            Box::new(|e: &mut Emitter| {
                e.collisions.depth_collision = Some(Default::default());
            }),
        ),
        (
            "trail on (4 points, every 2 steps)",
            Box::new(|e: &mut Emitter| {
                e.look.trail = Some(crate::effect::Trail {
                    points: 4,
                    ..Default::default()
                })
            }),
        ),
    ];
    for (name, apply) in on {
        let mut effect = plain.clone();
        for e in &mut effect.emitters {
            apply(e);
        }
        let mods = Modules::of(&effect.emitters[0]);
        variants.push((
            format!("{name} [{}]", mods.names().join(", ")),
            effect,
            ShaderLibrary::embedded(),
        ));
    }
    variants.push(events_variant(plain));
    Ok(variants)
}

/// Events: the pool's particles spawn one child each on death into a small emitter (the
/// records of every slot written each step, the scan, the child's update).
fn events_variant(plain: &Effect) -> Variant {
    let mut events = plain.clone();
    let mut child = events.emitters[0].clone();
    child.name = "event child".into();
    child.capacity = 4096;
    child.spawn_rate_per_sec = crate::effect::Param::Constant(0.0);
    events.emitters[0].events = vec![crate::effect::Event {
        emitter: child.name.clone(),
        max_per_sec: 4096.0 * 120.0,
        ..Default::default()
    }];
    events.emitters.push(child);
    let mods = Modules::in_effect(&events, 0);
    (
        format!(
            "events on (death → a 4096-slot child) [{}]",
            mods.names().join(", ")
        ),
        events,
        ShaderLibrary::embedded(),
    )
}

/// The update's GPU time of every variant (ms samples, one list per variant).
fn time_variants(
    ctx: &GpuContext,
    opts: &PerfOptions,
    variants: &[Variant],
    plain: &Effect,
    timer: &GpuTimer,
) -> Result<Vec<Vec<f64>>, SimError> {
    // Every variant on one pool, filled like the throughput rows' (66 steps: every slot
    // alive), and no other large pool alive: on the H100 the same one-step update of a
    // 16.8M pool measured 0.41 ms with one such pool allocated, 0.74 ms with two and
    // 1.04 ms with ten (a device-memory effect, not the code);
    // earlier versions of this table, holding two or more pools, reported the slowed
    // figures, and pools allocated and freed in turn land erratically. Switching variants
    // swaps the pipelines (the bare one is built from another library), never the pool.
    // Stateless mode clears the pool (its records mean something else), so it is measured
    // last. Rounds over the variants keep slow drifts of a shared machine hitting all
    // alike; the H100 spends seconds at a time in a state where the same step takes twice
    // as long, so a variant needs several rounds to be seen in the fast one too (with three
    // rounds some variants never were, and read +100 %).
    let rounds = MODULE_ROUNDS;
    let per_round = opts.repeats.max(1);
    let mut samples = vec![Vec::new(); variants.len()];
    let is_stateless = |e: &Effect| e.emitters.iter().any(|e| e.stateless);
    let mut sim = GpuSim::new(ctx, variants[1].2.clone(), plain)?;
    sim.set_host_depth(Some(bench_depth(ctx)));
    sim.step(plain, 1.0 / 60.0, 66)?;
    let mut bare_loaded = false;
    let mut order: Vec<usize> = (0..variants.len())
        .filter(|&i| !is_stateless(&variants[i].1))
        .collect();
    for round in 0..=rounds {
        if round == rounds {
            // The last pass: the stateless variants only.
            order = (0..variants.len())
                .filter(|&i| is_stateless(&variants[i].1))
                .collect();
        }
        for &i in &order {
            let (_, effect, lib) = &variants[i];
            if (i == 0) != bare_loaded {
                sim.reload_shaders(lib.clone(), effect)
                    .map_err(SimError::Shader)?;
                bare_loaded = i == 0;
            }
            warm_up(ctx, &mut sim, effect)?;
            for _ in 0..per_round {
                let ms = timer.time(ctx, |enc| {
                    let plans = sim.plan(effect, 1.0 / 60.0, 1);
                    sim.record(enc, effect, &plans);
                });
                samples[i].push(ms);
            }
        }
    }
    Ok(samples)
}

/// The depth-collision row's host depth: 1920×1080, the campfire seen from 3 m, holding a
/// plane facing the camera through the flames' axis (the half of the flames behind it
/// cross it and bounce; every particle on screen marches its step).
fn bench_depth(ctx: &GpuContext) -> crate::sim::depth_collision::HostDepthView {
    use glam::Vec3;
    let size = (1920, 1080);
    let view = glam::camera::rh::view::look_at_mat4(
        Vec3::new(0.0, 0.8, 3.0),
        Vec3::new(0.0, 0.6, 0.0),
        Vec3::Y,
    );
    let proj = glam::camera::rh::proj::directx::perspective(0.8, 16.0 / 9.0, 0.05, 100.0);
    let clip_from_world = (proj * view).as_dmat4();
    let c = clip_from_world * glam::DVec4::new(0.0, 0.6, 0.0, 1.0);
    let texture = crate::gpu::texture_2d(
        &ctx.device,
        "bench depth",
        size,
        1,
        wgpu::TextureFormat::Depth32Float,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
    );
    let view = texture.create_view(&Default::default());
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    drop(enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: &view,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear((c.z / c.w) as f32),
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        }),
        ..Default::default()
    }));
    ctx.queue.submit([enc.finish()]);
    crate::sim::depth_collision::HostDepthView {
        view,
        clip_from_world,
        reversed_z: false,
        size,
    }
}

/// Untimed steps for at least 100 ms: after a pause (a pipeline compile) the H100's SM
/// clock takes tens of ms to climb back, and a fixed 10 steps (4 ms) left ALU-bound
/// variants measured at a low clock (turbulence: 3.3 ms instead of 0.89) while
/// memory-bound ones looked fine.
fn warm_up(ctx: &GpuContext, sim: &mut GpuSim, effect: &Effect) -> Result<(), SimError> {
    let warm = std::time::Instant::now();
    loop {
        sim.step(effect, 1.0 / 60.0, 10)?;
        let _ = ctx.device.poll(wgpu::PollType::wait_indefinitely());
        if warm.elapsed().as_secs_f64() > 0.1 {
            return Ok(());
        }
    }
}

/// One row of the sort table.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SortRow {
    /// Keys sorted.
    pub keys: u32,
    /// Dispatches of the split network.
    pub split_dispatches: usize,
    /// Dispatches of the plain network.
    pub plain_dispatches: usize,
    /// Split network, ms.
    pub split_ms: f64,
    /// Plain network, ms.
    pub plain_ms: f64,
}

/// The GPU sort of random keys with the split and the plain bitonic network.
pub(super) fn sort_costs(
    ctx: &GpuContext,
    opts: &PerfOptions,
    timer: &GpuTimer,
) -> Result<Vec<SortRow>, SimError> {
    let largest = if ctx.profile.is_software() {
        1 << 18
    } else {
        1 << 24
    };
    let split = crate::render::sort::SortPass::new(ctx, &ShaderLibrary::embedded())?;
    let mut plain = crate::render::sort::SortPass::new(ctx, &ShaderLibrary::embedded())?;
    plain.split_network = false;
    let mut rows = Vec::new();
    let mut state = 0x2545_F491u32;
    for keys in [1u32 << 12, 1 << 16, 1 << 20, 1 << 24] {
        if keys > largest || keys > ctx.max_capacity() as u32 {
            continue;
        }
        let data: Vec<u32> = (0..keys)
            .map(|_| {
                state ^= state << 13;
                state ^= state >> 17;
                state ^= state << 5;
                state
            })
            .collect();
        let a = split.key_sort(ctx, &data);
        let b = plain.key_sort(ctx, &data);
        // Interleaved, so drifts of a shared machine hit both alike; the random keys are
        // uploaded again before every sample (a sorted input swaps, so writes, less).
        let (mut sa, mut sb) = (Vec::new(), Vec::new());
        for _ in 0..opts.repeats {
            a.reset_keys(ctx, &data);
            sa.push(timer.time(ctx, |enc| split.record_key_sort(enc, &a)));
            b.reset_keys(ctx, &data);
            sb.push(timer.time(ctx, |enc| plain.record_key_sort(enc, &b)));
        }
        rows.push(SortRow {
            keys,
            split_dispatches: crate::render::sort::sort_dispatches(keys).len(),
            plain_dispatches: crate::render::sort::bitonic_stages(keys).len(),
            split_ms: median(&mut sa),
            plain_ms: median(&mut sb),
        });
    }
    Ok(rows)
}
