// params_instanced.wgsl — composed in place of params.wgsl for a runtime player's batched
// instances: one dispatch updates the same emitter of many instances (workgroup z is the
// instance), each with its own SimParams (its seed, place, clock and ring) and its own
// segment of the shared state buffers (`capacity` slots from `slot_base`).
#import "common.wgsl"

@group(0) @binding(0) var<storage, read> params_all: array<SimParams>;
var<private> params: SimParams;
var<private> slot_base: u32;

fn select_instance(i: u32) {
    params = params_all[i];
    slot_base = i * params.capacity;
}
