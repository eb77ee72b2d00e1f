//! The effect model: what a designer edits and what a preset file stores.
//!
//! Everything a designer tunes lives here (no parameter lives only in a widget or a
//! shader). The structs are plain serde data; [`Effect::validate`] checks ranges and
//! finiteness so nothing impossible ever reaches the GPU.

use serde::{Deserialize, Serialize};

mod curve;
mod events;
mod lit;
mod rate_cap;
mod stability;
mod trail;
mod validate;

pub use curve::{
    CURVE_WIDTH, Curve, MAX_CURVE_KEYS, Param, ParamMode, SHAPES, bake_rows, lookup, lookup_blend,
    rows_key,
};
pub use events::{CountRange, Event, MAX_CHILDREN_PER_EVENT, MAX_EVENTS_PER_EMITTER, Trigger};
pub use lit::{Lighting, Lit, SixWayMaps};
pub use rate_cap::{CAP_BURST_SECS, RateCap, cap_burst};
pub use stability::{
    GROWTH_LIMIT, StabilityWarning, Stiffness, largest_stable_step, lifetime_growth,
};
pub use trail::{MAX_TRAIL_POINTS, Trail, TrailLayout, TrailMode};
use validate::Checker;
pub use validate::ValidationError;

/// The preset format version this build writes (and the newest it reads).
pub const CURRENT_VERSION: u32 = 3;

/// A whole fire effect: a seed, time settings and a list of emitter layers.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Effect {
    /// Preset format version (see [`CURRENT_VERSION`]).
    pub version: u32,
    /// Human-readable name.
    pub name: String,
    /// Master seed; every random number is a hash of (seed, emitter, slot, spawn counter).
    pub seed: u32,
    /// How simulated time advances.
    pub time: TimeSettings,
    /// Where the camera starts.
    pub camera: CameraHint,
    /// Emitter layers (flame, embers, smoke…), drawn in order.
    pub emitters: Vec<Emitter>,
    /// The HDR composite: exposure and bloom.
    pub post: Post,
    /// The sun and ambient light of lit layers (a host may set its own).
    pub lighting: Lighting,
}

/// The HDR composite applied to the whole image: exposure, optional bloom, ACES tonemap.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Post {
    /// Multiplies the HDR image before the tonemap (1 = unchanged).
    pub exposure: f32,
    /// Glow around bright light; `None` costs nothing (the passes are not recorded).
    pub bloom: Option<Bloom>,
    /// Draw the alpha-blended layers (smoke) at 1/n of the resolution, n = 1..=4, and
    /// upsample them in the composite: soft smoke looks the same and costs n² less fill.
    pub alpha_downscale: u32,
}

impl Default for Post {
    fn default() -> Self {
        Self {
            exposure: 1.0,
            bloom: None,
            alpha_downscale: 1,
        }
    }
}

/// Bloom: light above `threshold` is blurred over a mip chain and added back.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Bloom {
    /// HDR luminance where the glow starts (soft knee below it).
    pub threshold: f32,
    /// How much of the blurred light is added back.
    pub intensity: f32,
    /// Blur levels (each halves the resolution; more = wider glow), 1..=8.
    pub levels: u32,
}

impl Default for Bloom {
    fn default() -> Self {
        Self {
            threshold: 1.0,
            intensity: 0.35,
            levels: 6,
        }
    }
}

/// How simulated time advances relative to wall-clock frames.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TimeSettings {
    /// Fixed step (deterministic, frame-rate independent) or one step per frame.
    pub mode: TimeMode,
    /// Fixed step size in seconds (fixed mode).
    pub step_secs: f32,
    /// At most this many steps per frame; the rest of the time is dropped and counted.
    pub max_substeps: u32,
    /// Largest step in frame-delta mode, in seconds (a long frame is clamped to this).
    pub max_frame_dt_secs: f32,
    /// Simulation speed multiplier (1 = real time).
    pub speed: f32,
}

/// Time stepping mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum TimeMode {
    /// A fixed step with an accumulator: the same result at any frame rate.
    FixedStep,
    /// One step per frame with dt = min(frame dt, max dt): the 2006 thesis's mode.
    FrameDelta,
}

/// Initial camera placement (an orbit around `target_m`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CameraHint {
    /// The orbit centre in world space, metres.
    pub target_m: [f32; 3],
    /// Distance from the target, metres.
    pub distance_m: f32,
    /// Rotation around the vertical axis, degrees.
    pub yaw_deg: f32,
    /// Elevation above the horizon, degrees.
    pub pitch_deg: f32,
    /// Vertical field of view, degrees.
    pub fov_y_deg: f32,
}

/// One layer of the effect: its own particle pool, spawning, forces and look.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Emitter {
    /// Display name (unique within the effect).
    pub name: String,
    /// Muted emitters neither simulate nor draw.
    pub enabled: bool,
    /// Number of particle slots in this emitter's ring.
    pub capacity: u32,
    /// Continuous emission rate, particles per second, over the effect's time in seconds
    /// (a curve's keys are `(seconds, rate)`; a range or two curves pick one rate or one
    /// blend per instance, from its seed).
    pub spawn_rate_per_sec: Param,
    /// At most this many continuous spawns per second of simulated time, whatever the
    /// step (a rate curve's peaks are clipped to it; bursts are not capped), with bursts of
    /// a tenth of a second's worth let through ([`RateCap`]). 0 = no cap.
    pub max_spawn_per_sec: f32,
    /// One-shot bursts.
    pub bursts: Vec<Burst>,
    /// Lifetime range, seconds; each particle draws its own.
    pub lifetime_secs: Range,
    /// Where particles are born (in emitter space).
    pub shape: Shape,
    /// Emitter placement in the world.
    pub transform: Transform,
    /// Initial direction (emitter space, normalised on use).
    pub direction: [f32; 3],
    /// Half-angle of the cone of initial directions around `direction`, degrees.
    pub spread_deg: f32,
    /// Initial speed range, metres per second.
    pub speed_m_per_s: Range,
    /// Forces acting on alive particles.
    pub forces: Forces,
    /// Noise that perturbs spawn positions and directions over time (flicker).
    pub spawn_noise: SpawnNoise,
    /// Integration method.
    pub integrator: Integrator,
    /// Stateless mode (Latta; the 2012 blog's closed-form fountain): no per-step update,
    /// positions evaluated in closed form from each particle's spawn record and age.
    /// Cheaper and exact, but only for constant acceleration + linear drag: see
    /// [`Emitter::stateless_blockers`].
    pub stateless: bool,
    /// Store the state packed in 20 bytes per particle instead of 32 (f16 velocity, the
    /// age as a 16-bit fraction of the lifetime, the lifetime re-derived from the spawn
    /// hash): less memory traffic, at the accuracy cost `ignis bench accuracy` reports.
    /// Not with `stateless`. Editing the lifetime range re-times living particles.
    pub packed_state: bool,
    /// Store the state in 10 bytes per particle: f16 position (relative to the emitter's
    /// origin), the velocity as a shared exponent and three 9-bit mantissas, no age
    /// (derived exactly from a table of each step's births) and no lifetime (re-derived
    /// from the spawn hash). An update moves 20 bytes per particle-step; the accuracy cost
    /// is in `ignis bench accuracy` ("+ tiny" rows). Not with `stateless` or
    /// `packed_state`. Changing the capacity restarts the emitter's particles; editing the
    /// lifetime range re-times living ones (as with `packed_state`). Positions stay
    /// precise while the emitter is near where its pool started (f16 relative to that
    /// origin: 1 mm at 1 m, 0.5 m at 1 km); particles beyond ±65 km die.
    pub tiny_state: bool,
    /// Ground and sphere colliders.
    pub collisions: Collisions,
    /// Added to the effect seed for this emitter's stream.
    pub seed_offset: u32,
    /// How the particles are drawn.
    pub look: Look,
    /// Particles of other emitters this emitter's particles spawn (on death, collision,
    /// birth or over life; see [`Event`]).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub events: Vec<Event>,
}

/// A one-shot burst of particles.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Burst {
    /// When the burst fires, seconds after the start.
    pub time_secs: f32,
    /// How many particles it spawns.
    pub count: u32,
}

/// A closed interval `[min, max]`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Range {
    /// Lower bound.
    pub min: f32,
    /// Upper bound (≥ min).
    pub max: f32,
}

impl Range {
    /// A range `[min, max]`.
    pub const fn new(min: f32, max: f32) -> Self {
        Self { min, max }
    }
}

/// Spawn shapes, all in emitter space.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Shape {
    /// All particles start at the emitter origin.
    Point,
    /// A sphere around the origin.
    Sphere {
        /// Radius, metres.
        radius_m: f32,
        /// Only on the surface (true) or anywhere inside (false).
        surface_only: bool,
    },
    /// A flat disc through the origin (the area emitter the 2006 thesis wished for).
    Disc {
        /// Radius, metres.
        radius_m: f32,
        /// Disc normal (normalised on use).
        normal: [f32; 3],
    },
    /// An axis-aligned box around the origin.
    Box {
        /// Half extents, metres.
        half_extents_m: [f32; 3],
    },
    /// A cone: born on its base disc (normal = emitter direction), directions within its angle.
    Cone {
        /// Half-angle of the cone, degrees (replaces `spread_deg`).
        angle_deg: f32,
        /// Radius of the base disc, metres.
        radius_m: f32,
    },
    /// A segment between two points.
    Line {
        /// First endpoint, metres.
        a_m: [f32; 3],
        /// Second endpoint, metres.
        b_m: [f32; 3],
    },
}

impl Shape {
    /// Stable index used on the GPU (keep in sync with `SHAPE_*` in `shaders/common.wgsl`).
    pub fn kind_index(&self) -> u32 {
        match self {
            Shape::Point => 0,
            Shape::Sphere { .. } => 1,
            Shape::Disc { .. } => 2,
            Shape::Box { .. } => 3,
            Shape::Cone { .. } => 4,
            Shape::Line { .. } => 5,
        }
    }

    /// Name for the UI.
    pub fn label(&self) -> &'static str {
        match self {
            Shape::Point => "Point",
            Shape::Sphere { .. } => "Sphere",
            Shape::Disc { .. } => "Disc",
            Shape::Box { .. } => "Box",
            Shape::Cone { .. } => "Cone",
            Shape::Line { .. } => "Line",
        }
    }

    /// A default instance of every shape, for pickers.
    pub fn all_defaults() -> [Shape; 6] {
        [
            Shape::Point,
            Shape::Sphere {
                radius_m: 0.3,
                surface_only: false,
            },
            Shape::Disc {
                radius_m: 0.3,
                normal: [0.0, 1.0, 0.0],
            },
            Shape::Box {
                half_extents_m: [0.3, 0.05, 0.3],
            },
            Shape::Cone {
                angle_deg: 15.0,
                radius_m: 0.2,
            },
            Shape::Line {
                a_m: [-0.4, 0.0, 0.0],
                b_m: [0.4, 0.0, 0.0],
            },
        ]
    }
}

/// Emitter placement: translation, then rotation (degrees, applied X, then Y, then Z).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Transform {
    /// World position of the emitter origin, metres.
    pub position_m: [f32; 3],
    /// Euler rotation, degrees.
    pub rotation_deg: [f32; 3],
}

impl Transform {
    /// The matrix that takes emitter-space points to world space.
    pub fn world_from_emitter(&self) -> glam::Mat4 {
        let [rx, ry, rz] = self.rotation_deg.map(f32::to_radians);
        let rotation = glam::Quat::from_euler(glam::EulerRot::ZYX, rz, ry, rx);
        glam::Mat4::from_rotation_translation(rotation, self.position_m.into())
    }
}

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
        }
    }
}

impl Collisions {
    /// True when any collider is present.
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

/// Noise that perturbs spawn positions and directions over time, so the flame flickers.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SpawnNoise {
    /// Spatial frequency of the noise field, 1/m.
    pub frequency_per_m: f32,
    /// Position offset amplitude, metres.
    pub position_amplitude_m: f32,
    /// Direction tilt amplitude (0..1, fraction of the direction vector).
    pub direction_amplitude: f32,
    /// How fast the field scrolls in time, 1/s.
    pub scroll_per_sec: f32,
}

/// Time integration methods (keep in sync with `INTEGRATOR_*` in `shaders/integrators.wgsl`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Integrator {
    /// x += v·dt; v += a(x, v)·dt — the 2006 thesis's method. Order 1.
    ExplicitEuler,
    /// v += a·dt; x += v·dt (symplectic Euler). Order 1.
    SemiImplicitEuler,
    /// Velocity Verlet with a predicted velocity for drag. Order 2.
    VelocityVerlet,
    /// Heun / RK2 (explicit trapezoid). Order 2.
    Heun,
    /// Classic Runge–Kutta 4 (four force evaluations). Order 4.
    Rk4,
    /// Exponential integrator: exact for constant acceleration plus linear drag.
    Exponential,
}

impl Integrator {
    /// All integrators, in UI order.
    pub const ALL: [Integrator; 6] = [
        Integrator::ExplicitEuler,
        Integrator::SemiImplicitEuler,
        Integrator::VelocityVerlet,
        Integrator::Heun,
        Integrator::Rk4,
        Integrator::Exponential,
    ];

    /// Stable index used as the `INTEGRATOR` pipeline override constant.
    pub fn index(self) -> u32 {
        match self {
            Integrator::ExplicitEuler => 0,
            Integrator::SemiImplicitEuler => 1,
            Integrator::VelocityVerlet => 2,
            Integrator::Heun => 3,
            Integrator::Rk4 => 4,
            Integrator::Exponential => 5,
        }
    }

    /// Name for the UI and tables.
    pub fn label(self) -> &'static str {
        match self {
            Integrator::ExplicitEuler => "explicit Euler",
            Integrator::SemiImplicitEuler => "semi-implicit Euler",
            Integrator::VelocityVerlet => "velocity Verlet",
            Integrator::Heun => "Heun (RK2)",
            Integrator::Rk4 => "RK4",
            Integrator::Exponential => "exponential",
        }
    }

    /// Largest stable k·dt for pure linear drag `v' = −k v` (None = unconditionally stable).
    ///
    /// From the amplification factor of each method on the test equation: Euler-type and
    /// Heun need |1 − z + …| ≤ 1 with z = k·dt, giving z < 2; RK4's real stability
    /// interval ends at z ≈ 2.785.
    pub fn drag_stability_limit(self) -> Option<f32> {
        match self {
            Integrator::ExplicitEuler
            | Integrator::SemiImplicitEuler
            | Integrator::VelocityVerlet
            | Integrator::Heun => Some(2.0),
            Integrator::Rk4 => Some(2.785_293_6),
            Integrator::Exponential => None,
        }
    }
}

/// How an emitter's particles look.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Look {
    /// The sprite texture: a built-in procedural one or a PNG.
    pub sprite: Sprite,
    /// Animate the sprite as an atlas of frames (`None`: the whole texture is one sprite).
    pub flipbook: Option<Flipbook>,
    /// Billboard size (diameter) over normalised age, metres.
    pub size_m: Param,
    /// Multiplies each particle's contribution over normalised age: its light when
    /// additive, its coverage (alpha) when alpha-blended (1 = as the colour says).
    pub opacity: Param,
    /// Per-particle random initial rotation, 0..=360 degrees of spread.
    pub rotation_random_deg: f32,
    /// Angular velocity over normalised age, degrees per second (a range: each particle
    /// spins at its own constant rate).
    pub spin_deg_per_s: Param,
    /// Stretch the billboard along the screen-space velocity (sparks).
    pub streak: Option<Streak>,
    /// A ribbon through each particle's last positions (see [`Trail`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub trail: Option<Trail>,
    /// Fade the sprite where it meets the ground plane over this distance, metres (0 =
    /// off; the plane is the emitter's ground collider, or y = 0 without one).
    pub soft_ground_m: f32,
    /// Colour and alpha over normalised age (0 = birth, 1 = death); linear RGB.
    pub color_over_life: Vec<ColorStop>,
    /// Multiplies the colour (HDR brightness).
    pub intensity: f32,
    /// How particles are blended.
    pub blend: BlendMode,
    /// Which draw path renders them.
    pub draw_path: DrawPath,
    /// Shade an alpha-blended layer with six-way lightmaps (see [`Lit`]; its maps
    /// replace `sprite`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lit: Option<Lit>,
}

/// The two draw paths; both render the same look.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum DrawPath {
    /// Splat when the particles project smaller than [`SPLAT_BELOW_PX`] and blend
    /// additively (on GPUs, the adapter profile's `splat_dense_only`, only from
    /// [`SPLAT_PX_PER_QUAD`]); on GPUs (`tile_raster`) the tile rasteriser from
    /// [`TILES_ABOVE_PX`] and [`TILES_MIN_FILL_PX`]; billboards otherwise.
    #[default]
    Auto,
    /// Always instanced billboards (textured quads through the rasteriser).
    Billboard,
    /// Always the compute splat (additive emitters only; alpha emitters fall back to
    /// billboards, which they need for ordering).
    Splat,
    /// Always the compute tile rasteriser: the billboards' quads, binned into screen
    /// tiles and blended per tile on the compute units (the look of the billboards; in a
    /// host's pass only with its depth view). Alpha-blended emitters take it together or
    /// not at all (ribbons aside: they stay billboards, drawn behind the tiles' blended
    /// layers); streaks stay billboards.
    Tiles,
}

/// Auto draw path: below this projected particle size (pixels), splat.
pub const SPLAT_BELOW_PX: f32 = 4.0;

/// Auto draw path on adapters whose profile says `splat_dense_only` (GPUs): small particles
/// splat only when the draw has a quad (its widest live window × its instances) for every
/// this many pixels of the target or more. The splat clears and resolves the whole target:
/// on the H100 at 1920×1080 the thesis preset's 16384 points (one per 127 pixels) took
/// 0.42 ms a frame splatted and 0.20 ms as billboards (`ignis bench presets`).
pub const SPLAT_PX_PER_QUAD: f32 = 64.0;

/// Auto draw path on adapters whose profile allows the tile rasteriser: particles that
/// project at least this large (pixels) take it — where the splat stops: on the H100 the
/// tiles beat the billboards from there (`ignis bench perf`: 4M flames of about 6 px,
/// 22.5 ms against 31.4).
pub const TILES_ABOVE_PX: f32 = 4.0;

/// Auto draw path: an emitter takes the tile rasteriser only when its quads (all its
/// instances' live windows) at their largest projected size would cover at least this
/// many pixels: light fill costs the billboards little, and the tiles a fixed ~0.1 ms on
/// the H100 (`ignis bench presets`: the spark fountain's 26-sprite glow).
pub const TILES_MIN_FILL_PX: f32 = 1.0e6;

/// A sprite texture: one of the procedural set generated at start, or a PNG with alpha.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Sprite {
    /// A soft round disc.
    SoftDisc,
    /// A hard-edged point (the thesis's look).
    Point,
    /// A bright core with a soft halo (sparks).
    Spark,
    /// A teardrop flame tongue, brighter at the base.
    FlameWisp,
    /// A lumpy, noisy puff (smoke).
    SmokePuff,
    /// A built-in 4 × 4 flipbook of licking flame tongues (use with a 4 × 4 flipbook).
    FlameSheet,
    /// A PNG (straight alpha) at this path, relative to the preset file.
    Image(String),
}

impl Sprite {
    /// The built-in sprites, in menu order.
    pub const BUILT_IN: [Sprite; 6] = [
        Sprite::SoftDisc,
        Sprite::Point,
        Sprite::Spark,
        Sprite::FlameWisp,
        Sprite::SmokePuff,
        Sprite::FlameSheet,
    ];

    /// A short name for menus and messages.
    pub fn label(&self) -> &str {
        match self {
            Sprite::SoftDisc => "soft disc",
            Sprite::Point => "point",
            Sprite::Spark => "spark",
            Sprite::FlameWisp => "flame wisp",
            Sprite::SmokePuff => "smoke puff",
            Sprite::FlameSheet => "flame sheet (4×4)",
            Sprite::Image(path) => path,
        }
    }
}

/// A sprite atlas of `rows` × `cols` frames (row-major, top-left first), animated.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Flipbook {
    /// Frame rows in the atlas.
    pub rows: u32,
    /// Frame columns in the atlas.
    pub cols: u32,
    /// How the frame advances.
    pub mode: FlipbookMode,
    /// Cross-fade between consecutive frames (two texture samples) instead of cutting.
    pub blend_frames: bool,
    /// Start each particle on a random frame.
    pub random_start: bool,
}

impl Default for Flipbook {
    fn default() -> Self {
        Self {
            rows: 4,
            cols: 4,
            mode: FlipbookMode::OverLife,
            blend_frames: true,
            random_start: false,
        }
    }
}

/// How a flipbook's frame advances.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum FlipbookMode {
    /// Frame 0 at birth to the last frame at death.
    OverLife,
    /// A fixed rate, looping.
    FrameRate {
        /// Frames per second.
        fps: f32,
    },
    /// The frame over normalised age (0 = the first frame; a fraction blends toward the
    /// next when `blend_frames`; clamped to the last).
    Frames(Param),
}

/// Spark streaks: the billboard runs from the particle back along its velocity.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Streak {
    /// The tail is where the particle was this many seconds ago (at its current
    /// velocity), like the thesis's old-to-new interpolation.
    pub length_secs: f32,
    /// Longest tail, metres (keeps very fast sparks from crossing the screen).
    pub max_length_m: f32,
}

impl Default for Streak {
    fn default() -> Self {
        Self {
            length_secs: 0.03,
            max_length_m: 0.5,
        }
    }
}

/// Blend modes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum BlendMode {
    /// Light adds up (fire, sparks): order-independent.
    Additive,
    /// Premultiplied alpha "over" (smoke): darkens what is behind.
    Alpha,
}

/// One stop of a colour gradient.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColorStop {
    /// Normalised age, 0..1.
    pub t: f32,
    /// Linear RGB and alpha.
    pub rgba: [f32; 4],
}

/// The most gradient stops a look may have: the ramp baking handles any number, but stops
/// closer than one of its 1024 texels cannot be told apart, so more would be noise.
pub const MAX_COLOR_STOPS: usize = 1024;

impl Default for Effect {
    fn default() -> Self {
        Self {
            version: CURRENT_VERSION,
            name: "campfire".to_owned(),
            seed: 1,
            time: TimeSettings::default(),
            camera: CameraHint::default(),
            emitters: vec![Emitter::default()],
            post: Post::default(),
            lighting: Lighting::default(),
        }
    }
}

impl TimeSettings {
    /// The step settings counted in time are laid out for: the fixed step, or in
    /// frame-delta mode a 60 Hz frame (at most the largest frame step).
    pub fn nominal_step_secs(&self) -> f32 {
        match self.mode {
            TimeMode::FixedStep => self.step_secs,
            TimeMode::FrameDelta => self.max_frame_dt_secs.min(1.0 / 60.0),
        }
    }

    /// The longest single step this clock can take, seconds.
    pub fn longest_step_secs(&self) -> f32 {
        match self.mode {
            TimeMode::FixedStep => self.step_secs,
            TimeMode::FrameDelta => self.max_frame_dt_secs,
        }
    }
}

impl Default for TimeSettings {
    fn default() -> Self {
        Self {
            mode: TimeMode::FixedStep,
            step_secs: 1.0 / 120.0,
            max_substeps: 8,
            max_frame_dt_secs: 0.1,
            speed: 1.0,
        }
    }
}

impl Default for CameraHint {
    fn default() -> Self {
        Self {
            target_m: [0.0, 0.8, 0.0],
            distance_m: 3.2,
            yaw_deg: 0.0,
            pitch_deg: 8.0,
            fov_y_deg: 45.0,
        }
    }
}

impl Default for Emitter {
    fn default() -> Self {
        Self {
            name: "flames".to_owned(),
            enabled: true,
            capacity: 4096,
            spawn_rate_per_sec: Param::Constant(1800.0),
            max_spawn_per_sec: 0.0,
            bursts: Vec::new(),
            lifetime_secs: Range::new(0.6, 1.4),
            shape: Shape::Disc {
                radius_m: 0.35,
                normal: [0.0, 1.0, 0.0],
            },
            transform: Transform::default(),
            direction: [0.0, 1.0, 0.0],
            spread_deg: 12.0,
            speed_m_per_s: Range::new(0.3, 0.8),
            forces: Forces::default(),
            spawn_noise: SpawnNoise::default(),
            integrator: Integrator::SemiImplicitEuler,
            stateless: false,
            packed_state: false,
            tiny_state: false,
            collisions: Collisions::default(),
            seed_offset: 0,
            look: Look::default(),
            events: Vec::new(),
        }
    }
}

impl Default for Transform {
    fn default() -> Self {
        Self {
            position_m: [0.0, 0.0, 0.0],
            rotation_deg: [0.0, 0.0, 0.0],
        }
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

impl Default for SpawnNoise {
    fn default() -> Self {
        Self {
            frequency_per_m: 2.0,
            position_amplitude_m: 0.08,
            direction_amplitude: 0.25,
            scroll_per_sec: 1.5,
        }
    }
}

impl Default for Look {
    fn default() -> Self {
        Self {
            sprite: Sprite::SoftDisc,
            flipbook: None,
            size_m: Param::Curve {
                keys: vec![(0.0, 0.22), (1.0, 0.06)],
                smooth: false,
            },
            opacity: Param::Constant(1.0),
            rotation_random_deg: 0.0,
            spin_deg_per_s: Param::Constant(0.0),
            streak: None,
            trail: None,
            soft_ground_m: 0.0,
            color_over_life: vec![
                ColorStop {
                    t: 0.0,
                    rgba: [1.0, 0.9, 0.6, 0.0],
                },
                ColorStop {
                    t: 0.08,
                    rgba: [1.0, 0.75, 0.3, 0.9],
                },
                ColorStop {
                    t: 0.35,
                    rgba: [1.0, 0.38, 0.06, 0.7],
                },
                ColorStop {
                    t: 0.7,
                    rgba: [0.7, 0.1, 0.02, 0.35],
                },
                ColorStop {
                    t: 1.0,
                    rgba: [0.08, 0.05, 0.05, 0.0],
                },
            ],
            intensity: 1.6,
            blend: BlendMode::Additive,
            draw_path: DrawPath::Auto,
            lit: None,
        }
    }
}

impl Default for Range {
    fn default() -> Self {
        Self::new(1.0, 1.0)
    }
}

/// Largest capacity a single emitter may ask for (device limits may be lower).
pub const MAX_CAPACITY: u32 = 1 << 28;

impl Effect {
    /// The longest lifetime any emitter can give a particle, seconds.
    pub fn longest_lifetime_secs(&self) -> f64 {
        self.emitters
            .iter()
            .map(|e| f64::from(e.lifetime_secs.max))
            .fold(0.0, f64::max)
    }

    /// When the last burst of any emitter fires, seconds (0 without bursts).
    pub fn last_burst_secs(&self) -> f64 {
        self.emitters
            .iter()
            .flat_map(|e| &e.bursts)
            .map(|b| f64::from(b.time_secs))
            .fold(0.0, f64::max)
    }
}

impl Emitter {
    /// Why this emitter cannot run stateless (empty = it can): every module beyond
    /// constant acceleration and linear drag needs per-step state.
    pub fn stateless_blockers(&self) -> Vec<&'static str> {
        let f = &self.forces;
        let mut v = Vec::new();
        if f.quadratic_drag_per_m > 0.0 {
            v.push("quadratic drag");
        }
        if f.gusts.is_some() {
            v.push("gusts");
        }
        if f.turbulence.is_some() {
            v.push("turbulence");
        }
        if f.vortex.is_some() {
            v.push("vortex");
        }
        if f.attractor.is_some() {
            v.push("attractor");
        }
        if f.flame_pull.is_some() {
            v.push("flame pull");
        }
        if self.collisions.any() {
            v.push("collisions");
        }
        if !f.drag_over_life.is_constant(1.0) {
            v.push("drag over life");
        }
        if !f.speed_over_life.is_constant(1.0) {
            v.push("speed over life");
        }
        if !self.events.is_empty() {
            v.push("events");
        }
        if self.look.trail.is_some() {
            v.push("trail");
        }
        v
    }
}
