// splat_accum.wgsl — the splat's accumulation (splat.wgsl): three u32 per pixel, R, G and
// B in units of 1/FIXED_SCALE, three atomic adds per lit pixel. Where the device has
// 64-bit atomics, splat_accum64.wgsl packs the three into one u64 (one add: the splat's
// cost is its atomics).
@group(2) @binding(0) var<storage, read_write> accum: array<atomic<u32>>;

// Units per unit of light.
const FIXED_SCALE: f32 = 4096.0;

// Adds `rgb` at pixel `p` (inside the target), rounded with `dither` (in [0, 1)): the
// expected energy of faint contributions is kept.
fn add_fixed(p: vec2<i32>, rgb: vec3<f32>, dither: vec3<f32>) {
    let base = u32(p.y * i32(camera.viewport.x) + p.x) * 3u;
    let q = vec3<u32>(rgb * FIXED_SCALE + dither);
    if q.r > 0u {
        atomicAdd(&accum[base], q.r);
    }
    if q.g > 0u {
        atomicAdd(&accum[base + 1u], q.g);
    }
    if q.b > 0u {
        atomicAdd(&accum[base + 2u], q.b);
    }
}

// The light accumulated at pixel `i` (row-major).
fn accum_rgb(i: u32) -> vec3<f32> {
    let rgb = vec3<u32>(atomicLoad(&accum[3u * i]), atomicLoad(&accum[3u * i + 1u]), atomicLoad(&accum[3u * i + 2u]));
    return vec3<f32>(rgb) / FIXED_SCALE;
}
