// trail_ring.wgsl — a trail's ring, as the update (trail_on.wgsl) or the event scan
// (events.wgsl) writes it and the billboards read it (trail.wgsl). `mode` TRAIL_HISTORY:
// `points` entries per slot, one recorded every `every` steps (xyz: position in simulation
// space, w: the particle's age then), point-major (`ring_entry`). TRAIL_PER_PARENT: one
// entry per slot, its u32 bits (the previous child of the same parent: slot or 0xFFFFFFFF, birth stamp; this
// particle's birth stamp; 0), a stamp being the step's number + 1.
// Keep in sync with src/sim/trails.rs.

const TRAIL_HISTORY: u32 = 0u;
const TRAIL_PER_PARENT: u32 = 1u;

struct TrailRing {
    points: u32,
    every: u32,
    mode: u32,
    pad0: u32,
    history: array<vec4<f32>>,
}

// Where point `r` of `slot` lives in a ring of `slots` slots: point-major (every slot's
// point 0, then every slot's point 1, ...), so that the update's neighbouring invocations
// write whole memory sectors (slot-major, each wrote 16 bytes of its own 64: on an H100 the
// recording steps cost 2.3 times a plain step). A ring per parent has one point per slot.
fn ring_entry(slot: u32, r: u32, slots: u32) -> u32 {
    return r * slots + slot;
}

// The ring entry of point j ≥ 1 of a trail of `points` entries recorded every `every`
// steps, after the step numbered `last`: the newest recording step before that step, then
// `every` steps further back a point (a particle born in the last step filled its whole
// ring, so any entry is its birth point). src/sim/trails.rs `trail_indices` is the same.
fn trail_point_entry(last: u32, j: u32, points: u32, every: u32) -> u32 {
    let before = last - 1u;
    let k = before - before % every;
    return (k / every + points - (j - 1u) % points) % points;
}
