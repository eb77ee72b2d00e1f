// params.wgsl — the update pass's per-step parameters (SimParams, one block per emitter
// and step at a dynamic offset): a uniform buffer, the fast path on GPUs.
//
// On CPU adapters `params_storage.wgsl` is composed in its place (read-only storage):
// lavapipe inlines uniform values that steer branches into the shader and recompiles it
// on every bind of a new offset. Keep the two declarations the same but for the space.
#import "common.wgsl"

@group(0) @binding(0) var<uniform> params: SimParams;

// One emitter's pool per dispatch, from slot 0 (params_instanced.wgsl batches instances).
const slot_base: u32 = 0u;
fn select_instance(i: u32) {}
