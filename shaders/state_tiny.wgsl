// state_tiny.wgsl — the update pass's state I/O for the `tiny_state` option: 10 bytes a
// slot (common.wgsl, "Tiny state"): f16 position, a shared-exponent velocity in 32 bits;
// the age from the birth table (births.wgsl), the lifetime from the spawn hash. Two
// adjacent slots share a word, so one invocation updates a pair: `begin_pair` reads its
// five words, `load_state` / `store_state` work on them, `end_pair` writes them. Rounding
// is dithered by a hash of (slot, step). Composed in place of state_full.wgsl (same
// bindings, plus 4 `births`). Plumbing, not a hook.
//
// Contract: group 0 binding 1 `src` (read), 2 `dst` (written), 4 `births`; needs `params`
// (SimParams: `tiny` = t0 hi, lo bits, table's first sequence number, entries; `tiny_b` =
// the oldest entry's first counter, the counters spanned; `flags` = the table's index
// mask).
#import "common.wgsl"
#import "rng.wgsl"
#import "births.wgsl"

@group(0) @binding(1) var<storage, read> src: array<PackedParticle>;
@group(0) @binding(2) var<storage, read_write> dst: array<PackedParticle>;
@group(0) @binding(4) var<storage, read> births: array<Birth>;

override MOD_PACKED: bool = false;
override MOD_TINY: bool = true;
// Invocations update adjacent pairs of slots (update.wgsl).
const PAIRED_STATE: bool = true;

var<private> pair: PackedParticle;
// The birth-table entry of the last lookup: the pair's odd slot usually shares the even
// slot's (consecutive spawn counters).
var<private> entry: Birth;

fn begin_pair(k: u32) {
    pair = src[k];
    entry.count = 0u;
}

fn end_pair(k: u32) {
    dst[k] = pair;
}

fn load_state(slot: u32) -> Particle {
    let s = tiny_decode(tiny_bits(pair, (slot & 1u) != 0u));
    if s.dead {
        return Particle(vec4<f32>(0.0), vec4<f32>(0.0));
    }
    // The ring before this step's spawns: `spawn_base` spawned, next slot `spawn_head`.
    let c = slot_counter(slot, params.spawn_head, params.spawn_base_lo, params.spawn_base_hi, params.capacity);
    if c.x - entry.first >= entry.count {
        entry = birth_entry(c.x, vec3<u32>(params.tiny.zw, params.flags), params.tiny_b.x, params.tiny_b.y);
    }
    let age = birth_age(entry, c.x, bitcast<vec2<f32>>(params.tiny.xy));
    // The lifetime (two hashes) only where it matters: a particle younger than the range's
    // minimum by more than this step survives it whatever its lifetime, and only the flame
    // pull and the over-life curves read the lifetime otherwise. Elsewhere "longer than
    // any age" stands in for it.
    // (The minimum with a margin: `mix` may round a lifetime an ulp below it.)
    var life = 3.4e38;
    if MOD_FLAME_PULL || MOD_CURVES || age + params.dt_secs >= params.speed_life.z * 0.9999 {
        let key = spawn_key(params.seed, params.emitter_salt, slot, c.x, c.y);
        life = spawn_life(key, params.speed_life.z, params.speed_life.w);
    }
    if !(age >= 0.0 && age < life) {
        return Particle(vec4<f32>(0.0), vec4<f32>(0.0));
    }
    return Particle(vec4<f32>(s.pos, age), vec4<f32>(s.vel, life));
}

fn store_state(slot: u32, p: Particle) {
    var b = vec3<u32>(TINY_DEAD, 0u, 0u);
    if is_alive(p) {
        // Six 10-bit dithers from two cheap hashes of (slot, step, seed): dithering needs
        // no more (pcg4d's four words would cost a third of the pass on the H100).
        let step_key = bitcast<u32>(params.wind_time.w) ^ params.spawn_base_lo;
        let h0 = lowbias32((slot * 0x9E3779B9u) ^ step_key ^ (params.seed * 0x85EBCA6Bu));
        let h1 = lowbias32(h0 ^ 0x7F4A7C15u);
        let m = vec3<u32>(0u, 10u, 20u);
        let d0 = vec4<f32>(vec3<f32>((vec3<u32>(h0) >> m) & vec3<u32>(1023u)) / 1024.0, 0.0);
        let d1 = vec4<f32>(vec3<f32>((vec3<u32>(h1) >> m) & vec3<u32>(1023u)) / 1024.0, 0.0);
        b = tiny_encode(p.pos_age.xyz, p.vel_life.xyz, d0, d1);
    }
    pair = tiny_put(pair, (slot & 1u) != 0u, b);
}
