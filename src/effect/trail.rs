//! Trails: ribbons drawn by the billboards (`shaders/billboard.wgsl`, `TRAIL`), one
//! camera-facing segment per pair of neighbouring points, in one of two modes:
//! - [`TrailMode::History`]: each particle through its last positions, which the update
//!   records in a small ring per particle (`shaders/trail_on.wgsl`);
//! - [`TrailMode::PerParent`]: an emitter fed by events, one ribbon per parent through the
//!   particles it spawned, in order — each particle joined to the one its parent spawned
//!   before it (the event scan keeps the links, `shaders/events.wgsl`).
//!
//! The velocity streak (`Look::streak`) stays the cheap option: one quad stretched along
//! the velocity.

use serde::{Deserialize, Serialize};

use super::Checker;

/// The most points a trail keeps per particle.
pub const MAX_TRAIL_POINTS: u32 = 64;

/// What a ribbon passes through.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum TrailMode {
    /// Each particle's own last positions (`points` over the last `length_secs`).
    #[default]
    History,
    /// The particles each parent's events spawned, in order: every particle joined to its
    /// parent's previous child while both live (an emitter fed by events only; `points`
    /// and `length_secs` are not used). Smoke lines behind debris, lightning-like chains.
    PerParent,
}

impl TrailMode {
    /// Every mode, in the order the panel lists them.
    pub const ALL: [TrailMode; 2] = [TrailMode::History, TrailMode::PerParent];

    /// What the panel calls it.
    pub fn label(self) -> &'static str {
        match self {
            TrailMode::History => "its own last positions",
            TrailMode::PerParent => "a ribbon per parent",
        }
    }
}

/// A ribbon behind each particle.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Trail {
    /// What the ribbon passes through.
    #[serde(skip_serializing_if = "is_history")]
    pub mode: TrailMode,
    /// Positions kept per particle (the ribbon has one segment fewer, plus the one to the
    /// particle itself): 2..=64. A step too coarse to record them all over `length_secs`
    /// keeps fewer (one per step), so the ribbon's length never depends on the step.
    pub points: u32,
    /// How far back the ribbon reaches, seconds of simulated time: a point is recorded
    /// every `length_secs / points` (rounded to whole steps, see [`Trail::layout`]).
    pub length_secs: f32,
    /// The ribbon's width at the particle as a multiple of the particle's size.
    pub width: f32,
    /// The width at the tail as a fraction of the width at the particle (per parent: at
    /// the end of a particle's life, the width following its age).
    pub tail_width: f32,
    /// The opacity at the tail as a fraction of the particle's (per parent: at the end of
    /// a particle's life).
    pub tail_opacity: f32,
    /// Also draw the particle's own sprite (off: the ribbon alone).
    pub draw_sprite: bool,
}

fn is_history(mode: &TrailMode) -> bool {
    *mode == TrailMode::History
}

impl Default for Trail {
    fn default() -> Self {
        Self {
            mode: TrailMode::History,
            points: 12,
            length_secs: 0.2,
            width: 1.0,
            tail_width: 0.2,
            tail_opacity: 0.0,
            draw_sprite: true,
        }
    }
}

impl Trail {
    /// Checks the fields under `path` (e.g. `emitters[2].look.trail`).
    pub(super) fn check(&self, path: &str, c: &mut Checker) {
        if !(2..=MAX_TRAIL_POINTS).contains(&self.points) {
            c.push(
                format!("{path}.points"),
                self.points,
                &format!("must be in 2..={MAX_TRAIL_POINTS}"),
            );
        }
        c.num(
            || format!("{path}.length_secs"),
            self.length_secs,
            1e-4,
            60.0,
        );
        c.num(|| format!("{path}.width"), self.width, 0.0, 100.0);
        c.num(|| format!("{path}.tail_width"), self.tail_width, 0.0, 1.0);
        c.num(
            || format!("{path}.tail_opacity"),
            self.tail_opacity,
            0.0,
            1.0,
        );
    }

    /// How the ring records the trail at steps of `step_secs`: a point every
    /// `round(length / (points·step))` steps (at least one), and as many points as span
    /// `length_secs` at that spacing (at most `points`, at least 2). The ribbon then spans
    /// `points × every × step` = `length_secs` whenever the step divides the spacing (or
    /// the length, on steps coarser than the spacing).
    pub fn layout(&self, step_secs: f32) -> TrailLayout {
        match self.mode {
            TrailMode::PerParent => TrailLayout {
                points: 1,
                every: 1,
            },
            TrailMode::History => {
                let (len, dt) = (f64::from(self.length_secs), f64::from(step_secs).max(1e-9));
                let points = self.points.clamp(2, MAX_TRAIL_POINTS);
                let every = (len / (f64::from(points) * dt)).round().clamp(1.0, 1e6) as u32;
                let fit = (len / (f64::from(every) * dt)).round();
                TrailLayout {
                    points: fit.clamp(2.0, f64::from(points)) as u32,
                    every,
                }
            }
        }
    }

    /// Segments drawn per particle at steps of `step_secs`: one per recorded point but the
    /// newest (the segment from the particle to the newest point older than its current
    /// step replaces it); per parent, one (to the parent's previous child).
    pub fn segments(&self, step_secs: f32) -> u32 {
        match self.mode {
            TrailMode::History => self.layout(step_secs).points.saturating_sub(1).max(1),
            TrailMode::PerParent => 1,
        }
    }
}

/// A trail's ring at a given step size ([`Trail::layout`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TrailLayout {
    /// Ring entries per slot: the recorded points, or per parent one link (the previous
    /// child's slot and birth stamp, this particle's birth stamp).
    pub points: u32,
    /// Steps between two recorded points.
    pub every: u32,
}

impl TrailLayout {
    /// The simulated time the ribbon spans at steps of `step_secs`, seconds.
    pub fn span_secs(&self, step_secs: f32) -> f64 {
        f64::from(self.points) * f64::from(self.every) * f64::from(step_secs)
    }
}

impl super::Look {
    /// Whether the look draws a ribbon per parent (its particles linked by the events that
    /// spawn them).
    pub fn ribbon_per_parent(&self) -> bool {
        self.trail
            .as_ref()
            .is_some_and(|t| t.mode == TrailMode::PerParent)
    }
}
