//! The effect model: what a designer edits and what a preset file stores.
//!
//! Everything a designer tunes lives here (no parameter lives only in a widget or a
//! shader). The structs are plain serde data; [`Effect::validate`] checks ranges and
//! finiteness so nothing impossible ever reaches the GPU.

use serde::{Deserialize, Serialize};

pub(crate) mod curve;
mod events;
mod forces;
mod lit;
mod look;
mod rate_cap;
mod stability;
mod trail;
mod validate;

pub(crate) use curve::{CURVE_WIDTH, bake_rows, lookup_blend, rows_key};
pub use curve::{Curve, MAX_CURVE_KEYS, Param, ParamMode, SHAPES};
pub use events::{CountRange, Event, MAX_CHILDREN_PER_EVENT, MAX_EVENTS_PER_EMITTER, Trigger};
pub use forces::{
    Attractor, Collisions, DepthCollision, Falloff, FlamePull, Forces, GroundPlane, Gusts,
    MAX_SPHERES, SphereCollider, Turbulence, Vortex,
};
pub use lit::{Lighting, Lit, SixWayMaps};
pub use look::{
    BlendMode, ColorStop, DrawPath, Flipbook, FlipbookMode, HeatHaze, Look, MAX_COLOR_STOPS,
    SPLAT_BELOW_PX, SPLAT_PX_PER_QUAD, Sprite, Streak, TILES_ABOVE_PX, TILES_MIN_FILL_PX,
    TILES_MIN_QUADS,
};
pub use rate_cap::RateCap;
pub(crate) use rate_cap::cap_burst;
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
    /// Draw the large additive sprites (flame tongues: billboards at least 12 px on
    /// screen, not streaks) at 1/n of the resolution, n = 1 or 2, into a glow layer that
    /// the bloom and the tonemap add: soft flames look alike and cost a quarter of the
    /// fill. Sparks and embers stay sharp.
    pub glow_downscale: u32,
}

impl Default for Post {
    fn default() -> Self {
        Self {
            exposure: 1.0,
            bloom: None,
            alpha_downscale: 1,
            glow_downscale: 1,
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
        if self.collisions.depth_collision.is_some() {
            v.push("depth collision");
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
