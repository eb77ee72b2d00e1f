//! [`IgnisEffect`]: the component that plays one instance of a preset where its entity
//! is.

use bevy::prelude::*;

use crate::asset::IgnisPreset;

/// Plays one instance of `preset` at the entity's `Transform` (rotation and translation;
/// moving the entity moves the emitter, living particles keep their world motion).
///
/// Instances of one preset share one player (one batch of instances, one dispatch per
/// emitter) and its clock: Bevy's virtual time, so pausing `Time<Virtual>` pauses them.
/// Despawning the entity removes the instance.
#[derive(Component, Clone, Debug)]
#[require(Transform, Visibility)]
pub struct IgnisEffect {
    /// The preset (`asset_server.load("effects/torch.ron")`).
    pub preset: Handle<IgnisPreset>,
    /// The instance's seed: the same preset and seed give the same particles.
    pub seed: u32,
    /// Playing (true) or stopped and hidden (false); set true again to start it from
    /// its beginning.
    pub playing: bool,
}

impl IgnisEffect {
    /// A playing instance of `preset` with `seed`.
    pub fn new(preset: Handle<IgnisPreset>, seed: u32) -> Self {
        Self {
            preset,
            seed,
            playing: true,
        }
    }
}

/// Seeks every instance of the entity's preset to `secs` seconds from their start
/// (exactly: the runtime replays the steps from its nearest snapshot), for cut-scenes.
/// Instances of one preset share a clock, so all of them move; the component is removed
/// once applied.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct IgnisSeek(pub f64);
