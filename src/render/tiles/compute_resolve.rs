//! The tiles' resolve by compute: the shaded tiles blended over the HDR target in place,
//! where the adapter can read and write it.

use super::*;

/// The compute resolve's target layout and pipeline layout.
pub(super) struct ComputeResolve {
    /// The target's layout (group 2) and groups.
    pub(super) images: ImageGroups,
    pub(super) layout: wgpu::PipelineLayout,
}

impl ComputeResolve {
    /// Group 2 binding 2, the target (read and written in place), after the frame and
    /// the resolve's groups; `None` where `target` is not a single-sample HDR image or the
    /// device cannot read and write one in place (Vulkan adapters can, asked for their own
    /// format features: the layout is tried in an error scope, which works on a host's
    /// device too).
    pub(super) fn new(
        ctx: &GpuContext,
        target: DrawTarget,
        frame_layout: &wgpu::BindGroupLayout,
        resolve_layout: &wgpu::BindGroupLayout,
    ) -> Option<Self> {
        let d = &ctx.device;
        let adapter_formats = d
            .features()
            .contains(wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES);
        if !adapter_formats
            || target.color_format != crate::render::HDR_FORMAT
            || target.sample_count > 1
        {
            return None;
        }
        let scope = d.push_error_scope(wgpu::ErrorFilter::Validation);
        let images = ImageGroups::new(
            ctx,
            "TilePass::image",
            2,
            wgpu::StorageTextureAccess::ReadWrite,
        );
        if let Some(err) = pollster::block_on(scope.pop()) {
            log::info!("the tiles are resolved by draws: {err}");
            return None;
        }
        let layout = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("TilePass::resolve_over_layout"),
            bind_group_layouts: &[
                Some(frame_layout),
                Some(resolve_layout),
                Some(images.layout()),
            ],
            immediate_size: 0,
        });
        Some(Self { images, layout })
    }
}
