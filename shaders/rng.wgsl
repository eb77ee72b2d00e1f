// rng.wgsl — counter-based randomness: a hash, never a per-frame uniform.
//
// Contract: every random number is a pure function of (seed, emitter, slot, spawn
// counter, draw index). `pcg4d` is Jarzynski & Olano's 2020 hash ("Hash Functions for
// GPU Rendering"); it is a bijection on 128 bits, so distinct spawns get distinct
// streams. Mirrored exactly in `src/rng.rs` (integer maths: bit-identical on the CPU).

fn pcg4d(v_in: vec4<u32>) -> vec4<u32> {
    var v = v_in * 1664525u + 1013904223u;
    v.x += v.y * v.w;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    v.w += v.y * v.z;
    v = v ^ (v >> vec4<u32>(16u));
    v.x += v.y * v.w;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    v.w += v.y * v.z;
    return v;
}

// The key of one spawn: (seed, emitter ^ slot mix, spawn counter lo, hi).
fn spawn_key(seed: u32, emitter_salt: u32, slot: u32, spawn_lo: u32, spawn_hi: u32) -> vec4<u32> {
    return pcg4d(vec4<u32>(seed, emitter_salt ^ (slot * 0x9E3779B9u), spawn_lo, spawn_hi));
}

// Block `block` of four random words of the stream `key`.
fn rand_block(key: vec4<u32>, block: u32) -> vec4<u32> {
    return pcg4d(key ^ vec4<u32>(block, 0x85EBCA6Bu * block, 0u, 0u));
}

// Top 24 bits to a float in [0, 1): exact, identical on CPU and GPU.
fn unorm4(x: vec4<u32>) -> vec4<f32> {
    return vec4<f32>(x >> vec4<u32>(8u)) * (1.0 / 16777216.0);
}

// The lifetime a spawn with stream `key` draws, in [lo, hi] (block 1, w). spawn.wgsl uses
// it, and the packed state re-derives lifetimes with it instead of storing them.
fn spawn_life(key: vec4<u32>, lo: f32, hi: f32) -> f32 {
    return mix(lo, hi, unorm4(rand_block(key, 1u)).w);
}

// Wellons' "lowbias32" avalanche of one word (two multiplies, three xor-shifts).
fn lowbias32(x: u32) -> u32 {
    var h = x;
    h ^= h >> 16u;
    h *= 0x7FEB352Du;
    h ^= h >> 15u;
    h *= 0x846CA68Bu;
    h ^= h >> 16u;
    return h;
}

// A lattice hash for noise: integer cell + seed → [0, 1). Noise evaluates eight of these
// per channel and octave (curl noise: 48 per particle-step), so it is a cheap one: the
// cell folded into one word by large odd multipliers, then Wellons' "lowbias32"
// avalanche (two multiplies, three xor-shifts) — a third of pcg4d's work.
fn hash_cell(c: vec3<i32>, seed: u32) -> f32 {
    return f32(hash_cell_word(c, seed) >> 8u) * (1.0 / 16777216.0);
}

// `hash_cell`'s word: the cell and seed folded by large odd multipliers, then avalanched.
fn hash_cell_word(c: vec3<i32>, seed: u32) -> u32 {
    let u = bitcast<vec3<u32>>(c);
    return lowbias32((u.x * 0x8DA6B343u) ^ (u.y * 0xD8163841u) ^ (u.z * 0xCB1AB31Fu) ^ (seed * 0x9E3779B9u));
}
