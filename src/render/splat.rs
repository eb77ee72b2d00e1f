//! The compute splat draw path for small particles: project, accumulate fixed-point
//! light with atomics, resolve into the HDR target. ~90× cheaper than tiny instanced
//! quads on GPUs whose rasteriser runs on a few SMs (see the perf bench).

use std::collections::HashMap;

use crate::gpu::GpuContext;
use crate::render::billboard::ADDITIVE;
use crate::render::frame::{DrawItem, FrameResources, StateVariant};
use crate::shaders::{ShaderError, ShaderLibrary, create_checked};
use crate::sim::gpu_sim::dispatch_size;

/// Fixed-point scale of the accumulation buffer (keep in sync with `FIXED_SCALE` in
/// `shaders/splat.wgsl`): 1/4096 resolution, up to ~1e6 of HDR light per pixel.
pub const SPLAT_FIXED_SCALE: f32 = 4096.0;

/// Compute splat + resolve.
pub struct SplatPass {
    accum_layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    resolve_layout: wgpu::PipelineLayout,
    empty_group: wgpu::BindGroup,
    module: wgpu::ShaderModule,
    /// Splat pipelines per state variant, built on first use (`None`: failed, logged).
    splats: HashMap<StateVariant, Option<wgpu::ComputePipeline>>,
    resolve: wgpu::RenderPipeline,
    accum: Option<((u32, u32), wgpu::Buffer, wgpu::BindGroup)>,
}

impl SplatPass {
    /// Builds the pipelines from `lib`.
    pub fn new(
        ctx: &GpuContext,
        lib: &ShaderLibrary,
        frame: &FrameResources,
    ) -> Result<Self, ShaderError> {
        let accum_layout = ctx
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("SplatPass::accum_layout"),
                entries: &[wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::COMPUTE | wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage { read_only: false },
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                }],
            });
        let pipeline_layout = ctx
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("SplatPass::pipeline_layout"),
                bind_group_layouts: &[
                    Some(&frame.splat_layout),
                    Some(&frame.particle_layout),
                    Some(&accum_layout),
                ],
                immediate_size: 0,
            });
        // The resolve reads no particles: group 1 is an empty placeholder.
        let empty_layout = ctx
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("SplatPass::empty_layout"),
                entries: &[],
            });
        let empty_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("SplatPass::empty_group"),
            layout: &empty_layout,
            entries: &[],
        });
        let resolve_layout = ctx
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("SplatPass::resolve_layout"),
                bind_group_layouts: &[
                    Some(&frame.splat_layout),
                    Some(&empty_layout),
                    Some(&accum_layout),
                ],
                immediate_size: 0,
            });
        let (module, splats, resolve) = Self::build(ctx, lib, &pipeline_layout, &resolve_layout)?;
        Ok(Self {
            accum_layout,
            pipeline_layout,
            resolve_layout,
            empty_group,
            module,
            splats,
            resolve,
            accum: None,
        })
    }

    fn splat_pipeline(
        ctx: &GpuContext,
        layout: &wgpu::PipelineLayout,
        module: &wgpu::ShaderModule,
        state: StateVariant,
    ) -> wgpu::ComputePipeline {
        ctx.device
            .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(&format!("SplatPass::splat {state:?}")),
                layout: Some(layout),
                module,
                entry_point: Some("splat"),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: &state.constants(),
                    ..Default::default()
                },
                cache: None,
            })
    }

    /// The module, the full-state splat (validated with it) and the resolve.
    #[allow(clippy::type_complexity)]
    fn build(
        ctx: &GpuContext,
        lib: &ShaderLibrary,
        layout: &wgpu::PipelineLayout,
        resolve_layout: &wgpu::PipelineLayout,
    ) -> Result<
        (
            wgpu::ShaderModule,
            HashMap<StateVariant, Option<wgpu::ComputePipeline>>,
            wgpu::RenderPipeline,
        ),
        ShaderError,
    > {
        let composed = lib.compose("splat.wgsl")?;
        create_checked(&ctx.device, &composed, lib, |module| {
            let full = StateVariant::default();
            let splats =
                HashMap::from([(full, Some(Self::splat_pipeline(ctx, layout, module, full)))]);
            let resolve = crate::render::simple_pipeline(
                ctx,
                "SplatPass::resolve",
                resolve_layout,
                module,
                ("vs_resolve", "fs_resolve"),
                crate::render::hdr_target(ADDITIVE),
                &[],
                wgpu::PrimitiveTopology::TriangleList,
            );
            (module.clone(), splats, resolve)
        })
    }

    /// Rebuilds the pipelines; keeps the old ones on error. Other state variants are
    /// rebuilt on first use.
    pub fn rebuild(&mut self, ctx: &GpuContext, lib: &ShaderLibrary) -> Result<(), ShaderError> {
        let (module, splats, resolve) =
            Self::build(ctx, lib, &self.pipeline_layout, &self.resolve_layout)?;
        self.module = module;
        self.splats = splats;
        self.resolve = resolve;
        Ok(())
    }

    /// Clears the accumulation buffer and splats every splat item (compute). Returns
    /// false when there was nothing to splat (then `resolve` can be skipped).
    pub fn splat(
        &mut self,
        ctx: &GpuContext,
        enc: &mut wgpu::CommandEncoder,
        frame: &FrameResources,
        items: &[DrawItem],
        size: (u32, u32),
    ) -> bool {
        if !items.iter().any(|d| d.splat) {
            return false;
        }
        if self.accum.as_ref().is_none_or(|a| a.0 != size) {
            let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("SplatPass::accum"),
                size: size.0 as u64 * size.1 as u64 * 12,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("SplatPass::accum_group"),
                layout: &self.accum_layout,
                entries: &[wgpu::BindGroupEntry {
                    binding: 0,
                    resource: buffer.as_entire_binding(),
                }],
            });
            self.accum = Some((size, buffer, group));
        }
        let Some((_, buffer, group)) = self.accum.as_ref() else {
            return false;
        };
        for d in items.iter().filter(|d| d.splat) {
            let state = d.variant.state;
            if !self.splats.contains_key(&state) {
                let p = crate::render::scoped_variant(
                    ctx,
                    format_args!("splat variant {state:?}"),
                    || Self::splat_pipeline(ctx, &self.pipeline_layout, &self.module, state),
                );
                self.splats.insert(state, p);
            }
        }
        enc.clear_buffer(buffer, 0, None);
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("SplatPass::splat"),
            timestamp_writes: None,
        });
        pass.set_bind_group(2, group, &[]);
        for d in items.iter().filter(|d| d.splat) {
            let Some(particles) = frame.particle_group(d.key) else {
                continue;
            };
            let Some(Some(pipeline)) = self.splats.get(&d.variant.state) else {
                continue;
            };
            pass.set_pipeline(pipeline);
            pass.set_bind_group(
                0,
                &frame.splat_group,
                &[FrameResources::look_offset(d.look_slot)],
            );
            pass.set_bind_group(1, particles, &[]);
            let (x, y) = dispatch_size(d.window.len);
            pass.dispatch_workgroups(x, y, 1);
        }
        true
    }

    /// The accumulation buffer of the last splat (the tonemap reads it directly).
    pub fn accum_buffer(&self) -> Option<&wgpu::Buffer> {
        self.accum.as_ref().map(|a| &a.1)
    }

    /// Adds the accumulated light into the HDR target (inside an open render pass). The
    /// renderer fuses this into the tonemap instead; kept for the bench and for targets
    /// without a tonemap.
    pub fn resolve(&self, pass: &mut wgpu::RenderPass<'_>, frame: &FrameResources) {
        let Some((_, _, group)) = self.accum.as_ref() else {
            return;
        };
        pass.set_pipeline(&self.resolve);
        pass.set_bind_group(0, &frame.splat_group, &[0]);
        pass.set_bind_group(1, &self.empty_group, &[]);
        pass.set_bind_group(2, group, &[]);
        pass.draw(0..3, 0..1);
    }
}
