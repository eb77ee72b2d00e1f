// trail.wgsl — the ribbon of an emitter with a trail, as the billboards draw it
// (`TRAIL`): segment s of a particle joins point s and point s + 1, where point 0 is the
// particle as drawn (between the last two steps) and point j ≥ 1 the j-th newest entry
// of its ring (trail_on.wgsl) recorded before the last step. A segment is a
// camera-facing strip, its width and opacity tapering from the particle to the tail, its
// colour the colour ramp at the age the particle had at the segment's near end.
// A ribbon per parent (the ring's mode TRAIL_PER_PARENT) has one segment per particle:
// from it to the child its parent spawned before it (linked by the event scan), drawn
// while that slot still holds that child and it lives; the width at each end follows
// that end's particle (its size, tapering to the tail width over its life), and so does
// the opacity.
//
// Contract: as quad.wgsl, plus group 1 binding 6 `trail_ring` (the emitter's ring; a
// placeholder without a trail) and the look's trail fields: `look.tiny_c.y` the last
// step's number, `look.spin_streak.x` the width (× the particle's size),
// `look.size_intensity.x` the tail's width fraction, `size_intensity.y` its opacity.
// Mirrored by `trail_points` in src/sim/trails.rs.
#import "quad.wgsl"
#import "trail_ring.wgsl"

override TRAIL: bool = false;

@group(1) @binding(6) var<storage, read> trail_ring: TrailRing;

// Point j ≥ 1 of the trail of `slot` (xyz position, w age).
fn trail_point(slot: u32, j: u32) -> vec4<f32> {
    let n = max(trail_ring.points, 1u);
    let r = trail_point_entry(look.tiny_c.y, j, n, max(trail_ring.every, 1u));
    let slots = arrayLength(&trail_ring.history) / n;
    return trail_ring.history[ring_entry(look.flags.w + slot, r, slots)];
}

struct TrailCorner {
    clip: vec4<f32>,
    // Premultiplied colour of the segment (flat).
    color: vec4<f32>,
    // The opacity taper at this corner (interpolated along the segment).
    fade: f32,
    // Across the ribbon: -1 .. 1.
    across: f32,
    world: vec3<f32>,
}

// Corner `vi` of segment `seg` (of `segments`) of the particle `qd`.
fn trail_corner(qd: Quad, seg: u32, segments: u32, vi: u32) -> TrailCorner {
    if trail_ring.mode == TRAIL_PER_PARENT {
        return ribbon_corner(qd, vi);
    }
    var out: TrailCorner;
    let d = qd.d;
    let head = select(trail_point(qd.slot, seg), vec4<f32>(d.pos, d.age), seg == 0u);
    let tail = trail_point(qd.slot, seg + 1u);
    let far = (vi & 1u) == 0u;
    let end = select(head, tail, far);
    let u = (f32(seg) + select(0.0, 1.0, far)) / f32(segments);
    let taper = mix(1.0, look.size_intensity.x, u);
    out.fade = mix(1.0, look.size_intensity.y, u);
    let s = strip_between(head.xyz, tail.xyz);
    let perp = vec2<f32>(-s.dir.y, s.dir.x);
    let half_vp = 0.5 * camera.viewport.xy;
    let c = select(s.head, s.tail, far);
    out.across = f32(vi >> 1u) * 2.0 - 1.0;
    // The half-width in pixels is 0.5·width·viewport.z / w; in clip units the w cancels.
    let width = qd.lc.x * look.spin_streak.x * taper;
    let off_px = perp * out.across * (0.5 * width * camera.viewport.z);
    out.clip = vec4<f32>(c.xy + off_px / half_vp, c.z, c.w);
    out.world = end.xyz;
    // The colour at the age of the segment's near end.
    let color = premultiplied_color(age_fraction(head.w, d.life), qd.lc.y);
    out.color = vec4<f32>(color.rgb * inherited_rgb(d.life), color.a);
    return out;
}

// The child spawned before `slot`'s particle by the same parent, as drawn, and its size.
struct Link {
    ok: bool,
    d: Drawn,
    size: f32,
}

fn parent_link(slot: u32) -> Link {
    var out: Link;
    let base = look.flags.w;
    let l = bitcast<vec4<u32>>(trail_ring.history[base + slot]);
    // No link (0xFFFFFFFF), or the slot holds another particle by now.
    if l.x >= look.ring_b.z || bitcast<vec4<u32>>(trail_ring.history[base + l.x]).z != l.y {
        return out;
    }
    let pair = load_pair(l.x);
    out.d = drawn(pair[0], pair[1]);
    let t = age_fraction(out.d.age, out.d.life);
    let rnd = particle_random(l.x, out.d.life);
    out.size = look_curves(t, curve_random(l.x, out.d.life, rnd)).x;
    out.ok = out.d.alive;
    return out;
}

// Corner `vi` of the segment from particle `qd` to its parent's previous child (off
// screen when there is none).
fn ribbon_corner(qd: Quad, vi: u32) -> TrailCorner {
    var out: TrailCorner;
    let link = parent_link(qd.slot);
    if !link.ok {
        out.clip = vec4<f32>(2.0, 2.0, 2.0, 1.0);
        return out;
    }
    let far = (vi & 1u) == 0u;
    var d = qd.d;
    if far {
        d = link.d;
    }
    let t = age_fraction(d.age, d.life);
    let taper = mix(1.0, look.size_intensity.x, t);
    out.fade = mix(1.0, look.size_intensity.y, t);
    let s = strip_between(qd.d.pos, link.d.pos);
    let perp = vec2<f32>(-s.dir.y, s.dir.x);
    let c = select(s.head, s.tail, far);
    out.across = f32(vi >> 1u) * 2.0 - 1.0;
    let width = select(qd.lc.x, link.size, far) * look.spin_streak.x * taper;
    let off_px = perp * out.across * (0.5 * width * camera.viewport.z);
    out.clip = vec4<f32>(c.xy + off_px / (0.5 * camera.viewport.xy), c.z, c.w);
    out.world = d.pos;
    out.color = qd.color;
    return out;
}
