//! Pass 2 and the composite: billboards into an HDR target, tonemapped to sRGB.

pub mod billboard;
pub mod bloom;
pub mod camera;
pub mod clear;
pub(crate) mod compute_resolve;
pub mod depth_resolve;
pub mod draw_item;
pub mod frame;
pub mod haze;
pub(crate) mod image_groups;
pub mod light;
pub mod light_apply;
pub mod look_bake;
pub mod matrix;
pub mod scene_lighting;
pub mod sixway_maps;
pub mod sort;
pub mod splat;
pub mod sprite_trim;
pub mod sprites;
pub mod test_scene;
pub mod tiles;
pub mod tonemap;
pub mod variant;

pub use crate::gpu::compute_pipeline;
pub use billboard::BillboardPass;
pub use camera::Camera;
pub use camera::OrbitCamera;
pub use frame::{DrawItem, FrameResources, Scene};
pub use splat::SplatPass;
pub use tiles::TilePass;
pub use tonemap::TonemapPass;

use crate::gpu::GpuContext;

/// The HDR format particles accumulate into.
pub const HDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// The format of the display image the tonemap writes (a compute pass: storage textures
/// cannot be sRGB, so it holds sRGB-encoded values, the bytes an `Rgba8UnormSrgb` image
/// would hold).
pub const LDR_STORAGE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

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
            LDR_STORAGE_FORMAT,
            wgpu::TextureUsages::STORAGE_BINDING
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
        wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::COPY_SRC
            | wgpu::TextureUsages::COPY_DST,
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

/// The full-screen draw of a compute path's image into a host's pass (`vs_resolve`,
/// `fs_resolve` of `module`): it passes any depth test, writes no depth, and blends with
/// `blend` into `target`.
pub fn resolve_pipeline(
    ctx: &GpuContext,
    label: &str,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    target: billboard::DrawTarget,
    blend: wgpu::BlendState,
) -> wgpu::RenderPipeline {
    let color = wgpu::ColorTargetState {
        format: target.color_format,
        blend: Some(blend),
        write_mask: wgpu::ColorWrites::ALL,
    };
    crate::gpu::render_pipeline(
        ctx,
        crate::gpu::PipelineParts {
            label,
            layout: Some(layout),
            module,
            entries: ("vs_resolve", "fs_resolve"),
            buffers: &[],
            depth_stencil: target.read_only_depth(Some(wgpu::CompareFunction::Always)),
            multisample: target.multisample(),
            targets: &[Some(color)],
        },
    )
}

/// The compute paths' `DEPTH_TEST` constant for a target: 0 none, 1 a particle nearer
/// than or level with the host's depth passes, 2 the reverse (reversed Z).
pub fn depth_test(target: billboard::DrawTarget) -> f64 {
    use wgpu::CompareFunction as C;
    match target.depth.map(|(_, c)| c) {
        Some(C::Less | C::LessEqual | C::Equal) => 1.0,
        Some(C::Greater | C::GreaterEqual) => 2.0,
        _ => 0.0,
    }
}

/// `size` divided by `factor`, rounded up.
pub(crate) fn reduced(size: (u32, u32), factor: u32) -> (u32, u32) {
    (size.0.div_ceil(factor), size.1.div_ceil(factor))
}

/// Makes `slot` an HDR target of `size` unless it already is one.
pub(crate) fn ensure_layer(
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

#[cfg(feature = "editor")]
/// Opens a render pass that clears the HDR target to transparent black.
pub fn begin_hdr_pass<'a>(
    enc: &'a mut wgpu::CommandEncoder,
    hdr: &'a wgpu::TextureView,
) -> wgpu::RenderPass<'a> {
    let clear = wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT);
    crate::gpu::color_pass(enc, hdr, clear, "Renderer::hdr_pass")
}

/// A render pass into an HDR target that keeps what it holds (cleared by
/// [`clear::ClearPass`]).
pub fn load_hdr_pass<'a>(
    enc: &'a mut wgpu::CommandEncoder,
    hdr: &'a wgpu::TextureView,
) -> wgpu::RenderPass<'a> {
    crate::gpu::color_pass(enc, hdr, wgpu::LoadOp::Load, "Renderer::hdr_pass")
}
