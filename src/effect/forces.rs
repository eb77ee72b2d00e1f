//! Forces and colliders of an emitter: gravity, buoyancy, drag and wind, and the optional
//! modules (gusts, turbulence, vortex, attractor, flame pull), the ground and spheres.

use serde::{Deserialize, Serialize};

use super::*;

/// Forces on alive particles: a = gravity + buoyancy·up − drag·(v − wind).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Forces {
    /// Gravity, m/s².
    pub gravity_m_per_s2: [f32; 3],
    /// Upward buoyancy of hot gas, m/s² along +Y (the thesis's "negative gravity").
    pub buoyancy_m_per_s2: f32,
    /// Linear (Stokes) drag rate k, 1/s: the velocity relaxes toward the wind.
    pub drag_per_sec: f32,
    /// The flow velocity drag pulls toward, m/s.
    pub wind_m_per_s: [f32; 3],
    /// Multiplies both drags over each particle's normalised age (1 = unchanged).
    pub drag_over_life: Param,
    /// Multiplies each step's displacement over each particle's normalised age: the
    /// particle moves this much faster than its velocity says (1 = unchanged).
    pub speed_over_life: Param,
    /// Quadratic drag c, 1/m: a = −c·|v − wind|·(v − wind). 0 = off.
    pub quadratic_drag_per_m: f32,
    /// Noise-modulated wind strength (off when absent).
    pub gusts: Option<Gusts>,
    /// Curl-noise turbulence (off when absent).
    pub turbulence: Option<Turbulence>,
    /// Swirl around an axis (off when absent).
    pub vortex: Option<Vortex>,
    /// Point attractor / repulsor (off when absent).
    pub attractor: Option<Attractor>,
    /// Pull toward the emitter axis growing with age, so flames taper (off when absent).
    pub flame_pull: Option<FlamePull>,
}

/// Wind gusts: the wind is scaled by 1 + strength·n(t), n a smooth noise in [−1, 1].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Gusts {
    /// Gust strength as a fraction of the wind (0..).
    pub strength: f32,
    /// How often gusts change, Hz.
    pub frequency_hz: f32,
}

/// Curl-noise turbulence: divergence-free, seeded, scrolling upward.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Turbulence {
    /// Typical acceleration, m/s².
    pub strength_m_per_s2: f32,
    /// Spatial frequency, 1/m.
    pub frequency_per_m: f32,
    /// Octaves (1..=4), each twice the frequency and half the amplitude.
    pub octaves: u32,
    /// Upward scroll of the field, m/s.
    pub scroll_m_per_s: f32,
    /// Multiplies the strength over each particle's normalised age (1 = unchanged).
    pub over_life: Param,
}

/// A vortex: tangential acceleration around an axis with a Gaussian falloff.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Vortex {
    /// A point on the axis, world metres.
    pub center_m: [f32; 3],
    /// Axis direction (normalised on use).
    pub axis: [f32; 3],
    /// Tangential acceleration near the axis, m/s² (sign = direction of spin).
    pub swirl_m_per_s2: f32,
    /// Falloff radius, metres: a·exp(−d²/R²).
    pub radius_m: f32,
}

/// How an attractor's pull falls off with distance (Latta's two choices).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Falloff {
    /// a = s·d/(|d|² + ε²)^{3/2}, s in m³/s², ε = radius (Plummer softening).
    InverseSquare,
    /// |a| = s (m/s²) within the radius, zero outside.
    ConstantWithinRadius,
}

/// A point attractor (positive strength) or repulsor (negative).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Attractor {
    /// Position, world metres.
    pub position_m: [f32; 3],
    /// Strength (see [`Falloff`] for units); negative repels.
    pub strength: f32,
    /// Softening radius (inverse square) or range (constant), metres.
    pub radius_m: f32,
    /// Falloff law.
    pub falloff: Falloff,
}

/// Pull toward the emitter axis: a = −strength·(age/life)^exponent·(radial offset).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FlamePull {
    /// Pull strength, 1/s².
    pub strength_per_s2: f32,
    /// Growth with normalised age (1 = linear).
    pub exponent: f32,
    /// Multiplies the strength over each particle's normalised age (1 = unchanged).
    pub over_life: Param,
}

/// Colliders an emitter's particles bounce off (or die on).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Collisions {
    /// An infinite horizontal ground plane.
    pub ground: Option<GroundPlane>,
    /// Up to four spheres.
    pub spheres: Vec<SphereCollider>,
    /// Normal restitution, 0 (stop) ..= 1 (perfect bounce).
    pub elasticity: f32,
    /// Tangential loss per contact, 0..=1.
    pub friction: f32,
    /// Below this normal speed after a bounce, the particle rests (no hovering, no jitter).
    pub rest_speed_m_per_s: f32,
    /// Kill particles that touch a sphere (smoke into a wall).
    pub kill_on_sphere_contact: bool,
    /// Particles lose all velocity where they touch a collider (embers settling on the
    /// ground). Forces still act afterwards: on the ground a stuck particle stays; on a
    /// sphere's side, gravity can pull it off again.
    pub stick_on_contact: bool,
    /// Collide with the host's depth buffer (screen-space collision): the geometry the
    /// camera sees stops the particles, with the response above. Needs a depth view handed
    /// to the runtime; without one (or off screen) particles fly on.
    pub depth_collision: Option<DepthCollision>,
}

/// Collision with what the host's depth buffer shows: each step's path of a particle is
/// marched across the screen against the depth, the crossing refined, the surface's
/// normal rebuilt from the depth around it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DepthCollision {
    /// How thick the surfaces the depth buffer shows are taken to be, metres: a particle
    /// that crosses behind a surface within this distance of it hits it; one further
    /// behind (a silhouette it passes behind, a wall seen edge-on) flies on.
    pub thickness_m: f32,
    /// Kill particles that touch the host's geometry (sparks that go out).
    pub kill_on_contact: bool,
}

impl Default for DepthCollision {
    fn default() -> Self {
        Self {
            thickness_m: 0.25,
            kill_on_contact: false,
        }
    }
}

/// A horizontal plane y = height.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GroundPlane {
    /// Height of the plane, metres.
    pub height_m: f32,
    /// Kill particles that touch it.
    pub kill_on_contact: bool,
}

/// A sphere collider.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SphereCollider {
    /// Centre, world metres.
    pub center_m: [f32; 3],
    /// Radius, metres.
    pub radius_m: f32,
}

/// The maximum number of sphere colliders per emitter.
pub const MAX_SPHERES: usize = 4;

impl Default for Gusts {
    fn default() -> Self {
        Self {
            strength: 0.6,
            frequency_hz: 0.7,
        }
    }
}

impl Default for Turbulence {
    fn default() -> Self {
        Self {
            strength_m_per_s2: 2.0,
            frequency_per_m: 2.5,
            octaves: 2,
            scroll_m_per_s: 0.8,
            over_life: Param::Constant(1.0),
        }
    }
}

impl Default for Vortex {
    fn default() -> Self {
        Self {
            center_m: [0.0; 3],
            axis: [0.0, 1.0, 0.0],
            swirl_m_per_s2: 2.0,
            radius_m: 0.5,
        }
    }
}

impl Default for Attractor {
    fn default() -> Self {
        Self {
            position_m: [0.0, 1.5, 0.0],
            strength: 1.0,
            radius_m: 0.2,
            falloff: Falloff::InverseSquare,
        }
    }
}

impl Default for FlamePull {
    fn default() -> Self {
        Self {
            strength_per_s2: 6.0,
            exponent: 1.0,
            over_life: Param::Constant(1.0),
        }
    }
}

impl Default for Collisions {
    fn default() -> Self {
        Self {
            ground: None,
            spheres: Vec::new(),
            elasticity: 0.4,
            friction: 0.2,
            rest_speed_m_per_s: 0.05,
            kill_on_sphere_contact: false,
            stick_on_contact: false,
            depth_collision: None,
        }
    }
}

impl Collisions {
    /// True when the ground or a sphere is present (the analytic colliders).
    pub fn any(&self) -> bool {
        self.ground.is_some() || !self.spheres.is_empty()
    }
}

impl Default for SphereCollider {
    fn default() -> Self {
        Self {
            center_m: [0.0, 1.0, 0.0],
            radius_m: 0.3,
        }
    }
}

impl Forces {
    /// The constant part of the acceleration (gravity + buoyancy), m/s².
    pub fn constant_acceleration(&self) -> glam::Vec3 {
        glam::Vec3::from(self.gravity_m_per_s2) + glam::Vec3::Y * self.buoyancy_m_per_s2
    }
}

impl Default for Forces {
    fn default() -> Self {
        Self {
            gravity_m_per_s2: [0.0, -9.81, 0.0],
            buoyancy_m_per_s2: 11.5,
            drag_per_sec: 1.2,
            wind_m_per_s: [0.1, 0.0, 0.0],
            drag_over_life: Param::Constant(1.0),
            speed_over_life: Param::Constant(1.0),
            quadratic_drag_per_m: 0.0,
            gusts: None,
            turbulence: None,
            vortex: None,
            attractor: None,
            flame_pull: None,
        }
    }
}
