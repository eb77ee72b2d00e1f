//! A single-sample copy of a host's multisampled depth buffer
//! (`shaders/depth_resolve.wgsl`): the passes that sample the host's depth bind
//! `texture_depth_2d`, which a multisampled texture cannot be bound as.

use crate::gpu::GpuContext;
use crate::gpu::commands::CountedRender;
use crate::shaders::{ShaderError, ShaderLibrary, create_checked};

/// The resolve's pipeline and its target (kept while the size holds).
pub struct DepthResolvePass {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
    /// The single-sample copy, its size, and the group over the source it was made for.
    target: Option<Resolved>,
}

/// A resolve target and the group over its source.
struct Resolved {
    size: (u32, u32),
    view: wgpu::TextureView,
    source: wgpu::TextureView,
    group: wgpu::BindGroup,
}

/// The copy's format: what the depth-sampling passes read.
const RESOLVED_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

impl DepthResolvePass {
    /// Builds the pipeline from `lib`.
    pub fn new(ctx: &GpuContext, lib: &ShaderLibrary) -> Result<Self, ShaderError> {
        let layout = crate::gpu::bind_group_layout(
            ctx,
            "DepthResolvePass::layout",
            &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Depth,
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: true,
                },
                count: None,
            }],
        );
        let pipeline_layout = ctx
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("DepthResolvePass::pipeline_layout"),
                bind_group_layouts: &[Some(&layout)],
                immediate_size: 0,
            });
        let composed = lib.compose("depth_resolve.wgsl")?;
        let pipeline = create_checked(&ctx.device, &composed, lib, |module| {
            crate::gpu::render_pipeline(
                ctx,
                crate::gpu::PipelineParts {
                    label: "DepthResolvePass",
                    layout: Some(&pipeline_layout),
                    module,
                    entries: ("vs", "fs"),
                    buffers: &[],
                    depth_stencil: Some(wgpu::DepthStencilState {
                        format: RESOLVED_FORMAT,
                        depth_write_enabled: Some(true),
                        depth_compare: Some(wgpu::CompareFunction::Always),
                        stencil: Default::default(),
                        bias: Default::default(),
                    }),
                    multisample: Default::default(),
                    targets: &[],
                },
            )
        })?;
        Ok(Self {
            layout,
            pipeline,
            target: None,
        })
    }

    /// Records the copy of `source` (a multisampled view of a depth aspect, `size`
    /// pixels) and returns the single-sample view the depth-sampling passes bind.
    pub fn record(
        &mut self,
        ctx: &GpuContext,
        enc: &mut wgpu::CommandEncoder,
        source: &wgpu::TextureView,
        size: (u32, u32),
    ) -> wgpu::TextureView {
        let t = match self.target.take() {
            Some(t) if t.size == size && &t.source == source => t,
            old => self.resolved(ctx, source, size, old),
        };
        let t = self.target.insert(t);
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("DepthResolvePass"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &t.view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(0.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            ..Default::default()
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &t.group, &[]);
        pass.counted_draw(0..3, 0..1);
        drop(pass);
        t.view.clone()
    }

    /// A target of `size` (the `old` one's while the size holds) and the group over
    /// `source`.
    fn resolved(
        &self,
        ctx: &GpuContext,
        source: &wgpu::TextureView,
        size: (u32, u32),
        old: Option<Resolved>,
    ) -> Resolved {
        let view = match old.filter(|t| t.size == size) {
            Some(t) => t.view.clone(),
            None => crate::gpu::texture_2d(
                &ctx.device,
                "DepthResolvePass::target",
                size,
                1,
                RESOLVED_FORMAT,
                wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            )
            .create_view(&Default::default()),
        };
        let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("DepthResolvePass::group"),
            layout: &self.layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(source),
            }],
        });
        Resolved {
            size,
            view,
            source: source.clone(),
            group,
        }
    }
}
