//! Helpers shared by the integration tests. Every GPU test runs on a real adapter
//! (lavapipe in CI); no adapter is a failure, never a skip.
#![allow(dead_code)]

use ignis::effect::{ColorStop, Effect, Emitter, Forces, Range, Shape, SpawnNoise, Sprite};
use ignis::testing::gpu::GpuContext;
use ignis::testing::gpu::types::{Particle, SimParams};
use ignis::testing::shaders::ShaderLibrary;
use ignis::testing::sim::{CpuSim, EffectPlanner, GpuSim};

/// The GPU context for a test.
pub fn gpu() -> GpuContext {
    match GpuContext::headless() {
        Ok(ctx) => ctx,
        Err(e) => panic!("GPU tests need an adapter (CI installs mesa-vulkan-drivers): {e}"),
    }
}

/// A single-emitter effect with no noise, no drag and no forces unless set.
pub fn bare_effect(emitter: Emitter) -> Effect {
    Effect {
        emitters: vec![emitter],
        ..Effect::default()
    }
}

/// An emitter with deterministic, simple settings.
pub fn plain_emitter() -> Emitter {
    Emitter {
        name: "test".into(),
        capacity: 4096,
        spawn_rate_per_sec: ignis::effect::Param::Constant(1000.0),
        lifetime_secs: Range::new(1.0, 1.0),
        shape: Shape::Point,
        spread_deg: 0.0,
        speed_m_per_s: Range::new(0.0, 0.0),
        forces: Forces {
            gravity_m_per_s2: [0.0; 3],
            buoyancy_m_per_s2: 0.0,
            drag_per_sec: 0.0,
            wind_m_per_s: [0.0; 3],
            ..Forces::default()
        },
        spawn_noise: SpawnNoise {
            position_amplitude_m: 0.0,
            direction_amplitude: 0.0,
            ..SpawnNoise::default()
        },
        ..Emitter::default()
    }
}

/// Plans `steps` steps and runs them on the GPU and on the CPU reference with the very
/// same parameter blocks. Returns (GPU state, CPU state) of emitter 0.
pub fn run_gpu_and_cpu(
    ctx: &GpuContext,
    effect: &Effect,
    dt: f32,
    steps: usize,
) -> (Vec<Particle>, CpuSim) {
    let mut sim = GpuSim::new(ctx, ShaderLibrary::embedded(), effect).expect("sim");
    let mut planner = EffectPlanner::default();
    let e = &effect.emitters[0];
    let mut cpu = CpuSim::for_emitter(e);
    let mut chunk: Vec<Vec<Option<SimParams>>> = Vec::new();
    for s in 0..steps {
        let plan = planner.plan_step(effect, dt);
        if let Some(p) = &plan[0] {
            cpu.step(p);
        }
        chunk.push(plan);
        if chunk.len() == 32 || s + 1 == steps {
            sim.record_and_submit(effect, &chunk);
            chunk.clear();
        }
    }
    (sim.read_particles(0).expect("readback"), cpu)
}

/// Runs `steps` GPU steps of `dt` and returns the sim.
pub fn run_gpu(ctx: &GpuContext, effect: &Effect, dt: f32, steps: u32) -> GpuSim {
    let mut sim = GpuSim::new(ctx, ShaderLibrary::embedded(), effect).expect("sim");
    sim.step(effect, dt, steps).expect("step");
    sim
}

/// A dump of the effect's state for messages.
pub fn alive_of(p: &[Particle]) -> usize {
    p.iter().filter(|p| p.is_alive()).count()
}

/// Mean and largest absolute difference per channel byte of two same-size images.
pub fn image_diff(a: &image::RgbaImage, b: &image::RgbaImage) -> (f64, u8) {
    assert_eq!(a.dimensions(), b.dimensions());
    let (mut sum, mut max) = (0u64, 0u8);
    for (x, y) in a.as_raw().iter().zip(b.as_raw()) {
        let d = x.abs_diff(*y);
        sum += u64::from(d);
        max = max.max(d);
    }
    (sum as f64 / a.as_raw().len().max(1) as f64, max)
}

/// The share of channels (of all) that differ by more than 8/255 between `a` and `b`.
pub fn share_off(a: &image::RgbaImage, b: &image::RgbaImage) -> f64 {
    let off = a
        .as_raw()
        .iter()
        .zip(b.as_raw())
        .filter(|(x, y)| x.abs_diff(**y) > 8);
    off.count() as f64 / a.as_raw().len() as f64
}

/// The sum of every pixel's R + G + B.
pub fn total_light(img: &image::RgbaImage) -> f64 {
    img.pixels()
        .map(|p| p[0] as f64 + p[1] as f64 + p[2] as f64)
        .sum()
}

/// The light-weighted mean position of `img`'s red channel, in pixels (x right, y down):
/// a sprite brighter at one side (the flame wisp's base) puts it off its middle that way.
pub fn light_centroid(img: &image::RgbaImage) -> (f32, f32) {
    let (mut sum, mut sx, mut sy) = (0.0f64, 0.0f64, 0.0f64);
    for (x, y, p) in img.enumerate_pixels() {
        let r = f64::from(p[0]);
        (sum, sx, sy) = (
            sum + r,
            sx + r * (f64::from(x) + 0.5),
            sy + r * (f64::from(y) + 0.5),
        );
    }
    assert!(sum > 0.0, "nothing lit");
    ((sx / sum) as f32, (sy / sum) as f32)
}

/// Runs `steps` single steps of `player` on the GPU (one submission each).
pub fn play_steps(ctx: &GpuContext, player: &mut ignis::Player, steps: u32) {
    for _ in 0..steps {
        player.step();
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        player.simulate(&mut enc);
        ctx.queue.submit([enc.finish()]);
    }
}

/// A colour gradient of one colour over the whole life.
pub fn flat_color(rgba: [f32; 4]) -> Vec<ColorStop> {
    vec![ColorStop { t: 0.0, rgba }, ColorStop { t: 1.0, rgba }]
}

// ---------------------------------------------------------------------------------------
// Lit smoke (tests/lit.rs, tests/export.rs).

/// The maps' texels of the flat test pair (bytes): RTBA and LBFE.
pub const FLAT_RTBA: [u8; 4] = [51, 102, 153, 255];
pub const FLAT_LBFE: [u8; 4] = [26, 77, 128, 255];
pub const ALBEDO: [f32; 3] = [0.5, 0.6, 0.7];
/// Where the lit test puff hangs.
pub const SMOKE: [f32; 3] = [0.0, 0.5, 0.0];

/// One still, alpha-blended, lit particle at `SMOKE`, 1.5 m wide, opaque white.
pub fn still_smoke(
    maps: ignis::effect::SixWayMaps,
    lighting: ignis::effect::Lighting,
    path: ignis::effect::DrawPath,
) -> Effect {
    let mut e = plain_emitter();
    e.name = "smoke".into();
    e.capacity = 4;
    e.spawn_rate_per_sec = ignis::effect::Param::Constant(0.0);
    e.bursts = vec![ignis::effect::Burst {
        time_secs: 0.0,
        count: 1,
    }];
    e.lifetime_secs = Range::new(100.0, 100.0);
    e.transform.position_m = SMOKE;
    e.look.sprite = ignis::effect::Sprite::SoftDisc;
    e.look.size_m = ignis::effect::Param::Constant(1.5);
    e.look.rotation_random_deg = 0.0;
    e.look.spin_deg_per_s = ignis::effect::Param::Constant(0.0);
    e.look.blend = ignis::effect::BlendMode::Alpha;
    e.look.draw_path = path;
    e.look.color_over_life = flat_color([1.0, 1.0, 1.0, 1.0]);
    e.look.lit = Some(ignis::effect::Lit {
        maps,
        albedo: ALBEDO,
        emission: 0.0,
        self_light: 0.0,
    });
    let mut effect = bare_effect(e);
    effect.lighting = lighting;
    effect
}

/// Writes the flat six-way pair (every texel alike) into `dir`.
pub fn flat_maps(dir: &std::path::Path) -> ignis::effect::SixWayMaps {
    let write = |name: &str, texel: [u8; 4]| {
        let path = dir.join(name);
        image::RgbaImage::from_pixel(16, 16, image::Rgba(texel))
            .save(&path)
            .expect("png");
        path.display().to_string()
    };
    ignis::effect::SixWayMaps::Images {
        rtba: write("flat_rtba.png", FLAT_RTBA),
        lbfe: write("flat_lbfe.png", FLAT_LBFE),
    }
}

/// A 16×16 image sprite written into `dir` as `name`: white where `opaque(x, y)`, clear
/// elsewhere.
fn image_sprite(dir: &std::path::Path, name: &str, opaque: impl Fn(u32, u32) -> bool) -> Sprite {
    let path = dir.join(name);
    image::RgbaImage::from_fn(16, 16, |x, y| {
        image::Rgba(if opaque(x, y) { [255; 4] } else { [0; 4] })
    })
    .save(&path)
    .expect("png");
    Sprite::Image(path.display().to_string())
}

/// A 16×16 white image written into `dir`: a sprite bright up to its frame's edge (its
/// trim the whole frame).
pub fn white_sprite(dir: &std::path::Path) -> Sprite {
    image_sprite(dir, "white.png", |_, _| true)
}

/// A 16×16 white image with its left five columns and bottom five rows clear, written
/// into `dir`: a sprite whose trim cuts its quad on two sides (the quad's first corner off
/// the frame's corner).
pub fn cornered_sprite(dir: &std::path::Path) -> Sprite {
    image_sprite(dir, "cornered.png", |x, y| x >= 5 && y <= 10)
}

/// [`plain_emitter`] as one burst of `count` still particles at its start, living
/// `life_secs`, in a pool of exactly `count`.
pub fn still_burst(count: u32, life_secs: f32) -> Emitter {
    Emitter {
        capacity: count,
        spawn_rate_per_sec: ignis::effect::Param::Constant(0.0),
        bursts: vec![ignis::effect::Burst {
            time_secs: 0.0,
            count,
        }],
        lifetime_secs: Range::new(life_secs, life_secs),
        ..plain_emitter()
    }
}

/// Pixels per metre on the default orbit camera's image plane 3 m out, `height_px` high
/// (its 45° field of view as `Camera` takes it, in f32).
pub fn px_per_m_at_3m(height_px: u32) -> f64 {
    let f = 1.0 / (0.5 * f64::from(45f32.to_radians())).tan();
    0.5 * f64::from(height_px) * f / 3.0
}

/// The pixels an image's light is in (any channel above zero), row by row.
pub fn lit_pixels(img: &image::RgbaImage) -> Vec<(u32, u32)> {
    img.enumerate_pixels()
        .filter(|(_, _, p)| p[0] > 0 || p[1] > 0 || p[2] > 0)
        .map(|(x, y, _)| (x, y))
        .collect()
}

/// Runs `cmd` to completion and fails the test, with its stderr, unless it succeeded.
/// Returns its stdout.
pub fn run_ok(cmd: &mut std::process::Command) -> String {
    let out = cmd
        .output()
        .unwrap_or_else(|e| panic!("running {cmd:?}: {e}"));
    assert!(
        out.status.success(),
        "{cmd:?} failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// A headless run of `effect` advanced `steps` fixed 60 Hz steps.
pub fn headless_after(
    ctx: &GpuContext,
    effect: Effect,
    steps: u32,
) -> ignis::testing::headless::Headless {
    headless_frames(ctx, effect, steps, 1.0 / 60.0)
}

/// A headless run of `effect` advanced `frames` frames of `frame_dt` seconds.
pub fn headless_frames(
    ctx: &GpuContext,
    effect: Effect,
    frames: u32,
    frame_dt: f64,
) -> ignis::testing::headless::Headless {
    let mut run = ignis::testing::headless::Headless::new(ctx, effect, ShaderLibrary::embedded())
        .expect("headless");
    for _ in 0..frames {
        run.advance(frame_dt);
    }
    run
}

/// A 2D sampled texture of `format` holding `bytes` (one mip, tightly packed rows).
pub fn texture_with(
    ctx: &GpuContext,
    (width, height): (u32, u32),
    format: wgpu::TextureFormat,
    bytes: &[u8],
) -> wgpu::Texture {
    use wgpu::util::DeviceExt;
    ctx.device.create_texture_with_data(
        &ctx.queue,
        &wgpu::TextureDescriptor {
            label: Some("test texture"),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        bytes,
    )
}

/// The shipped presets' files (`presets/*.ron`), sorted; at least seven.
pub fn shipped_preset_paths() -> Vec<std::path::PathBuf> {
    let mut paths: Vec<_> = std::fs::read_dir("presets")
        .expect("presets/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "ron"))
        .collect();
    paths.sort();
    assert!(paths.len() >= 7, "shipped presets: {paths:?}");
    paths
}

/// A compute resolve's image (`computed`) is the one its draw gives (`drawn`): within
/// 0.01/255 mean and 1/255 max, with something drawn.
pub fn resolves_agree(what: &str, drawn: &image::RgbaImage, computed: &image::RgbaImage) {
    assert!(total_light(drawn) > 1e3, "{what}: almost nothing drawn");
    let (mean, max) = image_diff(drawn, computed);
    eprintln!("{what}: compute resolve vs draw: mean {mean:.4}/255, max {max}/255");
    assert!(
        mean <= 0.01 && max <= 1,
        "{what}: the compute resolve differs by {mean:.4}/255 mean, {max}/255 max"
    );
}

/// A frame resolved by compute (`computed`, with the commands its player recorded) is the
/// frame the resolve's draw gives (`drawn`): the same image ([`resolves_agree`]), with the
/// resolve's draw become one dispatch.
pub fn compute_resolve_replaces_the_draw(
    what: &str,
    (drawn, by_draw): &(image::RgbaImage, ignis::CommandCounts),
    (computed, by_compute): &(image::RgbaImage, ignis::CommandCounts),
) {
    resolves_agree(what, drawn, computed);
    assert_eq!(
        (by_compute.dispatches, by_compute.draws + 1),
        (by_draw.dispatches + 1, by_draw.draws),
        "{what}: the resolve's draw became a dispatch"
    );
}

/// A folder holding the shaders under test (the embedded ones, or a mutant's copy when
/// scripts/wgsl_mutants.py runs the tests), with each `(name, text)` of `replace` written
/// over or beside them.
pub fn shader_folder(replace: &[(&str, &str)]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("tempdir");
    let mutant = std::env::var_os("IGNIS_MUTANT_SHADERS").map(std::path::PathBuf::from);
    for (name, text) in ignis::testing::shaders::EMBEDDED {
        let text = match &mutant {
            Some(m) => std::fs::read_to_string(m.join(name)).expect("read mutant shader"),
            None => text.to_string(),
        };
        std::fs::write(dir.path().join(name), text).expect("write shader");
    }
    for (name, text) in replace {
        std::fs::write(dir.path().join(name), text).expect("write shader");
    }
    dir
}

/// A compute pipeline of `probe` (WGSL whose entry point is `main`; it may `#import` any
/// embedded shader, or a mutant's under `IGNIS_MUTANT_SHADERS`), composed as the shader
/// library composes the shipped shaders, with its bind group layouts taken from the shader.
pub fn probe_pipeline(ctx: &GpuContext, probe: &str) -> wgpu::ComputePipeline {
    let dir = shader_folder(&[("probe.wgsl", probe)]);
    let composed = ShaderLibrary::from_dir(dir.path())
        .compose("probe.wgsl")
        .expect("probe composes");
    let module = ctx
        .device
        .create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("probe"),
            source: wgpu::ShaderSource::Wgsl(composed.source.as_str().into()),
        });
    ctx.device
        .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("probe"),
            layout: None,
            module: &module,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        })
}

/// Runs `probe` (see [`probe_pipeline`]; group 0: binding 0 the `input` bytes as read-only
/// storage, binding 1 an `out_size`-byte read-write storage buffer) as `workgroups`
/// workgroups, and returns binding 1's bytes.
pub fn run_probe(
    ctx: &GpuContext,
    probe: &str,
    input: &[u8],
    out_size: u64,
    workgroups: u32,
) -> Vec<u8> {
    use wgpu::util::DeviceExt;
    let d = &ctx.device;
    let pipeline = probe_pipeline(ctx, probe);
    let input = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: None,
        contents: input,
        usage: wgpu::BufferUsages::STORAGE,
    });
    let [out, staging] = [
        wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
    ]
    .map(|usage| {
        d.create_buffer(&wgpu::BufferDescriptor {
            label: None,
            size: out_size,
            usage,
            mapped_at_creation: false,
        })
    });
    let group = bind_in_order(
        ctx,
        &pipeline,
        [input.as_entire_binding(), out.as_entire_binding()],
    );
    let mut enc = d.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups(workgroups, 1, 1);
    }
    enc.copy_buffer_to_buffer(&out, 0, &staging, 0, out_size);
    ctx.queue.submit([enc.finish()]);
    ignis::testing::sim::gpu_sim::map_read(ctx, &staging).expect("read back")
}

/// Group 0 of `pipeline` with `resources` at bindings 0, 1, … in order.
pub fn bind_in_order<const N: usize>(
    ctx: &GpuContext,
    pipeline: &wgpu::ComputePipeline,
    resources: [wgpu::BindingResource<'_>; N],
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry<'_>> = resources
        .into_iter()
        .enumerate()
        .map(|(i, resource)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource,
        })
        .collect();
    ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(0),
        entries: &entries,
    })
}
