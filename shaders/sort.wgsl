// sort.wgsl — back-to-front ordering for alpha-blended emitters: depth keys, then a
// bitonic sort of (key, slot) pairs over a power-of-two array. Only built and run when an
// emitter blends with alpha; additive fire needs no order.
//
// Contract:
// - `keys` pass: group 0: 0 `look` (LookUniform of the emitter, dynamic offset),
//   1 `camera`; group 1: 0 `cur` particles, 1 `keys`, 2 `values`. Alive slots get
//   key = !bits(view depth) (farthest first), dead and padding slots 0xFFFFFFFF (last).
// - `bitonic` pass: group 2: 0 `step` ({k, j}), 1 `keys`, 2 `values`; one invocation per
//   element, compare-and-swap with element i ^ j.
#import "common.wgsl"

struct SortStep {
    k: u32,
    j: u32,
    // Power-of-two element count, and the emitter's capacity (slots beyond are padding).
    count: u32,
    capacity: u32,
    // The camera position and forward axis in the emitter's simulation space; eye.w: 1
    // when the state is packed (read through `cur_packed`).
    eye: vec4<f32>,
    forward: vec4<f32>,
}

@group(0) @binding(0) var<uniform> step: SortStep;
@group(0) @binding(1) var<storage, read_write> keys: array<u32>;
@group(0) @binding(2) var<storage, read_write> values: array<u32>;

@compute @workgroup_size(256)
fn bitonic(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let i = (wg.y * nwg.x + wg.x) * 256u + lid;
    let partner = i ^ step.j;
    if i >= step.count || partner <= i || partner >= step.count {
        return;
    }
    let ascending = (i & step.k) == 0u;
    let a = keys[i];
    let b = keys[partner];
    if (a > b) == ascending {
        keys[i] = b;
        keys[partner] = a;
        let v = values[i];
        values[i] = values[partner];
        values[partner] = v;
    }
}

@group(1) @binding(0) var<storage, read> cur: array<Particle>;
@group(1) @binding(1) var<storage, read> cur_packed: array<PackedParticle>;

@compute @workgroup_size(256)
fn depth_keys(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let i = (wg.y * nwg.x + wg.x) * 256u + lid;
    if i >= step.count {
        return;
    }
    var key = 0xFFFFFFFFu;
    if i < step.capacity {
        var alive = false;
        var pos = vec3<f32>(0.0);
        if step.eye.w > 0.5 {
            let q = cur_packed[i];
            alive = packed_alive(q);
            pos = vec3<f32>(q.px, q.py, q.pz);
        } else {
            let p = cur[i];
            alive = is_alive(p);
            pos = p.pos_age.xyz;
        }
        if alive {
            let depth = max(dot(pos - step.eye.xyz, step.forward.xyz), 0.0);
            // Non-negative floats order like their bits; inverted, the farthest comes first.
            key = ~bitcast<u32>(depth);
        }
    }
    keys[i] = key;
    values[i] = i;
}
