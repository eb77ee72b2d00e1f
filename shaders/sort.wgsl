// sort.wgsl — back-to-front ordering for alpha-blended emitters: depth keys, then a
// bitonic sort of (key, slot) pairs over a power-of-two array. Only built and run when an
// emitter blends with alpha; additive fire needs no order.
//
// Contract:
// - `depth_keys`: group 0: 0 `step`, 1 `keys`, 2 `values`, 3 `members` (the instances
//   sorted together: a batch's pools are segments of one buffer); group 1: 0 `cur`
//   particles, 1 `cur_packed`. Element i of the sort is instance k = i / window.x, and
//   for j = i mod window.x < its window's length, slot (first + j) mod capacity of its
//   live window (only slots that can hold a living particle are sorted); its value is
//   the slot's index in the state buffer. Alive slots get key = min(!bits(view depth),
//   0xFFFFFFFE) (farthest first), dead and padding elements 0xFFFFFFFF (last, with value
//   0xFFFFFFFF).
// - The network is split so that most of it runs in workgroup memory:
//   `bitonic_local` sorts 512-element blocks completely (window.z = 0: every stage with
//   k ≤ step.k) or finishes a merge (window.z = 1: stage k = step.k, j = 256 … 1);
//   `bitonic` is one global compare-and-swap stage (k, j ≥ 512), one invocation per
//   element. A sort of n ≤ 512 is one dispatch; 2048 is 6 instead of 66.
#import "common.wgsl"

struct SortStep {
    k: u32,
    j: u32,
    // Power-of-two element count, and the emitter's capacity (slots beyond are padding).
    count: u32,
    capacity: u32,
    // The camera position and forward axis in the emitter's simulation space (w unused;
    // the state layout is STATE_LAYOUT below).
    eye: vec4<f32>,
    forward: vec4<f32>,
    // x: elements per instance (the widest window), y: instances, z: local mode (0 sort,
    // 1 merge), w: unused.
    window: vec4<u32>,
}

// One instance of the sort.
struct SortMember {
    // The camera position in the instance's simulation space (w unused).
    eye: vec4<f32>,
    // x: first slot of its live window, y: the window's length, z: where its segment
    // starts in the state buffer, w: unused.
    window: vec4<u32>,
}

// Storage, not uniform: see params.wgsl (lavapipe's uniform inlining).
@group(0) @binding(0) var<storage, read> step: SortStep;
@group(0) @binding(1) var<storage, read_write> keys: array<u32>;
@group(0) @binding(2) var<storage, read_write> values: array<u32>;
@group(0) @binding(3) var<storage, read> members: array<SortMember>;

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

const BLOCK: u32 = 512u;
var<workgroup> block_keys: array<u32, 512>;
var<workgroup> block_values: array<u32, 512>;

// One compare-and-swap per invocation at distance j inside a 512-element block held in
// workgroup memory; `base` is the block's first element (the direction depends on the
// global index).
fn local_stage(base: u32, lid: u32, k: u32, j: u32) {
    let i = ((lid & ~(j - 1u)) << 1u) | (lid & (j - 1u));
    let p = i | j;
    let ascending = ((base + i) & k) == 0u;
    let a = block_keys[i];
    let b = block_keys[p];
    if (a > b) == ascending {
        block_keys[i] = b;
        block_keys[p] = a;
        let v = block_values[i];
        block_values[i] = block_values[p];
        block_values[p] = v;
    }
}

@compute @workgroup_size(256)
fn bitonic_local(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let base = (wg.y * nwg.x + wg.x) * BLOCK;
    // Elements past `count` (a sort shorter than a block) are padding, never written.
    for (var h = 0u; h < 2u; h++) {
        let e = lid + h * 256u;
        var key = 0xFFFFFFFFu;
        var value = 0u;
        if base + e < step.count {
            key = keys[base + e];
            value = values[base + e];
        }
        block_keys[e] = key;
        block_values[e] = value;
    }
    if step.window.z == 0u {
        for (var k = 2u; k <= min(step.k, BLOCK); k <<= 1u) {
            for (var j = k >> 1u; j > 0u; j >>= 1u) {
                workgroupBarrier();
                local_stage(base, lid, k, j);
            }
        }
    } else {
        for (var j = BLOCK >> 1u; j > 0u; j >>= 1u) {
            workgroupBarrier();
            local_stage(base, lid, step.k, j);
        }
    }
    workgroupBarrier();
    for (var h = 0u; h < 2u; h++) {
        let e = lid + h * 256u;
        if base + e < step.count {
            keys[base + e] = block_keys[e];
            values[base + e] = block_values[e];
        }
    }
}

@group(1) @binding(0) var<storage, read> cur: array<Particle>;
@group(1) @binding(1) var<storage, read> cur_packed: array<PackedParticle>;

// The state layout: 0 full, 1 packed, 2 tiny (both read through `cur_packed`). A pipeline
// constant (one depth-key pipeline per layout), not a branch on the step block: a CPU adapter
// would decode every layout for every key.
override STATE_LAYOUT: u32 = 0u;

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
    // Padding carries no slot (the billboard pass skips 0xFFFFFFFF).
    var index = 0xFFFFFFFFu;
    let width = max(step.window.x, 1u);
    let k = i / width;
    let j = i - k * width;
    if k < step.window.y && j < members[k].window.y {
        let m = members[k];
        var slot = m.window.x + j;
        if slot >= step.capacity {
            slot -= step.capacity;
        }
        index = m.window.z + slot;
        var alive = false;
        var pos = vec3<f32>(0.0);
        if STATE_LAYOUT == 2u {
            // Tiny state (never batched): slots whose age has run out sort among the
            // living; the draw skips them.
            let s = tiny_decode(tiny_bits(cur_packed[slot >> 1u], (slot & 1u) != 0u));
            alive = !s.dead;
            pos = s.pos;
        } else if STATE_LAYOUT == 1u {
            let q = cur_packed[index];
            alive = packed_alive(q);
            pos = bitcast<vec3<f32>>(vec3<u32>(q.px, q.py, q.pz));
        } else {
            let p = cur[index];
            alive = is_alive(p);
            pos = p.pos_age.xyz;
        }
        if alive {
            let depth = max(dot(pos - m.eye.xyz, step.forward.xyz), 0.0);
            // Non-negative floats order like their bits; inverted, the farthest comes first.
            // 0xFFFFFFFF (depth 0: at or behind the eye) is kept for dead and padding
            // slots, which must sort after every living one.
            key = min(~bitcast<u32>(depth), 0xFFFFFFFEu);
        }
    }
    keys[i] = key;
    values[i] = index;
}
