// events.wgsl — the event scan: one parent rule's counts and records (written by the
// parent's update this step, events_on.wgsl) become its child's spawn list, in slot order
// over the parent's window — an exclusive prefix sum of the children per slot, so the list
// is the same whatever the scheduling. Three passes over blocks of BLOCK slots:
// `count_blocks` sums each block's children, `scan_blocks` (one workgroup) turns the sums
// into each block's offset and settles the list's header, `write_list` writes each
// block's entries from its offset. At most `cap` children a step; the rest are counted as
// dropped. The first scan of a step into a child (its header's stamp is an older step's)
// moves the child's ring head past the last step's children and starts an empty list
// stamped with this step's number; each scan appends, so a child fed by several events
// gets them in update order. A child none of whose parents ran this step sees a stale
// stamp and spawns nothing.
//
// Group 0: binding 0 the parent's SimParams (dynamic offset), 1 its event buffer, 2 the
// child's list (header + entries), 3 this rule's ScanConfig, 4 the block sums (scratch:
// word 0 the list position this scan starts at, then one word per block).
// Mirrored by `scan_events` in src/sim/events.rs.
#import "common.wgsl"
#import "params.wgsl"
#import "event_types.wgsl"

struct ScanConfig {
    // The rule's index, the child's capacity, the most children a step, 1 when the
    // children inherit the parent's colour.
    rule_capacity_cap: vec4<u32>,
    // xyz: the parent's simulation origin minus the child's, w: the inherited fraction
    // of the parent's velocity.
    delta_inherit: vec4<f32>,
}

@group(0) @binding(1) var<storage, read> event_out: EventOut;
@group(0) @binding(2) var<storage, read_write> event_in: EventIn;
@group(0) @binding(3) var<uniform> cfg: ScanConfig;
@group(0) @binding(4) var<storage, read_write> blocks: array<u32>;

const GROUP: u32 = 256u;
// Slots per thread and per workgroup (keep in sync with EVENT_SCAN_BLOCK in
// src/sim/events.rs).
const PER_THREAD: u32 = 4u;
const BLOCK: u32 = 1024u;

var<workgroup> sums: array<u32, GROUP>;

// The children of the i-th slot of the parent's window.
fn count_of(i: u32) -> u32 {
    if i >= params.update_window.y {
        return 0u;
    }
    return event_out.words[cfg.rule_capacity_cap.x * params.capacity + window_slot(i)];
}

// The children of one thread's PER_THREAD slots of the window, from the i-th.
fn thread_children(first: u32) -> u32 {
    var n = 0u;
    for (var k = 0u; k < PER_THREAD; k++) {
        n += count_of(first + k);
    }
    return n;
}

fn window_slot(i: u32) -> u32 {
    var slot = params.update_window.x + i;
    if slot >= params.capacity {
        slot -= params.capacity;
    }
    return slot;
}

// An inclusive Hillis–Steele scan of `v` over the workgroup; every thread gets its own.
fn workgroup_inclusive(lid: u32, v: u32) -> u32 {
    sums[lid] = v;
    workgroupBarrier();
    for (var d = 1u; d < GROUP; d *= 2u) {
        var x = sums[lid];
        if lid >= d {
            x += sums[lid - d];
        }
        workgroupBarrier();
        sums[lid] = x;
        workgroupBarrier();
    }
    return sums[lid];
}

fn block_index(wg: vec3<u32>, nwg: vec3<u32>) -> u32 {
    return wg.y * nwg.x + wg.x;
}

@compute @workgroup_size(256)
fn count_blocks(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let b = block_index(wg, nwg);
    if b * BLOCK >= params.update_window.y {
        // A spare workgroup of the 2-D grid.
        return;
    }
    let total = workgroup_inclusive(lid, thread_children(b * BLOCK + lid * PER_THREAD));
    if lid == GROUP - 1u {
        blocks[1u + b] = total;
    }
}

@compute @workgroup_size(256)
fn scan_blocks(@builtin(local_invocation_index) lid: u32) {
    let n_blocks = (params.update_window.y + BLOCK - 1u) / BLOCK;
    var running = 0u;
    for (var base = 0u; base < n_blocks; base += GROUP) {
        let i = base + lid;
        var v = 0u;
        if i < n_blocks {
            v = blocks[1u + i];
        }
        let incl = workgroup_inclusive(lid, v);
        if i < n_blocks {
            blocks[1u + i] = running + incl - v;
        }
        running += sums[GROUP - 1u];
        workgroupBarrier();
    }
    if lid == 0u {
        if event_in.stamp != params.tiny_b.z {
            event_in.head = (event_in.head + event_in.count) % cfg.rule_capacity_cap.y;
            event_in.count = 0u;
            event_in.stamp = params.tiny_b.z;
        }
        blocks[0] = event_in.count;
        let n = min(running, cfg.rule_capacity_cap.z);
        event_in.count += n;
        event_in.dropped += running - n;
        event_in.total += running;
    }
}

@compute @workgroup_size(256)
fn write_list(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let b = block_index(wg, nwg);
    if b * BLOCK >= params.update_window.y {
        return;
    }
    let first = b * BLOCK + lid * PER_THREAD;
    let n = thread_children(first);
    let incl = workgroup_inclusive(lid, n);
    // This thread's first child's place among this scan's children.
    var at = blocks[1u + b] + incl - n;
    let start = blocks[0];
    let cap = cfg.rule_capacity_cap.z;
    let capacity = params.capacity;
    for (var k = 0u; k < PER_THREAD; k++) {
        let c = count_of(first + k);
        if c == 0u {
            continue;
        }
        let r = record_at(cfg.rule_capacity_cap.x, window_slot(first + k), capacity);
        let pos = bitcast<vec3<f32>>(vec3<u32>(event_out.words[r], event_out.words[r + 1u], event_out.words[r + 2u]));
        let vel = bitcast<vec3<f32>>(vec3<u32>(event_out.words[r + 4u], event_out.words[r + 5u], event_out.words[r + 6u]));
        let key = event_out.words[r + 3u];
        // The parent's normalised age to 1/255, and whether the child inherits its colour.
        let t = u32(bitcast<f32>(event_out.words[r + 7u]) * 255.0 + 0.5);
        let color = (t << 16u) | (cfg.rule_capacity_cap.w << 24u);
        for (var j = 0u; j < c && at + j < cap; j++) {
            event_in.list[start + at + j] = EventSpawn(
                vec4<f32>(pos + cfg.delta_inherit.xyz, bitcast<f32>(key)),
                vec4<f32>(vel * cfg.delta_inherit.w, bitcast<f32>(color | j)),
            );
        }
        at += c;
    }
}
