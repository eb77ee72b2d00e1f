//! Events on the GPU: a parent's update writes one record per slot and rule
//! (`shaders/events_on.wgsl`), a scan turns a rule's records into its child's spawn list
//! in slot order (`shaders/events.wgsl`), and the child's update spawns from the list the
//! same step. Deterministic: nothing depends on the order threads run in.
//!
//! This file holds the buffers' structs and sizes and the CPU mirror of the counts, keys
//! and scan (the tests hold the GPU to it); the buffers themselves and the scan's
//! pipelines are the update's hooks (`crate::sim::hooks`).

use bytemuck::{Pod, Zeroable};

use crate::effect::{Effect, Emitter, MAX_CHILDREN_PER_EVENT, MAX_EVENTS_PER_EMITTER};
use crate::gpu::types::{Particle, SimParams, slot_counter};
use crate::rng::pcg4d;

/// A rule slot with no event (`TRIGGER_NONE`).
const TRIGGER_NONE: u32 = u32::MAX;

/// One rule of a parent, as the update reads it (`EventRule` in the shaders).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct EventRule {
    /// [`crate::effect::Trigger::index`], or `u32::MAX` for none.
    pub trigger: u32,
    /// Fewest children per event.
    pub count_min: u32,
    /// Most children per event.
    pub count_max: u32,
    /// Over life: children per second.
    pub rate: f32,
    /// The chance an event (death, collision, birth) spawns at all.
    pub probability: f32,
    /// Padding.
    pub pad: [u32; 3],
}

/// One parent slot's record for one rule, as the CPU mirror takes it (the GPU keeps the
/// count apart from the rest: `EventOut` in `shaders/event_types.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct EventRecord {
    /// Position, and the children (u32 bits).
    pub pos_count: [f32; 4],
    /// Velocity, and the event's key (u32 bits).
    pub vel_key: [f32; 4],
    /// The parent's normalised age.
    pub parent_t: f32,
    /// The number of the event's first child in the parent's life (over life; 0 for the
    /// other triggers): its children are numbered on from it.
    pub first_child: u32,
}

/// A collision's ordinal is the parent's age in these units (`COLLISION_ORDINALS_PER_SEC`
/// in `shaders/events_on.wgsl`): one bounce draws the same children at any step.
pub const COLLISION_ORDINALS_PER_SEC: f32 = 16.0;

/// One entry of a child's spawn list (`EventSpawn`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct EventSpawn {
    /// Position in the child's simulation space, and the event's key (u32 bits).
    pub pos_key: [f32; 4],
    /// The inherited velocity, and the child's index in its event (u32 bits).
    pub vel_j: [f32; 4],
}

/// The head of a child's spawn list (the first 32 bytes of `EventIn`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct EventHeader {
    /// The ring slot of this step's first child.
    pub head: u32,
    /// Children this step.
    pub count: u32,
    /// The step number the scan last ran at.
    pub stamp: u32,
    /// Children dropped by the per-step cap, since the start.
    pub dropped: u32,
    /// Children the events asked for, since the start.
    pub total: u32,
    /// Padding.
    pub pad: [u32; 3],
}

/// One rule's scan settings (`ScanConfig` in `shaders/events.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct ScanConfig {
    /// The rule's index, the child's capacity, the child list's room per step ([`step_cap`]),
    /// flags (`scan_flags`).
    pub rule_capacity_cap: [u32; 4],
    /// The parent's simulation origin minus the child's, and the inherited fraction.
    pub delta_inherit: [f32; 4],
    /// The event's cap: children per second, the burst its bucket holds
    /// ([`crate::effect::RateCap`]); unused, unused.
    pub cap: [f32; 4],
}

/// A scan's flags: its children inherit the parent's colour (bit 0), they are linked
/// into a ribbon per parent (bit 1).
pub fn scan_flags(inherit_color: bool, ribbon: bool) -> u32 {
    u32::from(inherit_color) | u32::from(ribbon) << 1
}

/// Bytes before the counts of a parent's buffer (the two rules).
pub(super) const RULES_BYTES: u64 = (MAX_EVENTS_PER_EMITTER * size_of::<EventRule>()) as u64;

/// Words of one record (`RECORD_WORDS` in `shaders/event_types.wgsl`).
pub(super) const RECORD_WORDS: u64 = 8;

/// Slots per workgroup of the scan's passes (`BLOCK` in `shaders/events.wgsl`).
pub const EVENT_SCAN_BLOCK: u32 = 1024;

/// The update's rules of emitter `e` (unused slots say none).
pub fn rules_of(e: &Emitter) -> [EventRule; MAX_EVENTS_PER_EMITTER] {
    let mut rules = [EventRule {
        trigger: TRIGGER_NONE,
        ..Default::default()
    }; MAX_EVENTS_PER_EMITTER];
    for (r, ev) in rules.iter_mut().zip(&e.events) {
        *r = EventRule {
            trigger: ev.trigger.index(),
            count_min: ev.count.min,
            count_max: ev.count.max.max(ev.count.min),
            rate: ev.rate_per_sec,
            probability: ev.probability,
            pad: [0; 3],
        };
    }
    rules
}

/// The room event `k` of `parent` needs in its child's spawn list per step: the most its
/// cap lets through in one step (a full bucket and the effect's longest step's refill,
/// [`crate::effect::RateCap`]), within the child's capacity.
pub fn step_cap(effect: &Effect, parent: usize, k: usize) -> u32 {
    let ev = &effect.emitters[parent].events[k];
    let child = effect
        .event_target(ev)
        .map_or(1, |c| effect.emitters[c].capacity);
    let longest = f64::from(effect.time.longest_step_secs());
    let burst = f64::from(crate::effect::cap_burst(ev.max_per_sec));
    let most = (burst + f64::from(ev.max_per_sec) * longest).floor() + 1.0;
    (most.min(f64::from(child)) as u32).max(1)
}

/// The children one parent slot's rule asks for this step, the event's key and the number
/// of its first child: the CPU mirror of `emit_events` (`shaders/events_on.wgsl`). `before`/`after`: the slot's state
/// at the step's start and end; `born`: spawned this step; `hit`: a collider impact.
#[allow(clippy::too_many_arguments)]
pub fn event_of(
    rule: &EventRule,
    k: u32,
    p: &SimParams,
    slot: u32,
    before: &Particle,
    after: &Particle,
    born: bool,
    hit: bool,
) -> (u32, u32, u32) {
    let cap = p.capacity;
    let total =
        (u64::from(p.spawn_base_hi) << 32 | u64::from(p.spawn_base_lo)) + u64::from(p.spawn_count);
    let counter = slot_counter(slot, total, cap);
    let lived = born || before.is_alive();
    let alive = after.is_alive();
    let (mut n, mut ordinal, mut fired, mut first) = (0u32, 0u32, false, 0u32);
    match rule.trigger {
        0 => fired = lived && !alive,
        1 => {
            fired = lived && hit;
            ordinal = (after.pos_age[3] * COLLISION_ORDINALS_PER_SEC).floor() as u32;
        }
        2 => fired = born,
        3 => {
            if lived {
                let a0 = if born { 0.0 } else { before.pos_age[3] };
                let a1 = after.pos_age[3].min(after.vel_life[3]);
                let k0 = (rule.rate * a0).floor();
                n = ((rule.rate * a1).floor() - k0).max(0.0) as u32;
                first = k0 as u32;
            }
        }
        _ => return (0, 0, 0),
    }
    let h = pcg4d([
        p.seed ^ slot.wrapping_mul(0x9E37_79B9),
        counter as u32,
        ((counter >> 32) as u32) ^ (k << 28),
        ordinal,
    ]);
    let key = h[0] ^ p.emitter_salt;
    if fired {
        let h = pcg4d([key, p.seed, k, 0xC0]);
        let span = rule.count_max - rule.count_min + 1;
        let chosen = crate::rng::unorm(h[2]) < rule.probability;
        n = if chosen {
            rule.count_min + h[1] % span
        } else {
            0
        };
    }
    (n.min(MAX_CHILDREN_PER_EVENT), key, first)
}

/// The spawn list a scan makes of one rule's records over the parent's window (the CPU
/// mirror of `shaders/events.wgsl`): entries in slot order, at most `cap`; and the
/// children asked for in all.
pub fn scan_events(
    window: (u32, u32),
    capacity: u32,
    records: &[(u32, EventRecord)],
    cfg: &ScanConfig,
) -> (Vec<EventSpawn>, u32) {
    let by_slot: std::collections::HashMap<u32, &EventRecord> =
        records.iter().map(|(s, r)| (*s, r)).collect();
    let cap = cfg.rule_capacity_cap[2];
    let d = cfg.delta_inherit;
    let mut list = Vec::new();
    let mut total = 0u32;
    for i in 0..window.1 {
        let slot = (window.0 + i) % capacity;
        let Some(r) = by_slot.get(&slot) else {
            continue;
        };
        let n = r.pos_count[3].to_bits();
        let t = (r.parent_t * 255.0 + 0.5) as u32;
        let color = (t << 16) | ((cfg.rule_capacity_cap[3] & 1) << 24);
        let first = r.first_child;
        for j in 0..n {
            if total + j < cap {
                list.push(EventSpawn {
                    pos_key: [
                        r.pos_count[0] + d[0],
                        r.pos_count[1] + d[1],
                        r.pos_count[2] + d[2],
                        r.vel_key[3],
                    ],
                    vel_j: [
                        r.vel_key[0] * d[3],
                        r.vel_key[1] * d[3],
                        r.vel_key[2] * d[3],
                        f32::from_bits(color | (first.wrapping_add(j) & 0xFFFF)),
                    ],
                });
            }
        }
        total += n;
    }
    (list, total)
}

/// The random stream of child `j` of the event `event_key` (`child_key` in
/// `shaders/events_on.wgsl`).
pub fn child_key(seed: u32, salt: u32, event_key: u32, j: u32) -> [u32; 4] {
    pcg4d([
        seed,
        salt ^ 0xE7E7_E7E7,
        event_key,
        j.wrapping_mul(0x9E37_79B9),
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::effect::{Event, Trigger};

    /// A parent whose one event feeds `child`, with the event's fields from `event`.
    fn parent_and_child(event: Event, child_capacity: u32) -> Effect {
        let parent = Emitter {
            name: "parent".into(),
            events: vec![Event {
                emitter: "child".into(),
                ..event
            }],
            ..Emitter::default()
        };
        let child = Emitter {
            name: "child".into(),
            capacity: child_capacity,
            ..Emitter::default()
        };
        Effect {
            emitters: vec![parent, child],
            ..Effect::default()
        }
    }

    /// A rule that always fires `count` children (probability 1).
    fn rule(trigger: Trigger, count: u32) -> EventRule {
        EventRule {
            trigger: trigger.index(),
            count_min: count,
            count_max: count,
            probability: 1.0,
            ..EventRule::default()
        }
    }

    fn params() -> SimParams {
        SimParams {
            capacity: 64,
            seed: 0x1234_5678,
            emitter_salt: 0x9ABC,
            spawn_count: 3,
            spawn_base_lo: 200,
            ..SimParams::default()
        }
    }

    /// Rule `k` of `r` for slot `slot` of a particle that dies this step: (children, key,
    /// first child).
    fn on_death(r: &EventRule, k: u32, p: &SimParams, slot: u32) -> (u32, u32, u32) {
        event_of(r, k, p, slot, &living(1.9), &living(2.0), false, false)
    }

    /// A living particle of age `age` (of a 2 s life), before and after a step.
    fn living(age: f32) -> Particle {
        Particle {
            pos_age: [0.0, 0.0, 0.0, age],
            vel_life: [0.0, 0.0, 0.0, 2.0],
        }
    }

    #[test]
    fn unused_rule_slots_say_none() {
        let effect = parent_and_child(
            Event {
                trigger: Trigger::Birth,
                ..Event::default()
            },
            16,
        );
        let rules = rules_of(&effect.emitters[0]);
        assert_eq!(rules[0].trigger, Trigger::Birth.index());
        assert_eq!(
            rules[1].trigger, TRIGGER_NONE,
            "the second slot has no event"
        );
    }

    /// The room per step is a full bucket (0.1 s of the cap) plus the longest step's
    /// refill, rounded down, plus one; within the child's capacity, and at least one.
    #[test]
    fn a_step_cap_is_a_full_bucket_and_the_longest_steps_refill() {
        let mut effect = parent_and_child(
            Event {
                max_per_sec: 750.0,
                ..Event::default()
            },
            4096,
        );
        effect.time.mode = crate::effect::TimeMode::FixedStep;
        effect.time.step_secs = 1.0 / 60.0;
        // 75 + 12.5 → 87, + 1.
        assert_eq!(step_cap(&effect, 0, 0), 88);
        effect.time.step_secs = 0.1;
        // 75 + 75 → 150, + 1.
        assert_eq!(step_cap(&effect, 0, 0), 151);
        effect.emitters[1].capacity = 100;
        assert_eq!(step_cap(&effect, 0, 0), 100, "held to the child's capacity");
    }

    /// A collision fires for a living particle that hit, not for one that did not; two
    /// hits in one ordinal (1/16 s of age) share a key, hits in different ones do not.
    #[test]
    fn a_collision_fires_on_a_hit_and_keys_by_the_hits_age() {
        let (r, p) = (rule(Trigger::Collision, 2), params());
        let at =
            |age: f32, hit: bool| event_of(&r, 0, &p, 5, &living(0.1), &living(age), false, hit);
        assert_eq!(at(0.50, false).0, 0, "no hit, no children");
        let (n, key, first) = at(0.50, true);
        assert_eq!((n, first), (2, 0));
        assert_eq!(at(0.52, true).1, key, "the same ordinal: 0.50 s and 0.52 s");
        assert_ne!(at(0.60, true).1, key, "the next ordinal: 0.5625 s on");
        let dead = Particle::default();
        assert_eq!(
            event_of(&r, 0, &p, 5, &dead, &dead, false, true).0,
            0,
            "a slot that never lived does not collide"
        );
    }

    /// An event fires when its draw is below the probability: a probability equal to the
    /// draw does not fire, the next float up does (so 0 never fires and 1 always does).
    #[test]
    fn a_draw_equal_to_the_probability_does_not_fire() {
        let (mut r, p) = (rule(Trigger::Death, 1), params());
        let dies = |r: &EventRule| on_death(r, 0, &p, 7);
        let (n, key, _) = dies(&r);
        assert_eq!(n, 1, "probability 1 fires");
        let draw = crate::rng::unorm(pcg4d([key, p.seed, 0, 0xC0])[2]);
        r.probability = draw;
        assert_eq!(dies(&r).0, 0, "a probability equal to the draw {draw}");
        r.probability = f32::from_bits(draw.to_bits() + 1);
        assert_eq!(dies(&r).0, 1, "the next float up");
    }

    /// An event's key mixes in the whole spawn counter and the rule's number: a slot past
    /// 2³² spawns, or the same slot's second rule, draws other children.
    #[test]
    fn the_counters_high_word_and_the_rule_number_change_the_key() {
        let (r, p) = (rule(Trigger::Death, 1), params());
        let key = |p: &SimParams, k: u32| on_death(&r, k, p, 9).1;
        let past = SimParams {
            spawn_base_hi: 1,
            ..p
        };
        assert_ne!(key(&p, 0), key(&past, 0), "the counter's high word");
        assert_ne!(key(&p, 0), key(&p, 1), "the rule's number");
        assert_ne!(key(&past, 0), key(&past, 1), "the rule's number past 2³²");
    }

    /// A scan's list holds at most the room it is given, in slot order; the children asked
    /// for count them all.
    #[test]
    fn a_spawn_list_holds_at_most_its_room() {
        let record = |n: u32| EventRecord {
            pos_count: [0.0, 0.0, 0.0, f32::from_bits(n)],
            ..EventRecord::default()
        };
        let records = [(2, record(3)), (5, record(4)), (6, record(2))];
        let cfg = ScanConfig {
            rule_capacity_cap: [0, 64, 6, 0],
            ..ScanConfig::default()
        };
        let (list, asked) = scan_events((0, 8), 8, &records, &cfg);
        assert_eq!((list.len(), asked), (6, 9));
        let firsts: Vec<u32> = list.iter().map(|e| e.vel_j[3].to_bits() & 0xFFFF).collect();
        assert_eq!(
            firsts,
            [0, 1, 2, 0, 1, 2],
            "slot 2's three, then slot 5's first three"
        );
    }

    /// A count range draws within itself; a rule with no trigger asks for nothing.
    #[test]
    fn counts_stay_in_their_range_and_no_trigger_asks_nothing() {
        let mut r = rule(Trigger::Death, 0);
        r.count_max = 3;
        r.count_min = 1;
        let p = params();
        let counts: Vec<u32> = (0..64).map(|slot| on_death(&r, 0, &p, slot).0).collect();
        assert!(counts.iter().all(|n| (1..=3).contains(n)), "{counts:?}");
        assert!((1..=3).all(|n| counts.contains(&n)), "{counts:?}");
        r.trigger = TRIGGER_NONE;
        assert_eq!(on_death(&r, 0, &p, 3), (0, 0, 0));
    }
}
