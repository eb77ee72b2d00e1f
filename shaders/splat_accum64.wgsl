// splat_accum64.wgsl — the splat's accumulation where the device has 64-bit atomics: one
// u64 per pixel holding R, G and B in 21 bits each (units of 1/FIXED_SCALE, up to 1024 a
// channel: far past white at any exposure a fire is shown at), one atomic add per lit
// pixel instead of splat_accum.wgsl's three. A contribution is clamped to its channel;
// a pixel's sum past it carries into the next channel.
@group(2) @binding(0) var<storage, read_write> accum: array<atomic<u64>>;

// Units per unit of light.
const FIXED_SCALE: f32 = 2048.0;
const CHANNEL_BITS: u32 = 21u;
const CHANNEL_MAX: u32 = 0x1FFFFFu;

// Adds `rgb` at pixel `p` (inside the target), rounded with `dither` (in [0, 1)): the
// expected energy of faint contributions is kept.
fn add_fixed(p: vec2<i32>, rgb: vec3<f32>, dither: vec3<f32>) {
    let q = vec3<u32>(min(rgb * FIXED_SCALE + dither, vec3<f32>(f32(CHANNEL_MAX))));
    if any(q > vec3<u32>(0u)) {
        let v = u64(q.r) | (u64(q.g) << CHANNEL_BITS) | (u64(q.b) << (2u * CHANNEL_BITS));
        atomicAdd(&accum[u32(p.y * i32(camera.viewport.x) + p.x)], v);
    }
}

// The light accumulated at pixel `i` (row-major).
fn accum_rgb(i: u32) -> vec3<f32> {
    let v = atomicLoad(&accum[i]);
    let m = u64(CHANNEL_MAX);
    let rgb = vec3<u32>(u32(v & m), u32((v >> CHANNEL_BITS) & m), u32((v >> (2u * CHANNEL_BITS)) & m));
    return vec3<f32>(rgb) / FIXED_SCALE;
}
