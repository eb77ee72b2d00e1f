//! Bloom: the HDR image thresholded into a half-resolution
//! chain of levels, blurred down and back up (`shaders/bloom.wgsl`); the tonemap adds the result.
//! Nothing is recorded when the effect has no bloom.

use crate::effect::Bloom;
use crate::gpu::GpuContext;
use crate::render::HDR_FORMAT;
use crate::shaders::{ShaderError, ShaderLibrary, create_checked};

/// The bloom passes and their chain of levels.
pub struct BloomPass {
    layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    pipelines: BloomPipelines,
    sampler: wgpu::Sampler,
    uniform: wgpu::Buffer,
    /// Bound in place of the glow layer when there is none.
    no_glow: wgpu::TextureView,
    chain: Option<Chain>,
}

struct BloomPipelines {
    /// Indexed by `quarter + 2 · glow`: to a quarter of the resolution (draft), with the
    /// draft glow layer.
    prefilter: [wgpu::RenderPipeline; 4],
    down: wgpu::RenderPipeline,
    up: wgpu::RenderPipeline,
}

/// The chain: level 0 is half the target size (a quarter in draft), each next level half
/// the last; one texture per level.
struct Chain {
    target_size: (u32, u32),
    levels: u32,
    quarter: bool,
    views: Vec<wgpu::TextureView>,
    /// `groups[m]` reads level m (the source of the down pass m → m+1 and of the up pass
    /// m → m−1), built with the chain.
    groups: Vec<wgpu::BindGroup>,
}

impl BloomPass {
    /// Builds the pipelines from `lib`.
    pub fn new(ctx: &GpuContext, lib: &ShaderLibrary) -> Result<Self, ShaderError> {
        let d = &ctx.device;
        let layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("BloomPass::layout"),
            entries: &[
                crate::gpu::fragment_texture_entry(0, true),
                crate::gpu::fragment_sampler_entry(1),
                crate::gpu::fragment_buffer_entry(2, wgpu::BufferBindingType::Uniform),
                crate::gpu::fragment_texture_entry(4, true),
            ],
        });
        let pipeline_layout = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("BloomPass::pipeline_layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipelines = Self::build(ctx, lib, &pipeline_layout)?;
        Ok(Self {
            layout,
            pipeline_layout,
            pipelines,
            sampler: d.create_sampler(&wgpu::SamplerDescriptor {
                label: Some("BloomPass::sampler"),
                mag_filter: wgpu::FilterMode::Linear,
                min_filter: wgpu::FilterMode::Linear,
                ..Default::default()
            }),
            uniform: d.create_buffer(&wgpu::BufferDescriptor {
                label: Some("BloomPass::uniform"),
                size: 16,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            no_glow: crate::gpu::texture_2d(
                d,
                "BloomPass::no_glow",
                (1, 1),
                1,
                HDR_FORMAT,
                wgpu::TextureUsages::TEXTURE_BINDING,
            )
            .create_view(&Default::default()),
            chain: None,
        })
    }

    fn build(
        ctx: &GpuContext,
        lib: &ShaderLibrary,
        layout: &wgpu::PipelineLayout,
    ) -> Result<BloomPipelines, ShaderError> {
        let composed = lib.compose("bloom.wgsl")?;
        create_checked(&ctx.device, &composed, lib, |module| {
            let make = |fs: &str, blend: Option<wgpu::BlendState>, variant: usize| {
                let b = |bit: usize| if variant & bit != 0 { 1.0 } else { 0.0 };
                let constants = [("QUARTER", b(1)), ("GLOW", b(2))];
                crate::render::simple_pipeline(
                    ctx,
                    &format!("BloomPass::{fs}"),
                    layout,
                    module,
                    ("vs_main", fs),
                    wgpu::ColorTargetState {
                        format: HDR_FORMAT,
                        blend,
                        write_mask: wgpu::ColorWrites::ALL,
                    },
                    &constants,
                    wgpu::PrimitiveTopology::TriangleList,
                )
            };
            BloomPipelines {
                prefilter: std::array::from_fn(|v| make("prefilter", None, v)),
                down: make("down", None, 0),
                up: make("up", Some(crate::render::billboard::ADDITIVE), 0),
            }
        })
    }

    /// Rebuilds the pipelines; keeps the old ones on error.
    pub fn rebuild(&mut self, ctx: &GpuContext, lib: &ShaderLibrary) -> Result<(), ShaderError> {
        self.pipelines = Self::build(ctx, lib, &self.pipeline_layout)?;
        Ok(())
    }

    /// A bind group reading `src` (and the `glow` layer, for the prefilter).
    fn group(
        &self,
        ctx: &GpuContext,
        src: &wgpu::TextureView,
        glow: Option<&wgpu::TextureView>,
    ) -> wgpu::BindGroup {
        ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("BloomPass::group"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(src),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::Sampler(&self.sampler),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: self.uniform.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: wgpu::BindingResource::TextureView(glow.unwrap_or(&self.no_glow)),
                },
            ],
        })
    }

    fn ensure_chain(
        &mut self,
        ctx: &GpuContext,
        target_size: (u32, u32),
        levels: u32,
        quarter: bool,
    ) {
        let d = if quarter { 4 } else { 2 };
        let (w, h) = ((target_size.0 / d).max(1), (target_size.1 / d).max(1));
        // No level smaller than 1 × 1.
        let levels = levels.clamp(1, 32 - w.min(h).leading_zeros());
        let stale = self.chain.as_ref().is_none_or(|c| {
            c.target_size != target_size || c.levels != levels || c.quarter != quarter
        });
        if stale {
            // One texture per level, not the mips of one texture: on lavapipe the chain
            // of mips cost about twice as much (draft campfire bloom 5.2 → 2.5 ms), and
            // GPUs do not mind.
            let views: Vec<wgpu::TextureView> = (0..levels)
                .map(|m| {
                    crate::gpu::texture_2d(
                        &ctx.device,
                        "BloomPass::level",
                        ((w >> m).max(1), (h >> m).max(1)),
                        1,
                        HDR_FORMAT,
                        wgpu::TextureUsages::RENDER_ATTACHMENT
                            | wgpu::TextureUsages::TEXTURE_BINDING,
                    )
                    .create_view(&Default::default())
                })
                .collect();
            let groups = views.iter().map(|v| self.group(ctx, v, None)).collect();
            self.chain = Some(Chain {
                target_size,
                levels,
                quarter,
                views,
                groups,
            });
        }
    }

    /// Records the bloom of `hdr` (plus the draft `glow` layer) and returns the view the
    /// tonemap adds (level 0 of the chain). `draft` starts the chain at a quarter of the
    /// resolution, one level shorter (the same reach): the half-resolution passes are
    /// most of the bloom's cost on a software rasteriser.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &mut self,
        ctx: &GpuContext,
        enc: &mut wgpu::CommandEncoder,
        hdr: &wgpu::TextureView,
        glow: Option<&wgpu::TextureView>,
        target_size: (u32, u32),
        settings: &Bloom,
        draft: bool,
    ) -> Option<&wgpu::TextureView> {
        let params = [
            settings.threshold,
            0.5 * settings.threshold.max(1e-3),
            0.0,
            0.0,
        ];
        ctx.queue
            .write_buffer(&self.uniform, 0, bytemuck::cast_slice(&params));
        let quarter = draft && settings.levels > 1;
        let levels = settings.levels - u32::from(quarter);
        self.ensure_chain(ctx, target_size, levels, quarter);
        // The prefilter reads this frame's HDR target and glow layer; the chain's own bind
        // groups are built with the chain.
        let prefilter_group = self.group(ctx, hdr, glow);
        let chain = self.chain.as_ref()?;
        let p = &self.pipelines;
        let variant = usize::from(quarter) + 2 * usize::from(glow.is_some());
        full_screen_pass(
            enc,
            &p.prefilter[variant],
            &prefilter_group,
            &chain.views[0],
            false,
        );
        for m in 1..chain.views.len() {
            full_screen_pass(enc, &p.down, &chain.groups[m - 1], &chain.views[m], false);
        }
        for m in (1..chain.views.len()).rev() {
            full_screen_pass(enc, &p.up, &chain.groups[m], &chain.views[m - 1], true);
        }
        chain.views.first()
    }
}

/// One full-screen triangle of `pipeline` into `dst` (cleared first unless `load`).
fn full_screen_pass(
    enc: &mut wgpu::CommandEncoder,
    pipeline: &wgpu::RenderPipeline,
    bind: &wgpu::BindGroup,
    dst: &wgpu::TextureView,
    load: bool,
) {
    let mut rp = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("BloomPass::pass"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: dst,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: if load {
                    wgpu::LoadOp::Load
                } else {
                    wgpu::LoadOp::Clear(wgpu::Color::BLACK)
                },
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    rp.set_pipeline(pipeline);
    rp.set_bind_group(0, bind, &[]);
    rp.draw(0..3, 0..1);
}
