//! The billboard pass: one instanced draw of camera-facing quads per emitter, vertex
//! pulling from the state buffer the update pass just wrote.

use crate::effect::BlendMode;
use crate::gpu::GpuContext;
use crate::render::frame::{DrawItem, FrameResources};
use crate::shaders::{ShaderError, ShaderLibrary, create_checked};

/// Instanced billboards into the HDR target.
pub struct BillboardPass {
    pipeline_layout: wgpu::PipelineLayout,
    additive: wgpu::RenderPipeline,
    alpha: wgpu::RenderPipeline,
}

impl BillboardPass {
    /// Builds both blend pipelines from `lib`.
    pub fn new(
        ctx: &GpuContext,
        lib: &ShaderLibrary,
        frame: &FrameResources,
    ) -> Result<Self, ShaderError> {
        let pipeline_layout = ctx
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("BillboardPass::pipeline_layout"),
                bind_group_layouts: &[Some(&frame.frame_layout), Some(&frame.particle_layout)],
                immediate_size: 0,
            });
        let (additive, alpha) = Self::build(ctx, lib, &pipeline_layout)?;
        Ok(Self {
            pipeline_layout,
            additive,
            alpha,
        })
    }

    fn build(
        ctx: &GpuContext,
        lib: &ShaderLibrary,
        layout: &wgpu::PipelineLayout,
    ) -> Result<(wgpu::RenderPipeline, wgpu::RenderPipeline), ShaderError> {
        let composed = lib.compose("billboard.wgsl")?;
        let make = |module: &wgpu::ShaderModule, blend: wgpu::BlendState, label| {
            // The alpha pipeline draws through the back-to-front order.
            let sorted = blend != ADDITIVE;
            crate::render::simple_pipeline(
                ctx,
                label,
                layout,
                module,
                ("vs_main", "fs_main"),
                crate::render::hdr_target(blend),
                &[("SORTED", if sorted { 1.0 } else { 0.0 })],
            )
        };
        create_checked(&ctx.device, &composed, lib, |module| {
            (
                make(module, ADDITIVE, "BillboardPass::additive"),
                make(
                    module,
                    wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING,
                    "BillboardPass::alpha",
                ),
            )
        })
    }

    /// Rebuilds the pipelines; keeps the old ones on error.
    pub fn rebuild(&mut self, ctx: &GpuContext, lib: &ShaderLibrary) -> Result<(), ShaderError> {
        let (additive, alpha) = Self::build(ctx, lib, &self.pipeline_layout)?;
        self.additive = additive;
        self.alpha = alpha;
        Ok(())
    }

    /// Draws the billboard items into an open render pass (alpha-blended layers first,
    /// then additive ones on top).
    pub fn draw(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        frame: &FrameResources,
        items: &[DrawItem],
    ) {
        let mut sorted: Vec<&DrawItem> = items.iter().filter(|d| !d.splat).collect();
        sorted.sort_by_key(|d| match d.blend {
            BlendMode::Alpha => 0,
            BlendMode::Additive => 1,
        });
        for d in sorted {
            let Some(group) = frame.particle_group(d.key) else {
                continue;
            };
            pass.set_pipeline(match d.blend {
                BlendMode::Additive => &self.additive,
                BlendMode::Alpha => &self.alpha,
            });
            pass.set_bind_group(
                0,
                &frame.frame_group,
                &[FrameResources::look_offset(d.index)],
            );
            pass.set_bind_group(1, group, &[]);
            pass.draw(0..6, 0..d.capacity);
        }
    }
}

/// Light adds up: colour One + One, destination alpha kept.
pub const ADDITIVE: wgpu::BlendState = wgpu::BlendState {
    color: wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::One,
        operation: wgpu::BlendOperation::Add,
    },
    alpha: wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::Zero,
        dst_factor: wgpu::BlendFactor::One,
        operation: wgpu::BlendOperation::Add,
    },
};
