// noise.wgsl — smooth value noise, seeded: spawn flicker, gusts, and curl-noise turbulence.
//
// Contract: `value_noise3(p, seed)` returns a value in [0, 1] that varies smoothly with p
// (quintic fade); mirrored in `src/sim/cpu_reference.rs`.
#import "rng.wgsl"

fn fade3(t: vec3<f32>) -> vec3<f32> {
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
}

fn value_noise3(p: vec3<f32>, seed: u32) -> f32 {
    let cell = floor(p);
    let f = p - cell;
    let c = vec3<i32>(cell);
    let u = fade3(f);
    let a = hash_cell(c + vec3<i32>(0, 0, 0), seed);
    let b = hash_cell(c + vec3<i32>(1, 0, 0), seed);
    let cc = hash_cell(c + vec3<i32>(0, 1, 0), seed);
    let d = hash_cell(c + vec3<i32>(1, 1, 0), seed);
    let e = hash_cell(c + vec3<i32>(0, 0, 1), seed);
    let ff = hash_cell(c + vec3<i32>(1, 0, 1), seed);
    let g = hash_cell(c + vec3<i32>(0, 1, 1), seed);
    let h = hash_cell(c + vec3<i32>(1, 1, 1), seed);
    // The trilinear form (as `curl_octave`'s, one channel).
    let k4 = a - b - cc + d;
    let k5 = a - cc - e + g;
    let k6 = a - b - e + ff;
    let k7 = -a + b + cc - d + e - ff - g + h;
    return a + (b - a) * u.x + (cc - a) * u.y + (e - a) * u.z + k4 * u.x * u.y + k5 * u.y * u.z
        + k6 * u.z * u.x + k7 * u.x * u.y * u.z;
}

// Three decorrelated noise channels centred on zero, in [-1, 1].
fn value_noise3_vec(p: vec3<f32>, seed: u32) -> vec3<f32> {
    return vec3<f32>(
        value_noise3(p, seed),
        value_noise3(p + vec3<f32>(31.416, 47.853, 12.793), seed),
        value_noise3(p + vec3<f32>(-17.231, 5.117, 63.941), seed),
    ) * 2.0 - 1.0;
}

fn fade3_deriv(t: vec3<f32>) -> vec3<f32> {
    return 30.0 * t * t * (t * (t - 2.0) + 1.0);
}

// Three lattice values in [0, 1) for the three channels of a vector potential: ten bits
// each of `hash_cell_word`, set as the mantissa of a float in [1, 2) — exact multiples of
// 1/1024, no integer-to-float conversion.
fn hash_cell3(c: vec3<i32>, seed: u32) -> vec3<f32> {
    let h = hash_cell_word(c, seed);
    let m = ((vec3<u32>(h) >> vec3<u32>(22u, 12u, 2u)) & vec3<u32>(0x3FFu)) << vec3<u32>(13u);
    return bitcast<vec3<f32>>(m | vec3<u32>(0x3F800000u)) - 1.0;
}

// One octave of curl noise: the curl of a vector potential ψ whose three channels are
// value noise on one lattice (one hash per corner for all three), so the fade weights and
// their derivatives are shared. Trilinear form with quintic fade, as `value_noise3`.
fn curl_octave(p: vec3<f32>, seed: u32) -> vec3<f32> {
    let cell = floor(p);
    let f = p - cell;
    let c = vec3<i32>(cell);
    let u = fade3(f);
    let du = fade3_deriv(f);
    let a = hash_cell3(c + vec3<i32>(0, 0, 0), seed);
    let b = hash_cell3(c + vec3<i32>(1, 0, 0), seed);
    let cc = hash_cell3(c + vec3<i32>(0, 1, 0), seed);
    let d = hash_cell3(c + vec3<i32>(1, 1, 0), seed);
    let e = hash_cell3(c + vec3<i32>(0, 0, 1), seed);
    let ff = hash_cell3(c + vec3<i32>(1, 0, 1), seed);
    let g = hash_cell3(c + vec3<i32>(0, 1, 1), seed);
    let h = hash_cell3(c + vec3<i32>(1, 1, 1), seed);
    let k1 = b - a;
    let k2 = cc - a;
    let k3 = e - a;
    let k4 = a - b - cc + d;
    let k5 = a - cc - e + g;
    let k6 = a - b - e + ff;
    let k7 = -a + b + cc - d + e - ff - g + h;
    // ∂ψ/∂x, ∂ψ/∂y, ∂ψ/∂z, each over the three channels.
    let dx = du.x * (k1 + k4 * u.y + k6 * u.z + k7 * u.y * u.z);
    let dy = du.y * (k2 + k4 * u.x + k5 * u.z + k7 * u.x * u.z);
    let dz = du.z * (k3 + k5 * u.y + k6 * u.x + k7 * u.x * u.y);
    // curl ψ = (∂ψz/∂y − ∂ψy/∂z, ∂ψx/∂z − ∂ψz/∂x, ∂ψy/∂x − ∂ψx/∂y).
    return vec3<f32>(dy.z - dz.y, dz.x - dx.z, dx.y - dy.x);
}

// Curl noise (Bridson et al. 2007), summed over octaves: divergence-free by construction.
// The result is in units of the potential per unit length (frequency is applied by the
// caller); octave o uses seed + o.
fn curl_noise(p: vec3<f32>, seed: u32, octaves: u32) -> vec3<f32> {
    var sum = vec3<f32>(0.0);
    var freq = 1.0;
    var amp = 1.0;
    for (var o = 0u; o < octaves; o++) {
        // Chain rule: the octave's gradient × its frequency.
        sum += amp * freq * curl_octave(p * freq, seed + o);
        freq *= 2.0;
        amp *= 0.5;
    }
    return sum;
}
