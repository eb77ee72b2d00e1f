//! The version-1 preset format, frozen: only the types that version 2 changed (the
//! effect, its emitters and their looks), each with the conversion that reproduces the
//! same effect in the current model. Never edit these types; `tests/presets.rs` loads
//! `tests/fixtures/v1_campfire.ron` through them.
//!
//! What changed in version 2: the spawn rate, the size and the spin became [`Param`]s
//! (constant, range, curve or two curves); the look gained `opacity`; forces gained
//! `drag_over_life` and `speed_over_life`, turbulence and the flame pull `over_life` (all
//! defaulting to a constant 1, so version-1 files read them as they were). Version 3's
//! changes (counts per step as rates, `crate::preset::v2`) apply here too.

use serde::Deserialize;

use crate::effect::{
    BlendMode, CURRENT_VERSION, CameraHint, Collisions, ColorStop, Curve, DrawPath, Forces,
    Integrator, Param, Post, Range, Shape, SpawnNoise, Sprite, Streak, TimeSettings, Transform,
};

/// A version-1 effect.
#[derive(Deserialize)]
#[serde(default, deny_unknown_fields)]
pub(super) struct Effect {
    version: u32,
    name: String,
    seed: u32,
    time: TimeSettings,
    camera: CameraHint,
    emitters: Vec<Emitter>,
    post: Post,
}

#[derive(Deserialize)]
#[serde(default, deny_unknown_fields)]
struct Emitter {
    name: String,
    enabled: bool,
    capacity: u32,
    spawn_rate_per_sec: f32,
    max_spawn_per_step: u32,
    bursts: Vec<crate::effect::Burst>,
    lifetime_secs: Range,
    shape: Shape,
    transform: Transform,
    direction: [f32; 3],
    spread_deg: f32,
    speed_m_per_s: Range,
    forces: Forces,
    spawn_noise: SpawnNoise,
    integrator: Integrator,
    stateless: bool,
    packed_state: bool,
    tiny_state: bool,
    collisions: Collisions,
    seed_offset: u32,
    look: Look,
}

#[derive(Deserialize)]
#[serde(default, deny_unknown_fields)]
struct Look {
    sprite: Sprite,
    flipbook: Option<Flipbook>,
    size_start_m: f32,
    size_end_m: f32,
    size_random: f32,
    rotation_random_deg: f32,
    spin_deg_per_s: Range,
    streak: Option<Streak>,
    soft_ground_m: f32,
    color_over_life: Vec<ColorStop>,
    intensity: f32,
    blend: BlendMode,
    draw_path: DrawPath,
}

#[derive(Deserialize)]
#[serde(default, deny_unknown_fields)]
struct Flipbook {
    rows: u32,
    cols: u32,
    mode: FlipbookMode,
    blend_frames: bool,
    random_start: bool,
}

#[derive(Deserialize)]
enum FlipbookMode {
    OverLife,
    FrameRate { fps: f32 },
}

impl Default for Effect {
    fn default() -> Self {
        let e = crate::effect::Effect::default();
        Self {
            version: 1,
            name: e.name,
            seed: e.seed,
            time: e.time,
            camera: e.camera,
            emitters: Vec::new(),
            post: e.post,
        }
    }
}

impl Default for Emitter {
    fn default() -> Self {
        let e = crate::effect::Emitter::default();
        Self {
            name: e.name,
            enabled: e.enabled,
            capacity: e.capacity,
            spawn_rate_per_sec: 1800.0,
            max_spawn_per_step: 0,
            bursts: e.bursts,
            lifetime_secs: e.lifetime_secs,
            shape: e.shape,
            transform: e.transform,
            direction: e.direction,
            spread_deg: e.spread_deg,
            speed_m_per_s: e.speed_m_per_s,
            forces: e.forces,
            spawn_noise: e.spawn_noise,
            integrator: e.integrator,
            stateless: e.stateless,
            packed_state: e.packed_state,
            tiny_state: e.tiny_state,
            collisions: e.collisions,
            seed_offset: e.seed_offset,
            look: Look::default(),
        }
    }
}

impl Default for Look {
    fn default() -> Self {
        let l = crate::effect::Look::default();
        Self {
            sprite: l.sprite,
            flipbook: None,
            size_start_m: 0.22,
            size_end_m: 0.06,
            size_random: 0.0,
            rotation_random_deg: l.rotation_random_deg,
            spin_deg_per_s: Range::new(0.0, 0.0),
            streak: l.streak,
            soft_ground_m: l.soft_ground_m,
            color_over_life: l.color_over_life,
            intensity: l.intensity,
            blend: l.blend,
            draw_path: l.draw_path,
        }
    }
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

impl From<Effect> for crate::effect::Effect {
    fn from(v: Effect) -> Self {
        // A version above 1 never reaches this reader; 0 is refused before it.
        let _ = v.version;
        let time = v.time;
        Self {
            version: CURRENT_VERSION,
            name: v.name,
            seed: v.seed,
            emitters: v
                .emitters
                .into_iter()
                .map(|e| e.into_current(&time))
                .collect(),
            time,
            camera: v.camera,
            post: v.post,
            lighting: Default::default(),
        }
    }
}

impl Emitter {
    fn into_current(self, time: &TimeSettings) -> crate::effect::Emitter {
        let e = self;
        crate::effect::Emitter {
            name: e.name,
            enabled: e.enabled,
            capacity: e.capacity,
            spawn_rate_per_sec: Param::Constant(e.spawn_rate_per_sec),
            max_spawn_per_sec: super::v2::per_sec(e.max_spawn_per_step, time),
            bursts: e.bursts,
            lifetime_secs: e.lifetime_secs,
            shape: e.shape,
            transform: e.transform,
            direction: e.direction,
            spread_deg: e.spread_deg,
            speed_m_per_s: e.speed_m_per_s,
            forces: e.forces,
            spawn_noise: e.spawn_noise,
            integrator: e.integrator,
            stateless: e.stateless,
            packed_state: e.packed_state,
            tiny_state: e.tiny_state,
            collisions: e.collisions,
            seed_offset: e.seed_offset,
            look: e.look.into(),
            events: Vec::new(),
        }
    }
}

/// `x` to six significant digits, as a person would write it (the scaled sizes below are
/// products like 0.24499999; within 1e-6 relative of them).
fn readable(x: f32) -> f32 {
    format!("{x:.5e}").parse().unwrap_or(x)
}

/// Version 1's size: a line from start to end, scaled per particle by 1 + r·(2u − 1) with
/// u the particle's size random. Two lines scaled by 1 − r and 1 + r, blended by the same
/// u, give that (to six significant digits).
fn size(start: f32, end: f32, random: f32) -> Param {
    let (lo, hi) = (1.0 - random, 1.0 + random);
    let scaled = |x: f32, f: f32| readable(x * f);
    match (start == end, random == 0.0) {
        (true, true) => Param::Constant(start),
        (true, false) => Param::Range {
            min: scaled(start, lo),
            max: scaled(start, hi),
        },
        (false, true) => Param::Curve {
            keys: vec![(0.0, start), (1.0, end)],
            smooth: false,
        },
        (false, false) => Param::TwoCurves {
            a: Curve::line(scaled(start, lo), scaled(end, lo)),
            b: Curve::line(scaled(start, hi), scaled(end, hi)),
        },
    }
}

impl From<Look> for crate::effect::Look {
    fn from(l: Look) -> Self {
        let spin = l.spin_deg_per_s;
        Self {
            sprite: l.sprite,
            flipbook: l.flipbook.map(|f| crate::effect::Flipbook {
                rows: f.rows,
                cols: f.cols,
                mode: match f.mode {
                    FlipbookMode::OverLife => crate::effect::FlipbookMode::OverLife,
                    FlipbookMode::FrameRate { fps } => {
                        crate::effect::FlipbookMode::FrameRate { fps }
                    }
                },
                blend_frames: f.blend_frames,
                random_start: f.random_start,
            }),
            size_m: size(l.size_start_m, l.size_end_m, l.size_random),
            opacity: Param::Constant(1.0),
            rotation_random_deg: l.rotation_random_deg,
            spin_deg_per_s: if spin.min == spin.max {
                Param::Constant(spin.min)
            } else {
                Param::Range {
                    min: spin.min,
                    max: spin.max,
                }
            },
            streak: l.streak,
            trail: None,
            soft_ground_m: l.soft_ground_m,
            color_over_life: l.color_over_life,
            intensity: l.intensity,
            blend: l.blend,
            draw_path: l.draw_path,
            lit: None,
            heat_haze: None,
        }
    }
}
