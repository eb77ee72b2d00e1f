//! What the render world takes from the main world each frame: the presets (cloned when
//! loaded or hot-reloaded), the effect entities and their transforms, and the seeks.

use std::collections::HashMap;
use std::path::PathBuf;

use bevy::ecs::message::MessageReader;
use bevy::prelude::*;
use bevy::render::Extract;

use crate::asset::IgnisPreset;
use crate::effect::{IgnisEffect, IgnisSeek};

/// The folder the asset server reads from (the presets' sprites are found through it).
#[derive(Resource, Clone, Debug)]
pub struct IgnisAssetRoot(pub PathBuf);

/// A preset as the render world plays it.
pub struct ExtractedPreset {
    /// The effect.
    pub effect: ignis::Effect,
    /// The folder its sprite paths are relative to.
    pub asset_dir: PathBuf,
    /// Counts loads and reloads: players update their effect when it changes.
    pub generation: u64,
}

/// One playing instance this frame.
pub struct ExtractedInstance {
    /// The main-world entity.
    pub entity: Entity,
    /// Its preset.
    pub preset: AssetId<IgnisPreset>,
    /// Its seed.
    pub seed: u32,
    /// Its world transform (column-major).
    pub world: [[f32; 4]; 4],
    /// It lights the scene (an [`IgnisLight`](crate::IgnisLight)): its light is estimated.
    pub light: bool,
}

/// The render world's copy of the presets and this frame's instances and seeks.
#[derive(Resource, Default)]
pub struct ExtractedIgnis {
    /// Every preset seen, by asset.
    pub presets: HashMap<AssetId<IgnisPreset>, ExtractedPreset>,
    /// This frame's playing instances.
    pub instances: Vec<ExtractedInstance>,
    /// This frame's seeks: a preset's instances to a time in seconds.
    pub seeks: Vec<(AssetId<IgnisPreset>, f64)>,
    generation: u64,
}

/// The seeks asked for this frame (main world; moved here from [`IgnisSeek`] components).
#[derive(Resource, Default)]
pub struct PendingSeeks(pub Vec<(AssetId<IgnisPreset>, f64)>);

/// Main world, after the frame's systems: turns [`IgnisSeek`] components into
/// [`PendingSeeks`] (extracted this frame, cleared at the next).
pub fn take_seeks(
    mut commands: Commands,
    mut pending: ResMut<PendingSeeks>,
    seeks: Query<(Entity, &IgnisEffect, &IgnisSeek)>,
) {
    for (entity, effect, seek) in &seeks {
        pending.0.push((effect.preset.id(), seek.0));
        commands.entity(entity).remove::<IgnisSeek>();
    }
}

/// Main world, first thing in a frame: the last frame's seeks were extracted.
pub fn clear_seeks(mut pending: ResMut<PendingSeeks>) {
    pending.0.clear();
}

/// What extraction reads of an effect entity.
type EffectItem = (
    Entity,
    &'static IgnisEffect,
    &'static GlobalTransform,
    Has<crate::IgnisLight>,
);

/// Render world: copies the instances, the seeks and every loaded or reloaded preset.
pub fn extract_ignis(
    mut out: ResMut<ExtractedIgnis>,
    effects: Extract<Query<EffectItem>>,
    presets: Extract<Res<Assets<IgnisPreset>>>,
    mut events: Extract<MessageReader<AssetEvent<IgnisPreset>>>,
    pending: Extract<Res<PendingSeeks>>,
    root: Extract<Res<IgnisAssetRoot>>,
) {
    let out = &mut *out;
    for event in events.read() {
        match event {
            AssetEvent::Added { id } | AssetEvent::Modified { id } => {
                if let Some(p) = presets.get(*id) {
                    out.generation += 1;
                    out.presets
                        .insert(*id, preset_entry(p, &root.0, out.generation));
                }
            }
            AssetEvent::Removed { id } | AssetEvent::Unused { id } => {
                out.presets.remove(id);
            }
            AssetEvent::LoadedWithDependencies { .. } => {}
        }
    }
    out.instances.clear();
    for (entity, effect, transform, light) in &effects {
        let id = effect.preset.id();
        if !effect.playing {
            continue;
        }
        if !out.presets.contains_key(&id)
            && let Some(p) = presets.get(id)
        {
            out.generation += 1;
            out.presets
                .insert(id, preset_entry(p, &root.0, out.generation));
        }
        out.instances.push(ExtractedInstance {
            entity,
            preset: id,
            seed: effect.seed,
            world: transform.to_matrix().to_cols_array_2d(),
            light,
        });
    }
    out.seeks.clone_from(&pending.0);
}

fn preset_entry(p: &IgnisPreset, root: &std::path::Path, generation: u64) -> ExtractedPreset {
    let folder = p.path.parent().unwrap_or(std::path::Path::new(""));
    ExtractedPreset {
        effect: p.effect.clone(),
        asset_dir: root.join(folder),
        generation,
    }
}
