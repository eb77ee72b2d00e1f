//! The version-2 preset format, frozen: only the types that version 3 changed (the
//! effect, its emitters, their looks, trails and events), each with the conversion that
//! reproduces the same effect in the current model. Never edit these types;
//! `tests/presets.rs` loads `tests/fixtures/v2/` through them.
//!
//! What changed in version 3: every setting counted in simulation steps became a time or a
//! rate, so that the step size is a pure accuracy setting — a trail's `every_steps` became
//! `length_secs` (the span its points cover), an emitter's `max_spawn_per_step` became
//! `max_spawn_per_sec` and an event's `max_per_step` became `max_per_sec`. A version-2
//! file converts at its own step (`time`'s fixed step, or a 60 Hz frame in frame-delta
//! mode), so it plays as it did at that step wherever its caps did not bind (a cap per
//! second lets a tenth of a second's worth through at once, `crate::effect::RateCap`). An
//! automatic spawn cap (0) becomes no cap: it only ever bound on steps longer than 1/15 s.

use serde::Deserialize;

use crate::effect::{
    CURRENT_VERSION, CameraHint, Collisions, ColorStop, CountRange, DrawPath, Flipbook, Forces,
    Integrator, Param, Post, Range, Shape, SpawnNoise, Sprite, Streak, TimeSettings, TrailMode,
    Transform, Trigger,
};

/// A version-2 effect.
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
    spawn_rate_per_sec: Param,
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
    events: Vec<Event>,
}

#[derive(Deserialize)]
#[serde(default, deny_unknown_fields)]
struct Look {
    sprite: Sprite,
    flipbook: Option<Flipbook>,
    size_m: Param,
    opacity: Param,
    rotation_random_deg: f32,
    spin_deg_per_s: Param,
    streak: Option<Streak>,
    trail: Option<Trail>,
    soft_ground_m: f32,
    color_over_life: Vec<ColorStop>,
    intensity: f32,
    blend: crate::effect::BlendMode,
    draw_path: DrawPath,
}

#[derive(Deserialize)]
#[serde(default, deny_unknown_fields)]
struct Trail {
    mode: TrailMode,
    points: u32,
    every_steps: u32,
    width: f32,
    tail_width: f32,
    tail_opacity: f32,
    draw_sprite: bool,
}

#[derive(Deserialize)]
#[serde(default, deny_unknown_fields)]
struct Event {
    trigger: Trigger,
    emitter: String,
    count: CountRange,
    probability: f32,
    rate_per_sec: f32,
    inherit_velocity: f32,
    inherit_color: bool,
    max_per_step: u32,
}

impl Default for Effect {
    fn default() -> Self {
        let e = crate::effect::Effect::default();
        Self {
            version: 2,
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
            spawn_rate_per_sec: e.spawn_rate_per_sec,
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
            events: Vec::new(),
        }
    }
}

impl Default for Look {
    fn default() -> Self {
        let l = crate::effect::Look::default();
        Self {
            sprite: l.sprite,
            flipbook: l.flipbook,
            size_m: l.size_m,
            opacity: l.opacity,
            rotation_random_deg: l.rotation_random_deg,
            spin_deg_per_s: l.spin_deg_per_s,
            streak: l.streak,
            trail: None,
            soft_ground_m: l.soft_ground_m,
            color_over_life: l.color_over_life,
            intensity: l.intensity,
            blend: l.blend,
            draw_path: l.draw_path,
        }
    }
}

impl Default for Trail {
    fn default() -> Self {
        let t = crate::effect::Trail::default();
        Self {
            mode: t.mode,
            points: 12,
            every_steps: 2,
            width: t.width,
            tail_width: t.tail_width,
            tail_opacity: t.tail_opacity,
            draw_sprite: t.draw_sprite,
        }
    }
}

impl Default for Event {
    fn default() -> Self {
        let e = crate::effect::Event::default();
        Self {
            trigger: e.trigger,
            emitter: e.emitter,
            count: e.count,
            probability: e.probability,
            rate_per_sec: e.rate_per_sec,
            inherit_velocity: e.inherit_velocity,
            inherit_color: e.inherit_color,
            max_per_step: 1024,
        }
    }
}

/// A count per step at the effect's own step, as a rate (to six significant digits).
pub(super) fn per_sec(per_step: u32, time: &TimeSettings) -> f32 {
    readable(f64::from(per_step) / f64::from(time.nominal_step_secs()))
}

/// `x` to six significant digits, as a person would write it (1/120 s steps are not exact
/// in f32: 64 a step is 7679.9997 a second, which means 7680).
fn readable(x: f64) -> f32 {
    format!("{x:.5e}").parse().unwrap_or(x as f32)
}

impl From<Effect> for crate::effect::Effect {
    fn from(v: Effect) -> Self {
        // A version other than 2 never reaches this reader.
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
            spawn_rate_per_sec: e.spawn_rate_per_sec,
            max_spawn_per_sec: per_sec(e.max_spawn_per_step, time),
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
            look: e.look.into_current(time),
            events: e.events.into_iter().map(|v| v.into_current(time)).collect(),
        }
    }
}

impl Look {
    fn into_current(self, time: &TimeSettings) -> crate::effect::Look {
        let l = self;
        crate::effect::Look {
            sprite: l.sprite,
            flipbook: l.flipbook,
            size_m: l.size_m,
            opacity: l.opacity,
            rotation_random_deg: l.rotation_random_deg,
            spin_deg_per_s: l.spin_deg_per_s,
            streak: l.streak,
            trail: l.trail.map(|t| crate::effect::Trail {
                mode: t.mode,
                points: t.points,
                // The span the ring covered at the file's own step.
                length_secs: readable(
                    f64::from(t.points)
                        * f64::from(t.every_steps.max(1))
                        * f64::from(time.nominal_step_secs()),
                ),
                width: t.width,
                tail_width: t.tail_width,
                tail_opacity: t.tail_opacity,
                draw_sprite: t.draw_sprite,
            }),
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

impl Event {
    fn into_current(self, time: &TimeSettings) -> crate::effect::Event {
        crate::effect::Event {
            trigger: self.trigger,
            emitter: self.emitter,
            count: self.count,
            probability: self.probability,
            rate_per_sec: self.rate_per_sec,
            inherit_velocity: self.inherit_velocity,
            inherit_color: self.inherit_color,
            max_per_sec: per_sec(self.max_per_step.max(1), time),
        }
    }
}
