// params.wgsl — the update pass's per-step parameters (SimParams, one block per emitter
// and step at a dynamic offset): a uniform buffer. A runtime player's batched instances
// compose `params_instanced.wgsl` in its place (an array of blocks in storage).
#import "common.wgsl"

@group(0) @binding(0) var<uniform> params: SimParams;

// One emitter's pool per dispatch, from slot 0 (params_instanced.wgsl batches instances).
const slot_base: u32 = 0u;
fn select_instance(i: u32) {}
