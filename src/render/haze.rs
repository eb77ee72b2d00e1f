//! Heat haze: the distortion target the haze layers add their screen offsets into
//! (`billboard.wgsl` HAZE) and the refraction of the frame's colour by it
//! (`shaders/haze_apply.wgsl`).

use crate::gpu::GpuContext;
use crate::gpu::commands::{CountedCompute, CountedRender};
use crate::render::billboard::HAZE_FORMAT;
use crate::shaders::{ShaderError, ShaderLibrary, create_checked};

/// How many times smaller than the frame the distortion target is (keep in sync with
/// `HAZE_DOWNSCALE` in `shaders/billboard.wgsl`).
pub const HAZE_DOWNSCALE: u32 = 4;

/// The distortion target (kept while its size holds) and the refraction's pipeline.
pub struct HazePass {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
    /// The refraction by compute into an `Rgba16Float` storage target.
    compute_layout: wgpu::BindGroupLayout,
    compute: wgpu::ComputePipeline,
    sampler: wgpu::Sampler,
    target: Option<((u32, u32), wgpu::Texture, wgpu::TextureView)>,
}

impl HazePass {
    /// Builds the refraction into targets of `format` from `lib`.
    pub fn new(
        ctx: &GpuContext,
        lib: &ShaderLibrary,
        format: wgpu::TextureFormat,
    ) -> Result<Self, ShaderError> {
        let layout = crate::gpu::bind_group_layout(
            ctx,
            "HazePass::layout",
            &[
                crate::gpu::fragment_texture_entry(0, true),
                crate::gpu::fragment_texture_entry(1, true),
                crate::gpu::fragment_sampler_entry(2),
            ],
        );

        let compute_layout = crate::gpu::bind_group_layout(
            ctx,
            "HazePass::compute_layout",
            &[
                compute_entry(0, texture_entry()),
                compute_entry(1, texture_entry()),
                compute_entry(
                    2,
                    wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                ),
                compute_entry(
                    3,
                    wgpu::BindingType::StorageTexture {
                        access: wgpu::StorageTextureAccess::WriteOnly,
                        format: COMPUTE_FORMAT,
                        view_dimension: wgpu::TextureViewDimension::D2,
                    },
                ),
            ],
        );
        let (pipeline, compute) = pipelines(ctx, lib, [&layout, &compute_layout], format)?;
        let sampler = ctx.device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("HazePass::sampler"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        Ok(Self {
            layout,
            pipeline,
            compute_layout,
            compute,
            sampler,
            target: None,
        })
    }

    /// The distortion target for a frame of `frame` pixels, `downscale` times smaller
    /// ([`HAZE_DOWNSCALE`] for a frame's refraction, 1 for the export's pass; made on
    /// first need), cleared to `clear` (no offset: transparent) and open in a pass for
    /// the haze layers' draws.
    pub fn begin<'e>(
        &mut self,
        ctx: &GpuContext,
        enc: &'e mut wgpu::CommandEncoder,
        (frame, downscale): ((u32, u32), u32),
        clear: wgpu::Color,
    ) -> wgpu::RenderPass<'e> {
        let size = crate::render::reduced(frame, downscale.max(1));
        if self.target.as_ref().is_some_and(|(s, _, _)| *s != size) {
            self.target = None;
        }
        let (_, _, view) = self.target.get_or_insert_with(|| {
            let texture = crate::gpu::texture_2d(
                &ctx.device,
                "HazePass::distortion",
                size,
                1,
                HAZE_FORMAT,
                wgpu::TextureUsages::RENDER_ATTACHMENT
                    | wgpu::TextureUsages::TEXTURE_BINDING
                    | wgpu::TextureUsages::COPY_SRC,
            );
            let view = texture.create_view(&Default::default());
            (size, texture, view)
        });
        let clear = wgpu::LoadOp::Clear(clear);
        crate::gpu::color_pass(enc, view, clear, "HazePass::distortion")
    }

    /// The distortion target as last drawn (rg: offsets in uv units, a: weights).
    pub fn distortion(&self) -> Option<&wgpu::Texture> {
        self.target.as_ref().map(|t| &t.1)
    }

    /// Refracts `scene` (a copy of the frame's colour, the frame's size) into `target`,
    /// every pixel written, by the distortion target: by compute where `target` is an
    /// `Rgba16Float` storage texture, else by a full-screen draw.
    pub fn refract(
        &self,
        ctx: &GpuContext,
        enc: &mut wgpu::CommandEncoder,
        scene: &wgpu::TextureView,
        target: &wgpu::TextureView,
    ) {
        let Some((_, _, distortion)) = &self.target else {
            return;
        };
        let texture = target.texture();
        let entries = |extra| group_entries([scene, distortion], &self.sampler, extra);
        if texture.format() == COMPUTE_FORMAT
            && texture
                .usage()
                .contains(wgpu::TextureUsages::STORAGE_BINDING)
        {
            let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("HazePass::compute_group"),
                layout: &self.compute_layout,
                entries: &entries(Some(target)),
            });
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("HazePass::refract"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.compute);
            pass.set_bind_group(0, &group, &[]);
            pass.dispatch(texture.width().div_ceil(8), texture.height().div_ceil(8), 1);
            return;
        }
        let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("HazePass::group"),
            layout: &self.layout,
            entries: &entries(None),
        });
        let load = wgpu::LoadOp::Load;
        let mut pass = crate::gpu::color_pass(enc, target, load, "HazePass::refract");
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.counted_draw(0..3, 0..1);
    }
}

/// The refraction's bindings: the scene copy and the distortion, the sampler, and (the
/// compute path) the target.
fn group_entries<'a>(
    views: [&'a wgpu::TextureView; 2],
    sampler: &'a wgpu::Sampler,
    target: Option<&'a wgpu::TextureView>,
) -> Vec<wgpu::BindGroupEntry<'a>> {
    let view = |binding, view| wgpu::BindGroupEntry {
        binding,
        resource: wgpu::BindingResource::TextureView(view),
    };
    let mut entries = vec![
        view(0, views[0]),
        view(1, views[1]),
        wgpu::BindGroupEntry {
            binding: 2,
            resource: wgpu::BindingResource::Sampler(sampler),
        },
    ];
    entries.extend(target.map(|t| view(3, t)));
    entries
}

/// The storage format the compute refraction writes.
const COMPUTE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// A filterable float texture binding.
fn texture_entry() -> wgpu::BindingType {
    wgpu::BindingType::Texture {
        sample_type: wgpu::TextureSampleType::Float { filterable: true },
        view_dimension: wgpu::TextureViewDimension::D2,
        multisampled: false,
    }
}

/// A compute-stage binding.
fn compute_entry(binding: u32, ty: wgpu::BindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty,
        count: None,
    }
}

/// A pipeline layout of one group.
fn one_group(ctx: &GpuContext, layout: &wgpu::BindGroupLayout) -> wgpu::PipelineLayout {
    ctx.device
        .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("HazePass::pipeline_layout"),
            bind_group_layouts: &[Some(layout)],
            immediate_size: 0,
        })
}

/// The refraction's pipelines from one module: the full-screen draw into `format`
/// (`layouts[0]`) and the compute (`layouts[1]`).
fn pipelines(
    ctx: &GpuContext,
    lib: &ShaderLibrary,
    layouts: [&wgpu::BindGroupLayout; 2],
    format: wgpu::TextureFormat,
) -> Result<(wgpu::RenderPipeline, wgpu::ComputePipeline), ShaderError> {
    let [draw_layout, compute_layout] = layouts.map(|l| one_group(ctx, l));
    let composed = lib.compose("haze_apply.wgsl")?;
    create_checked(&ctx.device, &composed, lib, |module| {
        let compute = crate::gpu::compute_pipeline(
            ctx,
            "HazePass::compute",
            &compute_layout,
            module,
            "cs_main",
            &[],
        );
        (draw(ctx, module, &draw_layout, format), compute)
    })
}

/// The full-screen draw (`vs_main`, `fs_main`) into `format`.
fn draw(
    ctx: &GpuContext,
    module: &wgpu::ShaderModule,
    pipeline_layout: &wgpu::PipelineLayout,
    format: wgpu::TextureFormat,
) -> wgpu::RenderPipeline {
    crate::gpu::render_pipeline(
        ctx,
        crate::gpu::PipelineParts {
            label: "HazePass",
            layout: Some(pipeline_layout),
            module,
            entries: ("vs_main", "fs_main"),
            buffers: &[],
            depth_stencil: None,
            multisample: Default::default(),
            targets: &[Some(format.into())],
        },
    )
}
