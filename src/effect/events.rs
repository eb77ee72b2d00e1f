//! Events: a parent emitter's particles spawn particles of another emitter of the same
//! effect when they die, collide, are born, or at a rate while they live.
//!
//! The events are listed on the parent ([`crate::effect::Emitter::events`]); the emitter an
//! event names (the child) then spawns only from events — its own rate and bursts are
//! not used — and both run the full 32-byte state (stateless, packed and tiny state are
//! off for them). A child may be fed by several events (its list takes their children in
//! update order); chains (a child that is itself a parent) are allowed, cycles are not.

use serde::{Deserialize, Serialize};

use super::{Checker, Effect};

/// The most events one emitter can list.
pub const MAX_EVENTS_PER_EMITTER: usize = 2;

/// The most children one parent particle can spawn per event and step.
pub const MAX_CHILDREN_PER_EVENT: u32 = 64;

/// What makes a parent particle spawn children.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Trigger {
    /// The step the particle dies (its age reaches its lifetime, or a collider kills it).
    #[default]
    Death,
    /// Each step the particle hits the ground or a sphere faster than the rest speed.
    Collision,
    /// The step the particle is born.
    Birth,
    /// Continuously while the particle lives, `rate_per_sec` children per second each.
    OverLife,
}

impl Trigger {
    /// Every trigger, in the panel's order.
    pub const ALL: [Trigger; 4] = [
        Trigger::Death,
        Trigger::Collision,
        Trigger::Birth,
        Trigger::OverLife,
    ];

    /// The shaders' trigger number (`TRIGGER_*` in `shaders/events_on.wgsl`).
    pub fn index(self) -> u32 {
        self as u32
    }

    /// A short name for the panel.
    pub fn label(self) -> &'static str {
        match self {
            Trigger::Death => "on death",
            Trigger::Collision => "on collision",
            Trigger::Birth => "on birth",
            Trigger::OverLife => "over life",
        }
    }
}

/// An inclusive range of whole numbers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CountRange {
    /// Fewest.
    pub min: u32,
    /// Most.
    pub max: u32,
}

/// One event of a parent emitter: when its particles spawn children, and how many.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Event {
    /// When a parent particle spawns.
    pub trigger: Trigger,
    /// The child emitter's name (another emitter of the same effect).
    pub emitter: String,
    /// Children per event (death, collision, birth), each event drawing its own count.
    pub count: CountRange,
    /// The chance that a death, collision or birth spawns children at all (1 = always):
    /// a few smoke puffs from thousands of dying flames.
    pub probability: f32,
    /// Children per second per living parent (`OverLife` only).
    pub rate_per_sec: f32,
    /// The fraction of the parent's velocity a child starts with, added to the velocity
    /// its own spawn settings give it.
    pub inherit_velocity: f32,
    /// The child's colour is multiplied by the parent's colour at the event (its colour
    /// ramp at its age then, to 1/255): a white child ramp takes the parent's colour.
    pub inherit_color: bool,
    /// At most this many children per second of simulated time (whole effect), whatever
    /// the step, with bursts of a tenth of a second's worth let through (a bucket of
    /// tokens, [`super::RateCap`]); the rest are dropped and counted in the child's
    /// statistics.
    pub max_per_sec: f32,
}

impl Default for Event {
    fn default() -> Self {
        Self {
            trigger: Trigger::Death,
            emitter: String::new(),
            count: CountRange { min: 1, max: 1 },
            probability: 1.0,
            rate_per_sec: 10.0,
            inherit_velocity: 0.3,
            inherit_color: false,
            max_per_sec: 122_880.0,
        }
    }
}

impl Effect {
    /// The events feeding emitter `child`, as (parent index, event index), in update
    /// order of the parents.
    pub fn event_sources(&self, child: usize) -> Vec<(usize, usize)> {
        let Some(c) = self.emitters.get(child) else {
            return Vec::new();
        };
        let mut sources = Vec::new();
        for (p, e) in self.emitters.iter().enumerate() {
            for (k, ev) in e.events.iter().enumerate() {
                if ev.emitter == c.name {
                    sources.push((p, k));
                }
            }
        }
        sources
    }

    /// True when emitter `i` spawns from other emitters' events.
    pub fn event_fed(&self, i: usize) -> bool {
        let Some(c) = self.emitters.get(i) else {
            return false;
        };
        self.emitters
            .iter()
            .any(|e| e.events.iter().any(|ev| ev.emitter == c.name))
    }

    /// The emitter whose colour emitter `child` inherits: the first parent whose event
    /// feeding it has `inherit_color`.
    pub fn color_parent(&self, child: usize) -> Option<usize> {
        self.event_sources(child)
            .into_iter()
            .find(|&(p, k)| self.emitters[p].events[k].inherit_color)
            .map(|(p, _)| p)
    }

    /// The index of the emitter an event names.
    pub fn event_target(&self, event: &Event) -> Option<usize> {
        self.emitters.iter().position(|e| e.name == event.emitter)
    }

    /// Removes the events whose child is no longer an emitter of the effect (after
    /// emitters were removed).
    pub fn drop_dangling_events(&mut self) {
        let names: std::collections::HashSet<String> =
            self.emitters.iter().map(|e| e.name.clone()).collect();
        for e in &mut self.emitters {
            e.events.retain(|ev| names.contains(&ev.emitter));
        }
    }

    /// Each emitter's depth in the event graph: 0 without a parent, else one more than its
    /// deepest parent's (at most the emitter count: cycles are rejected by validation).
    fn event_depths(&self) -> Vec<usize> {
        let n = self.emitters.len();
        let mut depth = vec![0; n];
        // Bellman–Ford style relaxation: n rounds settle any acyclic graph.
        for _ in 0..n {
            let mut changed = false;
            for (p, e) in self.emitters.iter().enumerate() {
                for ev in &e.events {
                    if let Some(c) = self.event_target(ev) {
                        let d = (depth[p] + 1).min(n + 1);
                        if c != p && depth[c] < d {
                            depth[c] = d;
                            changed = true;
                        }
                    }
                }
            }
            if !changed {
                break;
            }
        }
        depth
    }

    /// The emitters in update order: every parent before the children its events feed
    /// (they read the parent's events the same step), otherwise in effect order.
    pub fn update_order(&self) -> Vec<usize> {
        let depth = self.event_depths();
        let mut order: Vec<usize> = (0..self.emitters.len()).collect();
        order.sort_by_key(|&i| (depth[i], i));
        order
    }

    /// The events' problems: unknown or self targets, a child fed twice, cycles, counts.
    pub(super) fn check_events(&self, c: &mut Checker) {
        for (i, e) in self.emitters.iter().enumerate() {
            if e.events.len() > MAX_EVENTS_PER_EMITTER {
                c.push(
                    format!("emitters[{i}].events"),
                    e.events.len(),
                    &format!("an emitter lists at most {MAX_EVENTS_PER_EMITTER} events"),
                );
            }
            for (k, ev) in e.events.iter().enumerate() {
                let p = |f: &str| format!("emitters[{i}].events[{k}].{f}");
                match self.event_target(ev) {
                    None => c.push(
                        p("emitter"),
                        format!("{:?}", ev.emitter),
                        "names no emitter of this effect; use another emitter's name",
                    ),
                    Some(t) if t == i => c.push(
                        p("emitter"),
                        format!("{:?}", ev.emitter),
                        "an emitter cannot feed itself; add a second emitter for the children",
                    ),
                    Some(_) => {}
                }
                if ev.count.min > ev.count.max || ev.count.max > MAX_CHILDREN_PER_EVENT {
                    c.push(
                        p("count"),
                        format!("{}..={}", ev.count.min, ev.count.max),
                        &format!("must be min ≤ max ≤ {MAX_CHILDREN_PER_EVENT}"),
                    );
                }
                c.num(|| p("probability"), ev.probability, 0.0, 1.0);
                c.num(|| p("rate_per_sec"), ev.rate_per_sec, 0.0, 1000.0);
                c.num(|| p("inherit_velocity"), ev.inherit_velocity, -10.0, 10.0);
                c.num(|| p("max_per_sec"), ev.max_per_sec, 1.0, 1e8);
            }
            if e.look.ribbon_per_parent() && !self.event_fed(i) {
                c.push(
                    format!("emitters[{i}].look.trail.mode"),
                    "PerParent",
                    "a ribbon per parent joins the particles events spawn; add an event on \
                     another emitter that spawns this one, or use History",
                );
            }
        }
        self.check_event_cycles(c);
    }

    fn check_event_cycles(&self, c: &mut Checker) {
        // A depth that reaches the emitter count means a cycle (an acyclic chain is shorter).
        let n = self.emitters.len();
        let depth = self.event_depths();
        if let Some((p, k)) = self.emitters.iter().enumerate().find_map(|(p, e)| {
            (depth[p] >= n)
                .then(|| {
                    e.events
                        .iter()
                        .position(|ev| self.event_target(ev).is_some_and(|t| t != p))
                })
                .flatten()
                .map(|k| (p, k))
        }) {
            c.push(
                format!("emitters[{p}].events[{k}].emitter"),
                format!("{:?}", self.emitters[p].events[k].emitter),
                "closes a cycle of events (an emitter would feed itself through others); \
                 remove one event of the cycle",
            );
        }
    }
}
