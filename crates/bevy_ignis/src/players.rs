//! The render world's players: one per preset and camera view (a player records its
//! camera through the queue, and Bevy submits every view's work at once), each with the
//! instances of its preset, kept in step with the main world's entities.

use std::collections::{HashMap, HashSet};

use bevy::prelude::*;
use bevy::render::renderer::{RenderDevice, RenderQueue};
use bevy::render::view::{Msaa, ViewTarget};
use ignis::{InstanceId, Player, PlayerSettings};

use crate::asset::IgnisPreset;
use crate::extract::{ExtractedIgnis, ExtractedPreset};

/// Bevy's 3D depth: `Depth32Float`, reversed Z (1 near, 0 far).
pub const BEVY_DEPTH: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// A player of one preset for one view, and its instances by main-world entity.
pub struct ViewPlayer {
    /// The player.
    pub player: Player,
    /// Its instances: entity → (instance, seed).
    pub instances: HashMap<Entity, (InstanceId, u32)>,
    /// The preset generation it plays.
    generation: u64,
    /// The view's colour format and samples it was built for.
    target: (wgpu::TextureFormat, u32),
    /// The last error its view's frame logged (each distinct one is logged once).
    pub last_error: Option<String>,
}

/// Every player, by (preset, render-world view entity).
#[derive(Resource, Default)]
pub struct IgnisPlayers {
    /// The players.
    pub players: HashMap<(AssetId<IgnisPreset>, Entity), ViewPlayer>,
}

impl IgnisPlayers {
    /// The player of `preset` for the first view that has one (tests and tools: its
    /// particles, its instances).
    pub fn any_of(&self, preset: AssetId<IgnisPreset>) -> Option<&ViewPlayer> {
        self.players
            .iter()
            .filter(|((p, _), _)| *p == preset)
            .min_by_key(|((_, view), _)| *view)
            .map(|(_, v)| v)
    }
}

/// Render world, once per frame before the views render: makes or updates the player of
/// every preset for every 3D view, adds, moves and removes instances, applies seeks, and
/// advances the clocks by Bevy's (virtual) frame time.
pub fn prepare_players(
    mut players: ResMut<IgnisPlayers>,
    extracted: Res<ExtractedIgnis>,
    views: Query<(Entity, &ViewTarget, &Msaa), With<Camera3d>>,
    device: Res<RenderDevice>,
    queue: Res<RenderQueue>,
    time: Res<Time>,
    lights: Res<crate::EffectLights>,
) {
    publish_lights(&players, &lights);
    let wanted: HashSet<AssetId<IgnisPreset>> =
        extracted.instances.iter().map(|i| i.preset).collect();
    let mut alive = HashSet::new();
    for (view, target, msaa) in &views {
        let key = (target.main_texture_format(), msaa.samples());
        for &preset in &wanted {
            let Some(entry) = extracted.presets.get(&preset) else {
                continue;
            };
            alive.insert((preset, view));
            let slot = players.players.get_mut(&(preset, view));
            let Some(vp) = ready(slot, entry, key, device.wgpu_device(), &queue) else {
                continue;
            };
            let vp = match vp {
                Ready::Kept(vp) => vp,
                Ready::New(vp) => players
                    .players
                    .entry((preset, view))
                    .insert_entry(*vp)
                    .into_mut(),
            };
            sync_instances(vp, &extracted, preset);
            let lit = (extracted.instances.iter()).any(|i| i.preset == preset && i.light);
            vp.player.set_light_estimate(lit);
            for (_, secs) in extracted.seeks.iter().filter(|(p, _)| *p == preset) {
                vp.player.seek(*secs, time.delta_secs_f64().max(1.0 / 60.0));
            }
            vp.player.advance(time.delta_secs_f64());
        }
    }
    players.players.retain(|k, _| alive.contains(k));
}

/// A player ready to play `entry` into a view of `key`: the kept one (its effect
/// updated after a reload), or a new one (`None`: it could not be made, logged).
enum Ready<'a> {
    Kept(&'a mut ViewPlayer),
    New(Box<ViewPlayer>),
}

fn ready<'a>(
    slot: Option<&'a mut ViewPlayer>,
    entry: &ExtractedPreset,
    key: (wgpu::TextureFormat, u32),
    device: &wgpu::Device,
    queue: &wgpu::Queue,
) -> Option<Ready<'a>> {
    match slot {
        Some(vp) if vp.target == key => {
            if vp.generation != entry.generation {
                vp.generation = entry.generation;
                if let Err(e) = vp.player.set_effect(&entry.effect) {
                    error!(
                        "ignis: the reloaded preset cannot play, keeping the last good one: {e}"
                    );
                }
            }
            Some(Ready::Kept(vp))
        }
        _ => {
            let settings = PlayerSettings {
                depth_format: Some(BEVY_DEPTH),
                depth_compare: wgpu::CompareFunction::GreaterEqual,
                sample_count: key.1,
                asset_dir: Some(entry.asset_dir.clone()),
                ..PlayerSettings::new(key.0)
            };
            match Player::new(device, queue, &entry.effect, settings) {
                Ok(player) => Some(Ready::New(Box::new(ViewPlayer {
                    player,
                    instances: HashMap::new(),
                    generation: entry.generation,
                    target: key,
                    last_error: None,
                }))),
                Err(e) => {
                    error!("ignis: cannot play a preset in this view: {e}");
                    None
                }
            }
        }
    }
}

/// Adds the preset's new instances, moves the living ones, removes the gone ones.
fn sync_instances(vp: &mut ViewPlayer, extracted: &ExtractedIgnis, preset: AssetId<IgnisPreset>) {
    let mut seen = HashSet::new();
    for i in extracted.instances.iter().filter(|i| i.preset == preset) {
        seen.insert(i.entity);
        match vp.instances.get(&i.entity) {
            Some((id, seed)) if *seed == i.seed => {
                vp.player.set_transform(*id, i.world);
            }
            _ => {
                if let Some((old, _)) = vp.instances.remove(&i.entity) {
                    vp.player.remove_instance(old);
                }
                match vp.player.add_instance(i.world, i.seed) {
                    Ok(id) => {
                        vp.instances.insert(i.entity, (id, i.seed));
                    }
                    Err(e) => error!("ignis: cannot add an instance: {e}"),
                }
            }
        }
    }
    vp.instances.retain(|entity, (id, _)| {
        let keep = seen.contains(entity);
        if !keep {
            vp.player.remove_instance(*id);
        }
        keep
    });
}

/// Shares the lights the players last read back with the main world (the first view's
/// player of each preset speaks for its instances).
fn publish_lights(players: &IgnisPlayers, lights: &crate::EffectLights) {
    let Ok(mut out) = lights.0.lock() else {
        return;
    };
    out.clear();
    let mut views: Vec<_> = players.players.iter().collect();
    views.sort_by_key(|((_, view), _)| std::cmp::Reverse(*view));
    for (_, vp) in views {
        for (entity, (id, _)) in &vp.instances {
            if let Some(light) = vp.player.effect_light(*id) {
                out.insert(*entity, light);
            }
        }
    }
}
