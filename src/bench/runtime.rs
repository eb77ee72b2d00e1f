//! `ignis bench runtime`: what the runtime adds to a host's frame, through the public
//! API only. A host with an HDR target and a depth buffer plays N torches (1, 10, 100
//! instances of one player); for each N, after a warm-up past the longest lifetime, the
//! median over frames of the GPU time of `record` (simulation + sort) and of `draw`
//! (inside the host's pass, soft edges against its depth), and of the CPU time of the
//! calls themselves. Then 100 instances against the same particles in one instance whose
//! emitters have 100× the capacity and spawn rate, both at one spot (the same fill), to
//! separate the per-instance constant from the per-particle cost.

use std::time::Instant;

use glam::{Mat4, Vec3, vec3};

use crate::bench::Report;
use crate::effect::{BlendMode, Effect};
use crate::gpu::GpuContext;
use crate::gpu::timer::{GpuTimer, median};
use crate::render::tiles::TileStages;
use crate::runtime::{Camera, Player, PlayerError, PlayerSettings};

const COLOR: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
const DEPTH: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Settings of the runtime bench.
pub struct RuntimeOptions {
    /// The effect played (the torch).
    pub effect: Effect,
    /// Its folder (PNG sprites).
    pub asset_dir: std::path::PathBuf,
    /// Instance counts to measure.
    pub counts: Vec<u32>,
    /// The host's target size.
    pub size: (u32, u32),
    /// Measured frames per row (the median is reported).
    pub frames: usize,
}

/// One measured configuration.
struct Row {
    label: String,
    instances: u32,
    slots: u64,
    record_ms: f64,
    draw_ms: f64,
    cpu_us: f64,
    /// Of which (medians apart): `advance`, `record`, `draw` in the host's pass, and
    /// finishing the encoder (where wgpu encodes the commands it recorded for the driver).
    cpu_parts_us: [f64; 4],
    /// The dispatches and draws the player recorded for the last timed frame.
    commands: crate::gpu::commands::CommandCounts,
    /// The record's GPU time in parts (medians apart): the steps alone, then the rest
    /// (light, sort, splat, tiles) with the tiles stopped after their projection, after
    /// their binning, and whole.
    stages_ms: [f64; 4],
}

/// Runs the bench and returns its report.
pub fn run(ctx: &GpuContext, opts: &RuntimeOptions) -> Result<Report, PlayerError> {
    let host = Host::new(ctx, opts.size);
    let timer = GpuTimer::new(ctx);
    let mut rows = Vec::new();
    for &n in &opts.counts {
        let spots = grid(n);
        rows.push(measure(
            &host,
            &timer,
            opts,
            &opts.effect,
            &spots,
            format!("{n} torches, a grid 1 m apart"),
        )?);
    }
    let n = opts.counts.iter().copied().max().unwrap_or(100).max(2);
    let same_spot = vec![Vec3::ZERO; n as usize];
    let many = measure(
        &host,
        &timer,
        opts,
        &opts.effect,
        &same_spot,
        format!("{n} torches at one spot"),
    )?;
    let merged = scaled(&opts.effect, n);
    let one = measure(
        &host,
        &timer,
        opts,
        &merged,
        &[Vec3::ZERO],
        format!("1 torch with {n}× the particles"),
    )?;
    // The same without the alpha-blended layers (no sort): what the sort adds per instance.
    let mut additive = opts.effect.clone();
    additive
        .emitters
        .retain(|e| e.look.blend == BlendMode::Additive);
    let label = |what: &str| format!("{what}, additive layers only");
    let many_additive = measure(
        &host,
        &timer,
        opts,
        &additive,
        &same_spot,
        label(&format!("{n} torches at one spot")),
    )?;
    let one_additive = measure(
        &host,
        &timer,
        opts,
        &scaled(&additive, n),
        &[Vec3::ZERO],
        label(&format!("1 torch with {n}× the particles")),
    )?;
    let compare = [many, one, many_additive, one_additive];
    Ok(report(ctx, opts, &timer, &rows, &compare))
}

/// `n` spots on a square grid 1 m apart, centred on the origin.
fn grid(n: u32) -> Vec<Vec3> {
    let side = (n as f32).sqrt().ceil().max(1.0) as u32;
    (0..n)
        .map(|i| {
            let (x, z) = ((i % side) as f32, (i / side) as f32);
            vec3(
                x - 0.5 * (side - 1) as f32,
                0.0,
                -(z - 0.5 * (side - 1) as f32),
            )
        })
        .collect()
}

/// `effect` with every emitter's capacity and spawn rate multiplied by `n`.
fn scaled(effect: &Effect, n: u32) -> Effect {
    let mut e = effect.clone();
    for em in &mut e.emitters {
        em.capacity *= n;
        em.spawn_rate_per_sec = em.spawn_rate_per_sec.scaled(n as f32);
    }
    e
}

/// Plays `effect` at `spots` and measures the median frame.
fn measure(
    host: &Host,
    timer: &GpuTimer,
    opts: &RuntimeOptions,
    effect: &Effect,
    spots: &[Vec3],
    label: String,
) -> Result<Row, PlayerError> {
    let settings = PlayerSettings {
        depth_format: Some(DEPTH),
        asset_dir: Some(opts.asset_dir.clone()),
        ..PlayerSettings::new(COLOR)
    };
    let mut player = Player::new(&host.ctx.device, &host.ctx.queue, effect, settings)?;
    for (i, spot) in spots.iter().enumerate() {
        player.add_instance(Mat4::from_translation(*spot), i as u32 + 1)?;
    }
    let camera = host.camera(spots);
    let warm_up = (effect.longest_lifetime_secs() * 60.0).ceil() as usize + 10;
    let (mut record, mut draw) = (Vec::new(), Vec::new());
    let (mut cpu, mut parts) = (Vec::new(), [(); 4].map(|_| Vec::new()));
    let us = |a: Instant, b: Instant| (b - a).as_secs_f64() * 1e6;
    for frame in 0..warm_up + opts.frames {
        // The CPU time of the calls alone: the GPU (on a CPU adapter, the same cores)
        // is idle while they run.
        let _ = host.ctx.device.poll(wgpu::PollType::wait_indefinitely());
        let mut marks = [Instant::now(); 5];
        player.advance(1.0 / 60.0);
        marks[1] = Instant::now();
        let mut enc = host.ctx.device.create_command_encoder(&Default::default());
        player.record(&mut enc, &camera, Some(&host.depth))?;
        marks[2] = Instant::now();
        host.pass(&mut enc, |pass| player.draw(pass));
        marks[3] = Instant::now();
        let commands = enc.finish();
        marks[4] = Instant::now();
        host.ctx.queue.submit([commands]);
        if frame < warm_up {
            continue;
        }
        // The next frame timed on the GPU, in two parts.
        cpu.push(us(marks[0], marks[4]));
        for (i, part) in parts.iter_mut().enumerate() {
            part.push(us(marks[i], marks[i + 1]));
        }
        player.advance(1.0 / 60.0);
        let mut recorded = Ok(());
        record.push(timer.time(&host.ctx, |enc| {
            recorded = player.record(enc, &camera, Some(&host.depth));
        }));
        recorded?;
        draw.push(timer.time(&host.ctx, |enc| host.pass(enc, |pass| player.draw(pass))));
    }
    let commands = player.recorded_commands();
    let stages_ms = stage_costs(host, timer, opts.frames, &mut player, &camera)?;
    Ok(Row {
        label,
        instances: spots.len() as u32,
        slots: spots.len() as u64
            * effect
                .emitters
                .iter()
                .map(|e| u64::from(e.capacity))
                .sum::<u64>(),
        record_ms: median(&mut record),
        draw_ms: median(&mut draw),
        cpu_us: median(&mut cpu),
        cpu_parts_us: parts.map(|mut p| median(&mut p)),
        commands,
        stages_ms,
    })
}

/// The record's GPU time in parts, over `frames` frames each: the steps (`simulate`),
/// then the rest of the record with the tiles stopped after their projection, after
/// their binning, and whole (the same three without tiles where nothing takes them).
fn stage_costs(
    host: &Host,
    timer: &GpuTimer,
    frames: usize,
    player: &mut Player,
    camera: &Camera,
) -> Result<[f64; 4], PlayerError> {
    let mut parts = [(); 4].map(|_| Vec::new());
    let stages = [TileStages::Project, TileStages::Bin, TileStages::All];
    for _ in 0..frames {
        for (k, stage) in stages.into_iter().enumerate() {
            if let Some(t) = player.tile_pass() {
                t.set_stages(stage);
            }
            player.advance(1.0 / 60.0);
            let steps = timer.time(&host.ctx, |enc| player.simulate(enc));
            if k == 0 {
                parts[0].push(steps);
            }
            let mut recorded = Ok(());
            parts[k + 1].push(timer.time(&host.ctx, |enc| {
                recorded = player.record(enc, camera, Some(&host.depth));
            }));
            recorded?;
        }
    }
    Ok(parts.map(|mut p| median(&mut p)))
}

fn report(
    ctx: &GpuContext,
    opts: &RuntimeOptions,
    timer: &GpuTimer,
    rows: &[Row],
    compare: &[Row; 4],
) -> Report {
    let [many, one, ..] = compare;
    let mut r = Report::new(
        "ignis runtime: the cost of N instances in a host frame",
        ctx,
    );
    r.para(&format!(
        "`{}` at {}×{}: a host HDR target and depth buffer; medians of {} frames after a \
            warm-up past the longest lifetime, {} frames at 60 fps. `record` = the instances' \
            simulation steps and the smoke's sort; `draw` = every instance's billboards in the \
            host's pass, soft edges against its depth. CPU = the API calls of a frame (advance, \
            record, draw and finishing the encoder; encoding, not waiting), and each part's \
            median apart (wgpu encodes the recorded commands for the driver when the encoder \
            is finished). The last column splits the record's GPU time over as many frames \
            more: the steps alone, then the rest of the record (the light, the sort, the \
            splat and the tiles) with the tiles stopped after their projection, after their \
            binning, and whole. GPU times: {}.",
        opts.effect.name,
        opts.size.0,
        opts.size.1,
        opts.frames,
        opts.frames,
        timer.source.label()
    ));
    let row = |x: &Row| {
        vec![
            x.label.clone(),
            x.slots.to_string(),
            format!("{:.3}", x.record_ms),
            format!("{:.3}", x.draw_ms),
            format!("{:.3}", x.record_ms + x.draw_ms),
            format!("{:.0}", x.cpu_us),
            x.cpu_parts_us.map(|t| format!("{t:.0}")).join(" / "),
            format!("{} / {}", x.commands.dispatches, x.commands.draws),
            format!("{:.1}", x.cpu_us / f64::from(x.instances.max(1))),
            x.stages_ms.map(|t| format!("{t:.3}")).join(" / "),
        ]
    };
    let header = [
        "configuration",
        "slots",
        "record ms",
        "draw ms",
        "total ms",
        "CPU µs",
        "CPU: advance / record / draw / finish µs",
        "dispatches / draws",
        "CPU µs / instance",
        "record on the GPU: steps / rest to the tiles' projection / binning / shade ms",
    ];
    r.heading("Instances in a host frame");
    r.table(&header, &rows.iter().map(row).collect::<Vec<_>>());
    r.heading("Instances against one emitter with the same particles");
    r.table(&header, &compare.iter().map(row).collect::<Vec<_>>());
    let extra = (many.record_ms + many.draw_ms) - (one.record_ms + one.draw_ms);
    let per = extra / f64::from(many.instances.saturating_sub(1).max(1));
    r.para(&format!(
        "{} instances cost {:.3} ms more than one emitter with the same particles: {:.4} ms \
            ({:.1} µs) of GPU time per extra instance (its own dispatches, sort and draw \
            calls); CPU {:.1} µs per instance.",
        many.instances,
        extra,
        per,
        per * 1e3,
        (many.cpu_us - one.cpu_us) / f64::from(many.instances.saturating_sub(1).max(1))
    ));
    r.json["runtime"] = serde_json::json!({
        "effect": opts.effect.name,
        "size": format!("{}x{}", opts.size.0, opts.size.1),
        "timing": timer.source.label(),
        "rows": rows.iter().chain(compare).map(|x| serde_json::json!({
            "configuration": x.label,
            "instances": x.instances,
            "slots": x.slots,
            "record_ms": x.record_ms,
            "draw_ms": x.draw_ms,
            "cpu_us": x.cpu_us,
            "cpu_advance_us": x.cpu_parts_us[0],
            "cpu_record_us": x.cpu_parts_us[1],
            "cpu_draw_us": x.cpu_parts_us[2],
            "cpu_finish_us": x.cpu_parts_us[3],
            "dispatches": x.commands.dispatches,
            "draws": x.commands.draws,
            "gpu_steps_ms": x.stages_ms[0],
            "gpu_rest_to_tiles_projection_ms": x.stages_ms[1],
            "gpu_rest_to_tiles_binning_ms": x.stages_ms[2],
            "gpu_rest_ms": x.stages_ms[3],
        })).collect::<Vec<_>>(),
        "extra_gpu_ms_per_instance": per,
    });
    r
}

/// The bench's host: colour and depth targets.
struct Host {
    ctx: GpuContext,
    size: (u32, u32),
    color: wgpu::TextureView,
    depth: wgpu::TextureView,
}

impl Host {
    fn new(ctx: &GpuContext, size: (u32, u32)) -> Self {
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        let make = |format| {
            crate::gpu::texture_2d(&ctx.device, "bench host", size, 1, format, usage)
                .create_view(&Default::default())
        };
        let host = Self {
            ctx: ctx.clone(),
            size,
            color: make(COLOR),
            depth: make(DEPTH),
        };
        // The host's opaque pass: here it only clears the depth the particles read.
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        drop(enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &host.depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            ..Default::default()
        }));
        ctx.queue.submit([enc.finish()]);
        host
    }

    /// A camera that frames every spot (the torches' flames are about 1 m up).
    fn camera(&self, spots: &[Vec3]) -> Camera {
        let radius = spots.iter().map(|s| s.length()).fold(0.0, f32::max) + 1.0;
        let target = vec3(0.0, 1.0, 0.0);
        let eye = target + vec3(0.0, 0.6, 1.0).normalize() * radius * 2.2;
        let aspect = self.size.0 as f32 / self.size.1 as f32;
        Camera::new(
            glam::camera::rh::view::look_at_mat4(eye, target, Vec3::Y),
            glam::camera::rh::proj::directx::perspective(0.8, aspect, 0.05, 200.0),
            self.size,
        )
    }

    /// The host's transparent pass: its colour loaded, its depth read-only.
    fn pass(&self, enc: &mut wgpu::CommandEncoder, draw: impl FnOnce(&mut wgpu::RenderPass<'_>)) {
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("bench host pass"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &self.color,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.depth,
                depth_ops: None,
                stencil_ops: None,
            }),
            ..Default::default()
        });
        draw(&mut pass);
    }
}
