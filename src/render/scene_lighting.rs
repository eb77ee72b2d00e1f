//! Lit layers' light on the CPU side: the scene's light a host (or the preset) gives —
//! [`SceneLighting`] — and each lit look slot's [`LitUniform`] (`shaders/lit.wgsl`), in the
//! emitter's simulation space. The effect's own light is added on the GPU
//! (`light_apply.rs`).

use bytemuck::{Pod, Zeroable};
use glam::{DVec3, Vec3};

use crate::effect::{Lighting, Lit};

/// Host point lights a lit layer takes at most (the nearest are the host's to choose).
pub const MAX_POINT_LIGHTS: usize = 4;

/// The light of the scene a lit layer is drawn in, besides the effect's own: a sun, an
/// ambient term and a few point lights, in the effect's world (the host's, turned by
/// `PlayerSettings::world_up`, in the runtime).
#[derive(Clone, Debug, PartialEq)]
pub struct SceneLighting {
    /// Towards the sun (normalised when used).
    pub sun_direction: Vec3,
    /// The sun's colour times its strength (linear; 1 lights a white sprite white).
    pub sun_color: [f32; 3],
    /// Light from every direction (linear).
    pub ambient: [f32; 3],
    /// Point lights (at most [`MAX_POINT_LIGHTS`] are used: the first ones).
    pub point_lights: Vec<PointLight>,
    /// Multiplies the effect's own light on its lit layers (1: as the preset says; 0: a
    /// host that lights the smoke with the effect's light itself, or the export's
    /// six-way passes).
    pub own_light: f32,
    /// Multiplies the lit layers' glow (their `emission`; 1: as the preset says).
    pub glow: f32,
}

/// A host's point light as lit layers see it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLight {
    /// Where it is.
    pub position: Vec3,
    /// Its colour times its intensity: the light it gives at 1 m (linear).
    pub color: [f32; 3],
    /// Where its light ends (smoothly), metres.
    pub range_m: f32,
}

impl From<&Lighting> for SceneLighting {
    fn from(l: &Lighting) -> Self {
        Self {
            sun_direction: l.sun_unit(),
            sun_color: l.sun_color,
            ambient: l.ambient,
            point_lights: Vec::new(),
            own_light: 1.0,
            glow: 1.0,
        }
    }
}

/// `shaders/look.wgsl`'s `LitUniform`: the part of a look slot after its `LookUniform`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct LitUniform {
    /// xyz: towards the sun, w: the effect light's gain.
    pub sun_dir: [f32; 4],
    /// rgb: the sun's colour, w: point lights used.
    pub sun_color: [f32; 4],
    /// rgb: ambient, w: emission.
    pub ambient: [f32; 4],
    /// rgb: albedo.
    pub albedo: [f32; 4],
    /// The effect's light (written on the GPU): centre and spread².
    pub self_pos: [f32; 4],
    /// The effect's light: power (rgb) and luminance.
    pub self_rgb: [f32; 4],
    /// Point lights: (position, range), (colour, 0).
    pub points: [[f32; 4]; 2 * MAX_POINT_LIGHTS],
}

impl LitUniform {
    /// The uniform of a layer lit by `lit` under `scene`, for an emitter whose simulation
    /// space starts at `origin` (the effect's own light is left for the GPU).
    pub fn new(lit: &Lit, scene: &SceneLighting, origin: DVec3) -> Self {
        let sun = scene.sun_direction.try_normalize().unwrap_or(Vec3::Y);
        let mut points = [[0.0; 4]; 2 * MAX_POINT_LIGHTS];
        let used = scene.point_lights.len().min(MAX_POINT_LIGHTS);
        for (k, p) in scene.point_lights.iter().take(used).enumerate() {
            let at = (p.position.as_dvec3() - origin).as_vec3();
            points[2 * k] = at.extend(p.range_m.max(0.0)).to_array();
            points[2 * k + 1] = [p.color[0], p.color[1], p.color[2], 0.0];
        }
        let [r, g, b] = scene.sun_color;
        let [ar, ag, ab] = scene.ambient;
        let [lr, lg, lb] = lit.albedo;
        Self {
            sun_dir: sun.extend(lit.self_light * scene.own_light).to_array(),
            sun_color: [r, g, b, used as f32],
            ambient: [ar, ag, ab, lit.emission * scene.glow],
            albedo: [lr, lg, lb, 0.0],
            self_pos: [0.0; 4],
            self_rgb: [0.0; 4],
            points,
        }
    }
}

/// Writes `u` into a look slot's bytes (after its `LookUniform`).
pub fn write_lit(slot: &mut [u8], u: &LitUniform) {
    let at = size_of::<crate::gpu::types::LookUniform>();
    slot[at..at + size_of::<LitUniform>()].copy_from_slice(bytemuck::bytes_of(u));
}

const _: () = assert!(
    size_of::<crate::gpu::types::LookUniform>() + size_of::<LitUniform>()
        == crate::gpu::types::PARAMS_STRIDE as usize
);
