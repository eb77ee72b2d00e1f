//! The effect's light (`shaders/light.wgsl`): the light the additive particles alive now
//! emit, summed per instance and emitter on the GPU, and read back without stalling — a
//! ring of readback buffers, each mapped when the GPU is done with it, so results arrive a
//! frame or two after the frame they measure.

use crate::gpu::commands::CountedCompute;
use std::collections::HashMap;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use crate::effect::BlendMode;
use crate::gpu::{GpuContext, Uploads};
use crate::render::frame::StateVariant;
use crate::render::light_apply::ItemTotals;
use crate::render::{DrawItem, FrameResources};
use crate::shaders::{ShaderError, ShaderLibrary, create_checked};
use crate::sim::gpu_sim::dispatch_size;

/// One emitter of one instance's light, in its simulation space: Σ E.rgb, Σ Y, Σ Y·p,
/// Σ Y·|p|² (E the emitted light, Y its luminance, p the particle's position).
pub type LightSums = [f32; 8];

/// Bytes of one job's uniform (a dynamic offset's alignment).
const JOB_STRIDE: u64 = 256;
/// Readbacks in flight at most (a fourth frame's light is skipped until one is free).
const RING: usize = 3;

/// The light pass: its pipelines, its buffers, and the readbacks in flight.
pub struct LightPass<T> {
    layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    /// The totals' group: the sums and the totals' plan.
    total_layout: wgpu::BindGroupLayout,
    total_pipeline_layout: wgpu::PipelineLayout,
    module: wgpu::ShaderModule,
    sums: HashMap<StateVariant, Option<wgpu::ComputePipeline>>,
    total: wgpu::ComputePipeline,
    /// Partials, totals and jobs, and their group (grown as needed).
    buffers: Option<Buffers>,
    /// The last `prepare`'s jobs, for its dispatch and readback.
    jobs: Vec<Job>,
    /// The last `prepare`'s partials and totals.
    counts: (u32, u32),
    ring: Vec<Readback<T>>,
    next: usize,
}

/// The sums buffer (partials, then totals), the jobs' uniforms and the totals' plan
/// (`light_total`'s: the count, then each total's first partial, partials and index), with
/// their sizes in bytes.
struct Buffers {
    sums: u64,
    jobs: u64,
    totals: u64,
    sums_buffer: wgpu::Buffer,
    jobs_buffer: wgpu::Buffer,
    totals_plan: wgpu::Buffer,
    group: wgpu::BindGroup,
    total_group: wgpu::BindGroup,
}

/// A readback buffer and what it holds: `None` free, else the frame's owners (look slots
/// in totals order), whether its map was asked for, and whether it has completed.
struct Readback<T> {
    buffer: wgpu::Buffer,
    size: u64,
    pending: Option<Pending<T>>,
}

struct Pending<T> {
    owners: Vec<Option<T>>,
    mapping: bool,
    done: Arc<AtomicBool>,
}

/// What one job of a frame sums.
struct Job {
    item: usize,
    partial_base: u32,
    groups: u32,
    total_base: u32,
}

impl<T: Clone> LightPass<T> {
    /// Builds the pipelines from `lib` (the look and state groups are `frame`'s).
    pub fn new(
        ctx: &GpuContext,
        lib: &ShaderLibrary,
        frame: &FrameResources,
    ) -> Result<Self, ShaderError> {
        let storage = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: false },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let layout = crate::gpu::bind_group_layout(
            ctx,
            "LightPass::layout",
            &[
                storage(0),
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: true,
                        min_binding_size: wgpu::BufferSize::new(16),
                    },
                    count: None,
                },
            ],
        );
        let pipeline_layout = ctx
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("LightPass::pipeline_layout"),
                bind_group_layouts: &[
                    Some(&frame.frame_layout),
                    Some(&frame.particle_layout),
                    Some(&layout),
                ],
                immediate_size: 0,
            });
        let entry = crate::gpu::compute_storage_entry;
        let total_layout = crate::gpu::bind_group_layout(
            ctx,
            "LightPass::total_layout",
            &[entry(0, false), entry(1, true)],
        );
        let total_pipeline_layout =
            ctx.device
                .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                    label: Some("LightPass::total_pipeline_layout"),
                    bind_group_layouts: &[None, None, Some(&total_layout)],
                    immediate_size: 0,
                });
        let layouts = (&pipeline_layout, &total_pipeline_layout);
        let (module, sums, total) = Self::build(ctx, lib, layouts)?;
        Ok(Self {
            layout,
            pipeline_layout,
            total_layout,
            total_pipeline_layout,
            module,
            sums,
            total,
            buffers: None,
            jobs: Vec::new(),
            counts: (0, 0),
            ring: Vec::new(),
            next: 0,
        })
    }

    #[allow(clippy::type_complexity)]
    fn build(
        ctx: &GpuContext,
        lib: &ShaderLibrary,
        (layout, total_layout): (&wgpu::PipelineLayout, &wgpu::PipelineLayout),
    ) -> Result<
        (
            wgpu::ShaderModule,
            HashMap<StateVariant, Option<wgpu::ComputePipeline>>,
            wgpu::ComputePipeline,
        ),
        ShaderError,
    > {
        let composed = lib.compose("light.wgsl")?;
        create_checked(&ctx.device, &composed, lib, |module| {
            let full = StateVariant::default();
            let sum = Self::sum_pipeline(ctx, layout, module, full);
            let total = crate::render::compute_pipeline(
                ctx,
                "LightPass::total",
                total_layout,
                module,
                "light_total",
                &[],
            );
            (module.clone(), HashMap::from([(full, Some(sum))]), total)
        })
    }

    fn sum_pipeline(
        ctx: &GpuContext,
        layout: &wgpu::PipelineLayout,
        module: &wgpu::ShaderModule,
        state: StateVariant,
    ) -> wgpu::ComputePipeline {
        let constants = state.constants();
        crate::render::compute_pipeline(
            ctx,
            "LightPass::sum",
            layout,
            module,
            "light_sum",
            &constants,
        )
    }

    /// Rebuilds the pipelines; keeps the old ones on error.
    pub fn rebuild(&mut self, ctx: &GpuContext, lib: &ShaderLibrary) -> Result<(), ShaderError> {
        let layouts = (&self.pipeline_layout, &self.total_pipeline_layout);
        let (module, sums, total) = Self::build(ctx, lib, layouts)?;
        (self.module, self.sums, self.total) = (module, sums, total);
        Ok(())
    }

    /// Plans the sums of every additive item's instances and uploads the plan through
    /// `uploads` (copies recorded into `enc`, outside a pass); returns where each item's
    /// totals will be in [`LightPass::sums_buffer`] (for the lit layers, `light_apply.rs`).
    /// [`LightPass::dispatch`] records the sums, [`LightPass::record_readback`] their
    /// copy for the CPU.
    pub fn prepare(
        &mut self,
        ctx: &GpuContext,
        (enc, uploads): (&mut wgpu::CommandEncoder, &mut Uploads),
        items: &[DrawItem],
    ) -> Vec<ItemTotals> {
        let (jobs, partials, totals) = plan(items);
        self.jobs = jobs;
        self.counts = (partials, totals);
        if self.jobs.is_empty() {
            return Vec::new();
        }
        self.ensure_buffers(ctx, partials + totals, totals, self.jobs.len() as u64);
        self.ensure_variants(ctx, items);
        let Some(b) = &self.buffers else {
            self.jobs.clear();
            return Vec::new();
        };
        let mut bytes = vec![0u8; self.jobs.len() * JOB_STRIDE as usize];
        let mut totals_plan = vec![[totals, 0, 0, 0]];
        for (k, j) in self.jobs.iter().enumerate() {
            let members = items[j.item].members;
            let words = [j.partial_base, j.groups, partials + j.total_base, members];
            bytes[k * JOB_STRIDE as usize..][..16].copy_from_slice(bytemuck::cast_slice(&words));
            totals_plan.extend((0..members).map(|m| {
                let first = j.partial_base + m * j.groups;
                [first, j.groups, partials + j.total_base + m, 0]
            }));
        }
        uploads.write_bytes(enc, &b.jobs_buffer, 0, &bytes);
        uploads.write_bytes(enc, &b.totals_plan, 0, bytemuck::cast_slice(&totals_plan));
        self.jobs
            .iter()
            .map(|j| (j.item, partials + j.total_base))
            .collect()
    }

    /// The buffer of the last dispatch's sums (partials, then totals).
    pub fn sums_buffer(&self) -> Option<&wgpu::Buffer> {
        self.buffers.as_ref().map(|b| &b.sums_buffer)
    }

    /// Copies the totals of the last [`LightPass::dispatch`] (outside its pass) into a
    /// free readback buffer with what `owner` says of each look slot (the instance and
    /// emitter it measures): [`LightPass::collect`] returns them once the GPU has
    /// finished (nothing when every readback is in flight).
    pub fn record_readback(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        items: &[DrawItem],
        owner: &dyn Fn(usize) -> Option<T>,
    ) {
        let (partials, totals) = self.counts;
        let (Some(ring), Some(b)) = (self.free_readback(), &self.buffers) else {
            return;
        };
        if self.jobs.is_empty() {
            return;
        }
        let owners = self
            .jobs
            .iter()
            .flat_map(|j| {
                let d = &items[j.item];
                (0..d.members as usize).map(move |m| d.look_slot + m)
            })
            .map(owner)
            .collect();
        let r = &mut self.ring[ring];
        let size = u64::from(totals) * 32;
        let from = u64::from(partials) * 32;
        enc.copy_buffer_to_buffer(&b.sums_buffer, from, &r.buffer, 0, size.min(r.size));
        r.pending = Some(Pending {
            owners,
            mapping: false,
            done: Arc::new(AtomicBool::new(false)),
        });
        self.next = (ring + 1) % RING;
    }

    /// Records the sums the last [`LightPass::prepare`] planned into `pass`: each job's
    /// partials, then every total in one dispatch.
    pub fn dispatch(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        frame: &FrameResources,
        items: &[DrawItem],
    ) {
        let Some(b) = &self.buffers else {
            return;
        };
        if self.jobs.is_empty() {
            return;
        }
        for (k, j) in self.jobs.iter().enumerate() {
            let d = &items[j.item];
            let (Some(particles), Some(Some(sum))) =
                (frame.particle_group(d.key), self.sums.get(&d.variant.state))
            else {
                continue;
            };
            pass.set_bind_group(
                0,
                &frame.frame_group,
                &[FrameResources::look_offset(d.look_slot)],
            );
            pass.set_bind_group(1, particles, &[]);
            pass.set_bind_group(2, &b.group, &[(k as u64 * JOB_STRIDE) as u32]);
            pass.set_pipeline(sum);
            let (x, y) = dispatch_size(d.width);
            pass.dispatch(x, y, d.members);
        }
        pass.set_pipeline(&self.total);
        pass.set_bind_group(2, &b.total_group, &[]);
        pass.dispatch(self.counts.1.div_ceil(64), 1, 1);
    }

    /// The newest finished frame's sums with their owners, if one finished since the
    /// last call (never waits: it polls the device once).
    pub fn collect(&mut self, ctx: &GpuContext) -> Option<Vec<(T, LightSums)>> {
        let _ = ctx.device.poll(wgpu::PollType::Poll);
        let mut newest = None;
        for k in 1..=RING {
            let i = (self.next + RING - k) % RING;
            let Some(r) = self.ring.get_mut(i) else {
                continue;
            };
            let done = (r.pending.as_ref()).is_some_and(|p| p.done.load(Ordering::Acquire));
            if !done {
                continue;
            }
            let Some(p) = r.pending.take() else {
                continue;
            };
            let sums = read_sums(&r.buffer, &p.owners);
            r.buffer.unmap();
            newest = newest.or(Some(sums));
        }
        newest
    }

    /// Asks for the maps of the readbacks recorded before (call after the submission that
    /// holds their copies: a player's next record).
    pub fn map_recorded(&mut self) {
        for r in &mut self.ring {
            if let Some(p) = &mut r.pending
                && !p.mapping
            {
                p.mapping = true;
                let flag = p.done.clone();
                r.buffer
                    .slice(..)
                    .map_async(wgpu::MapMode::Read, move |res| {
                        if res.is_ok() {
                            flag.store(true, Ordering::Release);
                        }
                    });
            }
        }
    }

    /// A readback buffer with nothing in flight, or none.
    fn free_readback(&self) -> Option<usize> {
        let i = self.next;
        let r = self.ring.get(i)?;
        r.pending.is_none().then_some(i)
    }

    /// Buffers for `sums` vec4 pairs (partials, then totals), readbacks for `totals`
    /// pairs, and `jobs` uniforms.
    fn ensure_buffers(&mut self, ctx: &GpuContext, sums: u32, totals: u32, jobs: u64) {
        let s = u64::from(sums.max(1)) * 32;
        let j = jobs * JOB_STRIDE;
        // The totals' plan: a count, then one entry per total (16 bytes each).
        let p = (u64::from(totals) + 1) * 16;
        let have = self.buffers.as_ref().map(|b| (b.sums, b.jobs, b.totals));
        if !have.is_some_and(|(hs, hj, hp)| hs >= s && hj >= j && hp >= p) {
            let grow = |have: u64, need: u64| need.max(have).next_power_of_two();
            let (hs, hj, hp) = have.unwrap_or_default();
            let sizes = (grow(hs, s), grow(hj, j), grow(hp, p));
            self.buffers = Some(Buffers::new(ctx, (&self.layout, &self.total_layout), sizes));
        }
        while self.ring.len() < RING {
            self.ring.push(Readback {
                buffer: readback_buffer(ctx, 32),
                size: 32,
                pending: None,
            });
        }
        let t = (u64::from(totals.max(1)) * 32).next_power_of_two();
        for r in (self.ring.iter_mut()).filter(|r| r.pending.is_none() && r.size < t) {
            r.buffer = readback_buffer(ctx, t);
            r.size = t;
        }
    }

    fn ensure_variants(&mut self, ctx: &GpuContext, items: &[DrawItem]) {
        for j in &self.jobs {
            let state = items[j.item].variant.state;
            if !self.sums.contains_key(&state) {
                let p = crate::render::scoped_variant(
                    ctx,
                    format_args!("light variant {state:?}"),
                    || Self::sum_pipeline(ctx, &self.pipeline_layout, &self.module, state),
                );
                self.sums.insert(state, p);
            }
        }
    }
}

impl Buffers {
    fn new(
        ctx: &GpuContext,
        (layout, total_layout): (&wgpu::BindGroupLayout, &wgpu::BindGroupLayout),
        (sums, jobs, totals): (u64, u64, u64),
    ) -> Self {
        let buffer = |label, size, usage| {
            ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage,
                mapped_at_creation: false,
            })
        };
        let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
        let sums_buffer = buffer("LightPass::sums", sums, usage);
        let usage = wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST;
        let jobs_buffer = buffer("LightPass::jobs", jobs, usage);
        let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST;
        let totals_plan = buffer("LightPass::totals_plan", totals, usage);
        let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("LightPass::group"),
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: sums_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &jobs_buffer,
                        offset: 0,
                        size: wgpu::BufferSize::new(16),
                    }),
                },
            ],
        });
        let total_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("LightPass::total_group"),
            layout: total_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: sums_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: totals_plan.as_entire_binding(),
                },
            ],
        });
        Self {
            sums,
            jobs,
            totals,
            sums_buffer,
            jobs_buffer,
            totals_plan,
            group,
            total_group,
        }
    }
}

/// The frame's jobs (every additive item with particles), and the partials and totals
/// they need.
fn plan(items: &[DrawItem]) -> (Vec<Job>, u32, u32) {
    let (mut jobs, mut partials, mut totals) = (Vec::new(), 0, 0);
    for (item, d) in items.iter().enumerate() {
        if d.blend != BlendMode::Additive || d.variant.haze || d.width == 0 {
            continue;
        }
        let (x, y) = dispatch_size(d.width);
        jobs.push(Job {
            item,
            partial_base: partials,
            groups: x * y,
            total_base: totals,
        });
        partials += x * y * d.members;
        totals += d.members;
    }
    (jobs, partials, totals)
}

fn readback_buffer(ctx: &GpuContext, size: u64) -> wgpu::Buffer {
    ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("LightPass::readback"),
        size,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    })
}

/// The mapped `buffer`'s totals, with their owners.
fn read_sums<T: Clone>(buffer: &wgpu::Buffer, owners: &[Option<T>]) -> Vec<(T, LightSums)> {
    let Ok(view) = buffer.slice(..).get_mapped_range() else {
        return Vec::new();
    };
    let floats: &[f32] = bytemuck::cast_slice(&view);
    owners
        .iter()
        .enumerate()
        .filter_map(|(k, owner)| {
            let s = floats.get(k * 8..k * 8 + 8)?;
            let mut sums = [0.0; 8];
            sums.copy_from_slice(s);
            Some((owner.clone()?, sums))
        })
        .collect()
}
