//! The render world's players: one per preset and kind of view target (colour format and
//! MSAA samples: the pipelines are built for them), each with the instances of its preset,
//! kept in step with the main world's entities. A player's clock advances once a frame and
//! its steps are recorded once, by the first view that draws it; every other view of the
//! same target kind records only its own sort and splat and draws the same particles.

use std::collections::{HashMap, HashSet};

use bevy::prelude::*;
use bevy::render::renderer::{RenderDevice, RenderQueue};
use bevy::render::view::{Msaa, ViewTarget};
use ignis::{InstanceId, Player, PlayerSettings};

use crate::asset::IgnisPreset;
use crate::extract::{ExtractedIgnis, ExtractedPreset};

/// Bevy's 3D depth: `Depth32Float`, reversed Z (1 near, 0 far).
pub const BEVY_DEPTH: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// A player of one preset for one kind of view target, and its instances by main-world
/// entity.
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
    /// Views that recorded it this frame (a later view submits the earlier ones' work
    /// first: the camera goes through the queue).
    pub(crate) recorded: u32,
}

/// What a player is built for: its preset, and the views' colour format and MSAA samples.
pub type PlayerKey = (AssetId<IgnisPreset>, wgpu::TextureFormat, u32);

/// Every player, by preset and target kind.
#[derive(Resource, Default)]
pub struct IgnisPlayers {
    /// The players.
    pub players: HashMap<PlayerKey, ViewPlayer>,
}

impl IgnisPlayers {
    /// A player of `preset` (tests and tools: its particles, its instances; with views of
    /// several target kinds, the one of the lowest sample count).
    pub fn any_of(&self, preset: AssetId<IgnisPreset>) -> Option<&ViewPlayer> {
        self.players
            .iter()
            .filter(|((p, _, _), _)| *p == preset)
            .min_by_key(|((_, _, samples), _)| *samples)
            .map(|(_, v)| v)
    }
}

/// Render world, once per frame before the views render: makes or updates the player of
/// every preset for every kind of 3D view target, adds, moves and removes instances,
/// applies seeks, and advances the clocks by Bevy's (virtual) frame time.
pub fn prepare_players(
    mut players: ResMut<IgnisPlayers>,
    extracted: Res<ExtractedIgnis>,
    views: Query<(&ViewTarget, &Msaa), With<Camera3d>>,
    device: Res<RenderDevice>,
    queue: Res<RenderQueue>,
    time: Res<Time>,
    lights: Res<crate::EffectLights>,
) {
    publish_lights(&players, &lights);
    let wanted: HashSet<AssetId<IgnisPreset>> =
        extracted.instances.iter().map(|i| i.preset).collect();
    let mut alive = HashSet::new();
    let kinds: HashSet<_> = (views.iter())
        .map(|(target, msaa)| (target.main_texture_format(), msaa.samples()))
        .collect();
    for &(format, samples) in &kinds {
        for &preset in &wanted {
            let Some(entry) = extracted.presets.get(&preset) else {
                continue;
            };
            let key = (preset, format, samples);
            alive.insert(key);
            let slot = players.players.get_mut(&key);
            let target = (format, samples);
            let Some(vp) = ready(slot, entry, target, device.wgpu_device(), &queue) else {
                continue;
            };
            let vp = match vp {
                Ready::Kept(vp) => vp,
                Ready::New(vp) => players.players.entry(key).insert_entry(*vp).into_mut(),
            };
            vp.recorded = 0;
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
                    recorded: 0,
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

/// Shares the lights the players last read back with the main world (the player of each
/// preset with the fewest samples speaks for its instances).
fn publish_lights(players: &IgnisPlayers, lights: &crate::EffectLights) {
    let Ok(mut out) = lights.0.lock() else {
        return;
    };
    out.clear();
    let mut views: Vec<_> = players.players.iter().collect();
    views.sort_by_key(|((_, _, samples), _)| std::cmp::Reverse(*samples));
    for (_, vp) in views {
        for (entity, (id, _)) in &vp.instances {
            if let Some(light) = vp.player.effect_light(*id) {
                out.insert(*entity, light);
            }
        }
    }
}
