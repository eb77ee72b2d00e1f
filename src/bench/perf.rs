//! `ignis bench perf`: update, draw (both paths) and composite cost from 64² to the
//! device's limit, the update pass's bandwidth against a compute copy of the same bytes
//! in the same run, the 2006 thesis's frame rates next to its sizes, and what optional
//! modules cost on and off.

use crate::bench::Report;
use crate::bench::report::sci;
use crate::effect::{Effect, Emitter, Param, Range};
use crate::gpu::GpuContext;
use crate::gpu::timer::{GpuTimer, median};
use crate::gpu::types::StateLayout;
use crate::render::billboard::{BillboardPass, DrawTarget};
use crate::render::sort::SortPass;
use crate::render::tiles::TileStages;
use crate::render::{
    DrawItem, FrameResources, OrbitCamera, SplatPass, TilePass, TonemapPass, load_hdr_pass,
};
use crate::shaders::ShaderLibrary;
use crate::sim::{GpuSim, Modules, SimError};

/// The 2006 thesis's measurements (GeForce 8800, points only): texture side → fps.
pub const THESIS_FPS: [(u32, f64); 7] = [
    (64, 5300.0),
    (128, 5300.0),
    (256, 2500.0),
    (512, 700.0),
    (1024, 180.0),
    (2048, 46.0),
    (4096, 12.0),
];

/// Options of `ignis bench perf`.
pub struct PerfOptions {
    /// Texture sides: capacity = side².
    pub sides: Vec<u32>,
    /// Render resolution.
    pub size: (u32, u32),
    /// Timed repeats (median reported).
    pub repeats: usize,
    /// Skip the billboard path above this many particles (it is ~100× slower).
    pub billboard_limit: u64,
    /// Particles for the module-cost table.
    pub module_capacity: u32,
}

/// The default campfire's flames, scaled to `n` particles: sizes shrink with √n so the
/// lit area (and the total light) stays that of the 4096-particle original. Pools larger
/// than one storage binding are split into several emitters.
pub fn scaled_campfire(n: u64, max_pool: u64) -> Effect {
    let base = Effect::default_campfire();
    let flames = base
        .emitters
        .iter()
        .find(|e| e.name == "flames")
        .cloned()
        .unwrap_or_default();
    let scale = (4096.0 / n as f64).sqrt() as f32;
    let pools = n.div_ceil(max_pool).max(1);
    let per_pool = (n / pools) as u32;
    let emitters = (0..pools)
        .map(|i| {
            let mut e = Emitter {
                name: format!("flames {i}"),
                capacity: per_pool,
                lifetime_secs: Range::new(1.0, 1.0),
                spawn_rate_per_sec: Param::Constant(per_pool as f32),
                seed_offset: i as u32,
                ..flames.clone()
            };
            e.max_spawn_per_sec = 0.0;
            e.look.size_m = e.look.size_m.scaled(scale.min(1.0));
            // The flames alone: no smoke from their deaths (the events' cost has a row of
            // its own in the module table).
            e.events.clear();
            e
        })
        .collect();
    Effect {
        name: format!("campfire × {n}"),
        emitters,
        ..base
    }
}

/// `effect` without turbulence and flame pull (the ALU-heavy modules): what the
/// bandwidth figures measure.
pub fn lean_effect(effect: &Effect) -> Effect {
    let mut lean = effect.clone();
    for e in &mut lean.emitters {
        e.forces.turbulence = None;
        e.forces.flame_pull = None;
    }
    lean
}

/// One row of the throughput table.
#[derive(Clone, Debug, serde::Serialize)]
pub struct PerfRow {
    /// Particles.
    pub particles: u64,
    /// Pools (emitters) the particles were split into.
    pub pools: u64,
    /// Update pass, ms.
    pub update_ms: f64,
    /// Update pass without the ALU-heavy force modules (turbulence, flame pull): the
    /// memory-bound case the bandwidth column uses, ms.
    pub lean_update_ms: f64,
    /// Compute copy of the same bytes, ms.
    pub copy_ms: f64,
    /// Billboard draw, ms (None when skipped).
    pub billboard_ms: Option<f64>,
    /// Splat draw (clear + splat + resolve), ms.
    pub splat_ms: f64,
    /// Tile draw (project, bin, shade and the resolve), ms (None when the quads do not
    /// fit the device's tile buffers, or the device has no tile rasteriser).
    pub tiles_ms: Option<f64>,
    /// The tile draw's project alone and project + bin, ms (the shade and resolve are the
    /// rest of `tiles_ms`).
    pub tiles_stages_ms: Option<[f64; 2]>,
    /// The tiles' resolve alone, ms: by compute (None where the adapter cannot; the tile
    /// draw uses it where it can, as the editor does) and by a draw.
    pub tiles_resolve_ms: Option<(Option<f64>, f64)>,
    /// Tonemap composite, ms.
    pub composite_ms: f64,
    /// The path Auto picks for this scene.
    pub auto_path: &'static str,
    /// update + auto draw + composite, ms.
    pub frame_ms: f64,
}

fn copy_pipeline(ctx: &GpuContext, wgsl: &str) -> (wgpu::ComputePipeline, wgpu::BindGroupLayout) {
    let module = ctx
        .device
        .create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("bench copy"),
            source: wgpu::ShaderSource::Wgsl(wgsl.into()),
        });
    let layout = ctx
        .device
        .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("bench copy layout"),
            entries: &[
                crate::gpu::compute_storage_entry(0, true),
                crate::gpu::compute_storage_entry(1, false),
            ],
        });
    let pl = ctx
        .device
        .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("bench copy pipeline layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
    let pipeline = ctx
        .device
        .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("bench copy"),
            layout: Some(&pl),
            module: &module,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        });
    (pipeline, layout)
}

/// A plain compute copy, 32 bytes per invocation: the same bytes the update moves.
const COPY_WGSL: &str = "
struct P { a: vec4<f32>, b: vec4<f32> }
@group(0) @binding(0) var<storage, read> src: array<P>;
@group(0) @binding(1) var<storage, read_write> dst: array<P>;
@compute @workgroup_size(256)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) n: vec3<u32>, @builtin(local_invocation_index) l: u32) {
    let i = (wg.y * n.x + wg.x) * 256u + l;
    if i < arrayLength(&src) { dst[i] = src[i]; }
}
";

/// The same copy with the packed state's 20-byte elements (five scalars, as the update
/// reads and writes them; a tiny-state pair of slots is the same five words).
const COPY20_WGSL: &str = "
struct Q { a: u32, b: u32, c: u32, d: u32, e: u32 }
@group(0) @binding(0) var<storage, read> src: array<Q>;
@group(0) @binding(1) var<storage, read_write> dst: array<Q>;
@compute @workgroup_size(256)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) n: vec3<u32>, @builtin(local_invocation_index) l: u32) {
    let i = (wg.y * n.x + wg.x) * 256u + l;
    if i < arrayLength(&src) { dst[i] = src[i]; }
}
";

/// One row of a compact-state table: update ms of the packed (or tiny) pools and of a
/// compute copy of the same bytes (20 read + 20 written per packed particle, 10 + 10 per
/// tiny one).
#[derive(Clone, Debug, serde::Serialize)]
pub struct PackedRow {
    /// Particles.
    pub particles: u64,
    /// Update pass on the compact state, ms.
    pub update_ms: f64,
    /// Copy of the same bytes, ms.
    pub copy_ms: f64,
}

fn measure_compact(
    ctx: &GpuContext,
    opts: &PerfOptions,
    n: u64,
    layout: StateLayout,
    copy: &(wgpu::ComputePipeline, wgpu::BindGroupLayout),
) -> Result<PackedRow, SimError> {
    let max_pool = ctx.max_capacity().min(1 << 24);
    let mut effect = lean_effect(&scaled_campfire(n, max_pool));
    for e in &mut effect.emitters {
        e.packed_state = layout == StateLayout::Packed;
        e.tiny_state = layout == StateLayout::Tiny;
    }
    let mut sim = GpuSim::new(ctx, ShaderLibrary::embedded(), &effect)?;
    for _ in 0..3 {
        sim.step(&effect, 1.0 / 60.0, 22)?;
    }
    let timer = GpuTimer::new(ctx);
    let update_ms = time_update(&timer, ctx, &mut sim, &effect, opts.repeats);
    let copy_ms = time_copy(&timer, ctx, &sim, copy, opts.repeats);
    Ok(PackedRow {
        particles: n,
        update_ms,
        copy_ms,
    })
}

/// Median time of one update step of every pool of `sim`.
fn time_update(
    timer: &GpuTimer,
    ctx: &GpuContext,
    sim: &mut GpuSim,
    effect: &Effect,
    repeats: usize,
) -> f64 {
    time_median(timer, ctx, repeats, |enc| {
        let plans = sim.plan(effect, 1.0 / 60.0, 1);
        sim.record(enc, effect, &plans);
    })
}

/// Median time of `copy` over every pool of `sim` (current → previous: the bytes one
/// update step reads and writes; one invocation per element of the copy's type).
fn time_copy(
    timer: &GpuTimer,
    ctx: &GpuContext,
    sim: &GpuSim,
    copy: &(wgpu::ComputePipeline, wgpu::BindGroupLayout),
    repeats: usize,
) -> f64 {
    let groups: Vec<_> = (0..sim.emitter_count())
        .filter_map(|i| sim.emitter_buffers(i))
        .map(|b| {
            let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("bench copy group"),
                layout: &copy.1,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: b.current.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: b.previous.as_entire_binding(),
                    },
                ],
            });
            let element = match b.layout {
                StateLayout::Full => 32,
                _ => 20,
            };
            (group, (b.layout.bytes(b.capacity) / element) as u32)
        })
        .collect();
    time_median(timer, ctx, repeats, |enc| {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&copy.0);
        for (g, cap) in &groups {
            pass.set_bind_group(0, g, &[]);
            let (x, y) = crate::sim::gpu_sim::dispatch_size(*cap);
            pass.dispatch_workgroups(x, y, 1);
        }
    })
}

fn time_median(
    timer: &GpuTimer,
    ctx: &GpuContext,
    repeats: usize,
    mut work: impl FnMut(&mut wgpu::CommandEncoder),
) -> f64 {
    let mut samples: Vec<f64> = (0..repeats).map(|_| timer.time(ctx, &mut work)).collect();
    median(&mut samples)
}

/// Measures one capacity.
fn measure_row(
    ctx: &GpuContext,
    opts: &PerfOptions,
    n: u64,
    copy: &(wgpu::ComputePipeline, wgpu::BindGroupLayout),
) -> Result<PerfRow, SimError> {
    let max_pool = ctx.max_capacity().min(1 << 24);
    let effect = scaled_campfire(n, max_pool);
    let mut sim = GpuSim::new(ctx, ShaderLibrary::embedded(), &effect)?;
    // Fill the pools: 1.1 s of simulation.
    for _ in 0..3 {
        sim.step(&effect, 1.0 / 60.0, 22)?;
    }
    let timer = GpuTimer::new(ctx);
    let update_ms = time_update(&timer, ctx, &mut sim, &effect, opts.repeats);
    // The same pools without turbulence and flame pull: memory-bound.
    let lean = lean_effect(&effect);
    sim.step(&lean, 1.0 / 60.0, 2)?;
    let lean_update_ms = time_update(&timer, ctx, &mut sim, &lean, opts.repeats);
    // The copy: the same bytes as every pool's read + write, in one run.
    let copy_ms = time_copy(&timer, ctx, &sim, copy, opts.repeats);
    // Re-run one step so the state is a real one again (the copy wrote into `previous`).
    sim.step(&effect, 1.0 / 60.0, 1)?;

    let lib = ShaderLibrary::embedded();
    let mut frame = FrameResources::new(ctx);
    frame.allow_tiles = TilePass::supported(&ctx.device);
    let mut sort = SortPass::new(ctx, &lib)?;
    let mut billboard = BillboardPass::new(ctx, &lib, &frame, DrawTarget::hdr())?;
    let mut splat = SplatPass::new(ctx, &lib, &frame, DrawTarget::hdr())?;
    let mut tiles = frame
        .allow_tiles
        .then(|| TilePass::new(ctx, &lib, &frame, DrawTarget::hdr()))
        .transpose()?;
    let tonemap = TonemapPass::new(ctx, &lib)?;
    let camera = OrbitCamera::from_hint(&effect.camera);
    let size = opts.size;
    let targets = crate::render::Targets::new(ctx, size);
    let scene = [Some(crate::render::Scene {
        sim: &sim,
        effect: &effect,
    })];
    let items = frame.prepare(ctx, &[&scene], &camera.view(size), 1.0, &mut sort, None);
    let mut uploads = crate::gpu::Uploads::new(&ctx.device);
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    frame.upload_looks(&mut uploads, &mut enc);
    uploads.finish(&enc);
    ctx.queue.submit([enc.finish()]);
    let auto_path = if items.iter().all(|d| d.splat) {
        "splat"
    } else if items.iter().all(|d| d.tiles) {
        "tiles"
    } else {
        "billboard"
    };
    let with_path = |splat: bool, tiles: bool| -> Vec<DrawItem> {
        items
            .iter()
            .map(|d| DrawItem {
                splat,
                tiles,
                ..d.clone()
            })
            .collect()
    };
    let (all_billboard, all_splat) = (with_path(false, false), with_path(true, false));
    let all_tiles = with_path(false, true);
    billboard.prepare(ctx, &all_billboard, &frame.sprites.sampler, false);
    let billboard_ms = (n <= opts.billboard_limit).then(|| {
        time_median(&timer, ctx, opts.repeats.min(3), |enc| {
            let mut pass = load_hdr_pass(enc, &targets.hdr_view);
            billboard.draw(&mut pass, &frame, &all_billboard, |_| true);
        })
    });
    // Splat: clear + compute splat + its resolve into the HDR target.
    let splat_ms = {
        let mut samples = Vec::new();
        for _ in 0..opts.repeats {
            samples.push(timer.time(ctx, |enc| {
                splat.splat(ctx, enc, &frame, &all_splat, size, None);
                splat.resolve(&mut load_hdr_pass(enc, &targets.hdr_view), &frame);
            }));
        }
        median(&mut samples)
    };
    // Tiles: project, bin, shade and the resolve into the HDR target (by compute where
    // the adapter can, as the composite does).
    let (mut tiles_stages_ms, mut tiles_resolve_ms) = (None, None);
    let hdr = &targets.hdr_view;
    let tiles_ms = tiles.as_mut().and_then(|t| {
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        let fits = t.record(ctx, &mut enc, &frame, &all_tiles, size, None);
        ctx.queue.submit([enc.finish()]);
        let resolve = |t: &mut TilePass, enc: &mut wgpu::CommandEncoder| {
            if !t.resolve_into(ctx, enc, &frame, hdr, size) {
                t.resolve(&mut load_hdr_pass(enc, hdr), &frame);
            }
        };
        let time = |t: &mut TilePass, stages| {
            t.set_stages(stages);
            time_median(&timer, ctx, opts.repeats, |enc| {
                t.record(ctx, enc, &frame, &all_tiles, size, None);
                resolve(t, enc);
            })
        };
        fits.then(|| {
            tiles_stages_ms = Some([TileStages::Project, TileStages::Bin].map(|s| time(t, s)));
            let all = time(t, TileStages::All);
            // The last record stays shaded: each resolve timed alone.
            let by_compute = t
                .can_resolve_into(size)
                .then(|| time_median(&timer, ctx, opts.repeats, |enc| resolve(t, enc)));
            let by_draw = time_median(&timer, ctx, opts.repeats, |enc| {
                t.resolve(&mut load_hdr_pass(enc, hdr), &frame);
            });
            tiles_resolve_ms = Some((by_compute, by_draw));
            all
        })
    });
    // Composite: the tonemap.
    let composite_ms = time_median(&timer, ctx, opts.repeats, |enc| {
        tonemap.record(
            ctx,
            enc,
            &targets.hdr_view,
            None,
            None,
            None,
            (&targets.ldr_view, targets.size),
            1.0,
        );
    });
    let draw = match auto_path {
        "splat" => splat_ms,
        "tiles" => tiles_ms.unwrap_or(f64::NAN),
        _ => billboard_ms.unwrap_or(f64::NAN),
    };
    Ok(PerfRow {
        particles: n,
        pools: effect.emitters.len() as u64,
        update_ms,
        lean_update_ms,
        copy_ms,
        billboard_ms,
        splat_ms,
        tiles_ms,
        tiles_stages_ms,
        tiles_resolve_ms,
        composite_ms,
        auto_path,
        frame_ms: update_ms + draw + composite_ms,
    })
}

/// Update cost with each optional module on, with every module compiled out by its
/// override constant, and with the module code removed from the source.
fn module_costs(ctx: &GpuContext, opts: &PerfOptions) -> Result<Vec<(String, f64, f64)>, SimError> {
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
    let bare_lib = ShaderLibrary::embedded()
        .without_modules()
        .map_err(SimError::Shader)?;
    let mut variants: Vec<(String, Effect, ShaderLibrary)> = vec![
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
    // Events: the pool's particles spawn one child each on death into a small emitter (the
    // records of every slot written each step, the scan, the child's update).
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
    variants.push((
        format!(
            "events on (death → a 4096-slot child) [{}]",
            mods.names().join(", ")
        ),
        events,
        ShaderLibrary::embedded(),
    ));
    // Every variant on one pool, filled like the throughput rows' (66 steps: every slot
    // alive), and no other large pool alive: on the H100 the same one-step update of a
    // 16.8M pool measured 0.41 ms with one such pool allocated, 0.74 ms with two and
    // 1.04 ms with ten (a device-memory effect, not the code);
    // earlier versions of this table, holding two or more pools, reported the slowed
    // figures, and pools allocated and freed in turn land erratically. Switching variants
    // swaps the pipelines (the bare one is built from another library), never the pool.
    // Stateless mode clears the pool (its records mean something else), so it is measured
    // last. Rounds over the variants keep slow drifts of a shared machine hitting all
    // alike.
    let rounds = 3;
    let per_round = opts.repeats.max(1);
    let mut samples = vec![Vec::new(); variants.len()];
    let is_stateless = |e: &Effect| e.emitters.iter().any(|e| e.stateless);
    let mut sim = GpuSim::new(ctx, variants[1].2.clone(), &plain)?;
    sim.step(&plain, 1.0 / 60.0, 66)?;
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
            // Untimed steps for at least 100 ms: after a pause (a pipeline compile) the
            // H100's SM clock takes tens of ms to climb back, and a fixed 10 steps (4 ms)
            // left ALU-bound variants measured at a low clock (turbulence: 3.3 ms instead
            // of 0.89) while memory-bound ones looked fine.
            let warm = std::time::Instant::now();
            loop {
                sim.step(effect, 1.0 / 60.0, 10)?;
                let _ = ctx.device.poll(wgpu::PollType::wait_indefinitely());
                if warm.elapsed().as_secs_f64() > 0.1 {
                    break;
                }
            }
            for _ in 0..per_round {
                let ms = timer.time(ctx, |enc| {
                    let plans = sim.plan(effect, 1.0 / 60.0, 1);
                    sim.record(enc, effect, &plans);
                });
                samples[i].push(ms);
            }
        }
    }
    let rows = variants
        .iter()
        .zip(samples.iter_mut())
        .map(|((name, _, _), s)| {
            let best = s.iter().copied().fold(f64::INFINITY, f64::min);
            (name.clone(), median(s), best)
        })
        .collect();
    Ok(rows)
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
fn sort_costs(
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

/// The compact state layouts the bench measures beside the full state, and their names.
const COMPACT: [(StateLayout, &str); 2] =
    [(StateLayout::Packed, "packed"), (StateLayout::Tiny, "tiny")];

/// The throughput rows as they are measured: the main table, the tile path's stages, the
/// JSON rows and, per compact layout ([`COMPACT`]), its table and JSON rows.
#[derive(Default)]
struct Tables {
    table: Vec<Vec<String>>,
    tile_table: Vec<Vec<String>>,
    rows: Vec<serde_json::Value>,
    compact_tables: [Vec<Vec<String>>; 2],
    compact_rows: [Vec<serde_json::Value>; 2],
}

impl Tables {
    /// Measures row `side`² on a device of its own, as a fresh process has: after a large
    /// pool is freed, small work on the same device runs 2–5× slower on the H100 (not
    /// memory we keep: its allocator holds nothing then; a new device is fast again). The
    /// compact states are measured from 1M particles up (below, launch overheads dominate).
    fn measure_side(
        &mut self,
        ctx: &GpuContext,
        opts: &PerfOptions,
        side: u32,
        report: &mut Report,
    ) -> anyhow::Result<()> {
        let n = side as u64 * side as u64;
        eprintln!("bench perf: {side}² = {n} particles");
        let row_ctx = GpuContext::headless()?.with_profile(Some(ctx.profile));
        let ctx = &row_ctx;
        let copy = copy_pipeline(ctx, COPY_WGSL);
        let copy20 = copy_pipeline(ctx, COPY20_WGSL);
        let row = measure_row(ctx, opts, n, &copy)?;
        self.push_row(side, n, &row);
        for (k, (layout, name)) in COMPACT.iter().enumerate() {
            if n < 1 << 20 {
                break;
            }
            eprintln!("bench perf: {side}² {name}");
            match measure_compact(ctx, opts, n, *layout, &copy20) {
                Ok(p) => self.push_compact(k, side, n, 2.0 * layout.slot_bytes() as f64, &p, &row),
                Err(e) => report.para(&format!("{side}² {name}: {e}")),
            }
        }
        Ok(())
    }

    /// Row `side`² = `n` of the throughput and tile-stage tables and the JSON.
    fn push_row(&mut self, side: u32, n: u64, row: &PerfRow) {
        if let (Some(all), Some([project, bin]), Some((by_compute, by_draw))) =
            (row.tiles_ms, row.tiles_stages_ms, row.tiles_resolve_ms)
        {
            self.tile_table.push(vec![
                format!("{side}² = {n}"),
                format!("{project:.3}"),
                format!("{:.3}", bin - project),
                format!("{:.3}", all - bin),
                format!("{all:.3}"),
                by_compute.map_or_else(|| "—".into(), |ms| format!("{ms:.3}")),
                format!("{by_draw:.3}"),
            ]);
        }
        let gbps = n as f64 * 64.0 / (row.lean_update_ms * 1e-3) / 1e9;
        let copy_gbps = n as f64 * 64.0 / (row.copy_ms * 1e-3) / 1e9;
        let thesis = THESIS_FPS.iter().find(|(s, _)| *s == side).map(|(_, f)| *f);
        let fps = 1000.0 / row.frame_ms;
        self.table.push(vec![
            format!("{side}² = {n}"),
            format!("{:.3}", row.update_ms),
            format!("{:.3}", row.lean_update_ms),
            format!("{:.3}", row.copy_ms),
            format!(
                "{gbps:.3} GB/s ({:.0} % of the copy's {copy_gbps:.3})",
                100.0 * row.copy_ms / row.lean_update_ms
            ),
            row.billboard_ms
                .map_or("skipped".into(), |m| format!("{m:.3}")),
            format!("{:.3}", row.splat_ms),
            row.tiles_ms.map_or("—".into(), |m| format!("{m:.3}")),
            format!("{:.3}", row.composite_ms),
            format!("{:.3} ({})", row.frame_ms, row.auto_path),
            format!("{fps:.0}"),
            thesis.map_or("—".into(), |t| format!("{t:.0} (ours: {:.2}×)", fps / t)),
            sci(n as f64 * fps),
        ]);
        self.rows.push(serde_json::json!({
            "side": side, "row": row, "update_gb_per_s": gbps, "copy_gb_per_s": copy_gbps,
            "update_vs_copy": row.copy_ms / row.lean_update_ms, "fps": fps, "thesis_fps": thesis,
        }));
    }

    /// Compact layout `k`'s row `side`² = `n` (`moved` bytes per particle-step), against
    /// the full state's `row`.
    fn push_compact(
        &mut self,
        k: usize,
        side: u32,
        n: u64,
        moved: f64,
        p: &PackedRow,
        row: &PerfRow,
    ) {
        let pgbps = n as f64 * moved / (p.update_ms * 1e-3) / 1e9;
        let pcopy = n as f64 * moved / (p.copy_ms * 1e-3) / 1e9;
        self.compact_tables[k].push(vec![
            format!("{side}² = {n}"),
            format!("{:.3}", p.update_ms),
            format!("{:.3}", row.lean_update_ms),
            format!("{:.2}×", row.lean_update_ms / p.update_ms),
            format!("{:.3}", p.copy_ms),
            format!(
                "{pgbps:.3} GB/s ({:.0} % of the copy's {pcopy:.3})",
                100.0 * p.copy_ms / p.update_ms
            ),
        ]);
        self.compact_rows[k].push(serde_json::json!({
            "side": side, "row": p, "full_update_ms": row.lean_update_ms,
            "bytes_moved_per_particle_step": moved,
            "update_gb_per_s": pgbps, "copy_gb_per_s": pcopy,
            "update_vs_copy": p.copy_ms / p.update_ms,
        }));
    }

    /// Writes the throughput, tile-stage and compact-state sections and their JSON.
    fn report(self, report: &mut Report) {
        let Tables {
            table,
            tile_table,
            rows,
            compact_tables,
            compact_rows,
        } = self;
        report.heading("Throughput");
        report.table(
            &[
                "particles",
                "update ms (campfire flames: turbulence + flame pull)",
                "update ms (without them)",
                "copy ms",
                "update bandwidth, without them (vs copy)",
                "billboard draw ms",
                "splat draw ms (clear + splat)",
                "tile draw ms (project, bin, shade, resolve)",
                "composite ms (tonemap + splat resolve)",
                "frame ms (auto path)",
                "fps",
                "2006 thesis fps (ours ×)",
                "particles/s",
            ],
            &table,
        );
        report.heading("Tile path stages");
        report.para(
            "The tile draw of each row timed stage by stage (records that stop after a stage, same run): \
             project every quad, bin (count per block, scan, list; then the dense bins' lists per tile), then shade and resolve (the rest). \
             The last two columns time the resolve of the shaded tiles into the HDR image alone: by compute \
             (the tile draw's, as in the editor, where the adapter reads and writes the image in place) and by a draw \
             (what a host's render pass gets).",
        );
        report.table(
            &[
                "particles",
                "project ms",
                "bin ms",
                "shade + resolve ms",
                "tile draw ms",
                "resolve ms (compute)",
                "resolve ms (draw)",
            ],
            &tile_table,
        );
        let [packed_table, tiny_table] = compact_tables;
        let [packed_rows, tiny_rows] = compact_rows;
        let compact_header = |what: &str| {
            [
                "particles".to_string(),
                format!("{what} update ms"),
                "full update ms (above, without turbulence)".into(),
                "speed-up".into(),
                "copy ms (20 B elements)".into(),
                format!("{what} bandwidth (vs copy)"),
            ]
        };
        report.heading("Packed state (20 B per particle)");
        report.para(
            "The `packed_state` option: f32 position, f16 velocity, 16-bit life fraction, lifetime re-derived \
             from the spawn hash — 40 B moved per particle-step (20 read + 20 written) instead of 64. The copy \
             moves the same 20-byte elements in the same run. Accuracy cost: `ignis bench accuracy` (\"+ packed\" rows).",
        );
        report.table(
            &compact_header("packed").each_ref().map(String::as_str),
            &packed_table,
        );
        report.json["packed"] = serde_json::Value::Array(packed_rows);
        report.heading("Tiny state (10 B per particle)");
        report.para(
            "The `tiny_state` option: f16 position, shared-exponent velocity (8 significant bits of the largest \
             component), no age (each step's births are in a table the update reads, so ages are exact) and no \
             lifetime (re-derived) — 20 B moved per particle-step (10 read + 10 written). One invocation updates a \
             pair of slots (they share a word); the copy moves the same bytes as 20-byte pairs in the same run. \
             Accuracy cost: `ignis bench accuracy` (\"+ tiny\" rows).",
        );
        report.table(
            &compact_header("tiny").each_ref().map(String::as_str),
            &tiny_table,
        );
        report.json["tiny"] = serde_json::Value::Array(tiny_rows);
        report.json["rows"] = serde_json::Value::Array(rows);
    }
}

/// Writes the optional modules' section (`costs`: variant, median ms, best ms).
fn report_modules(
    report: &mut Report,
    ctx: &GpuContext,
    opts: &PerfOptions,
    costs: &[(String, f64, f64)],
) -> anyhow::Result<()> {
    report.heading("Optional modules");
    let bare = costs.first().map_or(f64::NAN, |c| c.2);
    let mcap = opts.module_capacity.min(ctx.max_capacity() as u32);
    report.para(&format!(
        "Update pass at {mcap} particles, ms per step: the median and the best of {} one-step submissions in 3 rounds \
         over the variants, all on one full pool (several large pools alive at once slow every one of them on the \
         H100), each after 100 ms of untimed steps; stateless mode, which clears the pool, last. The comparison uses \
         the best: on the H100 a share of samples runs in a slow state (0.42 → 0.75 ms for the same step, bimodal), which moves medians by tens of percent while the best repeats to 1 %. \
         The first two rows are the \"off costs nothing\" check: the pipeline with every module compiled out \
         by its override constant against one built from source with the module code deleted.",
        opts.repeats.max(1) * 3
    ));
    let mrows: Vec<Vec<String>> = costs
        .iter()
        .map(|(name, ms, best)| {
            vec![
                name.clone(),
                format!("{ms:.4}"),
                format!("{best:.4}"),
                format!("{:+.1} %", 100.0 * (best / bare - 1.0)),
            ]
        })
        .collect();
    report.table(
        &["variant", "update ms/step (median)", "best", "best vs bare"],
        &mrows,
    );
    report.json["modules"] = serde_json::to_value(
        costs
            .iter()
            .map(|(n, ms, best)| serde_json::json!({"variant": n, "ms": ms, "best_ms": best}))
            .collect::<Vec<_>>(),
    )?;
    Ok(())
}

/// Writes the sorting section and its JSON.
fn report_sorts(report: &mut Report, sorts: &[SortRow]) -> anyhow::Result<()> {
    report.heading("Sorting (alpha-blended emitters)");
    report.para(
        "Back-to-front order of (depth key, slot) pairs: the bitonic network split so that every run of stages \
         with a compare distance below 512 is one dispatch in workgroup memory, against the plain network (one \
         global dispatch per stage), same keys, same run. In a frame only the emitter's live window is sorted.",
    );
    let srows: Vec<Vec<String>> = sorts
        .iter()
        .map(|r| {
            vec![
                r.keys.to_string(),
                format!("{} / {}", r.split_dispatches, r.plain_dispatches),
                format!("{:.3}", r.split_ms),
                format!("{:.3}", r.plain_ms),
                format!("{:.2}×", r.plain_ms / r.split_ms),
            ]
        })
        .collect();
    report.table(
        &[
            "keys",
            "dispatches (split / plain)",
            "split ms",
            "plain ms",
            "speed-up",
        ],
        &srows,
    );
    report.json["sort"] = serde_json::to_value(sorts)?;
    Ok(())
}

/// Runs the perf bench.
pub fn run(ctx: &GpuContext, opts: &PerfOptions) -> anyhow::Result<Report> {
    let mut report = Report::new("ignis bench perf", ctx);
    let timer = GpuTimer::new(ctx);
    report.para(&format!(
        "Resolution {}×{}; the default campfire's flames scaled to N particles (sizes ∝ 1/√N, so the fire's \
         footprint and light stay those of the original); medians of {} runs measured with **{}**. \
         The frame uses the update as the campfire's flames have it (2-octave curl-noise turbulence and flame \
         pull: ALU-bound); bandwidth = 64 B per particle-step (32 read + 32 written) / the update time of the same \
         pools without those two modules (memory-bound); the copy is a compute shader moving the same bytes, in the \
         same run. Pools larger than {} particles are split into several emitters \
         (one storage binding each). Each row runs on a GPU device of its own, as in a fresh \
         process (after a large pool is freed, small work on the same device can run several \
         times slower).",
        opts.size.0,
        opts.size.1,
        opts.repeats,
        timer.source.label(),
        ctx.max_capacity().min(1 << 24)
    ));
    // Modules first: measured on a fresh device, before the large pools of the throughput
    // rows have been allocated and freed.
    eprintln!("bench perf: module costs");
    let fresh_ms = small_frame_ms(ctx, opts)?;
    let costs = module_costs(ctx, opts)?;
    let state = ProcessState {
        fresh_ms,
        after_large_ms: small_frame_ms(ctx, opts)?,
        new_device_ms: small_frame_ms(
            &GpuContext::headless()?.with_profile(Some(ctx.profile)),
            opts,
        )?,
        pool: u64::from(opts.module_capacity).min(ctx.max_capacity()),
    };
    let mut tables = Tables::default();
    let limit = ctx.max_capacity() * 8;
    for &side in &opts.sides {
        let n = side as u64 * side as u64;
        if n > limit {
            report.para(&format!(
                "{side}² = {n}: beyond this device's memory budget for the bench, skipped."
            ));
            continue;
        }
        if let Err(e) = tables.measure_side(ctx, opts, side, &mut report) {
            report.para(&format!("{side}² = {n}: {e}"));
        }
    }
    tables.report(&mut report);
    report_modules(&mut report, ctx, opts, &costs)?;
    eprintln!("bench perf: sorting");
    let sorts = sort_costs(ctx, opts, &timer)?;
    report_sorts(&mut report, &sorts)?;
    state.report(&mut report);
    report.json["resolution"] = serde_json::json!([opts.size.0, opts.size.1]);
    report.json["timing"] = serde_json::Value::String(timer.source.label().into());
    Ok(report)
}

/// A small frame (the 64² flames) in three states of the process: on a fresh device; on
/// the same device after the module table's pools were allocated and freed; on a new
/// device of the same process (what each throughput row, and the editor after a large
/// pool, move to).
struct ProcessState {
    fresh_ms: f64,
    after_large_ms: f64,
    new_device_ms: f64,
    /// Particles in the module table's pool.
    pool: u64,
}

/// The 64² row's frame on `ctx`, ms.
fn small_frame_ms(ctx: &GpuContext, opts: &PerfOptions) -> Result<f64, SimError> {
    let copy = copy_pipeline(ctx, COPY_WGSL);
    measure_row(ctx, opts, 64 * 64, &copy).map(|r| r.frame_ms)
}

impl ProcessState {
    /// The section and its JSON (`process_state`).
    fn report(&self, report: &mut Report) {
        report.heading("Process state");
        report.para(&format!(
            "The 64² row's frame (update, auto draw, composite) on the first device before the module table, on the \
             same device after the table's {}-particle pools were allocated and freed, and on a new device of the \
             same process. The check: no state of the process leaves small work 2× slower than a fresh process — \
             the throughput rows run on new devices, and the editor moves to one when a large pool is freed.",
            self.pool
        ));
        let ratio = |ms: f64| format!("{:.2}×", ms / self.fresh_ms);
        report.table(
            &["device", "frame ms", "vs fresh"],
            &[
                vec![
                    "fresh".into(),
                    format!("{:.3}", self.fresh_ms),
                    ratio(self.fresh_ms),
                ],
                vec![
                    "same device, after the large pools".into(),
                    format!("{:.3}", self.after_large_ms),
                    ratio(self.after_large_ms),
                ],
                vec![
                    "new device, same process".into(),
                    format!("{:.3}", self.new_device_ms),
                    ratio(self.new_device_ms),
                ],
            ],
        );
        report.json["process_state"] = serde_json::json!({
            "pool": self.pool,
            "fresh_ms": self.fresh_ms,
            "after_large_ms": self.after_large_ms,
            "new_device_ms": self.new_device_ms,
            "new_device_within_2x": self.new_device_ms <= 2.0 * self.fresh_ms,
        });
    }
}
