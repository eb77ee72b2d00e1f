//! The effect's light handed to its lit layers on the GPU (`shaders/light_apply.wgsl`):
//! after the light pass sums each additive emitter's light per instance, one small
//! dispatch adds up each instance's emitters, moves the result into each lit emitter's
//! simulation space and writes it into that look slot's `LitUniform` — the same frame,
//! with no readback.

use crate::gpu::commands::CountedCompute;
use crate::gpu::{GpuContext, Uploads};
use crate::render::DrawItem;
use crate::render::frame::FrameResources;
use crate::shaders::{ShaderError, ShaderLibrary, create_checked};

/// Where an item's totals start in the light pass's sums buffer (entries of two vec4s).
pub type ItemTotals = (usize, u32);

/// The apply pass: its pipeline, its plan buffer and the group over the frame's buffers.
pub struct SelfLightPass {
    layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    pipeline: wgpu::ComputePipeline,
    plan: Option<wgpu::Buffer>,
    /// The group over (sums, looks, plan), kept while those buffers are the same.
    group: Option<([wgpu::Buffer; 3], wgpu::BindGroup)>,
    /// Lit look slots the last `prepare` planned for (0: nothing to dispatch).
    targets: u32,
}

impl SelfLightPass {
    /// Builds the pipeline from `lib`.
    pub fn new(ctx: &GpuContext, lib: &ShaderLibrary) -> Result<Self, ShaderError> {
        let entry = crate::gpu::compute_storage_entry;
        let layout = crate::gpu::bind_group_layout(
            ctx,
            "SelfLightPass::layout",
            &[entry(0, true), entry(1, false), entry(2, true)],
        );
        let pipeline_layout = ctx
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("SelfLightPass::pipeline_layout"),
                bind_group_layouts: &[Some(&layout)],
                immediate_size: 0,
            });
        let pipeline = Self::build(ctx, lib, &pipeline_layout)?;
        Ok(Self {
            layout,
            pipeline_layout,
            pipeline,
            plan: None,
            group: None,
            targets: 0,
        })
    }

    fn build(
        ctx: &GpuContext,
        lib: &ShaderLibrary,
        layout: &wgpu::PipelineLayout,
    ) -> Result<wgpu::ComputePipeline, ShaderError> {
        let composed = lib.compose("light_apply.wgsl")?;
        create_checked(&ctx.device, &composed, lib, |module| {
            let label = "SelfLightPass::apply";
            crate::render::compute_pipeline(ctx, label, layout, module, "light_apply", &[])
        })
    }

    /// Rebuilds the pipeline; keeps the old one on error.
    pub fn rebuild(&mut self, ctx: &GpuContext, lib: &ShaderLibrary) -> Result<(), ShaderError> {
        self.pipeline = Self::build(ctx, lib, &self.pipeline_layout)?;
        Ok(())
    }

    /// Plans the apply of the frame's lit items and uploads the plan through `uploads`
    /// (a copy recorded into `enc`, outside a pass): `totals` says where each additive
    /// item's totals are in `sums` (the light pass's buffer). False when no item is lit;
    /// else [`SelfLightPass::dispatch`] records it, after the light pass's sums.
    pub fn prepare(
        &mut self,
        ctx: &GpuContext,
        (enc, uploads): (&mut wgpu::CommandEncoder, &mut Uploads),
        frame: &FrameResources,
        items: &[DrawItem],
        totals: &[ItemTotals],
        sums: &wgpu::Buffer,
    ) -> bool {
        let words = plan(items, totals, &frame.slot_origins);
        self.targets = words.first().map_or(0, |w| w[0]);
        if self.targets == 0 {
            return false;
        }
        let bytes: &[u8] = bytemuck::cast_slice(&words);
        let size = (bytes.len() as u64).next_power_of_two().max(256);
        if self.plan.as_ref().is_none_or(|b| b.size() < size) {
            self.plan = Some(ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("SelfLightPass::plan"),
                size,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }));
        }
        let Some(plan) = &self.plan else {
            self.targets = 0;
            return false;
        };
        uploads.write_bytes(enc, plan, 0, bytes);
        let buffers = [sums.clone(), frame.looks_buffer().clone(), plan.clone()];
        if self.group.as_ref().is_none_or(|(b, _)| *b != buffers) {
            let group = self.bind_group(ctx, &buffers);
            self.group = Some((buffers, group));
        }
        true
    }

    /// Records the apply the last [`SelfLightPass::prepare`] planned into `pass`.
    pub fn dispatch(&self, pass: &mut wgpu::ComputePass<'_>) {
        let Some((_, group)) = self.group.as_ref().filter(|_| self.targets > 0) else {
            return;
        };
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, group, &[]);
        pass.dispatch(self.targets.div_ceil(64), 1, 1);
    }
}

impl SelfLightPass {
    /// The group over `[sums, looks, plan]`.
    fn bind_group(&self, ctx: &GpuContext, buffers: &[wgpu::Buffer; 3]) -> wgpu::BindGroup {
        let entries: Vec<wgpu::BindGroupEntry<'_>> = (0u32..)
            .zip(buffers)
            .map(|(binding, b)| wgpu::BindGroupEntry {
                binding,
                resource: b.as_entire_binding(),
            })
            .collect();
        ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("SelfLightPass::group"),
            layout: &self.layout,
            entries: &entries,
        })
    }
}

/// The plan `light_apply.wgsl` reads: the targets' count, a header per lit look slot
/// (slot, first source, sources), then the sources — each additive item of the same
/// group, the same member: the offset between the two emitters' origins and the total's
/// index.
pub fn plan(items: &[DrawItem], totals: &[ItemTotals], origins: &[glam::DVec3]) -> Vec<[u32; 4]> {
    let targets: Vec<(usize, usize, usize)> = items
        .iter()
        .filter(|d| d.variant.lit)
        .flat_map(|d| (0..d.members as usize).map(move |m| (d.look_slot + m, d.group, m)))
        .collect();
    let mut words = vec![[targets.len() as u32, 0, 0, 0]];
    words.resize(1 + targets.len(), [0; 4]);
    for (t, (slot, group, m)) in targets.iter().enumerate() {
        let first = words.len() as u32;
        let origin = origins.get(*slot).copied().unwrap_or_default();
        for (item, total) in totals {
            let Some(d) = items.get(*item).filter(|d| d.group == *group) else {
                continue;
            };
            let source = origins.get(d.look_slot + m).copied().unwrap_or_default();
            let delta = (source - origin).as_vec3().to_array().map(f32::to_bits);
            words.push([delta[0], delta[1], delta[2], total + *m as u32]);
        }
        words[1 + t] = [*slot as u32, first, words.len() as u32 - first, 0];
    }
    words
}
