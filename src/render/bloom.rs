//! Bloom: the HDR image thresholded into a half-resolution
//! chain of levels, blurred down and back up (`shaders/bloom.wgsl`, compute passes); the
//! tonemap adds the result. Nothing is recorded when the effect has no bloom.

use crate::effect::Bloom;
use crate::gpu::GpuContext;
use crate::gpu::commands::CountedCompute;
use crate::render::HDR_FORMAT;
use crate::shaders::{ShaderError, ShaderLibrary, create_checked};

/// The bloom passes and their chain of levels.
pub struct BloomPass {
    layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    pipelines: BloomPipelines,
    sampler: wgpu::Sampler,
    uniform: wgpu::Buffer,
    /// Bound in place of the glow layer and the `below` level when there is none.
    placeholder: wgpu::TextureView,
    chain: Option<Chain>,
}

struct BloomPipelines {
    /// Indexed by `quarter + 2 · glow`: to a quarter of the resolution (draft), with the
    /// draft glow layer.
    prefilter: [wgpu::ComputePipeline; 4],
    down: wgpu::ComputePipeline,
    up: wgpu::ComputePipeline,
}

/// The chain: level 0 is half the target size (a quarter in draft), each next level half
/// the last. `down[m]` holds the thresholded image blurred down to level m; `up[m]` is
/// `down[m]` plus the tent-upsampled `up[m + 1]` (the last level's is its down level).
struct Chain {
    target_size: (u32, u32),
    levels: u32,
    quarter: bool,
    down: Vec<wgpu::TextureView>,
    up: Vec<wgpu::TextureView>,
    /// Workgroups (8 × 8 pixels) across level m.
    groups_of: Vec<(u32, u32)>,
    /// `down_groups[m]` writes down level m + 1 from level m.
    down_groups: Vec<wgpu::BindGroup>,
    /// `up_groups[m]` writes up level m (from level m + 1).
    up_groups: Vec<wgpu::BindGroup>,
}

impl Chain {
    /// The view the tonemap reads: the top of the up chain.
    fn result(&self) -> Option<&wgpu::TextureView> {
        self.up.first().or(self.down.first())
    }
}

/// What one bloom pass reads and writes.
struct Io<'a> {
    src: &'a wgpu::TextureView,
    dst: &'a wgpu::TextureView,
    glow: Option<&'a wgpu::TextureView>,
    below: Option<&'a wgpu::TextureView>,
}

impl BloomPass {
    /// Builds the pipelines from `lib`.
    pub fn new(ctx: &GpuContext, lib: &ShaderLibrary) -> Result<Self, ShaderError> {
        let d = &ctx.device;
        let c = wgpu::ShaderStages::COMPUTE;
        let texture = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: c,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: true },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        };
        let layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("BloomPass::layout"),
            entries: &[
                texture(0),
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: c,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: c,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 3,
                    visibility: c,
                    ty: wgpu::BindingType::StorageTexture {
                        access: wgpu::StorageTextureAccess::WriteOnly,
                        format: HDR_FORMAT,
                        view_dimension: wgpu::TextureViewDimension::D2,
                    },
                    count: None,
                },
                texture(4),
                texture(5),
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
            placeholder: crate::gpu::texture_2d(
                d,
                "BloomPass::placeholder",
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
            let make = |entry: &str, variant: usize| {
                let b = |bit: usize| if variant & bit != 0 { 1.0 } else { 0.0 };
                let constants = [("QUARTER", b(1)), ("GLOW", b(2))];
                let label = format!("BloomPass::{entry}");
                crate::render::compute_pipeline(ctx, &label, layout, module, entry, &constants)
            };
            BloomPipelines {
                prefilter: std::array::from_fn(|v| make("prefilter", v)),
                down: make("down", 0),
                up: make("up", 0),
            }
        })
    }

    /// Rebuilds the pipelines; keeps the old ones on error.
    pub fn rebuild(&mut self, ctx: &GpuContext, lib: &ShaderLibrary) -> Result<(), ShaderError> {
        self.pipelines = Self::build(ctx, lib, &self.pipeline_layout)?;
        Ok(())
    }

    /// A bind group for one pass.
    fn group(&self, ctx: &GpuContext, io: Io<'_>) -> wgpu::BindGroup {
        use wgpu::BindingResource::TextureView as view;
        ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("BloomPass::group"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: view(io.src),
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
                    binding: 3,
                    resource: view(io.dst),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: view(io.glow.unwrap_or(&self.placeholder)),
                },
                wgpu::BindGroupEntry {
                    binding: 5,
                    resource: view(io.below.unwrap_or(&self.placeholder)),
                },
            ],
        })
    }

    /// The chain for a target of `target_size`, made anew when it changes.
    fn ensure_chain(
        &mut self,
        ctx: &GpuContext,
        target_size: (u32, u32),
        levels: u32,
        quarter: bool,
    ) {
        let d = if quarter { 4 } else { 2 };
        let (w, h) = ((target_size.0 / d).max(1), (target_size.1 / d).max(1));
        let levels = levels.clamp(1, 32 - w.min(h).leading_zeros());
        let stale = self.chain.as_ref().is_none_or(|c| {
            c.target_size != target_size || c.levels != levels || c.quarter != quarter
        });
        if !stale {
            return;
        }
        let dims = |m: u32| ((w >> m).max(1), (h >> m).max(1));
        let groups_of = (0..levels)
            .map(|m| (dims(m).0.div_ceil(8), dims(m).1.div_ceil(8)))
            .collect();
        let level = |m: u32| {
            crate::gpu::texture_2d(
                &ctx.device,
                "BloomPass::level",
                dims(m),
                1,
                HDR_FORMAT,
                wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING,
            )
            .create_view(&Default::default())
        };
        let down: Vec<wgpu::TextureView> = (0..levels).map(level).collect();
        let up: Vec<wgpu::TextureView> = (0..levels - 1).map(level).collect();
        let down_groups = (1..levels as usize)
            .map(|m| {
                let io = Io {
                    src: &down[m - 1],
                    dst: &down[m],
                    glow: None,
                    below: None,
                };
                self.group(ctx, io)
            })
            .collect();
        let up_groups = (0..up.len())
            .map(|m| {
                let src = if m + 1 == up.len() {
                    &down[m + 1]
                } else {
                    &up[m + 1]
                };
                let io = Io {
                    src,
                    dst: &up[m],
                    glow: None,
                    below: Some(&down[m]),
                };
                self.group(ctx, io)
            })
            .collect();
        self.chain = Some(Chain {
            target_size,
            levels,
            quarter,
            down,
            up,
            groups_of,
            down_groups,
            up_groups,
        });
    }

    /// Records the bloom of `hdr` (plus the draft `glow` layer) and returns the view the
    /// tonemap adds (the top of the chain). `draft` starts the chain at a quarter of the
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
        let chain = self.chain.as_ref()?;
        let prefilter_group = self.group(
            ctx,
            Io {
                src: hdr,
                dst: chain.down.first()?,
                glow,
                below: None,
            },
        );
        let p = &self.pipelines;
        let variant = usize::from(quarter) + 2 * usize::from(glow.is_some());
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("BloomPass"),
            timestamp_writes: None,
        });
        let mut run = |pipeline, group, level: usize| {
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, group, &[]);
            let (x, y) = chain.groups_of[level];
            pass.dispatch(x, y, 1);
        };
        run(&p.prefilter[variant], &prefilter_group, 0);
        for (m, group) in chain.down_groups.iter().enumerate() {
            run(&p.down, group, m + 1);
        }
        for (m, group) in chain.up_groups.iter().enumerate().rev() {
            run(&p.up, group, m);
        }
        drop(pass);
        chain.result()
    }
}
