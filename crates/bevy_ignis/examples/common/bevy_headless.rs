//! A Bevy app without a window, whatever else it plays: any adapter (lavapipe works),
//! frames of exactly 1/60 s, the render world on the main thread (each update renders its
//! own frame), pipelines compiled before the first frame; and a frame read back through
//! Bevy's screenshot. Shared by the plugin's examples, bench and tests (`headless.rs` adds
//! the plugin) and by the peer bench (`crates/bench_hanabi`).

// Each includer uses part of it.
#![allow(dead_code)]

use std::sync::{Arc, Mutex};
use std::time::Duration;

use bevy::app::{PluginGroupBuilder, PluginsState};
use bevy::prelude::*;
use bevy::render::RenderPlugin;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use bevy::time::TimeUpdateStrategy;
use bevy::window::ExitCondition;

/// Bevy's default plugins without a window, winit or pipelined rendering, pipelines
/// compiled synchronously, assets as `assets` says.
pub fn plugins(assets: AssetPlugin) -> PluginGroupBuilder {
    DefaultPlugins
        .set(assets)
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
        .disable::<bevy::render::pipelined_rendering::PipelinedRenderingPlugin>()
}

/// `app` with frames of exactly 1/60 s, its plugins built and finished: ready to spawn
/// into (Bevy refuses plugins after this).
pub fn finish(mut app: App) -> App {
    app.insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_secs_f64(
        1.0 / 60.0,
    )));
    while app.plugins_state() == PluginsState::Adding {
        bevy::tasks::tick_global_task_pools_on_main_thread();
    }
    app.finish();
    app.cleanup();
    app
}

/// The image of `target` a screenshot reads back, rendering up to `frames` frames for it.
pub fn screenshot(app: &mut App, target: &Handle<Image>, frames: u32) -> Result<Image, String> {
    let slot: Arc<Mutex<Option<Image>>> = Arc::default();
    let out = slot.clone();
    app.world_mut()
        .spawn(Screenshot::image(target.clone()))
        .observe(move |shot: On<ScreenshotCaptured>| {
            if let Ok(mut s) = out.lock() {
                *s = Some(shot.image.clone());
            }
        });
    for _ in 0..frames {
        app.update();
        if let Some(image) = slot.lock().ok().and_then(|mut s| s.take()) {
            return Ok(image);
        }
    }
    Err(format!("no screenshot arrived in {frames} frames"))
}
