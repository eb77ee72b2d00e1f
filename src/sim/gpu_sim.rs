//! Pass 1 on the GPU: per-emitter ping-pong state buffers and the update pipeline.

use std::collections::VecDeque;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

use crate::effect::{CURVE_WIDTH, Effect, rows_key};
use crate::gpu::types::{
    Birth, PARAMS_STRIDE, PackedParticle, Particle, SimParams, StateLayout, double_single,
    slot_counter, tiny_decode,
};
use crate::gpu::{GpuContext, GpuError};
use crate::shaders::{ShaderError, ShaderLibrary};
use crate::sim::depth_collision::{DepthCollider, HostDepthView};
use crate::sim::event_scan::{EventHeader, ScanConfig, scan_flags};
use crate::sim::hooks::EmitterHooks;
use crate::sim::modules::Modules;
use crate::sim::planner::{EffectPlanner, LiveWindow};

mod recording;
mod state_readback;

pub use super::sim_state::{EmitterBuffers, SimState, TrailRing};
pub(crate) use super::update_pass::lock;
use super::update_pass::update_counts;
pub use super::update_pass::{SharedUpdate, UpdateMode, UpdatePass, pipeline_key, used_keys};
pub use state_readback::{map_read, read_buffer};

/// Steps recorded per submission (the per-step params blocks live side by side).
const STEPS_PER_SUBMIT: usize = 32;

/// Simulation failures.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// A shader failed to compose, validate or build.
    #[error(transparent)]
    Shader(#[from] ShaderError),
    /// A device limit.
    #[error(transparent)]
    Gpu(#[from] GpuError),
    /// Reading back from the GPU failed.
    #[error("GPU readback failed: {0}")]
    Readback(String),
}

/// One emitter's pool on the GPU.
pub(super) struct EmitterState {
    pub(super) capacity: u32,
    pub(super) buffers: [wgpu::Buffer; 2],
    pub(super) counters: wgpu::Buffer,
    pub(super) bind_groups: [wgpu::BindGroup; 2],
    /// Which buffer holds the current state (the thesis's `mFlip`).
    pub(super) current: usize,
    pub(super) generation: u64,
    /// Holds stateless spawn records (no ping-pong: buffer 0 only).
    pub(super) stateless: bool,
    /// How the state is stored.
    pub(super) layout: StateLayout,
    /// Tiny state's birth table: a ring of entries, entry `seq` at `seq & births_mask`
    /// (one placeholder entry for the other layouts).
    pub(super) births: wgpu::Buffer,
    pub(super) births_mask: u32,
    /// The emitter's over-life curves baked (`Modules::CURVES`), and what they hold.
    pub(super) curves: wgpu::Buffer,
    pub(super) curves_key: Option<u64>,
    /// The entries the steps recorded last may read (sequence number, entry), oldest
    /// first: what a larger table must be filled with.
    pub(super) births_mirror: VecDeque<(u64, Birth)>,
    /// Lifetime range, seed and salt of the last sync (packed state re-derives lifetimes).
    pub(super) life_range: (f32, f32),
    pub(super) seed: u32,
    pub(super) salt: u32,
    /// Until this time on the emitter's planner clock every slot may be alive, and the
    /// update and the draws visit the whole pool: state written from outside the planner
    /// (`write_particles`: forever, until a restart), or particles kept at their old slots
    /// by a capacity change (until they have all died).
    pub(super) whole_pool_until: f64,
    /// The spawn counter after the last recorded step (equal to the planner's when the
    /// steps came from it; otherwise the live window is unknown).
    pub(super) spawned_end: u64,
    /// Event records (a parent) and spawn list (a child).
    pub(super) hooks: Option<EmitterHooks>,
    /// Spawns from other emitters' events: the GPU fills the ring, so the planner cannot
    /// know its live window and every slot is visited.
    pub(super) gpu_fed: bool,
    /// Group 2 of an emitter with depth collision.
    pub(super) depth: Option<DepthCollider>,
}

impl EmitterState {
    /// Writes birth-table entry `seq` at its place in the ring (`seq & births_mask`),
    /// through `queue` (before the next submission's steps read it).
    pub(super) fn write_birth(&self, queue: &wgpu::Queue, seq: u64, entry: &Birth) {
        let at = (seq & u64::from(self.births_mask)) * size_of::<Birth>() as u64;
        queue.write_buffer(&self.births, at, bytemuck::bytes_of(entry));
    }
}

/// A buffer for an emitter's baked over-life curves (rows A and B, [`CURVE_WIDTH`]
/// texels of four f32 each; see `shaders/curves.wgsl`).
pub(crate) fn over_life_buffer(device: &wgpu::Device) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("over_life_curves"),
        size: 2 * u64::from(CURVE_WIDTH) * 16,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// Bakes and uploads `e`'s over-life curves into `buffer` when they differ from what
/// `key` says it holds.
pub(crate) fn upload_over_life(
    queue: &wgpu::Queue,
    buffer: &wgpu::Buffer,
    key: &mut Option<u64>,
    e: &crate::effect::Emitter,
) {
    let k = rows_key(&crate::sim::modules::over_life_params(e));
    if *key == Some(k) {
        return;
    }
    let [a, b] = crate::sim::modules::bake_over_life(e);
    queue.write_buffer(buffer, 0, bytemuck::cast_slice(&a));
    queue.write_buffer(
        buffer,
        16 * u64::from(CURVE_WIDTH),
        bytemuck::cast_slice(&b),
    );
    *key = Some(k);
}

/// The spawn counter and lifetime of `slot` in a ring of `capacity` slots after `total`
/// spawns (packed and tiny state re-derive lifetimes rather than store them).
pub(crate) fn packed_life(
    capacity: u32,
    total: u64,
    (seed, salt): (u32, u32),
    life_range: (f32, f32),
    slot: u32,
) -> (u64, f32) {
    let c = slot_counter(slot, total, capacity);
    let key = crate::rng::spawn_key(seed, salt, slot, c);
    let r = crate::rng::unorm4(crate::rng::rand_block(key, 1))[3];
    (c, crate::sim::planner::mix(life_range.0, life_range.1, r))
}

/// Buffer generations, unique in the process: the draws' bind-group caches key on them,
/// and several simulations (a player's instances) share one cache.
static NEXT_GENERATION: AtomicU64 = AtomicU64::new(1);

/// A generation no pool has had.
pub(crate) fn next_generation() -> u64 {
    NEXT_GENERATION.fetch_add(1, Ordering::Relaxed)
}

/// The GPU simulation of an effect.
pub struct GpuSim {
    pub(super) ctx: GpuContext,
    library: ShaderLibrary,
    update: SharedUpdate,
    params_buffer: wgpu::Buffer,
    params_slots: usize,
    /// The blocks of a record's chunks after the first (copied into the params ring by the
    /// encoder before each chunk's steps); grown as needed, kept between records.
    later_chunks: Option<wgpu::Buffer>,
    pub(super) emitters: Vec<EmitterState>,
    /// CPU planning (time, spawn counts).
    pub planner: EffectPlanner,
    /// The host's depth the next record's steps collide with (emitters with depth
    /// collision; none: they fly on).
    host_depth: Option<HostDepthView>,
}

impl SimState for GpuSim {
    fn emitter_buffers(&self, index: usize) -> Option<EmitterBuffers<'_>> {
        GpuSim::emitter_buffers(self, index)
    }

    fn planner(&self) -> &EffectPlanner {
        &self.planner
    }
}

impl GpuSim {
    /// Creates buffers for every emitter of `effect` and the pipelines it uses.
    pub fn new(
        ctx: &GpuContext,
        library: ShaderLibrary,
        effect: &Effect,
    ) -> Result<Self, SimError> {
        let update = Self::shared_update(ctx, &library, effect, UpdateMode::Counted)?;
        Self::with_update(ctx, library, update, effect)
    }

    /// The update pipelines `effect` needs in `mode`, built once to be shared by the
    /// simulations of its instances ([`GpuSim::with_update`], or batched in an
    /// [`crate::sim::batch::InstanceBatch`]).
    pub fn shared_update(
        ctx: &GpuContext,
        library: &ShaderLibrary,
        effect: &Effect,
        mode: UpdateMode,
    ) -> Result<SharedUpdate, SimError> {
        let mut update = UpdatePass::new(ctx, mode);
        update.rebuild(ctx, library, &used_keys(effect))?;
        Ok(Arc::new(Mutex::new(update)))
    }

    /// A simulation of `effect` on shared update pipelines: only its buffers are created.
    pub fn with_update(
        ctx: &GpuContext,
        library: ShaderLibrary,
        update: SharedUpdate,
        effect: &Effect,
    ) -> Result<Self, SimError> {
        let mut sim = Self {
            ctx: ctx.clone(),
            library,
            update,
            params_buffer: ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("GpuSim::params"),
                size: PARAMS_STRIDE,
                usage: wgpu::BufferUsages::UNIFORM
                    | wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            params_slots: 1,
            later_chunks: None,
            emitters: Vec::new(),
            planner: EffectPlanner::default(),
            host_depth: None,
        };
        sim.sync(effect)?;
        Ok(sim)
    }

    /// The host's depth (and the camera that drew it) the next record's steps collide
    /// with, for emitters with depth collision; `None`: they fly on.
    pub fn set_host_depth(&mut self, host: Option<HostDepthView>) {
        self.host_depth = host;
    }

    /// The shader library in use.
    pub fn library(&self) -> &ShaderLibrary {
        &self.library
    }

    /// Files the update pipelines depend on.
    pub fn shader_files(&self) -> Vec<String> {
        lock(&self.update).files.clone()
    }

    /// Rebuilds the update pipelines from `library`; the particles are untouched, and on
    /// error the last good pipelines keep running.
    pub fn reload_shaders(
        &mut self,
        library: ShaderLibrary,
        effect: &Effect,
    ) -> Result<(), ShaderError> {
        lock(&self.update).rebuild(&self.ctx, &library, &used_keys(effect))?;
        self.library = library;
        Ok(())
    }

    /// Matches the GPU pools to the effect: new emitters get buffers, removed ones are
    /// dropped, a changed capacity keeps the particles that fit (a tiny-state pool, and
    /// any pool whose layout changes, restarts empty).
    pub fn sync(&mut self, effect: &Effect) -> Result<(), SimError> {
        self.check_limits(effect)?;
        self.sync_pools(effect);
        self.sync_settings(effect);
        let grown = self.grow_params(effect);
        for key in used_keys(effect) {
            lock(&self.update).ensure(&self.ctx, &self.library, key)?;
        }
        self.sync_events(effect, grown);
        Ok(())
    }

    /// Refuses capacities, event records and trail rings the device cannot hold, naming
    /// the emitter.
    fn check_limits(&self, effect: &Effect) -> Result<(), SimError> {
        for e in &effect.emitters {
            self.ctx.check_capacity(&e.name, e.capacity)?;
            if !e.events.is_empty() {
                let bytes = super::hooks::record_bytes();
                self.ctx.check_events(&e.name, e.capacity.max(1), bytes)?;
            }
            if let Some(t) = &e.look.trail {
                let points = t.layout(effect.time.nominal_step_secs()).points;
                let bytes = super::trails::ring_bytes(e.capacity.max(1), points);
                self.ctx
                    .check_trail(&e.name, (e.capacity.max(1), points), bytes)?;
            }
        }
        Ok(())
    }

    /// One pool per emitter, of its capacity and state layout.
    fn sync_pools(&mut self, effect: &Effect) {
        self.emitters.truncate(effect.emitters.len());
        for (i, e) in effect.emitters.iter().enumerate() {
            let capacity = e.capacity.max(1);
            let layout = Modules::in_effect(effect, i).state_layout();
            match self.emitters.get(i) {
                Some(s) if s.capacity == capacity && s.layout == layout => {}
                // Switching the layout restarts the pool (nothing to convert in place), and
                // so does resizing a tiny pool (its particles' ages are tied to their
                // slots' spawn counters, which a new modulus changes).
                Some(s) if s.layout != layout || layout == StateLayout::Tiny => {
                    self.emitters[i] = self.create_state(capacity, layout);
                    // The new pool is empty: no batch before it can be alive in it.
                    if let Some(p) = self.planner.emitters.get_mut(i) {
                        p.forget_births();
                    }
                }
                _ => {
                    let fresh = self.create_state(capacity, layout);
                    self.keep_particles(i, e, fresh);
                }
            }
        }
    }

    /// Puts `fresh`, emitter `i`'s resized pool, in place of its old one, keeping the
    /// particles that fit.
    fn keep_particles(&mut self, i: usize, e: &crate::effect::Emitter, mut fresh: EmitterState) {
        if let Some(old) = self.emitters.get(i) {
            // The kept particles stay at their old slots, which the ring's
            // new modulus does not map their spawn counters to: visit the
            // whole pool until they have all died.
            let dead_by = self
                .planner
                .emitters
                .get(i)
                .map_or(f64::INFINITY, |p| p.all_dead_by(e.lifetime_secs.max));
            fresh.whole_pool_until = old.whole_pool_until.max(dead_by);
            // Keep the particles that fit (packed ones get the lifetimes of
            // their new ring positions).
            let keep = fresh.layout.bytes(old.capacity.min(fresh.capacity));
            let mut enc = self.ctx.device.create_command_encoder(&Default::default());
            for b in 0..2 {
                enc.copy_buffer_to_buffer(&old.buffers[old.current], 0, &fresh.buffers[b], 0, keep);
            }
            self.ctx.queue.submit([enc.finish()]);
            self.emitters[i] = fresh;
        } else {
            self.emitters.push(fresh);
        }
    }

    /// Each pool's per-frame settings: lifetimes, seed, curves, stateless mode.
    fn sync_settings(&mut self, effect: &Effect) {
        // Switching an emitter between stateless records and stateful particles restarts
        // its pool: the two layouts mean different things.
        // Created only when a pool must be cleared (this runs every frame).
        let mut enc: Option<wgpu::CommandEncoder> = None;
        for (i, (s, e)) in self.emitters.iter_mut().zip(&effect.emitters).enumerate() {
            s.life_range = (e.lifetime_secs.min, e.lifetime_secs.max);
            s.seed = effect.seed;
            s.salt = crate::rng::emitter_salt(i as u32, e.seed_offset);
            let modules = Modules::in_effect(effect, i);
            s.gpu_fed = modules.contains(Modules::EVENT_SPAWN);
            if modules.contains(Modules::DEPTH_COLLISION) != s.depth.is_some() {
                s.depth = modules
                    .contains(Modules::DEPTH_COLLISION)
                    .then(|| DepthCollider::new(&self.ctx, &lock(&self.update).depth_layout));
            }
            if modules.contains(Modules::CURVES) {
                upload_over_life(&self.ctx.queue, &s.curves, &mut s.curves_key, e);
            }
            let stateless = modules.contains(Modules::STATELESS);
            if s.stateless != stateless {
                let enc = enc.get_or_insert_with(|| {
                    self.ctx.device.create_command_encoder(&Default::default())
                });
                for b in &s.buffers {
                    enc.clear_buffer(b, 0, None);
                }
                s.current = 0;
                s.stateless = stateless;
            }
        }
        if let Some(enc) = enc {
            self.ctx.queue.submit([enc.finish()]);
        }
    }

    /// Grows the parameter buffer to one slot per emitter and step of a submit; returns
    /// whether it grew (every pool's groups rebound).
    fn grow_params(&mut self, effect: &Effect) -> bool {
        let slots = STEPS_PER_SUBMIT * effect.emitters.len().max(1);
        let grown = slots > self.params_slots;
        if grown {
            self.params_slots = slots;
            self.params_buffer = self.ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("GpuSim::params"),
                size: slots as u64 * PARAMS_STRIDE,
                usage: wgpu::BufferUsages::UNIFORM
                    | wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            for i in 0..self.emitters.len() {
                let s = &self.emitters[i];
                self.emitters[i].bind_groups =
                    self.bind_groups(&s.buffers, &s.counters, &s.births, &s.curves);
            }
        }
        grown
    }

    /// Matches the event buffers to the effect's events (kept while they fit), and binds
    /// each parent's scans to its children's lists.
    fn sync_events(&mut self, effect: &Effect, rebind: bool) {
        let update = Arc::clone(&self.update);
        let update = lock(&update);
        let mut changed = rebind;
        for i in 0..self.emitters.len() {
            let capacity = self.emitters[i].capacity;
            let old = self.emitters[i].hooks.take();
            let was = old.as_ref().map(|o| o.hooks.clone());
            let fresh = EmitterHooks::sync(&self.ctx, &update.hooks, effect, i, capacity, old);
            changed |= fresh.as_ref().map(|f| &f.hooks) != was.as_ref();
            self.emitters[i].hooks = fresh;
        }
        if !changed {
            return;
        }
        let lists: Vec<Option<wgpu::Buffer>> = self
            .emitters
            .iter()
            .map(|s| s.hooks.as_ref().and_then(|ev| ev.list.clone()))
            .collect();
        let ribbons: Vec<Option<wgpu::Buffer>> = effect
            .emitters
            .iter()
            .zip(&self.emitters)
            .map(|(e, s)| {
                s.hooks
                    .as_ref()
                    .and_then(|ev| ev.trail.clone())
                    .filter(|_| e.look.ribbon_per_parent())
            })
            .collect();
        for s in &mut self.emitters {
            if let Some(ev) = &mut s.hooks {
                ev.bind_scans(
                    &self.ctx.device,
                    &update.hooks,
                    &self.params_buffer,
                    &lists,
                    &ribbons,
                );
            }
        }
    }

    fn create_state(&mut self, capacity: u32, layout: StateLayout) -> EmitterState {
        // At least one full `Particle`: the full-state bindings see the same buffer.
        let size = layout.bytes(capacity).max(size_of::<Particle>() as u64);
        let make = |label| {
            self.ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_SRC
                    | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let buffers = [make("GpuSim::state_a"), make("GpuSim::state_b")];
        let counters = self.ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("GpuSim::counters"),
            size: 8,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_SRC
                | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let entries = if layout == StateLayout::Tiny { 1024 } else { 1 };
        let births = self.births_buffer(entries);
        let curves = over_life_buffer(&self.ctx.device);
        let bind_groups = self.bind_groups(&buffers, &counters, &births, &curves);
        let generation = next_generation();
        EmitterState {
            capacity,
            buffers,
            counters,
            bind_groups,
            current: 0,
            generation,
            stateless: false,
            layout,
            births,
            births_mask: entries - 1,
            curves,
            curves_key: None,
            births_mirror: VecDeque::new(),
            life_range: (0.0, 0.0),
            seed: 0,
            salt: 0,
            whole_pool_until: f64::NEG_INFINITY,
            spawned_end: 0,
            hooks: None,
            gpu_fed: false,
            depth: None,
        }
    }

    fn births_buffer(&self, entries: u32) -> wgpu::Buffer {
        self.ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("GpuSim::births"),
            size: u64::from(entries) * size_of::<Birth>() as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        })
    }

    fn bind_groups(
        &self,
        buffers: &[wgpu::Buffer; 2],
        counters: &wgpu::Buffer,
        births: &wgpu::Buffer,
        curves: &wgpu::Buffer,
    ) -> [wgpu::BindGroup; 2] {
        let layout = lock(&self.update).layout.clone();
        let make = |src: usize| {
            self.ctx
                .device
                .create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("GpuSim::bind_group"),
                    layout: &layout,
                    entries: &[
                        wgpu::BindGroupEntry {
                            binding: 0,
                            resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                                buffer: &self.params_buffer,
                                offset: 0,
                                size: wgpu::BufferSize::new(size_of::<SimParams>() as u64),
                            }),
                        },
                        wgpu::BindGroupEntry {
                            binding: 1,
                            resource: buffers[src].as_entire_binding(),
                        },
                        wgpu::BindGroupEntry {
                            binding: 2,
                            resource: buffers[1 - src].as_entire_binding(),
                        },
                        wgpu::BindGroupEntry {
                            binding: 3,
                            resource: counters.as_entire_binding(),
                        },
                        wgpu::BindGroupEntry {
                            binding: 4,
                            resource: births.as_entire_binding(),
                        },
                        wgpu::BindGroupEntry {
                            binding: 5,
                            resource: curves.as_entire_binding(),
                        },
                    ],
                })
        };
        [make(0), make(1)]
    }

    /// Follows a structural edit of the effect's emitter list (reorder, insert, remove):
    /// `sources[new] = Some(old)` moves pool `old` (its particles and spawn accounting) to
    /// position `new`; `None` starts an empty pool there. Pools no source names are
    /// dropped. Call it before the next [`GpuSim::step`] with the edited effect, which then
    /// sizes the new pools.
    pub fn remap_emitters(&mut self, sources: &[Option<usize>]) {
        let mut old_pools: Vec<Option<EmitterState>> = std::mem::take(&mut self.emitters)
            .into_iter()
            .map(Some)
            .collect();
        let mut old_planners: Vec<Option<crate::sim::EmitterPlanner>> =
            std::mem::take(&mut self.planner.emitters)
                .into_iter()
                .map(Some)
                .collect();
        for source in sources {
            let pool = source
                .and_then(|o| old_pools.get_mut(o))
                .and_then(Option::take);
            // A one-slot placeholder: `sync` sees the capacity differ and replaces it.
            let pool = pool.unwrap_or_else(|| self.create_state(1, StateLayout::Full));
            self.emitters.push(pool);
            let planner = source
                .and_then(|o| old_planners.get_mut(o))
                .and_then(Option::take)
                .unwrap_or_default();
            self.planner.emitters.push(planner);
        }
    }

    /// Buffers of emitter `index` for drawing.
    pub fn emitter_buffers(&self, index: usize) -> Option<EmitterBuffers<'_>> {
        let planner = self.planner.emitters.get(index);
        self.emitters.get(index).map(|s| EmitterBuffers {
            previous: &s.buffers[1 - s.current],
            current: &s.buffers[s.current],
            capacity: s.capacity,
            generation: s.generation,
            parity: s.current,
            layout: s.layout,
            births: &s.births,
            tiny: planner.map_or([[0; 4]; 3], |p| {
                let (hi, lo) = double_single(p.clock_secs());
                let (first, len) = p.birth_window();
                let (oldest, span, prev_span) = p.birth_span_now();
                let dt_bits = (p.last_dt_secs() as f32).to_bits();
                [
                    [hi.to_bits(), lo.to_bits(), first as u32, len],
                    [s.births_mask, dt_bits, oldest, span],
                    [prev_span, 0, 0, 0],
                ]
            }),
            spawned_total: planner.map_or(0, |p| p.spawned_total()),
            life_range: s.life_range,
            seed_salt: (s.seed, s.salt),
            window: match planner {
                Some(p)
                    if !s.gpu_fed
                        && p.clock_secs() >= s.whole_pool_until
                        && p.spawned_total() == s.spawned_end =>
                {
                    p.live_window(s.capacity, s.life_range.1)
                }
                _ => LiveWindow::all(s.capacity),
            },
            slot_base: 0,
            trail: s.hooks.as_ref().and_then(|ev| ev.trail.as_ref()),
            last_step: self.planner.step_index.saturating_sub(1) as u32,
        })
    }

    /// Number of emitter pools.
    pub fn emitter_count(&self) -> usize {
        self.emitters.len()
    }

    /// Kills every particle and restarts time (keeps the pipelines).
    pub fn restart(&mut self) {
        let mut enc = self.ctx.device.create_command_encoder(&Default::default());
        for s in &mut self.emitters {
            for b in &s.buffers {
                enc.clear_buffer(b, 0, None);
            }
            enc.clear_buffer(&s.counters, 0, None);
            if let Some(hooks) = s.hooks.as_ref() {
                if let Some(list) = &hooks.list {
                    enc.clear_buffer(list, 0, None);
                }
                // The events' caps start with full buckets again.
                for scan in &hooks.scans {
                    enc.clear_buffer(&scan.blocks, 0, None);
                }
            }
            s.current = 0;
            s.whole_pool_until = f64::NEG_INFINITY;
            s.spawned_end = 0;
            // Batch numbers start again at 0 (the table's entries are rewritten as they come).
            s.births_mirror.clear();
        }
        self.ctx.queue.submit([enc.finish()]);
        self.planner.reset();
    }
}

/// Slots one update invocation handles (`SLOTS_PER_INVOCATION` in `shaders/update.wgsl`).
pub const SLOTS_PER_INVOCATION: u32 = 2;

/// Workgroups for `slots` slots of 256, as a 2-D grid (x ≤ 65535).
pub fn dispatch_size(slots: u32) -> (u32, u32) {
    dispatch_groups(slots.div_ceil(256))
}

/// `groups` workgroups (at least one) as a 2-D grid (x ≤ 65535); the grid may hold a few
/// more, which find no work.
pub fn dispatch_groups(groups: u32) -> (u32, u32) {
    let groups = groups.max(1);
    let x = groups.min(65_535);
    (x, groups.div_ceil(x))
}
