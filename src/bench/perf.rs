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

mod report;
use report::*;

mod costs;
use costs::*;

mod draws;
use draws::*;

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

impl PerfOptions {
    /// `bench perf`'s options for `ctx`'s adapter: on a software adapter smaller defaults (sides up to 2048², 1M
    /// billboards, a 1M-particle module pool); 0 or none given means the default.
    pub fn for_adapter(
        ctx: &crate::gpu::GpuContext,
        sides: Vec<u32>,
        size: (u32, u32),
        repeats: usize,
        module_capacity: u32,
    ) -> PerfOptions {
        let cpu = ctx.profile.is_software();
        let sides = if sides.is_empty() {
            let mut s = vec![64, 128, 256, 512, 1024, 2048];
            if !cpu {
                s.extend([4096, 8192, 11586]);
            }
            s
        } else {
            sides
        };
        PerfOptions {
            sides,
            size,
            repeats: repeats.max(1),
            billboard_limit: if cpu { 1 << 20 } else { 1 << 26 },
            module_capacity: if module_capacity > 0 {
                module_capacity
            } else if cpu {
                1 << 20
            } else {
                1 << 24
            },
        }
    }
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
    /// The draw paths' times.
    #[serde(flatten)]
    pub draws: DrawCosts,
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
    let layout = crate::gpu::bind_group_layout(
        ctx,
        "bench copy layout",
        &[
            crate::gpu::compute_storage_entry(0, true),
            crate::gpu::compute_storage_entry(1, false),
        ],
    );
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

    let d = draw_costs(ctx, opts, n, (&sim, &effect), &timer)?;
    let draw = match d.auto_path {
        "splat" => d.splat_ms,
        "tiles" => d.tiles_ms.unwrap_or(f64::NAN),
        _ => d.billboard_ms.unwrap_or(f64::NAN),
    };
    Ok(PerfRow {
        particles: n,
        pools: effect.emitters.len() as u64,
        update_ms,
        lean_update_ms,
        copy_ms,
        frame_ms: update_ms + draw + d.composite_ms,
        draws: d,
    })
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
