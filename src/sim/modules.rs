//! Optional modules: which parts of the update shader an emitter needs. Each maps to a
//! WGSL `override` constant (keep in sync with `MOD_*` in `shaders/forces.wgsl` and
//! `shaders/collide.wgsl`), so a module that is off is compiled out of the pipeline.

use crate::effect::{Emitter, Param};

/// A set of modules, as bits.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Modules(pub u32);

impl Modules {
    /// Linear drag toward the wind.
    pub const DRAG: Modules = Modules(1);
    /// Noise-modulated wind.
    pub const GUSTS: Modules = Modules(2);
    /// Quadratic drag.
    pub const QUADRATIC_DRAG: Modules = Modules(4);
    /// Curl-noise turbulence.
    pub const TURBULENCE: Modules = Modules(8);
    /// Vortex.
    pub const VORTEX: Modules = Modules(16);
    /// Attractor.
    pub const ATTRACTOR: Modules = Modules(32);
    /// Flame-closing pull.
    pub const FLAME_PULL: Modules = Modules(64);
    /// Ground and sphere colliders.
    pub const COLLISIONS: Modules = Modules(128);
    /// Stateless mode: spawn records only, positions in closed form when drawn.
    pub const STATELESS: Modules = Modules(256);
    /// Packed 20-byte state.
    pub const PACKED: Modules = Modules(512);
    /// Tiny 10-byte state.
    pub const TINY: Modules = Modules(1024);
    /// Over-life multipliers (speed, drag, turbulence, flame pull) read from baked curves.
    pub const CURVES: Modules = Modules(2048);
    /// Events: the update writes each particle's events for the scan (events_on.wgsl).
    pub const EVENTS: Modules = Modules(4096);
    /// Spawning from another emitter's events instead of the emitter's own rate.
    pub const EVENT_SPAWN: Modules = Modules(8192);
    /// Trails: the update records each particle's positions in a ring (trail_on.wgsl).
    pub const TRAIL: Modules = Modules(16384);
    /// Collision with the host's depth buffer (depth_on.wgsl, group 2).
    pub const DEPTH_COLLISION: Modules = Modules(32768);

    /// Every module with its override-constant name.
    pub const ALL: [(Modules, &'static str); 16] = [
        (Self::DRAG, "MOD_DRAG"),
        (Self::GUSTS, "MOD_GUSTS"),
        (Self::QUADRATIC_DRAG, "MOD_QUADRATIC_DRAG"),
        (Self::TURBULENCE, "MOD_TURBULENCE"),
        (Self::VORTEX, "MOD_VORTEX"),
        (Self::ATTRACTOR, "MOD_ATTRACTOR"),
        (Self::FLAME_PULL, "MOD_FLAME_PULL"),
        (Self::COLLISIONS, "MOD_COLLISIONS"),
        (Self::STATELESS, "MOD_STATELESS"),
        (Self::PACKED, "MOD_PACKED"),
        (Self::TINY, "MOD_TINY"),
        (Self::CURVES, "MOD_CURVES"),
        (Self::EVENTS, "MOD_EVENTS"),
        (Self::EVENT_SPAWN, "MOD_EVENT_SPAWN"),
        (Self::TRAIL, "MOD_TRAIL"),
        (Self::DEPTH_COLLISION, "MOD_DEPTH_COLLISION"),
    ];

    /// The modules an emitter's settings need.
    pub fn of(e: &Emitter) -> Modules {
        let f = &e.forces;
        let mut m = Modules(0);
        let wind = f.wind_m_per_s.iter().any(|w| *w != 0.0);
        if f.drag_per_sec > 0.0 {
            m.0 |= Self::DRAG.0;
        }
        if f.gusts.is_some() && wind && (f.drag_per_sec > 0.0 || f.quadratic_drag_per_m > 0.0) {
            m.0 |= Self::GUSTS.0;
        }
        if f.quadratic_drag_per_m > 0.0 {
            m.0 |= Self::QUADRATIC_DRAG.0;
        }
        if f.turbulence
            .as_ref()
            .is_some_and(|t| t.strength_m_per_s2 != 0.0)
        {
            m.0 |= Self::TURBULENCE.0;
        }
        if f.vortex.as_ref().is_some_and(|v| v.swirl_m_per_s2 != 0.0) {
            m.0 |= Self::VORTEX.0;
        }
        if f.attractor.as_ref().is_some_and(|a| a.strength != 0.0) {
            m.0 |= Self::ATTRACTOR.0;
        }
        if f.flame_pull
            .as_ref()
            .is_some_and(|p| p.strength_per_s2 != 0.0)
        {
            m.0 |= Self::FLAME_PULL.0;
        }
        if e.collisions.any() {
            m.0 |= Self::COLLISIONS.0;
        }
        if over_life_params(e).iter().any(|p| !p.is_constant(1.0)) {
            m.0 |= Self::CURVES.0;
        }
        // A ribbon per parent records nothing in the update (the event scan links the
        // children).
        if e.look.trail.is_some() && !e.look.ribbon_per_parent() {
            m.0 |= Self::TRAIL.0;
        }
        if !e.events.is_empty() {
            m.0 |= Self::EVENTS.0;
        }
        if e.collisions.depth_collision.is_some() {
            m.0 |= Self::DEPTH_COLLISION.0;
        }
        if m.has_hooks() || m.contains(Self::DEPTH_COLLISION) {
            // Events and trails read the particles' whole state every step, and depth
            // collision is composed for it only: the full layout, stateful.
        } else if e.stateless && e.stateless_blockers().is_empty() {
            m.0 |= Self::STATELESS.0;
        } else if e.tiny_state {
            m.0 |= Self::TINY.0;
        } else if e.packed_state {
            m.0 |= Self::PACKED.0;
        }
        m
    }

    /// The modules emitter `i` of `effect` needs: [`Modules::of`], and for an emitter
    /// fed by another's events the event spawn on the full state (its ring is filled by
    /// the GPU, which packed, tiny and stateless pools cannot follow).
    pub fn in_effect(effect: &crate::effect::Effect, i: usize) -> Modules {
        let Some(e) = effect.emitters.get(i) else {
            return Modules(0);
        };
        let m = Self::of(e);
        if effect.event_fed(i) {
            let layout = Self::STATELESS.0 | Self::PACKED.0 | Self::TINY.0;
            Modules((m.0 & !layout) | Self::EVENT_SPAWN.0)
        } else {
            m
        }
    }

    /// True when the update composes the event hooks (events_on.wgsl).
    pub fn has_events(self) -> bool {
        self.0 & (Self::EVENTS.0 | Self::EVENT_SPAWN.0) != 0
    }

    /// True when the update has hooks in group 1 (events or the trail's ring).
    pub fn has_hooks(self) -> bool {
        self.has_events() || self.contains(Self::TRAIL)
    }

    /// True when every module of `other` is in `self`.
    pub fn contains(self, other: Modules) -> bool {
        self.0 & other.0 == other.0
    }

    /// The union.
    pub fn with(self, other: Modules) -> Modules {
        Modules(self.0 | other.0)
    }

    /// The pipeline override constants for this set.
    pub fn constants(self) -> Vec<(&'static str, f64)> {
        Self::ALL
            .iter()
            .map(|(m, name)| (*name, if self.contains(*m) { 1.0 } else { 0.0 }))
            .collect()
    }

    /// Names of the modules that are on.
    pub fn names(self) -> Vec<&'static str> {
        Self::ALL
            .iter()
            .filter(|(m, _)| self.contains(*m))
            .map(|(_, n)| &n[4..])
            .collect()
    }
}

/// The over-life multipliers the update reads (speed, drag, turbulence, flame pull), each
/// 1 where its force is off: the channels of the emitter's baked simulation curves.
pub fn over_life_params(e: &Emitter) -> [&Param; 4] {
    const ONE: &Param = &Param::Constant(1.0);
    let f = &e.forces;
    let drag_on = f.drag_per_sec > 0.0 || f.quadratic_drag_per_m > 0.0;
    [
        &f.speed_over_life,
        if drag_on { &f.drag_over_life } else { ONE },
        f.turbulence.as_ref().map_or(ONE, |t| &t.over_life),
        f.flame_pull.as_ref().map_or(ONE, |p| &p.over_life),
    ]
}

/// The emitter's simulation curves baked (rows A and B of `over_life_params`).
pub fn bake_over_life(e: &Emitter) -> [Vec<[f32; 4]>; 2] {
    crate::effect::bake_rows(over_life_params(e), [false; 4], [1.0; 4])
}

impl Modules {
    /// The state layout these modules ask for.
    pub fn state_layout(self) -> crate::gpu::types::StateLayout {
        use crate::gpu::types::StateLayout;
        if self.contains(Modules::TINY) {
            StateLayout::Tiny
        } else if self.contains(Modules::PACKED) {
            StateLayout::Packed
        } else {
            StateLayout::Full
        }
    }
}
