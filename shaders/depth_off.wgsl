// depth_off.wgsl — the update's depth collision compiled out: no bindings, no code. The
// update composes this file unless the emitter collides with the host's depth buffer (then
// depth_on.wgsl takes its place).
#import "collide.wgsl"

fn depth_collide(old_pos: vec3<f32>, pos: vec3<f32>, vel: vec3<f32>) -> Collided {
    return Collided(pos, vel, false, false);
}
