// collide.wgsl — ground plane and sphere colliders, applied after each integration step.
//
// Contract: `collide(old_pos, state)` returns the corrected state and whether the
// particle was killed by contact. The test is on the segment old → new position
// (Latta's predicted-position test), so a fast particle cannot tunnel through a sphere;
// the plane is a half-space, so nothing ends below it. The normal velocity is reflected
// and scaled by the elasticity, the tangential one scaled by (1 − friction); below the
// rest speed the normal velocity is zeroed so resting particles do not jitter.
#import "common.wgsl"

override MOD_COLLISIONS: bool = false;

struct Collided {
    pos: vec3<f32>,
    vel: vec3<f32>,
    killed: bool,
    // An impact: the particle touched a collider moving into it faster than the rest
    // speed (beyond what the constant acceleration adds in one step: a particle resting
    // on the ground is not hitting it at every step, whatever the step), or was killed
    // by it (a collision event fires).
    hit: bool,
}

// Whether touching a collider of normal `n` at velocity `vel` is an impact.
fn is_impact(vel: vec3<f32>, n: vec3<f32>) -> bool {
    let settle = max(0.0, -dot(params.accel_drag.xyz, n)) * params.dt_secs;
    return -dot(vel, n) > params.collide_b.x + settle;
}

fn bounce(vel: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    if params.collide_c.x > 0.5 {
        // Stick: stop at the contact.
        return vec3<f32>(0.0);
    }
    let elasticity = params.ground.y;
    let friction = params.ground.z;
    let vn = dot(vel, n);
    if vn >= 0.0 {
        return vel;
    }
    let tangent = (vel - vn * n) * max(0.0, 1.0 - friction);
    var out_n = -vn * elasticity;
    if out_n < params.collide_b.x {
        out_n = 0.0;
    }
    return tangent + out_n * n;
}

fn collide(old_pos: vec3<f32>, pos_in: vec3<f32>, vel_in: vec3<f32>) -> Collided {
    var pos = pos_in;
    var vel = vel_in;
    var impact = false;
    let count = u32(params.collide_b.y);
    for (var i = 0u; i < min(count, 4u); i++) {
        let s = params.spheres[i];
        let d = pos - old_pos;
        let f = old_pos - s.xyz;
        let r2 = s.w * s.w;
        // First hit of the segment old + t·d (t in [0, 1]) with the sphere, or "ends inside".
        let a = dot(d, d);
        let b = dot(f, d);
        let c = dot(f, f) - r2;
        var hit = dot(pos - s.xyz, pos - s.xyz) < r2;
        var t_hit = 1.0;
        if a > 1e-12 && c > 0.0 {
            let disc = b * b - a * c;
            if disc >= 0.0 {
                let t = (-b - sqrt(disc)) / a;
                if t >= 0.0 && t <= 1.0 {
                    hit = true;
                    t_hit = t;
                }
            }
        }
        if hit {
            if params.collide_b.z > 0.5 {
                return Collided(pos, vel, true, true);
            }
            let contact = select(pos, old_pos + d * t_hit, c > 0.0);
            var n = contact - s.xyz;
            let len = length(n);
            n = select(vec3<f32>(0.0, 1.0, 0.0), n / len, len > 1e-6);
            impact = impact || is_impact(vel, n);
            pos = s.xyz + n * (s.w * 1.0001);
            vel = bounce(vel, n);
        }
    }
    if params.collide_b.w > 0.5 && pos.y < params.ground.x {
        if params.ground.w > 0.5 {
            return Collided(pos, vel, true, true);
        }
        impact = impact || is_impact(vel, vec3<f32>(0.0, 1.0, 0.0));
        pos.y = params.ground.x;
        vel = bounce(vel, vec3<f32>(0.0, 1.0, 0.0));
    }
    return Collided(pos, vel, false, impact);
}
