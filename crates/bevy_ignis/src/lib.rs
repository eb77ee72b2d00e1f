//! Play ignis fire presets as Bevy entities, in Bevy's own renderer.
//!
//! Add [`IgnisPlugin`], load a preset made in the ignis editor as an asset, and spawn an
//! entity with an [`IgnisEffect`] and a `Transform`:
//!
//! ```no_run
//! use bevy::prelude::*;
//! use bevy_ignis::{IgnisEffect, IgnisPlugin};
//!
//! fn setup(mut commands: Commands, assets: Res<AssetServer>) {
//!     let torch = assets.load("torch.ron");
//!     commands.spawn((IgnisEffect::new(torch, 1), Transform::from_xyz(0.0, 0.0, -2.0)));
//! }
//!
//! App::new()
//!     .add_plugins((DefaultPlugins, IgnisPlugin::default()))
//!     .add_systems(Startup, setup)
//!     .run();
//! ```
//!
//! The simulation is recorded once per frame per view into Bevy's command encoder, on
//! Bevy's device (ignis and Bevy 0.20 share wgpu 30: no copy, no second device), and the
//! particles are drawn after the main transparent pass of every 3D camera, against its
//! reversed-Z depth (MSAA and HDR included). `README.md` has the details.

mod asset;
mod draw;
mod effect;
mod extract;
mod light;
mod players;

pub use asset::{IgnisLoadError, IgnisPreset, IgnisPresetLoader};
pub use effect::{IgnisEffect, IgnisSeek};
pub use extract::IgnisAssetRoot;
pub use ignis;
pub use light::{EffectLights, IgnisLight, IgnisLightOf};
pub use players::{IgnisPlayers, ViewPlayer};

use bevy::core_pipeline::core_3d::main_transparent_pass_3d;
use bevy::core_pipeline::{Core3d, Core3dSystems};
use bevy::prelude::*;
use bevy::render::{ExtractSchedule, Render, RenderApp, RenderSystems};

/// Plays [`IgnisEffect`]s: registers the preset asset and its loader, extracts the
/// effects to the render world, and draws them in every 3D camera.
#[derive(Clone, Debug)]
pub struct IgnisPlugin {
    /// The folder Bevy's asset server reads from (`AssetPlugin::file_path` resolved; by
    /// default Bevy's `assets` beside the executable's project): the presets' sprites
    /// are read from the preset's folder inside it.
    pub asset_root: std::path::PathBuf,
}

impl Default for IgnisPlugin {
    fn default() -> Self {
        Self {
            asset_root: bevy::asset::io::file::FileAssetReader::get_base_path().join("assets"),
        }
    }
}

impl Plugin for IgnisPlugin {
    fn build(&self, app: &mut App) {
        app.init_asset::<IgnisPreset>()
            .init_asset_loader::<IgnisPresetLoader>()
            .init_resource::<extract::PendingSeeks>()
            .insert_resource(IgnisAssetRoot(self.asset_root.clone()))
            .init_resource::<EffectLights>()
            .add_systems(First, extract::clear_seeks)
            .add_systems(PostUpdate, light::update_lights)
            .add_systems(Last, extract::take_seeks);
        let lights = app.world().resource::<EffectLights>().clone();
        let Some(render_app) = app.get_sub_app_mut(RenderApp) else {
            return;
        };
        render_app
            .insert_resource(lights)
            .init_resource::<extract::ExtractedIgnis>()
            .init_resource::<IgnisPlayers>()
            .add_systems(ExtractSchedule, extract::extract_ignis)
            .add_systems(
                Render,
                (
                    draw::sampleable_depth.in_set(RenderSystems::PrepareViews),
                    players::prepare_players.in_set(RenderSystems::PrepareResources),
                ),
            )
            .add_systems(
                Core3d,
                draw::draw_players
                    .after(main_transparent_pass_3d)
                    .after(Core3dSystems::MainPass)
                    .before(Core3dSystems::EarlyPostProcess),
            );
    }
}
