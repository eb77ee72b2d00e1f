//! [`HostTargets`]: the host's views the particles are drawn into, and the render pass a
//! host without one of its own begins on them.

use super::Player;

/// The host's colour (and MSAA resolve) and depth views, as the particles' pass uses
/// them: colour loaded and stored, depth read-only (the particles test against it and
/// sample it; they never write it).
#[derive(Clone, Copy, Debug)]
pub struct HostTargets<'a> {
    /// The colour attachment (the player's `color_format` and `sample_count`).
    pub color: &'a wgpu::TextureView,
    /// Where a multisampled `color` is resolved at the end of the pass (`None`: not
    /// multisampled, or the host resolves later).
    pub resolve_target: Option<&'a wgpu::TextureView>,
    /// The depth attachment (the player's `depth_format`), written by the host's opaque
    /// pass; `None` for a player without depth.
    pub depth: Option<&'a wgpu::TextureView>,
}

impl<'a> HostTargets<'a> {
    /// Begins the particles' render pass on these views; draw any number of players in
    /// it with [`Player::draw`].
    pub fn begin_pass<'e>(&self, encoder: &'e mut wgpu::CommandEncoder) -> wgpu::RenderPass<'e> {
        encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("ignis: particles"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: self.color,
                depth_slice: None,
                resolve_target: self.resolve_target,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                },
            })],
            // Read-only depth (and stencil, for a depth-stencil format).
            depth_stencil_attachment: self.depth.map(|view| {
                wgpu::RenderPassDepthStencilAttachment {
                    view,
                    depth_ops: None,
                    stencil_ops: None,
                }
            }),
            ..Default::default()
        })
    }
}

impl Player {
    /// Draws every instance's particles in a render pass of their own on the host's
    /// views ([`HostTargets::begin_pass`], then [`Player::draw`]), for a host with no
    /// pass of its own to draw them in.
    pub fn draw_to(&self, encoder: &mut wgpu::CommandEncoder, targets: &HostTargets<'_>) {
        let mut pass = targets.begin_pass(encoder);
        self.draw(&mut pass);
    }
}
