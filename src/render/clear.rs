//! A compute clear of HDR targets (`shaders/clear.wgsl`): the particles' passes then
//! load them instead of clearing, which the H100's small raster slice does slowly.

use crate::gpu::GpuContext;
use crate::render::HDR_FORMAT;
use crate::shaders::{ShaderError, ShaderLibrary, create_checked};

/// Targets whose bind groups a clear keeps.
const MAX_GROUPS: usize = 4;

/// The clear's pipeline.
pub struct ClearPass {
    layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    pipeline: wgpu::ComputePipeline,
    /// The groups over the last targets cleared, newest last (the composite's targets — the
    /// image and its reduced layers — change only with its size).
    groups: Vec<(wgpu::TextureView, wgpu::BindGroup)>,
}

impl ClearPass {
    /// Builds the pipeline from `lib`.
    pub fn new(ctx: &GpuContext, lib: &ShaderLibrary) -> Result<Self, ShaderError> {
        let layout = ctx
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("ClearPass::layout"),
                entries: &[wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::StorageTexture {
                        access: wgpu::StorageTextureAccess::WriteOnly,
                        format: HDR_FORMAT,
                        view_dimension: wgpu::TextureViewDimension::D2,
                    },
                    count: None,
                }],
            });
        let pipeline_layout = ctx
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("ClearPass::pipeline_layout"),
                bind_group_layouts: &[Some(&layout)],
                immediate_size: 0,
            });
        let pipeline = Self::build(ctx, lib, &pipeline_layout)?;
        Ok(Self {
            layout,
            pipeline_layout,
            pipeline,
            groups: Vec::new(),
        })
    }

    fn build(
        ctx: &GpuContext,
        lib: &ShaderLibrary,
        layout: &wgpu::PipelineLayout,
    ) -> Result<wgpu::ComputePipeline, ShaderError> {
        let composed = lib.compose("clear.wgsl")?;
        create_checked(&ctx.device, &composed, lib, |module| {
            crate::render::compute_pipeline(ctx, "ClearPass::clear", layout, module, "clear", &[])
        })
    }

    /// Rebuilds the pipeline; keeps the old one on error.
    pub fn rebuild(&mut self, ctx: &GpuContext, lib: &ShaderLibrary) -> Result<(), ShaderError> {
        self.pipeline = Self::build(ctx, lib, &self.pipeline_layout)?;
        Ok(())
    }

    /// Zeroes `target` (an HDR texture with storage usage, `size` pixels).
    pub fn record(
        &mut self,
        ctx: &GpuContext,
        enc: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        size: (u32, u32),
    ) {
        let group = match self.groups.iter().position(|(view, _)| view == target) {
            Some(k) => self.groups.remove(k),
            None => {
                let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("ClearPass::group"),
                    layout: &self.layout,
                    entries: &[wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::TextureView(target),
                    }],
                });
                (target.clone(), group)
            }
        };
        if self.groups.len() >= MAX_GROUPS {
            self.groups.remove(0);
        }
        self.groups.push(group);
        let Some((_, group)) = self.groups.last() else {
            return;
        };
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("ClearPass"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, group, &[]);
        pass.dispatch_workgroups(size.0.div_ceil(8), size.1.div_ceil(8), 1);
    }
}
