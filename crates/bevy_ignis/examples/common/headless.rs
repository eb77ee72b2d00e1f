//! A Bevy app without a window, for the examples' headless runs, the bench and the tests:
//! any adapter (lavapipe works), frames of exactly 1/60 s, the render world on the main
//! thread (each update renders its own frame), pipelines compiled before the first frame,
//! and the ignis plugin reading presets from `assets`.

use std::path::Path;
use std::time::Duration;

use bevy::app::PluginsState;
use bevy::prelude::*;
use bevy::render::RenderPlugin;
use bevy::time::TimeUpdateStrategy;
use bevy::window::ExitCondition;
use bevy_ignis::IgnisPlugin;

/// The app, its plugins built and finished, ready to spawn into (`watch`: Bevy's file
/// watcher on the asset folder).
pub fn headless_app(assets: &Path, watch: bool) -> App {
    headless_app_with(assets, watch, |_| {})
}

/// [`headless_app`] with `more` plugins added before they are built and finished (Bevy
/// refuses plugins after that).
pub fn headless_app_with(assets: &Path, watch: bool, more: impl FnOnce(&mut App)) -> App {
    let mut app = App::new();
    app.add_plugins(
        DefaultPlugins
            .set(AssetPlugin {
                file_path: assets.to_string_lossy().into_owned(),
                watch_for_changes_override: Some(watch),
                ..default()
            })
            .set(WindowPlugin {
                primary_window: None,
                exit_condition: ExitCondition::DontExit,
                ..default()
            })
            .set(RenderPlugin {
                synchronous_pipeline_compilation: true,
                ..default()
            })
            .disable::<bevy::winit::WinitPlugin>()
            .disable::<bevy::render::pipelined_rendering::PipelinedRenderingPlugin>(),
    )
    .add_plugins(IgnisPlugin {
        asset_root: assets.to_path_buf(),
    })
    .insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_secs_f64(
        1.0 / 60.0,
    )));
    more(&mut app);
    while app.plugins_state() == PluginsState::Adding {
        bevy::tasks::tick_global_task_pools_on_main_thread();
    }
    app.finish();
    app.cleanup();
    app
}
