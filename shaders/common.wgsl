// common.wgsl — data shared by every ignis shader.
//
// Contract: `Particle` and `SimParams` mirror `src/gpu/types.rs` byte for byte
// (keep in sync with `Particle` and `SimParams` there; a test compares naga's layout
// with `size_of`). A slot is alive while `pos_age.w < vel_life.w`; a slot that was never
// spawned has age = lifetime = 0 and is therefore dead.

struct Particle {
    // xyz: world position (m), w: age (s).
    pos_age: vec4<f32>,
    // xyz: velocity (m/s), w: this particle's lifetime (s).
    vel_life: vec4<f32>,
}

struct SimParams {
    world_from_emitter: mat4x4<f32>,
    // Shape parameters; meaning depends on `shape_kind` (see spawn.wgsl).
    shape_a: vec4<f32>,
    shape_b: vec4<f32>,
    // xyz: initial direction (emitter space, unit), w: spread half-angle (rad).
    direction_spread: vec4<f32>,
    // speed min, speed max, lifetime min, lifetime max.
    speed_life: vec4<f32>,
    // xyz: constant acceleration (gravity + buoyancy), w: linear drag k (1/s).
    accel_drag: vec4<f32>,
    // xyz: wind (drag target velocity), w: simulated time (s, wrapped) for noise.
    wind_time: vec4<f32>,
    // frequency (1/m), position amplitude (m), direction amplitude, scroll (1/s).
    noise: vec4<f32>,
    dt_secs: f32,
    seed: u32,
    emitter_salt: u32,
    shape_kind: u32,
    capacity: u32,
    spawn_head: u32,
    spawn_count: u32,
    spawn_base_lo: u32,
    spawn_base_hi: u32,
    // Tiny state: the birth table's index mask (its size − 1).
    flags: u32,
    // Birth time of the k-th spawn within the step, as a fraction of the step:
    // spawn_frac0 + k * spawn_frac_step (sub-step emission: no puffs at low frame rates).
    spawn_frac0: f32,
    spawn_frac_step: f32,
    // Optional force modules (each compiled in only when on; see forces.wgsl).
    // strength (m/s²), frequency (1/m), octaves, scroll (m/s).
    turbulence: vec4<f32>,
    // gust strength (fraction of wind), gust frequency (Hz), quadratic drag (1/m),
    // flame pull strength (1/s²).
    gusts_qdrag_pull: vec4<f32>,
    // xyz: vortex centre (m), w: falloff radius (m).
    vortex_center: vec4<f32>,
    // xyz: unit vortex axis, w: swirl acceleration (m/s²) at the axis.
    vortex_axis: vec4<f32>,
    // xyz: attractor position (m), w: strength (m/s², negative repels).
    attractor: vec4<f32>,
    // x: attractor radius (m), y: falloff (0 softened inverse square, 1 constant within
    // radius), z: flame pull exponent, w: unused.
    attractor_b: vec4<f32>,
    // xyz: emitter origin (world), the flame pull's axis passes through it.
    axis_origin: vec4<f32>,
    // xyz: emitter direction (world, unit).
    axis_dir: vec4<f32>,
    // Ground plane: height (m), elasticity, friction, kill on contact (0/1).
    ground: vec4<f32>,
    // rest speed (m/s), sphere count, kill on contact with spheres (0/1), ground on (0/1).
    collide_b: vec4<f32>,
    // Sphere colliders: xyz centre (m), w radius (m).
    spheres: array<vec4<f32>, 4>,
    // x: stick on contact (0/1): the particle stops where it touches, y: depth
    // collision's surface thickness (m), z: kill on depth contact (0/1), w: unused.
    collide_c: vec4<f32>,
    // x: first slot this step updates, y: how many (wrapping at the capacity): the ring's
    // live window plus this step's spawns; every other slot is dead in both buffers.
    update_window: vec4<u32>,
    // Tiny state: x, y: the step's start on the emitter's clock (double-single hi, lo, as
    // f32 bits), z: the birth table's first sequence number, w: its entries (`flags` holds
    // the table's index mask).
    tiny: vec4<u32>,
    // Tiny state: x: the birth table's oldest entry's first spawn counter (low 32 bits),
    // y: the counters from it to the newest spawn, z: the step's number (the event
    // scan's stamp), w: unused.
    tiny_b: vec4<u32>,
}

const SHAPE_POINT: u32 = 0u;
const SHAPE_SPHERE: u32 = 1u;
const SHAPE_DISC: u32 = 2u;
const SHAPE_BOX: u32 = 3u;
const SHAPE_CONE: u32 = 4u;
const SHAPE_LINE: u32 = 5u;

const PI: f32 = 3.14159265358979;
const TAU: f32 = 6.28318530717959;

// Packed state (20 bytes, the `packed_state` option): the position as three f32; the
// velocity as three f16; the remaining life fraction 1 − age/lifetime as unorm16 (zero is
// dead, so a zeroed buffer is all dead). The lifetime is not stored: it is a pure
// function of (seed, emitter, slot, spawn counter) — see `slot_counter` and `spawn_life`.
// Keep in sync with `PackedParticle` in src/gpu/types.rs.
struct PackedParticle {
    // f32 position bits (u32 words, so that the same buffer seen as a tiny-state pair —
    // five words — reads back every bit, NaN patterns included).
    px: u32,
    py: u32,
    pz: u32,
    // f16 velocity x (low half) and y (high half).
    vxy: u32,
    // f16 velocity z (low half), unorm16 remaining life fraction (high half).
    vz_rest: u32,
}

fn packed_alive(q: PackedParticle) -> bool {
    return (q.vz_rest >> 16u) != 0u;
}

// One f16 step (ulp) at x, for dithering before rounding to f16: x + (d − ½)·ulp rounded
// to nearest rounds up with probability equal to x's fraction of a step.
fn f16_ulp(x: f32) -> f32 {
    let e = i32((bitcast<u32>(x) >> 23u) & 0xFFu) - 127;
    return exp2(f32(max(e, -14) - 10));
}

// Packs with dithered rounding (`dither` ∈ [0, 1)⁴, a hash of the slot and step): the
// rounding errors of successive steps average out instead of drifting one way.
fn pack_particle(p: Particle, dither: vec4<f32>) -> PackedParticle {
    var rest = 0.0;
    if p.pos_age.w < p.vel_life.w {
        rest = clamp(1.0 - p.pos_age.w / p.vel_life.w, 0.0, 1.0);
    }
    // An alive particle never rounds to dead.
    var r = min(u32(rest * 65535.0 + dither.w), 65535u);
    if rest > 0.0 {
        r = max(r, 1u);
    }
    let v = p.vel_life.xyz;
    let vd = v + (dither.xyz - 0.5) * vec3<f32>(f16_ulp(v.x), f16_ulp(v.y), f16_ulp(v.z));
    let vz = pack2x16float(vec2<f32>(vd.z, 0.0)) & 0xFFFFu;
    let x = bitcast<vec3<u32>>(p.pos_age.xyz);
    return PackedParticle(x.x, x.y, x.z, pack2x16float(vd.xy), vz | (r << 16u));
}

// `life` is the particle's lifetime (re-derived by the caller).
fn unpack_particle(q: PackedParticle, life: f32) -> Particle {
    let r = f32(q.vz_rest >> 16u) / 65535.0;
    let vxy = unpack2x16float(q.vxy);
    let vz = unpack2x16float(q.vz_rest & 0xFFFFu).x;
    if r <= 0.0 {
        return Particle(vec4<f32>(0.0), vec4<f32>(0.0));
    }
    let x = bitcast<vec3<f32>>(vec3<u32>(q.px, q.py, q.pz));
    return Particle(vec4<f32>(x, (1.0 - r) * life), vec4<f32>(vxy, vz, life));
}

// Tiny state (10 bytes, the `tiny_state` option): slots 2k and 2k + 1 share the five
// words of element k of the buffer seen as `PackedParticle`s (w0…w4, one 20-byte pair).
// A slot is three fields: `xy` = f16 x | f16 y << 16, `z` = f16 z (16 bits) and `vel`
// (32 bits). Even slot: w0 = xy, w1 = z | vel << 16, low half of w2 = vel >> 16. Odd
// slot: high half of w2 = x, w3 = y | z << 16, w4 = vel. The position is f16 in the
// emitter's simulation space (relative to its origin); the velocity a shared exponent
// (bits 0…4, bias 15) and three 9-bit mantissas offset by 256 (x bits 5…13, y 14…22,
// z 23…31): v = (m − 256) · 2^(e − 23). Neither the age nor the lifetime is stored: the
// age comes from the emitter's birth table (births.wgsl) and the lifetime from the spawn
// hash. x = 0xFFFF (an f16 NaN) marks a dead slot. Keep in sync with `tiny` in
// src/gpu/types.rs.
const TINY_DEAD: u32 = 0xFFFFu;

struct TinySlot {
    pos: vec3<f32>,
    vel: vec3<f32>,
    dead: bool,
}

// The three fields (xy, z, vel) of one slot of pair `q`.
fn tiny_bits(q: PackedParticle, odd: bool) -> vec3<u32> {
    if odd {
        return vec3<u32>((q.pz >> 16u) | (q.vxy << 16u), q.vxy >> 16u, q.vz_rest);
    }
    return vec3<u32>(q.px, q.py & 0xFFFFu, (q.py >> 16u) | (q.pz << 16u));
}

// Pair `q` with one slot's fields replaced.
fn tiny_put(q: PackedParticle, odd: bool, b: vec3<u32>) -> PackedParticle {
    var r = q;
    if odd {
        r.pz = (r.pz & 0xFFFFu) | (b.x << 16u);
        r.vxy = (b.x >> 16u) | (b.y << 16u);
        r.vz_rest = b.z;
    } else {
        r.px = b.x;
        r.py = (b.y & 0xFFFFu) | (b.z << 16u);
        r.pz = (r.pz & 0xFFFF0000u) | (b.z >> 16u);
    }
    return r;
}

fn tiny_decode(b: vec3<u32>) -> TinySlot {
    if (b.x & 0xFFFFu) == TINY_DEAD {
        return TinySlot(vec3<f32>(0.0), vec3<f32>(0.0), true);
    }
    let pos = vec3<f32>(unpack2x16float(b.x), unpack2x16float(b.y).x);
    let scale = exp2(f32(i32(b.z & 31u) - 23));
    let m = vec3<u32>((b.z >> 5u) & 511u, (b.z >> 14u) & 511u, b.z >> 23u);
    return TinySlot(pos, (vec3<f32>(m) - 256.0) * scale, false);
}

// Encodes a living particle's position and velocity with dithered rounding (`d0`, `d1`
// ∈ [0, 1)⁴, hashes of slot and step: unbiased, so errors average out instead of
// drifting). Positions beyond ±65000 m (the f16 range, 65504, less the dither's reach) and
// speeds of 2^16 m/s or more cannot be stored: the slot is marked dead.
fn tiny_encode(pos: vec3<f32>, vel: vec3<f32>, d0: vec4<f32>, d1: vec4<f32>) -> vec3<u32> {
    let m = max(max(abs(vel.x), abs(vel.y)), abs(vel.z));
    if !(max(max(abs(pos.x), abs(pos.y)), abs(pos.z)) < 65000.0) || !(m < 65536.0) {
        return vec3<u32>(TINY_DEAD, 0u, 0u);
    }
    let pd = pos + (d0.xyz - 0.5) * vec3<f32>(f16_ulp(pos.x), f16_ulp(pos.y), f16_ulp(pos.z));
    // The smallest e with m < 2^e, within [−15, 16]: mantissas |v| / 2^(e − 8) < 256.
    let e = clamp(i32((bitcast<u32>(m) >> 23u) & 0xFFu) - 126, -15, 16);
    let q = clamp(floor(vel * exp2(f32(8 - e)) + d1.xyz), vec3<f32>(-255.0), vec3<f32>(255.0));
    let u = vec3<u32>(vec3<i32>(q) + 256);
    let v = u32(e + 15) | (u.x << 5u) | (u.y << 14u) | (u.z << 23u);
    return vec3<u32>(pack2x16float(pd.xy), pack2x16float(vec2<f32>(pd.z, 0.0)) & 0xFFFFu, v);
}

// One step's births in a tiny-state emitter's birth table (keep in sync with `Birth` in
// src/gpu/types.rs): `count` spawns from counter `first` (low 32 bits), the k-th born at
// t0 + dt · clamp(frac0 + k · frac_step, 0, 1) on the emitter's clock, t0 held as a
// double-single (hi + lo) so ages stay exact in runs of any length.
struct Birth {
    first: u32,
    count: u32,
    t0_hi: f32,
    t0_lo: f32,
    dt: f32,
    frac0: f32,
    frac_step: f32,
    pad: u32,
}

// The spawn counter (lo, hi) of the particle now in `slot` of a ring of `capacity` slots
// that has spawned `total` particles, the last into slot `head` − 1 (head = total mod
// capacity): slots are filled in counter order, so it is total − 1 − ((head − 1 − slot)
// mod capacity). Only meaningful for slots that were ever spawned.
fn slot_counter(slot: u32, head: u32, total_lo: u32, total_hi: u32, capacity: u32) -> vec2<u32> {
    // (head − 1 − slot) mod capacity without an integer division (both are < capacity).
    var back = head + capacity - 1u - slot;
    if back >= capacity {
        back -= capacity;
    }
    back += 1u;
    let lo = total_lo - back;
    let hi = total_hi - select(0u, 1u, total_lo < back);
    return vec2<u32>(lo, hi);
}

fn is_alive(p: Particle) -> bool {
    return p.pos_age.w < p.vel_life.w;
}

// True when x is neither NaN nor ±Inf (bit test, so no compiler may fold it away).
fn finite_f32(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7f800000u) != 0x7f800000u;
}

fn finite_vec3(v: vec3<f32>) -> bool {
    return finite_f32(v.x) && finite_f32(v.y) && finite_f32(v.z);
}

// phi = (1 - e^{-z})/k · … and psi = (dt - phi)/k, with series below z = 0.5 so that
// neither loses digits to cancellation (truncation < 1e-7 relative).
fn exp_phi_psi(k: f32, dt: f32) -> vec2<f32> {
    let z = k * dt;
    if z < 0.5 {
        let phi = dt * (1.0 + z * (-1.0 / 2.0 + z * (1.0 / 6.0 + z * (-1.0 / 24.0 + z * (1.0 / 120.0
            + z * (-1.0 / 720.0 + z * (1.0 / 5040.0 - z / 40320.0)))))));
        let psi = dt * dt * (1.0 / 2.0 + z * (-1.0 / 6.0 + z * (1.0 / 24.0 + z * (-1.0 / 120.0
            + z * (1.0 / 720.0 + z * (-1.0 / 5040.0 + z * (1.0 / 40320.0 - z / 362880.0)))))));
        return vec2<f32>(phi, psi);
    }
    let phi = (1.0 - exp(-z)) / k;
    return vec2<f32>(phi, (dt - phi) / k);
}
