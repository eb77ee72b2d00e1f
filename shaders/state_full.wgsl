// state_full.wgsl — how the update pass reads and writes particles: 32-byte `Particle`s
// (common.wgsl). Plumbing, not a hook. The `packed_state` option composes update.wgsl
// with state_packed.wgsl in this file's place (same bindings, 20-byte elements), so the
// full-state pipeline holds no trace of the packed one.
//
// Contract: group 0 binding 1 `src` (state before the step, read), 2 `dst` (written).

@group(0) @binding(1) var<storage, read> src: array<Particle>;
@group(0) @binding(2) var<storage, read_write> dst: array<Particle>;

// Set for every pipeline (src/sim/modules.rs); only state_packed.wgsl is packed.
override MOD_PACKED: bool = false;
override MOD_TINY: bool = false;
// One slot per store (state_tiny.wgsl pairs them): the pair hooks do nothing.
const PAIRED_STATE: bool = false;

fn begin_pair(k: u32) {}

fn end_pair(k: u32) {}

// `slot_base`: where this pool's segment starts (params.wgsl: 0).
fn load_state(slot: u32) -> Particle {
    return src[slot_base + slot];
}

fn store_state(slot: u32, p: Particle) {
    dst[slot_base + slot] = p;
}
