//! Depth collision's GPU side (group 2 of an update with `Modules::DEPTH_COLLISION`): the
//! host's depth of this frame, and how each emitter's simulation space is seen, composed in
//! f64 and rounded once (`shaders/depth_on.wgsl` marches against them).

use glam::{DMat4, DVec3};

use crate::gpu::GpuContext;
use crate::gpu::types::DepthViewUniform;

/// The host's depth as the simulation collides with it: the view the draws sample (one
/// sample, depth aspect), the camera that drew it (world → clip, wgpu's depth 0..1) and the
/// target's size in pixels.
#[derive(Clone, Debug)]
pub struct HostDepthView {
    /// The depth, bindable as `texture_depth_2d`.
    pub view: wgpu::TextureView,
    /// World (the simulation's world, before each emitter's origin) → clip.
    pub clip_from_world: DMat4,
    /// Depth shrinks away from the camera (the clear value, "nothing there", is 0).
    pub reversed_z: bool,
    /// The target's size, pixels.
    pub size: (u32, u32),
}

impl HostDepthView {
    /// The uniform for an emitter whose simulation space has its origin at `origin`.
    fn uniform(&self, origin: DVec3) -> DepthViewUniform {
        let clip_from_sim = self.clip_from_world * DMat4::from_translation(origin);
        DepthViewUniform {
            clip_from_sim: clip_from_sim.as_mat4().to_cols_array_2d(),
            sim_from_clip: clip_from_sim.inverse().as_mat4().to_cols_array_2d(),
            viewport: [
                self.size.0 as f32,
                self.size.1 as f32,
                if self.reversed_z { -1.0 } else { 1.0 },
                1.0,
            ],
        }
    }
}

/// The layout of group 2: the depth (binding 0) and the view (binding 1).
pub(crate) fn layout(ctx: &GpuContext) -> wgpu::BindGroupLayout {
    crate::gpu::bind_group_layout(
        ctx,
        "depth_collision::layout",
        &[
            crate::gpu::depth_texture_entry(0, wgpu::ShaderStages::COMPUTE),
            wgpu::BindGroupLayoutEntry {
                visibility: wgpu::ShaderStages::COMPUTE,
                ..crate::gpu::fragment_buffer_entry(1, wgpu::BufferBindingType::Uniform)
            },
        ],
    )
}

/// One emitter's group 2: its view uniform and the depth it is bound to.
pub(crate) struct DepthCollider {
    uniform: wgpu::Buffer,
    /// The group, and the depth view it binds (`None`: the placeholder).
    group: wgpu::BindGroup,
    bound: Option<wgpu::TextureView>,
    placeholder: wgpu::TextureView,
}

impl DepthCollider {
    /// A collider bound to nothing (nothing collides until [`DepthCollider::update`]).
    pub fn new(ctx: &GpuContext, layout: &wgpu::BindGroupLayout) -> Self {
        let uniform = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("DepthCollider::uniform"),
            size: size_of::<DepthViewUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let placeholder = crate::gpu::placeholder_depth(&ctx.device, "DepthCollider::placeholder");
        let group = bind(ctx, layout, &placeholder, &uniform);
        Self {
            uniform,
            group,
            bound: None,
            placeholder,
        }
    }

    /// Points the collider at `host` (or at nothing) for an emitter whose simulation
    /// space has its origin at `origin`; the write lands before the submission runs.
    pub fn update(
        &mut self,
        ctx: &GpuContext,
        layout: &wgpu::BindGroupLayout,
        host: Option<&HostDepthView>,
        origin: DVec3,
    ) {
        let uniform = host.map_or_else(DepthViewUniform::default, |h| h.uniform(origin));
        ctx.queue
            .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
        let view = host.map(|h| &h.view);
        if view != self.bound.as_ref() {
            let bound = view.unwrap_or(&self.placeholder);
            self.group = bind(ctx, layout, bound, &self.uniform);
            self.bound = view.cloned();
        }
    }

    /// The group to set at index 2.
    pub fn group(&self) -> &wgpu::BindGroup {
        &self.group
    }
}

fn bind(
    ctx: &GpuContext,
    layout: &wgpu::BindGroupLayout,
    depth: &wgpu::TextureView,
    uniform: &wgpu::Buffer,
) -> wgpu::BindGroup {
    ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("DepthCollider::group"),
        layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(depth),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: uniform.as_entire_binding(),
            },
        ],
    })
}
