//! The sphere workload in bevy_hanabi: the app, the effect, the camera, and the timed
//! frames. The sprite differs: ignis's scenes draw its soft disc, hanabi a hard-edged one
//! (`RoundModifier`): the cost is the same shape of quad.

use std::path::Path;

use bevy::camera::RenderTarget;
use bevy::core_pipeline::tonemapping::{DebandDither, Tonemapping};
use bevy::diagnostic::DiagnosticsStore;
use bevy::prelude::*;
use bevy::render::diagnostic::RenderDiagnosticsPlugin;
use bevy::render::render_resource::TextureFormat;
use bevy::render::renderer::RenderAdapterInfo;
use bevy_hanabi::prelude::*;

use crate::Options;
use crate::bevy_headless;
use crate::stamps::{Stamps, StampsPlugin};

/// One N's medians.
pub struct Run {
    pub n: u32,
    pub adapter: String,
    /// The render graph between the two stamps: hanabi's simulation and the camera.
    pub frame_ms: f64,
    /// Bevy's span of the transparent pass (hanabi's additive particles' draw).
    pub draw_ms: f64,
    pub frames: usize,
}

/// A headless app (`bevy_headless`: no window, frames of exactly 1/60 s, the render world
/// on the main thread, pipelines compiled before the first frame) with hanabi and the
/// timers.
fn app() -> App {
    let mut app = App::new();
    // One app per N: Bevy's logger can be set only once in a process.
    app.add_plugins(
        bevy_headless::plugins(AssetPlugin::default()).disable::<bevy::log::LogPlugin>(),
    )
    .add_plugins((HanabiPlugin, RenderDiagnosticsPlugin, StampsPlugin))
    .insert_resource(ClearColor(Color::BLACK));
    bevy_headless::finish(app)
}

/// ignis's `bench/scenes/sphere_*.ron` of `n` particles as a hanabi effect.
fn effect(n: u32) -> EffectAsset {
    let w = ExprWriter::new();
    let lifetime = SetAttributeModifier::new(Attribute::LIFETIME, w.lit(2.0).expr());
    let age = SetAttributeModifier::new(Attribute::AGE, w.lit(0.0).expr());
    let position = SetPositionSphereModifier {
        center: w.lit(Vec3::ZERO).expr(),
        radius: w.lit(1.0).expr(),
        dimension: ShapeDimension::Volume,
    };
    // A random direction (ignis: a 180° spread around +y), 0 to 0.3 m/s.
    let direction = (w.rand(VectorType::VEC3F) * w.lit(2.0) - w.lit(1.0)).normalized();
    let speed = w.rand(ScalarType::Float) * w.lit(0.3);
    let velocity = SetAttributeModifier::new(Attribute::VELOCITY, (direction * speed).expr());
    let gravity = AccelModifier::new(w.lit(Vec3::new(0.0, -0.5, 0.0)).expr());
    let drag = LinearDragModifier::new(w.lit(0.5).expr());
    let round = RoundModifier {
        roundness: w.lit(1.0).expr(),
    };
    // Additive: hanabi weighs the colour by its alpha, so the intensity scales the rgb.
    let k = intensity(n);
    let mut color = bevy_hanabi::Gradient::new();
    color.add_key(0.0, Vec4::new(k, 0.8 * k, 0.4 * k, 1.0));
    color.add_key(1.0, Vec4::new(k, 0.4 * k, 0.1 * k, 1.0));
    EffectAsset::new(
        n,
        SpawnerSettings::rate((n as f32 / 2.0).into()),
        w.finish(),
    )
    .with_name("sphere")
    .with_alpha_mode(bevy_hanabi::AlphaMode::Add)
    .init(position)
    .init(velocity)
    .init(age)
    .init(lifetime)
    .update(gravity)
    .update(drag)
    .render(SetSizeModifier {
        size: Vec3::splat(0.0092).into(),
    })
    .render(ColorOverLifetimeModifier::new(color))
    .render(round)
}

/// The scenes' intensity for `n` particles (the pile stays below white).
fn intensity(n: u32) -> f32 {
    match n {
        1_048_576 => 0.03,
        4_194_304 => 0.008,
        16_777_216 => 0.002,
        67_100_000 => 0.0005,
        _ => 0.03 * (1 << 20) as f32 / n.max(1) as f32,
    }
}

/// Plays `n` particles past their lifetime, times `frames` frames, and writes the last
/// one's image into `out`.
pub fn run(n: u32, size: (u32, u32), frames: usize, out: &Path) -> Run {
    let mut app = app();
    let image = Image::new_target_texture(size.0, size.1, TextureFormat::Rgba8UnormSrgb, None);
    let target = app.world_mut().resource_mut::<Assets<Image>>().add(image);
    app.world_mut().spawn((
        Camera3d::default(),
        bevy::camera::Hdr,
        RenderTarget::from(target.clone()),
        Projection::Perspective(PerspectiveProjection {
            fov: 45f32.to_radians(),
            ..default()
        }),
        Tonemapping::None,
        DebandDither::Disabled,
        Transform::from_xyz(0.0, 0.0, 4.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    let handle = app
        .world_mut()
        .resource_mut::<Assets<EffectAsset>>()
        .add(effect(n));
    app.world_mut().spawn(ParticleEffect::new(handle));
    // 2 s lives: 2.5 s of frames reach the steady state.
    for _ in 0..150 {
        app.update();
    }
    let stamps = app.world().resource::<Stamps>().clone();
    let (mut frame, mut draw) = (Vec::new(), Vec::new());
    for _ in 0..frames {
        app.update();
        frame.extend(stamps.read_ms());
        draw.extend(transparent_pass_ms(&app));
    }
    let adapter = app
        .sub_app(bevy::render::RenderApp)
        .world()
        .resource::<RenderAdapterInfo>()
        .name
        .clone();
    let png = out.join(format!("hanabi-{n}.png"));
    if let Err(e) = crate::capture::save(&mut app, &target, &png) {
        eprintln!("bench_hanabi: no image for {n}: {e}");
    }
    Run {
        n,
        adapter,
        frame_ms: median(&mut frame),
        draw_ms: median(&mut draw),
        frames,
    }
}

/// Bevy's latest GPU time of the transparent pass, in milliseconds.
fn transparent_pass_ms(app: &App) -> Option<f64> {
    let store = app.world().resource::<DiagnosticsStore>();
    store
        .iter()
        .find(|d| {
            let p = d.path().as_str();
            p.contains("main_transparent_pass_3d") && p.ends_with("elapsed_gpu")
        })
        .and_then(|d| d.measurement())
        .map(|m| m.value)
}

fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// The runs as JSON (hand-written: a flat record per N).
pub fn to_json(adapter: &str, opts: &Options, rows: &[Run]) -> String {
    let rows: Vec<String> = rows
        .iter()
        .map(|r| {
            format!(
                "    {{\"n\": {}, \"frame_ms\": {:.6}, \"transparent_pass_ms\": {:.6}, \
                 \"frames\": {}, \"image\": \"hanabi-{}.png\"}}",
                r.n, r.frame_ms, r.draw_ms, r.frames, r.n
            )
        })
        .collect();
    format!(
        "{{\n  \"adapter\": {:?},\n  \"peer\": \"bevy_hanabi 0.20.0, Bevy 0.20.1\",\n  \
         \"size\": \"{}x{}\",\n  \"rows\": [\n{}\n  ]\n}}\n",
        adapter,
        opts.size.0,
        opts.size.1,
        rows.join(",\n")
    )
}
