// trail_off.wgsl — the update's trail hook compiled out: no binding, no code (the update
// composes trail_on.wgsl in its place for an emitter with a trail).
#import "common.wgsl"

override MOD_TRAIL: bool = false;

fn record_trail(slot: u32, p: Particle, born: bool, alive: bool) {}
