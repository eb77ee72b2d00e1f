// update.wgsl — pass 1: one invocation per two slots of the live window, reads state A,
// writes state B.
//
// Contract (plumbing; designers change spawn.wgsl, forces.wgsl, integrators.wgsl):
// - group 0: binding 0 `params` (SimParams, dynamic offset per step), 1 `src` (read),
//   2 `dst` (write; both declared in state_full.wgsl / state_packed.wgsl /
//   state_tiny.wgsl), 3 `counters` ([0] alive after this step when COUNT_ALIVE is on,
//   [1] non-finite kills, total), 4 the tiny state's birth table (read by
//   state_tiny.wgsl only), 5 `sim_curves`: the emitter's over-life multipliers baked
//   (curves.wgsl; row A then row B, texels of (speed, drag, turbulence, flame pull)),
//   read only when MOD_CURVES is on.
// - MOD_CURVES: each alive particle's multipliers are looked up once per step, at its
//   age at the step's start, into `over_life` (forces.wgsl reads y, z, w; the step's
//   displacement is scaled by x). Off, they are 1 and nothing is read.
// - COUNT_ALIVE (GPUs): a workgroup reduction, one global atomic per workgroup. On CPU
//   adapters it is off — a workgroup barrier makes lavapipe run every invocation
//   separately — and count.wgsl counts on demand instead. (On the H100 the update with the
//   reduction measured 0.417 ms at 16.8M particles, without it 0.468 ms: kept.)
// - One invocation per slot of `update_window` (the planner's live window of the ring as
//   of the previous step's start, plus this step's spawns): slots in the spawn window
//   [spawn_head, spawn_head + spawn_count) (mod capacity) are born; alive slots integrate
//   and age; every visited slot is written. A slot outside the window was dead at the
//   start of the previous step, so it is dead (and identical) in A and B: B never holds
//   stale live data from two steps ago.
// - The dispatch is 2-D (x ≤ 65535 groups) so pools beyond 16M slots fit.
// - Tiny state (state_tiny.wgsl, PAIRED_STATE): one invocation per pair of adjacent slots
//   of the window, since the two share a word.
#import "common.wgsl"

// `params` (binding 0): a uniform on GPUs, read-only storage on CPU adapters.
#import "params.wgsl"
@group(0) @binding(3) var<storage, read_write> counters: array<atomic<u32>, 2>;
@group(0) @binding(5) var<storage, read> sim_curves: array<vec4<f32>>;

// The state's bindings (1 `src`, 2 `dst`) and `load_state` / `store_state`: full 32-byte
// particles, or — for packed_state / tiny_state pipelines — state_packed.wgsl /
// state_tiny.wgsl composed in its place.
#import "state_full.wgsl"
#import "spawn.wgsl"
#import "integrators.wgsl"
#import "collide.wgsl"
// Depth collision: depth_off.wgsl (nothing) unless the emitter collides with the host's
// depth buffer (depth_on.wgsl, group 2).
#import "depth_off.wgsl"
#import "alive_count.wgsl"
#import "curves.wgsl"
// The event hooks: events_off.wgsl (no code, no bindings) unless the emitter has events or
// spawns from them, whose pipelines compose events_on.wgsl in its place.
#import "events_off.wgsl"
// The trail hook: trail_off.wgsl (nothing) unless the emitter has a trail (trail_on.wgsl).
#import "trail_off.wgsl"

// Stateless mode: this pass only writes the spawn records of this step's window (one
// invocation per spawn, no other slot is touched); the draw passes evaluate positions in
// closed form (look.wgsl). The record keeps the spawn position and velocity, and in
// pos_age.w the birth time on the 4096 s clock.
override MOD_STATELESS: bool = false;
override COUNT_ALIVE: bool = true;
override MOD_CURVES: bool = false;
override MOD_DEPTH_COLLISION: bool = false;

// This particle's multipliers for the step: x displacement (speed), y drag (linear and
// quadratic), z turbulence, w flame pull. All 1 unless MOD_CURVES.
var<private> over_life: vec4<f32> = vec4<f32>(1.0);

// The multipliers at normalised age t for the particle's random numbers u.
fn over_life_at(t: f32, u: vec4<f32>) -> vec4<f32> {
    let c = curve_texels(t);
    let a = mix(sim_curves[c.i], sim_curves[c.j], c.f);
    let b = mix(sim_curves[CURVE_WIDTH + c.i], sim_curves[CURVE_WIDTH + c.j], c.f);
    return mix(a, b, u);
}

// The random numbers blending a particle's over-life curves: fixed for its life (its
// slot and lifetime bits, like the look's), one per multiplier.
fn over_life_random(slot: u32, life: f32) -> vec4<f32> {
    return unorm4(pcg4d(vec4<u32>(slot, bitcast<u32>(life), params.emitter_salt, params.seed ^ 0x5C0u)));
}

fn stateless_spawn(i: u32) {
    if i >= params.spawn_count {
        return;
    }
    let slot = (params.spawn_head + i) % params.capacity;
    let lo = params.spawn_base_lo + i;
    let hi = params.spawn_base_hi + select(0u, 1u, lo < i);
    var p = spawn_particle(slot, spawn_key(params.seed, params.emitter_salt, slot, lo, hi));
    let f = clamp(params.spawn_frac0 + f32(i) * params.spawn_frac_step, 0.0, 1.0);
    p.pos_age.w = (params.wind_time.w + f * params.dt_secs) % 4096.0;
    store_state(slot, p);
}

// Slots per invocation (keep in sync with `SLOTS_PER_INVOCATION` in src/sim/gpu_sim.rs):
// a workgroup covers 2 × 256 consecutive slots, each round coalesced — twice the bytes in
// flight per invocation of a memory-bound pass.
const SLOTS_PER_INVOCATION: u32 = 2u;

@compute @workgroup_size(256)
fn main(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    select_instance(wg.z);
    let base = (wg.y * nwg.x + wg.x) * 256u * SLOTS_PER_INVOCATION + lid;
    if MOD_STATELESS {
        for (var r = 0u; r < SLOTS_PER_INVOCATION; r++) {
            stateless_spawn(base + r * 256u);
        }
        return;
    }
    var alive = 0u;
    if PAIRED_STATE {
        // Tiny state: one invocation per pair of adjacent slots (they share a word), over
        // the pairs the window touches (a few more is harmless: slots outside the window
        // are left as they are, dead in both buffers).
        let j = (wg.y * nwg.x + wg.x) * 256u + lid;
        let pairs = (params.capacity + 1u) / 2u;
        let w = params.update_window;
        if j < min(pairs, w.y / 2u + 2u) {
            var k = w.x / 2u + j;
            if k >= pairs {
                k -= pairs;
            }
            begin_pair(k);
            var touched = false;
            for (var r = 0u; r < 2u; r++) {
                let slot = 2u * k + r;
                var rel = slot + params.capacity - w.x;
                if rel >= params.capacity {
                    rel -= params.capacity;
                }
                if slot < params.capacity && rel < w.y {
                    touched = true;
                    if update_at(slot) {
                        alive += 1u;
                    }
                }
            }
            if touched {
                end_pair(k);
            }
        }
    } else {
        for (var r = 0u; r < SLOTS_PER_INVOCATION; r++) {
            if update_slot(base + r * 256u) {
                alive += 1u;
            }
        }
    }
    if COUNT_ALIVE {
        add_alive_in_workgroup(alive, lid);
    }
}

// Updates the i-th slot of this step's window of the ring; true when it is alive after.
fn update_slot(i: u32) -> bool {
    if i >= params.update_window.y {
        return false;
    }
    // The i-th slot of this step's window of the ring.
    var slot = params.update_window.x + i;
    if slot >= params.capacity {
        slot -= params.capacity;
    }
    return update_at(slot);
}

// Spawns or steps the particle in `slot` and stores it; true when it is alive after.
fn update_at(slot: u32) -> bool {
    var alive = false;
    var p = load_state(slot);
    over_life = vec4<f32>(1.0);
    // Position of this slot in the ring relative to the spawn head (capacity ≤ 2^28; both
    // are below it, so no integer division).
    var rel = slot + params.capacity - params.spawn_head;
    if rel >= params.capacity {
        rel -= params.capacity;
    }
    let was_alive = is_alive(p);
    let age_start = p.pos_age.w;
    var born = false;
    var hit = false;
    var finite = true;
    // module-begin
    let from_event = event_birth(slot);
    if from_event.born {
        // A child of another emitter's event, born at the event's place this step.
        p = from_event.p;
        born = true;
        alive = is_alive(p);
    } else
    // module-end
    if rel < params.spawn_count {
        born = true;
        // 64-bit spawn counter = base + rel.
        let lo = params.spawn_base_lo + rel;
        let hi = params.spawn_base_hi + select(0u, 1u, lo < rel);
        p = spawn_particle(slot, spawn_key(params.seed, params.emitter_salt, slot, lo, hi));
        // Sub-step emission: a particle born at fraction f of the step is (1 - f)·dt old
        // at its end, moved over that partial step in closed form under the constant
        // acceleration and linear drag (cheap, and exact where stateless mode applies;
        // the other modules act from its first full step).
        let f = clamp(params.spawn_frac0 + f32(rel) * params.spawn_frac_step, 0.0, 1.0);
        let age0 = (1.0 - f) * params.dt_secs;
        if MOD_CURVES {
            over_life = over_life_at(0.0, over_life_random(slot, p.vel_life.w));
        }
        let k = linear_drag_k();
        let pp = exp_phi_psi(k, age0);
        let c = params.accel_drag.xyz + k * params.wind_time.xyz;
        let v0 = p.vel_life.xyz;
        var x = p.pos_age.xyz + v0 * pp.x + c * pp.y;
        if MOD_CURVES {
            x = p.pos_age.xyz + (v0 * pp.x + c * pp.y) * over_life.x;
        }
        p = Particle(
            vec4<f32>(x, age0),
            vec4<f32>(v0 * (1.0 - k * pp.x) + c * pp.x, p.vel_life.w),
        );
        alive = is_alive(p);
    } else if is_alive(p) {
        let life = p.vel_life.w;
        if MOD_CURVES {
            over_life = over_life_at(p.pos_age.w / life, over_life_random(slot, life));
        }
        var s = integrate(p.pos_age.xyz, p.vel_life.xyz, p.pos_age.w, life, params.wind_time.w, params.dt_secs);
        if MOD_CURVES {
            s.pos = p.pos_age.xyz + (s.pos - p.pos_age.xyz) * over_life.x;
        }
        var age = p.pos_age.w + params.dt_secs;
        // module-begin
        if MOD_COLLISIONS {
            let c = collide(p.pos_age.xyz, s.pos, s.vel);
            s = State(c.pos, c.vel);
            hit = c.hit;
            if c.killed {
                // Killed on contact: dead, and its age says so.
                age = life;
            }
        }
        if MOD_DEPTH_COLLISION && age < life {
            let c = depth_collide(p.pos_age.xyz, s.pos, s.vel);
            s = State(c.pos, c.vel);
            hit = hit || c.hit;
            if c.killed {
                age = life;
            }
        }
        // module-end
        if finite_vec3(s.pos) && finite_vec3(s.vel) {
            p = Particle(vec4<f32>(s.pos, age), vec4<f32>(s.vel, life));
            alive = age < life;
        } else {
            // Non-finite guard: kill and count, never let NaN reach the draw.
            p = Particle(vec4<f32>(0.0), vec4<f32>(0.0));
            atomicAdd(&counters[1], 1u);
            finite = false;
        }
    }
    // module-begin
    emit_events(slot, p, born, was_alive && finite, alive, hit, age_start);
    record_trail(slot, p, born, alive);
    // module-end
    store_state(slot, p);
    return alive;
}
