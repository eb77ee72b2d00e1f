// trail_on.wgsl — the update's trail hook: each particle's last positions in a ring of
// `points` entries (xyz: position in the emitter's simulation space, w: the particle's
// age then), group 1 binding 2. Point-major (trail_ring.wgsl `ring_entry`): neighbouring
// invocations write neighbouring entries, whole memory sectors.
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
    let slots = arrayLength(&trail.history) / max(n, 1u);
    let at = slot_base + slot;
    let point = p.pos_age;
    if born {
        for (var i = 0u; i < n; i++) {
            trail.history[ring_entry(at, i, slots)] = point;
        }
        return;
    }
    let step = params.tiny_b.z;
    if step % trail.every == 0u {
        trail.history[ring_entry(at, (step / trail.every) % n, slots)] = point;
    }
}
