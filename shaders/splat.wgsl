// splat.wgsl — pass 2, small particles: a compute splat. Each quad of the draw (as the
// billboards would draw it: quad.wgsl, projected by sprite_project.wgsl) adds its light
// into a fixed-point accumulation buffer with atomics, order-independent, so additive
// fire needs no sort. A sprite whose pixel box is at most FOOTPRINT pixels a side adds,
// at every pixel centre it covers, the texel the billboard's fragment would add there
// (its footprint: the billboards' image); a larger one (the path forced on large
// sprites) adds its integrated light (colour · intensity · ∫coverage · (size in px / 2)²)
// bilinearly over the 2×2 pixels nearest its centre. `resolve` turns the buffer into HDR
// light. Alpha-blended emitters always use billboards.
//
// Contract:
// - groups 0 and 1: particle_bindings.wgsl (camera, looks with a dynamic offset per
//   emitter, ramps; the state buffers).
// - group 2: 0 `accum` (splat_accum.wgsl: three u32 per pixel, or one u64 where the
//   device has 64-bit atomics, splat_accum64.wgsl), 1 `scene_depth` (the host's depth,
//   tested at every pixel a particle adds light to when it is the viewport's size).
// - group 3: the emitter's sprite and sampler; the compute resolve (`resolve_add`, where
//   the adapter can): binding 2 `resolve_image`, the target, and no group 1.
// - DEPTH_TEST: 0 none, 1 a particle nearer than or level with the host's depth passes
//   (depth 0 = near), 2 the reverse (reversed Z). Particles never write depth.
#import "common.wgsl"
#import "rng.wgsl"
#import "sprite_project.wgsl"
#import "particle_bindings.wgsl"
#import "splat_accum.wgsl"

@group(2) @binding(1) var scene_depth: texture_depth_2d;
@group(3) @binding(0) var sprite_tex: texture_2d<f32>;
@group(3) @binding(1) var sprite_sampler: sampler;
// The compute resolve's target (the HDR image, read and written in place).
@group(3) @binding(2) var resolve_image: texture_storage_2d<rgba16float, read_write>;

override DEPTH_TEST: u32 = 0u;

// Sprites whose pixel box is at most this many pixels a side add their footprint;
// larger ones their integrated light (`FOOTPRINT_PX` in src/render/splat.rs sets it).
override FOOTPRINT: i32 = 8;

// Whether a particle at NDC depth `z` is in front of the host's geometry at pixel `p`.
fn visible(p: vec2<i32>, z: f32) -> bool {
    let dims = textureDimensions(scene_depth);
    if DEPTH_TEST == 0u || dims.x != u32(camera.viewport.x) || dims.y != u32(camera.viewport.y) {
        return true;
    }
    let d = textureLoad(scene_depth, p, 0);
    return select(z >= d, z <= d, DEPTH_TEST == 1u);
}

@compute @workgroup_size(256)
fn splat(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    // One invocation per quad of instance wg.z's live window (the draw's widest window
    // per instance: quad.wgsl's `quad_slot`).
    let i = (wg.y * nwg.x + wg.x) * 256u + lid;
    let width = max(looks[0].look.ring.w, 1u);
    if i >= width {
        return;
    }
    let qd = load_quad(wg.z * width + i);
    if !qd.d.alive {
        return;
    }
    let s = project_quad(qd);
    if s.bounds.x > s.bounds.z || s.bounds.y > s.bounds.w {
        return;
    }
    let seed = vec2<u32>(qd.slot, bitcast<u32>(qd.d.age));
    if all(s.bounds.zw - s.bounds.xy < vec2<i32>(FOOTPRINT)) {
        for (var y = s.bounds.y; y <= s.bounds.w; y++) {
            for (var x = s.bounds.x; x <= s.bounds.z; x++) {
                footprint_pixel(s, vec2<i32>(x, y), seed);
            }
        }
    } else {
        integrated_light(qd, seed);
    }
}

// Sprite `s`'s light at pixel `p`, as the billboard's fragment adds it there.
fn footprint_pixel(s: TileSprite, p: vec2<i32>, seed: vec2<u32>) {
    let pc = vec2<f32>(p) + 0.5;
    var sp: SpritePoint;
    if s.offset.z != 0.0 {
        sp = affine_point(s.map, s.offset, pc);
    } else {
        sp = projective_point(s.map, s.offset, s.map_z, s.z_row, s.w_row, pc);
    }
    if sprite_misses(sp, pc, p, s.offset, s.uv_box) {
        return;
    }
    let tex = sprite_texel(sp.uv * s.grad.xy, s.frames, s.grad.z, sp.ddx * s.grad.xy, sp.ddy * s.grad.xy);
    var rgb = s.color.rgb * tex.rgb;
    if SOFT || SOFT_DEPTH {
        rgb *= soft_fade(p, sp.uv, sp.z, s.ground, s.grad.w);
    }
    let dither = unorm4(pcg4d(vec4<u32>(seed, u32(p.x) | (u32(p.y) << 16u), 0x5EEDu)));
    add_fixed(p, rgb, dither.xyz);
}

// A large quad's integrated light, bilinearly over the 2×2 pixels nearest its centre
// (one pixel below 2 px), each tested against the host's depth at the centre's depth.
fn integrated_light(qd: Quad, seed: vec2<u32>) {
    let clip = look.clip_from_sim * vec4<f32>(qd.d.pos, 1.0);
    if clip.w <= 1e-4 || clip.z < 0.0 || clip.z > clip.w {
        return;
    }
    let size_px = qd.lc.x * camera.viewport.z / clip.w;
    let half = 0.5 * size_px;
    // qd.color: premultiplied, × the intensity.
    var energy = qd.color.rgb * (look.extra.x * half * half);
    if look.soft.y > 0.0 {
        // The billboard's ground fade, taken at the particle's centre.
        energy *= clamp((qd.d.pos.y - look.soft.x) * look.soft.y, 0.0, 1.0);
    }
    let ndc = clip.xy / clip.w;
    let px = vec2<f32>((ndc.x * 0.5 + 0.5) * camera.viewport.x, (0.5 - ndc.y * 0.5) * camera.viewport.y) - 0.5;
    let dither = unorm4(pcg4d(vec4<u32>(seed, 0u, 0x5EEDu)));
    let small = size_px < 2.0;
    let b = vec2<i32>(select(floor(px), floor(px + 0.5), small));
    let f = select(px - floor(px), vec2<f32>(0.0), small);
    let taps = select(4u, 1u, small);
    let size = vec2<i32>(camera.viewport.xy);
    for (var k = 0u; k < taps; k++) {
        let o = vec2<u32>(k & 1u, k >> 1u);
        let p = b + vec2<i32>(o);
        let wx = select(1.0 - f.x, f.x, o.x == 1u);
        let wy = select(1.0 - f.y, f.y, o.y == 1u);
        if all(p >= vec2<i32>(0)) && all(p < size) && visible(p, clip.z / clip.w) {
            add_fixed(p, energy * (wx * wy), vec3<f32>(dither[k]));
        }
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
    return vec4<f32>(accum_rgb(u32(frag.y) * w + u32(frag.x)), 0.0);
}

// The resolve by compute (where the adapter can read and write the target in place):
// the accumulated light added to the HDR image, as the draw's additive blending does, on
// every compute unit rather than the raster.
@compute @workgroup_size(16, 16)
fn resolve_add(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(camera.viewport.xy);
    if any(id.xy >= size) {
        return;
    }
    let rgb = accum_rgb(id.y * size.x + id.x);
    if all(rgb == vec3<f32>(0.0)) {
        return;
    }
    let dst = textureLoad(resolve_image, vec2<i32>(id.xy));
    textureStore(resolve_image, vec2<i32>(id.xy), vec4<f32>(dst.rgb + rgb, dst.a));
}
