//! Events on a real adapter: children spawn exactly where and as many as the CPU mirror of
//! the records and the scan says (the per-step cap and its dropped count included), every
//! trigger fires when it should, a child never spawns twice from one step's list, and
//! effects with events stay deterministic.

mod common;

use common::*;
use ignis::effect::*;
use ignis::testing::gpu::types::{Particle, SimParams};
use ignis::testing::shaders::ShaderLibrary;
use ignis::testing::sim::GpuSim;
use ignis::testing::sim::event_scan::{
    EventRecord, EventSpawn, ScanConfig, child_key, event_of, rules_of, scan_events,
};

const DT: f32 = 1.0 / 60.0;

/// The test's adapter, with any validation error a failure (the programs log them).
fn strict_gpu() -> ignis::testing::gpu::GpuContext {
    let ctx = gpu();
    ctx.device.on_uncaptured_error(std::sync::Arc::new(|e| {
        let mut msg = e.to_string();
        let mut source = std::error::Error::source(&e);
        while let Some(s) = source {
            msg += &format!(" / {s}");
            source = s.source();
        }
        panic!("GPU validation error: {msg}")
    }));
    ctx
}

/// A parent spraying short-lived particles and a child fed by `event` (no own spawns).
fn parent_and_child(event: Event, parent_rate: f32) -> Effect {
    let parent = Emitter {
        name: "parent".into(),
        capacity: 1024,
        spawn_rate_per_sec: Param::Constant(parent_rate),
        lifetime_secs: Range::new(0.2, 0.6),
        speed_m_per_s: Range::new(0.5, 1.5),
        spread_deg: 40.0,
        forces: Forces {
            gravity_m_per_s2: [0.0, -2.0, 0.0],
            ..plain_emitter().forces
        },
        events: vec![Event {
            emitter: "child".into(),
            ..event
        }],
        ..plain_emitter()
    };
    let child = Emitter {
        name: "child".into(),
        capacity: 4096,
        // Ignored: a fed emitter spawns from its events only.
        spawn_rate_per_sec: Param::Constant(500.0),
        lifetime_secs: Range::new(50.0, 100.0),
        transform: Transform {
            position_m: [2.0, 0.5, 0.0],
            ..Transform::default()
        },
        ..plain_emitter()
    };
    Effect {
        emitters: vec![parent, child],
        ..Effect::default()
    }
}

/// The CPU mirror of one step: the parent's records for its window and the scan's list,
/// within what the event's cap (`bucket`, carried from step to step) allows.
fn expected_list(
    effect: &Effect,
    sim: &GpuSim,
    p: &SimParams,
    (before, after): (&[Particle], &[Particle]),
    bucket: &mut ignis::effect::RateCap,
) -> (Vec<EventSpawn>, u32) {
    let rule = rules_of(&effect.emitters[0])[0];
    let mut records = Vec::new();
    for i in 0..p.update_window[1] {
        let slot = (p.update_window[0] + i) % p.capacity;
        let rel = (slot + p.capacity - p.spawn_head) % p.capacity;
        let born = rel < p.spawn_count;
        let a = &after[slot as usize];
        let (n, key, first_child) =
            event_of(&rule, 0, p, slot, &before[slot as usize], a, born, false);
        records.push((
            slot,
            EventRecord {
                pos_count: [a.pos_age[0], a.pos_age[1], a.pos_age[2], f32::from_bits(n)],
                vel_key: [
                    a.vel_life[0],
                    a.vel_life[1],
                    a.vel_life[2],
                    f32::from_bits(key),
                ],
                parent_t: (a.pos_age[3] / a.vel_life[3]).clamp(0.0, 1.0),
                first_child,
            },
        ));
    }
    let delta = (sim.planner.emitters[0].origin() - sim.planner.emitters[1].origin()).as_vec3();
    let ev = &effect.emitters[0].events[0];
    let room = ignis::testing::sim::event_scan::step_cap(effect, 0, 0);
    let cfg = ScanConfig {
        rule_capacity_cap: [
            0,
            effect.emitters[1].capacity,
            room,
            u32::from(ev.inherit_color),
        ],
        delta_inherit: [delta.x, delta.y, delta.z, ev.inherit_velocity],
        ..Default::default()
    };
    let (mut list, asked) = scan_events(
        (p.update_window[0], p.update_window[1]),
        p.capacity,
        &records,
        &cfg,
    );
    // The cap's bucket lets the first of them through (in slot order).
    let allowed = bucket.take(asked.min(room), ev.max_per_sec, p.dt_secs);
    list.truncate(allowed as usize);
    (list, asked)
}

/// Step by step, the children born equal the CPU mirror's list: count (capped), slots,
/// positions (in the child's simulation space), inherited velocities and lifetimes (from
/// the keys); the dropped count is the excess.
#[test]
fn death_children_match_the_cpu_mirror_including_the_cap() {
    // One block of the scan; then a parent window of several blocks wrapping its ring.
    // The caps per second refill 12.5 and 100.5 children per 1/60 s step into buckets of
    // 75 and 603: once a bucket has drained, 12 or 13, 100 or 101, alternating.
    check_against_the_mirror(Trigger::Death, DT, 1024, 900.0, 750.0, false);
    // Children that inherit the parent's colour carry its age at the event.
    check_against_the_mirror(Trigger::Death, DT, 4096, 9_000.0, 6030.0, true);
    // A window of more blocks than the scan's workgroup has invocations (about 350 blocks
    // of 1024 slots): each invocation places a run of consecutive blocks.
    check_against_the_mirror(Trigger::Death, DT, 1 << 19, 900_000.0, 12_000.0, false);
}

/// A parent whose event records cannot fit one storage binding is refused with a message
/// that names the emitter, the limit and the capacity that fits (nothing half-built).
#[test]
fn events_too_large_for_the_device_are_a_clear_error() {
    let ctx = gpu();
    let limit = ctx.device.limits().max_storage_buffer_binding_size;
    let mut effect = parent_and_child(Event::default(), 0.0);
    effect.emitters[0].name = "crowded parent".into();
    // The state (32 bytes a slot) fits; the records (72 bytes a slot) do not.
    effect.emitters[0].capacity = (limit / 64).min(u64::from(u32::MAX)) as u32;
    let err = match GpuSim::new(&ctx, ShaderLibrary::embedded(), &effect) {
        Ok(_) => panic!("event records over the binding limit were accepted"),
        Err(err) => err.to_string(),
    };
    let fits = (limit - 64) / 72;
    assert!(
        err.contains("crowded parent")
            && err.contains("max_storage_buffer_binding_size")
            && err.contains(&format!("capacity to {fits} or less")),
        "{err}"
    );
}

/// The same for birth events, whose parents are the slots just spawned: across the
/// steps where the parent's spawn ring wraps (2,000 births a second into 1,024 slots),
/// the slots spawned past the ring's end still get their own keys.
#[test]
fn birth_children_match_the_cpu_mirror_where_the_ring_wraps() {
    check_against_the_mirror(Trigger::Birth, DT, 1024, 2000.0, 1500.0, false);
}

/// The same for children over life at 1,000 a second in steps of 0.1 s: 100 due per parent
/// a step, held to the 64 one event spawns at most.
#[test]
fn over_life_children_match_the_cpu_mirror_up_to_the_per_event_limit() {
    check_against_the_mirror(Trigger::OverLife, 0.1, 1024, 300.0, 2_000.0, false);
}

fn check_against_the_mirror(
    trigger: Trigger,
    dt: f32,
    parent_capacity: u32,
    parent_rate: f32,
    max_per_sec: f32,
    inherit_color: bool,
) {
    let ctx = strict_gpu();
    let event = Event {
        trigger,
        rate_per_sec: 1000.0,
        count: CountRange { min: 1, max: 3 },
        probability: 0.8,
        inherit_velocity: 0.5,
        inherit_color,
        max_per_sec,
        ..Event::default()
    };
    let mut effect = parent_and_child(event, parent_rate);
    effect.emitters[0].capacity = parent_capacity;
    let child = &mut effect.emitters[1];
    child.capacity = 16384;
    // Off the parent's origin on every axis: the inherited offset has three components.
    child.transform.position_m = [2.0, 0.5, -0.7];
    // Children spread over a shape of their own and fly at a speed of their own, on top of
    // where the event happened and what they inherit.
    child.shape = Shape::Sphere {
        radius_m: 0.1,
        surface_only: false,
    };
    child.speed_m_per_s = Range::new(0.2, 0.4);
    effect.validate().expect("valid");
    let mut sim = GpuSim::new(&ctx, ShaderLibrary::embedded(), &effect).expect("sim");
    let (mut head, mut last_count, mut dropped, mut capped_steps) = (0u32, 0u32, 0u32, 0);
    let child_cap = effect.emitters[1].capacity;
    let mut bucket = ignis::effect::RateCap::default();
    for step in 0..60 {
        if step == 20 {
            // The child emitter moved: events still place children where they happen
            // (its simulation keeps its first origin, so its placement is now offset).
            effect.emitters[1].transform.position_m = [2.3, 0.2, -0.4];
        }
        sim.sync(&effect).expect("sync");
        let before = sim.read_particles(0).expect("read");
        let plans = sim.plan(&effect, dt, 1);
        sim.record_and_submit(&effect, &plans);
        let after = sim.read_particles(0).expect("read");
        let child = sim.read_particles(1).expect("read");
        let header = sim.read_event_header(1).expect("read").expect("a child");
        let p = plans[0][0].expect("parent planned");
        let (list, total) = expected_list(&effect, &sim, &p, (&before, &after), &mut bucket);
        head = (head + last_count) % child_cap;
        assert_eq!(header.head, head, "step {step}: head");
        assert_eq!(header.count as usize, list.len(), "step {step}: count");
        dropped += total - list.len() as u32;
        capped_steps += usize::from(total > list.len() as u32);
        assert_eq!(header.dropped, dropped, "step {step}: dropped");
        let cp = plans[0][1].expect("child planned");
        assert_eq!(cp.spawn_count, 0, "a fed emitter has no spawns of its own");
        for (k, s) in list.iter().enumerate() {
            let c = &child[((head + k as u32) % child_cap) as usize];
            check_child(c, s, &cp, inherit_color, &format!("step {step} child {k}"));
        }
        last_count = list.len() as u32;
    }
    assert!(
        capped_steps > 5,
        "the cap was reached in {capped_steps} steps"
    );
    let alive = alive_of(&sim.read_particles(1).expect("read"));
    let header = sim.read_event_header(1).expect("read").expect("a child");
    assert_eq!(
        alive as u32,
        header.total - header.dropped,
        "children alive"
    );
}

/// Child `c` of list entry `s` against the CPU's spawn of the child `cp` plans: the event's
/// position plus its own shape's offset, its own velocity plus what it inherits, and the
/// lifetime its key draws (with the parent's age in its lowest bits when `inherit_color`).
fn check_child(c: &Particle, s: &EventSpawn, cp: &SimParams, inherit_color: bool, what: &str) {
    let bits = s.vel_j[3].to_bits();
    assert_eq!(
        bits >> 24 & 1 == 1,
        inherit_color,
        "{what}: the entry's colour flag"
    );
    let key = child_key(
        cp.seed,
        cp.emitter_salt,
        s.pos_key[3].to_bits(),
        bits & 0xFFFF,
    );
    let q = ignis::testing::sim::cpu_reference::spawn_particle(cp, key);
    let origin = cp.world_from_emitter[3];
    let want_pos: Vec<f32> = (0..3)
        .map(|i| s.pos_key[i] + (q.pos_age[i] - origin[i]))
        .collect();
    // The shape's and the direction's trigonometry differ from the CPU's in the last bits.
    let near = |a: &[f32], b: &[f32]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-5);
    assert!(
        near(&c.pos_age[..3], &want_pos),
        "{what}: position {:?}, want {want_pos:?}",
        &c.pos_age[..3]
    );
    assert_eq!(c.pos_age[3], 0.0, "{what}: born this step");
    let want_vel: Vec<f32> = (0..3).map(|i| q.vel_life[i] + s.vel_j[i]).collect();
    assert!(
        near(&c.vel_life[..3], &want_vel),
        "{what}: velocity {:?}, want {want_vel:?}",
        &c.vel_life[..3]
    );
    let want = q.vel_life[3];
    // Inheriting the colour, the lifetime's lowest 8 bits carry the parent's age.
    let want = if inherit_color {
        f32::from_bits((want.to_bits() & !0xFF) | ((bits >> 16) & 0xFF))
    } else {
        want
    };
    assert_eq!(c.vel_life[3].to_bits(), want.to_bits(), "{what}: lifetime");
}

/// [`parent_and_child`] with one burst of `burst` parents at time 0, living `life_secs`
/// each, with no gravity, each spawning `children` at its death (inheriting no velocity).
fn burst_parents(children: u32, burst: u32, life_secs: f32) -> Effect {
    let event = Event {
        count: CountRange {
            min: children,
            max: children,
        },
        inherit_velocity: 0.0,
        ..Event::default()
    };
    let mut effect = parent_and_child(event, 0.0);
    let p = &mut effect.emitters[0];
    p.bursts = vec![Burst {
        time_secs: 0.0,
        count: burst,
    }];
    p.lifetime_secs = Range::new(life_secs, life_secs);
    p.forces.gravity_m_per_s2 = [0.0; 3];
    effect
}

/// A burst of 100 parents of one fixed lifetime: once they are all dead there are exactly
/// 100 × 3 children, born where the parents died.
#[test]
fn a_burst_that_dies_leaves_exactly_count_children() {
    let ctx = strict_gpu();
    let mut effect = burst_parents(3, 100, 0.5);
    let mut sim = GpuSim::new(&ctx, ShaderLibrary::embedded(), &effect).expect("sim");
    sim.step(&effect, DT, 25).expect("step");
    assert_eq!(
        alive_of(&sim.read_particles(1).expect("read")),
        0,
        "none dead yet"
    );
    // Step by step to the one step where they all die (and their children are listed).
    let mut children = sim.read_particles(1).expect("read");
    for _ in 0..35 {
        sim.step(&effect, DT, 1).expect("step");
        children = sim.read_particles(1).expect("read");
        if alive_of(&children) > 0 {
            break;
        }
    }
    assert_eq!(alive_of(&sim.read_particles(0).expect("read")), 0);
    assert_eq!(alive_of(&children), 300);
    // Parents flew straight at 0.5..1.5 m/s for 0.5 s from the origin: children sit on
    // that shell (in the child's space, offset by its placement).
    for c in children.iter().filter(|c| c.is_alive()) {
        let world = c.position() + glam::Vec3::new(2.0, 0.5, 0.0);
        let r = world.length();
        assert!((0.24..0.76).contains(&r), "child at {world} (r = {r})");
    }
    // With its parent switched off right after that step (no scan runs for it), the
    // child's list of 300 is stale and spawns nothing: ten steps on, each child is ten
    // steps older (a child reading the stale list would be born again every step).
    let born_at: Vec<f32> = children.iter().map(|c| c.pos_age[3]).collect();
    effect.emitters[0].enabled = false;
    sim.step(&effect, DT, 10).expect("step");
    let later = sim.read_particles(1).expect("read");
    for (c, age) in later.iter().zip(&born_at).filter(|(c, _)| c.is_alive()) {
        let grown = c.pos_age[3] - age;
        assert!(
            (grown - 10.0 * DT).abs() < 1e-5,
            "a child aged {grown} s in 10 steps"
        );
    }
}

/// Two parents feed one child in the same step: the second scan appends its children
/// after the first's (each scan starts where the list ends), so ten still parents dying
/// at x = −1 and ten at x = +1 leave ten children at each place.
#[test]
fn two_parents_feeding_one_child_in_one_step_both_get_their_children() {
    let ctx = strict_gpu();
    let mut effect = burst_parents(1, 10, 0.3);
    let a = &mut effect.emitters[0];
    a.speed_m_per_s = Range::new(0.0, 0.0);
    a.transform.position_m = [-1.0, 0.0, 0.0];
    let mut b = a.clone();
    b.name = "second parent".into();
    b.transform.position_m = [1.0, 0.0, 0.0];
    effect.emitters.insert(1, b);
    effect.validate().expect("valid");
    let mut sim = GpuSim::new(&ctx, ShaderLibrary::embedded(), &effect).expect("sim");
    sim.step(&effect, DT, 30).expect("step");
    let children = sim.read_particles(2).expect("read");
    let xs: Vec<f32> = children
        .iter()
        .filter(|c| c.is_alive())
        .map(|c| c.position().x + 2.0)
        .collect();
    assert_eq!(xs.len(), 20, "children: {xs:?}");
    for x in [-1.0f32, 1.0] {
        let at = xs.iter().filter(|&&v| (v - x).abs() < 1e-4).count();
        assert_eq!(at, 10, "children at x = {x}: {xs:?}");
    }
}

/// A parent with two rules feeds two children, each exactly: every rule has its own
/// records (a birth rule's two children and a death rule's three, per parent).
#[test]
fn two_rules_of_one_parent_keep_their_own_counts() {
    let ctx = strict_gpu();
    let mut effect = parent_and_child(
        Event {
            trigger: Trigger::Birth,
            count: CountRange { min: 2, max: 2 },
            ..Event::default()
        },
        0.0,
    );
    let mut second = effect.emitters[1].clone();
    second.name = "second child".into();
    effect.emitters.push(second);
    let parent = &mut effect.emitters[0];
    parent.events.push(Event {
        emitter: "second child".into(),
        count: CountRange { min: 3, max: 3 },
        ..Event::default()
    });
    parent.bursts = vec![Burst {
        time_secs: 0.0,
        count: 40,
    }];
    parent.lifetime_secs = Range::new(0.5, 0.5);
    effect.validate().expect("valid");
    let mut sim = GpuSim::new(&ctx, ShaderLibrary::embedded(), &effect).expect("sim");
    sim.step(&effect, DT, 10).expect("step");
    let alive = |sim: &GpuSim, e| alive_of(&sim.read_particles(e).expect("read"));
    assert_eq!(alive(&sim, 1), 80, "born: two each");
    assert_eq!(alive(&sim, 2), 0, "none dead yet");
    sim.step(&effect, DT, 50).expect("step");
    assert_eq!(alive(&sim, 0), 0);
    assert_eq!(alive(&sim, 1), 80, "the birth rule fired once");
    assert_eq!(alive(&sim, 2), 120, "died: three each");
}

/// Each trigger fires when it should: births (one child per parent born), over life
/// (rate × life children per parent), collisions (an impact on the ground).
#[test]
fn birth_over_life_and_collision_triggers_count_exactly() {
    let ctx = strict_gpu();
    let burst = |effect: &mut Effect| {
        effect.emitters[0].bursts = vec![Burst {
            time_secs: 0.0,
            count: 50,
        }];
        effect.emitters[0].lifetime_secs = Range::new(1.0, 1.0);
    };
    // Birth: one child each.
    let mut birth = parent_and_child(
        Event {
            trigger: Trigger::Birth,
            count: CountRange { min: 2, max: 2 },
            ..Event::default()
        },
        0.0,
    );
    burst(&mut birth);
    let mut sim = GpuSim::new(&ctx, ShaderLibrary::embedded(), &birth).expect("sim");
    sim.step(&birth, DT, 10).expect("step");
    assert_eq!(alive_of(&sim.read_particles(1).expect("read")), 100);
    // Over life: 10 per second for a 1 s life = 10 each (the ages cross 1..=10 tenths;
    // the last at age 1.0 when it dies).
    let mut over = parent_and_child(
        Event {
            trigger: Trigger::OverLife,
            rate_per_sec: 10.0,
            ..Event::default()
        },
        0.0,
    );
    burst(&mut over);
    let mut sim = GpuSim::new(&ctx, ShaderLibrary::embedded(), &over).expect("sim");
    sim.step(&over, DT, 90).expect("step");
    let header = sim.read_event_header(1).expect("read").expect("child");
    assert_eq!(header.dropped, 0);
    assert_eq!(alive_of(&sim.read_particles(1).expect("read")), 50 * 10);
    // Collision: parents fall onto the ground; each impact spawns one child; resting
    // particles (below the rest speed) spawn nothing more.
    let mut fall = parent_and_child(
        Event {
            trigger: Trigger::Collision,
            ..Event::default()
        },
        0.0,
    );
    burst(&mut fall);
    let p = &mut fall.emitters[0];
    p.lifetime_secs = Range::new(3.0, 3.0);
    p.speed_m_per_s = Range::new(0.0, 0.0);
    p.transform.position_m = [0.0, 0.3, 0.0];
    p.forces.gravity_m_per_s2 = [0.0, -9.81, 0.0];
    p.collisions = Collisions {
        ground: Some(GroundPlane {
            height_m: 0.0,
            kill_on_contact: false,
        }),
        elasticity: 0.0,
        rest_speed_m_per_s: 0.5,
        ..Collisions::default()
    };
    fall.validate().expect("valid");
    let mut sim = GpuSim::new(&ctx, ShaderLibrary::embedded(), &fall).expect("sim");
    sim.step(&fall, DT, 120).expect("step");
    assert_eq!(
        alive_of(&sim.read_particles(1).expect("read")),
        50,
        "one impact each"
    );
}

/// Validation names the field and the fix: unknown children, self-feeding, a child fed
/// twice, cycles, impossible counts, a ribbon per parent with no parent.
#[test]
fn bad_events_are_rejected_with_their_field() {
    let mut effect = parent_and_child(Event::default(), 10.0);
    effect.emitters[0].events[0].emitter = "nope".into();
    let errs = effect.validate().expect_err("unknown child");
    assert!(
        errs.iter()
            .any(|e| e.path == "emitters[0].events[0].emitter"),
        "{errs:?}"
    );
    let mut effect = parent_and_child(Event::default(), 10.0);
    effect.emitters[1].events = vec![Event {
        emitter: "parent".into(),
        ..Event::default()
    }];
    let errs = effect.validate().expect_err("a cycle");
    assert!(errs.iter().any(|e| e.problem.contains("cycle")), "{errs:?}");
    let mut effect = parent_and_child(Event::default(), 10.0);
    effect.emitters[0].events[0].count = CountRange { min: 4, max: 2 };
    let errs = effect.validate().expect_err("min > max");
    assert!(
        errs.iter().any(|e| e.path == "emitters[0].events[0].count"),
        "{errs:?}"
    );
    let mut effect = parent_and_child(Event::default(), 10.0);
    effect.emitters[0].events[0].emitter = "parent".into();
    let errs = effect.validate().expect_err("self");
    assert!(
        errs.iter()
            .any(|e| e.problem.contains("cannot feed itself")),
        "{errs:?}"
    );
    // A ribbon per parent on an emitter no event feeds.
    let mut effect = parent_and_child(Event::default(), 10.0);
    effect.emitters[0].look.trail = Some(Trail {
        mode: TrailMode::PerParent,
        ..Trail::default()
    });
    let errs = effect.validate().expect_err("an unfed ribbon per parent");
    assert!(
        errs.iter()
            .any(|e| e.path == "emitters[0].look.trail.mode" && e.problem.contains("History")),
        "{errs:?}"
    );
}

/// Two parents feeding one child: the list takes both parents' children in update order,
/// one ring head; exactly 100 × 3 + 40 × 2 children once both bursts have died.
#[test]
fn two_parents_feed_one_child() {
    let ctx = strict_gpu();
    let mut effect = parent_and_child(
        Event {
            count: CountRange { min: 3, max: 3 },
            ..Event::default()
        },
        0.0,
    );
    let p = &mut effect.emitters[0];
    p.bursts = vec![Burst {
        time_secs: 0.0,
        count: 100,
    }];
    p.lifetime_secs = Range::new(0.3, 0.5);
    let mut second = effect.emitters[0].clone();
    second.name = "second parent".into();
    second.seed_offset = 5;
    second.bursts[0].count = 40;
    second.events[0].count = CountRange { min: 2, max: 2 };
    effect.emitters.push(second);
    effect.validate().expect("valid");
    assert_eq!(effect.event_sources(1), [(0, 0), (2, 0)]);
    assert_eq!(effect.update_order(), [0, 2, 1], "parents first");
    let mut sim = GpuSim::new(&ctx, ShaderLibrary::embedded(), &effect).expect("sim");
    sim.step(&effect, DT, 45).expect("step");
    assert_eq!(alive_of(&sim.read_particles(1).expect("read")), 380);
    let header = sim.read_event_header(1).expect("read").expect("child");
    assert_eq!((header.total, header.dropped), (380, 0));
}

/// 2 s of frames at 30, 60, 144 and 240 fps, and jittered between 4 and 40 ms.
fn frame_sequences() -> Vec<(String, Vec<f64>)> {
    let mut out: Vec<(String, Vec<f64>)> = [30.0, 60.0, 144.0, 240.0]
        .iter()
        .map(|fps| (format!("{fps} fps"), vec![1.0 / fps; (2.0 * fps) as usize]))
        .collect();
    let (mut jitter, mut t, mut x) = (Vec::new(), 0.0, 12345u32);
    while t < 2.0 {
        x = x.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        let dt = 0.004 + 0.036 * f64::from(x >> 8) / f64::from(1u32 << 24);
        let dt = dt.min(2.0 - t).max(1e-4);
        jitter.push(dt);
        t += dt;
    }
    out.push(("jitter".into(), jitter));
    out
}

/// A fixed-step chain of events: death → child, whose ground collisions feed a
/// grandchild drawn as a ribbon per parent.
fn event_chain() -> Effect {
    let mut effect = parent_and_child(
        Event {
            count: CountRange { min: 1, max: 4 },
            ..Event::default()
        },
        600.0,
    );
    effect.time.mode = TimeMode::FixedStep;
    let child = &mut effect.emitters[1];
    child.lifetime_secs = Range::new(0.5, 1.5);
    child.speed_m_per_s = Range::new(0.5, 1.0);
    child.spread_deg = 60.0;
    child.forces.gravity_m_per_s2 = [0.0, -9.81, 0.0];
    child.collisions.ground = Some(GroundPlane {
        height_m: -0.5,
        kill_on_contact: true,
    });
    child.events = vec![Event {
        trigger: Trigger::Collision,
        emitter: "grandchild".into(),
        count: CountRange { min: 2, max: 3 },
        ..Event::default()
    }];
    let mut grandchild = Emitter {
        name: "grandchild".into(),
        capacity: 2048,
        lifetime_secs: Range::new(0.3, 0.6),
        speed_m_per_s: Range::new(1.0, 2.0),
        spread_deg: 80.0,
        ..plain_emitter()
    };
    // The grandchildren of one impact joined by a ribbon per parent: its links too.
    grandchild.look.trail = Some(Trail {
        mode: TrailMode::PerParent,
        ..Trail::default()
    });
    effect.emitters.push(grandchild);
    effect.validate().expect("valid");
    effect
}

/// A fixed-step effect with a chain of events (death → child, whose collisions feed a
/// grandchild drawn as a ribbon per parent) played through a player at 30, 60, 144 and
/// 240 fps and under jitter ends bit-identical, and seeking back to 1 s (from snapshots and from the start) gives the
/// played state.
#[test]
fn events_are_frame_rate_independent_and_seekable() {
    let ctx = strict_gpu();
    let effect = event_chain();
    let state = |run: &ignis::testing::headless::Headless| -> Vec<u8> {
        let links = run
            .player
            .trail(run.instance, 2)
            .expect("read")
            .expect("a ring");
        (0..3)
            .flat_map(|e| {
                let p = run.player.particles(run.instance, e).expect("read");
                bytemuck::cast_slice::<_, u8>(&p).to_vec()
            })
            .chain(bytemuck::cast_slice::<_, u8>(&links.entries).to_vec())
            .collect()
    };
    let mut reference = None;
    for (name, frames) in frame_sequences() {
        let mut run = ignis::testing::headless::Headless::new(
            &ctx,
            effect.clone(),
            ShaderLibrary::embedded(),
        )
        .expect("headless");
        for dt in &frames {
            run.advance(*dt);
        }
        let got = state(&run);
        let grandchildren = run.player.particles(run.instance, 2).expect("read");
        assert!(
            alive_of(&grandchildren) > 20,
            "{name}: the chain reached the grandchild"
        );
        match &reference {
            None => reference = Some(got),
            Some(want) => assert!(*want == got, "{name}: differs from the first sequence"),
        }
    }
    // Seeking: played to 2 s at 60 fps with snapshots every 0.75 s, back to 1 s.
    let settings = ignis::PlayerSettings {
        batch_instances: false,
        ..ignis::testing::composite::Composite::player_settings()
    };
    let mut run = ignis::testing::headless::Headless::with_settings(
        &ctx,
        effect,
        ShaderLibrary::embedded(),
        settings,
    )
    .expect("headless");
    run.player.keep_seek_snapshots(0.75, 64 << 20);
    let mut at_one = Vec::new();
    for frame in 1..=120 {
        run.advance(1.0 / 60.0);
        if frame == 60 {
            at_one = state(&run);
        }
    }
    run.seek(1.0, 1.0 / 60.0);
    assert!(
        state(&run) == at_one,
        "seeking back to 1 s gives the played state"
    );
    // Without snapshots a seek replays from the start (a restart of every pool).
    let mut fresh = ignis::testing::headless::Headless::new(
        &ctx,
        run.effect().clone(),
        ShaderLibrary::embedded(),
    )
    .expect("headless");
    fresh.seek(1.0, 1.0 / 60.0);
    assert!(
        state(&fresh) == at_one,
        "a seek from the start gives the played state"
    );
}

/// The shipped campfire: its smoke is born where its flames die (about 90 puffs a second:
/// one dying flame in 22), and its embers' trails are recorded.
#[test]
fn the_campfire_smoke_comes_from_its_flames() {
    let ctx = strict_gpu();
    let effect = ignis::preset::load(std::path::Path::new("presets/campfire.ron")).expect("load");
    let smoke = effect
        .emitters
        .iter()
        .position(|e| e.name == "smoke")
        .expect("smoke");
    assert_eq!(effect.event_sources(smoke).len(), 1);
    let mut sim = GpuSim::new(&ctx, ShaderLibrary::embedded(), &effect).expect("sim");
    sim.step(&effect, effect.time.step_secs, 480).expect("step");
    let header = sim.read_event_header(smoke).expect("read").expect("fed");
    let alive = alive_of(&sim.read_particles(smoke).expect("read"));
    // 4 s of flames dying at ~2000/s, one in 22 kept: ~360 puffs, 2.5–4 s lives.
    assert!(
        (250..=450).contains(&header.total),
        "puffs asked for: {}",
        header.total
    );
    assert_eq!(header.dropped, 0);
    assert!((150..=400).contains(&alive), "smoke alive: {alive}");
}

/// A runtime player's live edit that adds events to a batched effect moves its instances
/// onto simulations of their own (events are not batched) and the children spawn; removing
/// the events batches them again, and the instances keep playing.
#[test]
fn adding_and_removing_events_live_moves_instances_between_batches_and_own_sims() {
    let ctx = strict_gpu();
    let torch = ignis::preset::load(std::path::Path::new("presets/torch.ron")).expect("load");
    assert!(ignis::testing::sim::batch::batchable(&torch));
    let settings = ignis::PlayerSettings {
        batch_instances: true,
        ..ignis::testing::composite::Composite::player_settings()
    };
    let mut run = ignis::testing::headless::Headless::with_settings(
        &ctx,
        torch,
        ShaderLibrary::embedded(),
        settings,
    )
    .expect("headless");
    let second = run
        .player
        .add_instance(glam::Mat4::from_translation(glam::vec3(1.0, 0.0, 0.0)), 9)
        .expect("instance");
    for _ in 0..30 {
        run.advance(1.0 / 60.0);
    }
    let smoke = run
        .effect()
        .emitters
        .iter()
        .position(|e| e.name == "smoke")
        .expect("smoke");
    let sparks = run
        .effect()
        .emitters
        .iter()
        .position(|e| e.name == "sparks")
        .expect("sparks");
    run.edit(|fx| {
        let flame = fx
            .emitters
            .iter()
            .position(|e| e.name == "flame")
            .expect("flame");
        fx.emitters[flame].events = vec![Event {
            emitter: "sparks".into(),
            count: CountRange { min: 1, max: 2 },
            probability: 0.2,
            ..Event::default()
        }];
    })
    .expect("the edit");
    for _ in 0..60 {
        run.advance(1.0 / 60.0);
    }
    for id in [run.instance, second] {
        let counts = run.player.count_particles(id).expect("counts");
        let events = counts[sparks].events.expect("the sparks are fed");
        assert!(events.asked > 20, "{events:?}");
        assert!(counts[sparks].alive > 0 && counts[smoke].alive > 0);
    }
    run.edit(|fx| {
        for e in &mut fx.emitters {
            e.events.clear();
        }
    })
    .expect("the edit back");
    for _ in 0..30 {
        run.advance(1.0 / 60.0);
    }
    let alive = |id| {
        run.player
            .count_particles(id)
            .expect("counts")
            .iter()
            .map(|c| c.alive)
            .sum::<u32>()
    };
    assert!(alive(run.instance) > 0 && alive(second) > 0);
}

/// A child that inherits its parent's colour is drawn in it: an invisible parent with a
/// pure red ramp, whose births spawn white children; with `inherit_color` the children's
/// light is red, without it white (billboards, tiles and the splat read it alike).
#[test]
fn inherited_colour_tints_the_children() {
    let ctx = strict_gpu();
    let white = flat_color([1.0, 1.0, 1.0, 1.0]);
    let light = |inherit_color: bool, path: DrawPath| {
        let mut effect = parent_and_child(
            Event {
                trigger: Trigger::Birth,
                inherit_color,
                inherit_velocity: 0.0,
                ..Event::default()
            },
            400.0,
        );
        effect.camera.target_m = [0.0, 0.5, 0.0];
        effect.post.bloom = None;
        let parent = &mut effect.emitters[0];
        parent.look.intensity = 0.0;
        parent.look.color_over_life = flat_color([1.0, 0.0, 0.0, 1.0]);
        let child = &mut effect.emitters[1];
        child.transform.position_m = [0.0, 0.0, 0.0];
        child.look.color_over_life = white.clone();
        child.look.intensity = 0.5;
        child.look.draw_path = path;
        effect.validate().expect("valid");
        let image = headless_after(&ctx, effect, 30)
            .render((160, 120))
            .expect("render");
        let mut sum = [0.0f64; 3];
        for p in image.pixels() {
            for c in 0..3 {
                sum[c] += f64::from(p[c]);
            }
        }
        sum
    };
    for path in [DrawPath::Billboard, DrawPath::Splat, DrawPath::Tiles] {
        let [r, g, b] = light(true, path);
        assert!(
            r > 1000.0 && g < r * 0.05 && b < r * 0.05,
            "{path:?} inherited: {r} {g} {b}"
        );
        let [r, g, b] = light(false, path);
        assert!(
            g > r * 0.5 && b > r * 0.5,
            "{path:?} own colour: {r} {g} {b}"
        );
    }
}

/// The children of the events of `effect` (emitter 1) after `secs` at steps of `dt`: their
/// lifetimes' bits (drawn from their keys: the same bits, the same particle), sorted.
fn children_at_step(effect: &Effect, dt: f32, secs: f32) -> Vec<u32> {
    let ctx = gpu();
    let mut effect = effect.clone();
    effect.time.step_secs = dt;
    let mut sim = GpuSim::new(&ctx, ShaderLibrary::embedded(), &effect).expect("sim");
    sim.step(&effect, dt, (secs / dt).round() as u32)
        .expect("step");
    let mut lives: Vec<u32> = sim
        .read_particles(1)
        .expect("read")
        .iter()
        .filter(|p| p.is_alive())
        .map(|p| p.vel_life[3].to_bits())
        .collect();
    lives.sort_unstable();
    lives
}

/// Events' children are the same particles at any step: an over-life child is keyed by
/// its number in its parent's life (not by the step it falls in), a bounce by the parent's
/// age in 1/16 s (not by the age's bits, which differ with the step) — so the image of an
/// effect with events converges as the step shrinks (`ignis tune`'s references).
#[test]
fn the_children_of_events_are_the_same_particles_at_any_step() {
    // Over life: 20 parents living 1 s, 30 children a second each.
    let mut over_life = parent_and_child(
        Event {
            trigger: Trigger::OverLife,
            rate_per_sec: 30.0,
            ..Event::default()
        },
        0.0,
    );
    over_life.emitters[0].bursts = vec![Burst {
        time_secs: 0.0,
        count: 20,
    }];
    over_life.emitters[0].lifetime_secs = Range::new(1.0, 1.0);
    let a = children_at_step(&over_life, 1.0 / 60.0, 0.55);
    assert_eq!(a.len(), 20 * 16, "born at 0: 0.55 s old");
    // Keyed by their parent's life too: no two parents' k-th children alike.
    let mut distinct = a.clone();
    distinct.dedup();
    assert_eq!(
        distinct.len(),
        a.len(),
        "over-life children's lifetimes repeat"
    );
    assert_eq!(a, children_at_step(&over_life, 1.0 / 240.0, 0.55));
    assert_eq!(a, children_at_step(&over_life, 1.0 / 20.0, 0.55));

    // Collisions: sparks bouncing on the ground, a child per bounce.
    let mut bounce = parent_and_child(
        Event {
            trigger: Trigger::Collision,
            ..Event::default()
        },
        0.0,
    );
    let p = &mut bounce.emitters[0];
    p.bursts = vec![Burst {
        time_secs: 0.0,
        count: 200,
    }];
    p.lifetime_secs = Range::new(5.0, 5.0);
    p.transform.position_m = [0.0, 0.5, 0.0];
    p.speed_m_per_s = Range::new(1.0, 3.0);
    p.forces.gravity_m_per_s2 = [0.0, -9.81, 0.0];
    p.collisions.ground = Some(GroundPlane::default());
    p.collisions.elasticity = 0.6;
    // The same children, but for bounces whose age straddles a 1/16 s mark between two
    // steps, and for the last, near-resting hops: fewer as the step shrinks.
    let finest = children_at_step(&bounce, 1.0 / 960.0, 2.0);
    let shared_with_finest = |dt: f32| {
        let a = children_at_step(&bounce, dt, 2.0);
        let shared = a.iter().filter(|x| finest.binary_search(x).is_ok()).count();
        (shared as f64 / a.len().max(finest.len()) as f64, a.len())
    };
    let ((coarse, coarse_bounces), (fine, _)) = (
        shared_with_finest(1.0 / 120.0),
        shared_with_finest(1.0 / 480.0),
    );
    assert!(finest.len() > 400, "{} bounces", finest.len());
    // Each bounce draws children of its own: a spark's bounces are told apart by their
    // ordinal (its age in 1/16 s), so their lifetimes seldom repeat — only the last hops,
    // less than 1/16 s apart, share one (without the ordinal, about one in eight would
    // be distinct: 200 sparks).
    let mut distinct = finest.clone();
    distinct.dedup();
    assert!(
        distinct.len() * 4 >= finest.len() * 3,
        "{} distinct lifetimes among {} children of bounces",
        distinct.len(),
        finest.len()
    );
    assert!(
        fine > 0.8 && fine > coarse,
        "shared: {coarse} at 1/120 s, {fine} at 1/480 s"
    );
    // A spark resting on the ground does not hit it at every coarse step (what gravity
    // adds in a step is no impact): no more bounces at 1/120 s than at 1/960 s.
    assert!(
        coarse_bounces <= finest.len(),
        "{coarse_bounces} bounces at 1/120 s, {} at 1/960 s",
        finest.len()
    );
}
