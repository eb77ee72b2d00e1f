// billboard.wgsl — pass 2, large particles: camera-facing quads (four vertices, indexed),
// one per slot of the emitter's live window (vertex pulling from the state buffer the
// update pass just wrote). One draw covers an emitter of every instance of a batch: the
// instances' pools are segments of one state buffer, each with its own look.
//
// Contract:
// - groups 0 and 1: particle_bindings.wgsl — `camera`, `looks` (one LookSlot per instance
//   of the draw, from a dynamic offset; keep in sync with `src/gpu/types.rs`), `ramps`;
//   `prev` (state before the last step), `cur` (after it), `order` (sorted: buffer
//   indices of the batch's slots, farthest first), the packed views and the births.
// - Unsorted, quad q is slot q mod W of instance q / W's live window (W: the widest
//   window of the draw's instances); sorted, quad q is `order[q]`.
// - Dead slots (and flat quads at or behind the camera) emit a degenerate quad outside the
//   clip volume: no fragments, unlike the 2006 thesis whose dead particles piled up at the
//   origin.
// - The fragment output is premultiplied: additive blending adds it, alpha blending
//   composites it "over". The look itself lives in look.wgsl (shared with splat.wgsl).
#import "common.wgsl"
#import "quad.wgsl"
// The ribbon of an emitter with a trail (TRAIL: `segments` quads per particle).
#import "trail.wgsl"

#import "particle_bindings.wgsl"
// The sprite: linear, premultiplied, mipmapped (src/render/sprites.rs).
@group(2) @binding(0) var sprite_tex: texture_2d<f32>;
@group(2) @binding(1) var sprite_sampler: sampler;
// The host's depth buffer (runtime player), read for soft edges; a 1×1 placeholder when
// SOFT_DEPTH is off.
@group(3) @binding(0) var scene_depth: texture_depth_2d;

// The motion pass (flipbook export): each fragment adds (motion · w, 0, w), with w the
// particle's visible weight (its coverage, or its light when additive) and motion its
// screen-space motion in pixels over `camera.up.w` seconds; the sums' ratio is the
// weighted mean motion of the particles seen at a pixel.
override MOTION: bool = false;

// The heat-haze pass (an emitter with `heat_haze`, never drawn in colour): each fragment
// adds its screen-space offset (uv units; rg) and its weight (a) into the distortion
// target: a ripple across the sprite (look.extra.y ripples), of amplitude
// look.size_intensity.w × the particle's size on screen, weighted by the sprite's
// coverage, the opacity over life and the soft edges. haze_apply.wgsl refracts the frame
// by the sum. The distortion target is HAZE_DOWNSCALE times smaller than the frame
// (keep in sync with `HAZE_DOWNSCALE` in src/render/haze.rs): the ripples are smooth, and
// large hot-air sprites cost a quarter of their fill.
override HAZE: bool = false;
const HAZE_DOWNSCALE: f32 = 4.0;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    // Atlas coordinates of this frame and of the next (flipbook blending).
    @location(0) uv0: vec2<f32>,
    @location(1) uv1: vec2<f32>,
    // The same at every corner: flat, so llvmpipe's triangle set-up and per-fragment
    // interpolation skip it (the flames' glow layer about 5 % faster).
    @location(2) @interpolate(flat) color: vec4<f32>,
    // x: weight of the next frame, y: height above the ground over the soft-edge distance
    // (SOFT_DEPTH: 1 / the soft-edge distance).
    @location(3) blend_height: vec2<f32>,
}

@vertex
fn vs_main(@builtin(vertex_index) vertex: u32, @builtin(instance_index) inst: u32) -> VsOut {
    var out: VsOut;
    if TRAIL {
        return trail_vertex(vertex, inst);
    }
    // Quad q (one instance each), corner `vi` (two triangles: 0 1 2, 2 1 3) of four
    // shared vertices over the corners (-1,-1) (1,-1) (-1,1) (1,1): a third fewer vertex
    // invocations than two separate triangles. OCTAGON: eight vertices, six triangles.
    let qd = load_quad(inst);
    if !qd.d.alive {
        out.clip = vec4<f32>(2.0, 2.0, 2.0, 1.0);
        return out;
    }
    return quad_vertex(qd, corner_index(vertex));
}

// The corner a vertex of the index buffer is (src/render/billboard.rs: the quad's six
// indices over 0..3, the octagon's eighteen over 0..7).
fn corner_index(vertex: u32) -> u32 {
    return select(vertex & 3u, vertex & 7u, OCTAGON);
}

// Corner `vi` of the living quad `qd`.
fn quad_vertex(qd: Quad, vi: u32) -> VsOut {
    var out: VsOut;
    let corner = quad_corner(qd, vi);
    out.clip = corner.clip;
    let flat_w = quad_flat_w(qd);
    if flat_w >= 0.0 {
        // A flat quad (one w: camera-facing): its corner on the sub-pixel grid, where the
        // tile rasteriser puts it (quad.wgsl `grid_pixels`); at or behind the camera, the
        // whole quad is culled.
        if flat_w <= 1e-4 {
            out.clip = vec4<f32>(2.0, 2.0, 2.0, 1.0);
            return out;
        }
        out.clip = grid_clip(grid_pixels(corner.clip), corner.clip.z / corner.clip.w);
    }
    if FLIPBOOK {
        let f = quad_frames(qd);
        out.uv0 = atlas_uv(f.x, corner.uv);
        out.uv1 = atlas_uv(f.y, corner.uv);
        out.blend_height.x = f.z;
    } else {
        out.uv0 = vec2<f32>(corner.uv.x * 0.5 + 0.5, 0.5 - corner.uv.y * 0.5);
        out.uv1 = out.uv0;
    }
    // Soft particles: the ground fade's argument (linear in world.y, so interpolating it
    // is exact).
    out.blend_height.y = ground_fade_arg(corner.world);
    if SOFT_DEPTH {
        out.blend_height.y = look.soft.y;
    }
    out.color = qd.color;
    if MOTION {
        // Where this corner's particle is `camera.up.w` seconds later, at its velocity.
        let d = qd.d;
        let now = look.clip_from_sim * vec4<f32>(d.pos, 1.0);
        let later = look.clip_from_sim * vec4<f32>(d.pos + d.vel * camera.up.w, 1.0);
        var px = vec2<f32>(0.0);
        if now.w > 1e-4 && later.w > 1e-4 {
            // Clip y points up, pixel rows down.
            px = (later.xy / later.w - now.xy / now.w) * vec2<f32>(0.5, -0.5) * camera.viewport.xy;
        }
        // The weight: coverage for alpha-blended layers, the brightest channel of the
        // light for additive ones.
        let w = select(max(max(out.color.r, out.color.g), out.color.b), out.color.a, SORTED);
        out.color = vec4<f32>(px, 0.0, w);
    }
    if HAZE {
        // For the fragment (which has no look): the ripple's phase (cycles: random per
        // particle, moving with its age), its amplitude (the strength × the particle's
        // size on screen, px), the ripples per sprite and its weight.
        let d = qd.d;
        let w = dot(transpose(look.clip_from_sim)[3], vec4<f32>(d.pos, 1.0));
        let size_px = qd.lc.x * camera.viewport.z / max(w, 1e-4);
        let weight = select(max(max(out.color.r, out.color.g), out.color.b), out.color.a, SORTED);
        let phase = qd.rnd.x + d.age * look.spin_streak.y;
        out.color = vec4<f32>(phase, size_px * look.size_intensity.w, look.extra.y, weight);
    }
    return out;
}

// The heat-haze pass's output at sprite coordinates `uv` (0..1) with coverage `a`.
fn haze_offset(in: VsOut, uv: vec2<f32>, a: f32) -> vec4<f32> {
    let p = uv * 2.0 - 1.0;
    let k = 6.2831853 * in.color.z;
    let phase = 6.2831853 * in.color.x;
    // A procedural normal: two crossed ripples, sideways stronger than vertical.
    let n = vec2<f32>(sin(k * p.y + phase), 0.5 * cos(k * p.x * 0.8 + 1.7 * phase));
    let offset_px = n * in.color.y * a;
    return vec4<f32>(offset_px / camera.viewport.xy, 0.0, a);
}

// A ribbon's corner: quad q is segment q mod S of particle quad q / S (S segments each).
fn trail_vertex(vertex: u32, inst: u32) -> VsOut {
    var out: VsOut;
    let segments = max(trail_ring.points, 2u) - 1u;
    let q = (vertex >> 2u) + inst;
    let qd = load_quad(q / segments);
    if !qd.d.alive {
        out.clip = vec4<f32>(2.0, 2.0, 2.0, 1.0);
        return out;
    }
    let c = trail_corner(qd, q % segments, segments, vertex & 3u);
    out.clip = c.clip;
    // Across the ribbon: the sprite's middle column.
    out.uv0 = vec2<f32>(0.5, 0.5 - c.across * 0.5);
    out.uv1 = out.uv0;
    out.color = c.color;
    out.blend_height = vec2<f32>(c.fade, ground_fade_arg(c.world));
    if SOFT_DEPTH {
        out.blend_height.y = look.soft.y;
    }
    return out;
}

@fragment
fn fs_main(in: VsOut) -> @location(0) vec4<f32> {
    // A lit layer's motion pass weighs the coverage of its RTBA map (lit.wgsl).
    let uv0 = select(in.uv0, rtba_uv(in.uv0), LIT);
    let uv1 = select(in.uv1, rtba_uv(in.uv1), LIT);
    var tex = textureSample(sprite_tex, sprite_sampler, uv0);
    if FLIPBOOK && FLIP_BLEND {
        tex = mix(tex, textureSample(sprite_tex, sprite_sampler, uv1), in.blend_height.x);
    }
    // The sprite is premultiplied: its rgb already carries its alpha (and the colour its
    // own alpha and, additive, the intensity).
    var a = in.color.a * tex.a;
    if MOTION {
        // The weight times the sprite's coverage (the motion's weight, in alpha).
        a = in.color.a * select(max(max(tex.r, tex.g), tex.b), tex.a, SORTED);
    }
    var rgb = in.color.rgb * tex.rgb;
    if TRAIL {
        // The taper of opacity along the ribbon.
        a *= in.blend_height.x;
        rgb *= in.blend_height.x;
    }
    let fade = edge_fade(in.clip, in.blend_height.y);
    a *= fade;
    rgb *= fade;
    if HAZE {
        return haze_offset(in, in.uv0, in.color.a * tex.a * fade);
    }
    if MOTION {
        // Weighted by the cube of the visible weight: where sparks cross, the brightest
        // one's motion wins rather than a mean that fits neither.
        let k = a * a * a;
        return vec4<f32>(in.color.xy * k, 0.0, k);
    }
    return vec4<f32>(rgb, a);
}

// The soft edges' fade of a fragment at `clip` (its position) with the ground fade's
// argument `height` (SOFT_DEPTH: 1 / the soft-edge distance): 1 without them.
fn edge_fade(clip: vec4<f32>, height: f32) -> f32 {
    var fade = 1.0;
    if SOFT {
        // Soft particles: fade out towards the ground plane instead of a hard cut.
        fade = clamp(height, 0.0, 1.0);
    }
    if SOFT_DEPTH {
        // Soft particles against the host's scene: fade over the soft-edge distance
        // between this fragment and what the host drew behind it (view-space distances).
        // The host's depth is the frame's size; the distortion target is smaller.
        let px = clip.xy * select(1.0, HAZE_DOWNSCALE, HAZE);
        let scene = textureLoad(scene_depth, vec2<i32>(px), 0);
        fade = clamp((view_distance(scene) - view_distance(clip.z)) * height, 0.0, 1.0);
    }
    return fade;
}

// A lit quad's corner (lit.wgsl): the billboard's, its six-way light flat.
struct VsLit {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv0: vec2<f32>,
    @location(1) uv1: vec2<f32>,
    // The emitted colour (the colour over life × the emission) and the coverage.
    @location(2) @interpolate(flat) color: vec4<f32>,
    @location(3) blend_height: vec2<f32>,
    @location(4) @interpolate(flat) l0: vec4<f32>,
    @location(5) @interpolate(flat) l1: vec4<f32>,
    @location(6) @interpolate(flat) l2: vec4<f32>,
    @location(7) @interpolate(flat) l3: vec4<f32>,
    @location(8) @interpolate(flat) l4: vec4<f32>,
}

@vertex
fn vs_lit(@builtin(vertex_index) vertex: u32, @builtin(instance_index) inst: u32) -> VsLit {
    var out: VsLit;
    let qd = load_quad(inst);
    if !qd.d.alive {
        out.clip = vec4<f32>(2.0, 2.0, 2.0, 1.0);
        return out;
    }
    let v = quad_vertex(qd, corner_index(vertex));
    let l = quad_sixway(qd);
    return VsLit(v.clip, v.uv0, v.uv1, vec4<f32>(v.color.rgb * lit.ambient.w, v.color.a), v.blend_height, l[0], l[1], l[2], l[3], l[4]);
}

@fragment
fn fs_lit(in: VsLit) -> @location(0) vec4<f32> {
    var rtba = textureSample(sprite_tex, sprite_sampler, rtba_uv(in.uv0));
    var lbfe = textureSample(sprite_tex, sprite_sampler, lbfe_uv(in.uv0));
    if FLIPBOOK && FLIP_BLEND {
        rtba = mix(rtba, textureSample(sprite_tex, sprite_sampler, rtba_uv(in.uv1)), in.blend_height.x);
        lbfe = mix(lbfe, textureSample(sprite_tex, sprite_sampler, lbfe_uv(in.uv1)), in.blend_height.x);
    }
    let l = array<vec4<f32>, 5>(in.l0, in.l1, in.l2, in.l3, in.l4);
    let rgb = sixway_rgb(l, rtba, lbfe) + in.color.rgb * lbfe.a;
    let fade = edge_fade(in.clip, in.blend_height.y);
    return vec4<f32>(rgb, in.color.a * rtba.a) * fade;
}

// The view-space distance in front of the camera of a depth-buffer value.
fn view_distance(depth: f32) -> f32 {
    let k = camera.depth_to_view;
    return -(k.x * depth + k.y) / (k.z * depth + k.w);
}
