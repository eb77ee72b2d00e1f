//! The tonemap: HDR (+ the reduced-resolution layers and the bloom) → exposure → ACES
//! fit → sRGB display target.

use crate::gpu::GpuContext;
use crate::gpu::commands::CountedCompute;
use crate::gpu::types::ToneUniform;
use crate::shaders::{ShaderError, ShaderLibrary, create_checked};

/// The tonemap, a compute pass over the display image, in eight variants: with and without the bloom, the
/// reduced-resolution alpha layer and the draft glow layer.
pub struct TonemapPass {
    layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    /// Indexed by `bloom + 2 · low_alpha + 4 · glow`.
    pipelines: [wgpu::ComputePipeline; 8],
    uniform: wgpu::Buffer,
    /// Bound in place of the bloom chain when there is no bloom.
    no_bloom: wgpu::TextureView,
    sampler: wgpu::Sampler,
}

/// A layout entry seen by the compute stage.
fn compute(mut e: wgpu::BindGroupLayoutEntry) -> wgpu::BindGroupLayoutEntry {
    e.visibility = wgpu::ShaderStages::COMPUTE;
    e
}

impl TonemapPass {
    /// Builds the pass (its output: a [`crate::render::LDR_STORAGE_FORMAT`] storage view).
    pub fn new(ctx: &GpuContext, lib: &ShaderLibrary) -> Result<Self, ShaderError> {
        let layout = crate::gpu::bind_group_layout(
            ctx,
            "TonemapPass::layout",
            &[
                compute(crate::gpu::fragment_texture_entry(0, false)),
                compute(crate::gpu::fragment_buffer_entry(
                    1,
                    wgpu::BufferBindingType::Uniform,
                )),
                compute(crate::gpu::fragment_texture_entry(3, true)),
                compute(crate::gpu::fragment_sampler_entry(4)),
                compute(crate::gpu::fragment_texture_entry(5, true)),
                compute(crate::gpu::fragment_texture_entry(6, true)),
                wgpu::BindGroupLayoutEntry {
                    binding: 7,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::StorageTexture {
                        access: wgpu::StorageTextureAccess::WriteOnly,
                        format: crate::render::LDR_STORAGE_FORMAT,
                        view_dimension: wgpu::TextureViewDimension::D2,
                    },
                    count: None,
                },
            ],
        );
        let pipeline_layout = ctx
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("TonemapPass::pipeline_layout"),
                bind_group_layouts: &[Some(&layout)],
                immediate_size: 0,
            });
        let pipelines = Self::build(ctx, lib, &pipeline_layout)?;
        let uniform = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("TonemapPass::uniform"),
            size: size_of::<ToneUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let no_bloom = crate::gpu::texture_2d(
            &ctx.device,
            "TonemapPass::no_bloom",
            (1, 1),
            1,
            crate::render::HDR_FORMAT,
            wgpu::TextureUsages::TEXTURE_BINDING,
        )
        .create_view(&Default::default());
        let sampler = ctx.device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("TonemapPass::sampler"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        Ok(Self {
            layout,
            pipeline_layout,
            pipelines,
            uniform,
            no_bloom,
            sampler,
        })
    }

    fn build(
        ctx: &GpuContext,
        lib: &ShaderLibrary,
        layout: &wgpu::PipelineLayout,
    ) -> Result<[wgpu::ComputePipeline; 8], ShaderError> {
        let composed = lib.compose("tonemap.wgsl")?;
        create_checked(&ctx.device, &composed, lib, |module| {
            let make = |i: usize| {
                let (bloom, low, glow) = (i & 1 != 0, i & 2 != 0, i & 4 != 0);
                let b = |v: bool| if v { 1.0 } else { 0.0 };
                let constants = [
                    ("BLOOM", b(bloom)),
                    ("LOW_ALPHA", b(low)),
                    ("GLOW", b(glow)),
                ];
                let label = format!("TonemapPass bloom={bloom} low_alpha={low} glow={glow}");
                crate::render::compute_pipeline(ctx, &label, layout, module, "tonemap", &constants)
            };
            std::array::from_fn(make)
        })
    }

    /// Rebuilds the pipelines; keeps the old ones on error.
    pub fn rebuild(&mut self, ctx: &GpuContext, lib: &ShaderLibrary) -> Result<(), ShaderError> {
        self.pipelines = Self::build(ctx, lib, &self.pipeline_layout)?;
        Ok(())
    }

    /// Records the tonemap from `hdr` (plus `bloom`'s glow × intensity, the `low_alpha`
    /// layer and the draft `glow` layer, when given) into `out` (a storage view of
    /// `size` pixels, the HDR image's).
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        ctx: &GpuContext,
        enc: &mut wgpu::CommandEncoder,
        hdr: &wgpu::TextureView,
        bloom: Option<(&wgpu::TextureView, f32)>,
        low_alpha: Option<&wgpu::TextureView>,
        glow: Option<&wgpu::TextureView>,
        (out, size): (&wgpu::TextureView, (u32, u32)),
        exposure: f32,
    ) {
        ctx.queue.write_buffer(
            &self.uniform,
            0,
            bytemuck::bytes_of(&ToneUniform {
                exposure: [exposure, bloom.map_or(0.0, |b| b.1), 0.0, 0.0],
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
                    binding: 3,
                    resource: wgpu::BindingResource::TextureView(
                        bloom.map_or(&self.no_bloom, |b| b.0),
                    ),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: wgpu::BindingResource::Sampler(&self.sampler),
                },
                wgpu::BindGroupEntry {
                    binding: 5,
                    resource: wgpu::BindingResource::TextureView(
                        low_alpha.unwrap_or(&self.no_bloom),
                    ),
                },
                wgpu::BindGroupEntry {
                    binding: 6,
                    resource: wgpu::BindingResource::TextureView(glow.unwrap_or(&self.no_bloom)),
                },
                wgpu::BindGroupEntry {
                    binding: 7,
                    resource: wgpu::BindingResource::TextureView(out),
                },
            ],
        });
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("TonemapPass::pass"),
            timestamp_writes: None,
        });
        let variant = usize::from(bloom.is_some())
            + 2 * usize::from(low_alpha.is_some())
            + 4 * usize::from(glow.is_some());
        pass.set_pipeline(&self.pipelines[variant]);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch(size.0.div_ceil(8), size.1.div_ceil(8), 1);
    }
}
