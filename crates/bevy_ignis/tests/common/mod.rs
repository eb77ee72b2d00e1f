//! A headless Bevy app for the plugin's tests: lavapipe or any adapter, no window, frames
//! of exactly 1/60 s, a camera into an image that the tests read back.

#![allow(dead_code)]

#[path = "../../examples/common/headless.rs"]
mod headless;

use std::path::{Path, PathBuf};
use std::time::Duration;

use bevy::camera::RenderTarget;
use bevy::core_pipeline::tonemapping::{DebandDither, Tonemapping};
use bevy::prelude::*;
use bevy::render::render_resource::TextureFormat;
use bevy_ignis::{IgnisPlayers, IgnisPreset};

/// The test image's size.
pub const SIZE: (u32, u32) = (200, 150);

/// The repository's presets.
pub fn presets() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../presets")
}

/// A headless app reading assets from `assets` (watching them when `watch`), with the
/// plugin, ready to spawn into; a black background.
pub fn app(assets: &Path, watch: bool) -> App {
    let mut app = headless::headless_app(assets, watch);
    app.insert_resource(ClearColor(Color::BLACK));
    app
}

/// An LDR image target of the test size and a camera into it at `eye` looking at
/// `target`: no tonemapping or dithering (the image is what was drawn).
pub fn camera(app: &mut App, eye: Vec3, target: Vec3) -> Handle<Image> {
    let image = Image::new_target_texture(SIZE.0, SIZE.1, TextureFormat::Rgba8UnormSrgb, None);
    let handle = app.world_mut().resource_mut::<Assets<Image>>().add(image);
    app.world_mut().spawn((
        Camera3d::default(),
        RenderTarget::from(handle.clone()),
        Tonemapping::None,
        DebandDither::Disabled,
        Transform::from_translation(eye).looking_at(target, Vec3::Y),
    ));
    handle
}

/// Loads `path` and updates until it is loaded (so that entities spawned next start on
/// a known frame).
pub fn load(app: &mut App, path: &str) -> Handle<IgnisPreset> {
    let handle: Handle<IgnisPreset> = app.world().resource::<AssetServer>().load(path.to_owned());
    for _ in 0..600 {
        if app
            .world()
            .resource::<Assets<IgnisPreset>>()
            .get(&handle)
            .is_some()
        {
            return handle;
        }
        app.update();
        std::thread::sleep(Duration::from_millis(5));
    }
    panic!("{path} did not load");
}

/// Runs `frames` frames.
pub fn run(app: &mut App, frames: u32) {
    for _ in 0..frames {
        app.update();
    }
}

/// The next frame's image as RGBA8 (sRGB), read back through a screenshot.
pub fn capture(app: &mut App, target: &Handle<Image>) -> Vec<[u8; 4]> {
    let image = headless::bevy_headless::screenshot(app, target, 30).expect("a screenshot");
    let bytes = image.data.expect("screenshot bytes");
    bytes
        .chunks_exact(4)
        .map(|c| [c[0], c[1], c[2], c[3]])
        .collect()
}

/// The render world's players.
pub fn players(app: &App) -> &IgnisPlayers {
    app.get_sub_app(bevy::render::RenderApp)
        .expect("render app")
        .world()
        .resource::<IgnisPlayers>()
}

/// A temporary asset folder holding the repository's `name` preset, as `edit` rewrites its
/// text, and its textures.
pub fn temp_presets(name: &str, edit: impl Fn(&str) -> String) -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("temp dir");
    let text = std::fs::read_to_string(presets().join(name)).expect("preset");
    std::fs::write(dir.path().join(name), edit(&text)).expect("write preset");
    let textures = dir.path().join("textures");
    std::fs::create_dir(&textures).expect("textures");
    for e in std::fs::read_dir(presets().join("textures")).expect("textures") {
        let e = e.expect("entry");
        std::fs::copy(e.path(), textures.join(e.file_name())).expect("copy texture");
    }
    dir
}
