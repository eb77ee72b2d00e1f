//! Pass 2 and the composite: billboards into an HDR target, tonemapped to sRGB.

pub mod billboard;
pub mod bloom;
pub mod camera;
pub mod frame;
pub mod look;
pub mod sort;
pub mod splat;
pub mod sprites;
pub mod tonemap;

pub use billboard::BillboardPass;
pub use camera::Camera;
pub use camera::OrbitCamera;
pub use frame::{DrawItem, FrameResources, Scene};
pub use splat::SplatPass;
pub use tonemap::TonemapPass;

use crate::effect::{BlendMode, Effect};
use crate::gpu::GpuContext;
use crate::shaders::{ShaderError, ShaderLibrary};
use crate::sim::gpu_sim::{GpuSim, SimError, map_read};

/// The HDR format particles accumulate into.
pub const HDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// The display format of headless frames.
pub const LDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// Offscreen HDR and display targets of one size.
pub struct Targets {
    /// Width and height in pixels.
    pub size: (u32, u32),
    /// The HDR accumulation target.
    pub hdr_view: wgpu::TextureView,
    /// The tonemapped display image.
    pub ldr: wgpu::Texture,
    /// A view of `ldr`.
    pub ldr_view: wgpu::TextureView,
}

impl Targets {
    /// Creates both targets.
    pub fn new(ctx: &GpuContext, size: (u32, u32)) -> Self {
        let size = (size.0.max(1), size.1.max(1));
        let make = |label, format, usage| {
            crate::gpu::texture_2d(&ctx.device, label, size, 1, format, usage)
        };
        let hdr = hdr_texture(ctx, "Targets::hdr", size);
        let ldr = make(
            "Targets::ldr",
            LDR_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
        );
        Self {
            size,
            hdr_view: hdr.create_view(&Default::default()),
            ldr_view: ldr.create_view(&Default::default()),
            ldr,
        }
    }
}

/// An HDR render target that passes can also sample.
pub fn hdr_texture(ctx: &GpuContext, label: &str, size: (u32, u32)) -> wgpu::Texture {
    crate::gpu::texture_2d(
        &ctx.device,
        label,
        size,
        1,
        HDR_FORMAT,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
    )
}

/// A pipeline variant built on first use from an already validated module: `make` runs
/// inside a validation error scope, and a failure (an override constant the edited shader
/// no longer declares, say) is logged with `what` and gives `None`, so the frame goes on
/// without that draw instead of reaching the device's uncaptured-error handler.
pub fn scoped_variant<P>(
    ctx: &GpuContext,
    what: impl std::fmt::Display,
    make: impl FnOnce() -> P,
) -> Option<P> {
    let scope = ctx.device.push_error_scope(wgpu::ErrorFilter::Validation);
    let p = make();
    match pollster::block_on(scope.pop()) {
        None => Some(p),
        Some(err) => {
            log::error!("{what} failed: {err}");
            None
        }
    }
}

/// A render pipeline without vertex buffers: `vs` and `fs` of one module, one colour
/// target, override constants (given to both stages) and the primitive topology.
#[allow(clippy::too_many_arguments)]
pub fn simple_pipeline(
    ctx: &GpuContext,
    label: &str,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    (vs, fs): (&str, &str),
    target: wgpu::ColorTargetState,
    constants: &[(&str, f64)],
    topology: wgpu::PrimitiveTopology,
) -> wgpu::RenderPipeline {
    ctx.device
        .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout: Some(layout),
            vertex: wgpu::VertexState {
                module,
                entry_point: Some(vs),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants,
                    zero_initialize_workgroup_memory: true,
                },
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState {
                topology,
                ..Default::default()
            },
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module,
                entry_point: Some(fs),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants,
                    zero_initialize_workgroup_memory: true,
                },
                targets: &[Some(target)],
            }),
            multiview_mask: None,
            cache: None,
        })
}

/// A colour target on the HDR format with `blend`.
pub fn hdr_target(blend: wgpu::BlendState) -> wgpu::ColorTargetState {
    wgpu::ColorTargetState {
        format: HDR_FORMAT,
        blend: Some(blend),
        write_mask: wgpu::ColorWrites::ALL,
    }
}

/// `size` divided by `factor`, rounded up.
fn reduced(size: (u32, u32), factor: u32) -> (u32, u32) {
    (size.0.div_ceil(factor), size.1.div_ceil(factor))
}

/// Makes `slot` an HDR target of `size` unless it already is one.
fn ensure_layer(
    ctx: &GpuContext,
    slot: &mut Option<((u32, u32), wgpu::TextureView)>,
    label: &str,
    size: (u32, u32),
) {
    if slot.as_ref().is_some_and(|(s, _)| *s == size) {
        return;
    }
    *slot = Some((
        size,
        hdr_texture(ctx, label, size).create_view(&Default::default()),
    ));
}

/// Opens a render pass that clears the HDR target to transparent black.
pub fn begin_hdr_pass<'a>(
    enc: &'a mut wgpu::CommandEncoder,
    hdr: &'a wgpu::TextureView,
) -> wgpu::RenderPass<'a> {
    enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("Renderer::hdr_pass"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: hdr,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

/// Draws a simulation: billboards and splats → HDR → tonemap → display texture.
pub struct Renderer {
    /// Uniforms and bind groups shared by the draw paths.
    pub frame: FrameResources,
    /// The billboard pass.
    pub billboard: BillboardPass,
    /// The compute splat pass.
    pub splat: SplatPass,
    /// Back-to-front sorting of alpha-blended emitters.
    pub sort: sort::SortPass,
    /// The tonemap pass.
    pub tonemap: TonemapPass,
    /// The bloom passes (recorded only when the effect has bloom).
    pub bloom: bloom::BloomPass,
    targets: Option<Targets>,
    /// Exposure multiplier applied before tonemapping (times the effect's own).
    pub exposure: f32,
    /// The folder PNG sprite paths are relative to (the preset's; the working directory
    /// when `None`).
    pub asset_dir: Option<std::path::PathBuf>,
    /// The reduced-resolution target of the alpha-blended layers (`post.alpha_downscale`).
    alpha_layer: Option<((u32, u32), wgpu::TextureView)>,
    /// Draft quality (the editor's default on software adapters): large additive
    /// billboards ([`DrawItem::is_glow`], e.g. flame tongues) are drawn at half
    /// resolution into a glow layer that the bloom's prefilter and the tonemap read — a
    /// quarter of their fill; the alpha-blended layers are drawn at half the resolution
    /// `post.alpha_downscale` asks for (the campfire's smoke at an eighth).
    pub draft: bool,
    /// The half-resolution target of the glow layer (draft).
    glow_layer: Option<((u32, u32), wgpu::TextureView)>,
}

impl Renderer {
    /// Builds the pipelines from `lib`.
    pub fn new(ctx: &GpuContext, lib: &ShaderLibrary) -> Result<Self, ShaderError> {
        let frame = FrameResources::new(ctx);
        Ok(Self {
            billboard: BillboardPass::new(ctx, lib, &frame, billboard::DrawTarget::hdr())?,
            splat: SplatPass::new(ctx, lib, &frame)?,
            sort: sort::SortPass::new(ctx, lib)?,
            frame,
            tonemap: TonemapPass::new(ctx, lib, LDR_FORMAT)?,
            bloom: bloom::BloomPass::new(ctx, lib)?,
            targets: None,
            exposure: 1.0,
            asset_dir: None,
            alpha_layer: None,
            draft: false,
            glow_layer: None,
        })
    }

    /// Rebuilds every pipeline from `lib`, keeping the old ones on error.
    pub fn reload_shaders(
        &mut self,
        ctx: &GpuContext,
        lib: &ShaderLibrary,
    ) -> Result<(), ShaderError> {
        self.billboard.rebuild(ctx, lib)?;
        self.splat.rebuild(ctx, lib)?;
        self.sort.rebuild(ctx, lib)?;
        self.tonemap.rebuild(ctx, lib)?;
        self.bloom.rebuild(ctx, lib)?;
        Ok(())
    }

    /// The targets, (re)created at `size` when needed.
    pub fn targets(&mut self, ctx: &GpuContext, size: (u32, u32)) -> &Targets {
        let stale = self.targets.as_ref().is_none_or(|t| t.size != size);
        if stale {
            self.targets = Some(Targets::new(ctx, size));
        }
        self.targets.get_or_insert_with(|| Targets::new(ctx, size))
    }

    /// The targets of the last frame, if any.
    pub fn targets_ref(&self) -> Option<&Targets> {
        self.targets.as_ref()
    }

    /// Records the frame into `enc`: particles into the HDR target, then the tonemap
    /// into the display texture.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &mut self,
        ctx: &GpuContext,
        enc: &mut wgpu::CommandEncoder,
        sim: &GpuSim,
        effect: &Effect,
        camera: &OrbitCamera,
        alpha: f32,
        size: (u32, u32),
    ) {
        self.targets(ctx, size);
        let Some(targets) = self.targets.as_ref() else {
            return;
        };
        let view = camera.view(targets.size);
        let scenes = [Scene { sim, effect }];
        let items = self.frame.prepare(
            ctx,
            &scenes,
            &view,
            alpha,
            &mut self.sort,
            self.asset_dir.as_deref(),
        );
        self.billboard
            .prepare(ctx, &items, &self.frame.sprites.sampler);
        self.sort.record_items(ctx, enc, &scenes, &items, &view);
        let splatted = self.splat.splat(ctx, enc, &self.frame, &items, size);
        // Alpha layers at reduced resolution: their own target, added in the composite.
        // Draft halves it again (soft smoke hides it).
        let downscale = effect.post.alpha_downscale.clamp(1, 4) << u32::from(self.draft);
        let low_alpha = downscale > 1
            && items
                .iter()
                .any(|d| !d.splat && d.blend == BlendMode::Alpha);
        if low_alpha {
            let low = reduced(targets.size, downscale);
            ensure_layer(ctx, &mut self.alpha_layer, "Renderer::alpha_layer", low);
            if let Some((_, view)) = &self.alpha_layer {
                let mut pass = begin_hdr_pass(enc, view);
                self.billboard.draw(&mut pass, &self.frame, &items, |d| {
                    d.blend == BlendMode::Alpha
                });
            }
        }
        let glow = self.draft && items.iter().any(DrawItem::is_glow);
        if glow {
            let half = reduced(targets.size, 2);
            ensure_layer(ctx, &mut self.glow_layer, "Renderer::glow_layer", half);
            if let Some((_, view)) = &self.glow_layer {
                let mut pass = begin_hdr_pass(enc, view);
                self.billboard
                    .draw(&mut pass, &self.frame, &items, DrawItem::is_glow);
            }
        }
        {
            let mut pass = begin_hdr_pass(enc, &targets.hdr_view);
            self.billboard.draw(&mut pass, &self.frame, &items, |d| {
                // What the reduced-resolution layers did not draw.
                let in_layer = (low_alpha && d.blend == BlendMode::Alpha) || (glow && d.is_glow());
                !in_layer
            });
        }
        // The glow layer joins the image in the bloom's prefilter and in the tonemap
        // (upsampled bilinearly there): no pass of its own.
        let glow_view = self.glow_layer.as_ref().filter(|_| glow).map(|(_, v)| v);
        // The splat's light is resolved inside the tonemap (one full-screen pass less).
        let accum = if splatted {
            self.splat.accum_buffer()
        } else {
            None
        };
        let bloom = match &effect.post.bloom {
            Some(b) => self
                .bloom
                .record(
                    ctx,
                    enc,
                    &targets.hdr_view,
                    accum,
                    glow_view,
                    targets.size,
                    b,
                    self.draft,
                )
                .map(|view| (view, b.intensity)),
            None => None,
        };
        self.tonemap.record(
            ctx,
            enc,
            &targets.hdr_view,
            accum,
            bloom,
            self.alpha_layer
                .as_ref()
                .filter(|_| low_alpha)
                .map(|(_, v)| v),
            glow_view,
            &targets.ldr_view,
            self.exposure * effect.post.exposure,
        );
    }

    /// Renders one frame and reads it back as an RGBA8 image (blocking).
    pub fn render_image(
        &mut self,
        ctx: &GpuContext,
        sim: &GpuSim,
        effect: &Effect,
        camera: &OrbitCamera,
        alpha: f32,
        size: (u32, u32),
    ) -> Result<image::RgbaImage, SimError> {
        let mut enc = ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("Renderer::render_image"),
            });
        self.record(ctx, &mut enc, sim, effect, camera, alpha, size);
        let Some(targets) = self.targets.as_ref() else {
            return Err(SimError::Readback("no render target".into()));
        };
        let (w, h) = targets.size;
        let row = (w * 4).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let staging = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("Renderer::readback"),
            size: row as u64 * h as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        enc.copy_texture_to_buffer(
            targets.ldr.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &staging,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(row),
                    rows_per_image: Some(h),
                },
            },
            wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
        );
        ctx.queue.submit([enc.finish()]);
        let bytes = map_read(ctx, &staging)?;
        let mut pixels = Vec::with_capacity((w * h * 4) as usize);
        for y in 0..h as usize {
            let start = y * row as usize;
            pixels.extend_from_slice(&bytes[start..start + (w * 4) as usize]);
        }
        image::RgbaImage::from_raw(w, h, pixels)
            .ok_or_else(|| SimError::Readback("image size mismatch".into()))
    }
}
