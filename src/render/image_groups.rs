//! Bind groups over one HDR storage image, kept per target view: the compute passes that
//! write the composite's images (its clear, the tiles' compute resolve) bind a target that
//! changes only with the image's size.

use crate::gpu::GpuContext;
use crate::render::HDR_FORMAT;

/// Views whose groups are kept (the composite's image and its reduced layers).
const MAX_GROUPS: usize = 4;

/// A layout of one `Rgba16Float` storage image and the groups over the last views bound.
pub(crate) struct ImageGroups {
    layout: wgpu::BindGroupLayout,
    label: &'static str,
    binding: u32,
    /// Newest last.
    groups: Vec<(wgpu::TextureView, wgpu::BindGroup)>,
}

impl ImageGroups {
    /// The layout: the image at `binding`, for compute, with `access`.
    pub(crate) fn new(
        ctx: &GpuContext,
        label: &'static str,
        binding: u32,
        access: wgpu::StorageTextureAccess,
    ) -> Self {
        let layout = ctx
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some(label),
                entries: &[wgpu::BindGroupLayoutEntry {
                    binding,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::StorageTexture {
                        access,
                        format: HDR_FORMAT,
                        view_dimension: wgpu::TextureViewDimension::D2,
                    },
                    count: None,
                }],
            });
        Self {
            layout,
            label,
            binding,
            groups: Vec::new(),
        }
    }

    /// The layout the groups follow.
    pub(crate) fn layout(&self) -> &wgpu::BindGroupLayout {
        &self.layout
    }

    /// The group over `view` (made on first use; the oldest kept one goes past
    /// `MAX_GROUPS`).
    pub(crate) fn group(&mut self, ctx: &GpuContext, view: &wgpu::TextureView) -> &wgpu::BindGroup {
        let entry = match self.groups.iter().position(|(v, _)| v == view) {
            Some(k) => self.groups.remove(k),
            None => {
                let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some(self.label),
                    layout: &self.layout,
                    entries: &[wgpu::BindGroupEntry {
                        binding: self.binding,
                        resource: wgpu::BindingResource::TextureView(view),
                    }],
                });
                (view.clone(), group)
            }
        };
        if self.groups.len() >= MAX_GROUPS {
            self.groups.remove(0);
        }
        self.groups.push(entry);
        &self.groups[self.groups.len() - 1].1
    }
}
