// count.wgsl — counts alive particles on demand (the stats panel, tests): one invocation
// per slot, a workgroup reduction. Plumbing, not a hook.
//
// Contract: group 0 binding 0 `state` (read), binding 1 `counters` ([0] += alive),
// binding 2 `state_packed` (the same buffer as packed state, read when PACKED is on).
#import "common.wgsl"

@group(0) @binding(0) var<storage, read> state: array<Particle>;
@group(0) @binding(1) var<storage, read_write> counters: array<atomic<u32>, 2>;
@group(0) @binding(2) var<storage, read> state_packed: array<PackedParticle>;

#import "alive_count.wgsl"

override PACKED: bool = false;

@compute @workgroup_size(256)
fn main(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let slot = (wg.y * nwg.x + wg.x) * 256u + lid;
    var alive = false;
    if PACKED {
        alive = slot < arrayLength(&state_packed) && packed_alive(state_packed[slot]);
    } else {
        alive = slot < arrayLength(&state) && is_alive(state[slot]);
    }
    add_alive_in_workgroup(select(0u, 1u, alive), lid);
}
