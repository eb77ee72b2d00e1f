//! The billboard pass: camera-facing quads, four vertices each, pulled from the state
//! buffer the update pass just wrote: one instance per quad over a six-index buffer
//! (two triangles on four shared vertices; the shader reads quad = instance), or cut to
//! an octagon where the sprite leaves its corners empty (eighteen indices over eight).

use crate::gpu::commands::CountedRender;
use std::collections::HashMap;

use wgpu::util::DeviceExt;

use crate::gpu::GpuContext;
use crate::render::frame::{DrawItem, FrameResources, LookVariant};
use crate::shaders::{ShaderError, ShaderLibrary, create_checked};

/// What the billboards draw into: the colour format, the depth buffer they test against
/// (read-only) and the sample count — the editor's HDR target, or a host's pass.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DrawTarget {
    /// The colour attachment's format.
    pub color_format: wgpu::TextureFormat,
    /// The depth attachment's format and the test (particles never write depth).
    pub depth: Option<(wgpu::TextureFormat, wgpu::CompareFunction)>,
    /// Samples per pixel of the attachments.
    pub sample_count: u32,
}

impl DrawTarget {
    /// The renderer's own HDR target: no depth, one sample.
    pub fn hdr() -> Self {
        Self {
            color_format: crate::render::HDR_FORMAT,
            depth: None,
            sample_count: 1,
        }
    }

    /// The depth state of a draw into this target: tested with `compare` (the target's
    /// own test when `None`), never written.
    pub fn read_only_depth(
        &self,
        compare: Option<wgpu::CompareFunction>,
    ) -> Option<wgpu::DepthStencilState> {
        self.depth.map(|(format, own)| wgpu::DepthStencilState {
            format,
            depth_write_enabled: Some(false),
            depth_compare: Some(compare.unwrap_or(own)),
            stencil: Default::default(),
            bias: Default::default(),
        })
    }

    /// The multisample state of a draw into this target.
    pub fn multisample(&self) -> wgpu::MultisampleState {
        wgpu::MultisampleState {
            count: self.sample_count.max(1),
            ..Default::default()
        }
    }
}

/// Instanced billboards into the HDR target, one pipeline per look variant (built on
/// first use), one sprite bind group per texture.
pub struct BillboardPass {
    target: DrawTarget,
    /// Group 3: the host's depth, sampled for soft edges.
    depth_layout: wgpu::BindGroupLayout,
    /// Group 3 now: the host's depth, or a 1×1 placeholder.
    depth_group: wgpu::BindGroup,
    /// The host depth view `depth_group` is over (`None`: the placeholder).
    depth_view: Option<wgpu::TextureView>,
    /// The 1×1 placeholder bound when no host depth is sampled.
    no_depth: wgpu::TextureView,
    /// Two triangles over a quad's four vertices: 0 1 2, 2 1 3.
    quad_indices: wgpu::Buffer,
    pipeline_layout: wgpu::PipelineLayout,
    module: wgpu::ShaderModule,
    pipelines: HashMap<LookVariant, Option<wgpu::RenderPipeline>>,
    sprites: crate::render::sprites::SpriteGroups,
}

impl BillboardPass {
    /// Builds the basic additive and alpha pipelines from `lib`.
    pub fn new(
        ctx: &GpuContext,
        lib: &ShaderLibrary,
        frame: &FrameResources,
        target: DrawTarget,
    ) -> Result<Self, ShaderError> {
        let depth_layout = crate::gpu::bind_group_layout(
            ctx,
            "BillboardPass::depth_layout",
            &[crate::gpu::depth_texture_entry(
                0,
                wgpu::ShaderStages::FRAGMENT,
            )],
        );
        let no_depth = crate::gpu::placeholder_depth(&ctx.device, "BillboardPass::no_depth");
        let depth_group = Self::depth_group(ctx, &depth_layout, &no_depth);
        let sprite_layout = crate::gpu::bind_group_layout(
            ctx,
            "BillboardPass::sprite_layout",
            &[
                crate::gpu::fragment_texture_entry(0, true),
                crate::gpu::fragment_sampler_entry(1),
            ],
        );
        let pipeline_layout = ctx
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("BillboardPass::pipeline_layout"),
                bind_group_layouts: &[
                    Some(&frame.frame_layout),
                    Some(&frame.particle_layout),
                    Some(&sprite_layout),
                    Some(&depth_layout),
                ],
                immediate_size: 0,
            });
        let (module, pipelines) = Self::build(ctx, lib, &pipeline_layout, target)?;
        let quad_indices = ctx
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("BillboardPass::quad_indices"),
                contents: bytemuck::cast_slice(&QUAD_AND_OCTAGON),
                usage: wgpu::BufferUsages::INDEX,
            });
        Ok(Self {
            target,
            depth_layout,
            depth_group,
            depth_view: None,
            no_depth,
            quad_indices,
            pipeline_layout,
            module,
            pipelines,
            sprites: crate::render::sprites::SpriteGroups::new(
                "BillboardPass::sprite_group",
                sprite_layout,
            ),
        })
    }

    fn pipeline(
        ctx: &GpuContext,
        layout: &wgpu::PipelineLayout,
        module: &wgpu::ShaderModule,
        v: LookVariant,
        target: DrawTarget,
    ) -> wgpu::RenderPipeline {
        // Heat haze adds offsets into the distortion target (no depth attachment: the soft
        // edges against the host's depth hide it behind geometry).
        let target = match v.haze {
            true => DrawTarget {
                color_format: HAZE_FORMAT,
                depth: None,
                sample_count: 1,
            },
            false => target,
        };
        let blend = if v.motion || v.haze {
            SUMMED
        } else if v.alpha {
            wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING
        } else {
            ADDITIVE
        };
        let constants = v.constants();
        // Lit layers shade with the six-way maps (the motion pass only weighs coverage).
        let (vs, fs) = match v.lit && !v.motion {
            true => ("vs_lit", "fs_lit"),
            false => ("vs_main", "fs_main"),
        };
        let options = wgpu::PipelineCompilationOptions {
            constants: &constants,
            zero_initialize_workgroup_memory: true,
        };
        ctx.device
            .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(&format!("BillboardPass {v:?}")),
                layout: Some(layout),
                vertex: wgpu::VertexState {
                    module,
                    entry_point: Some(vs),
                    compilation_options: options.clone(),
                    buffers: &[],
                },
                primitive: wgpu::PrimitiveState::default(),
                // Particles test against the host's depth and never write it.
                depth_stencil: target.read_only_depth(None),
                multisample: target.multisample(),
                fragment: Some(wgpu::FragmentState {
                    module,
                    entry_point: Some(fs),
                    compilation_options: options,
                    targets: &[Some(wgpu::ColorTargetState {
                        format: target.color_format,
                        blend: Some(blend),
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                multiview_mask: None,
                cache: None,
            })
    }

    /// The soft-edge depth group over `view`.
    fn depth_group(
        ctx: &GpuContext,
        layout: &wgpu::BindGroupLayout,
        view: &wgpu::TextureView,
    ) -> wgpu::BindGroup {
        ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("BillboardPass::depth_group"),
            layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(view),
            }],
        })
    }

    /// Samples `view` (the host's single-sample depth, the size of the colour target)
    /// for soft edges from now on (a new bind group only when the view changes).
    /// `None` binds the placeholder again, so that the host's texture is not bound (its
    /// pass may then write depth, or it may be destroyed).
    pub fn set_scene_depth(&mut self, ctx: &GpuContext, view: Option<&wgpu::TextureView>) {
        if self.depth_view.as_ref() != view {
            let bound = view.unwrap_or(&self.no_depth);
            self.depth_group = Self::depth_group(ctx, &self.depth_layout, bound);
            self.depth_view = view.cloned();
        }
    }

    /// The two basic variants (validated together with the module).
    #[allow(clippy::type_complexity)]
    fn build(
        ctx: &GpuContext,
        lib: &ShaderLibrary,
        layout: &wgpu::PipelineLayout,
        target: DrawTarget,
    ) -> Result<
        (
            wgpu::ShaderModule,
            HashMap<LookVariant, Option<wgpu::RenderPipeline>>,
        ),
        ShaderError,
    > {
        let composed = lib.compose("billboard.wgsl")?;
        create_checked(&ctx.device, &composed, lib, |module| {
            let mut pipelines = HashMap::new();
            for alpha in [false, true] {
                let v = LookVariant::basic(alpha);
                pipelines.insert(v, Some(Self::pipeline(ctx, layout, module, v, target)));
            }
            (module.clone(), pipelines)
        })
    }

    /// Rebuilds the pipelines; keeps the old ones on error. Other variants are rebuilt
    /// on first use.
    pub fn rebuild(&mut self, ctx: &GpuContext, lib: &ShaderLibrary) -> Result<(), ShaderError> {
        let (module, pipelines) = Self::build(ctx, lib, &self.pipeline_layout, self.target)?;
        self.module = module;
        self.pipelines = pipelines;
        Ok(())
    }

    /// Creates the pipelines and sprite bind groups `items` need (call before `draw`);
    /// with `motion`, also their motion-pass pipelines (for `draw_motion`).
    pub fn prepare(
        &mut self,
        ctx: &GpuContext,
        items: &[DrawItem],
        sampler: &wgpu::Sampler,
        motion: bool,
    ) {
        for d in items.iter().filter(|d| d.is_billboard()) {
            if d.trail.is_none_or(|(_, sprite)| sprite) {
                self.ensure_pipeline(ctx, d.variant);
                if motion {
                    self.ensure_pipeline(ctx, d.variant.with_motion());
                }
            }
            if d.trail.is_some() {
                self.ensure_pipeline(ctx, d.variant.with_trail());
            }
            self.sprites.ensure(ctx, &d.sprite, sampler);
        }
        self.sprites.keep_drawn(items.iter().map(|d| d.sprite.id));
    }

    /// Creates the pipeline of `variant` unless it exists (an invalid one is remembered
    /// as missing and skipped by the draws).
    fn ensure_pipeline(&mut self, ctx: &GpuContext, variant: LookVariant) {
        if self.pipelines.contains_key(&variant) {
            return;
        }
        let p = crate::render::scoped_variant(
            ctx,
            format_args!("billboard variant {variant:?}"),
            || {
                Self::pipeline(
                    ctx,
                    &self.pipeline_layout,
                    &self.module,
                    variant,
                    self.target,
                )
            },
        );
        self.pipelines.insert(variant, p);
    }

    /// Draws the motion pass of `items` into an open render pass whose colour target was
    /// cleared to zero: per pixel (Σ w·motion_px, 0, Σ w), `w` each particle's visible
    /// weight (needs `prepare` with `motion`).
    pub fn draw_motion(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        frame: &FrameResources,
        items: &[DrawItem],
    ) {
        let visible = |d: &DrawItem| !d.variant.haze;
        self.draw_as(pass, frame, items, visible, LookVariant::with_motion);
    }

    /// Draws the heat-haze items into an open pass over the distortion target
    /// ([`HAZE_FORMAT`], cleared to zero): per pixel the summed offsets (rg) and weights.
    pub fn draw_haze(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        frame: &FrameResources,
        items: &[DrawItem],
    ) {
        self.draw_as(pass, frame, items, |d| d.variant.haze, |v| v);
    }

    /// Draws the billboard items that `wanted` accepts into an open render pass
    /// (alpha-blended layers first, then additive ones on top); heat haze is never drawn
    /// here. Items whose pipeline or sprite was not prepared are skipped.
    pub fn draw(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        frame: &FrameResources,
        items: &[DrawItem],
        wanted: impl Fn(&DrawItem) -> bool,
    ) {
        let wanted = |d: &DrawItem| !d.variant.haze && wanted(d);
        self.draw_as(pass, frame, items, wanted, |v| v);
    }

    /// [`BillboardPass::draw`] with each item's pipeline variant mapped by `variant`.
    fn draw_as(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        frame: &FrameResources,
        items: &[DrawItem],
        wanted: impl Fn(&DrawItem) -> bool,
        variant: impl Fn(LookVariant) -> LookVariant,
    ) {
        let mut sorted: Vec<&DrawItem> = items
            .iter()
            .filter(|d| d.is_billboard() && wanted(d))
            .collect();
        sorted.sort_by_key(|d| d.draw_key());
        pass.set_index_buffer(self.quad_indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.set_bind_group(3, &self.depth_group, &[]);
        let mut bound: Option<(LookVariant, u64)> = None;
        for d in sorted {
            // The ribbon first (behind its particles' sprites), then the sprites.
            let ribbon = d.trail.filter(|_| !variant(d.variant).motion);
            let draws = [
                ribbon.map(|(segments, _)| (d.variant.with_trail(), segments)),
                d.trail
                    .is_none_or(|(_, sprite)| sprite)
                    .then(|| (variant(d.variant), 1)),
            ];
            for (v, segments) in draws.into_iter().flatten() {
                let (Some(group), Some(Some(pipeline)), Some(sprite)) = (
                    frame.particle_group(d.key),
                    self.pipelines.get(&v),
                    self.sprites.get(d.sprite.id),
                ) else {
                    continue;
                };
                if bound.is_none_or(|(b, _)| b != v) {
                    pass.set_pipeline(pipeline);
                }
                if bound.is_none_or(|(_, id)| id != d.sprite.id) {
                    pass.set_bind_group(2, sprite, &[]);
                }
                bound = Some((v, d.sprite.id));
                pass.set_bind_group(
                    0,
                    &frame.frame_group,
                    &[FrameResources::look_offset(d.look_slot)],
                );
                pass.set_bind_group(1, group, &[]);
                // One quad per slot of each instance's live window (`width` per
                // instance), or sorted, through the sort's order; a ribbon has
                // `segments` quads per particle.
                let indices = if v.octagon { 6..24 } else { 0..6 };
                pass.counted_draw_indexed(indices, 0..d.width * d.members * segments);
            }
        }
    }
}

/// The index buffer: a quad's two triangles over its four corners, then an octagon's six
/// over its eight (corners in order around it; `shaders/sprite_trim.wgsl`).
const QUAD_AND_OCTAGON: [u32; 24] = [
    0, 1, 2, 2, 1, 3, //
    0, 1, 7, 1, 2, 7, 7, 2, 6, 2, 3, 6, 6, 3, 5, 3, 4, 5,
];

/// The distortion target's format: screen offsets (rg, uv units) and weights (a), summed.
pub const HAZE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// Everything adds up, alpha too (the motion pass's weighted sums).
const SUMMED: wgpu::BlendState = wgpu::BlendState {
    color: wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::One,
        operation: wgpu::BlendOperation::Add,
    },
    alpha: wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::One,
        operation: wgpu::BlendOperation::Add,
    },
};

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
