//! Looks on a real adapter: the WGSL flipbook and colour-ramp functions against
//! hand-computed values, PNG sprites (missing, broken, reloaded), streaks (their cap and
//! side), a sprite's turn (random rotation and spin), soft ground,
//! bloom, and fixed-seed frames of presets against committed reference images.
//!
//! Reference images live in `tests/reference/`. They are regenerated only deliberately:
//! `IGNIS_BLESS=1 cargo test --release --test looks reference_images` (then look at them
//! and commit them with the change that moved them).
// The editor, the `ignis` binary or the benches: the default `editor` feature.
#![cfg(feature = "editor")]

mod common;

use std::path::Path;

use common::*;
use glam::Vec3;
use ignis::effect::{
    BlendMode, ColorStop, Curve, DrawPath, Effect, Flipbook, FlipbookMode, GroundPlane, Look,
    Param, Range, Sprite, Streak,
};
use ignis::testing::effect::{CURVE_WIDTH, lookup_blend};
use ignis::testing::gpu::GpuContext;
use ignis::testing::gpu::types::{CameraUniform, LookUniform};
use ignis::testing::headless::Headless;
use ignis::testing::render::frame::look_uniform;
use ignis::testing::render::look_bake::{
    RAMP_WIDTH, bake_look_curves, bake_ramp, flipbook_frame, sample_gradient,
};
use ignis::testing::render::sprites::SpriteLibrary;
use ignis::testing::shaders::ShaderLibrary;
use wgpu::util::DeviceExt;

const PROBE: &str = r#"
#import "look.wgsl"
@group(0) @binding(0) var<uniform> camera: CameraUniform;
@group(0) @binding(1) var<uniform> look: LookUniform;
@group(0) @binding(2) var ramps: texture_2d<f32>;
// The state bindings look.wgsl's `load_pair` reads (unused here).
@group(1) @binding(0) var<storage, read> prev: array<Particle>;
@group(1) @binding(1) var<storage, read> cur: array<Particle>;
@group(1) @binding(3) var<storage, read> prev_packed: array<PackedParticle>;
@group(1) @binding(4) var<storage, read> cur_packed: array<PackedParticle>;
@group(1) @binding(5) var<storage, read> births: array<Birth>;
// x: age, y: life, z: random start number, w: blend frames (0/1).
@group(0) @binding(3) var<storage, read> inputs: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> outputs: array<vec4<f32>>;

@compute @workgroup_size(1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    _ = camera.viewport;
    let v = inputs[i];
    let curves = look_curves(age_fraction(v.x, v.y), vec4<f32>(v.z));
    outputs[3u * i] = vec4<f32>(flipbook_frames(v.x, v.y, v.z, v.w > 0.5, curves.w), 0.0);
    outputs[3u * i + 1u] = particle_color(age_fraction(v.x, v.y));
    outputs[3u * i + 2u] = curves;
}
"#;

/// Runs look.wgsl's `flipbook_frames`, `particle_color` and `look_curves` on the GPU for
/// `inputs` (age, life, start01 — also every curve's random number —, blend) with
/// `look`'s uniform, ramp and curve rows. Returns per input (frame, next, weight), the
/// colour and the curves.
fn probe(ctx: &GpuContext, look: &Look, inputs: &[[f32; 4]]) -> Vec<([f32; 3], [f32; 4])> {
    probe_all(ctx, look, inputs)
        .into_iter()
        .map(|(f, c, _)| (f, c))
        .collect()
}

/// The look's colour ramp and its two curve rows, as the frame's ramp texture holds them.
fn ramp_texture(ctx: &GpuContext, look: &Look) -> wgpu::Texture {
    let mut ramp = bake_ramp(&look.color_over_life);
    let [a, b] = bake_look_curves(look);
    ramp.extend(a);
    ramp.extend(b);
    common::texture_with(
        ctx,
        (RAMP_WIDTH, 3),
        wgpu::TextureFormat::Rgba32Float,
        bytemuck::cast_slice(&ramp),
    )
}

/// [`probe`] with each input's curves.
fn probe_all(
    ctx: &GpuContext,
    look: &Look,
    inputs: &[[f32; 4]],
) -> Vec<([f32; 3], [f32; 4], [f32; 4])> {
    let pipeline = probe_pipeline(ctx, PROBE);
    let d = &ctx.device;
    let uniform = look_uniform(look, 0, 1234, 1.0);
    let camera = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: None,
        contents: bytemuck::bytes_of(&CameraUniform::default()),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let look_buf = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: None,
        contents: bytemuck::bytes_of::<LookUniform>(&uniform),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let ramps = ramp_texture(ctx, look);
    let input_buf = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: None,
        contents: bytemuck::cast_slice(inputs),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let out_size = (inputs.len() * 48) as u64;
    let out = d.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: out_size,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let view = ramps.create_view(&Default::default());
    let group = d.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: camera.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: look_buf.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: wgpu::BindingResource::TextureView(&view),
            },
            wgpu::BindGroupEntry {
                binding: 3,
                resource: input_buf.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 4,
                resource: out.as_entire_binding(),
            },
        ],
    });
    let staging = d.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: out_size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc = d.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups(inputs.len() as u32, 1, 1);
    }
    enc.copy_buffer_to_buffer(&out, 0, &staging, 0, out_size);
    ctx.queue.submit([enc.finish()]);
    let bytes = ignis::testing::sim::gpu_sim::map_read(ctx, &staging).expect("readback");
    let values: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
    values
        .chunks(3)
        .map(|c| ([c[0][0], c[0][1], c[0][2]], c[1], c[2]))
        .collect()
}

fn flip_look(flipbook: Flipbook) -> Look {
    Look {
        flipbook: Some(flipbook),
        ..Look::default()
    }
}

/// A look with a curve in every channel, each in another mode: size from two curves,
/// opacity a smooth curve, spin a random range, the flipbook frame a curve.
fn curved_look() -> Look {
    Look {
        size_m: Param::TwoCurves {
            a: Curve {
                keys: vec![(0.0, 0.1), (0.3, 0.6), (1.0, 0.2)],
                smooth: true,
            },
            b: Curve::line(0.3, 1.2),
        },
        opacity: Param::Curve {
            keys: ignis::effect::SHAPES[3].1.to_vec(),
            smooth: true,
        },
        spin_deg_per_s: Param::Range {
            min: -90.0,
            max: 200.0,
        },
        flipbook: Some(Flipbook {
            rows: 4,
            cols: 4,
            mode: FlipbookMode::Frames(Param::Curve {
                keys: vec![(0.0, 0.0), (0.5, 15.0), (1.0, 3.0)],
                smooth: true,
            }),
            blend_frames: true,
            random_start: false,
        }),
        ..Look::default()
    }
}

/// `look_curves` on the GPU equals the CPU reference (`lookup_blend` of the baked rows) at
/// every texel and between texels within 1e-4, and both equal the curves themselves
/// (`Param::eval`, the spin's integral) within 1e-4; the frame curve drives the flipbook.
#[test]
fn look_curves_on_the_gpu_match_the_cpu_reference_at_every_texel_and_between() {
    let ctx = gpu();
    let look = curved_look();
    let life = 2.0f32;
    let n = CURVE_WIDTH as usize;
    let mut inputs = Vec::new();
    for i in 0..n {
        let u = (i as f32 * 0.618_034).fract();
        inputs.push([life * i as f32 / (n - 1) as f32, life, u, 1.0]);
    }
    for k in 0..1001 {
        let u = (k as f32 * 0.381_966).fract();
        inputs.push([life * (k as f32 + 0.37) / 1001.0, life, u, 1.0]);
    }
    let got = probe_all(&ctx, &look, &inputs);
    let rows = bake_look_curves(&look);
    let params = ignis::testing::render::look_bake::look_curve_params(&look);
    let mut worst = [0.0f32; 4];
    for (input, (frames, _, curves)) in inputs.iter().zip(&got) {
        let t = (input[0] / input[1]).clamp(0.0, 1.0);
        let u = input[2];
        let cpu = lookup_blend(&rows, t, [u; 4]);
        let (t64, u64) = (f64::from(t), f64::from(u));
        let exact = [
            params[0].eval(t64, u64),
            params[1].eval(t64, u64),
            params[2].integral(u64, 0.0, t64).to_radians(),
            params[3].eval(t64, u64),
        ];
        for c in 0..4 {
            let d = (curves[c] - cpu[c]).abs();
            worst[c] = worst[c].max(d);
            assert!(
                d <= 1e-4,
                "channel {c} at t {t}, u {u}: GPU {} vs CPU {}",
                curves[c],
                cpu[c]
            );
            let e = (f64::from(curves[c]) - exact[c]).abs();
            assert!(
                e <= 1e-4,
                "channel {c} at t {t}, u {u}: GPU {} vs exact {}",
                curves[c],
                exact[c]
            );
        }
        // The frame curve picks the flipbook frame (CPU mirror of flipbook_frames).
        let flip = look.flipbook.as_ref().expect("flipbook");
        let choice = flipbook_frame(flip, input[0], input[1], input[2], cpu[3]);
        assert_eq!(
            [frames[0], frames[1]],
            [choice.frame as f32, choice.next as f32]
        );
    }
    eprintln!("worst GPU − CPU per channel (size, opacity, spin, frame): {worst:?}");
}

#[test]
fn flipbook_frames_match_hand_computed_values_at_the_ends_and_between() {
    let ctx = gpu();
    let life = 2.0;
    // 4 × 4 over life: frame 0 at birth, frame 15 at death.
    let over_life = Flipbook {
        rows: 4,
        cols: 4,
        mode: FlipbookMode::OverLife,
        blend_frames: true,
        random_start: false,
    };
    let fb = |rows, cols, mode, blend_frames, random_start| Flipbook {
        rows,
        cols,
        mode,
        blend_frames,
        random_start,
    };
    let cut = fb(4, 4, FlipbookMode::OverLife, false, false);
    let fps10 = || FlipbookMode::FrameRate { fps: 10.0 };
    let cases: Vec<(Flipbook, [f32; 4], [f32; 3])> = vec![
        // Blending: position t·(16 − 1).
        (over_life.clone(), [0.0, life, 0.0, 1.0], [0.0, 1.0, 0.0]),
        (over_life.clone(), [life, life, 0.0, 1.0], [15.0, 15.0, 0.0]),
        (over_life.clone(), [1.0, life, 0.0, 1.0], [7.0, 8.0, 0.5]),
        // Cutting: each frame an equal share of life.
        (cut.clone(), [0.0, life, 0.0, 0.0], [0.0, 0.0, 0.0]),
        (cut.clone(), [life, life, 0.0, 0.0], [15.0, 15.0, 0.0]),
        (cut.clone(), [1.0, life, 0.0, 0.0], [8.0, 8.0, 0.0]),
        // 2 × 3 at 10 fps from a random start: start01 0.5 → frame 3 of 6.
        (
            fb(2, 3, fps10(), false, true),
            [0.0, life, 0.5, 0.0],
            [3.0, 4.0, 0.0],
        ),
        (
            fb(2, 3, fps10(), false, true),
            [0.25, life, 0.5, 0.0],
            [5.0, 0.0, 0.0],
        ),
        // Looping past the last frame, with blending: 0.35 s × 10 = 3.5 → frames 3, 4.
        (
            fb(2, 3, fps10(), true, false),
            [0.35, life, 0.9, 1.0],
            [3.0, 4.0, 0.5],
        ),
        (
            fb(2, 3, fps10(), true, false),
            [0.55, life, 0.0, 1.0],
            [5.0, 0.0, 0.5],
        ),
    ];
    for (flip, input, want) in cases {
        let got = probe(&ctx, &flip_look(flip.clone()), &[input])[0].0;
        for k in 0..3 {
            assert!(
                (got[k] - want[k]).abs() < 1e-4,
                "{flip:?} at {input:?}: GPU {got:?}, hand-computed {want:?}"
            );
        }
        let cpu = flipbook_frame(&flip, input[0], input[1], input[2], 0.0);
        assert_eq!(
            [cpu.frame as f32, cpu.next as f32],
            [want[0], want[1]],
            "CPU mirror"
        );
        assert!((cpu.weight - want[2]).abs() < 1e-4, "CPU mirror weight");
    }
}

#[test]
fn gradient_sampling_is_exact_at_birth_and_death_and_any_number_of_stops_works() {
    let ctx = gpu();
    let mut look = Look {
        color_over_life: vec![
            ColorStop {
                t: 0.0,
                rgba: [0.9, 0.8, 0.7, 0.0],
            },
            ColorStop {
                t: 0.25,
                rgba: [1.0, 0.5, 0.0, 1.0],
            },
            ColorStop {
                t: 1.0,
                rgba: [0.1, 0.2, 0.3, 0.4],
            },
        ],
        ..Look::default()
    };
    let life = 1.5;
    // Age 0, age = lifetime, and t = 0.625 (between stops: hand-computed midpoint of the
    // second segment: (1.0+0.1)/2, (0.5+0.2)/2, (0.0+0.3)/2, (1.0+0.4)/2).
    let out = probe(
        &ctx,
        &look,
        &[
            [0.0, life, 0.0, 0.0],
            [life, life, 0.0, 0.0],
            [0.625 * life, life, 0.0, 0.0],
        ],
    );
    assert_eq!(out[0].1, [0.9, 0.8, 0.7, 0.0], "age 0 is the first stop");
    assert_eq!(
        out[1].1,
        [0.1, 0.2, 0.3, 0.4],
        "age = lifetime is the last stop"
    );
    let mid = [0.55, 0.35, 0.15, 0.7];
    for k in 0..4 {
        assert!(
            (out[2].1[k] - mid[k]).abs() < 2e-3,
            "{:?} vs {mid:?}",
            out[2].1
        );
    }

    // 40 stops (beyond the old 8-stop uniform): the ramp follows the CPU gradient.
    let stops: Vec<ColorStop> = (0..40)
        .map(|i| {
            let t = i as f32 / 39.0;
            ColorStop {
                t,
                rgba: [t, 1.0 - t, (i % 2) as f32, 0.5],
            }
        })
        .collect();
    look.color_over_life = stops.clone();
    assert!(
        Effect {
            emitters: vec![ignis::effect::Emitter {
                look: look.clone(),
                ..plain_emitter()
            }],
            ..Effect::default()
        }
        .validate()
        .is_ok()
    );
    let inputs: Vec<[f32; 4]> = (0..=64)
        .map(|i| [i as f32 / 64.0 * life, life, 0.0, 0.0])
        .collect();
    let out = probe(&ctx, &look, &inputs);
    let mut worst: f32 = 0.0;
    for (input, (_, c)) in inputs.iter().zip(&out) {
        let want = sample_gradient(&stops, input[0] / life);
        for k in 0..4 {
            worst = worst.max((c[k] - want[k]).abs());
        }
    }
    // Ramp texels are 1/1023 apart: a zig-zag of 39 segments deviates by at most one
    // texel's share of a segment's rise (39 / 1023 ≈ 0.04) near its corners.
    assert!(worst < 0.04, "worst ramp deviation {worst}");
    assert_eq!(out[0].1, stops[0].rgba);
    assert_eq!(out[64].1, stops[39].rgba);
}

fn write_png(path: &Path, w: u32, h: u32, pixel: impl Fn(u32, u32) -> [u8; 4]) {
    image::RgbaImage::from_fn(w, h, |x, y| image::Rgba(pixel(x, y)))
        .save(path)
        .expect("write png");
}

#[test]
fn missing_or_broken_pngs_fall_back_with_a_clear_error_and_changed_files_reload() {
    let ctx = gpu();
    let dir = tempfile::tempdir().expect("tempdir");
    let mut lib = SpriteLibrary::new(&ctx);
    let (disc, err) = lib.resolve(&ctx, &Sprite::SoftDisc, None);
    assert!(err.is_none());

    let (tex, err) = lib.resolve(&ctx, &Sprite::Image("nope.png".into()), Some(dir.path()));
    let err = err.expect("missing file is an error");
    assert_eq!(tex.id, disc.id, "falls back to the soft disc");
    let msg = err.to_string();
    assert!(
        msg.contains("nope.png") && msg.contains("cannot read"),
        "{msg}"
    );
    assert!(msg.contains("soft disc"), "{msg}");

    std::fs::write(
        dir.path().join("broken.png"),
        b"\x89PNG\r\n\x1a\nnot really",
    )
    .expect("write");
    let (tex, err) = lib.resolve(&ctx, &Sprite::Image("broken.png".into()), Some(dir.path()));
    let msg = err.expect("broken file is an error").to_string();
    assert_eq!(tex.id, disc.id);
    assert!(
        msg.contains("broken.png") && msg.contains("not a readable PNG"),
        "{msg}"
    );

    // A good PNG, then a change on disk: invalidate → the new content is uploaded.
    let path = dir.path().join("dot.png");
    write_png(&path, 16, 16, |_, _| [255, 255, 255, 64]);
    let (first, err) = lib.resolve(&ctx, &Sprite::Image("dot.png".into()), Some(dir.path()));
    assert!(err.is_none());
    assert!(
        (first.integral - 4.0 * 64.0 / 255.0).abs() < 1e-3,
        "{}",
        first.integral
    );
    assert_eq!(first.size, (16, 16));
    write_png(&path, 32, 8, |_, _| [255, 255, 255, 255]);
    let (same, _) = lib.resolve(&ctx, &Sprite::Image("dot.png".into()), Some(dir.path()));
    assert_eq!(same.id, first.id, "cached until invalidated");
    assert!(lib.invalidate(std::slice::from_ref(&path)));
    let (second, err) = lib.resolve(&ctx, &Sprite::Image("dot.png".into()), Some(dir.path()));
    assert!(err.is_none());
    assert_ne!(second.id, first.id);
    assert_eq!(second.size, (32, 8));
    assert!((second.integral - 4.0).abs() < 1e-3);
    assert_eq!(lib.watched_dirs(), vec![dir.path().to_path_buf()]);

    // A whole frame with a missing sprite: drawn with the fallback, error reported.
    let mut run = sprite_run(&ctx, "missing/fire.png", dir.path());
    let img = run.render((160, 120)).expect("render");
    assert!(img.pixels().any(|p| p[0] > 40), "fallback sprite drawn");
    let errors = run.player.sprite_errors();
    assert_eq!(errors.len(), 1);
    assert!(errors[0].1.to_string().contains("fire.png"));
}

/// The plain emitter on billboards with the PNG sprite `sprite` of the asset folder `dir`,
/// played for half a second.
fn sprite_run(ctx: &GpuContext, sprite: &str, dir: &Path) -> Headless {
    let mut e = bare_effect(plain_emitter());
    e.emitters[0].look.sprite = Sprite::Image(sprite.into());
    e.emitters[0].look.draw_path = DrawPath::Billboard;
    let mut run = Headless::new(ctx, e, ShaderLibrary::embedded()).expect("headless");
    run.player.set_asset_dir(Some(dir.to_path_buf()));
    for _ in 0..30 {
        run.advance(1.0 / 60.0);
    }
    run
}

/// A player's PNG sprites through its own calls, as the editor drives them: looked up in
/// the asset folder it is given, that folder reported to watch, and a changed file
/// redrawn only once the player is told of it (an unrelated file changes nothing).
#[test]
fn a_players_sprite_folder_is_watched_and_a_changed_sprite_is_redrawn() {
    let ctx = gpu();
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("dot.png");
    write_png(&path, 16, 16, |_, _| [255, 255, 255, 255]);
    let mut run = sprite_run(&ctx, "dot.png", dir.path());
    let first = run.render((160, 120)).expect("render");
    assert!(
        run.player.sprite_errors().is_empty(),
        "{:?}",
        run.player.sprite_errors()
    );
    assert!(first.pixels().any(|p| p[0] > 40), "the sprite is drawn");
    assert_eq!(run.player.sprite_folders(), vec![dir.path().to_path_buf()]);

    // A dot in the middle instead of the square: drawn as before until the player is told.
    write_png(&path, 16, 16, |x, y| {
        let inside = (6..10).contains(&x) && (6..10).contains(&y);
        [255, 255, 255, if inside { 255 } else { 0 }]
    });
    let unrelated = dir.path().join("other.png");
    assert!(!run.player.reload_sprites(std::slice::from_ref(&unrelated)));
    assert!(run.render((160, 120)).expect("render") == first, "cached");
    assert!(run.player.reload_sprites(std::slice::from_ref(&path)));
    let second = run.render((160, 120)).expect("render");
    let changed = (first.pixels().zip(second.pixels()))
        .filter(|(a, b)| a != b)
        .count();
    assert!(
        changed > 20,
        "redrawn with the new file: {changed} pixels changed"
    );
}

/// One emitter of particles at rest at `pos` (or moving with `vel`), drawn as billboards.
fn single(pos: Vec3, vel: Vec3, look: Look) -> Effect {
    let mut em = plain_emitter();
    em.capacity = 64;
    em.spawn_rate_per_sec = ignis::effect::Param::Constant(0.0);
    em.bursts = vec![ignis::effect::Burst {
        time_secs: 0.0,
        count: 1,
    }];
    em.lifetime_secs = Range::new(10.0, 10.0);
    em.transform.position_m = pos.into();
    let speed = vel.length();
    em.speed_m_per_s = Range::new(speed, speed);
    if speed > 0.0 {
        em.direction = vel.normalize().into();
    }
    em.look = Look {
        draw_path: DrawPath::Billboard,
        color_over_life: vec![ColorStop {
            t: 0.0,
            rgba: [1.0, 1.0, 1.0, 1.0],
        }],
        ..look
    };
    let mut e = bare_effect(em);
    e.camera.target_m = [0.0, 0.0, 0.0];
    e.camera.distance_m = 4.0;
    e.camera.pitch_deg = 0.0;
    e.camera.yaw_deg = 0.0;
    e
}

fn render_after(ctx: &GpuContext, effect: Effect, frames: u32) -> image::RgbaImage {
    let mut run = Headless::new(ctx, effect, ShaderLibrary::embedded()).expect("headless");
    for _ in 0..frames {
        run.advance(1.0 / 60.0);
    }
    run.render((200, 200)).expect("render")
}

/// (width, height) of the lit pixels' bounding box.
fn lit_extent(img: &image::RgbaImage, threshold: u8) -> (u32, u32) {
    let (mut x0, mut y0, mut x1, mut y1) = (u32::MAX, u32::MAX, 0, 0);
    for (x, y, p) in img.enumerate_pixels() {
        if p[0] > threshold {
            x0 = x0.min(x);
            y0 = y0.min(y);
            x1 = x1.max(x);
            y1 = y1.max(y);
        }
    }
    if x1 < x0 {
        return (0, 0);
    }
    (x1 - x0 + 1, y1 - y0 + 1)
}

#[test]
fn streaks_stretch_along_the_screen_velocity() {
    let ctx = gpu();
    let look = Look {
        size_m: Param::Constant(0.05),
        ..Look::default()
    };
    let still = render_after(&ctx, single(Vec3::ZERO, Vec3::ZERO, look.clone()), 2);
    let (w0, h0) = lit_extent(&still, 20);
    assert!(
        w0 > 0 && (w0 as i32 - h0 as i32).abs() <= 1,
        "round: {w0}×{h0}"
    );
    // Moving right at 2 m/s with a 0.2 s tail: 0.4 m long, 0.05 m wide.
    let streak = Look {
        streak: Some(Streak {
            length_secs: 0.2,
            max_length_m: 10.0,
        }),
        ..look
    };
    let moving = render_after(
        &ctx,
        single(Vec3::new(-0.5, 0.0, 0.0), Vec3::X * 2.0, streak.clone()),
        2,
    );
    let (w, h) = lit_extent(&moving, 20);
    assert!(w as f32 > 5.0 * h as f32, "a horizontal streak: {w}×{h}");
    // Moving up: a vertical streak.
    let up = render_after(
        &ctx,
        single(Vec3::new(0.0, -0.5, 0.0), Vec3::Y * 2.0, streak),
        2,
    );
    let (w, h) = lit_extent(&up, 20);
    assert!(h as f32 > 5.0 * w as f32, "a vertical streak: {w}×{h}");
}

#[test]
fn soft_ground_fades_sprites_towards_the_ground_plane() {
    let ctx = gpu();
    let look = Look {
        size_m: Param::Constant(0.8),
        ..Look::default()
    };
    let mut hard = single(Vec3::ZERO, Vec3::ZERO, look.clone());
    hard.emitters[0].collisions.ground = Some(GroundPlane {
        height_m: -0.2,
        kill_on_contact: false,
    });
    let mut soft = hard.clone();
    soft.emitters[0].look.soft_ground_m = 0.3;
    let a = render_after(&ctx, hard, 2);
    let b = render_after(&ctx, soft, 2);
    // Rows near the ground line (y = −0.2 m is below the centre) darken; the top half
    // of the sprite (more than 0.3 m above the ground) is unchanged.
    let row = |img: &image::RgbaImage, y: u32| -> u32 {
        (0..200).map(|x| u32::from(img.get_pixel(x, y)[0])).sum()
    };
    let centre = 100;
    let top = 85; // ≈ 0.15 m above the centre: 0.35 m above the ground.
    assert_eq!(row(&a, top), row(&b, top), "no fade far above the ground");
    let near = 112; // ≈ 0.12 m below the centre: 0.08 m above the ground.
    assert!(
        row(&b, near) * 2 < row(&a, near),
        "faded near the ground: {} vs {}",
        row(&b, near),
        row(&a, near)
    );
    assert!(row(&b, centre) < row(&a, centre));
}

#[test]
fn bloom_spreads_light_and_exposure_scales_it() {
    let ctx = gpu();
    let look = Look {
        size_m: Param::Constant(0.1),
        intensity: 8.0,
        ..Look::default()
    };
    let plain = single(Vec3::ZERO, Vec3::ZERO, look);
    let mut bloom = plain.clone();
    bloom.post.bloom = Some(ignis::effect::Bloom {
        threshold: 1.0,
        intensity: 1.0,
        levels: 6,
    });
    let a = render_after(&ctx, plain.clone(), 2);
    let b = render_after(&ctx, bloom, 2);
    // 14 px from the sprite (radius ≈ 6 px): dark without bloom, lit with it.
    let far = |img: &image::RgbaImage| img.get_pixel(114, 100)[0];
    println!("14 px away: {} without bloom, {} with", far(&a), far(&b));
    assert!(
        far(&a) < 3,
        "no light 14 px away without bloom: {}",
        far(&a)
    );
    assert!(
        far(&b) > far(&a) + 8,
        "bloom spreads light: {} vs {}",
        far(&b),
        far(&a)
    );
    let mut dim = plain;
    dim.post.exposure = 0.05;
    let c = render_after(&ctx, dim, 2);
    let centre = |img: &image::RgbaImage| img.get_pixel(100, 100)[0];
    assert!(
        centre(&c) + 40 < centre(&a),
        "exposure dims: {} vs {}",
        centre(&c),
        centre(&a)
    );
}

#[test]
fn random_size_rotation_and_spin_vary_per_particle_deterministically() {
    let ctx = gpu();
    // Many particles on a line, each with a random size: the lit widths differ.
    let mut em = plain_emitter();
    em.shape = ignis::effect::Shape::Line {
        a_m: [-1.0, 0.0, 0.0],
        b_m: [1.0, 0.0, 0.0],
    };
    em.spawn_rate_per_sec = ignis::effect::Param::Constant(0.0);
    em.bursts = vec![ignis::effect::Burst {
        time_secs: 0.0,
        count: 12,
    }];
    em.lifetime_secs = Range::new(5.0, 9.0);
    em.look = Look {
        draw_path: DrawPath::Billboard,
        size_m: Param::Range {
            min: 0.12 * 0.4,
            max: 0.12 * 1.6,
        },
        rotation_random_deg: 360.0,
        spin_deg_per_s: Param::Range {
            min: -90.0,
            max: 90.0,
        },
        blend: BlendMode::Additive,
        sprite: Sprite::FlameWisp,
        ..Look::default()
    };
    let mut e = bare_effect(em);
    e.camera.target_m = [0.0, 0.0, 0.0];
    e.camera.distance_m = 3.0;
    e.camera.pitch_deg = 0.0;
    let a = render_after(&ctx, e.clone(), 10);
    let b = render_after(&ctx, e.clone(), 10);
    assert_eq!(a.as_raw(), b.as_raw(), "same preset + seed ⇒ same frame");
    let mut uniform = e.clone();
    uniform.emitters[0].look.size_m = Param::Constant(0.12);
    uniform.emitters[0].look.rotation_random_deg = 0.0;
    uniform.emitters[0].look.spin_deg_per_s = Param::Constant(0.0);
    let c = render_after(&ctx, uniform, 10);
    assert_ne!(a.as_raw(), c.as_raw(), "randomness changes the frame");
    let mut reseeded = e;
    reseeded.seed = 99;
    let d = render_after(&ctx, reseeded, 10);
    assert_ne!(a.as_raw(), d.as_raw(), "another seed, another frame");
}

/// Mean absolute difference per channel (0–255) of two equally sized images.
fn mean_abs_diff(a: &image::RgbaImage, b: &image::RgbaImage) -> f64 {
    image_diff(a, b).0
}

/// Fixed-seed frames of presets against committed references on the software adapter.
/// Tolerance: mean absolute difference ≤ 1.0 of 255 per channel (lavapipe builds differ
/// in the last bits of their maths; a real look change moves the mean by far more — the
/// test checks that the references differ from each other by ≥ 5).
#[test]
fn reference_images() {
    const TOLERANCE: f64 = 1.0;
    let ctx = gpu();
    let bless = std::env::var_os("IGNIS_BLESS").is_some();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut rendered = Vec::new();
    for name in ["campfire", "torch", "spark_fountain", "candle", "bonfire"] {
        let preset = root.join("presets").join(format!("{name}.ron"));
        let effect = ignis::preset::load(&preset).expect("preset");
        let mut run = Headless::new(&ctx, effect, ShaderLibrary::embedded()).expect("headless");
        run.player
            .set_asset_dir(preset.parent().map(Path::to_path_buf));
        for _ in 0..90 {
            run.advance(1.0 / 60.0);
        }
        let img = run.render((240, 180)).expect("render");
        assert!(
            run.player.sprite_errors().is_empty(),
            "{name}: sprites load"
        );
        let reference = root.join("tests/reference").join(format!("{name}.png"));
        if bless {
            std::fs::create_dir_all(reference.parent().expect("dir")).expect("mkdir");
            img.save(&reference).expect("write reference");
        }
        let want = image::open(&reference)
            .unwrap_or_else(|e| {
                panic!(
                    "{}: {e} (regenerate with IGNIS_BLESS=1 cargo test --release --test looks \
                        reference_images)",
                    reference.display()
                )
            })
            .to_rgba8();
        let diff = mean_abs_diff(&img, &want);
        println!("{name}: mean |difference| {diff:.3} (tolerance {TOLERANCE})");
        if diff > TOLERANCE {
            let out = std::env::temp_dir().join(format!("ignis-{name}-actual.png"));
            let _ = img.save(&out);
            panic!(
                "{name} differs from {} by {diff:.3} > {TOLERANCE} (actual frame: {}); if the \
                    change is deliberate, regenerate with IGNIS_BLESS=1 cargo test --release \
                    --test looks reference_images",
                reference.display(),
                out.display()
            );
        }
        rendered.push(img);
    }
    // The metric catches a small look change: the campfire without its bloom.
    let preset = root.join("presets/campfire.ron");
    let mut effect = ignis::preset::load(&preset).expect("preset");
    effect.post.bloom = None;
    let mut run = Headless::new(&ctx, effect, ShaderLibrary::embedded()).expect("headless");
    for _ in 0..90 {
        run.advance(1.0 / 60.0);
    }
    let no_bloom = run.render((240, 180)).expect("render");
    let d = mean_abs_diff(&no_bloom, &rendered[0]);
    println!("campfire without bloom: mean |difference| {d:.3}");
    assert!(
        d > 2.0 * TOLERANCE,
        "turning bloom off moves the mean by only {d}"
    );
    // The metric discriminates: different presets are far apart.
    for i in 0..rendered.len() {
        for j in i + 1..rendered.len() {
            let d = mean_abs_diff(&rendered[i], &rendered[j]);
            println!("presets {i} and {j}: mean |difference| {d:.3}");
            assert!(
                d >= 5.0 * TOLERANCE,
                "presets {i} and {j} differ by only {d}"
            );
        }
    }
}

/// The editor's PNG hot reload, end to end below the window: the file watcher sees the
/// sprite's folder change, the library drops the file, the next resolve uploads the new
/// pixels.
#[test]
fn a_png_changed_on_disk_is_seen_by_the_watcher_and_reloaded() {
    let ctx = gpu();
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("glow.png");
    write_png(&path, 8, 8, |_, _| [255, 255, 255, 128]);
    let mut lib = SpriteLibrary::new(&ctx);
    let sprite = Sprite::Image("glow.png".into());
    let (first, err) = lib.resolve(&ctx, &sprite, Some(dir.path()));
    assert!(err.is_none());
    let dirs = lib.watched_dirs();
    let paths: Vec<&Path> = dirs.iter().map(|d| d.as_path()).collect();
    let watcher = ignis::testing::hot_reload::FileWatcher::new(&paths).expect("watch");
    // A save: write a new image next to it, then rename over (as editors do).
    let tmp = dir.path().join("glow.tmp.png");
    write_png(&tmp, 8, 8, |_, _| [255, 255, 255, 255]);
    std::fs::rename(&tmp, &path).expect("rename");
    let mut changed = Vec::new();
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(10);
    while !changed
        .iter()
        .any(|p: &std::path::PathBuf| p.file_name() == path.file_name())
        && std::time::Instant::now() < deadline
    {
        changed.extend(watcher.wait(std::time::Duration::from_millis(200)));
    }
    assert!(lib.invalidate(&changed), "the watcher reported {changed:?}");
    let (second, err) = lib.resolve(&ctx, &sprite, Some(dir.path()));
    assert!(err.is_none());
    assert_ne!(second.id, first.id);
    assert!((first.integral - 4.0 * 128.0 / 255.0).abs() < 1e-3);
    assert!((second.integral - 4.0).abs() < 1e-3, "{}", second.integral);

    // A PNG that is missing at first and created later is picked up too.
    let later = Sprite::Image("later.png".into());
    let (_, err) = lib.resolve(&ctx, &later, Some(dir.path()));
    assert!(err.is_some());
    write_png(&dir.path().join("later.png"), 4, 4, |_, _| {
        [255, 255, 255, 255]
    });
    let mut changed: Vec<std::path::PathBuf> = Vec::new();
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(10);
    while !changed
        .iter()
        .any(|p| p.file_name() == Some(std::ffi::OsStr::new("later.png")))
        && std::time::Instant::now() < deadline
    {
        changed.extend(watcher.wait(std::time::Duration::from_millis(200)));
    }
    assert!(lib.invalidate(&changed), "the watcher reported {changed:?}");
    let (_, err) = lib.resolve(&ctx, &later, Some(dir.path()));
    assert!(err.is_none(), "{err:?}");
}

/// Smoke drawn at half resolution (`post.alpha_downscale: 2`) looks like smoke drawn at
/// full resolution: the frame is close, and the smoke is there.
#[test]
fn alpha_layers_at_half_resolution_match_full_resolution() {
    let ctx = gpu();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut full = ignis::preset::load(&root.join("presets/campfire.ron")).expect("preset");
    full.post.bloom = None;
    full.post.alpha_downscale = 1;
    let mut half = full.clone();
    half.post.alpha_downscale = 2;
    let mut no_smoke = full.clone();
    no_smoke
        .emitters
        .retain(|e| e.look.blend != BlendMode::Alpha);
    no_smoke.drop_dangling_events();
    let frame = |effect: Effect| {
        let mut run = Headless::new(&ctx, effect, ShaderLibrary::embedded()).expect("headless");
        for _ in 0..150 {
            run.advance(1.0 / 60.0);
        }
        run.render((240, 180)).expect("render")
    };
    let (a, b, c) = (frame(full), frame(half), frame(no_smoke));
    let d_half = mean_abs_diff(&a, &b);
    let d_smoke = mean_abs_diff(&a, &c);
    println!("half-resolution smoke: {d_half:.3}; no smoke at all: {d_smoke:.3}");
    assert!(d_smoke > 1.0, "the smoke is visible ({d_smoke})");
    assert!(
        d_half < 0.25 * d_smoke,
        "half resolution: {d_half} vs {d_smoke}"
    );
}

/// Billboards are cut to the part of their sprite that holds something: the flame sheet's
/// tongues fill about half of each frame's width, the soft disc all of it, the lit puff's
/// sphere under half of its frame — and the trimmed frame (the campfire: lit smoke and
/// flames) is the untrimmed one (the flame quads lose ~40 % of their fill, the smoke's
/// ~half).
#[test]
fn trimmed_billboards_draw_the_untrimmed_frame() {
    let ctx = gpu();
    let mut sprites = SpriteLibrary::new(&ctx);
    let (sheet, _) = sprites.resolve(&ctx, &Sprite::FlameSheet, None);
    let t = ignis::testing::render::sprites::TRIM_THRESHOLD;
    let [u0, v0, u1, v1] = sheet.trim(4, 4, t).rect;
    assert!(
        u1 - u0 < 0.6 && u0 > 0.2 && u1 < 0.8,
        "flame sheet u {u0}..{u1}"
    );
    assert!(
        v1 - v0 > 0.95,
        "flame tongues span the height: v {v0}..{v1}"
    );
    let (disc, _) = sprites.resolve(&ctx, &Sprite::SoftDisc, None);
    let [d0, _, d1, _] = disc.trim(1, 1, t).rect;
    assert!(d1 - d0 > 0.97, "soft disc u {d0}..{d1}");
    // The threshold (divided by the emitter's intensity) decides what is kept: a brighter
    // emitter keeps fainter texels, never a narrower rectangle.
    let [w0, _, w1, _] = sheet.trim(4, 4, t / 1000.0).rect;
    let [n0, _, n1, _] = sheet.trim(4, 4, 0.3).rect;
    assert!(
        w1 - w0 >= u1 - u0,
        "faint texels kept at high intensity: {w0}..{w1}"
    );
    assert!(
        n1 - n0 < u1 - u0,
        "only bright texels kept at 0.3: {n0}..{n1}"
    );
    // Lit smoke's six-way maps (RTBA | LBFE side by side) are cut per half: the
    // built-in puff's sphere fills under half of its frame.
    let (puff, _) = sprites.resolve_lit(&ctx, &ignis::effect::SixWayMaps::Puff, None);
    let [p0, q0, p1, q1] = puff.trim(1, 2, t / 256.0).rect;
    assert!(
        (p1 - p0) * (q1 - q0) < 0.6 && p0 > 0.1 && p1 < 0.9,
        "lit puff u {p0}..{p1}, v {q0}..{q1}"
    );

    let mut effect = Effect::default_campfire();
    effect.post.bloom = None;
    // The smoke pale and dense, so that a cut into its puffs shows against the night.
    for stop in &mut effect.emitters[0].look.color_over_life {
        stop.rgba = [0.8, 0.8, 0.8, stop.rgba[3] * 3.0];
    }
    let mut run = Headless::new(&ctx, effect, ShaderLibrary::embedded()).expect("headless");
    for _ in 0..120 {
        run.advance(1.0 / 60.0);
    }
    let trimmed = run.render((320, 240)).expect("render");
    run.player.draw_resources().0.trim_sprites = false;
    let whole = run.render((320, 240)).expect("render");
    let lit = trimmed.pixels().filter(|p| p[0] > 60).count();
    let (mean, max) = image_diff(&trimmed, &whole);
    assert!(lit > 2000, "{lit} lit pixels");
    assert!(
        mean < 0.005 && max <= 1,
        "trimmed vs whole: mean {mean}, max {max}"
    );
}

/// A sprite turns by its random rotation (within ± half the range) plus its spin over its
/// age. The flame wisp's bright base, below its middle unturned, stays in the lower half
/// with a 180° range, whatever the seed; after spinning 45° a second for 2 s (of a 10 s
/// life) it is a quarter turn round, to the side.
#[test]
fn sprites_turn_by_their_random_rotation_and_their_spin() {
    let ctx = gpu();
    let wisp = Look {
        size_m: Param::Constant(0.8),
        sprite: Sprite::FlameWisp,
        intensity: 0.3,
        rotation_random_deg: 0.0,
        spin_deg_per_s: Param::Constant(0.0),
        ..Look::default()
    };
    // 200 × 200 frames, the particle at the middle (y down).
    let mut below = 0.0;
    for seed in 0..4 {
        let mut e = single(
            Vec3::ZERO,
            Vec3::ZERO,
            Look {
                rotation_random_deg: 180.0,
                ..wisp.clone()
            },
        );
        e.seed = seed;
        let (_, y) = light_centroid(&render_after(&ctx, e, 2));
        assert!(y > 99.9, "seed {seed}: the light's centre at y = {y}");
        below += y - 100.0;
    }
    assert!(below > 4.0, "the base {below} px below in all");
    let spun = Look {
        spin_deg_per_s: Param::Constant(45.0),
        ..wisp
    };
    let (x, y) = light_centroid(&render_after(
        &ctx,
        single(Vec3::ZERO, Vec3::ZERO, spun),
        120,
    ));
    assert!(
        (x - 100.0).abs() > 2.0 && (y - 100.0).abs() < 0.3 * (x - 100.0).abs(),
        "after a quarter turn the light's centre is at ({x}, {y})"
    );
}

/// A streak is no longer than its cap (`max_length_m`): moving right at 2 m/s with a 0.2 s
/// tail capped at 0.1 m, it is under half as long as uncapped, still longer than it is wide.
/// And it lays its sprite along the motion as ribbons do (its top on the motion's left):
/// moving right, the flame wisp's bright base is below the middle.
#[test]
fn a_streak_is_capped_at_its_longest_and_lays_its_sprite_as_ribbons_do() {
    let ctx = gpu();
    let streak = |max_length_m: f32, sprite: Sprite| Look {
        size_m: Param::Constant(0.05),
        streak: Some(Streak {
            length_secs: 0.2,
            max_length_m,
        }),
        sprite,
        intensity: 0.3,
        ..Look::default()
    };
    let moving = |look: Look| single(Vec3::new(-0.2, 0.0, 0.0), Vec3::X * 2.0, look);
    let (long, _) = lit_extent(
        &render_after(&ctx, moving(streak(10.0, Sprite::SoftDisc)), 2),
        20,
    );
    let (capped, h) = lit_extent(
        &render_after(&ctx, moving(streak(0.1, Sprite::SoftDisc)), 2),
        20,
    );
    assert!(
        capped * 2 < long && capped as f32 > 1.5 * h as f32,
        "0.4 m long: {long} px; capped at 0.1 m: {capped} × {h} px"
    );
    let wide = Look {
        size_m: Param::Constant(0.3),
        ..streak(10.0, Sprite::FlameWisp)
    };
    let (_, y) = light_centroid(&render_after(&ctx, moving(wide), 2));
    assert!(
        y > 100.5,
        "a streak's light is centred at y = {y} px (down)"
    );
}

/// A streak `size_m` wide of `intensity` whose tail is 0.2 s of its motion, uncapped.
fn tailed_streak(size_m: f32, intensity: f32) -> Look {
    Look {
        size_m: Param::Constant(size_m),
        streak: Some(Streak {
            length_secs: 0.2,
            max_length_m: 10.0,
        }),
        intensity,
        ..Look::default()
    }
}

/// A streak's soft-ground fade follows its ends' heights: rising through the ground plane
/// (y = 0, the frame's middle row) with a 0.05 m soft edge, nothing of it shows below the
/// plane, and its part above is (but for the last 0.05 m) as bright as without the fade.
#[test]
fn a_streak_through_the_ground_plane_fades_below_it_and_not_above() {
    let ctx = gpu();
    let streak = tailed_streak(0.15, 0.5);
    // 2 m/s up from 0.15 m with a 0.2 s tail: drawn two frames later its head is about
    // 0.2 m above the plane and its tail about 0.2 m below.
    let rising = |look: Look| single(Vec3::new(0.0, 0.15, 0.0), Vec3::Y * 2.0, look);
    let hard = render_after(&ctx, rising(streak.clone()), 2);
    let soft = render_after(
        &ctx,
        rising(Look {
            soft_ground_m: 0.05,
            ..streak
        }),
        2,
    );
    // Red summed over rows y0..y1 (the plane y = 0 is at row 100).
    let rows = |img: &image::RgbaImage, y0: u32, y1: u32| -> u64 {
        (y0..y1)
            .flat_map(|y| (0..img.width()).map(move |x| (x, y)))
            .map(|(x, y)| u64::from(img.get_pixel(x, y)[0]))
            .sum()
    };
    let (hard_above, hard_below) = (rows(&hard, 0, 100), rows(&hard, 100, 200));
    let (soft_above, soft_below) = (rows(&soft, 0, 100), rows(&soft, 100, 200));
    assert!(
        hard_above > 500 && hard_below > 500,
        "the streak crosses the plane: {hard_above} above, {hard_below} below"
    );
    assert!(
        soft_below * 50 <= hard_below,
        "below the plane it is gone: {soft_below} of {hard_below}"
    );
    assert!(
        soft_above * 2 >= hard_above,
        "above the plane it stays: {soft_above} of {hard_above}"
    );
}

/// A streak whose tail is behind the camera is drawn at its head alone (the strip's tail
/// put on its head): flying away from the eye at 10 m/s from 0.6 m in front of it with a
/// 0.2 s tail (2 m, over a metre behind the eye), it is a sprite-sized square, not a wedge
/// to the frame's edge.
#[test]
fn a_streak_with_its_tail_behind_the_camera_is_drawn_at_its_head() {
    let ctx = gpu();
    let look = tailed_streak(0.05, 0.3);
    // `single`'s eye is at z = 4, looking down −z.
    let img = render_after(
        &ctx,
        single(Vec3::new(0.1, 0.0, 3.4), Vec3::NEG_Z * 10.0, look),
        2,
    );
    let (w, h) = lit_extent(&img, 20);
    // 0.05 m about 0.8 m away: about 15 px.
    assert!(
        w > 3 && w <= 24 && h <= 24,
        "a square at the head: {w}×{h} px"
    );
}
