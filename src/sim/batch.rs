//! A runtime player's instances, batched: up to [`BATCH_SLOTS`] instances of one effect
//! share each emitter's state buffers (instance k owns the segment of `capacity` slots
//! from `k · capacity`) and one update dispatch per emitter and step, whose workgroups'
//! z is the instance (`params_instanced.wgsl`: one `SimParams` per instance — its own
//! seed, place, clock and ring). Each instance keeps its own planner, so a batched
//! instance steps exactly as a [`GpuSim`](crate::sim::GpuSim) of the same effect would:
//! `tests/runtime.rs` compares them bit for bit.
//!
//! Full and packed state only: tiny state's birth tables and stateless records are per
//! simulation (a player with such an emitter runs one simulation per instance).

use crate::effect::Effect;
use crate::gpu::commands::CountedCompute;
use crate::gpu::types::{PackedParticle, Particle, SimParams, StateLayout};
use crate::gpu::{GpuContext, Uploads};
use crate::sim::gpu_sim::{
    EmitterBuffers, SLOTS_PER_INVOCATION, SharedUpdate, SimError, SimState, dispatch_size, lock,
    over_life_buffer, packed_life, pipeline_key, read_buffer, upload_over_life,
};
use crate::sim::modules::Modules;
use crate::sim::planner::{EffectPlanner, LiveWindow};

// WGSL's `array<SimParams>` strides by the struct's size rounded to its 16-byte alignment:
// the blocks are written at `size_of` strides.
const _: () = assert!(size_of::<SimParams>().is_multiple_of(16));

/// Instances per batch at most: the segments of one set of buffers (fewer when an
/// emitter's pool times this would not fit one storage binding).
pub const BATCH_SLOTS: u32 = 128;

/// Instances a new batch has buffers for: a batch doubles its buffers when an instance
/// finds it full (16, 32, 64, 128), so one instance allocates few pools and a hundred
/// share one batch.
pub const FIRST_BATCH_SLOTS: u32 = 16;

/// Written for an empty segment or a disabled emitter.
const ZERO_BLOCK: [u8; size_of::<SimParams>()] = [0; size_of::<SimParams>()];

/// The state one batch allocates at most (unless one instance needs more): a large effect
/// is batched by few instances, so that a single one does not allocate sixteen.
pub const BATCH_STATE_BYTES: u64 = 64 << 20;

/// Steps one record may plan (the parameter blocks of a record live side by side).
const MAX_STEPS: usize = 32;

/// Whether `effect`'s emitters can be batched (full or packed state, not stateless, no
/// events, trails or depth collision: a batch runs one dispatch per emitter and step, the
/// events need a scan between, and none keeps per-instance hook buffers or the camera
/// each instance's simulation space is seen through).
pub fn batchable(effect: &Effect) -> bool {
    (0..effect.emitters.len()).all(|i| {
        let m = Modules::in_effect(effect, i);
        !m.contains(Modules::TINY)
            && !m.contains(Modules::STATELESS)
            && !m.has_hooks()
            && !m.contains(Modules::DEPTH_COLLISION)
    })
}

/// One emitter's buffers for every instance of a batch.
struct Pool {
    capacity: u32,
    layout: StateLayout,
    buffers: [wgpu::Buffer; 2],
    groups: [wgpu::BindGroup; 2],
    current: usize,
    generation: u64,
    life_range: (f32, f32),
    /// The emitter's random salt (`rng::emitter_salt`).
    salt: u32,
    /// The emitter's over-life curves baked, and what they hold (see `GpuSim`).
    curves: wgpu::Buffer,
    curves_key: Option<u64>,
}

/// One instance in a batch: its planner and seed.
struct Member {
    planner: EffectPlanner,
    seed: u32,
}

/// Up to [`BATCH_SLOTS`] instances of one effect, updated together.
pub struct InstanceBatch {
    ctx: GpuContext,
    update: SharedUpdate,
    pools: Vec<Pool>,
    params: wgpu::Buffer,
    /// Bytes of one (step, emitter) block: a `SimParams` per slot, 256-aligned.
    block_bytes: u64,
    /// Instances the buffers hold now.
    slots: u32,
    /// Instances the buffers may grow to hold.
    limit: u32,
    /// The instances (a slot each): more than `slots` after an insert into full
    /// buffers, until the next record grows them.
    members: Vec<Option<Member>>,
    /// Slots taken since the last record, whose segments it clears first.
    pending_clears: Vec<u32>,
    /// The steps planned and not yet dispatched: the invocations each (step, emitter)
    /// needs (the widest window of its instances), step-major.
    planned: Vec<u32>,
}

impl InstanceBatch {
    /// A batch of up to `max_slots` instances of `effect` (at most [`BATCH_SLOTS`]; as
    /// many as one storage binding holds of its largest pool, and as
    /// [`BATCH_STATE_BYTES`] of state hold; at least one) on batched update pipelines,
    /// with buffers for [`FIRST_BATCH_SLOTS`] of them to begin with.
    pub fn new(
        ctx: &GpuContext,
        update: SharedUpdate,
        effect: &Effect,
        max_slots: u32,
    ) -> Result<Self, SimError> {
        let largest = effect
            .emitters
            .iter()
            .map(|e| e.capacity.max(1))
            .max()
            .unwrap_or(1);
        // Bytes of one instance's state buffers (both of each ping-pong pair).
        let instance_bytes: u64 = effect
            .emitters
            .iter()
            .map(|e| 2 * Modules::of(e).state_layout().bytes(e.capacity.max(1)))
            .sum();
        let limit = (ctx.max_capacity() / u64::from(largest))
            .min(BATCH_STATE_BYTES / instance_bytes.max(1))
            .clamp(1, u64::from(max_slots.clamp(1, BATCH_SLOTS))) as u32;
        let slots = limit.min(FIRST_BATCH_SLOTS);
        let (params, block_bytes) = params_buffer(ctx, slots, effect.emitters.len());
        let mut batch = Self {
            ctx: ctx.clone(),
            update,
            pools: Vec::new(),
            params,
            block_bytes,
            slots,
            limit,
            pending_clears: Vec::new(),
            planned: Vec::new(),
            members: Vec::new(),
        };
        for (i, e) in effect.emitters.iter().enumerate() {
            ctx.check_capacity(&e.name, e.capacity.max(1).saturating_mul(limit))?;
            let layout = Modules::of(e).state_layout();
            let curves = over_life_buffer(&ctx.device);
            let mut pool = batch.pool(e.capacity.max(1), layout, curves);
            pool.life_range = (e.lifetime_secs.min, e.lifetime_secs.max);
            pool.salt = crate::rng::emitter_salt(i as u32, e.seed_offset);
            batch.pools.push(pool);
        }
        batch.follow(effect);
        Ok(batch)
    }

    /// Grows the buffers to hold every instance (doubling, up to the limit), their
    /// state copied by commands recorded into `enc` before any of this record's: the
    /// instances step on as they would have (slots and bytes are kept).
    fn grow(&mut self, enc: &mut wgpu::CommandEncoder) {
        let needed = self.members.len() as u32;
        if needed <= self.slots {
            return;
        }
        let mut slots = self.slots;
        while slots < needed {
            slots *= 2;
        }
        self.slots = slots.min(self.limit);
        (self.params, self.block_bytes) = params_buffer(&self.ctx, self.slots, self.pools.len());
        for k in 0..self.pools.len() {
            let (capacity, layout, curves) = {
                let p = &self.pools[k];
                (p.capacity, p.layout, p.curves.clone())
            };
            let grown = self.pool(capacity, layout, curves);
            let old = std::mem::replace(&mut self.pools[k], grown);
            let pool = &mut self.pools[k];
            for (from, to) in old.buffers.iter().zip(&pool.buffers) {
                enc.copy_buffer_to_buffer(from, 0, to, 0, from.size());
            }
            (pool.current, pool.life_range, pool.salt) = (old.current, old.life_range, old.salt);
            pool.curves_key = old.curves_key;
        }
    }

    /// Re-bakes the pools' over-life curves that `effect` changed.
    fn upload_curves(&mut self, effect: &Effect) {
        for (p, e) in self.pools.iter_mut().zip(&effect.emitters) {
            if Modules::of(e).contains(Modules::CURVES) {
                upload_over_life(&self.ctx.queue, &p.curves, &mut p.curves_key, e);
            }
        }
    }

    /// An emitter's buffers for the batch's slots (bound with its baked `curves`).
    fn pool(&self, capacity: u32, layout: StateLayout, curves: wgpu::Buffer) -> Pool {
        let d = &self.ctx.device;
        let bytes = layout.bytes(capacity * self.slots).max(32);
        let buffer = |label| {
            d.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_SRC
                    | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let buffers = [
            buffer("InstanceBatch::state_a"),
            buffer("InstanceBatch::state_b"),
        ];
        // Counters nobody reads (the batched update does not count) and a birth table
        // nobody reads (no tiny state): bindings of the shared layout.
        let spare = |label| {
            d.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: 32,
                usage: wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            })
        };
        let (counters, births) = (
            spare("InstanceBatch::counters"),
            spare("InstanceBatch::births"),
        );
        let update = lock(&self.update);
        let group = |src: usize| {
            let entry = |binding, resource| wgpu::BindGroupEntry { binding, resource };
            d.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("InstanceBatch::group"),
                layout: update.layout(),
                entries: &[
                    entry(
                        0,
                        wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                            buffer: &self.params,
                            offset: 0,
                            size: wgpu::BufferSize::new(self.block_bytes),
                        }),
                    ),
                    entry(1, buffers[src].as_entire_binding()),
                    entry(2, buffers[1 - src].as_entire_binding()),
                    entry(3, counters.as_entire_binding()),
                    entry(4, births.as_entire_binding()),
                    entry(5, curves.as_entire_binding()),
                ],
            })
        };
        let groups = [group(0), group(1)];
        Pool {
            capacity,
            layout,
            buffers,
            groups,
            current: 0,
            generation: crate::sim::gpu_sim::next_generation(),
            life_range: (0.0, 0.0),
            curves,
            curves_key: None,
            salt: 0,
        }
    }

    /// Takes a free slot for a new instance with `seed` (`None` when the batch holds
    /// its limit). Buffers that are full grow at the next [`InstanceBatch::settle_taken`],
    /// and the slot's segments are cleared there, in the same encoder as (and before)
    /// the steps: work already recorded (the last frame's, or the slot's earlier
    /// occupant's) still runs on the buffers as they were.
    pub fn insert(&mut self, seed: u32) -> Option<u32> {
        let member = Some(Member {
            planner: EffectPlanner::default(),
            seed,
        });
        let slot = match self.members.iter().position(Option::is_none) {
            Some(free) => free,
            None if (self.members.len() as u32) < self.limit => {
                self.members.push(None);
                self.members.len() - 1
            }
            None => return None,
        };
        self.pending_clears.push(slot as u32);
        self.members[slot] = member;
        Some(slot as u32)
    }

    /// Settles the instances taken since the last call: grows the buffers to hold every
    /// instance, then clears the taken slots' segments (outside a pass).
    pub fn settle_taken(&mut self, enc: &mut wgpu::CommandEncoder) {
        self.grow(enc);
        for slot in self.pending_clears.drain(..) {
            for p in &self.pools {
                let bytes = p.layout.bytes(p.capacity);
                for b in &p.buffers {
                    enc.clear_buffer(b, bytes * u64::from(slot), Some(bytes));
                }
            }
        }
    }

    /// Follows an edit of `effect` that keeps every pool's size and layout: the lifetime
    /// ranges and random salts the draws and readbacks re-derive packed lifetimes from.
    pub fn follow(&mut self, effect: &Effect) {
        for (i, (p, e)) in self.pools.iter_mut().zip(&effect.emitters).enumerate() {
            p.life_range = (e.lifetime_secs.min, e.lifetime_secs.max);
            p.salt = crate::rng::emitter_salt(i as u32, e.seed_offset);
        }
        self.upload_curves(effect);
    }

    /// Gives `slot`'s instance a new seed (for particles born from now on).
    pub fn set_seed(&mut self, slot: u32, seed: u32) {
        if let Some(Some(m)) = self.members.get_mut(slot as usize) {
            m.seed = seed;
        }
    }

    /// Frees `slot`.
    pub fn remove(&mut self, slot: u32) {
        if let Some(m) = self.members.get_mut(slot as usize) {
            *m = None;
        }
    }

    /// Instances the buffers hold now.
    pub fn buffer_slots(&self) -> u32 {
        self.slots
    }

    /// Segments up to the last taken one (what an update or a draw covers).
    pub fn active(&self) -> u32 {
        self.members
            .iter()
            .rposition(Option::is_some)
            .map_or(0, |i| i as u32 + 1)
    }

    /// Slots taken or freed so far (each instance's slot is below this).
    pub fn slot_count(&self) -> u32 {
        self.members.len() as u32
    }

    /// Empties every instance and restarts their clocks.
    pub fn restart(&mut self) {
        let mut enc = self.ctx.device.create_command_encoder(&Default::default());
        for p in &mut self.pools {
            for b in &p.buffers {
                enc.clear_buffer(b, 0, None);
            }
        }
        self.ctx.queue.submit([enc.finish()]);
        for m in self.members.iter_mut().flatten() {
            m.planner.reset();
        }
    }

    /// Plans `steps` steps of `dt_secs` for every instance (`effects[slot]`: the slot's
    /// placed effect and its revision, a value that changes whenever that effect does)
    /// and uploads their parameter blocks through `uploads`, recorded into `enc` (outside
    /// a pass); [`InstanceBatch::dispatch`] then records the steps.
    pub fn plan(
        &mut self,
        uploads: &mut Uploads,
        enc: &mut wgpu::CommandEncoder,
        effects: &[Option<(&Effect, u64)>],
        dt_secs: f32,
        steps: usize,
    ) {
        self.planned.clear();
        let steps = steps.min(MAX_STEPS);
        let n = self.pools.len();
        let active = self.active() as usize;
        if steps == 0 || active == 0 {
            return;
        }
        let bytes = self.block_bytes * (steps * n) as u64;
        // Written straight into mapped staging memory (no copy of its own).
        let Some(mut blocks) = uploads.write(enc, &self.params, 0, bytes) else {
            return;
        };
        // The invocations each (step, emitter) needs: the largest window of its instances.
        let mut widest = std::mem::take(&mut self.planned);
        widest.resize(steps * n, 0);
        let stride = size_of::<SimParams>();
        let block_bytes = self.block_bytes as usize;
        let capacities: Vec<u32> = self.pools.iter().map(|p| p.capacity).collect();
        for (slot, member) in self.members.iter_mut().enumerate().take(active) {
            let planned = member.as_mut().zip(effects.get(slot).copied().flatten());
            let Some((m, (effect, revision))) = planned else {
                // An empty segment: zero blocks update no slot (their windows are empty).
                for at in (0..steps * n).map(|b| b * block_bytes + slot * stride) {
                    blocks
                        .slice(at..at + stride)
                        .copy_from_slice(&ZERO_BLOCK[..stride]);
                }
                continue;
            };
            for s in 0..steps {
                m.planner
                    .plan_step_with(effect, Some(revision), dt_secs, |e, plan| {
                        let at = (s * n + e) * block_bytes + slot * stride;
                        let mut block = blocks.slice(at..at + stride);
                        let (Some(p), Some(&capacity)) = (plan, capacities.get(e)) else {
                            // A disabled emitter: a zero block.
                            block.copy_from_slice(&ZERO_BLOCK[..stride]);
                            return;
                        };
                        let width = if p.update_window[1] > capacity {
                            let mut whole = *p;
                            whole.update_window[..2].copy_from_slice(&[0, capacity]);
                            block.copy_from_slice(bytemuck::bytes_of(&whole));
                            capacity
                        } else {
                            block.copy_from_slice(bytemuck::bytes_of(p));
                            p.update_window[1]
                        };
                        let w = &mut widest[s * n + e];
                        *w = (*w).max(width);
                    });
            }
        }
        drop(blocks);
        self.planned = widest;
    }

    /// Records the steps [`InstanceBatch::plan`] planned into the compute pass open in
    /// `pass` (begun in `enc` on first need): one dispatch per emitter and step for the
    /// whole batch. `effect`: any instance's effect (they run the same emitters).
    pub fn dispatch(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        pass: &mut Option<wgpu::ComputePass<'static>>,
        effect: &Effect,
    ) {
        let n = self.pools.len();
        let active = self.active();
        if n == 0 || self.planned.is_empty() {
            return;
        }
        let update = lock(&self.update);
        // One pipeline per emitter for the batch.
        let pipelines: Vec<Option<&wgpu::ComputePipeline>> = (0..n)
            .map(|e| update.pipeline(&pipeline_key(effect, e)?))
            .collect();
        for (s, widths) in self.planned.chunks(n).enumerate() {
            for (e, pool) in self.pools.iter_mut().enumerate() {
                let Some(pipeline) = pipelines[e] else {
                    continue;
                };
                let group = &pool.groups[pool.current];
                pool.current = 1 - pool.current;
                let invocations = widths[e].div_ceil(SLOTS_PER_INVOCATION);
                if invocations == 0 {
                    // Every window is empty: the swap above is all a step does.
                    continue;
                }
                let pass = crate::gpu::compute_pass(pass, enc, "InstanceBatch::update");
                pass.set_pipeline(pipeline);
                let offset = ((s * n + e) as u64 * self.block_bytes) as u32;
                pass.set_bind_group(0, group, &[offset]);
                let (x, y) = dispatch_size(invocations);
                pass.dispatch(x, y, active);
            }
        }
        self.planned.clear();
    }

    /// Instance `slot` as the draw passes see it (`None` until the buffers hold it).
    pub fn member(&self, slot: u32) -> Option<BatchMember<'_>> {
        if slot >= self.slots {
            return None;
        }
        let m = self.members.get(slot as usize)?.as_ref()?;
        Some(BatchMember {
            batch: self,
            slot,
            planner: &m.planner,
            seed: m.seed,
        })
    }

    /// Emitter `e`'s particles of instance `slot` (a blocking readback).
    pub fn read_particles(&self, slot: u32, e: usize) -> Result<Vec<Particle>, SimError> {
        let (Some(pool), Some(Some(member))) = (self.pools.get(e), self.members.get(slot as usize))
        else {
            return Err(SimError::Readback(format!("no emitter {e} in slot {slot}")));
        };
        if slot >= self.slots {
            // Not recorded since it came: no particle yet.
            return Ok(vec![Particle::default(); pool.capacity as usize]);
        }
        let bytes = pool.layout.bytes(pool.capacity);
        let all = read_buffer(
            &self.ctx,
            &pool.buffers[pool.current],
            bytes * u64::from(self.slots),
        )?;
        let segment = &all[(bytes * u64::from(slot)) as usize..][..bytes as usize];
        if pool.layout == StateLayout::Full {
            return Ok(bytemuck::pod_collect_to_vec(segment));
        }
        let total = member
            .planner
            .emitters
            .get(e)
            .map_or(0, |p| p.spawned_total());
        let packed: Vec<PackedParticle> = bytemuck::pod_collect_to_vec(segment);
        Ok(packed
            .iter()
            .enumerate()
            .map(|(i, q)| {
                let key = (member.seed, pool.salt);
                let (_, life) = packed_life(pool.capacity, total, key, pool.life_range, i as u32);
                q.unpack(life)
            })
            .collect())
    }
}

/// One instance of a batch, for the draw passes.
pub struct BatchMember<'a> {
    batch: &'a InstanceBatch,
    slot: u32,
    planner: &'a EffectPlanner,
    seed: u32,
}

impl SimState for BatchMember<'_> {
    fn emitter_buffers(&self, index: usize) -> Option<EmitterBuffers<'_>> {
        let pool = self.batch.pools.get(index)?;
        let planner = self.planner.emitters.get(index);
        Some(EmitterBuffers {
            previous: &pool.buffers[1 - pool.current],
            current: &pool.buffers[pool.current],
            capacity: pool.capacity,
            generation: pool.generation,
            parity: pool.current,
            layout: pool.layout,
            // Read by tiny state only, which is not batched.
            births: &pool.buffers[0],
            tiny: [[0; 4]; 3],
            spawned_total: planner.map_or(0, |p| p.spawned_total()),
            life_range: pool.life_range,
            seed_salt: (self.seed, pool.salt),
            window: planner.map_or(LiveWindow::all(0), |p| {
                p.live_window(pool.capacity, pool.life_range.1)
            }),
            slot_base: self.slot * pool.capacity,
            // Trails are not batched.
            trail: None,
            last_step: 0,
        })
    }

    fn planner(&self) -> &EffectPlanner {
        self.planner
    }
}

/// The parameter blocks of a batch of `slots` instances with `emitters` emitters: every
/// step's block per emitter, `slots` `SimParams` each (aligned for a dynamic offset), and
/// the bytes of one block.
fn params_buffer(ctx: &GpuContext, slots: u32, emitters: usize) -> (wgpu::Buffer, u64) {
    let block_bytes = (u64::from(slots) * size_of::<SimParams>() as u64).next_multiple_of(
        u64::from(ctx.device.limits().min_storage_buffer_offset_alignment),
    );
    let params = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("InstanceBatch::params"),
        size: block_bytes * (MAX_STEPS * emitters.max(1)) as u64,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    (params, block_bytes)
}
