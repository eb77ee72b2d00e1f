//! Pass 1 on the GPU: per-emitter ping-pong state buffers and the update pipeline.

use std::collections::{HashMap, VecDeque};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};

use crate::effect::{CURVE_WIDTH, Effect, Integrator, rows_key};
use crate::gpu::types::{
    Birth, PARAMS_STRIDE, PackedParticle, Particle, SimParams, StateLayout, double_single,
    slot_counter, tiny_decode,
};
use crate::gpu::{GpuContext, GpuError};
use crate::shaders::{
    EVENTS_IO, PACKED_STATE_IO, PARAMS_INSTANCED, ShaderError, ShaderLibrary, TINY_STATE_IO,
    TRAIL_IO, create_checked,
};
use crate::sim::events::{EventHeader, ScanConfig, scan_flags};
use crate::sim::hooks::{EmitterHooks, HookPipes};
use crate::sim::modules::Modules;
use crate::sim::planner::{EffectPlanner, LiveWindow};

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

/// What specialises an update pipeline: the integrator and the modules compiled in.
pub type PipelineKey = (Integrator, Modules);

/// The pipeline key emitter `i` of `effect` needs.
pub fn pipeline_key(effect: &Effect, i: usize) -> Option<PipelineKey> {
    let e = effect.emitters.get(i)?;
    Some((e.integrator, Modules::in_effect(effect, i)))
}

/// The update pipelines (one per integrator × module set, built on demand) and their layout.
pub struct UpdatePass {
    layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    pipelines: HashMap<PipelineKey, wgpu::ComputePipeline>,
    count_layout: wgpu::BindGroupLayout,
    count_pipeline_layout: wgpu::PipelineLayout,
    /// The on-demand counts for full and packed state.
    count: Option<[wgpu::ComputePipeline; 2]>,
    /// Files the current pipelines were built from.
    pub files: Vec<String>,
    /// The update counts alive particles as it goes (GPUs; the editor's statistics).
    /// Off, nothing clears a counter between steps and counts are taken on demand.
    count_alive: bool,
    /// Batched instances (params_instanced.wgsl): parameters are an array in storage.
    batched: bool,
    /// The event hooks' layout and the event scan.
    pub(crate) hooks: HookPipes,
    /// Groups 0 and 1: the update of an emitter with hooks (none when batched).
    hooks_pipeline_layout: Option<wgpu::PipelineLayout>,
}

/// How an update pass's pipelines are specialised.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UpdateMode {
    /// One simulation per dispatch; the update counts alive particles on GPUs (the
    /// editor's statistics read them every frame).
    Counted,
    /// One simulation per dispatch; counts are taken on demand.
    Uncounted,
    /// The same emitter of many instances per dispatch (`params_instanced.wgsl`).
    Batched,
}

impl UpdatePass {
    fn new(ctx: &GpuContext, mode: UpdateMode) -> Self {
        let batched = mode == UpdateMode::Batched;
        let storage = crate::gpu::compute_storage_entry;
        let params_entry = wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                // See params.wgsl: an array of blocks for batched instances.
                ty: if batched {
                    wgpu::BufferBindingType::Storage { read_only: true }
                } else {
                    wgpu::BufferBindingType::Uniform
                },
                has_dynamic_offset: true,
                min_binding_size: wgpu::BufferSize::new(std::mem::size_of::<SimParams>() as u64),
            },
            count: None,
        };
        let layout = ctx
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("UpdatePass::layout"),
                entries: &[
                    params_entry,
                    storage(1, true),
                    storage(2, false),
                    storage(3, false),
                    // The birth table (tiny state; a placeholder for the others).
                    storage(4, true),
                    // The over-life curves (read with MOD_CURVES).
                    storage(5, true),
                ],
            });
        let pipeline_layout = ctx
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("UpdatePass::pipeline_layout"),
                bind_group_layouts: &[Some(&layout)],
                immediate_size: 0,
            });
        let hooks = HookPipes::new(ctx, params_entry);
        // Batched updates have no hooks (effects with events or trails are not batched),
        // and their parameters in storage would take them past 8 storage buffers.
        let hooks_pipeline_layout = (!batched).then(|| {
            ctx.device
                .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                    label: Some("UpdatePass::hooks_pipeline_layout"),
                    bind_group_layouts: &[Some(&layout), Some(&hooks.hooks_layout)],
                    immediate_size: 0,
                })
        });
        let count_layout = ctx
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("UpdatePass::count_layout"),
                entries: &[storage(0, true), storage(1, false), storage(2, true)],
            });
        let count_pipeline_layout =
            ctx.device
                .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                    label: Some("UpdatePass::count_pipeline_layout"),
                    bind_group_layouts: &[Some(&count_layout)],
                    immediate_size: 0,
                });
        Self {
            layout,
            pipeline_layout,
            pipelines: HashMap::new(),
            count_layout,
            count_pipeline_layout,
            count: None,
            files: Vec::new(),
            count_alive: mode == UpdateMode::Counted,
            batched,
            hooks,
            hooks_pipeline_layout,
        }
    }

    /// The layout of group 0 (parameters, state, counters, birth table).
    pub(crate) fn layout(&self) -> &wgpu::BindGroupLayout {
        &self.layout
    }

    /// The pipeline for `key`, if built.
    pub(crate) fn pipeline(&self, key: &PipelineKey) -> Option<&wgpu::ComputePipeline> {
        self.pipelines.get(key)
    }

    /// Builds the pipelines for `integrators` from `lib`; on any error keeps the old ones.
    pub fn rebuild(
        &mut self,
        ctx: &GpuContext,
        lib: &ShaderLibrary,
        keys: &[PipelineKey],
    ) -> Result<(), ShaderError> {
        let params = self.batched.then_some(PARAMS_INSTANCED);
        let compose = |io: Option<(&str, &str)>| {
            let aliases: Vec<(&str, &str)> = io.into_iter().chain(params).collect();
            lib.compose_with("update.wgsl", &aliases)
        };
        let composed = compose(None)?;
        // Packed-state pipelines: the same entry with state_packed.wgsl as the state I/O.
        let packed = compose(Some(PACKED_STATE_IO))?;
        // Tiny-state pipelines: state_tiny.wgsl as the state I/O.
        let tiny = compose(Some(TINY_STATE_IO))?;
        // Emitters with events (or fed by them) or trails: their hooks, full state only.
        let mut hooked = HashMap::new();
        for &(_, modules) in keys.iter().filter(|(_, m)| m.has_hooks()) {
            let key = (modules.has_events(), modules.contains(Modules::TRAIL));
            if let std::collections::hash_map::Entry::Vacant(v) = hooked.entry(key) {
                let hooks = [key.0.then_some(EVENTS_IO), key.1.then_some(TRAIL_IO)];
                let aliases: Vec<(&str, &str)> =
                    hooks.into_iter().flatten().chain(params).collect();
                v.insert(lib.compose_with("update.wgsl", &aliases)?);
            }
        }
        let mut fresh = HashMap::new();
        for &(integrator, modules) in keys {
            let hooks = (modules.has_events(), modules.contains(Modules::TRAIL));
            let with_hooks = hooked.get(&hooks).zip(self.hooks_pipeline_layout.as_ref());
            let (composed, layout) = if let Some((c, l)) = with_hooks {
                (c, l)
            } else if modules.contains(Modules::TINY) {
                (&tiny, &self.pipeline_layout)
            } else if modules.contains(Modules::PACKED) {
                (&packed, &self.pipeline_layout)
            } else {
                (&composed, &self.pipeline_layout)
            };
            let mut constants = modules.constants();
            constants.push(("INTEGRATOR", integrator.index() as f64));
            constants.push(("COUNT_ALIVE", if self.count_alive { 1.0 } else { 0.0 }));
            let pipeline = create_checked(&ctx.device, composed, lib, |module| {
                ctx.device
                    .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                        label: Some("UpdatePass::pipeline"),
                        layout: Some(layout),
                        module,
                        entry_point: Some("main"),
                        compilation_options: wgpu::PipelineCompilationOptions {
                            constants: &constants,
                            zero_initialize_workgroup_memory: true,
                        },
                        cache: None,
                    })
            })?;
            fresh.insert((integrator, modules), pipeline);
        }
        // The on-demand alive count.
        let count_src = lib.compose("count.wgsl")?;
        let count = create_checked(&ctx.device, &count_src, lib, |module| {
            [0.0, 1.0].map(|packed| {
                ctx.device
                    .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                        label: Some("UpdatePass::count"),
                        layout: Some(&self.count_pipeline_layout),
                        module,
                        entry_point: Some("main"),
                        compilation_options: wgpu::PipelineCompilationOptions {
                            constants: &[("PACKED", packed)],
                            zero_initialize_workgroup_memory: true,
                        },
                        cache: None,
                    })
            })
        })?;
        // The event scan (batched updates have no events: none).
        let scan_files = if self.batched {
            Vec::new()
        } else {
            self.hooks.rebuild(ctx, lib)?
        };
        self.pipelines = fresh;
        self.count = Some(count);
        self.files = composed.files;
        for f in packed
            .files
            .into_iter()
            .chain(tiny.files)
            .chain(hooked.into_values().flat_map(|c| c.files))
            .chain(count_src.files)
            .chain(scan_files)
        {
            if !self.files.contains(&f) {
                self.files.push(f);
            }
        }
        Ok(())
    }

    pub(crate) fn ensure(
        &mut self,
        ctx: &GpuContext,
        lib: &ShaderLibrary,
        key: PipelineKey,
    ) -> Result<(), ShaderError> {
        if self.pipelines.contains_key(&key) {
            return Ok(());
        }
        let mut wanted: Vec<PipelineKey> = self.pipelines.keys().copied().collect();
        wanted.push(key);
        self.rebuild(ctx, lib, &wanted)
    }
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

/// A trail's ring read back ([`GpuSim::read_trail`]).
#[derive(Clone, Debug, PartialEq)]
pub struct TrailRing {
    /// Entries per slot.
    pub points: u32,
    /// Steps between recorded points.
    pub every_steps: u32,
    /// `points` entries per slot, slot after slot: position (simulation space) and age.
    pub entries: Vec<[f32; 4]>,
}

/// The update pipelines, shared by the simulations of one effect's instances.
pub type SharedUpdate = Arc<Mutex<UpdatePass>>;

/// The update pass behind `update` (a poisoned lock is taken over: the pipelines in it
/// are whole).
pub(crate) fn lock(update: &SharedUpdate) -> MutexGuard<'_, UpdatePass> {
    update.lock().unwrap_or_else(PoisonError::into_inner)
}

fn update_counts(update: &SharedUpdate) -> bool {
    lock(update).count_alive
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
}

/// Read-only views of an emitter's state buffers, for the draw passes.
pub struct EmitterBuffers<'a> {
    /// State before the last step.
    pub previous: &'a wgpu::Buffer,
    /// State after the last step.
    pub current: &'a wgpu::Buffer,
    /// Slots.
    pub capacity: u32,
    /// Changes whenever the buffers are recreated (bind-group caches key on it).
    pub generation: u64,
    /// Which of the pair is current (0 or 1).
    pub parity: usize,
    /// How the state is stored (packed and tiny are read through `PackedParticle` views).
    pub layout: StateLayout,
    /// The tiny state's birth table (a placeholder for the other layouts).
    pub births: &'a wgpu::Buffer,
    /// Tiny state: `LookUniform::tiny`, `tiny_b` and `tiny_c` — the current state's time
    /// (double-single hi, lo; f32 bits), the birth table's first sequence number and
    /// entries; the table's index mask, the last step's size (f32 bits), the oldest
    /// entry's first counter and the counters spanned; the span before the last step.
    pub tiny: [[u32; 4]; 3],
    /// Particles spawned so far (the ring's position: packed state re-derives lifetimes).
    pub spawned_total: u64,
    /// Lifetime range of the emitter.
    pub life_range: (f32, f32),
    /// Effect seed and emitter salt.
    pub seed_salt: (u32, u32),
    /// The slots that can hold living particles (draws and the sort visit only these).
    pub window: LiveWindow,
    /// Where this pool's slots start in the buffers (a batched instance's segment; else 0).
    pub slot_base: u32,
    /// The trail's ring of positions (an emitter with a trail).
    pub trail: Option<&'a wgpu::Buffer>,
    /// The number of the last step (the trail's newest entries are older).
    pub last_step: u32,
}

/// What the draw passes read of a simulation: its pools and its planner (a
/// [`GpuSim`], or one instance of an [`crate::sim::batch::InstanceBatch`]).
pub trait SimState {
    /// Buffers of emitter `index` for drawing.
    fn emitter_buffers(&self, index: usize) -> Option<EmitterBuffers<'_>>;
    /// The CPU planning: times, origins, spawn counters.
    fn planner(&self) -> &EffectPlanner;
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
        };
        sim.sync(effect)?;
        Ok(sim)
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
        for e in &effect.emitters {
            self.ctx.check_capacity(&e.name, e.capacity)?;
            if let Some(t) = &e.look.trail {
                let points = t.layout(effect.time.nominal_step_secs()).points;
                let bytes = super::trails::ring_bytes(e.capacity.max(1), points);
                self.ctx
                    .check_trail(&e.name, (e.capacity.max(1), points), bytes)?;
            }
        }
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
                    let mut fresh = self.create_state(capacity, layout);
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
                        let keep = layout.bytes(old.capacity.min(capacity));
                        let mut enc = self.ctx.device.create_command_encoder(&Default::default());
                        for b in 0..2 {
                            enc.copy_buffer_to_buffer(
                                &old.buffers[old.current],
                                0,
                                &fresh.buffers[b],
                                0,
                                keep,
                            );
                        }
                        self.ctx.queue.submit([enc.finish()]);
                        self.emitters[i] = fresh;
                    } else {
                        self.emitters.push(fresh);
                    }
                }
            }
        }
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
        for key in used_keys(effect) {
            lock(&self.update).ensure(&self.ctx, &self.library, key)?;
        }
        self.sync_events(effect, grown);
        Ok(())
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

    /// Runs `steps` steps of `dt_secs` (spawning, integrating, ageing) on the GPU.
    pub fn step(&mut self, effect: &Effect, dt_secs: f32, steps: u32) -> Result<(), SimError> {
        self.sync(effect)?;
        let mut remaining = steps as usize;
        while remaining > 0 {
            let chunk = remaining.min(STEPS_PER_SUBMIT);
            let plans: Vec<Vec<Option<SimParams>>> = (0..chunk)
                .map(|_| self.planner.plan_step(effect, dt_secs))
                .collect();
            self.record_and_submit(effect, &plans);
            remaining -= chunk;
        }
        Ok(())
    }

    /// Records the planned steps (one `SimParams` per enabled emitter and step) and submits.
    pub fn record_and_submit(&mut self, effect: &Effect, plans: &[Vec<Option<SimParams>>]) {
        let mut enc = self
            .ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("GpuSim::step"),
            });
        self.record(&mut enc, effect, plans);
        self.ctx.queue.submit([enc.finish()]);
    }

    /// Plans `steps` steps of `dt_secs` ([`GpuSim::record`] records any number: the
    /// params ring holds 32 steps, later ones are copied in by the encoder).
    pub fn plan(
        &mut self,
        effect: &Effect,
        dt_secs: f32,
        steps: usize,
    ) -> Vec<Vec<Option<SimParams>>> {
        (0..steps)
            .map(|_| self.planner.plan_step(effect, dt_secs))
            .collect()
    }

    /// Uploads the planned blocks and records their dispatches into `enc`. Submit `enc`
    /// before the next call (the blocks share one buffer).
    pub fn record(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        effect: &Effect,
        plans: &[Vec<Option<SimParams>>],
    ) {
        enc.push_debug_group("update particles");
        let mut pass = None;
        self.record_into(enc, &mut pass, effect, plans);
        drop(pass);
        enc.pop_debug_group();
    }

    /// [`GpuSim::record`] into an open compute pass of `enc` (opened on first need), so
    /// that several simulations (a player's instances) share one pass. A simulation that
    /// counts alive particles ends the pass before its last step to clear its counters.
    /// Plans beyond the params ring's 32 steps run in further chunks: the pass is ended
    /// and the encoder copies each chunk's blocks into the ring before its steps.
    pub fn record_into(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        pass: &mut Option<wgpu::ComputePass<'static>>,
        effect: &Effect,
        plans: &[Vec<Option<SimParams>>],
    ) {
        let n_emitters = self.emitters.len();
        for e in 0..n_emitters {
            if self.emitters[e].layout == StateLayout::Tiny {
                self.upload_births(e, plans);
            }
        }
        self.write_scan_configs(effect);
        let chunks: Vec<(Vec<u8>, Vec<u32>)> = plans
            .chunks(STEPS_PER_SUBMIT)
            .map(|chunk| self.param_blocks(chunk))
            .collect();
        // Written before the submission runs: the first chunk's blocks into the ring, the
        // others after one another into `later_chunks`.
        if let Some((first, _)) = chunks.first() {
            self.ctx.queue.write_buffer(&self.params_buffer, 0, first);
        }
        let later: Vec<u8> = chunks
            .iter()
            .skip(1)
            .flat_map(|c| c.0.iter().copied())
            .collect();
        let staging = self.later_chunks_buffer(later.len() as u64);
        if let Some(buffer) = &staging {
            self.ctx.queue.write_buffer(buffer, 0, &later);
        }
        let mut at = 0u64;
        for (c, (chunk, (blocks, windows))) in
            plans.chunks(STEPS_PER_SUBMIT).zip(&chunks).enumerate()
        {
            if let (true, Some(buffer)) = (c > 0, &staging) {
                // The chunk's blocks into the ring once the steps before have run.
                drop(pass.take());
                let len = blocks.len() as u64;
                enc.copy_buffer_to_buffer(buffer, at, &self.params_buffer, 0, len);
                at += len;
            }
            self.dispatch_steps(enc, pass, effect, chunk, windows, c + 1 == chunks.len());
        }
    }

    /// `later_chunks`, at least `bytes` long (`None` for none).
    fn later_chunks_buffer(&mut self, bytes: u64) -> Option<wgpu::Buffer> {
        if bytes == 0 {
            return None;
        }
        if self.later_chunks.as_ref().is_none_or(|b| b.size() < bytes) {
            self.later_chunks = Some(self.ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("GpuSim::later_chunks"),
                size: bytes.next_power_of_two(),
                usage: wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }));
        }
        self.later_chunks.clone()
    }

    /// The parameter blocks of up to 32 steps' plans, as the params ring holds them, and
    /// each (step, emitter)'s update window.
    fn param_blocks(&self, plans: &[Vec<Option<SimParams>>]) -> (Vec<u8>, Vec<u32>) {
        let n_emitters = self.emitters.len();
        let mut blocks = vec![0u8; plans.len() * n_emitters * PARAMS_STRIDE as usize];
        let mut windows = vec![0u32; plans.len() * n_emitters];
        for (s, plan) in plans.iter().enumerate() {
            for (e, params) in plan.iter().enumerate() {
                if let (Some(p), Some(em)) = (params, self.emitters.get(e)) {
                    let mut p = *p;
                    // State written from outside the planner, or kept at old slots by a
                    // capacity change: every slot may be alive.
                    let clock = self
                        .planner
                        .emitters
                        .get(e)
                        .map_or(f64::INFINITY, |pl| pl.clock_secs());
                    if em.gpu_fed
                        || clock < em.whole_pool_until
                        || p.capacity != em.capacity
                        || p.update_window[1] > em.capacity
                    {
                        p.update_window[..2].copy_from_slice(&[0, em.capacity]);
                    }
                    windows[s * n_emitters + e] = p.update_window[1];
                    if em.layout == StateLayout::Tiny {
                        p.flags = em.births_mask;
                    }
                    let at = (s * n_emitters + e) * PARAMS_STRIDE as usize;
                    blocks[at..at + size_of::<SimParams>()].copy_from_slice(bytemuck::bytes_of(&p));
                }
            }
        }
        (blocks, windows)
    }

    /// Records the steps of `plans` (one chunk, its blocks in the params ring);
    /// `last_chunk`: the record's last steps (the alive counter is cleared before its
    /// last step).
    fn dispatch_steps(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        pass: &mut Option<wgpu::ComputePass<'static>>,
        effect: &Effect,
        plans: &[Vec<Option<SimParams>>],
        windows: &[u32],
        last_chunk: bool,
    ) {
        let n_emitters = self.emitters.len();
        let order = effect.update_order();
        // One compute pass for as many dispatches as possible (wgpu orders dependent
        // dispatches inside a pass): on lavapipe each pass costs about as much as a small
        // dispatch. GPUs end it where the alive counter must be cleared first.
        let clear_counters = update_counts(&self.update);
        let update = Arc::clone(&self.update);
        let update = lock(&update);
        for (s, plan) in plans.iter().enumerate() {
            if clear_counters && last_chunk && s + 1 == plans.len() {
                // The update counts alive particles (COUNT_ALIVE) into the counter: clear
                // it before the last step only, whose count is the one read (one break
                // of the pass per record, not one per emitter and step).
                drop(pass.take());
                for (em, params) in self.emitters.iter().zip(plan) {
                    if params.is_some() && !em.stateless {
                        enc.clear_buffer(&em.counters, 0, Some(4));
                    }
                }
            }
            for &e in &order {
                let (Some(Some(p)), Some(em)) = (plan.get(e), self.emitters.get_mut(e)) else {
                    continue;
                };
                em.spawned_end = (u64::from(p.spawn_base_hi) << 32 | u64::from(p.spawn_base_lo))
                    + u64::from(p.spawn_count);
                let Some(pipeline) = pipeline_key(effect, e).and_then(|k| update.pipelines.get(&k))
                else {
                    continue;
                };
                let offset = ((s * n_emitters + e) as u64 * PARAMS_STRIDE) as u32;
                // Stateless: spawn records only, written in place into buffer 0 (group 1
                // reads buffer 1 and writes buffer 0); nothing else is touched.
                let (group, slots) = if em.stateless {
                    (&em.bind_groups[1], p.spawn_count)
                } else {
                    (&em.bind_groups[em.current], windows[s * n_emitters + e])
                };
                // Tiny state: one invocation per pair of slots the window touches.
                let invocations = if em.layout == StateLayout::Tiny {
                    (slots / 2 + 2).min(em.capacity.div_ceil(2))
                } else {
                    slots.div_ceil(SLOTS_PER_INVOCATION)
                };
                if !em.stateless {
                    em.current = 1 - em.current;
                }
                // An empty window: nothing in the pool can be alive, both buffers hold the
                // same dead slots, so the swap above is all a step does (and the cleared
                // counter says zero).
                if slots > 0 {
                    let pass = crate::gpu::compute_pass(pass, enc, "GpuSim::update");
                    pass.set_pipeline(pipeline);
                    pass.set_bind_group(0, group, &[offset]);
                    if let Some(ev) = &em.hooks {
                        pass.set_bind_group(1, &ev.hooks, &[]);
                    }
                    let (x, y) = dispatch_size(invocations);
                    pass.dispatch_workgroups(x, y, 1);
                }
                // The parent's events become its children's spawn lists, the same step.
                if let (Some(ev), Some(scan)) = (&em.hooks, &update.hooks.scan) {
                    record_scans(
                        crate::gpu::compute_pass(pass, enc, "GpuSim::events"),
                        ev,
                        scan,
                        offset,
                        slots,
                    );
                }
            }
        }
    }

    /// Writes each scan's settings: the rule, the child's capacity and cap, the offset
    /// between the parent's and the child's simulation spaces, the inherited velocity.
    fn write_scan_configs(&mut self, effect: &Effect) {
        let origin = |j: usize| {
            self.planner
                .emitters
                .get(j)
                .map(|p| p.origin())
                .unwrap_or_default()
        };
        let mut configs = Vec::new();
        for (i, (s, e)) in self.emitters.iter().zip(&effect.emitters).enumerate() {
            let Some(hooks) = &s.hooks else {
                continue;
            };
            for (k, (scan, ev)) in hooks.scans.iter().zip(&e.events).enumerate() {
                let delta = (origin(i) - origin(scan.child)).as_vec3();
                let child_capacity = self.emitters.get(scan.child).map_or(1, |c| c.capacity);
                let cfg = ScanConfig {
                    rule_capacity_cap: [
                        k as u32,
                        child_capacity,
                        crate::sim::events::step_cap(effect, i, k),
                        scan_flags(ev.inherit_color, scan.linked),
                    ],
                    delta_inherit: [delta.x, delta.y, delta.z, ev.inherit_velocity],
                    cap: [
                        ev.max_per_sec,
                        crate::effect::cap_burst(ev.max_per_sec),
                        0.0,
                        0.0,
                    ],
                };
                configs.push((i, k, cfg));
            }
        }
        for (i, k, cfg) in configs {
            let Some(scan) = self.emitters[i]
                .hooks
                .as_mut()
                .and_then(|h| h.scans.get_mut(k))
            else {
                continue;
            };
            if scan.written != Some(cfg) {
                self.ctx
                    .queue
                    .write_buffer(&scan.config, 0, bytemuck::bytes_of(&cfg));
                scan.written = Some(cfg);
            }
        }
    }

    /// Emitter `index`'s hook buffers (events, trail), if it has any.
    fn hooks(&self, index: usize) -> Option<&EmitterHooks> {
        self.emitters.get(index).and_then(|s| s.hooks.as_ref())
    }

    /// Emitter `index`'s trail ring (a blocking readback): points per slot, steps between
    /// them, and the entries (`points` per slot: position, and the age then).
    pub fn read_trail(&self, index: usize) -> Result<Option<TrailRing>, SimError> {
        let Some(ring) = self.hooks(index).and_then(|h| h.trail.as_ref()) else {
            return Ok(None);
        };
        let bytes = read_buffer(&self.ctx, ring, ring.size())?;
        let header: [u32; 4] = bytemuck::pod_read_unaligned(&bytes[..16]);
        Ok(Some(TrailRing {
            points: header[0],
            every_steps: header[1],
            entries: bytemuck::pod_collect_to_vec(&bytes[16..]),
        }))
    }

    /// Emitter `index`'s spawn-list header (a child of an event): this step's children,
    /// and those the events asked for and the cap dropped since the start.
    pub fn read_event_header(&self, index: usize) -> Result<Option<EventHeader>, SimError> {
        let Some(list) = self.hooks(index).and_then(|h| h.list.as_ref()) else {
            return Ok(None);
        };
        let bytes = read_buffer(&self.ctx, list, size_of::<EventHeader>() as u64)?;
        Ok(Some(bytemuck::pod_read_unaligned(&bytes)))
    }

    /// Writes the birth-table entries of the batches `plans` spawned for tiny emitter `e`
    /// (each step's window of the table must stay intact until the submit has run: a table
    /// too small for the span of this submit's windows is replaced by a larger one).
    fn upload_births(&mut self, e: usize, plans: &[Vec<Option<SimParams>>]) {
        let steps: Vec<SimParams> = plans
            .iter()
            .filter_map(|p| p.get(e).copied().flatten())
            .collect();
        let (Some(first), Some(last)) = (steps.first(), steps.last()) else {
            return;
        };
        let mut fresh = Vec::new();
        for p in &steps {
            if p.spawn_count > 0 {
                // The step's own batch is the newest of its window.
                let seq = u64::from(p.tiny[2]) + u64::from(p.tiny[3]) - 1;
                let entry = Birth {
                    first: p.spawn_base_lo,
                    count: p.spawn_count,
                    t0_hi: f32::from_bits(p.tiny[0]),
                    t0_lo: f32::from_bits(p.tiny[1]),
                    dt: p.dt_secs,
                    frac0: p.spawn_frac0,
                    frac_step: p.spawn_frac_step,
                    pad: 0,
                };
                self.emitters[e].births_mirror.push_back((seq, entry));
                fresh.push((seq, entry));
            }
        }
        let lo = u64::from(first.tiny[2]);
        let hi = u64::from(last.tiny[2]) + u64::from(last.tiny[3]);
        let span = hi.saturating_sub(lo);
        let size = u64::from(self.emitters[e].births_mask) + 1;
        if span > size {
            let entries = (span * 2)
                .next_power_of_two()
                .min(u64::from(u32::MAX / 2 + 1)) as u32;
            let births = self.births_buffer(entries);
            let s = &self.emitters[e];
            let bind_groups = self.bind_groups(&s.buffers, &s.counters, &births, &s.curves);
            let generation = next_generation();
            let s = &mut self.emitters[e];
            s.births = births;
            s.births_mask = entries - 1;
            s.bind_groups = bind_groups;
            // The draws' bind groups key on the generation.
            s.generation = generation;
            fresh = s
                .births_mirror
                .iter()
                .copied()
                .filter(|(q, _)| *q >= lo)
                .collect();
        }
        let s = &self.emitters[e];
        for (seq, entry) in fresh {
            let at = (seq & u64::from(s.births_mask)) * size_of::<Birth>() as u64;
            self.ctx
                .queue
                .write_buffer(&s.births, at, bytemuck::bytes_of(&entry));
        }
        // Later submits read from the last step's window on.
        let keep = u64::from(last.tiny[2]);
        let s = &mut self.emitters[e];
        while s.births_mirror.front().is_some_and(|(q, _)| *q < keep) {
            s.births_mirror.pop_front();
        }
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

    /// Overwrites emitter `index`'s current (and previous) state (benches and tests that
    /// need an exact initial condition). `particles` is truncated to the capacity.
    pub fn write_particles(
        &mut self,
        index: usize,
        particles: &[Particle],
    ) -> Result<(), SimError> {
        let s = self
            .emitters
            .get(index)
            .ok_or_else(|| SimError::Readback(format!("no emitter {index}")))?;
        let n = particles.len().min(s.capacity as usize);
        if s.layout != StateLayout::Full {
            return Err(SimError::Readback(
                "write_particles needs full (unpacked) state".into(),
            ));
        }
        for b in &s.buffers {
            self.ctx
                .queue
                .write_buffer(b, 0, bytemuck::cast_slice(&particles[..n]));
        }
        if let Some(s) = self.emitters.get_mut(index) {
            s.whole_pool_until = f64::INFINITY;
        }
        Ok(())
    }

    /// Reads emitter `index`'s current state back (blocking; tests and tools).
    pub fn read_particles(&self, index: usize) -> Result<Vec<Particle>, SimError> {
        let s = self
            .emitters
            .get(index)
            .ok_or_else(|| SimError::Readback(format!("no emitter {index}")))?;
        let bytes = read_buffer(&self.ctx, &s.buffers[s.current], s.layout.bytes(s.capacity))?;
        if s.layout == StateLayout::Full {
            return Ok(bytemuck::pod_collect_to_vec(&bytes));
        }
        let planner = self.planner.emitters.get(index);
        let total = planner.map_or(0, |p| p.spawned_total());
        let life_of =
            |slot: u32| packed_life(s.capacity, total, (s.seed, s.salt), s.life_range, slot);
        let packed: Vec<PackedParticle> = bytemuck::pod_collect_to_vec(&bytes);
        if s.layout == StateLayout::Packed {
            return Ok(packed
                .iter()
                .enumerate()
                .map(|(slot, q)| q.unpack(life_of(slot as u32).1))
                .collect());
        }
        // Tiny: ages from the birth table's batches, as the GPU computes them.
        let now = planner.map_or(0.0, |p| p.clock_secs());
        Ok((0..s.capacity)
            .map(|slot| {
                let words: [u32; 5] = bytemuck::cast(packed[(slot / 2) as usize]);
                let (c, life) = life_of(slot);
                let age = planner.and_then(|p| p.birth_age(c, now));
                match (tiny_decode(words, slot), age) {
                    (Some((pos, vel)), Some(age)) if age >= 0.0 && age < f64::from(life) => {
                        Particle {
                            pos_age: [pos[0], pos[1], pos[2], age as f32],
                            vel_life: [vel[0], vel[1], vel[2], life],
                        }
                    }
                    _ => Particle::default(),
                }
            })
            .collect())
    }

    /// `[alive after the last step, non-finite kills so far]` of emitter `index` (blocking).
    ///
    /// GPUs count in the update pass (a workgroup reduction). On CPU adapters the alive
    /// count is computed now, by a counting pass over the current state (the update pass
    /// does not count there: only the stats need it); tiny-state emitters are counted from
    /// the unpacked state. Stateless emitters are counted on the CPU from their spawn
    /// records' ages.
    pub fn read_counters(&self, index: usize) -> Result<[u32; 2], SimError> {
        let s = self
            .emitters
            .get(index)
            .ok_or_else(|| SimError::Readback(format!("no emitter {index}")))?;
        if s.layout == StateLayout::Tiny && !update_counts(&self.update) {
            // Counted from the unpacked state (the on-demand count pass has no birth table).
            let alive = self
                .read_particles(index)?
                .iter()
                .filter(|p| p.is_alive())
                .count();
            let bytes = read_buffer(&self.ctx, &s.counters, 8)?;
            let v: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
            return Ok([alive as u32, v[1]]);
        }
        if s.stateless {
            let now = self.planner.time_secs.rem_euclid(4096.0) as f32;
            let alive = self
                .read_particles(index)?
                .iter()
                .filter(|r| {
                    let mut age = now - r.pos_age[3];
                    if age < 0.0 {
                        age += 4096.0;
                    }
                    r.vel_life[3] > 0.0 && age < r.vel_life[3]
                })
                .count() as u32;
            return Ok([alive, 0]);
        }
        // GPUs count in the update pass itself; CPU adapters count here, on demand.
        let update = lock(&self.update);
        if let Some(count) = update.count.as_ref().filter(|_| !update.count_alive) {
            let group = self
                .ctx
                .device
                .create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("GpuSim::count_group"),
                    layout: &update.count_layout,
                    entries: &[
                        wgpu::BindGroupEntry {
                            binding: 0,
                            resource: s.buffers[s.current].as_entire_binding(),
                        },
                        wgpu::BindGroupEntry {
                            binding: 1,
                            resource: s.counters.as_entire_binding(),
                        },
                        wgpu::BindGroupEntry {
                            binding: 2,
                            resource: s.buffers[s.current].as_entire_binding(),
                        },
                    ],
                });
            let mut enc = self.ctx.device.create_command_encoder(&Default::default());
            enc.clear_buffer(&s.counters, 0, Some(4));
            {
                let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("GpuSim::count"),
                    timestamp_writes: None,
                });
                pass.set_pipeline(&count[usize::from(s.layout == StateLayout::Packed)]);
                pass.set_bind_group(0, &group, &[]);
                let (x, y) = dispatch_size(s.capacity);
                pass.dispatch_workgroups(x, y, 1);
            }
            self.ctx.queue.submit([enc.finish()]);
        }
        let bytes = read_buffer(&self.ctx, &s.counters, 8)?;
        let v: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
        Ok([v[0], v[1]])
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

/// Records the scans of a parent's events (`ev`) after its update: per event the three
/// passes of `events.wgsl` over the blocks of the parent's window of `slots` slots, with
/// the step's parameter block at `offset`.
fn record_scans(
    pass: &mut wgpu::ComputePass<'static>,
    ev: &EmitterHooks,
    scan: &[wgpu::ComputePipeline; 3],
    offset: u32,
    slots: u32,
) {
    let blocks = slots.div_ceil(crate::sim::events::EVENT_SCAN_BLOCK);
    for group in ev.scans.iter().filter_map(|sc| sc.group.as_ref()) {
        pass.set_bind_group(0, group, &[offset]);
        for (pipeline, groups) in scan.iter().zip([blocks, 1, blocks]) {
            if groups > 0 {
                pass.set_pipeline(pipeline);
                let (x, y) = dispatch_groups(groups);
                pass.dispatch_workgroups(x, y, 1);
            }
        }
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

/// Every pipeline key the effect uses (so only those pipelines are built).
pub fn used_keys(effect: &Effect) -> Vec<PipelineKey> {
    let mut v: Vec<PipelineKey> = (0..effect.emitters.len())
        .filter_map(|i| pipeline_key(effect, i))
        .collect();
    v.sort_by_key(|(i, m)| (i.index(), *m));
    v.dedup();
    if v.is_empty() {
        v.push((Integrator::SemiImplicitEuler, Modules::DRAG));
    }
    v
}

/// Copies `size` bytes of `buffer` to the CPU (blocking).
pub fn read_buffer(
    ctx: &GpuContext,
    buffer: &wgpu::Buffer,
    size: u64,
) -> Result<Vec<u8>, SimError> {
    let staging = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    enc.copy_buffer_to_buffer(buffer, 0, &staging, 0, size);
    ctx.queue.submit([enc.finish()]);
    map_read(ctx, &staging)
}

/// Maps a `MAP_READ` buffer and copies its bytes out (blocking): [`crate::gpu::readback::map_read`]
/// with the simulation's error.
pub fn map_read(ctx: &GpuContext, staging: &wgpu::Buffer) -> Result<Vec<u8>, SimError> {
    Ok(crate::gpu::readback::map_read(ctx, staging)?)
}
