//! Live changes to a playing [`Player`]: a new version of its effect (an edit, a preset
//! saved again), WGSL and PNG sprites changed on disk. None of them waits for the GPU or
//! loses the particles of an emitter that survives the change.

use std::path::{Path, PathBuf};

use glam::Mat4;

use crate::effect::Effect;
use crate::gpu::types::StateLayout;
use crate::render::haze::HazePass;
use crate::runtime::instances::{Backing, Instance};
use crate::runtime::player::update_mode;
use crate::runtime::remap::emitter_sources;
use crate::runtime::{InstanceId, Player, PlayerError};
use crate::shaders::{ShaderError, ShaderLibrary};
use crate::sim::Modules;
use crate::sim::batch::{InstanceBatch, batchable};
use crate::sim::gpu_sim::{lock, used_keys};
use crate::sim::{GpuSim, SimError};

/// The WGSL entry files a player's pipelines are built from (see
/// [`Player::reload_shader`]); their imports are found from these.
pub const PLAYER_SHADERS: &[&str] = &[
    "update.wgsl",
    "count.wgsl",
    "events.wgsl",
    "billboard.wgsl",
    "splat.wgsl",
    "tiles.wgsl",
    "sort.wgsl",
    "depth_resolve.wgsl",
    "light.wgsl",
    "light_apply.wgsl",
    "haze_apply.wgsl",
];

impl Player {
    /// Plays `effect` from now on, keeping every instance and its particles: emitters are
    /// matched by name (a renamed, added, removed or reordered emitter keeps the right
    /// pool), and a resized pool keeps the particles that fit. Pipelines the edit needs
    /// are built now. With batched instances, an edit that changes an emitter's pool
    /// size or state layout, or the list of emitters, restarts the instances (their
    /// shared buffers are laid out by the pools). On error nothing changes.
    pub fn set_effect(&mut self, effect: &Effect) -> Result<(), PlayerError> {
        if *effect == self.effect {
            return Ok(());
        }
        effect.validate().map_err(PlayerError::Invalid)?;
        self.snapshots.clear();
        let batched = self.settings.batch_instances && batchable(effect);
        // The pipelines the edit needs (built now; extra pipelines change nothing else).
        let update = if batched == self.batched {
            let mut update = lock(&self.update);
            for key in used_keys(effect) {
                update
                    .ensure(&self.ctx, &self.library, key)
                    .map_err(SimError::from)?;
            }
            drop(update);
            self.update.clone()
        } else {
            GpuSim::shared_update(&self.ctx, &self.library, effect, update_mode(batched))?
        };
        let same_pools = batch_shape(&self.effect) == batch_shape(effect)
            && emitter_sources(&self.effect, effect).is_none();
        if batched && self.batched && same_pools {
            self.effect = effect.clone();
            self.replace_effects();
            for b in &mut self.batches {
                b.follow(effect);
            }
            return Ok(());
        }
        if !batched && !self.batched {
            return self.edit_own(effect);
        }
        // New buffers for every instance, all made before anything changes.
        let placed: Vec<(Mat4, u32)> = self
            .instances
            .iter()
            .map(|i| (i.world_from_effect, i.effect().seed))
            .collect();
        let mut batches = Vec::new();
        let mut backings = Vec::with_capacity(placed.len());
        for (world, seed) in placed {
            let instance = Instance::effect_for(effect, world, seed);
            let backing = if batched {
                let max = self.settings.max_batch_instances;
                batch_slot(&self.ctx, &update, effect, &mut batches, (seed, max))?
            } else {
                let sim = GpuSim::with_update(
                    &self.ctx,
                    self.library.clone(),
                    update.clone(),
                    &instance,
                )?;
                Backing::Own(Box::new(sim))
            };
            backings.push(backing);
        }
        self.update = update;
        self.batches = batches;
        self.batched = batched;
        self.effect = effect.clone();
        self.replace_effects();
        for (i, b) in self.instances.iter_mut().zip(backings) {
            i.state = b;
        }
        Ok(())
    }

    /// Every instance's copy of the effect follows the player's (seed and place kept).
    fn replace_effects(&mut self) {
        for i in self.instances.iter_mut() {
            let placed = Instance::effect_for(&self.effect, i.world_from_effect, i.effect().seed);
            *i.effect_mut() = placed;
        }
    }

    /// Instances with simulations of their own follow an edit in place; if any refuses
    /// it (a device limit), every one goes back to the old effect.
    fn edit_own(&mut self, effect: &Effect) -> Result<(), PlayerError> {
        let forward = emitter_sources(&self.effect, effect);
        let back = emitter_sources(effect, &self.effect);
        let old = std::mem::replace(&mut self.effect, effect.clone());
        // How many instances took (or tried) the edit before one refused it.
        let mut touched = 0;
        let mut failure = None;
        for i in self.instances.iter_mut() {
            let (world, seed) = (i.world_from_effect, i.effect().seed);
            let (Backing::Own(sim), _) = i.state_mut() else {
                continue;
            };
            touched += 1;
            if let Some(sources) = &forward {
                sim.remap_emitters(sources);
            }
            let placed = Instance::effect_for(effect, world, seed);
            if let Err(err) = sim.sync(&placed) {
                failure = Some(err);
                break;
            }
            *i.effect_mut() = placed;
        }
        let Some(err) = failure else {
            return Ok(());
        };
        self.effect = old;
        let own = self.instances.iter_mut().filter_map(|i| {
            let world = i.world_from_effect;
            match i.parts_mut() {
                (Backing::Own(sim), placed) => Some((sim, placed, world)),
                (Backing::Batched { .. }, _) => None,
            }
        });
        for (sim, placed, world) in own.take(touched) {
            if let Some(sources) = &back {
                sim.remap_emitters(sources);
            }
            *placed = Instance::effect_for(&self.effect, world, placed.seed);
            if let Err(e) = sim.sync(placed) {
                log::error!("ignis: an instance could not go back to its effect: {e}");
            }
        }
        Err(err.into())
    }

    /// Rebuilds the pipelines built from `entry` (one of [`PLAYER_SHADERS`]) with the
    /// WGSL files in `dir`, for a host that watches its shader folder. On error the last
    /// good pipelines keep running, the particles are untouched, and the error names the
    /// file, line and column.
    pub fn reload_shader(&mut self, dir: &Path, entry: &str) -> Result<(), ShaderError> {
        let lib = ShaderLibrary::from_dir(dir);
        match entry {
            "update.wgsl" | "count.wgsl" | "events.wgsl" => {
                lock(&self.update).rebuild(&self.ctx, &lib, &used_keys(&self.effect))?;
                // The state snapshots were simulated by the old update.
                self.snapshots.clear();
            }
            "billboard.wgsl" => self.billboard.rebuild(&self.ctx, &lib)?,
            "splat.wgsl" => self.splat.rebuild(&self.ctx, &lib)?,
            "tiles.wgsl" => {
                if let Some(tiles) = &mut self.tiles {
                    tiles.rebuild(&self.ctx, &lib)?;
                }
            }
            "sort.wgsl" => self.sort.rebuild(&self.ctx, &lib)?,
            "depth_resolve.wgsl" => self.host_depth.rebuild(&self.ctx, &lib)?,
            "light.wgsl" | "light_apply.wgsl" => {
                self.light.reload(&self.ctx, &lib, &self.frame, entry)?;
            }
            "haze_apply.wgsl" => {
                if self.haze.is_some() {
                    let format = self.settings.color_format;
                    self.haze = Some(HazePass::new(&self.ctx, &lib, format)?);
                }
            }
            _ => return Ok(()),
        }
        // Pipelines built later (a new variant, an edit's new integrator) use it too.
        self.library = lib;
        Ok(())
    }

    /// Gives an instance a new seed: particles born from now on draw their randomness
    /// from it (the living ones keep theirs). Returns false if `id` was removed.
    pub fn set_seed(&mut self, id: InstanceId, seed: u32) -> bool {
        let Some(i) = self.instances.get_mut(id) else {
            return false;
        };
        if i.effect().seed != seed {
            self.snapshots.clear();
            let (state, effect) = i.parts_mut();
            effect.seed = seed;
            match state {
                Backing::Own(sim) => {
                    if let Err(err) = sim.sync(effect) {
                        log::error!("ignis: a new seed was refused: {err}");
                    }
                }
                Backing::Batched { batch, slot } => {
                    if let Some(b) = self.batches.get_mut(*batch) {
                        b.set_seed(*slot, seed);
                    }
                }
            }
        }
        true
    }

    /// Looks the preset's PNG sprites up in `dir` from now on (the folder of a preset
    /// opened from elsewhere; `None`: the working directory).
    pub fn set_asset_dir(&mut self, dir: Option<PathBuf>) {
        self.settings.asset_dir = dir;
    }

    /// The folders holding the PNG sprites in use (for a host that watches them).
    pub fn sprite_folders(&self) -> Vec<PathBuf> {
        self.frame.sprites.watched_dirs()
    }

    /// Forgets the sprites among `changed` files: they load again at the next
    /// [`Player::record`]. Returns true when any was in use.
    pub fn reload_sprites(&mut self, changed: &[PathBuf]) -> bool {
        self.frame.sprites.invalidate(changed)
    }
}

/// A slot for a new instance with `seed` in `batches` of `template`'s instances, each of
/// up to `max` instances (`(seed, max)`): one in the first batch that takes it, or in a new
/// batch when every one holds its limit (the others are not touched).
pub(super) fn batch_slot(
    ctx: &crate::gpu::GpuContext,
    update: &crate::sim::gpu_sim::SharedUpdate,
    template: &Effect,
    batches: &mut Vec<InstanceBatch>,
    (seed, max): (u32, u32),
) -> Result<Backing, PlayerError> {
    for (batch, b) in batches.iter_mut().enumerate() {
        if let Some(slot) = b.insert(seed) {
            return Ok(Backing::Batched { batch, slot });
        }
    }
    let mut b = InstanceBatch::new(ctx, update.clone(), template, max)?;
    let slot = b
        .insert(seed)
        .ok_or_else(|| SimError::Readback("a new batch is full".into()))?;
    batches.push(b);
    Ok(Backing::Batched {
        batch: batches.len() - 1,
        slot,
    })
}

/// What lays out a batch's buffers: each emitter's pool size and state layout.
fn batch_shape(effect: &Effect) -> Vec<(u32, StateLayout)> {
    effect
        .emitters
        .iter()
        .enumerate()
        .map(|(i, e)| {
            (
                e.capacity.max(1),
                Modules::in_effect(effect, i).state_layout(),
            )
        })
        .collect()
}
