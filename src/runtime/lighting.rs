//! The scene's light for lit layers (six-way smoke): the host's sun, ambient and point
//! lights, in the host's world, turned into the preset's.

use super::Player;
use crate::render::scene_lighting::SceneLighting;

impl Player {
    /// Lights lit layers with the host's light instead of the preset's `lighting`: a
    /// sun, an ambient term and up to [`crate::MAX_POINT_LIGHTS`] point
    /// lights, in the host's world (turned into the preset's by
    /// [`super::PlayerSettings::world_up`]). `None` goes back to the preset's. The
    /// effect's own light (its additive layers) lights them either way, measured on the
    /// GPU the frame it is drawn.
    pub fn set_lighting(&mut self, lighting: Option<SceneLighting>) {
        let to_preset = self.settings.host_from_preset().map(|q| q.inverse());
        self.frame.lighting = lighting.map(|mut l| {
            if let Some(q) = to_preset {
                l.sun_direction = q * l.sun_direction;
                for p in &mut l.point_lights {
                    p.position = q * p.position;
                }
            }
            l
        });
    }

    /// The host's light set by [`Player::set_lighting`] (in the preset's world).
    pub fn lighting(&self) -> Option<&SceneLighting> {
        self.frame.lighting.as_ref()
    }
}
