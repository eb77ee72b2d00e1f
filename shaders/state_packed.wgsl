// state_packed.wgsl — the update pass's state I/O for the `packed_state` option: 20-byte
// `PackedParticle`s (common.wgsl): f32 position, f16 velocity, the remaining life
// fraction as unorm16. The lifetime is re-derived from the spawn hash of the slot's spawn
// counter; rounding is dithered by a hash of (slot, step) so errors average out instead
// of drifting. Composed in place of state_full.wgsl (same bindings). Plumbing, not a hook.
//
// Contract: group 0 binding 1 `src` (read), 2 `dst` (written); needs `params` (SimParams)
// and rng.wgsl (imported here).
#import "common.wgsl"
#import "rng.wgsl"

@group(0) @binding(1) var<storage, read> src: array<PackedParticle>;
@group(0) @binding(2) var<storage, read_write> dst: array<PackedParticle>;

override MOD_PACKED: bool = true;
override MOD_TINY: bool = false;
// One slot per store (state_tiny.wgsl pairs them): the pair hooks do nothing.
const PAIRED_STATE: bool = false;

fn begin_pair(k: u32) {}

fn end_pair(k: u32) {}

fn load_state(slot: u32) -> Particle {
    let q = src[slot_base + slot];
    if !packed_alive(q) {
        return Particle(vec4<f32>(0.0), vec4<f32>(0.0));
    }
    // The ring before this step's spawns: `spawn_base` spawned, next slot `spawn_head`.
    let c = slot_counter(slot, params.spawn_head, params.spawn_base_lo, params.spawn_base_hi, params.capacity);
    let key = spawn_key(params.seed, params.emitter_salt, slot, c.x, c.y);
    return unpack_particle(q, spawn_life(key, params.speed_life.z, params.speed_life.w));
}

fn store_state(slot: u32, p: Particle) {
    // Keyed by slot and step (the simulated time changes every step; the spawn counter
    // need not).
    let step_key = bitcast<u32>(params.wind_time.w) ^ params.spawn_base_lo;
    let dither = unorm4(pcg4d(vec4<u32>(slot, step_key, params.seed, 0xD1u)));
    dst[slot_base + slot] = pack_particle(p, dither);
}
