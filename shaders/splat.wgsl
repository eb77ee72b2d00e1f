// splat.wgsl — pass 2, small particles: a compute splat. Each alive slot projects its
// particle and adds its light, as the billboard would have integrated it
// (colour · alpha · intensity · ∫coverage · (size in px / 2)²), into a fixed-point
// accumulation buffer, spread bilinearly over the 2×2 nearest pixels (one pixel below 2 px); `resolve` turns the
// buffer into HDR light. Order-independent, so additive fire needs no sort; alpha-blended
// emitters always use billboards.
//
// Contract:
// - groups 0 and 1: particle_bindings.wgsl (camera, looks with a dynamic offset per
//   emitter, ramps; the state buffers).
// - group 2: 0 `accum` (3 × u32 per pixel: R, G, B in units of 1/FIXED_SCALE), 1
//   `scene_depth` (the host's depth, tested at every pixel a particle adds light to
//   when it is the viewport's size).
// - DEPTH_TEST: 0 none, 1 a particle nearer than or level with the host's depth passes
//   (depth 0 = near), 2 the reverse (reversed Z). Particles never write depth.
#import "common.wgsl"
#import "rng.wgsl"
#import "look.wgsl"
#import "particle_bindings.wgsl"

@group(2) @binding(0) var<storage, read_write> accum: array<atomic<u32>>;
@group(2) @binding(1) var scene_depth: texture_depth_2d;

override DEPTH_TEST: u32 = 0u;

// Whether a particle at NDC depth `z` is in front of the host's geometry at pixel `p`.
fn visible(p: vec2<i32>, z: f32) -> bool {
    let dims = textureDimensions(scene_depth);
    if DEPTH_TEST == 0u || dims.x != u32(camera.viewport.x) || dims.y != u32(camera.viewport.y) {
        return true;
    }
    let d = textureLoad(scene_depth, p, 0);
    return select(z >= d, z <= d, DEPTH_TEST == 1u);
}

// Keep in sync with `SPLAT_FIXED_SCALE` in src/render/splat.rs.
const FIXED_SCALE: f32 = 4096.0;

fn add_light(x: i32, y: i32, z: f32, rgb: vec3<f32>, dither: f32) {
    let w = i32(camera.viewport.x);
    let h = i32(camera.viewport.y);
    if x < 0 || y < 0 || x >= w || y >= h || !visible(vec2<i32>(x, y), z) {
        return;
    }
    let base = u32(y * w + x) * 3u;
    // Dithered rounding keeps the expected energy of faint contributions.
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

@compute @workgroup_size(256)
fn splat(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    // One invocation per slot of the live window: the last ring_b.w slots before the
    // ring's head (ring.x), wrapping at the capacity (ring_b.z).
    look = looks[wg.z].look;
    let i = (wg.y * nwg.x + wg.x) * 256u + lid;
    if i >= look.ring_b.w {
        return;
    }
    var slot = look.ring.x + look.ring_b.z - look.ring_b.w + i;
    if slot >= look.ring_b.z {
        slot -= look.ring_b.z;
    }
    let pair = load_pair(slot);
    let d = drawn(pair[0], pair[1]);
    if !d.alive {
        return;
    }
    let clip = look.clip_from_sim * vec4<f32>(d.pos, 1.0);
    if clip.w <= 1e-4 || any(abs(clip.xy) > vec2<f32>(clip.w * 1.01)) || clip.z < 0.0 || clip.z > clip.w {
        return;
    }
    let t = age_fraction(d.age, d.life);
    let color = particle_color(t) * vec4<f32>(inherited_rgb(d.life), 1.0);
    let rnd = particle_random(slot, d.life);
    let lc = look_curves(t, curve_random(slot, d.life, rnd));
    let size_px = lc.x * camera.viewport.z / clip.w;
    let half = 0.5 * size_px;
    var energy = color.rgb * (color.a * lc.y * look.size_intensity.z * look.extra.x * half * half);
    if look.soft.y > 0.0 {
        // The billboard's ground fade, taken at the particle's centre.
        energy *= clamp((d.pos.y - look.soft.x) * look.soft.y, 0.0, 1.0);
    }
    let ndc = clip.xy / clip.w;
    let px = vec2<f32>((ndc.x * 0.5 + 0.5) * camera.viewport.x, (0.5 - ndc.y * 0.5) * camera.viewport.y) - 0.5;
    let dither = unorm4(pcg4d(vec4<u32>(slot, bitcast<u32>(d.age), 0x5EEDu, 0u)));
    // Bilinear over the 2×2 nearest pixels; below two pixels one tap (3 atomics)
    // suffices: the footprint is sub-pixel anyway, and atomics are the splat's cost. One
    // loop for both, so a CPU adapter (which runs every branch for a SIMD batch of
    // particles, masked) pays for the taps the batch needs, not for both paths.
    let small = size_px < 2.0;
    let near = floor(px + 0.5);
    let b = vec2<i32>(select(floor(px), near, small));
    let f = select(px - floor(px), vec2<f32>(0.0), small);
    let taps = select(4u, 1u, small);
    for (var k = 0u; k < taps; k++) {
        let o = vec2<u32>(k & 1u, k >> 1u);
        let wx = select(1.0 - f.x, f.x, o.x == 1u);
        let wy = select(1.0 - f.y, f.y, o.y == 1u);
        add_light(b.x + i32(o.x), b.y + i32(o.y), clip.z / clip.w, energy * (wx * wy), dither[k]);
    }
}

// The resolve: a full-screen triangle reading the accumulated light into the HDR target
// (additive blending on top of the billboards).
@vertex
fn vs_resolve(@builtin(vertex_index) vi: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((vi << 1u) & 2u), f32(vi & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs_resolve(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let w = u32(camera.viewport.x);
    let i = (u32(frag.y) * w + u32(frag.x)) * 3u;
    let rgb = vec3<f32>(f32(atomicLoad(&accum[i])), f32(atomicLoad(&accum[i + 1u])), f32(atomicLoad(&accum[i + 2u])));
    return vec4<f32>(rgb / FIXED_SCALE, 0.0);
}
