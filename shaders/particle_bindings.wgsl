// particle_bindings.wgsl — the bindings of every pass that reads the particles as they are
// drawn (billboard.wgsl, tiles.wgsl, splat.wgsl, light.wgsl): group 0 the camera, the
// looks and the ramps (`FrameResources::frame_layout`), group 1 the state buffers
// (`FrameResources::particle_layout`). The including file's own groups start at 2.
#import "common.wgsl"
#import "births.wgsl"
#import "look.wgsl"

@group(0) @binding(0) var<uniform> camera: CameraUniform;
// The looks of the dispatch's or draw's instances (the instance index picks one).
// Storage, not uniform: see params.wgsl (lavapipe's uniform inlining).
@group(0) @binding(1) var<storage, read> looks: array<LookSlot>;
// The look of the instance this invocation reads (look.wgsl reads it).
var<private> look: LookUniform;
@group(0) @binding(2) var ramps: texture_2d<f32>;
@group(1) @binding(0) var<storage, read> prev: array<Particle>;
@group(1) @binding(1) var<storage, read> cur: array<Particle>;
// Back-to-front slot order (sort.wgsl), read only by the alpha-blended pipelines.
@group(1) @binding(2) var<storage, read> order: array<u32>;
// The same state buffers seen as packed state (src/gpu/types.rs `PackedParticle`).
@group(1) @binding(3) var<storage, read> prev_packed: array<PackedParticle>;
@group(1) @binding(4) var<storage, read> cur_packed: array<PackedParticle>;
// A tiny-state emitter's birth table (births.wgsl).
@group(1) @binding(5) var<storage, read> births: array<Birth>;
