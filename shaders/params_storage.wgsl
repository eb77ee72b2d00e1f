// params_storage.wgsl — SimParams as read-only storage: composed in place of
// params.wgsl on CPU adapters (see there).
#import "common.wgsl"

@group(0) @binding(0) var<storage, read> params: SimParams;

// One emitter's pool per dispatch, from slot 0 (params_instanced.wgsl batches instances).
const slot_base: u32 = 0u;
fn select_instance(i: u32) {}
