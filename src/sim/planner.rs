//! CPU-side planning of each step: exact spawn counts in a ring of slots, and the
//! `SimParams` block that both the GPU pass and the CPU reference consume.

use std::collections::VecDeque;

use crate::effect::{Collisions, Effect, Emitter, Forces, Param, RateCap, Shape};
use crate::gpu::types::{SimParams, double_single};
use crate::rng;

mod params;
pub use params::*;

/// Spawn accounting of one emitter (shown in the stats panel).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SpawnStats {
    /// Particles born since the start.
    pub spawned: u64,
    /// Spawns dropped by the per-step cap (a long step must not cause a burst).
    pub dropped_by_cap: u64,
    /// Spawns dropped because one step asked for more than the whole capacity.
    pub dropped_over_capacity: u64,
    /// Particles cut short because the ring wrapped onto them while still alive:
    /// the capacity is too small for rate × lifetime.
    pub recycled_alive: u64,
}

/// A step's spawns: how many, and the first's birth fraction within the step and the
/// fraction between consecutive births.
struct Spawns {
    count: u64,
    frac0: f64,
    frac_step: f64,
}

#[derive(Clone, Copy, Debug)]
struct Batch {
    first_index: u64,
    count: u32,
    birth_secs: f64,
    /// The end of the step that spawned the batch: no particle of it is younger.
    youngest_birth_secs: f64,
    /// The longest lifetime this batch's particles can have: the largest maximum of the
    /// lifetime range seen since its spawn (packed state re-derives lifetimes from the
    /// current range, so a particle's life stretches while the range is raised).
    max_life_secs: f64,
    /// This emitter's batch sequence number (the tiny state's birth table is indexed by it).
    seq: u64,
    /// The spawning step's start (emitter clock), size, and the birth fractions of its
    /// first spawn and per spawn — exactly the f32 values the GPU spawned with.
    t0_secs: f64,
    dt_secs: f32,
    frac0: f32,
    frac_step: f32,
}

impl Batch {
    /// Every particle of the batch is dead at `at_secs` (the emitter's clock): it outlived
    /// the longest lifetime it could have, with a margin for the GPU's f32 ages — they
    /// grow by `dt` each step, and the rounding of those sums can lean one way for a
    /// whole lifetime: (steps) × ulp(lifetime) at most, `min_dt_secs` the smallest step.
    fn surely_dead(&self, at_secs: f64, max_life_now: f64, min_dt_secs: f64) -> bool {
        at_secs >= self.dead_by(max_life_now, min_dt_secs)
    }

    /// The time from which [`Batch::surely_dead`] holds.
    fn dead_by(&self, max_life_now: f64, min_dt_secs: f64) -> f64 {
        let bound = self.max_life_secs.max(max_life_now);
        let steps = bound / min_dt_secs.max(1e-6);
        let f32_drift = steps * bound * f64::from(f32::EPSILON);
        self.youngest_birth_secs + bound * (1.0 + 1e-4) + 1e-4 + f32_drift
    }
}

/// The slots of a ring that can hold living particles: `len` slots from `first_slot`,
/// wrapping at the capacity.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LiveWindow {
    /// The oldest slot that may be alive.
    pub first_slot: u32,
    /// How many slots, oldest to newest (≤ the capacity).
    pub len: u32,
}

impl LiveWindow {
    /// The whole pool (state written from outside the planner).
    pub fn all(capacity: u32) -> Self {
        Self {
            first_slot: 0,
            len: capacity,
        }
    }
}

/// Exact spawn counts for one emitter: rate × dt accumulated in f64.
#[derive(Clone, Debug, Default)]
pub struct EmitterPlanner {
    accumulator: f64,
    /// The spawn cap's bucket (`Emitter::max_spawn_per_sec`).
    spawn_cap: RateCap,
    spawned_total: u64,
    /// Running statistics.
    pub stats: SpawnStats,
    history: VecDeque<Batch>,
    /// The origin of this emitter's simulation space, fixed at its first step.
    origin: Option<glam::DVec3>,
    /// Start time of the last planned step on this emitter's clock (the time of the
    /// older state buffer).
    last_t0_secs: Option<f64>,
    /// This emitter's simulated time: advances only with its own steps, so a disabled
    /// (frozen) emitter's particles do not age on it. Births and deaths of the live
    /// window are on this clock; bursts follow the effect's.
    clock_secs: f64,
    /// The smallest step planned so far (bounds the f32 age drift).
    min_dt_secs: f64,
    /// The step size of the last planned step.
    last_dt_secs: f64,
    /// The sequence number the next batch gets.
    next_seq: u64,
    /// Particles the last planned step spawned.
    last_count: u64,
    /// The step-independent part of this emitter's `SimParams` and the revision of the
    /// emitter it was built from ([`EffectPlanner::plan_step_with`]); patched per step.
    template: Option<(u64, SimParams)>,
}

/// Plans every emitter of an effect, step after step.
#[derive(Clone, Debug, Default)]
pub struct EffectPlanner {
    /// One planner per emitter, in effect order.
    pub emitters: Vec<EmitterPlanner>,
    /// Simulated time at the start of the next step (f64 sum of step sizes).
    pub time_secs: f64,
    /// Steps planned so far.
    pub step_index: u64,
    /// Size of the last planned step, seconds.
    pub last_dt_secs: f32,
}

impl EffectPlanner {
    /// Plans one step of `dt_secs` for every emitter (disabled emitters get `None`).
    pub fn plan_step(&mut self, effect: &Effect, dt_secs: f32) -> Vec<Option<SimParams>> {
        let mut params = vec![None; effect.emitters.len()];
        self.plan_step_with(effect, None, dt_secs, |i, p| params[i] = p.copied());
        params
    }

    /// Plans one step of `dt_secs` and hands each emitter's block to `sink` (emitter
    /// index, `None` when disabled) without collecting them. With a `revision` (a value
    /// that changes whenever `effect` does: its seed, place or settings), each emitter's
    /// step-independent part is built once per revision and patched per step — the
    /// blocks are bit-identical to building them anew.
    pub fn plan_step_with(
        &mut self,
        effect: &Effect,
        revision: Option<u64>,
        dt_secs: f32,
        mut sink: impl FnMut(usize, Option<&SimParams>),
    ) {
        self.emitters
            .resize_with(effect.emitters.len(), Default::default);
        let t0 = self.time_secs;
        let mut params = SimParams::default();
        for (i, (e, p)) in effect
            .emitters
            .iter()
            .zip(self.emitters.iter_mut())
            .enumerate()
        {
            if !e.enabled {
                sink(i, None);
                continue;
            }
            let fed = effect.event_fed(i);
            p.plan_step_into(
                e,
                effect.seed,
                i as u32,
                t0,
                dt_secs,
                revision,
                fed,
                &mut params,
            );
            // The step's number: the event scan stamps a child's list with it.
            params.tiny_b[2] = self.step_index as u32;
            sink(i, Some(&params));
        }
        self.time_secs += dt_secs as f64;
        self.step_index += 1;
        self.last_dt_secs = dt_secs;
    }

    /// Back to time zero with empty pools.
    pub fn reset(&mut self) {
        *self = Self::default();
    }
}

impl EmitterPlanner {
    /// Plans one step starting at `t0_secs`.
    pub fn plan_step(
        &mut self,
        e: &Emitter,
        seed: u32,
        emitter_index: u32,
        t0_secs: f64,
        dt_secs: f32,
    ) -> SimParams {
        let mut params = SimParams::default();
        self.plan_step_into(
            e,
            seed,
            emitter_index,
            t0_secs,
            dt_secs,
            None,
            false,
            &mut params,
        );
        params
    }

    /// [`EmitterPlanner::plan_step`] into `out`, reusing the step-independent part of the
    /// block while `revision` (of the emitter, its seed and place) stays the same. `fed`:
    /// the emitter spawns from another's events only (no rate, no bursts).
    #[allow(clippy::too_many_arguments)]
    fn plan_step_into(
        &mut self,
        e: &Emitter,
        seed: u32,
        emitter_index: u32,
        t0_secs: f64,
        dt_secs: f32,
        revision: Option<u64>,
        fed: bool,
        out: &mut SimParams,
    ) {
        let dt = dt_secs as f64;
        let salt = rng::emitter_salt(emitter_index, e.seed_offset);
        // The emitter's own clock (it stands still while the emitter is disabled).
        let c0 = self.clock_secs;
        let Spawns {
            count,
            frac0,
            frac_step,
        } = self.count_spawns(e, (seed, salt), t0_secs, dt, fed);
        let capacity = e.capacity.max(1) as u64;
        let max_life_now = self.advance_clock(e, dt);
        let update_window = self.update_window(e, (seed, salt), count, c0, max_life_now);
        let base = self.spawned_total;
        if count > 0 {
            self.history.push_back(Batch {
                first_index: base,
                count: count as u32,
                birth_secs: c0 + dt * frac0.clamp(0.0, 1.0),
                youngest_birth_secs: c0 + dt,
                max_life_secs: max_life_now,
                seq: self.next_seq,
                t0_secs: c0,
                dt_secs,
                frac0: frac0 as f32,
                frac_step: frac_step as f32,
            });
            self.next_seq += 1;
        }
        let (t0_hi, t0_lo) = double_single(c0);
        let (first_seq, entries) = self.birth_window();
        let (oldest, span) = self.birth_span(base + count);
        self.spawned_total += count;
        self.stats.spawned += count;
        self.last_count = count;

        let origin = *self.origin.get_or_insert_with(|| sim_origin_for(e));
        *out = match (revision, &self.template) {
            (Some(r), Some((built, t))) if *built == r => *t,
            _ => {
                let t = static_params(e, origin, seed, salt, capacity as u32);
                self.template = revision.map(|r| (r, t));
                t
            }
        };
        out.set_step(dt_secs, t0_secs, base, count as u32);
        out.spawn_frac0 = frac0 as f32;
        out.spawn_frac_step = frac_step as f32;
        out.update_window = update_window;
        out.tiny = [t0_hi.to_bits(), t0_lo.to_bits(), first_seq as u32, entries];
        out.tiny_b = [oldest, span, 0, 0];
    }

    /// The particles this step spawns (the continuous rate's integer crossings over
    /// [clock, clock + dt], capped, plus the bursts that fall in [t0, t0 + dt]; none when
    /// `fed`: the step's births come from events) and their birth fractions within the
    /// step. `keys` = (effect seed, emitter salt).
    fn count_spawns(
        &mut self,
        e: &Emitter,
        keys: (u32, u32),
        t0_secs: f64,
        dt: f64,
        fed: bool,
    ) -> Spawns {
        let (seed, salt) = keys;
        let expected = if fed {
            0.0
        } else {
            expected_spawns(&e.spawn_rate_per_sec, seed, salt, self.clock_secs, dt)
        };
        let acc_before = self.accumulator;
        self.accumulator += expected;
        let continuous = self.accumulator.floor();
        self.accumulator -= continuous;
        let mut continuous = continuous as u64;
        let mut capped = false;
        if e.max_spawn_per_sec > 0.0 {
            let asked = continuous.min(u64::from(u32::MAX)) as u32;
            let cap = u64::from(self.spawn_cap.take(asked, e.max_spawn_per_sec, dt as f32));
            capped = cap < continuous;
            self.stats.dropped_by_cap += continuous - cap;
            continuous = cap;
        }
        let in_step = |b: &&crate::effect::Burst| {
            let t = b.time_secs as f64;
            !fed && t >= t0_secs && t < t0_secs + dt
        };
        let burst: u64 = e
            .bursts
            .iter()
            .filter(in_step)
            .map(|b| b.count as u64)
            .sum();
        // A step of bursts alone: its particles are born at the (first) burst's moment,
        // whatever the step (ages the same at any step size).
        let burst_frac = e
            .bursts
            .iter()
            .filter(in_step)
            .map(|b| (b.time_secs as f64 - t0_secs) / dt)
            .fold(f64::INFINITY, f64::min);
        let mut count = continuous + burst;
        let capacity = e.capacity.max(1) as u64;
        if count > capacity {
            self.stats.dropped_over_capacity += count - capacity;
            count = capacity;
        }
        // Birth fractions within the step: the k-th integer crossing of the accumulator.
        let (frac0, frac_step) = if burst == 0 && !capped && expected > 0.0 {
            let per = 1.0 / expected;
            ((1.0 - acc_before) * per, per)
        } else if continuous == 0 && burst > 0 {
            (burst_frac.clamp(0.0, 1.0), 0.0)
        } else if count > 0 {
            (0.5 / count as f64, 1.0 / count as f64)
        } else {
            (0.0, 0.0)
        };
        Spawns {
            count,
            frac0,
            frac_step,
        }
    }

    /// Moves the emitter's clock on by `dt` (and the smallest and last steps); returns the
    /// lifetime range's maximum now, raising the batches' where it grew.
    fn advance_clock(&mut self, e: &Emitter, dt: f64) -> f64 {
        self.clock_secs += dt;
        self.min_dt_secs = if self.min_dt_secs > 0.0 {
            self.min_dt_secs.min(dt)
        } else {
            dt
        };
        self.last_dt_secs = dt;
        let max_life_now = e.lifetime_secs.max as f64;
        // A raised range stretches the lives of packed particles already born. Every
        // batch holds at least the last step's maximum: only a raise changes any.
        if self
            .history
            .back()
            .is_some_and(|b| b.max_life_secs < max_life_now)
        {
            for b in &mut self.history {
                b.max_life_secs = b.max_life_secs.max(max_life_now);
            }
        }
        max_life_now
    }

    /// The update's window for a step from `c0` that spawns `count`: from the first slot
    /// that may hold a living particle to the newest spawn (slot, length). Accounts the
    /// particles the spawns overwrite.
    fn update_window(
        &mut self,
        e: &Emitter,
        keys: (u32, u32),
        count: u64,
        c0: f64,
        max_life_now: f64,
    ) -> [u32; 4] {
        let (seed, salt) = keys;
        let capacity = e.capacity.max(1) as u64;
        // The older of the two state buffers holds the state at the last step's start:
        // a batch dead by then is dead (and identical) in both, and need not be visited.
        let t_dead = self.last_t0_secs.map_or(c0, |t| t.min(c0));
        self.last_t0_secs = Some(c0);
        self.account_overwrites(e, seed, salt, count, c0, t_dead);
        let base = self.spawned_total;
        let min_dt = self.min_dt_secs;
        let first_live = self
            .history
            .iter()
            .find(|b| !b.surely_dead(t_dead, max_life_now, min_dt))
            .map_or(base, |b| b.first_index);
        let end = base + count;
        let first_live = first_live.max(end.saturating_sub(capacity));
        [
            (first_live % capacity) as u32,
            (end - first_live) as u32,
            0,
            0,
        ]
    }

    /// The birth table's oldest entry's first spawn counter (low 32 bits) and the counters
    /// from it to `end` (the spawn counter after the newest birth).
    fn birth_span(&self, end: u64) -> (u32, u32) {
        let oldest = self.history.front().map_or(end, |b| b.first_index);
        (oldest as u32, (end - oldest) as u32)
    }

    /// The birth table's oldest first counter and span after the last step (see
    /// `SimParams::tiny_b`), and the span before the last step's spawns (counters below it
    /// were already alive, or dead, at the last step's start).
    pub fn birth_span_now(&self) -> (u32, u32, u32) {
        let (oldest, span) = self.birth_span(self.spawned_total);
        (oldest, span, span.saturating_sub(self.last_count as u32))
    }

    /// Forgets every batch: the pool restarted empty (the live window and the tiny state's
    /// birth table start again from the next spawn), and re-anchors the simulation space
    /// at the emitter's position at its next step (nothing is left in the old one).
    pub fn forget_births(&mut self) {
        self.history.clear();
        self.origin = None;
        self.template = None;
    }

    /// The batches of the birth table (tiny state): the first sequence number and how
    /// many — every step whose particles may still be alive, oldest first.
    pub fn birth_window(&self) -> (u64, u32) {
        let first = self.history.front().map_or(self.next_seq, |b| b.seq);
        (first, self.history.len() as u32)
    }

    /// The age at `at_secs` (this emitter's clock) of the particle with spawn counter
    /// `counter`, if a batch that may still be alive spawned it (the CPU mirror of the tiny
    /// state's `birth_entry` and `birth_age`).
    pub fn birth_age(&self, counter: u64, at_secs: f64) -> Option<f64> {
        // The history is in counter order: the last batch starting at or before `counter`.
        let i = self
            .history
            .partition_point(|b| b.first_index <= counter)
            .checked_sub(1)?;
        let b = &self.history[i];
        if counter >= b.first_index + b.count as u64 {
            return None;
        }
        let k = (counter - b.first_index) as f32;
        let f = (b.frac0 + k * b.frac_step).clamp(0.0, 1.0);
        Some(at_secs - b.t0_secs - f64::from(b.dt_secs * f))
    }

    /// The size of the last planned step (s).
    pub fn last_dt_secs(&self) -> f64 {
        self.last_dt_secs
    }

    /// Counts still-alive particles the ring is about to overwrite.
    fn account_overwrites(
        &mut self,
        e: &Emitter,
        seed: u32,
        salt: u32,
        count: u64,
        t0: f64,
        t_dead: f64,
    ) {
        let capacity = e.capacity.max(1) as u64;
        let max_life = e.lifetime_secs.max as f64;
        // Forget batches dead in both state buffers for sure, or already overwritten.
        while let Some(front) = self.history.front() {
            let end = front.first_index + front.count as u64;
            let overwritten = end + capacity <= self.spawned_total;
            if overwritten || front.surely_dead(t_dead, max_life, self.min_dt_secs) {
                self.history.pop_front();
            } else {
                break;
            }
        }
        if self.history.is_empty() || count == 0 {
            return;
        }
        // Nothing this step overwrites is tracked (older batches are forgotten, hence
        // dead): the usual case of a pool sized for rate × lifetime.
        let newest_old = (self.spawned_total + count - 1).checked_sub(capacity);
        if newest_old.is_none_or(|old| self.history.front().is_some_and(|b| old < b.first_index)) {
            return;
        }
        // The overwritten counters are consecutive, and so are the batches (in spawn
        // order): one binary search for the first, then a walk.
        let first_old = self.spawned_total.saturating_sub(capacity);
        let mut at = self
            .history
            .partition_point(|b| b.first_index <= first_old)
            .saturating_sub(1);
        for j in self.spawned_total..self.spawned_total + count {
            let Some(old) = j.checked_sub(capacity) else {
                continue;
            };
            while self
                .history
                .get(at)
                .is_some_and(|b| old >= b.first_index + b.count as u64)
            {
                at += 1;
            }
            let Some(batch) = self.history.get(at).filter(|b| old >= b.first_index) else {
                continue;
            };
            // Clearly younger than the shortest lifetime: alive; clearly older than the
            // longest: dead (margins for the f32 rounding of the lifetime's mix); in
            // between, the particle's own lifetime decides.
            let age = t0 - batch.birth_secs;
            let alive = if age < f64::from(e.lifetime_secs.min) * (1.0 - 1e-5) {
                true
            } else if age >= f64::from(e.lifetime_secs.max) * (1.0 + 1e-5) {
                false
            } else {
                let slot = (old % capacity) as u32;
                let r1 = rng::unorm4(rng::rand_block(rng::spawn_key(seed, salt, slot, old), 1));
                age < mix(e.lifetime_secs.min, e.lifetime_secs.max, r1[3]) as f64
            };
            self.stats.recycled_alive += u64::from(alive);
        }
    }

    /// The world position of this emitter's simulation space (particle positions are
    /// stored relative to it, so an effect far from the world origin keeps full f32
    /// precision). Fixed at the first step; world-space behaviour is kept when the
    /// emitter moves later.
    pub fn origin(&self) -> glam::DVec3 {
        self.origin.unwrap_or_default()
    }

    /// The parameter block a step of `e` starting at effect time `t_secs` would read (the
    /// forces' settings, in this emitter's simulation space): what an inspection of a
    /// particle evaluates the forces with.
    pub fn params_now(&self, e: &Emitter, seed: u32, emitter_index: u32, t_secs: f64) -> SimParams {
        let salt = rng::emitter_salt(emitter_index, e.seed_offset);
        let mut p = static_params(e, self.origin(), seed, salt, e.capacity.max(1));
        p.set_step(self.last_dt_secs as f32, t_secs, self.spawned_total, 0);
        p
    }

    /// The live window of the ring for drawing the last step: the last `len` spawns
    /// (slots `first_slot`, `first_slot + 1`, … modulo `capacity`) are the only ones that
    /// can hold a living particle — every earlier batch has outlived the longest lifetime
    /// it could have (the largest range maximum seen since its spawn, or `max_life_secs`
    /// now). Draws and the sort visit only this window instead of the whole pool.
    /// Conservative: a batch counts until its last-born particle is surely dead (margin
    /// for f32 ages), judged at the start of the last step, since frames are drawn
    /// between the last two steps (stateless emitters are evaluated there).
    pub fn live_window(&self, capacity: u32, max_life_secs: f32) -> LiveWindow {
        let capacity = u64::from(capacity.max(1));
        let at = self.clock_secs - self.last_dt_secs;
        let first = self
            .history
            .iter()
            .find(|b| !b.surely_dead(at, max_life_secs as f64, self.min_dt_secs))
            .map_or(self.spawned_total, |b| b.first_index);
        let first = first.max(self.spawned_total.saturating_sub(capacity));
        LiveWindow {
            first_slot: (first % capacity) as u32,
            len: (self.spawned_total - first) as u32,
        }
    }

    /// This emitter's simulated time (it stands still while the emitter is disabled).
    pub fn clock_secs(&self) -> f64 {
        self.clock_secs
    }

    /// The time on this emitter's clock by which every particle born so far is surely
    /// dead (with the margins of the live window, plus 0.1 s).
    pub fn all_dead_by(&self, max_life_secs: f32) -> f64 {
        self.history
            .iter()
            .map(|b| b.dead_by(max_life_secs as f64, self.min_dt_secs))
            .fold(self.clock_secs, f64::max)
            + 0.1
    }

    /// The spawn counter: how many particles this emitter has started.
    pub fn spawned_total(&self) -> u64 {
        self.spawned_total
    }
}

/// The simulation-space origin an emitter gets: its position, in f64.
pub fn sim_origin_for(e: &Emitter) -> glam::DVec3 {
    glam::Vec3::from(e.transform.position_m).as_dvec3()
}

/// The spawns a continuous `rate` asks for over `[t0, t0 + dt]` on the emitter's clock:
/// rate × dt for a constant; otherwise the rate's integral, its random number drawn once
/// per instance from (seed, emitter salt).
pub fn expected_spawns(rate: &Param, seed: u32, salt: u32, t0: f64, dt: f64) -> f64 {
    match rate {
        Param::Constant(r) => f64::from(r.max(0.0)) * dt,
        _ => rate
            .integral(instance_random(seed, salt), t0, t0 + dt)
            .max(0.0),
    }
}

/// An emitter's random number for its per-instance parameters (the spawn rate's range or
/// blend of two curves): fixed by the instance's seed.
pub fn instance_random(seed: u32, salt: u32) -> f64 {
    f64::from(rng::unorm(rng::pcg4d([seed, salt, 0x5A7E, 0])[0]))
}

#[cfg(test)]
mod tests;
