// noise.wgsl — smooth value noise, seeded, for spawn flicker (and later turbulence).
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
    let n000 = hash_cell(c + vec3<i32>(0, 0, 0), seed);
    let n100 = hash_cell(c + vec3<i32>(1, 0, 0), seed);
    let n010 = hash_cell(c + vec3<i32>(0, 1, 0), seed);
    let n110 = hash_cell(c + vec3<i32>(1, 1, 0), seed);
    let n001 = hash_cell(c + vec3<i32>(0, 0, 1), seed);
    let n101 = hash_cell(c + vec3<i32>(1, 0, 1), seed);
    let n011 = hash_cell(c + vec3<i32>(0, 1, 1), seed);
    let n111 = hash_cell(c + vec3<i32>(1, 1, 1), seed);
    let x00 = mix(n000, n100, u.x);
    let x10 = mix(n010, n110, u.x);
    let x01 = mix(n001, n101, u.x);
    let x11 = mix(n011, n111, u.x);
    return mix(mix(x00, x10, u.y), mix(x01, x11, u.y), u.z);
}

// Three decorrelated noise channels centred on zero, in [-1, 1].
fn value_noise3_vec(p: vec3<f32>, seed: u32) -> vec3<f32> {
    return vec3<f32>(
        value_noise3(p, seed),
        value_noise3(p + vec3<f32>(31.416, 47.853, 12.793), seed),
        value_noise3(p + vec3<f32>(-17.231, 5.117, 63.941), seed),
    ) * 2.0 - 1.0;
}
