//! The host's depth buffer as the player samples it: checked (it must be sampleable and
//! the target's size), its depth aspect taken from a depth-stencil format, and a
//! multisampled one copied to a single sample first.

use crate::gpu::GpuContext;
use crate::render::Camera;
use crate::render::depth_resolve::DepthResolvePass;
use crate::shaders::{ShaderError, ShaderLibrary};
use crate::sim::depth_collision::HostDepthView;

use super::Player;
use super::instances::Backing;

/// What the player keeps of the host's depth between frames.
pub(super) struct HostDepth {
    /// The host's view last handed over, and the view the passes bind for it (itself, its
    /// depth aspect, or the resolved copy's).
    last: Option<(wgpu::TextureView, wgpu::TextureView)>,
    /// The copy of a multisampled depth (built on first need).
    resolve: Option<DepthResolvePass>,
}

impl HostDepth {
    /// Nothing handed over yet.
    pub fn new() -> Self {
        Self {
            last: None,
            resolve: None,
        }
    }

    /// Rebuilds the copy's pipeline from `lib` (when it has been built); keeps the old
    /// one on error.
    pub fn rebuild(&mut self, ctx: &GpuContext, lib: &ShaderLibrary) -> Result<(), ShaderError> {
        if self.resolve.is_some() {
            self.resolve = Some(DepthResolvePass::new(ctx, lib)?);
            self.last = None;
        }
        Ok(())
    }

    /// The view of `host` the depth-sampling passes bind for a target of `size` pixels
    /// (recording the copy of a multisampled depth into `enc`), or why it cannot be used;
    /// `expected` is the player's depth format and sample count (its pipelines').
    pub fn sampled(
        &mut self,
        ctx: &GpuContext,
        lib: &ShaderLibrary,
        enc: &mut wgpu::CommandEncoder,
        host: &wgpu::TextureView,
        size: (u32, u32),
        expected: (wgpu::TextureFormat, u32),
    ) -> Result<wgpu::TextureView, String> {
        let texture = host.texture();
        check(texture, size, expected)?;
        let depth_only = match self.last.as_ref().filter(|(h, _)| h == host) {
            Some((_, view)) if texture.sample_count() == 1 => return Ok(view.clone()),
            Some((_, view)) => view.clone(),
            None => depth_aspect(host),
        };
        let bound = if texture.sample_count() > 1 {
            let pass = match &mut self.resolve {
                Some(p) => p,
                None => self
                    .resolve
                    .insert(DepthResolvePass::new(ctx, lib).map_err(|e| shader_error(&e))?),
            };
            let resolved = pass.record(ctx, enc, &depth_only, size);
            self.last = Some((host.clone(), depth_only));
            resolved
        } else {
            self.last = Some((host.clone(), depth_only.clone()));
            depth_only
        };
        Ok(bound)
    }
}

/// Why a host's depth `texture` cannot be sampled for a target of `size` by a player
/// built for `expected` (depth format, sample count), if it cannot.
fn check(
    texture: &wgpu::Texture,
    size: (u32, u32),
    expected: (wgpu::TextureFormat, u32),
) -> Result<(), String> {
    let usage = texture.usage();
    if usage.contains(wgpu::TextureUsages::TRANSIENT_ATTACHMENT) {
        return Err("it is a transient attachment (TextureUsages::TRANSIENT_ATTACHMENT), whose contents \
                    do not outlive the host's pass; create it without TRANSIENT_ATTACHMENT and with \
                    TEXTURE_BINDING, and store it (StoreOp::Store) in the opaque pass"
            .into());
    }
    if !usage.contains(wgpu::TextureUsages::TEXTURE_BINDING) {
        return Err(format!(
            "the texture's usage is {usage:?}, without TEXTURE_BINDING; add \
             TextureUsages::TEXTURE_BINDING where the host creates it"
        ));
    }
    let format = texture.format();
    if !format.has_depth_aspect() {
        return Err(format!("{format:?} is not a depth format"));
    }
    if (format, texture.sample_count()) != expected {
        return Err(format!(
            "it is {format:?} with {} sample(s), the player was created for {:?} with {} \
             (PlayerSettings::depth_format and sample_count must match the host's pass)",
            texture.sample_count(),
            expected.0,
            expected.1
        ));
    }
    let have = (texture.width(), texture.height());
    if have != size {
        return Err(format!(
            "it is {}×{} pixels, the camera's target {}×{}; hand over the depth of the \
             target drawn into",
            have.0, have.1, size.0, size.1
        ));
    }
    Ok(())
}

/// `host`'s depth aspect alone (a depth-stencil texture cannot be sampled whole).
fn depth_aspect(host: &wgpu::TextureView) -> wgpu::TextureView {
    if host.texture().format().has_stencil_aspect() {
        host.texture().create_view(&wgpu::TextureViewDescriptor {
            label: Some("ignis: host depth aspect"),
            aspect: wgpu::TextureAspect::DepthOnly,
            ..Default::default()
        })
    } else {
        host.clone()
    }
}

fn shader_error(e: &ShaderError) -> String {
    format!("the depth copy's shader failed: {e}")
}

impl Player {
    /// The depth (seen by `camera`) the steps of a following [`Player::simulate`] collide
    /// with: the editor's test scene, drawn before its timed update.
    #[cfg(feature = "editor")]
    pub(crate) fn collide_with(&mut self, camera: &Camera, depth: Option<&wgpu::TextureView>) {
        let camera = self.preset_camera(camera);
        self.point_depth_collision(&camera, depth);
    }

    /// Hands this frame's depth (and `camera`, in the presets' world) to every simulation
    /// with depth collision: the steps recorded next collide with it.
    pub(super) fn point_depth_collision(
        &mut self,
        camera: &Camera,
        depth: Option<&wgpu::TextureView>,
    ) {
        let host = depth.map(|view| HostDepthView {
            view: view.clone(),
            clip_from_world: camera.clip_from_world(),
            reversed_z: camera.reversed_z(),
            size: camera.size_px(),
        });
        for instance in self.instances.iter_mut() {
            if let (Backing::Own(sim), _) = instance.state_mut() {
                sim.set_host_depth(host.clone());
            }
        }
    }

    /// The view of the host's depth the passes sample (see [`HostDepth`]), or why the
    /// one handed over cannot be.
    pub(super) fn host_depth_view(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        camera: &Camera,
        scene_depth: Option<&wgpu::TextureView>,
    ) -> (Option<wgpu::TextureView>, Option<String>) {
        let Some(view) = scene_depth else {
            return (None, None);
        };
        let Some(format) = self.settings.depth_format else {
            let why = "the player was created without a depth format \
                       (PlayerSettings::depth_format)";
            return (None, Some(why.into()));
        };
        let expected = (format, self.settings.sample_count.max(1));
        let size = camera.size_px();
        match (self.host_depth).sampled(&self.ctx, &self.library, encoder, view, size, expected) {
            Ok(v) => (Some(v), None),
            Err(why) => (None, Some(why)),
        }
    }
}
