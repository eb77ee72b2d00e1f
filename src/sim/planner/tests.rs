//! Unit tests of the planner against closed forms (the GPU tests compare the GPU with the
//! CPU mirror, and both take their spawns from the planner).

use super::*;
use crate::effect::{Burst, Param, Range};

/// Every particle born so far is surely dead by its batch's end plus the longest life
/// (with its margins: 1e-4 of it, 1e-4 s, the f32 ages' drift over its steps) plus
/// 0.1 s; a raised lifetime range stretches the lives already born.
#[test]
fn all_are_dead_by_the_longest_life_and_its_margins() {
    let mut e = effect(
        0.0,
        0.0,
        vec![Burst {
            count: 10,
            ..Burst::default()
        }],
    );
    e.emitters[0].lifetime_secs = Range::new(0.5, 1.0);
    let (mut planner, _) = planned(&e, 1.0 / 60.0, 1);
    let drift = |life: f64| life * 60.0 * life * f64::from(f32::EPSILON);
    let by = |life: f64| 1.0 / 60.0 + life * (1.0 + 1e-4) + 1e-4 + drift(life) + 0.1;
    let dead = planner.emitters[0].all_dead_by(1.0);
    assert!((dead - by(1.0)).abs() < 1e-9, "{dead} against {}", by(1.0));
    e.emitters[0].lifetime_secs = Range::new(0.5, 2.0);
    planner.plan_step(&e, 1.0 / 60.0);
    let dead = planner.emitters[0].all_dead_by(1.0);
    assert!(
        (dead - by(2.0)).abs() < 1e-9,
        "raised: {dead} against {}",
        by(2.0)
    );
}

/// A collider sphere's centre is taken into the simulation's space, whose origin is
/// the emitter's first position: a sphere 0.5 m above an emitter at (1, 2, 3) sits at
/// (0, 0.5, 0) there.
#[test]
fn collider_spheres_sit_in_the_simulations_space() {
    let mut e = crate::effect::Emitter::default();
    e.collisions.spheres = vec![crate::effect::SphereCollider {
        center_m: [1.0, 2.5, 3.0],
        radius_m: 0.2,
    }];
    let p = params::static_params(&e, glam::DVec3::new(1.0, 2.0, 3.0), 0, 0, 16);
    assert_eq!(p.spheres[0], [0.0, 0.5, 0.0, 0.2]);
}

/// One emitter of `rate` a second, capped at `cap` a second (0: none), with `bursts`.
fn effect(rate: f32, cap: f32, bursts: Vec<Burst>) -> Effect {
    let mut effect = Effect::default();
    let e = &mut effect.emitters[0];
    e.capacity = 10_000;
    e.spawn_rate_per_sec = Param::Constant(rate);
    e.max_spawn_per_sec = cap;
    e.bursts = bursts;
    effect
}

/// A planner after `steps` steps of `dt` seconds of `effect`, and each step's (count,
/// first birth fraction, fraction between births).
fn planned(effect: &Effect, dt: f32, steps: usize) -> (EffectPlanner, Vec<(u32, f32, f32)>) {
    let mut planner = EffectPlanner::default();
    let births = (0..steps)
        .map(|_| {
            let p = planner.plan_step(effect, dt)[0].expect("enabled");
            (p.spawn_count, p.spawn_frac0, p.spawn_frac_step)
        })
        .collect();
    (planner, births)
}

/// Each step's births over the first `steps` steps of 1/60 s.
fn births(effect: &Effect, steps: usize) -> Vec<(u32, f32, f32)> {
    planned(effect, 1.0 / 60.0, steps).1
}

fn assert_births(got: (u32, f32, f32), want: (u32, f32, f32)) {
    assert!(
        got.0 == want.0 && (got.1 - want.1).abs() < 1e-5 && (got.2 - want.2).abs() < 1e-5,
        "births {got:?}, want {want:?}"
    );
}

/// A steady rate's particles are born where its running count crosses a whole one: at
/// 90 a second in 1/60 s steps (1.5 a step), one at 2/3 of the first step, then two at
/// 1/3 and 1 of the second.
#[test]
fn births_fall_where_the_rate_crosses_whole_particles() {
    let got = births(&effect(90.0, 0.0, Vec::new()), 2);
    assert_births(got[0], (1, 2.0 / 3.0, 2.0 / 3.0));
    assert_births(got[1], (2, 1.0 / 3.0, 2.0 / 3.0));
}

/// A step a cap cuts, or one with a burst besides the rate, spreads its births evenly
/// (the k-th at (k + ½) / n); a step of a burst alone puts them at the burst's moment.
#[test]
fn capped_and_mixed_steps_spread_their_births_and_bursts_keep_their_moment() {
    // 20 asked, the cap's bucket of 6 plus a step's 1 let through.
    let capped = births(&effect(1200.0, 60.0, Vec::new()), 1);
    assert_births(capped[0], (7, 0.5 / 7.0, 1.0 / 7.0));
    let burst = |time_secs: f32| Burst {
        time_secs,
        count: 3,
    };
    let mixed = births(&effect(90.0, 0.0, vec![burst(0.005)]), 1);
    assert_births(mixed[0], (4, 0.5 / 4.0, 1.0 / 4.0));
    let alone = births(&effect(0.0, 0.0, vec![burst(0.01)]), 1);
    assert_births(alone[0], (3, 0.6, 0.0));
}

/// A rate that is not constant asks for its integral over the step: a range, drawn once
/// per instance, asks for its drawn rate × the step.
#[test]
fn a_ranged_rate_asks_for_its_drawn_rate_over_the_step() {
    let rate = Param::Range {
        min: 30.0,
        max: 90.0,
    };
    let r = 30.0 + 60.0 * instance_random(7, 3);
    let got = expected_spawns(&rate, 7, 3, 0.5, 0.1);
    assert!(
        (got - r * 0.1).abs() < 1e-9,
        "{got} spawns, want {}",
        r * 0.1
    );
}

/// A burst at a step's end belongs to the next step only: 3 at 0.5 s over steps of
/// 0.25 s spawn once, in the third step.
#[test]
fn a_burst_on_a_step_boundary_spawns_once() {
    let e = effect(
        0.0,
        0.0,
        vec![Burst {
            time_secs: 0.5,
            count: 3,
        }],
    );
    let counts: Vec<u32> = planned(&e, 0.25, 4).1.iter().map(|b| b.0).collect();
    assert_eq!(counts, [0, 0, 3, 0]);
}

/// The stats count what a step could not spawn and what the ring cut short: a burst
/// of 25 into 10 slots drops 15; one more, a second later, while the first 10 (living
/// 5 s) are alive, recycles the oldest — and none when they lived only 0.9 s.
#[test]
fn the_stats_count_drops_and_living_particles_overwritten() {
    let mut e = effect(
        0.0,
        0.0,
        vec![
            Burst {
                time_secs: 0.0,
                count: 25,
            },
            Burst {
                time_secs: 1.0,
                count: 1,
            },
        ],
    );
    e.emitters[0].capacity = 10;
    e.emitters[0].lifetime_secs = Range::new(5.0, 5.0);
    let (planner, _) = planned(&e, 0.25, 8);
    let stats = &planner.emitters[0].stats;
    assert_eq!(stats.spawned, 11);
    assert_eq!(stats.dropped_over_capacity, 15);
    assert_eq!(stats.recycled_alive, 1);
    // Living 0.9 s, the first burst (born at 0 s) has died by 1 s: nothing recycled.
    e.emitters[0].lifetime_secs = Range::new(0.9, 0.9);
    let (planner, _) = planned(&e, 0.25, 8);
    assert_eq!(planner.emitters[0].stats.recycled_alive, 0);
}

/// A steady rate into a small ring overwrites living particles of many batches, each
/// counted once: 450 a second into 100 slots, living 10 s, for 1 s (60 steps of 7 or 8, so
/// one step's births overwrite two earlier steps' particles): the last 350 births each
/// overwrite a particle still alive.
#[test]
fn a_steady_rate_counts_every_living_particle_it_overwrites() {
    let mut e = effect(450.0, 0.0, Vec::new());
    e.emitters[0].capacity = 100;
    e.emitters[0].lifetime_secs = Range::new(10.0, 10.0);
    let (planner, births) = planned(&e, 1.0 / 60.0, 60);
    let stats = &planner.emitters[0].stats;
    assert_eq!(births.iter().map(|b| b.0).sum::<u32>(), 450);
    assert_eq!(stats.spawned, 450);
    assert_eq!(stats.recycled_alive, 350, "{stats:?}");
}
