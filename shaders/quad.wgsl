// quad.wgsl — one particle's camera-facing quad, as both quad draw paths build it: the
// billboards' vertex shader (billboard.wgsl) and the tile rasteriser's projection
// (tiles.wgsl). One function places a corner, so the two paths draw the same geometry.
//
// Contract: as look.wgsl, plus `looks: array<LookSlot>` (a draw's instances) and `order:
// array<u32>` (the sort's back-to-front buffer indices), and the look modules below.
#import "look.wgsl"
#import "lit.wgsl"
#import "sprite_trim.wgsl"

// Pipeline variants: each look module is compiled in only when an emitter uses it.
override SORTED: bool = false;
override FLIPBOOK: bool = false;
override FLIP_BLEND: bool = false;
override STREAK: bool = false;
override SOFT: bool = false;
// Soft edges against the host's depth buffer (replaces SOFT's ground plane).
override SOFT_DEPTH: bool = false;
// Lit smoke (lit.wgsl): six-way maps shaded by the instance's `LitUniform`.
override LIT: bool = false;
// Billboards cut to an octagon (sprite_trim.wgsl): `quad_corner`'s corner index runs over
// its eight corners instead of the rectangle's four. Never set for the compute paths.
override OCTAGON: bool = false;

// Which instance of the draw and which slot of its pool quad `q` is, or none.
// Unsorted, quad q is slot q mod W of instance q / W's live window (W: the widest window
// of the draw's instances); sorted, quad q is `order[q]`.
fn quad_slot(q: u32) -> vec2<u32> {
    if SORTED {
        // A buffer index (instance k's segment starts at k · capacity); padding has none.
        let v = order[q];
        if v == 0xFFFFFFFFu {
            return vec2<u32>(0xFFFFFFFFu);
        }
        let capacity = looks[0].look.ring_b.z;
        return vec2<u32>(v / capacity, v % capacity);
    }
    let width = max(looks[0].look.ring.w, 1u);
    let k = q / width;
    let i = q - k * width;
    // The window: the last `len` slots before the ring's head, wrapping at the capacity.
    let l = looks[k].look;
    if i >= l.ring_b.w {
        return vec2<u32>(0xFFFFFFFFu);
    }
    var slot = l.ring.x + l.ring_b.z - l.ring_b.w + i;
    if slot >= l.ring_b.z {
        slot -= l.ring_b.z;
    }
    return vec2<u32>(k, slot);
}

// What a particle's corners share.
struct Quad {
    d: Drawn,
    slot: u32,
    // particle_random's four numbers.
    rnd: vec4<f32>,
    // look_curves: size (m), opacity, spin, flipbook frame.
    lc: vec4<f32>,
    // Premultiplied colour (and, additive, scaled by the intensity).
    color: vec4<f32>,
}

// The quad of quad `q` of the draw; `d.alive` is false for none. Sets `look` to its
// instance's look.
fn load_quad(q: u32) -> Quad {
    var out: Quad;
    let ks = quad_slot(q);
    if ks.x == 0xFFFFFFFFu {
        return out;
    }
    look = looks[ks.x].look;
    if LIT {
        lit = looks[ks.x].lit;
    }
    let slot = ks.y;
    let pair = load_pair(slot);
    out.d = drawn(pair[0], pair[1]);
    if !out.d.alive {
        return out;
    }
    out.slot = slot;
    let t = age_fraction(out.d.age, out.d.life);
    out.rnd = particle_random(slot, out.d.life);
    out.lc = look_curves(t, curve_random(slot, out.d.life, out.rnd));
    // Premultiplied once per particle: the per-pixel work reads nothing from the look.
    out.color = premultiplied_color(t, out.lc.y);
    out.color = vec4<f32>(out.color.rgb * inherited_rgb(out.d.life), out.color.a);
    return out;
}

// The colour at normalised age `t` times `opacity`, premultiplied, and scaled by the
// intensity when additive.
fn premultiplied_color(t: f32, opacity: f32) -> vec4<f32> {
    let c = particle_color(t);
    let alpha = c.a * opacity;
    var gain = alpha;
    if !SORTED {
        gain *= look.size_intensity.z;
    }
    return vec4<f32>(c.rgb * gain, alpha);
}

// One corner of a quad: where it lands, its coordinates in the sprite's frame ([-1, 1]²,
// y up; cut to the sprite's occupied part) and its world position.
struct Corner {
    clip: vec4<f32>,
    uv: vec2<f32>,
    world: vec3<f32>,
}

// Corner `vi` (0 (-1,-1), 1 (1,-1), 2 (-1,1), 3 (1,1)) of quad `qd`; OCTAGON: corner
// `vi` (0..7) of its octagon.
fn quad_corner(qd: Quad, vi: u32) -> Corner {
    var out: Corner;
    let d = qd.d;
    let size = qd.lc.x;
    var corner = vec2<f32>(f32(vi & 1u), f32(vi >> 1u)) * 2.0 - 1.0;
    if !STREAK {
        // Cut the quad to the sprite's occupied rectangle (look.trim, frame texture
        // coordinates), grown by 6 screen pixels: trilinear filtering also reads the mip
        // above the one the derivatives ask for, whose texels are up to two pixels each,
        // and the mip chain's triangle filter has spread each level's edge by about
        // one and a half of its texels (3 pixels left a lit puff's sphere edge cut).
        let w = dot(transpose(look.clip_from_sim)[3], vec4<f32>(d.pos, 1.0));
        let px = size * camera.viewport.z / max(w, 1e-4);
        let m = 6.0 / max(px, 1e-3);
        let lo = max(look.trim.xy - m, vec2<f32>(0.0));
        let hi = min(look.trim.zw + m, vec2<f32>(1.0));
        var uv = vec2<f32>(mix(lo.x, hi.x, corner.x * 0.5 + 0.5), mix(lo.y, hi.y, 0.5 - corner.y * 0.5));
        if OCTAGON {
            uv = octagon_corner(lo, hi, look.trim, look.tiny_c.w, m, vi);
        }
        corner = vec2<f32>(2.0 * uv.x - 1.0, 1.0 - 2.0 * uv.y);
    }
    out.uv = corner;
    if STREAK {
        // Stretched from where the particle was `length` seconds ago (tail, corner.x = -1)
        // to where it is (head), `size` wide on screen.
        var tail = d.vel * look.spin_streak.z;
        let len = length(tail);
        if len > look.spin_streak.w {
            tail *= look.spin_streak.w / len;
        }
        let s = strip_between(d.pos, d.pos - tail);
        let dir = s.dir;
        let perp = vec2<f32>(-dir.y, dir.x);
        let half_vp = 0.5 * camera.viewport.xy;
        let end = select(s.tail, s.head, corner.x > 0.0);
        // The half-width in pixels is 0.5·size·viewport.z / w; in clip units the w cancels.
        let off_px = (dir * corner.x + perp * corner.y) * (0.5 * size * camera.viewport.z);
        out.clip = vec4<f32>(end.xy + off_px / half_vp, end.z, end.w);
        out.world = select(d.pos - tail, d.pos, corner.x > 0.0);
    } else {
        let cs = quad_turn(qd);
        let c = vec2<f32>(corner.x * cs.x - corner.y * cs.y, corner.x * cs.y + corner.y * cs.x);
        out.world = d.pos + (camera.right_alpha.xyz * c.x + camera.up.xyz * c.y) * (0.5 * size);
        out.clip = look.clip_from_sim * vec4<f32>(out.world, 1.0);
    }
    return out;
}

// The cosine and sine of quad `qd`'s turn in the image plane: its random initial
// rotation plus its spin over its age.
fn quad_turn(qd: Quad) -> vec2<f32> {
    let angle = (qd.rnd.y - 0.5) * look.extra.z + qd.lc.z * qd.d.life;
    return vec2<f32>(cos(angle), sin(angle));
}

// A lit quad's six-way light, packed (lit.wgsl): at its particle, in its sprite's turned
// frame, times the albedo and its opacity.
fn quad_sixway(qd: Quad) -> array<vec4<f32>, 5> {
    let cs = quad_turn(qd);
    let r = camera.right_alpha.xyz;
    let u = camera.up.xyz;
    let s = sixway_axes(qd.d.pos, r * cs.x + u * cs.y, u * cs.x - r * cs.y, lit.albedo.rgb * qd.color.a);
    return pack_sixway(s);
}

// The clip w that every corner of quad `qd` shares, or a negative number where its
// corners' w differ (a streak, or a view with shear, where the quad is not parallel to
// the image plane): a flat quad's interpolation is affine on screen. Both quad draw paths
// decide with it (the tiles' affine map, the billboards' grid corners).
fn quad_flat_w(qd: Quad) -> f32 {
    if STREAK {
        return -1.0;
    }
    let row = transpose(look.clip_from_sim)[3];
    let w = dot(row, vec4<f32>(qd.d.pos, 1.0));
    // The change of w across the quad's half-size along the camera's right and up.
    let dw = 0.5 * qd.lc.x * (abs(dot(row.xyz, camera.right_alpha.xyz)) + abs(dot(row.xyz, camera.up.xyz)));
    return select(-1.0, w, dw <= 1e-6 * abs(w));
}

// A clip position in pixels of `camera.viewport` (the origin at the top-left corner) on
// the rasteriser's sub-pixel grid (8 bits: Vulkan's usual subPixelPrecisionBits, lavapipe's
// and NVIDIA's). Both quad draw paths put a flat quad's corners here, so they
// light the same pixels where an edge meets a pixel centre. Left to the rasteriser's own
// snapping, a position computed a little differently (another division, another fused
// multiply-add) lands one step away from the tile path's now and then: on an H100 a few of
// the thesis preset's 16384 sparks a frame lit a column of pixels in one path only.
fn grid_pixels(c: vec4<f32>) -> vec2<f32> {
    let n = c.xy / c.w;
    let p = vec2<f32>((n.x * 0.5 + 0.5) * camera.viewport.x, (0.5 - n.y * 0.5) * camera.viewport.y);
    return round(p * 256.0) / 256.0;
}

// The clip position of `p`, a position on the sub-pixel grid (`grid_pixels`), at
// normalised depth `z`, with w = 1: the rasteriser's snapping finds `p` again (its
// arithmetic lands within a rounding error of the grid point, far from the halfway points
// between them). Only for a flat quad (`quad_flat_w`), so that its interpolation stays
// exact. On a target smaller than `camera.viewport` (a reduced layer) the point is still
// where it belongs; only the grid is finer than that target's.
fn grid_clip(p: vec2<f32>, z: f32) -> vec4<f32> {
    let n = p / camera.viewport.xy * 2.0 - 1.0;
    return vec4<f32>(n.x, -n.y, z, 1.0);
}

// A screen-space strip from `tail` to `head` (simulation space): both ends in clip space
// (the tail on the head when either end is behind the camera) and the unit direction in
// pixels from tail to head (x when they coincide on screen). Streaks and trails use it.
struct Strip {
    head: vec4<f32>,
    tail: vec4<f32>,
    dir: vec2<f32>,
}

fn strip_between(head: vec3<f32>, tail: vec3<f32>) -> Strip {
    let head_clip = look.clip_from_sim * vec4<f32>(head, 1.0);
    var tail_clip = look.clip_from_sim * vec4<f32>(tail, 1.0);
    if tail_clip.w <= 1e-4 || head_clip.w <= 1e-4 {
        tail_clip = head_clip;
    }
    let half_vp = 0.5 * camera.viewport.xy;
    let dir_px = (head_clip.xy / head_clip.w - tail_clip.xy / tail_clip.w) * half_vp;
    let l = length(dir_px);
    return Strip(head_clip, tail_clip, select(vec2<f32>(1.0, 0.0), dir_px / l, l > 1e-3));
}

// The flipbook frames of a quad: x = frame, y = next frame, z = weight of y.
fn quad_frames(qd: Quad) -> vec3<f32> {
    return flipbook_frames(qd.d.age, qd.d.life, qd.rnd.w, FLIP_BLEND, qd.lc.w);
}

// The ground fade's argument at a world position: height above the ground over the
// soft-edge distance (linear in the position, so interpolating it is exact).
fn ground_fade_arg(world: vec3<f32>) -> f32 {
    return (world.y - look.soft.x) * look.soft.y;
}
