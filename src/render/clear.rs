//! A compute clear of HDR targets (`shaders/clear.wgsl`): the particles' passes then
//! load them instead of clearing, which the H100's small raster slice does slowly.

use crate::gpu::GpuContext;
use crate::gpu::commands::CountedCompute;
use crate::render::image_groups::ImageGroups;
use crate::shaders::{ShaderError, ShaderLibrary, create_checked};

/// The clear's pipeline.
pub struct ClearPass {
    /// The target's layout and groups (the composite's targets — the image and its reduced
    /// layers — change only with its size).
    images: ImageGroups,
    pipeline_layout: wgpu::PipelineLayout,
    pipeline: wgpu::ComputePipeline,
}

impl ClearPass {
    /// Builds the pipeline from `lib`.
    pub fn new(ctx: &GpuContext, lib: &ShaderLibrary) -> Result<Self, ShaderError> {
        let images = ImageGroups::new(
            ctx,
            "ClearPass::image",
            0,
            wgpu::StorageTextureAccess::WriteOnly,
        );
        let pipeline_layout = ctx
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("ClearPass::pipeline_layout"),
                bind_group_layouts: &[Some(images.layout())],
                immediate_size: 0,
            });
        let pipeline = Self::build(ctx, lib, &pipeline_layout)?;
        Ok(Self {
            images,
            pipeline_layout,
            pipeline,
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
        let group = self.images.group(ctx, target);
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("ClearPass"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, group, &[]);
        pass.dispatch(size.0.div_ceil(8), size.1.div_ceil(8), 1);
    }
}
