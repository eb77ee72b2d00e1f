//! Trails: each particle drawn as a ribbon through its last positions, which the update
//! records in a small ring per particle (`shaders/trail_on.wgsl`); the billboards draw
//! one camera-facing segment per pair of neighbouring points (`shaders/billboard.wgsl`,
//! `TRAIL`). The velocity streak (`Look::streak`) stays the cheap option: one quad
//! stretched along the velocity.

use serde::{Deserialize, Serialize};

use super::Checker;

/// The most points a trail keeps per particle.
pub const MAX_TRAIL_POINTS: u32 = 64;

/// A ribbon behind each particle.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Trail {
    /// Positions kept per particle (the ribbon has one segment fewer, plus the one to the
    /// particle itself): 2..=64.
    pub points: u32,
    /// A position is recorded every this many simulation steps (the trail spans
    /// `points × every_steps` steps).
    pub every_steps: u32,
    /// The ribbon's width at the particle as a multiple of the particle's size.
    pub width: f32,
    /// The width at the tail as a fraction of the width at the particle.
    pub tail_width: f32,
    /// The opacity at the tail as a fraction of the particle's.
    pub tail_opacity: f32,
    /// Also draw the particle's own sprite (off: the ribbon alone).
    pub draw_sprite: bool,
}

impl Default for Trail {
    fn default() -> Self {
        Self {
            points: 12,
            every_steps: 2,
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
        if !(1..=120).contains(&self.every_steps) {
            c.push(
                format!("{path}.every_steps"),
                self.every_steps,
                "must be in 1..=120",
            );
        }
        c.num(|| format!("{path}.width"), self.width, 0.0, 100.0);
        c.num(|| format!("{path}.tail_width"), self.tail_width, 0.0, 1.0);
        c.num(
            || format!("{path}.tail_opacity"),
            self.tail_opacity,
            0.0,
            1.0,
        );
    }

    /// Segments drawn per particle: one per recorded point but the newest (the segment
    /// from the particle to the newest point older than its current step replaces it).
    pub fn segments(&self) -> u32 {
        self.points.saturating_sub(1).max(1)
    }
}
