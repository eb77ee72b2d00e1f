// trail_ring.wgsl — a trail's ring of positions, as the update writes it (trail_on.wgsl)
// and the billboards read it (trail.wgsl): `points` entries per slot, one recorded every
// `every` steps (xyz: position in simulation space, w: the particle's age then).
// Keep in sync with src/sim/trails.rs.

struct TrailRing {
    points: u32,
    every: u32,
    pad0: u32,
    pad1: u32,
    history: array<vec4<f32>>,
}
