//! The composite: HDR (+ the compute splat's light, fused here) → exposure → ACES fit →
//! sRGB display target.

use crate::gpu::GpuContext;
use crate::gpu::types::ToneUniform;
use crate::shaders::{ShaderError, ShaderLibrary, create_checked};

/// A full-screen tonemap pass, in two variants: with and without the splat's light.
pub struct TonemapPass {
    layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    plain: wgpu::RenderPipeline,
    with_splat: wgpu::RenderPipeline,
    uniform: wgpu::Buffer,
    /// Bound in place of the splat buffer when nothing was splatted.
    no_splat: wgpu::Buffer,
    format: wgpu::TextureFormat,
}

impl TonemapPass {
    /// Builds the pass for an output `format`.
    pub fn new(
        ctx: &GpuContext,
        lib: &ShaderLibrary,
        format: wgpu::TextureFormat,
    ) -> Result<Self, ShaderError> {
        let layout = ctx
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("TonemapPass::layout"),
                entries: &[
                    wgpu::BindGroupLayoutEntry {
                        binding: 0,
                        visibility: wgpu::ShaderStages::FRAGMENT,
                        ty: wgpu::BindingType::Texture {
                            sample_type: wgpu::TextureSampleType::Float { filterable: false },
                            view_dimension: wgpu::TextureViewDimension::D2,
                            multisampled: false,
                        },
                        count: None,
                    },
                    wgpu::BindGroupLayoutEntry {
                        binding: 1,
                        visibility: wgpu::ShaderStages::FRAGMENT,
                        ty: wgpu::BindingType::Buffer {
                            ty: wgpu::BufferBindingType::Uniform,
                            has_dynamic_offset: false,
                            min_binding_size: None,
                        },
                        count: None,
                    },
                    wgpu::BindGroupLayoutEntry {
                        binding: 2,
                        visibility: wgpu::ShaderStages::FRAGMENT,
                        ty: wgpu::BindingType::Buffer {
                            ty: wgpu::BufferBindingType::Storage { read_only: true },
                            has_dynamic_offset: false,
                            min_binding_size: None,
                        },
                        count: None,
                    },
                ],
            });
        let pipeline_layout = ctx
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("TonemapPass::pipeline_layout"),
                bind_group_layouts: &[Some(&layout)],
                immediate_size: 0,
            });
        let (plain, with_splat) = Self::build(ctx, lib, &pipeline_layout, format)?;
        let uniform = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("TonemapPass::uniform"),
            size: size_of::<ToneUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let no_splat = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("TonemapPass::no_splat"),
            size: 16,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        Ok(Self {
            layout,
            pipeline_layout,
            plain,
            with_splat,
            uniform,
            no_splat,
            format,
        })
    }

    fn build(
        ctx: &GpuContext,
        lib: &ShaderLibrary,
        layout: &wgpu::PipelineLayout,
        format: wgpu::TextureFormat,
    ) -> Result<(wgpu::RenderPipeline, wgpu::RenderPipeline), ShaderError> {
        let composed = lib.compose("tonemap.wgsl")?;
        create_checked(&ctx.device, &composed, lib, |module| {
            let make = |splat: bool| {
                let constants = [("SPLAT", if splat { 1.0 } else { 0.0 })];
                crate::render::simple_pipeline(
                    ctx,
                    if splat {
                        "TonemapPass::with_splat"
                    } else {
                        "TonemapPass::plain"
                    },
                    layout,
                    module,
                    ("vs_main", "fs_main"),
                    format.into(),
                    &constants,
                )
            };
            (make(false), make(true))
        })
    }

    /// Rebuilds the pipelines; keeps the old ones on error.
    pub fn rebuild(&mut self, ctx: &GpuContext, lib: &ShaderLibrary) -> Result<(), ShaderError> {
        let (plain, with_splat) = Self::build(ctx, lib, &self.pipeline_layout, self.format)?;
        self.plain = plain;
        self.with_splat = with_splat;
        Ok(())
    }

    /// Records the tonemap from `hdr` (plus `splat`'s accumulated light, when given) into
    /// `out`.
    pub fn record(
        &self,
        ctx: &GpuContext,
        enc: &mut wgpu::CommandEncoder,
        hdr: &wgpu::TextureView,
        splat: Option<&wgpu::Buffer>,
        out: &wgpu::TextureView,
        exposure: f32,
    ) {
        ctx.queue.write_buffer(
            &self.uniform,
            0,
            bytemuck::bytes_of(&ToneUniform {
                exposure: [exposure, 0.0, 0.0, 0.0],
            }),
        );
        let bind_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("TonemapPass::bind_group"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(hdr),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: self.uniform.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: splat.unwrap_or(&self.no_splat).as_entire_binding(),
                },
            ],
        });
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("TonemapPass::pass"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: out,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(if splat.is_some() {
            &self.with_splat
        } else {
            &self.plain
        });
        pass.set_bind_group(0, &bind_group, &[]);
        pass.draw(0..3, 0..1);
    }
}
