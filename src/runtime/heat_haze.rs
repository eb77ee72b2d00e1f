//! Heat haze in the runtime: the effect's haze layers drawn into the player's distortion
//! target and the frame refracted by it, after the particles' pass.

use crate::render::haze::{HAZE_DOWNSCALE, HazePass};
use crate::sim::SimError;

use super::{Player, PlayerError};

impl Player {
    /// Whether the last record has heat haze to apply (an emitter with `look.heat_haze`
    /// and particles to draw).
    pub fn has_haze(&self) -> bool {
        self.items.iter().any(|d| d.variant.haze && d.width > 0)
    }

    /// Heat haze, after the particles are drawn: draws the effect's haze layers into the
    /// player's distortion target (the target's size; the host's depth handed to
    /// [`Player::record`] hides them behind geometry) and refracts `scene` — a copy of the
    /// frame's colour so far (`copy_texture_to_texture` of your colour after the
    /// particles' pass) — into `target`, the frame's colour (single-sample: a multisampled
    /// host's resolved colour; the player's colour format, `RENDER_ATTACHMENT` usage),
    /// every pixel written. Without haze nothing is recorded
    /// and `target` keeps its image; returns whether the haze was applied.
    pub fn apply_haze(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        scene: &wgpu::TextureView,
        target: &wgpu::TextureView,
    ) -> Result<bool, PlayerError> {
        let size = target.texture().size();
        let frame = (size.width, size.height);
        let start = crate::gpu::commands::recorded();
        if !self.draw_distortion(encoder, (frame, HAZE_DOWNSCALE))? {
            return Ok(false);
        }
        if let Some(haze) = &self.haze {
            haze.refract(&self.ctx, encoder, scene, target);
        }
        // The frame's commands (`Player::recorded_commands`) include the haze's.
        self.commands.add_since(start);
        Ok(true)
    }

    /// Draws the haze layers into the distortion target of a frame of `size.0` pixels,
    /// `size.1` times smaller, without refracting anything (the export's distortion pass
    /// at full size); false, and nothing recorded, without haze.
    pub(crate) fn draw_distortion(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        size: ((u32, u32), u32),
    ) -> Result<bool, PlayerError> {
        if !self.has_haze() {
            return Ok(false);
        }
        let haze = match &mut self.haze {
            Some(h) => h,
            None => {
                let format = self.settings.color_format;
                let pass =
                    HazePass::new(&self.ctx, &self.library, format).map_err(SimError::from)?;
                self.haze.insert(pass)
            }
        };
        let mut pass = haze.begin(&self.ctx, encoder, size, wgpu::Color::TRANSPARENT);
        self.billboard
            .draw_haze(&mut pass, &self.frame, &self.items);
        Ok(true)
    }

    /// The distortion target as last drawn by [`Player::apply_haze`] (rg: summed offsets
    /// in uv units; the export's distortion pass).
    #[cfg(feature = "editor")]
    pub(crate) fn distortion(&self) -> Option<&wgpu::Texture> {
        self.haze.as_ref().and_then(HazePass::distortion)
    }
}
