//! [`Player`]: one effect's pipelines, ramps and sprites, shared by its instances, and
//! the three calls a host makes each frame — advance, record, draw.

use std::path::PathBuf;

use glam::{Mat4, Quat, Vec3};

use crate::effect::{BlendMode, Effect, TimeMode, ValidationError};
use crate::gpu::{AdapterProfile, GpuContext, Uploads};
use crate::render::billboard::{BillboardPass, DrawTarget};
use crate::render::matrix::IntoMat4;
use crate::render::sort::SortPass;
use crate::render::{Camera, DrawItem, FrameResources, Scene, SplatPass, TilePass};
use crate::runtime::device_check::{MissingLimit, missing_limits};
use crate::runtime::host_depth::HostDepth;
use crate::runtime::instances::{Backing, Instance, InstanceId, Slab};
use crate::runtime::{Layers, Resolves};
use crate::shaders::{ShaderError, ShaderLibrary};
use crate::sim::batch::{BatchMember, InstanceBatch, batchable};
use crate::sim::gpu_sim::{SharedUpdate, SimError, UpdateMode};
use crate::sim::{GpuSim, Stepper};

mod settings;
pub use settings::*;

/// Plays one effect inside a host's frame, as any number of instances.
///
/// Instances share the player's pipelines, colour ramps and sprites; each has its own
/// particles, seed and transform. All instances advance on the player's clock (the
/// preset's fixed step or the frame's delta), so a fixed-step effect is the same at any
/// frame rate. Each frame: [`Player::advance`], then [`Player::record`] into the host's
/// encoder (after the host's opaque pass when it hands over its depth for soft edges),
/// then [`Player::draw`] inside the host's render pass.
pub struct Player {
    pub(super) ctx: GpuContext,
    pub(super) effect: Effect,
    pub(super) library: ShaderLibrary,
    pub(super) update: SharedUpdate,
    pub(super) frame: FrameResources,
    pub(super) billboard: BillboardPass,
    pub(super) splat: SplatPass,
    /// The tile rasteriser, where the device's limits allow it.
    pub(super) tiles: Option<TilePass>,
    pub(super) sort: SortPass,
    pub(super) instances: Slab<Instance>,
    /// The batches of instances (when the effect can be batched; else each instance has
    /// a simulation of its own).
    pub(super) batches: Vec<InstanceBatch>,
    pub(super) batched: bool,
    pub(super) stepper: Stepper,
    pub(super) is_paused: bool,
    /// Steps planned by `advance` and not yet recorded, and their size.
    pub(super) pending: (u32, f32),
    /// The steps the last record ran, and their size.
    pub(super) last_steps: (u32, f32),
    /// Where frames are drawn between the last two steps (fixed step).
    pub(super) alpha: f32,
    pub(super) settings: PlayerSettings,
    pub(super) items: Vec<DrawItem>,
    /// This frame's parameter and look uploads (reused staging memory).
    uploads: Uploads,
    /// Whether the last record splatted light that `draw` resolves.
    splatted: bool,
    /// Whether records prepare the motion pass ([`Player::draw_motion`]).
    motion_pass: bool,
    /// The host's depth as the passes sample it.
    pub(super) host_depth: HostDepth,
    /// The instances' light, when estimated.
    pub(super) light: super::effect_light::LightEstimate,
    /// `simulate` ran since the last `record`, which then does not run it again.
    pub(super) simulated: bool,
    /// Snapshots a seek can start from (`Player::keep_seek_snapshots`).
    pub(super) snapshots: super::seeking::SeekSnapshots,
    /// Heat haze's distortion target and refraction (built on first use).
    pub(super) haze: Option<crate::render::haze::HazePass>,
    /// The frame's dispatches and draws (`Player::recorded_commands`).
    pub(super) commands: super::frame_commands::FrameCommands,
}

/// Steps one chunk of a `record` runs (the simulation's parameter ring holds this many
/// steps' blocks): a record runs as many chunks as its planned steps need, each with its
/// parameter copies recorded before its pass.
pub(super) const MAX_STEPS_PER_RECORD: u32 = 32;

impl Player {
    /// A player for `effect` on the host's device: builds its pipelines for the host's
    /// formats. No instance yet.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        effect: &Effect,
        settings: PlayerSettings,
    ) -> Result<Self, PlayerError> {
        effect.validate().map_err(PlayerError::Invalid)?;
        let missing = missing_limits(&device.limits());
        if !missing.is_empty() {
            return Err(PlayerError::DeviceLimits(missing));
        }
        // Whatever else the host's device refuses is an error, not a panic in its
        // uncaptured-error handler.
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let built = Self::build(device, queue, effect, settings);
        match pollster::block_on(scope.pop()) {
            Some(e) => Err(PlayerError::Device(e.to_string())),
            None => built,
        }
    }

    /// Builds the player's pipelines and resources ([`Player::new`] after its checks).
    fn build(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        effect: &Effect,
        settings: PlayerSettings,
    ) -> Result<Self, PlayerError> {
        let ctx = GpuContext::from_device(device, queue).with_profile(settings.adapter_profile);
        let library = match &settings.shader_dir {
            Some(dir) => ShaderLibrary::from_dir(dir),
            None => ShaderLibrary::embedded(),
        };
        let batched = settings.batch_instances && batchable(effect);
        let update = GpuSim::shared_update(&ctx, &library, effect, update_mode(batched))?;
        let frame = FrameResources::new(&ctx);
        let target = DrawTarget {
            color_format: settings.color_format,
            depth: settings.depth_format.map(|f| (f, settings.depth_compare)),
            sample_count: settings.sample_count.max(1),
        };
        let shader = |e: ShaderError| PlayerError::Sim(e.into());
        let billboard = BillboardPass::new(&ctx, &library, &frame, target).map_err(shader)?;
        let splat = SplatPass::new(&ctx, &library, &frame, target).map_err(shader)?;
        let tiles = TilePass::supported(&ctx.device)
            .then(|| TilePass::new(&ctx, &library, &frame, target))
            .transpose()
            .map_err(shader)?;
        let sort = SortPass::new(&ctx, &library).map_err(shader)?;
        Ok(Self {
            ctx,
            effect: effect.clone(),
            library,
            update,
            frame,
            billboard,
            splat,
            tiles,
            sort,
            instances: Slab::default(),
            batches: Vec::new(),
            batched,
            stepper: Stepper::default(),
            is_paused: false,
            pending: (0, 0.0),
            last_steps: (0, 0.0),
            alpha: 1.0,
            settings,
            items: Vec::new(),
            uploads: Uploads::new(device),
            splatted: false,
            motion_pass: false,
            host_depth: HostDepth::new(),
            light: Default::default(),
            simulated: false,
            snapshots: Default::default(),
            haze: None,
            commands: Default::default(),
        })
    }

    /// The effect this player plays.
    pub fn effect(&self) -> &Effect {
        &self.effect
    }

    /// The settings it draws with.
    pub fn settings(&self) -> &PlayerSettings {
        &self.settings
    }

    /// Adds an instance at `world_from_effect` (rotation and translation; scale is
    /// ignored; a `Mat4` or a column-major `[[f32; 4]; 4]`) with its own `seed`. It
    /// starts empty, at time 0 of its own. Creates only its particle buffers: no pipeline
    /// is built and no other instance is touched.
    pub fn add_instance(
        &mut self,
        world_from_effect: impl IntoMat4,
        seed: u32,
    ) -> Result<InstanceId, PlayerError> {
        let world_from_effect = self.preset_from_host(world_from_effect.into_mat4());
        let effect = Instance::effect_for(&self.effect, world_from_effect, seed);
        let state = self.backing(&effect)?;
        self.snapshots.clear();
        Ok(self
            .instances
            .insert(Instance::new(state, effect, world_from_effect)))
    }

    /// Where a new instance running `placed` (its seed and place) keeps its particles: a
    /// free batch slot (a new batch when every one is full; the others are not touched),
    /// or a simulation of its own.
    fn backing(&mut self, placed: &Effect) -> Result<Backing, PlayerError> {
        if !self.batched {
            let update = self.update.clone();
            let sim = GpuSim::with_update(&self.ctx, self.library.clone(), update, placed)?;
            return Ok(Backing::Own(Box::new(sim)));
        }
        super::editing::batch_slot(
            &self.ctx,
            &self.update,
            &self.effect,
            &mut self.batches,
            (placed.seed, self.settings.max_batch_instances),
        )
    }

    /// Removes an instance; its buffers are freed once the GPU is done with them. Returns
    /// false if `id` was already removed.
    pub fn remove_instance(&mut self, id: InstanceId) -> bool {
        let Some(instance) = self.instances.remove(id) else {
            return false;
        };
        self.snapshots.clear();
        if let Backing::Batched { batch, slot } = instance.state
            && let Some(b) = self.batches.get_mut(batch)
        {
            b.remove(slot);
        }
        true
    }

    /// Moves an instance (call it every frame for a carried torch): new particles spawn
    /// at the new place, living ones keep their world-space motion. Returns false if `id`
    /// was removed.
    pub fn set_transform(&mut self, id: InstanceId, world_from_effect: impl IntoMat4) -> bool {
        let world_from_effect = self.preset_from_host(world_from_effect.into_mat4());
        let Some(instance) = self.instances.get_mut(id) else {
            return false;
        };
        if instance.world_from_effect != world_from_effect {
            self.snapshots.clear();
        }
        instance.set_transform(&self.effect, world_from_effect);
        true
    }

    /// Where an instance is, if it exists.
    pub fn transform(&self, id: InstanceId) -> Option<Mat4> {
        let host = self.settings.host_from_preset().map(Mat4::from_quat);
        self.instances.get(id).map(|i| match host {
            Some(h) => h * i.world_from_effect * h.inverse(),
            None => i.world_from_effect,
        })
    }

    /// A host-world transform in the presets' y-up world (see
    /// [`PlayerSettings::world_up`]): the same motion seen from the turned world, so that
    /// an unrotated instance in a z-up host burns along +Z.
    fn preset_from_host(&self, host: Mat4) -> Mat4 {
        match self.settings.host_from_preset() {
            Some(q) => Mat4::from_quat(q.inverse()) * host * Mat4::from_quat(q),
            None => host,
        }
    }

    /// The host's camera seen from the presets' y-up world.
    pub(super) fn preset_camera(&self, camera: &Camera) -> Camera {
        match self.settings.host_from_preset() {
            Some(q) => camera.with_world_from(glam::DMat4::from_quat(q.as_dquat())),
            None => *camera,
        }
    }

    /// A position or direction the simulation holds (presets' y-up world) in the host's
    /// world.
    pub(super) fn to_host(&self, v: Vec3) -> Vec3 {
        self.settings.host_from_preset().map_or(v, |q| q * v)
    }

    /// How many instances there are.
    pub fn instance_count(&self) -> usize {
        self.instances.len()
    }

    /// Advances the clock by a frame of `frame_dt_secs` seconds: plans the steps the next
    /// [`Player::record`] runs (fixed steps as the preset says, or one step of the frame's
    /// delta). Nothing moves while paused.
    pub fn advance(&mut self, frame_dt_secs: f64) {
        if self.is_paused {
            return;
        }
        let plan = self.stepper.advance(frame_dt_secs, &self.effect.time);
        let dt_secs = match self.effect.time.mode {
            // Frames not yet recorded join this one's step (one step per record).
            TimeMode::FrameDelta if self.pending.0 > 0 => {
                (self.pending.1 + plan.dt_secs).min(self.effect.time.max_frame_dt_secs)
            }
            _ => plan.dt_secs,
        };
        let steps = match self.effect.time.mode {
            TimeMode::FrameDelta => plan.steps.max(self.pending.0).min(1),
            TimeMode::FixedStep => self.pending_within_cap(plan.steps),
        };
        self.pending = (steps, dt_secs);
        self.alpha = plan.alpha;
    }

    /// Plans exactly one more step for the next [`Player::record`], paused or not (a
    /// frame-by-frame look): the preset's fixed step, or a 60 Hz frame in frame-delta
    /// mode. Frames are then drawn at that step, not between two.
    pub fn step(&mut self) {
        let time = &self.effect.time;
        let dt_secs = match time.mode {
            TimeMode::FixedStep => time.step_secs,
            TimeMode::FrameDelta => time.max_frame_dt_secs.min(1.0 / 60.0),
        };
        let steps = match time.mode {
            TimeMode::FixedStep => self.pending_within_cap(1),
            TimeMode::FrameDelta => 1,
        };
        self.pending = (steps, dt_secs);
        self.alpha = 1.0;
    }

    /// The steps pending after `more` join them: at most the preset's `max_substeps` (the
    /// stepper's hitch guard; frames advanced without a record add up), the excess counted
    /// as dropped like the stepper's own.
    fn pending_within_cap(&mut self, more: u32) -> u32 {
        let wanted = u64::from(self.pending.0) + u64::from(more);
        let cap = u64::from(self.effect.time.max_substeps.max(1));
        if wanted > cap {
            self.stepper.dropped_steps += wanted - cap;
        }
        wanted.min(cap) as u32
    }

    /// Pauses or resumes the clock (a paused effect is still drawn).
    pub fn set_paused(&mut self, is_paused: bool) {
        self.is_paused = is_paused;
    }

    /// Whether the clock is paused.
    pub fn is_paused(&self) -> bool {
        self.is_paused
    }

    /// Empties every instance and starts the clock again from 0.
    pub fn restart(&mut self) {
        for instance in self.instances.iter_mut() {
            if let Backing::Own(sim) = &mut instance.state {
                sim.restart();
            }
        }
        for b in &mut self.batches {
            b.restart();
        }
        self.stepper.reset();
        self.pending = (0, 0.0);
        self.alpha = 1.0;
        self.snapshots.restarted();
    }

    /// Records this frame's compute work into the host's encoder — the planned steps of
    /// every instance, the back-to-front sort of alpha-blended layers for `camera`, and
    /// the compute splat of small additive particles — and uploads the draw's uniforms.
    /// `scene_depth` is the host's depth buffer as a single-sample view the size of the
    /// target (with `TEXTURE_BINDING` usage): soft edges fade where particles meet the
    /// host's geometry, and the splat hides particles behind it. Without it the preset's
    /// ground plane softens them, and a player with a depth format draws every particle
    /// as a billboard (the pass's depth test is then the only one). Call it once per
    /// submitted encoder (its uploads go through the queue); draw the result in as many
    /// passes as needed.
    ///
    /// The depth may be multisampled (it is then copied to one sample first) and of a
    /// depth-stencil format (its depth aspect is read); it must have the player's depth
    /// format and sample count, and the host's opaque pass must store it
    /// (`StoreOp::Store`: a discarded depth cannot be detected and hides or shows
    /// particles at random). A depth that cannot be used — no `TEXTURE_BINDING` usage, a
    /// transient attachment, another size, format or sample count — is an error,
    /// [`PlayerError::HostDepth`] naming the fix; the frame is then recorded as without
    /// a depth view, so the fire still shows.
    pub fn record(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        camera: &Camera,
        scene_depth: Option<&wgpu::TextureView>,
    ) -> Result<(), PlayerError> {
        let (depth, refused) = self.host_depth_view(encoder, camera, scene_depth);
        self.record_sampling(encoder, camera, depth.as_ref());
        refused.map_or(Ok(()), |why| Err(PlayerError::HostDepth(why)))
    }

    /// [`Player::record`] with the depth view the passes sample already made (the
    /// editor's, the export's and the composite's own targets: none).
    pub(crate) fn record_sampling(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        camera: &Camera,
        depth: Option<&wgpu::TextureView>,
    ) {
        let start = self.commands.begin(self.simulated);
        let camera = &self.preset_camera(camera);
        // This frame's depth for the steps recorded now, or (after `simulate`) for the
        // next frame's.
        self.point_depth_collision(camera, depth);
        if !std::mem::take(&mut self.simulated) {
            self.record_steps(encoder);
        }
        self.billboard.set_scene_depth(&self.ctx, depth);
        self.frame.soft_depth = depth.is_some();
        // The splat tests the host's depth itself: without the view, billboards (tested by
        // the pass's depth attachment) draw every particle.
        self.frame.allow_splat = depth.is_some() || self.settings.depth_format.is_none();
        self.frame.allow_tiles = self.tiles.is_some();
        let members: Vec<Vec<Option<BatchMember<'_>>>> = self
            .batches
            .iter()
            .map(|b| (0..b.active()).map(|slot| b.member(slot)).collect())
            .collect();
        let (groups, ids) = Self::draw_groups(&self.instances, &members, camera);
        // Who each look slot measures: only for the light estimate, when it reads back.
        let owners = match self.light.reads_back() {
            true => super::effect_light::light_owners(&groups, &ids),
            false => Vec::new(),
        };
        let groups: Vec<&[Option<Scene<'_>>]> = groups.iter().map(Vec::as_slice).collect();
        self.items = self.frame.prepare(
            &self.ctx,
            &groups,
            camera,
            self.alpha,
            &mut self.sort,
            self.settings.asset_dir.as_deref(),
        );
        self.frame.upload_looks(&mut self.uploads, encoder);
        // The effect's light: read back for the estimate, and handed to lit layers on the
        // GPU before they are drawn.
        let light = super::effect_light::LightFrame {
            ctx: &self.ctx,
            library: &self.library,
            frame: &self.frame,
            items: &self.items,
            host: self.settings.host_from_preset(),
        };
        self.light
            .record(&light, encoder, &mut self.uploads, &owners);
        self.sort
            .record_items(&self.ctx, (encoder, &mut self.uploads), &self.items, camera);
        self.splatted = self.splat.splat(
            &self.ctx,
            encoder,
            &self.frame,
            &self.items,
            camera.size_px(),
            depth,
        );
        let tiled = self.tiles.as_mut().is_some_and(|t| {
            t.record(
                &self.ctx,
                (&mut *encoder, &mut self.uploads),
                &self.frame,
                &self.items,
                camera.size_px(),
                depth,
            )
        });
        if !tiled {
            // A target larger than the tiles' bins (7680×4320): billboards draw them.
            for d in &mut self.items {
                d.tiles = false;
            }
        }
        self.billboard.prepare(
            &self.ctx,
            &self.items,
            &self.frame.sprites.sampler,
            self.motion_pass,
        );
        drop(groups);
        drop(members);
        self.uploads.finish(encoder);
        self.commands.add_since(start);
    }

    /// The groups of instances drawn together, far to near by their mean depth along
    /// the view (a far group's smoke lies under a nearer group's): each batch is one
    /// group (its members by segment; one sort orders their smoke together), each
    /// instance with a simulation of its own another.
    #[allow(clippy::type_complexity)]
    fn draw_groups<'a>(
        instances: &'a Slab<Instance>,
        members: &'a [Vec<Option<BatchMember<'a>>>],
        camera: &Camera,
    ) -> (Vec<Vec<Option<Scene<'a>>>>, Vec<Vec<Option<InstanceId>>>) {
        let (eye, forward) = (camera.eye_f64(), camera.forward().as_dvec3());
        let depth =
            |i: &Instance| (i.world_from_effect.w_axis.truncate().as_dvec3() - eye).dot(forward);
        type Member<'a> = Option<(InstanceId, Scene<'a>)>;
        let mut groups: Vec<(f64, Vec<Member<'a>>)> =
            members.iter().map(|m| (0.0, vec![None; m.len()])).collect();
        let mut counts = vec![0u32; groups.len()];
        for (id, i) in instances.iter_with_ids() {
            match &i.state {
                Backing::Own(sim) => groups.push((
                    depth(i),
                    vec![Some((
                        id,
                        Scene {
                            sim: sim.as_ref(),
                            effect: i.effect(),
                        },
                    ))],
                )),
                Backing::Batched { batch, slot } => {
                    let (Some(g), Some(Some(m))) = (
                        groups.get_mut(*batch),
                        members.get(*batch).and_then(|m| m.get(*slot as usize)),
                    ) else {
                        continue;
                    };
                    g.0 += depth(i);
                    counts[*batch] += 1;
                    if let Some(s) = g.1.get_mut(*slot as usize) {
                        *s = Some((
                            id,
                            Scene {
                                sim: m,
                                effect: i.effect(),
                            },
                        ));
                    }
                }
            }
        }
        for (g, n) in groups.iter_mut().zip(&counts) {
            g.0 /= f64::from((*n).max(1));
        }
        groups.retain(|g| g.1.iter().any(Option::is_some));
        groups.sort_by(|a, b| b.0.total_cmp(&a.0));
        groups
            .into_iter()
            .map(|(_, g)| {
                let ids = g.iter().map(|m| m.as_ref().map(|(id, _)| *id)).collect();
                (g.into_iter().map(|m| m.map(|(_, s)| s)).collect(), ids)
            })
            .unzip()
    }

    /// Records only the steps [`Player::advance`] planned for every instance, with no sort
    /// or draw preparation: for a frame that steps without drawing (a hidden window, a
    /// warm-up), or to time the update on its own. [`Player::record`] does this first
    /// unless it was called since the last record.
    pub fn simulate(&mut self, encoder: &mut wgpu::CommandEncoder) {
        let start = self.commands.begin(self.simulated);
        self.record_steps(encoder);
        self.uploads.finish(encoder);
        self.commands.add_since(start);
        self.simulated = true;
    }

    /// Records the planned steps of every instance into `encoder`.
    fn record_steps(&mut self, encoder: &mut wgpu::CommandEncoder) {
        // New instances' segments are cleared before any step of this record.
        for batch in &mut self.batches {
            batch.settle_taken(encoder);
        }
        let (steps, dt_secs) = std::mem::take(&mut self.pending);
        self.last_steps = (steps, dt_secs);
        if steps == 0 {
            return;
        }
        encoder.push_debug_group("ignis: update particles");
        // Batches in chunks of the parameter ring's size (each chunk's copies precede its
        // pass); instances with a simulation of their own take every step at once (they
        // chunk their own ring).
        let mut pass = None;
        let mut left = steps;
        while left > 0 {
            let chunk = left.min(MAX_STEPS_PER_RECORD);
            drop(pass.take());
            self.record_batches(encoder, &mut pass, chunk, dt_secs);
            left -= chunk;
        }
        for instance in self.instances.iter_mut() {
            let (Backing::Own(sim), effect) = instance.state_mut() else {
                continue;
            };
            let plans = sim.plan(effect, dt_secs, steps as usize);
            sim.record_into(encoder, &mut pass, effect, &plans);
        }
        drop(pass);
        encoder.pop_debug_group();
        self.take_snapshot_if_due(encoder);
    }

    /// Records `steps` (at most [`MAX_STEPS_PER_RECORD`]) steps of `dt_secs` of every
    /// batch: their parameter blocks' copies, then their dispatches in `pass` (opened on
    /// first need).
    fn record_batches(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        pass: &mut Option<wgpu::ComputePass<'static>>,
        steps: u32,
        dt_secs: f32,
    ) {
        // Every batch's parameter blocks first (their copies precede the pass).
        let mut effects: Vec<Option<(&Effect, u64)>> = Vec::new();
        for (b, batch) in self.batches.iter_mut().enumerate() {
            effects.clear();
            effects.resize(batch.slot_count() as usize, None);
            for i in self.instances.iter() {
                if let Backing::Batched { batch, slot } = i.state
                    && batch == b
                    && let Some(e) = effects.get_mut(slot as usize)
                {
                    *e = Some(i.revised_effect());
                }
            }
            batch.plan(
                &mut self.uploads,
                encoder,
                &effects,
                dt_secs,
                steps as usize,
            );
        }
        for batch in &mut self.batches {
            batch.dispatch(encoder, pass, &self.effect);
        }
    }

    /// Draws every instance's particles into the host's open render pass (alpha-blended
    /// layers first, then the additive light), as last recorded. The pass must have the
    /// colour format, depth format and sample count of the player's settings; its depth
    /// attachment must be read-only (`depth_ops: None`) when the depth is also handed to
    /// [`Player::record`] for soft edges.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>) {
        self.draw_layers(pass, Layers::ALL);
    }

    /// Draws the `layers` of every instance's particles into the host's open render pass
    /// (as [`Player::draw`]): a host can send the soft layers to reduced-resolution
    /// targets of its own and draw the rest at full resolution.
    pub fn draw_layers(&self, pass: &mut wgpu::RenderPass<'_>, layers: Layers) {
        // Alpha-blended billboards, then the tiles (alpha-blended layers are drawn by
        // one path or the other, never both), then the light.
        self.draw_under_tiles(pass, layers);
        self.draw_over_tiles(pass, layers, Resolves::DRAWN);
    }

    /// What [`Player::draw_layers`] draws before the tiles: the alpha-blended billboards
    /// of `layers`.
    pub(crate) fn draw_under_tiles(&self, pass: &mut wgpu::RenderPass<'_>, layers: Layers) {
        let start = crate::gpu::commands::recorded();
        self.billboard
            .draw(pass, &self.frame, &self.items, |d| under_tiles(d, layers));
        self.commands.add_draws_since(start);
    }

    /// Whether [`Player::draw_under_tiles`] draws anything for `layers`.
    pub(crate) fn draws_under_tiles(&self, layers: Layers) -> bool {
        self.items
            .iter()
            .any(|d| d.is_billboard() && under_tiles(d, layers))
    }

    /// The rest of [`Player::draw_layers`]: the tiles, the additive billboards and the
    /// splat's light (the resolves `drawn` says are drawn; the others are resolved by
    /// compute).
    pub(crate) fn draw_over_tiles(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        layers: Layers,
        drawn: Resolves,
    ) {
        let start = crate::gpu::commands::recorded();
        if let Some(t) = self
            .tiles
            .as_ref()
            .filter(|_| drawn.tiles && layers.contains(Layers::LIGHT))
        {
            t.resolve(pass, &self.frame);
        }
        self.billboard.draw(pass, &self.frame, &self.items, |d| {
            d.blend == BlendMode::Additive && layers.contains(Layers::of(d))
        });
        if self.splatted && drawn.splat && layers.contains(Layers::LIGHT) {
            self.splat.resolve(pass, &self.frame);
        }
        self.commands.add_draws_since(start);
    }

    /// Whether [`Player::resolve_splat_into`] resolves into a target of `size` pixels.
    pub(crate) fn splat_resolvable_into(&self, size: (u32, u32)) -> bool {
        self.splatted && self.splat.can_resolve_into(size)
    }

    /// Adds the last record's splatted light into `target` (an HDR image of `size` pixels
    /// with storage usage) by compute, after [`Player::draw_over_tiles`] drew the rest;
    /// false where it cannot (nothing recorded).
    pub(crate) fn resolve_splat_into(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        size: (u32, u32),
    ) -> bool {
        let start = crate::gpu::commands::recorded();
        let resolved = self.splatted
            && self
                .splat
                .resolve_into(&self.ctx, enc, &self.frame, target, size);
        self.commands.add_since(start);
        resolved
    }

    /// Whether [`Player::resolve_tiles_into`] resolves into a target of `size` pixels.
    pub(crate) fn tiles_resolvable_into(&self, size: (u32, u32)) -> bool {
        self.tiles
            .as_ref()
            .is_some_and(|t| t.can_resolve_into(size))
    }

    /// Resolves the last record's tiles into `target` (an HDR image of `size` pixels with
    /// storage usage) by compute, between [`Player::draw_under_tiles`] and
    /// [`Player::draw_over_tiles`]; false where it cannot (nothing recorded).
    pub(crate) fn resolve_tiles_into(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        size: (u32, u32),
    ) -> bool {
        let Some(tiles) = self.tiles.as_mut() else {
            return false;
        };
        let start = crate::gpu::commands::recorded();
        let resolved = tiles.resolve_into(&self.ctx, enc, &self.frame, target, size);
        self.commands.add_since(start);
        resolved
    }

    /// Prepares the motion pass from the next [`Player::record`] on (the export's
    /// motion vectors; billboards only: splatted particles have none).
    #[doc(hidden)]
    pub fn set_motion_pass(&mut self, on: bool) {
        self.motion_pass = on;
    }

    /// Draws the motion pass of every billboard, as last recorded, into an open pass
    /// whose colour target was cleared to zero: per pixel (Σ w·motion, 0, Σ w), with
    /// motion in pixels over the camera's motion interval
    /// ([`Camera::with_motion_secs`]) and `w` each particle's visible weight.
    #[doc(hidden)]
    pub fn draw_motion(&self, pass: &mut wgpu::RenderPass<'_>) {
        if self.motion_pass {
            self.billboard.draw_motion(pass, &self.frame, &self.items);
        }
    }

    /// The layers that hold particles to draw, as last recorded.
    pub fn drawn_layers(&self) -> Layers {
        let mut layers = Layers::NONE;
        for d in self
            .items
            .iter()
            .filter(|d| d.is_billboard() && !d.variant.haze)
        {
            layers |= Layers::of(d);
        }
        if self.splatted || self.tiles.as_ref().is_some_and(TilePass::drawn) {
            layers |= Layers::LIGHT;
        }
        layers
    }
}

/// The update pipelines' specialisation for a player. Nobody reads alive counts every
/// frame here: the update need not count them (they are counted on demand).
pub(super) fn update_mode(batched: bool) -> UpdateMode {
    if batched {
        UpdateMode::Batched
    } else {
        UpdateMode::Uncounted
    }
}

/// Whether `d`, when a billboard, is drawn before the tiles in `layers`: the
/// alpha-blended layers (the tiles' blended layers go over them).
fn under_tiles(d: &DrawItem, layers: Layers) -> bool {
    d.blend == BlendMode::Alpha && layers.contains(Layers::of(d))
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_player_can_move_to_another_thread() {
        fn send<T: Send>() {}
        send::<super::Player>();
        send::<super::InstanceId>();
    }
}
