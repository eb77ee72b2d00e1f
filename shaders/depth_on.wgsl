// depth_on.wgsl — collision with the host's depth buffer (screen-space collision), composed
// in place of depth_off.wgsl for an emitter with `depth_collision`.
//
// Contract:
// - group 2: binding 0 `host_depth` (the host's depth of this frame, one sample, as the
//   draws sample it), binding 1 `depth_view` (this emitter's simulation space → clip and
//   back, composed in f64 on the CPU, and the target's size).
// - depth_collide(old, pos, vel): the step's path old → pos is marched across the screen
//   (a sample every 2 px, at most 16) and the first sample behind the depth refined by
//   bisection (10 halvings). The crossing is a hit when the particle is then at most the
//   thickness (params.collide_c.y) behind the surface — across a continuous surface the
//   gap closes to 0, behind a silhouette it stays — so a wall thinner than a step's travel
//   still stops a fast particle. A path that starts behind a surface within the thickness
//   is put back on it; one that starts further behind is hidden by the geometry and flies
//   on. Off screen, behind the camera, where the depth holds its clear value, and without
//   a depth view (viewport.w = 0) nothing is hit.
// - The normal is rebuilt from the depth at the contact's pixel and its four neighbours
//   (on each axis the neighbour nearer in depth, so an edge does not bend it), facing the
//   camera: exact for a plane.
// - The response is the colliders' (collide.wgsl's bounce: elasticity, friction, rest
//   speed, stick); params.collide_c.z kills on contact. A hit is an impact for the
//   collision events.
#import "collide.wgsl"

struct DepthView {
    clip_from_sim: mat4x4<f32>,
    sim_from_clip: mat4x4<f32>,
    // xy: the target's size (px), z: +1 when depth grows away from the camera, −1 for
    // reversed Z, w: 1 when a depth is bound (0: nothing collides).
    viewport: vec4<f32>,
}

@group(2) @binding(0) var host_depth: texture_depth_2d;
@group(2) @binding(1) var<uniform> depth_view: DepthView;

// Bisection steps refining a crossing (2^-10 of a march sample).
const DEPTH_REFINE: u32 = 10u;
// The most march samples along one step's path.
const DEPTH_MARCH_MAX: u32 = 16u;

// A point on the screen: xy its pixel position, z its depth, w 1 when it is on screen
// between the near and far planes (else −1).
fn on_screen(p: vec3<f32>) -> vec4<f32> {
    let c = depth_view.clip_from_sim * vec4<f32>(p, 1.0);
    if c.w <= 0.0 {
        return vec4<f32>(0.0, 0.0, 0.0, -1.0);
    }
    let ndc = c.xyz / c.w;
    let size = depth_view.viewport.xy;
    let px = vec2<f32>((ndc.x * 0.5 + 0.5) * size.x, (0.5 - ndc.y * 0.5) * size.y);
    let inside = all(px >= vec2<f32>(0.0)) && all(px < size) && ndc.z >= 0.0 && ndc.z <= 1.0;
    return vec4<f32>(px, ndc.z, select(-1.0, 1.0, inside));
}

// The host's depth at pixel position `px` (clamped to the target).
fn depth_at(px: vec2<f32>) -> f32 {
    let last = vec2<i32>(depth_view.viewport.xy) - 1;
    return textureLoad(host_depth, clamp(vec2<i32>(floor(px)), vec2<i32>(0), last), 0);
}

// The simulation-space point at pixel position `px` and depth `d`.
fn unproject(px: vec2<f32>, d: f32) -> vec3<f32> {
    let size = depth_view.viewport.xy;
    let ndc = vec3<f32>(px.x / size.x * 2.0 - 1.0, 1.0 - px.y / size.y * 2.0, d);
    let h = depth_view.sim_from_clip * vec4<f32>(ndc, 1.0);
    return h.xyz / h.w;
}

// The depth of the near plane (0, or 1 for reversed Z) and of the clear value (the far
// plane: 1, or 0).
fn near_depth() -> f32 {
    return 0.5 - 0.5 * depth_view.viewport.z;
}

// Where `p` is against the depth: x how far behind the surface it is along its view ray
// (m; negative in front), y 1 when there is a surface there to compare with.
fn behind(p: vec3<f32>) -> vec2<f32> {
    let s = on_screen(p);
    if s.w < 0.0 {
        return vec2<f32>(-1.0, 0.0);
    }
    let d = depth_at(s.xy);
    if d == 1.0 - near_depth() {
        return vec2<f32>(-1.0, 0.0);
    }
    if (s.z - d) * depth_view.viewport.z < 0.0 {
        // In front: how far is not needed.
        return vec2<f32>(-1.0, 1.0);
    }
    return vec2<f32>(distance(p, unproject(s.xy, d)), 1.0);
}

fn is_behind(q: vec2<f32>) -> bool {
    return q.y > 0.5 && q.x >= 0.0;
}

// The surface's unit normal at pixel position `px`, facing the camera.
fn surface_normal(px: vec2<f32>) -> vec3<f32> {
    let size = depth_view.viewport.xy;
    let c = clamp(floor(px), vec2<f32>(0.0), size - 1.0) + 0.5;
    let d0 = depth_at(c);
    let p0 = unproject(c, d0);
    var axes: array<vec3<f32>, 2>;
    for (var a = 0; a < 2; a++) {
        let step = select(vec2<f32>(0.0, 1.0), vec2<f32>(1.0, 0.0), a == 0);
        let fwd = c + step;
        let back = c - step;
        // A neighbour off the target is never the nearer one.
        let dist_fwd = select(1e30, abs(depth_at(fwd) - d0), all(fwd < size));
        let dist_back = select(1e30, abs(depth_at(back) - d0), all(back >= vec2<f32>(0.0)));
        if dist_fwd <= dist_back {
            axes[a] = unproject(fwd, depth_at(fwd)) - p0;
        } else {
            axes[a] = p0 - unproject(back, depth_at(back));
        }
    }
    let ray = p0 - unproject(c, near_depth());
    var n = cross(axes[0], axes[1]);
    if !(dot(n, n) > 1e-30) || !finite_vec3(n) {
        return -normalize(ray);
    }
    n = normalize(n);
    return select(n, -n, dot(n, ray) > 0.0);
}

// The first crossing of the path old → pos behind the depth: x the fraction of the path
// last in front, y the fraction behind (both 0 when the path starts behind), z 1 when
// found.
fn crossing(old_pos: vec3<f32>, pos: vec3<f32>) -> vec3<f32> {
    let a = on_screen(old_pos);
    let b = on_screen(pos);
    var n = DEPTH_MARCH_MAX;
    if a.w > 0.0 && b.w > 0.0 {
        n = clamp(u32(ceil(distance(a.xy, b.xy) * 0.5)), 1u, DEPTH_MARCH_MAX);
    }
    var lo = 0.0;
    var hi = -1.0;
    for (var k = 1u; k <= n; k++) {
        let t = f32(k) / f32(n);
        if is_behind(behind(mix(old_pos, pos, t))) {
            hi = t;
            break;
        }
        lo = t;
    }
    if hi < 0.0 {
        return vec3<f32>(0.0);
    }
    for (var i = 0u; i < DEPTH_REFINE; i++) {
        let mid = 0.5 * (lo + hi);
        if is_behind(behind(mix(old_pos, pos, mid))) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    return vec3<f32>(lo, hi, 1.0);
}

fn depth_collide(old_pos: vec3<f32>, pos: vec3<f32>, vel: vec3<f32>) -> Collided {
    let none = Collided(pos, vel, false, false);
    if depth_view.viewport.w < 0.5 {
        return none;
    }
    let thickness = params.collide_c.y;
    let start = behind(old_pos);
    var contact: vec3<f32>;
    if is_behind(start) {
        if start.x > thickness {
            // Hidden behind the geometry: it flies on.
            return none;
        }
        let s = on_screen(old_pos);
        contact = unproject(s.xy, depth_at(s.xy));
    } else {
        let across = crossing(old_pos, pos);
        if across.z < 0.5 || behind(mix(old_pos, pos, across.y)).x > thickness {
            return none;
        }
        contact = mix(old_pos, pos, across.x);
    }
    let n = surface_normal(on_screen(contact).xy);
    if params.collide_c.z > 0.5 {
        return Collided(contact, vel, true, true);
    }
    // Just in front of the surface, off the depth's rounding.
    let lift = 1e-4 * (1.0 + length(contact - unproject(on_screen(contact).xy, near_depth())));
    return Collided(contact + n * lift, bounce(vel, n), false, is_impact(vel, n));
}
