//! A Bevy app without a window, for the examples' headless runs, the bench and the tests
//! (`bevy_headless.rs`: any adapter, frames of exactly 1/60 s, the render world on the
//! main thread, pipelines compiled before the first frame), with the ignis plugin reading
//! presets from `assets`.

use std::path::Path;

use bevy::prelude::*;
use bevy_ignis::IgnisPlugin;

#[path = "bevy_headless.rs"]
pub mod bevy_headless;

/// The app, its plugins built and finished, ready to spawn into (`watch`: Bevy's file
/// watcher on the asset folder).
pub fn headless_app(assets: &Path, watch: bool) -> App {
    headless_app_with(assets, watch, |_| {})
}

/// [`headless_app`] with `more` plugins added before they are built and finished (Bevy
/// refuses plugins after that).
pub fn headless_app_with(assets: &Path, watch: bool, more: impl FnOnce(&mut App)) -> App {
    let mut app = App::new();
    app.add_plugins(bevy_headless::plugins(AssetPlugin {
        file_path: assets.to_string_lossy().into_owned(),
        watch_for_changes_override: Some(watch),
        ..default()
    }))
    .add_plugins(IgnisPlugin {
        asset_root: assets.to_path_buf(),
    });
    more(&mut app);
    bevy_headless::finish(app)
}
