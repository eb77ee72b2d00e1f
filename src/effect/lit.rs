//! Lit smoke: an alpha-blended layer shaded by six-way lightmaps (how its sprite looks lit
//! from +X, −X, +Y, −Y, +Z and −Z of the sprite's frame), mixed per particle by where
//! each light is — the effect's own light (its additive layers), the scene's sun and
//! ambient ([`Lighting`]) and the host's point lights.

use serde::{Deserialize, Serialize};

use super::validate::Checker;

/// An alpha-blended emitter lit with six-way lightmaps (its `sprite` is replaced by the
/// maps).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Lit {
    /// Where the lightmaps come from.
    pub maps: SixWayMaps,
    /// The smoke's colour under white light (linear RGB; multiplies every light).
    pub albedo: [f32; 3],
    /// How much of the colour over life the smoke emits itself, masked by the maps'
    /// emissive channel (0: only lit; 1: the unlit look's colour is kept as glow — embers
    /// in the smoke).
    pub emission: f32,
    /// How strongly the effect's own light (its additive layers, measured on the GPU each
    /// frame) lights this layer: 1 = physically, the light's power over the squared
    /// distance; 0 = not at all.
    pub self_light: f32,
}

impl Default for Lit {
    fn default() -> Self {
        Self {
            maps: SixWayMaps::Puff,
            albedo: [0.6, 0.6, 0.6],
            emission: 0.0,
            self_light: 1.0,
        }
    }
}

/// A lit layer's six-way lightmaps: two RGBA images per frame in the packing Unity's
/// Six Way shader reads — RTBA (red: lit from the right, +X; green: from the top, +Y;
/// blue: from the back, +Z away from the viewer; alpha: coverage) and LBFE (left, bottom,
/// front, emissive mask). Linear, straight (not premultiplied) 8-bit channels.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum SixWayMaps {
    /// The built-in puff, ray-marched at start (`ignis sprites` writes it out).
    Puff,
    /// The built-in 4 × 4 flipbook of a puff that billows and thins over its life (use
    /// with a 4 × 4 flipbook).
    PuffSheet,
    /// A pair of PNGs (from EmberGen, Houdini or `ignis sprites`), relative to the preset
    /// file; a flipbook's frames lie in both images alike.
    Images {
        /// Right, top, back and alpha.
        rtba: String,
        /// Left, bottom, front and emissive.
        lbfe: String,
    },
}

/// The light a scene gives lit layers besides the effect's own: a sun and an ambient
/// term. The preset holds the editor's; a host that plays it sets its own
/// (`Player::set_lighting`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Lighting {
    /// Towards the sun, in the effect's world (normalised when used).
    pub sun_direction: [f32; 3],
    /// The sun's colour times its strength (linear; 1 lights a white sprite white).
    pub sun_color: [f32; 3],
    /// Light from every direction (linear).
    pub ambient: [f32; 3],
}

impl Default for Lighting {
    /// A night: a dim blue-white moon high to the left behind, a little sky.
    fn default() -> Self {
        Self {
            sun_direction: [-0.4, 0.8, -0.45],
            sun_color: [0.05, 0.06, 0.08],
            ambient: [0.015, 0.017, 0.022],
        }
    }
}

impl Lit {
    /// Checks the numbers and paths (`p` prefixes the field names).
    pub(super) fn check(&self, p: &dyn Fn(&str) -> String, c: &mut Checker) {
        for (k, v) in self.albedo.iter().enumerate() {
            c.num(|| p(&format!("look.lit.albedo[{k}]")), *v, 0.0, 1.0);
        }
        c.num(|| p("look.lit.emission"), self.emission, 0.0, 1e4);
        c.num(|| p("look.lit.self_light"), self.self_light, 0.0, 1e4);
        if let SixWayMaps::Images { rtba, lbfe } = &self.maps {
            for (name, path) in [("rtba", rtba), ("lbfe", lbfe)] {
                if path.trim().is_empty() {
                    c.push(
                        p(&format!("look.lit.maps.{name}")),
                        "\"\"",
                        "needs a PNG path, relative to the preset file",
                    );
                }
            }
        }
    }
}

impl Lighting {
    /// Checks the numbers.
    pub(super) fn check(&self, c: &mut Checker) {
        c.nonzero_vec3(|| "lighting.sun_direction".into(), self.sun_direction);
        for (name, v) in [("sun_color", self.sun_color), ("ambient", self.ambient)] {
            for (k, x) in v.iter().enumerate() {
                c.num(|| format!("lighting.{name}[{k}]"), *x, 0.0, 1e4);
            }
        }
    }

    /// The sun's direction, normalised (straight up when it has none).
    pub fn sun_unit(&self) -> glam::Vec3 {
        glam::Vec3::from(self.sun_direction)
            .try_normalize()
            .unwrap_or(glam::Vec3::Y)
    }
}
