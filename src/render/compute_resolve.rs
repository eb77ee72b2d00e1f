//! The compute draw paths' resolves by compute (the tiles' shaded pixels, the splat's
//! light) into the HDR target in place, where the adapter can read and write it: on every
//! compute unit rather than the raster, which the H100 keeps only a sliver of its chip for.

use crate::gpu::GpuContext;
use crate::gpu::commands::CountedCompute;
use crate::render::FrameResources;
use crate::render::billboard::DrawTarget;
use crate::render::image_groups::ImageGroups;

/// A compute resolve's target layout and pipeline layout.
pub(crate) struct ComputeResolve {
    /// The target's layout (the group after `groups`, binding 2) and groups.
    pub(crate) images: ImageGroups,
    pub(crate) layout: wgpu::PipelineLayout,
}

impl ComputeResolve {
    /// The target (binding 2, read and written in place) in the group after `groups`;
    /// `None` where `target` is not a single-sample HDR image or the device cannot read
    /// and write one in place (Vulkan adapters can, asked for their own format features:
    /// the layout is tried in an error scope, which works on a host's device too).
    pub(crate) fn new(
        ctx: &GpuContext,
        label: &'static str,
        target: DrawTarget,
        groups: &[&wgpu::BindGroupLayout],
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
        let images = ImageGroups::new(ctx, label, 2, wgpu::StorageTextureAccess::ReadWrite);
        if let Some(err) = pollster::block_on(scope.pop()) {
            log::info!("{label}: resolved by draws: {err}");
            return None;
        }
        let mut layouts: Vec<Option<&wgpu::BindGroupLayout>> =
            groups.iter().copied().map(Some).collect();
        layouts.push(Some(images.layout()));
        let layout = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(label),
            bind_group_layouts: &layouts,
            immediate_size: 0,
        });
        Some(Self { images, layout })
    }

    /// Records `pipeline` over `target` in a compute pass of its own: the frame's group 0,
    /// `groups` after it, the target's group last, `workgroups` dispatched.
    pub(crate) fn dispatch(
        &mut self,
        ctx: &GpuContext,
        enc: &mut wgpu::CommandEncoder,
        (label, pipeline): (&str, &wgpu::ComputePipeline),
        (frame, groups): (&FrameResources, &[&wgpu::BindGroup]),
        target: &wgpu::TextureView,
        workgroups: (u32, u32),
    ) {
        let image = self.images.group(ctx, target);
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(label),
            timestamp_writes: None,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &frame.frame_group, &[0]);
        for (i, g) in groups.iter().enumerate() {
            pass.set_bind_group(i as u32 + 1, *g, &[]);
        }
        pass.set_bind_group(groups.len() as u32 + 1, image, &[]);
        pass.dispatch(workgroups.0, workgroups.1, 1);
    }
}
