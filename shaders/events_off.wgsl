// events_off.wgsl — the update's event hooks compiled out: no bindings, no code. The
// update composes this file unless the emitter has events or spawns from them (then
// events_on.wgsl takes its place), so an emitter without events runs exactly the update
// it ran before events existed.
#import "common.wgsl"

override MOD_EVENTS: bool = false;
override MOD_EVENT_SPAWN: bool = false;

struct EventBirth {
    born: bool,
    p: Particle,
}

fn event_birth(slot: u32) -> EventBirth {
    return EventBirth(false, Particle(vec4<f32>(0.0), vec4<f32>(0.0)));
}

fn emit_events(slot: u32, p: Particle, born: bool, was_alive: bool, alive: bool, hit: bool, age_start: f32) {}
