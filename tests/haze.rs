//! Heat haze on a real adapter: the refraction shifts a host image by a known constant
//! offset exactly; an effect without haze leaves the host's image untouched bit for bit and
//! compiles the haze out of its pipelines; a haze layer bends the image only around its
//! particles and is never drawn in colour.

mod common;

use common::*;
use ignis::effect::{Burst, ColorStop, Effect, Emitter, HeatHaze, Range, Shape};
use ignis::testing::gpu::{GpuContext, TextureReadback};
use ignis::testing::render::haze::HazePass;
use ignis::testing::render::variant::{LookVariant, StateVariant};
use ignis::testing::shaders::ShaderLibrary;
use ignis::testing::sim::gpu_sim::map_read;
use ignis::{Camera, Player, PlayerSettings};

const W: u32 = 96;
const H: u32 = 64;
const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// A pattern no shift maps onto itself: every texel differs from its neighbours.
fn pattern(x: u32, y: u32) -> [u8; 4] {
    [
        (x * 37 + y * 11) as u8,
        (x * 5 + y * 53) as u8,
        ((x ^ y) * 29) as u8,
        255,
    ]
}

fn pattern_bytes() -> Vec<u8> {
    (0..H)
        .flat_map(|y| (0..W).flat_map(move |x| pattern(x, y)))
        .collect()
}

/// A target the size of the test's frame: sampled, drawn into, copied and read back.
fn target(ctx: &GpuContext, bytes: &[u8]) -> wgpu::Texture {
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
    texture_of(ctx, FORMAT, usage, bytes)
}

/// A texture of the test's frame size in `format` holding `bytes` (tight rows), sampled,
/// copied both ways, and with `usage` too.
fn texture_of(
    ctx: &GpuContext,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
    bytes: &[u8],
) -> wgpu::Texture {
    let texture = ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("haze test target"),
        size: wgpu::Extent3d {
            width: W,
            height: H,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: usage
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC
            | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let texel = format.block_copy_size(None).unwrap_or(4);
    ctx.queue.write_texture(
        texture.as_image_copy(),
        bytes,
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(W * texel),
            rows_per_image: None,
        },
        texture.size(),
    );
    texture
}

/// `texture`'s texels (tight rows) after `enc` runs.
fn read(ctx: &GpuContext, mut enc: wgpu::CommandEncoder, texture: &wgpu::Texture) -> Vec<u8> {
    let readback = TextureReadback::record(&ctx.device, &mut enc, texture, "haze test");
    ctx.queue.submit([enc.finish()]);
    let bytes = map_read(ctx, &readback.buffer).expect("read back");
    readback.rows(&bytes).expect("rows").concat()
}

/// A distortion of a constant (3, −2) pixels by the full-screen draw (an 8-bit target):
/// every pixel whose source is inside the image shows the pattern's texel there, to the
/// 8-bit level.
#[test]
fn the_refraction_shifts_the_image_by_the_distortion() {
    let got = refracted(FORMAT, wgpu::TextureUsages::RENDER_ATTACHMENT, (3, -2));
    assert_shifted((3, -2), |at, c| f32::from(got[at * 4 + c]) / 255.0);
}

/// The compute refraction (an `Rgba16Float` storage target, as the editor's HDR image):
/// a shift of (−4, 3) pixels, to 1/255.
#[test]
fn the_compute_refraction_shifts_an_hdr_image_by_the_distortion() {
    let format = wgpu::TextureFormat::Rgba16Float;
    let got = refracted(format, wgpu::TextureUsages::STORAGE_BINDING, (-4, 3));
    assert_shifted((-4, 3), |at, c| {
        half::f16::from_le_bytes([got[at * 8 + 2 * c], got[at * 8 + 2 * c + 1]]).to_f32()
    });
}

/// The pattern in a `format` texture (with `usage`) refracted by a constant distortion of
/// `shift` pixels into another: its bytes.
fn refracted(
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
    (dx, dy): (i32, i32),
) -> Vec<u8> {
    let ctx = gpu();
    let mut haze = HazePass::new(&ctx, &ShaderLibrary::embedded(), format).expect("haze pass");
    let bytes: Vec<u8> = match format {
        FORMAT => pattern_bytes(),
        _ => (pattern_bytes().iter())
            .flat_map(|&b| half::f16::from_f32(f32::from(b) / 255.0).to_le_bytes())
            .collect(),
    };
    let scene = texture_of(&ctx, format, usage, &bytes);
    let out = texture_of(&ctx, format, usage, &vec![0; bytes.len()]);
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    let offset = wgpu::Color {
        r: f64::from(dx) / f64::from(W),
        g: f64::from(dy) / f64::from(H),
        b: 0.0,
        a: 0.0,
    };
    drop(haze.begin(&ctx, &mut enc, ((W, H), 2), offset));
    let view = |t: &wgpu::Texture| t.create_view(&Default::default());
    haze.refract(&ctx, &mut enc, &view(&scene), &view(&out));
    read(&ctx, enc, &out)
}

/// Every pixel whose source, `shift` pixels away, is inside the frame holds the pattern's
/// texel there to 1/255 (`value(pixel, channel)`: what the image holds, 0..1).
fn assert_shifted((dx, dy): (i32, i32), value: impl Fn(usize, usize) -> f32) {
    let mut checked = 0;
    for y in 0..H as i32 {
        for x in 0..W as i32 {
            let (sx, sy) = (x + dx, y + dy);
            if sx < 0 || sy < 0 || sx >= W as i32 || sy >= H as i32 {
                continue;
            }
            let want = pattern(sx as u32, sy as u32);
            let at = (y as u32 * W + x as u32) as usize;
            for (c, w) in want.iter().enumerate() {
                let v = value(at, c);
                let d = (v - f32::from(*w) / 255.0).abs();
                assert!(
                    d <= 1.0 / 255.0 + 1e-6,
                    "({x}, {y}) channel {c}: {v} for {w}"
                );
            }
            checked += 1;
        }
    }
    let expected =
        (W as usize - dx.unsigned_abs() as usize) * (H as usize - dy.unsigned_abs() as usize);
    assert_eq!(checked, expected);
}

/// A torch player (no haze): nothing to apply, nothing recorded, the host's image kept
/// bit for bit; its pipelines compile the haze out (`HAZE` = 0), a haze look's in.
#[test]
fn without_haze_the_host_image_is_untouched_and_haze_is_compiled_out() {
    let ctx = gpu();
    let torch = ignis::preset::load("presets/torch.ron".as_ref()).expect("torch");
    // The flames about a metre up, brought down into the view.
    let frame = frame_with(&ctx, &torch, glam::Vec3::new(0.0, -0.9, 0.0));
    assert!(!frame.applied, "no haze to apply");
    assert!(frame.drawn != pattern_bytes(), "the torch was drawn");
    assert!(frame.hazed == frame.drawn, "the host image changed");
    let haze_of = |e: &Emitter| {
        let v = LookVariant::of(&e.look, StateVariant::default());
        v.constants()
            .iter()
            .find(|(n, _)| *n == "HAZE")
            .map(|c| c.1)
    };
    assert!(torch.emitters.iter().all(|e| haze_of(e) == Some(0.0)));
    assert_eq!(haze_of(&haze_emitter()), Some(1.0));
}

/// A haze layer (a burst of large particles in the middle of the frame): the refracted
/// image differs from the host's around them and is the host's bit for bit far from them;
/// the layer adds no colour of its own.
#[test]
fn a_haze_layer_bends_the_image_only_around_its_particles() {
    let ctx = gpu();
    let mut effect = bare_effect(haze_emitter());
    effect.post.bloom = None;
    let frame = frame_with(&ctx, &effect, glam::Vec3::ZERO);
    assert!(frame.applied);
    assert!(frame.drawn == pattern_bytes(), "the haze layer drew colour");
    let changed = |x: u32, y: u32| {
        let at = ((y * W + x) * 4) as usize;
        frame.hazed[at..at + 4] != frame.drawn[at..at + 4]
    };
    let near: usize = (W / 2 - 8..W / 2 + 8)
        .flat_map(|x| (H / 2 - 8..H / 2 + 8).map(move |y| (x, y)))
        .filter(|&(x, y)| changed(x, y))
        .count();
    assert!(near > 64, "only {near} of 256 pixels bent near the haze");
    for (x, y) in [(2, 2), (W - 3, 2), (2, H - 3), (W - 3, H - 3)] {
        assert!(!changed(x, y), "({x}, {y}) bent, far from the haze");
    }
}

/// The haze pass, built at its first use, reloads from a host's shader folder: a broken
/// `haze_apply.wgsl` is refused and named (the last good pass keeps refracting), a good
/// one builds.
#[test]
fn a_broken_haze_shader_reload_is_named_and_a_good_one_builds() {
    let ctx = gpu();
    let mut frame = frame_with(&ctx, &bare_effect(haze_emitter()), glam::Vec3::ZERO);
    assert!(frame.applied);
    let broken = shader_folder(&[("haze_apply.wgsl", "fn broken(")]);
    let Err(err) = frame.player.reload_shader(broken.path(), "haze_apply.wgsl") else {
        panic!("a broken haze_apply.wgsl is refused");
    };
    assert!(err.to_string().contains("haze_apply.wgsl"), "{err}");
    let good = shader_folder(&[]);
    (frame.player.reload_shader(good.path(), "haze_apply.wgsl")).expect("the good shader builds");
}

/// An invisible emitter of 40 particles 0.6 m wide at the origin, haze on.
fn haze_emitter() -> Emitter {
    let mut e = Emitter {
        name: "haze".into(),
        capacity: 64,
        spawn_rate_per_sec: ignis::effect::Param::Constant(0.0),
        bursts: vec![Burst {
            time_secs: 0.0,
            count: 40,
        }],
        lifetime_secs: Range::new(5.0, 5.0),
        shape: Shape::Sphere {
            radius_m: 0.05,
            surface_only: false,
        },
        ..plain_emitter()
    };
    e.look.size_m = ignis::effect::Param::Constant(0.6);
    e.look.soft_ground_m = 0.0;
    e.look.color_over_life = vec![ColorStop {
        t: 0.0,
        rgba: [1.0, 1.0, 1.0, 1.0],
    }];
    e.look.heat_haze = Some(HeatHaze {
        strength: 0.2,
        ..HeatHaze::default()
    });
    e
}

/// What a host frame held: after the particles' pass, after the haze, and whether haze
/// was applied; the player that drew it.
struct Framed {
    drawn: Vec<u8>,
    hazed: Vec<u8>,
    applied: bool,
    player: Player,
}

/// `effect` played 10 frames at `at`, seen from 1.5 m in front of the origin, each frame
/// drawn over a host image holding the pattern and its haze applied.
fn frame_with(ctx: &GpuContext, effect: &Effect, at: glam::Vec3) -> Framed {
    let settings = PlayerSettings::new(FORMAT);
    let mut player = Player::new(&ctx.device, &ctx.queue, effect, settings).expect("player");
    player
        .add_instance(glam::Mat4::from_translation(at), 1)
        .expect("instance");
    let view = glam::camera::rh::view::look_at_mat4(
        glam::Vec3::new(0.0, 0.0, 1.5),
        glam::Vec3::ZERO,
        glam::Vec3::Y,
    );
    let proj = glam::camera::rh::proj::directx::perspective(0.9, W as f32 / H as f32, 0.05, 50.0);
    let camera = Camera::new(view, proj, (W, H));
    let host = target(ctx, &pattern_bytes());
    let copy = target(ctx, &pattern_bytes());
    let mut applied = false;
    for _ in 0..10 {
        let layout = wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(W * 4),
            rows_per_image: None,
        };
        let bytes = pattern_bytes();
        ctx.queue
            .write_texture(host.as_image_copy(), &bytes, layout, host.size());
        player.advance(1.0 / 60.0);
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        player.record(&mut enc, &camera, None).expect("record");
        let host_view = host.create_view(&Default::default());
        {
            let mut pass = ignis::HostTargets {
                color: &host_view,
                resolve_target: None,
                depth: None,
            }
            .begin_pass(&mut enc);
            player.draw(&mut pass);
        }
        enc.copy_texture_to_texture(host.as_image_copy(), copy.as_image_copy(), host.size());
        let copy_view = copy.create_view(&Default::default());
        let before = player.recorded_commands();
        applied = player
            .apply_haze(&mut enc, &copy_view, &host_view)
            .expect("haze");
        // The frame's commands include the haze's: its distortion draw and refraction.
        let haze = player.recorded_commands() - before;
        assert!(
            !applied || haze.draws + haze.dispatches >= 2,
            "the haze's commands are not counted: {haze:?}"
        );
        ctx.queue.submit([enc.finish()]);
    }
    let enc = || ctx.device.create_command_encoder(&Default::default());
    Framed {
        drawn: read(ctx, enc(), &copy),
        hazed: read(ctx, enc(), &host),
        applied,
        player,
    }
}

/// The composite (the editor's, the renders' and the exports' frame) shows the refracted
/// image: the campfire rendered headless differs from itself with its haze emitter off
/// around the fire, by the haze's bending of the flames' light; with the composite's haze
/// switched off it is the image without the haze emitter.
#[test]
fn the_composite_shows_the_refracted_image() {
    let ctx = gpu();
    // `shown`: the composite's heat haze on (the editor's toggle).
    let render_with = |effect: Effect, shown: bool| {
        let mut run =
            ignis::testing::headless::Headless::new(&ctx, effect, ShaderLibrary::embedded())
                .expect("headless");
        run.composite.heat_haze = shown;
        for _ in 0..30 {
            run.advance(1.0 / 60.0);
        }
        run.render((160, 120)).expect("render")
    };
    let render = |effect: Effect| render_with(effect, true);
    let hazed = Effect::default_campfire();
    let haze = hazed
        .emitters
        .iter()
        .position(|e| e.look.heat_haze.is_some())
        .expect("the campfire's haze");
    let mut plain = hazed.clone();
    plain.emitters[haze].enabled = false;
    let (a, b) = (render(hazed.clone()), render(plain));
    let (mean, max) = image_diff(&a, &b);
    assert!(
        mean > 0.01 && max > 16,
        "the haze moved the image by {mean:.3}/255 mean, {max}/255 max"
    );
    // With the composite's haze off, the image is the one without the haze emitter.
    let off = render_with(hazed, false);
    assert!(off == b, "the haze shown with the composite's haze off");
}
