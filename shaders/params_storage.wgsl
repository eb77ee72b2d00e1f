// params_storage.wgsl — SimParams as read-only storage: composed in place of
// params.wgsl on CPU adapters (see there).
#import "common.wgsl"

@group(0) @binding(0) var<storage, read> params: SimParams;
