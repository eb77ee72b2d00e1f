//! Counter-based randomness, bit-identical to `shaders/rng.wgsl`.
//!
//! Every random number is a pure function of (seed, emitter, slot, spawn counter, draw
//! index) — no per-frame uniform shared by every particle (the 2006 thesis's artifact)
//! and no noise texture filled on the CPU.

/// Jarzynski & Olano's `pcg4d` (2020): a bijective 128-bit hash.
pub fn pcg4d(v: [u32; 4]) -> [u32; 4] {
    let mut v = v.map(|x| x.wrapping_mul(1_664_525).wrapping_add(1_013_904_223));
    mix(&mut v);
    v = v.map(|x| x ^ (x >> 16));
    mix(&mut v);
    v
}

fn mix(v: &mut [u32; 4]) {
    v[0] = v[0].wrapping_add(v[1].wrapping_mul(v[3]));
    v[1] = v[1].wrapping_add(v[2].wrapping_mul(v[0]));
    v[2] = v[2].wrapping_add(v[0].wrapping_mul(v[1]));
    v[3] = v[3].wrapping_add(v[1].wrapping_mul(v[2]));
}

/// The random stream key of one spawn (see `spawn_key` in `shaders/rng.wgsl`).
pub fn spawn_key(seed: u32, emitter_salt: u32, slot: u32, spawn_index: u64) -> [u32; 4] {
    pcg4d([
        seed,
        emitter_salt ^ slot.wrapping_mul(0x9E37_79B9),
        spawn_index as u32,
        (spawn_index >> 32) as u32,
    ])
}

/// Block `block` of four random words of the stream `key`.
pub fn rand_block(key: [u32; 4], block: u32) -> [u32; 4] {
    pcg4d([
        key[0] ^ block,
        key[1] ^ 0x85EB_CA6B_u32.wrapping_mul(block),
        key[2],
        key[3],
    ])
}

/// The top 24 bits as a float in [0, 1) (exact; identical on the GPU).
pub fn unorm(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// Four floats in [0, 1).
pub fn unorm4(x: [u32; 4]) -> [f32; 4] {
    x.map(unorm)
}

/// The per-emitter salt mixed into every key.
pub fn emitter_salt(emitter_index: u32, seed_offset: u32) -> u32 {
    pcg4d([emitter_index, seed_offset, 0x1DE5_F1E5, 0])[0]
}

/// The lattice hash's word (see `hash_cell` in `shaders/rng.wgsl`): the cell folded by
/// large odd multipliers, then Wellons' "lowbias32" avalanche.
fn hash_cell_word(c: [i32; 3], seed: u32) -> u32 {
    let mut h = (c[0] as u32).wrapping_mul(0x8DA6_B343)
        ^ (c[1] as u32).wrapping_mul(0xD816_3841)
        ^ (c[2] as u32).wrapping_mul(0xCB1A_B31F)
        ^ seed.wrapping_mul(0x9E37_79B9);
    h ^= h >> 16;
    h = h.wrapping_mul(0x7FEB_352D);
    h ^= h >> 15;
    h = h.wrapping_mul(0x846C_A68B);
    h ^= h >> 16;
    h
}

/// A lattice hash for value noise (see `hash_cell` in `shaders/rng.wgsl`).
pub fn hash_cell(c: [i32; 3], seed: u32) -> f32 {
    unorm(hash_cell_word(c, seed))
}

/// Three lattice values in [0, 1) from one hash, ten bits each (multiples of 1/1024): the
/// vector potential of curl noise (see `hash_cell3` in `shaders/noise.wgsl`).
pub fn hash_cell3(c: [i32; 3], seed: u32) -> [f32; 3] {
    let h = hash_cell_word(c, seed);
    [22, 12, 2].map(|shift| ((h >> shift) & 0x3FF) as f32 / 1024.0)
}
