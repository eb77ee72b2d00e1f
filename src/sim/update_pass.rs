//! The update pass: the update pipelines of an effect — one per integrator and module set,
//! built on demand, shared by its instances' simulations — and their layout.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};

use crate::effect::{Effect, Integrator};
use crate::gpu::GpuContext;
use crate::gpu::types::SimParams;
use crate::shaders::{
    DEPTH_IO, EVENTS_IO, PACKED_STATE_IO, PARAMS_INSTANCED, ShaderError, ShaderLibrary,
    TINY_STATE_IO, TRAIL_IO, create_checked,
};
use crate::sim::hooks::HookPipes;
use crate::sim::modules::Modules;

/// What specialises an update pipeline: the integrator and the modules compiled in.
pub type PipelineKey = (Integrator, Modules);

/// The pipeline key emitter `i` of `effect` needs.
pub fn pipeline_key(effect: &Effect, i: usize) -> Option<PipelineKey> {
    let e = effect.emitters.get(i)?;
    Some((e.integrator, Modules::in_effect(effect, i)))
}

/// The update pipelines (one per integrator × module set, built on demand) and their layout.
pub struct UpdatePass {
    pub(crate) layout: wgpu::BindGroupLayout,
    pub(crate) pipeline_layout: wgpu::PipelineLayout,
    pub(crate) pipelines: HashMap<PipelineKey, wgpu::ComputePipeline>,
    pub(crate) count_layout: wgpu::BindGroupLayout,
    pub(crate) count_pipeline_layout: wgpu::PipelineLayout,
    /// The on-demand counts for full and packed state.
    pub(crate) count: Option<[wgpu::ComputePipeline; 2]>,
    /// Files the current pipelines were built from.
    pub files: Vec<String>,
    /// The update counts alive particles as it goes (GPUs; the editor's statistics).
    /// Off, nothing clears a counter between steps and counts are taken on demand.
    pub(crate) count_alive: bool,
    /// Batched instances (params_instanced.wgsl): parameters are an array in storage.
    pub(crate) batched: bool,
    /// The event hooks' layout and the event scan.
    pub(crate) hooks: HookPipes,
    /// Groups 0 and 1: the update of an emitter with hooks (none when batched).
    pub(crate) hooks_pipeline_layout: Option<wgpu::PipelineLayout>,
    /// Group 2 of an update with depth collision: the host's depth and how the emitter's
    /// simulation space is seen (`crate::sim::depth_collision`).
    pub(crate) depth_layout: wgpu::BindGroupLayout,
    /// Groups 0 and 2, and 0, 1 and 2: the update of an emitter with depth collision,
    /// without and with hooks (none when batched).
    depth_pipeline_layouts: Option<[wgpu::PipelineLayout; 2]>,
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
    pub(crate) fn new(ctx: &GpuContext, mode: UpdateMode) -> Self {
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
        let layout = crate::gpu::bind_group_layout(
            ctx,
            "UpdatePass::layout",
            &[
                params_entry,
                storage(1, true),
                storage(2, false),
                storage(3, false),
                // The birth table (tiny state; a placeholder for the others).
                storage(4, true),
                // The over-life curves (read with MOD_CURVES).
                storage(5, true),
            ],
        );
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
        let depth_layout = crate::sim::depth_collision::layout(ctx);
        let depth_pipeline_layouts = (!batched).then(|| {
            [None, Some(&hooks.hooks_layout)].map(|hooks| {
                ctx.device
                    .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                        label: Some("UpdatePass::depth_pipeline_layout"),
                        bind_group_layouts: &[Some(&layout), hooks, Some(&depth_layout)],
                        immediate_size: 0,
                    })
            })
        });
        let count_layout = crate::gpu::bind_group_layout(
            ctx,
            "UpdatePass::count_layout",
            &[storage(0, true), storage(1, false), storage(2, true)],
        );
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
            depth_layout,
            depth_pipeline_layouts,
        }
    }

    /// The layout of an update with hooks or depth collision, if it can have them.
    fn hooked_layout(&self, modules: Modules) -> Option<&wgpu::PipelineLayout> {
        if modules.contains(Modules::DEPTH_COLLISION) {
            let layouts = self.depth_pipeline_layouts.as_ref()?;
            Some(&layouts[usize::from(modules.has_hooks())])
        } else {
            self.hooks_pipeline_layout.as_ref()
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
        let hooked = compose_hooked(lib, keys, params)?;
        let mut fresh = HashMap::new();
        for &(integrator, modules) in keys {
            let with_hooks = hooked
                .get(&hooked_key(modules))
                .zip(self.hooked_layout(modules));
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

/// The update composed for each combination of events (or being fed by them), trails and
/// depth collision among `keys` (their hooks; full state only).
fn compose_hooked(
    lib: &ShaderLibrary,
    keys: &[PipelineKey],
    params: Option<(&'static str, &'static str)>,
) -> Result<HashMap<(bool, bool, bool), crate::shaders::Composed>, ShaderError> {
    let mut hooked = HashMap::new();
    for &(_, modules) in keys.iter().filter(|(_, m)| is_hooked(*m)) {
        let key = hooked_key(modules);
        if let std::collections::hash_map::Entry::Vacant(v) = hooked.entry(key) {
            let hooks = [
                key.0.then_some(EVENTS_IO),
                key.1.then_some(TRAIL_IO),
                key.2.then_some(DEPTH_IO),
            ];
            let aliases: Vec<(&str, &str)> = hooks.into_iter().flatten().chain(params).collect();
            v.insert(lib.compose_with("update.wgsl", &aliases)?);
        }
    }
    Ok(hooked)
}

/// Whether an update with `modules` composes hooks or depth collision.
fn is_hooked(modules: Modules) -> bool {
    modules.has_hooks() || modules.contains(Modules::DEPTH_COLLISION)
}

/// Which of events, the trail and depth collision an update composes.
fn hooked_key(modules: Modules) -> (bool, bool, bool) {
    (
        modules.has_events(),
        modules.contains(Modules::TRAIL),
        modules.contains(Modules::DEPTH_COLLISION),
    )
}

/// The update pipelines, shared by the simulations of one effect's instances.
pub type SharedUpdate = Arc<Mutex<UpdatePass>>;

/// The update pass behind `update` (a poisoned lock is taken over: the pipelines in it
/// are whole).
pub(crate) fn lock(update: &SharedUpdate) -> MutexGuard<'_, UpdatePass> {
    update.lock().unwrap_or_else(PoisonError::into_inner)
}

pub(crate) fn update_counts(update: &SharedUpdate) -> bool {
    lock(update).count_alive
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
