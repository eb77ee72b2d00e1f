//! A Bevy scene — a ground, a few lit meshes, a camera — with the campfire and three
//! torches from the repository's `presets/`, played by `bevy_ignis` in Bevy's renderer.
//!
//! `cargo run --release --example campfire` opens a window. Headless (no window, an image
//! target; what CI runs): `campfire --frames 120 --screenshot shot.png` renders 120
//! frames of 1/60 s and saves the last.

use std::path::PathBuf;

use bevy::camera::{Hdr, RenderTarget};
use bevy::prelude::*;
use bevy::render::render_resource::TextureFormat;
use bevy::render::view::screenshot::{Screenshot, save_to_disk};
use bevy_ignis::{IgnisEffect, IgnisLight, IgnisPlugin};

#[path = "common/headless.rs"]
mod headless;

/// The night sky.
const NIGHT: ClearColor = ClearColor(Color::srgb(0.01, 0.012, 0.03));

/// The headless image's size.
const SHOT: (u32, u32) = (960, 540);

fn main() -> Result<(), String> {
    let mut frames = None;
    let mut screenshot = None;
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--frames" => frames = args.next().and_then(|n| n.parse::<u32>().ok()),
            "--screenshot" => screenshot = args.next().map(PathBuf::from),
            other => {
                return Err(format!(
                    "unknown argument {other:?} (--frames N --screenshot FILE)"
                ));
            }
        }
    }
    match frames {
        Some(n) => headless(n, screenshot),
        None => {
            let mut app = App::new();
            app.add_plugins((DefaultPlugins.set(asset_plugin()), ignis_plugin()))
                .insert_resource(NIGHT)
                .add_systems(
                    Startup,
                    |commands: Commands,
                     a: Res<AssetServer>,
                     m: ResMut<Assets<Mesh>>,
                     s: ResMut<Assets<StandardMaterial>>| {
                        scene(commands, a, m, s, None);
                    },
                );
            app.run();
            Ok(())
        }
    }
}

/// The repository's presets folder: the asset folder of this example.
fn presets() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../presets")
}

fn asset_plugin() -> AssetPlugin {
    AssetPlugin {
        file_path: presets().to_string_lossy().into_owned(),
        ..default()
    }
}

fn ignis_plugin() -> IgnisPlugin {
    IgnisPlugin {
        asset_root: presets(),
    }
}

/// Renders `frames` frames of 1/60 s into an image and saves the last as `screenshot`.
fn headless(frames: u32, screenshot: Option<PathBuf>) -> Result<(), String> {
    let mut app = headless::headless_app(&presets(), false);
    app.insert_resource(NIGHT);
    let image = Image::new_target_texture(SHOT.0, SHOT.1, TextureFormat::Rgba8UnormSrgb, None);
    let target = app.world_mut().resource_mut::<Assets<Image>>().add(image);
    app.world_mut()
        .run_system_cached_with(headless_scene, target.clone())
        .map_err(|e| e.to_string())?;
    for _ in 0..frames {
        app.update();
    }
    let Some(path) = screenshot else {
        return Ok(());
    };
    let _ = std::fs::remove_file(&path);
    app.world_mut()
        .spawn(Screenshot::image(target))
        .observe(save_to_disk(path.clone()));
    for _ in 0..30 {
        app.update();
        if path.exists() {
            return Ok(());
        }
    }
    Err(format!("the screenshot {} was not written", path.display()))
}

fn headless_scene(
    target: In<Handle<Image>>,
    commands: Commands,
    assets: Res<AssetServer>,
    meshes: ResMut<Assets<Mesh>>,
    materials: ResMut<Assets<StandardMaterial>>,
) {
    scene(commands, assets, meshes, materials, Some(target.0));
}

/// The ground, a log pile's stones, three posts with torches, a box in front of the
/// fire, the moon, the campfire's own flickering light, and the camera (into `target`,
/// or the window).
fn scene(
    mut commands: Commands,
    assets: Res<AssetServer>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    target: Option<Handle<Image>>,
) {
    let ground = materials.add(StandardMaterial {
        base_color: Color::srgb(0.28, 0.25, 0.22),
        perceptual_roughness: 0.95,
        ..default()
    });
    let stone = materials.add(Color::srgb(0.45, 0.43, 0.42));
    let wood = materials.add(Color::srgb(0.35, 0.22, 0.12));
    commands.spawn((
        Mesh3d(meshes.add(Plane3d::default().mesh().size(30.0, 30.0))),
        MeshMaterial3d(ground),
    ));
    for i in 0..8 {
        let a = i as f32 * std::f32::consts::TAU / 8.0;
        commands.spawn((
            Mesh3d(meshes.add(Sphere::new(0.12))),
            MeshMaterial3d(stone.clone()),
            Transform::from_xyz(0.55 * a.cos(), 0.06, 0.55 * a.sin()),
        ));
    }
    commands.spawn((
        Mesh3d(meshes.add(Cuboid::new(0.8, 0.5, 0.5))),
        MeshMaterial3d(stone),
        Transform::from_xyz(-0.55, 0.25, 1.2),
    ));
    let campfire = assets.load("campfire.ron");
    commands.spawn((
        IgnisEffect::new(campfire, 7),
        IgnisLight::default(),
        Transform::default(),
    ));
    let torch = assets.load("torch.ron");
    for (seed, x) in [(1, -2.5), (2, 2.5), (3, 0.0)] {
        let z = if x == 0.0 { -3.0 } else { -1.0 };
        // The torch preset burns at the top of a 1 m handle: its origin is the foot.
        commands.spawn((
            Mesh3d(meshes.add(Cylinder::new(0.05, 1.0))),
            MeshMaterial3d(wood.clone()),
            Transform::from_xyz(x, 0.5, z),
        ));
        commands.spawn((
            IgnisEffect::new(torch.clone(), seed),
            Transform::from_xyz(x, 0.0, z),
        ));
    }
    // The moon; the fire lights the ground itself (IgnisLight on the campfire).
    commands.spawn((
        DirectionalLight {
            color: Color::srgb(0.55, 0.62, 0.9),
            illuminance: 400.0,
            ..default()
        },
        Transform::from_xyz(-4.0, 8.0, 3.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    let eye = Transform::from_xyz(0.0, 2.4, 6.5).looking_at(Vec3::new(0.0, 0.8, 0.0), Vec3::Y);
    let mut camera = commands.spawn((Camera3d::default(), Hdr, eye));
    if let Some(image) = target {
        camera.insert(RenderTarget::from(image));
    }
}
