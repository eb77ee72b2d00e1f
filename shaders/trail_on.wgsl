// trail_on.wgsl — the update's trail hook: each particle's last positions in a ring of
// `points` entries (xyz: position in the emitter's simulation space, w: the particle's
// age then), group 1 binding 2.
//
// Contract (read by trail.wgsl when the billboards draw the ribbon):
// - A particle born this step fills its whole ring with its birth point, so a ribbon never
//   reaches into the slot's previous particle's life.
// - Every `every` steps (the step number `params.tiny_b.z` a multiple of it), entry
//   (step / every) mod points takes the particle's position after the step.
#import "common.wgsl"
#import "trail_ring.wgsl"

override MOD_TRAIL: bool = false;

@group(1) @binding(2) var<storage, read_write> trail: TrailRing;

fn record_trail(slot: u32, p: Particle, born: bool, alive: bool) {
    if !MOD_TRAIL || !alive {
        return;
    }
    let n = trail.points;
    let base = (slot_base + slot) * n;
    let point = p.pos_age;
    if born {
        for (var i = 0u; i < n; i++) {
            trail.history[base + i] = point;
        }
        return;
    }
    let step = params.tiny_b.z;
    if step % trail.every == 0u {
        trail.history[base + (step / trail.every) % n] = point;
    }
}
