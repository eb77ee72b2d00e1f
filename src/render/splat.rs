//! The compute splat draw path for small particles: each quad projected as the billboards
//! draw it, its light at every pixel centre it covers (its footprint; a sprite larger than
//! [`FOOTPRINT_PX`] its integrated light near its centre) accumulated in fixed point with
//! atomics, resolved into the HDR target. Far cheaper than tiny instanced quads on GPUs
//! whose rasteriser runs on a few SMs (see the perf bench).

use crate::gpu::commands::{CountedCompute, CountedRender};
use std::collections::HashMap;

use crate::gpu::GpuContext;
use crate::render::billboard::{ADDITIVE, DrawTarget};
use crate::render::compute_resolve::ComputeResolve;
use crate::render::frame::{DrawItem, FrameResources, LookVariant};
use crate::shaders::{ShaderError, ShaderLibrary, create_checked};
use crate::sim::gpu_sim::dispatch_size;

/// Sprites whose pixel box is at most this many pixels a side add their footprint (the
/// billboards' pixels); larger ones (a forced splat of large sprites) their integrated
/// light over the 2×2 pixels nearest their centre (splat.wgsl's `FOOTPRINT`).
pub const FOOTPRINT_PX: u32 = 8;

/// Compute splat + resolve.
pub struct SplatPass {
    target: DrawTarget,
    accum_layout: wgpu::BindGroupLayout,
    /// A 1×1 depth texture bound when no host depth is tested.
    no_depth: wgpu::TextureView,
    pipeline_layout: wgpu::PipelineLayout,
    resolve_layout: wgpu::PipelineLayout,
    empty_group: wgpu::BindGroup,
    module: wgpu::ShaderModule,
    /// Splat pipelines per look variant, built on first use (`None`: failed, logged).
    splats: HashMap<LookVariant, Option<wgpu::ComputePipeline>>,
    resolve: wgpu::RenderPipeline,
    /// The resolve by compute's layouts and groups over the targets it wrote last, and its
    /// pipeline (`None`: the adapter cannot, or the host's target is not an HDR image).
    compute_resolve: Option<(ComputeResolve, wgpu::ComputePipeline)>,
    /// Whether [`SplatPass::resolve_into`] may resolve by compute (tests compare it with
    /// the draw).
    compute_resolve_on: bool,
    accum: Option<Accum>,
    /// The splat items' sprites (group 3).
    sprites: crate::render::sprites::SpriteGroups,
}

/// Whether the splat accumulates into one u64 per pixel (one atomic add per lit pixel;
/// splat_accum64.wgsl): where the device has 64-bit atomics. Else three u32.
pub fn packed(ctx: &GpuContext) -> bool {
    ctx.device.features().contains(crate::gpu::INT64_ATOMICS)
}

/// Bytes of the accumulation per pixel.
fn pixel_bytes(ctx: &GpuContext) -> u64 {
    if packed(ctx) { 8 } else { 12 }
}

/// What a build of `splat.wgsl` makes.
struct Built {
    module: wgpu::ShaderModule,
    /// The basic variant's splat (built to validate the module).
    splats: HashMap<LookVariant, Option<wgpu::ComputePipeline>>,
    resolve: wgpu::RenderPipeline,
    /// The resolve by compute, where the adapter can read and write the target.
    resolve_add: Option<wgpu::ComputePipeline>,
}

/// The accumulation buffer of one size and its bind group (with the depth it tests).
struct Accum {
    size: (u32, u32),
    buffer: wgpu::Buffer,
    group: wgpu::BindGroup,
    depth: Option<wgpu::TextureView>,
}

impl SplatPass {
    /// Builds the pipelines from `lib`; the resolve draws into `target` (a pass with its
    /// formats), and the splat tests against its depth when it has one.
    pub fn new(
        ctx: &GpuContext,
        lib: &ShaderLibrary,
        frame: &FrameResources,
        target: DrawTarget,
    ) -> Result<Self, ShaderError> {
        let accum_layout = crate::gpu::bind_group_layout(
            ctx,
            "SplatPass::accum_layout",
            &[
                wgpu::BindGroupLayoutEntry {
                    visibility: wgpu::ShaderStages::COMPUTE | wgpu::ShaderStages::FRAGMENT,
                    ..crate::gpu::fragment_buffer_entry(
                        0,
                        wgpu::BufferBindingType::Storage { read_only: false },
                    )
                },
                crate::gpu::depth_texture_entry(1, wgpu::ShaderStages::COMPUTE),
            ],
        );
        let no_depth = crate::gpu::placeholder_depth(&ctx.device, "SplatPass::no_depth");
        let sprite_layout =
            crate::render::sprites::compute_sprite_layout(ctx, "SplatPass::sprite_layout");
        let pipeline_layout = ctx
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("SplatPass::pipeline_layout"),
                bind_group_layouts: &[
                    Some(&frame.frame_layout),
                    Some(&frame.particle_layout),
                    Some(&accum_layout),
                    Some(&sprite_layout),
                ],
                immediate_size: 0,
            });
        // The resolve reads no particles: group 1 is an empty placeholder.
        let empty_layout = crate::gpu::bind_group_layout(ctx, "SplatPass::empty_layout", &[]);
        let empty_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("SplatPass::empty_group"),
            layout: &empty_layout,
            entries: &[],
        });
        let resolve_layout = ctx
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("SplatPass::resolve_layout"),
                bind_group_layouts: &[
                    Some(&frame.frame_layout),
                    Some(&empty_layout),
                    Some(&accum_layout),
                ],
                immediate_size: 0,
            });
        let over = ComputeResolve::new(
            ctx,
            "SplatPass::resolve_add",
            target,
            &[&frame.frame_layout, &empty_layout, &accum_layout],
        );
        let built = Self::build(
            ctx,
            lib,
            [&pipeline_layout, &resolve_layout],
            over.as_ref().map(|c| &c.layout),
            target,
        )?;
        Ok(Self {
            target,
            accum_layout,
            no_depth,
            pipeline_layout,
            resolve_layout,
            empty_group,
            module: built.module,
            splats: built.splats,
            resolve: built.resolve,
            compute_resolve: over.zip(built.resolve_add),
            compute_resolve_on: true,
            accum: None,
            sprites: crate::render::sprites::SpriteGroups::new(
                "SplatPass::sprite_group",
                sprite_layout,
            ),
        })
    }

    fn splat_pipeline(
        ctx: &GpuContext,
        layout: &wgpu::PipelineLayout,
        module: &wgpu::ShaderModule,
        v: LookVariant,
        target: DrawTarget,
    ) -> wgpu::ComputePipeline {
        let mut constants = crate::render::variant::compute_constants(v, target);
        constants.push(("FOOTPRINT", f64::from(FOOTPRINT_PX)));
        crate::render::compute_pipeline(
            ctx,
            &format!("SplatPass::splat {v:?}"),
            layout,
            module,
            "splat",
            &constants,
        )
    }

    /// The module, the basic variant's splat (validated with it) and the resolves.
    fn build(
        ctx: &GpuContext,
        lib: &ShaderLibrary,
        [layout, resolve_layout]: [&wgpu::PipelineLayout; 2],
        over_layout: Option<&wgpu::PipelineLayout>,
        target: DrawTarget,
    ) -> Result<Built, ShaderError> {
        let aliases: &[(&str, &str)] = if packed(ctx) {
            &[crate::shaders::SPLAT_ACCUM64]
        } else {
            &[]
        };
        let composed = lib.compose_with("splat.wgsl", aliases)?;
        create_checked(&ctx.device, &composed, lib, |module| {
            let basic = LookVariant::basic(false);
            let splats = HashMap::from([(
                basic,
                Some(Self::splat_pipeline(ctx, layout, module, basic, target)),
            )]);
            let resolve = crate::render::resolve_pipeline(
                ctx,
                "SplatPass::resolve",
                resolve_layout,
                module,
                target,
                ADDITIVE,
            );
            let resolve_add = over_layout.map(|l| {
                crate::render::compute_pipeline(
                    ctx,
                    "SplatPass::resolve_add",
                    l,
                    module,
                    "resolve_add",
                    &[],
                )
            });
            Built {
                module: module.clone(),
                splats,
                resolve,
                resolve_add,
            }
        })
    }

    /// Rebuilds the pipelines; keeps the old ones on error. Other look variants are
    /// rebuilt on first use.
    pub fn rebuild(&mut self, ctx: &GpuContext, lib: &ShaderLibrary) -> Result<(), ShaderError> {
        let over = self.compute_resolve.as_ref().map(|(c, _)| &c.layout);
        let layouts = [&self.pipeline_layout, &self.resolve_layout];
        let built = Self::build(ctx, lib, layouts, over, self.target)?;
        self.module = built.module;
        self.splats = built.splats;
        self.resolve = built.resolve;
        if let (Some((_, p)), Some(new)) = (self.compute_resolve.as_mut(), built.resolve_add) {
            *p = new;
        }
        Ok(())
    }

    /// Clears the accumulation buffer and splats every splat item (compute), testing
    /// against `depth` (the host's, single-sample and `size`) when given. Returns false
    /// when there was nothing to splat (then `resolve` can be skipped).
    #[allow(clippy::too_many_arguments)]
    pub fn splat(
        &mut self,
        ctx: &GpuContext,
        enc: &mut wgpu::CommandEncoder,
        frame: &FrameResources,
        items: &[DrawItem],
        size: (u32, u32),
        depth: Option<&wgpu::TextureView>,
    ) -> bool {
        if !items.iter().any(|d| d.splat) {
            // Nothing is resolved, and the host's depth is not held.
            self.accum = None;
            return false;
        }
        match self.accum.take() {
            // The same buffer over another depth view: a new bind group only.
            Some(a) if a.size == size => {
                let fresh = a.depth.as_ref() != depth;
                self.accum = Some(if fresh {
                    self.accum_over(ctx, a.size, a.buffer, depth)
                } else {
                    a
                });
            }
            _ => {
                let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("SplatPass::accum"),
                    size: (size.0 as u64 * size.1 as u64 * pixel_bytes(ctx)).max(12),
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                self.accum = Some(self.accum_over(ctx, size, buffer, depth));
            }
        }
        self.prepare(ctx, items, &frame.sprites.sampler);
        let Some(Accum { buffer, group, .. }) = self.accum.as_ref() else {
            return false;
        };
        enc.clear_buffer(buffer, 0, None);
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("SplatPass::splat"),
            timestamp_writes: None,
        });
        pass.set_bind_group(2, group, &[]);
        for d in items.iter().filter(|d| d.splat) {
            let (Some(particles), Some(Some(pipeline)), Some(sprite)) = (
                frame.particle_group(d.key),
                self.splats.get(&d.variant),
                self.sprites.get(d.sprite.id),
            ) else {
                continue;
            };
            pass.set_pipeline(pipeline);
            pass.set_bind_group(
                0,
                &frame.frame_group,
                &[FrameResources::look_offset(d.look_slot)],
            );
            pass.set_bind_group(1, particles, &[]);
            pass.set_bind_group(3, sprite, &[]);
            // Workgroup z is the instance.
            let (x, y) = dispatch_size(d.width);
            pass.dispatch(x, y, d.members);
        }
        true
    }

    /// Builds what the frame's splat items need: pipelines of their variants and sprite
    /// bind groups.
    fn prepare(&mut self, ctx: &GpuContext, items: &[DrawItem], sampler: &wgpu::Sampler) {
        let (layout, module, target) = (&self.pipeline_layout, &self.module, self.target);
        self.sprites.prepare(
            ctx,
            ("splat", sampler),
            &mut self.splats,
            items.iter().filter(|d| d.splat),
            |v| Self::splat_pipeline(ctx, layout, module, v, target),
        );
    }

    /// The accumulation `buffer` (cleared on use) of `size` and its bind group over `depth`
    /// (the placeholder when `None`: the shader then tests nothing).
    fn accum_over(
        &self,
        ctx: &GpuContext,
        size: (u32, u32),
        buffer: wgpu::Buffer,
        depth: Option<&wgpu::TextureView>,
    ) -> Accum {
        let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("SplatPass::accum_group"),
            layout: &self.accum_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(depth.unwrap_or(&self.no_depth)),
                },
            ],
        });
        Accum {
            size,
            buffer,
            group,
            depth: depth.cloned(),
        }
    }

    /// Adds the light of the last splat into an open render pass of the target's
    /// formats (nothing when the last splat had nothing to do).
    pub fn resolve(&self, pass: &mut wgpu::RenderPass<'_>, frame: &FrameResources) {
        let Some(Accum { group, .. }) = self.accum.as_ref() else {
            return;
        };
        pass.set_pipeline(&self.resolve);
        pass.set_bind_group(0, &frame.frame_group, &[0]);
        pass.set_bind_group(1, &self.empty_group, &[]);
        pass.set_bind_group(2, group, &[]);
        pass.counted_draw(0..3, 0..1);
    }

    /// Whether [`SplatPass::resolve_into`] adds the last splat's light into a target of
    /// `size` pixels.
    pub fn can_resolve_into(&self, size: (u32, u32)) -> bool {
        self.compute_resolve_on
            && self.compute_resolve.is_some()
            && self.accum.as_ref().is_some_and(|a| a.size == size)
    }

    /// Lets [`SplatPass::resolve_into`] resolve by compute (the default) or not (tests
    /// compare the two).
    #[doc(hidden)]
    pub fn set_compute_resolve(&mut self, on: bool) {
        self.compute_resolve_on = on;
    }

    /// Adds the last splat's light into `target` (the HDR image of `size` pixels the
    /// resolve would draw into, with storage usage) by compute instead of a draw. Returns
    /// false, recording nothing, where it cannot (then [`SplatPass::resolve`] draws it).
    pub fn resolve_into(
        &mut self,
        ctx: &GpuContext,
        enc: &mut wgpu::CommandEncoder,
        frame: &FrameResources,
        target: &wgpu::TextureView,
        size: (u32, u32),
    ) -> bool {
        if !self.can_resolve_into(size) {
            return false;
        }
        let (Some((c, pipeline)), Some(Accum { group, .. })) =
            (self.compute_resolve.as_mut(), self.accum.as_ref())
        else {
            return false;
        };
        let groups = [&self.empty_group, group];
        let workgroups = (size.0.div_ceil(16), size.1.div_ceil(16));
        let label = ("SplatPass::resolve_add", &*pipeline);
        c.dispatch(ctx, enc, label, (frame, &groups), target, workgroups);
        true
    }
}
