// events.wgsl — the event scan: one parent rule's counts and records (written by the
// parent's update this step, events_on.wgsl) become its child's spawn list, in slot order
// over the parent's window — an exclusive prefix sum of the children per slot, so the list
// is the same whatever the scheduling. Three passes over blocks of BLOCK slots:
// `count_blocks` sums each block's children, `scan_blocks` (one workgroup) turns the sums
// into each block's offset and settles the list's header, `write_list` writes each
// block's entries from its offset. At most what the event's cap allows a step (a bucket of
// tokens refilled at its rate per second, `take_tokens`); the rest are counted as dropped. The first scan of a step into a child (its header's stamp is an older step's)
// moves the child's ring head past the last step's children and starts an empty list
// stamped with this step's number; each scan appends, so a child fed by several events
// gets them in update order. A child none of whose parents ran this step sees a stale
// stamp and spawns nothing.
//
//
// A child drawn as a ribbon per parent (ScanConfig flag RIBBON) is linked as the list is
// written: each child's entry of the child's trail ring gets (the slot and birth stamp of
// the child its parent spawned before it, or none; its own birth stamp), stamps being the
// step's number + 1. The parent's last child is kept per parent slot after the block sums
// and forgotten when the parent slot is born again (BORN_BIT), so a ribbon never joins two
// parents' lives; the draw (trail.wgsl) also checks that the linked slot still holds the
// child it names.
//
// Group 0: binding 0 the parent's SimParams (dynamic offset), 1 its event buffer, 2 the
// child's list (header + entries), 3 this rule's ScanConfig, 4 the scan's scratch (word 0
// the list position this scan starts at, one word per block of the parent's capacity, the
// cap's bucket and this step's allowance, then two words per parent slot: its last child's
// slot and stamp), 5 the child's trail ring (a placeholder unless RIBBON).
// Mirrored by `scan_events` in src/sim/event_scan.rs (the links are read by `Link` in
// src/sim/trails.rs).
#import "common.wgsl"
#import "params.wgsl"
#import "event_types.wgsl"
#import "trail_ring.wgsl"
#import "workgroup_scan.wgsl"

struct ScanConfig {
    // The rule's index, the child's capacity, the child list's room per step, flags
    // (INHERIT_COLOR, RIBBON).
    rule_capacity_cap: vec4<u32>,
    // xyz: the parent's simulation origin minus the child's, w: the inherited fraction
    // of the parent's velocity.
    delta_inherit: vec4<f32>,
    // The event's cap: x children per second, y the burst its bucket holds; zw unused.
    cap: vec4<f32>,
}

@group(0) @binding(1) var<storage, read> event_out: EventOut;
@group(0) @binding(2) var<storage, read_write> event_in: EventIn;
@group(0) @binding(3) var<uniform> cfg: ScanConfig;
@group(0) @binding(4) var<storage, read_write> blocks: array<u32>;
@group(0) @binding(5) var<storage, read_write> ribbon: TrailRing;

// ScanConfig flags (keep in sync with src/sim/event_scan.rs).
const INHERIT_COLOR: u32 = 1u;
const RIBBON: u32 = 2u;
// No previous child.
const NO_LINK: u32 = 0xFFFFFFFFu;

const GROUP: u32 = 256u;
// Slots per thread and per workgroup (keep in sync with EVENT_SCAN_BLOCK in
// src/sim/event_scan.rs).
const PER_THREAD: u32 = 4u;
const BLOCK: u32 = 1024u;


// Where the scratch keeps the cap's bucket (tokens short of full, f32 bits; zero: full)
// and then this step's allowance: after the block sums.
fn bucket_at() -> u32 {
    return 1u + (params.capacity + BLOCK - 1u) / BLOCK;
}

// Takes up to `asked` children from the cap's bucket (src/effect.rs `RateCap::take`, the
// same f32 arithmetic in the same order): a full bucket holds `cfg.cap.y`, the step adds
// `cfg.cap.x · dt` before it takes, what is left is kept. Within the list's room.
fn take_tokens(asked: u32) -> u32 {
    let burst = cfg.cap.y;
    let available = (burst - bitcast<f32>(blocks[bucket_at()])) + cfg.cap.x * params.dt_secs;
    let n = min(min(asked, u32(floor(max(available, 0.0)))), cfg.rule_capacity_cap.z);
    blocks[bucket_at()] = bitcast<u32>(burst - min(available - f32(n), burst));
    return n;
}

// The count word of the i-th slot of the parent's window (its children, BORN_BIT when
// born this step); 0 past the window.
fn slot_word(i: u32) -> u32 {
    if i >= params.update_window.y {
        return 0u;
    }
    return event_out.words[cfg.rule_capacity_cap.x * params.capacity + window_slot(i)];
}

// The children of the i-th slot of the parent's window.
fn count_of(i: u32) -> u32 {
    return slot_word(i) & ~BORN_BIT;
}

// Where parent `slot`'s last child (slot, stamp) is kept in the scratch.
fn last_child_at(slot: u32) -> u32 {
    return bucket_at() + 2u + 2u * slot;
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
    // Each invocation sums a run of consecutive blocks, one workgroup scan places the runs,
    // and each invocation writes its run's offsets: one scan, however many blocks (a scan
    // per 256 blocks was 64 in a row, each with its barriers, at 16.8M slots).
    let per = (n_blocks + GROUP - 1u) / GROUP;
    let first = lid * per;
    let last = min(first + per, n_blocks);
    var sum = 0u;
    for (var i = first; i < last; i++) {
        sum += blocks[1u + i];
    }
    var running = 0u;
    var at = running_exclusive(lid, sum, &running);
    for (var i = first; i < last; i++) {
        let v = blocks[1u + i];
        blocks[1u + i] = at;
        at += v;
    }
    if lid == 0u {
        if event_in.stamp != params.tiny_b.z {
            event_in.head = (event_in.head + event_in.count) % cfg.rule_capacity_cap.y;
            event_in.count = 0u;
            event_in.stamp = params.tiny_b.z;
        }
        blocks[0] = event_in.count;
        let n = take_tokens(running);
        blocks[bucket_at() + 1u] = n;
        event_in.count += n;
        event_in.dropped += running - n;
        event_in.total += running;
    }
}

// Whether write_list's block lies wholly past this step's allowance (set by its first
// invocation, read uniformly by all).
var<workgroup> past_allowance: u32;

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
    // A block whose first child falls past the allowance writes no entry: without ribbons
    // (whose born slots forget their last child in every block) its words are not read.
    // Where deaths outnumber a capped child's room, that is most blocks.
    if lid == 0u {
        let skip = (cfg.rule_capacity_cap.w & RIBBON) == 0u && blocks[1u + b] >= blocks[bucket_at() + 1u];
        past_allowance = select(0u, 1u, skip);
    }
    if workgroupUniformLoad(&past_allowance) != 0u {
        return;
    }
    let first = b * BLOCK + lid * PER_THREAD;
    let n = thread_children(first);
    let incl = workgroup_inclusive(lid, n);
    // This thread's first child's place among this scan's children.
    var at = blocks[1u + b] + incl - n;
    let start = blocks[0];
    // This step's allowance (scan_blocks took it from the cap's bucket).
    let cap = blocks[bucket_at() + 1u];
    let capacity = params.capacity;
    let flags = cfg.rule_capacity_cap.w;
    for (var k = 0u; k < PER_THREAD; k++) {
        let slot = window_slot(first + k);
        let word = slot_word(first + k);
        if (flags & RIBBON) != 0u && (word & BORN_BIT) != 0u {
            blocks[last_child_at(slot)] = NO_LINK;
        }
        let c = word & ~BORN_BIT;
        if c == 0u {
            continue;
        }
        let r = record_at(cfg.rule_capacity_cap.x, slot, capacity);
        let pos = bitcast<vec3<f32>>(vec3<u32>(event_out.words[r], event_out.words[r + 1u], event_out.words[r + 2u]));
        let vel = bitcast<vec3<f32>>(vec3<u32>(event_out.words[r + 4u], event_out.words[r + 5u], event_out.words[r + 6u]));
        let key = event_out.words[r + 3u];
        // The parent's normalised age to 1/255, whether the child inherits its colour, and
        // the number of the event's first child (its children's numbers follow).
        let packed = event_out.words[r + 7u];
        let t = packed & 0xFFu;
        let first = packed >> 8u;
        let color = (t << 16u) | ((flags & INHERIT_COLOR) << 24u);
        for (var j = 0u; j < c && at + j < cap; j++) {
            event_in.list[start + at + j] = EventSpawn(
                vec4<f32>(pos + cfg.delta_inherit.xyz, bitcast<f32>(key)),
                vec4<f32>(vel * cfg.delta_inherit.w, bitcast<f32>(color | ((first + j) & 0xFFFFu))),
            );
        }
        if (flags & RIBBON) != 0u && at < cap {
            link_children(slot, start + at, min(c, cap - at));
        }
        at += c;
    }
}

// Links the `n` children parent `slot` spawns this step, from list entry `entry` on: each
// to the one before it (the first to the parent's last child), and keeps the last.
fn link_children(slot: u32, entry: u32, n: u32) {
    let child_capacity = cfg.rule_capacity_cap.y;
    let stamp = params.tiny_b.z + 1u;
    let kept = last_child_at(slot);
    var prev = vec2<u32>(blocks[kept], blocks[kept + 1u]);
    var child = 0u;
    for (var j = 0u; j < n; j++) {
        child = (event_in.head + entry + j) % child_capacity;
        ribbon.history[child] = bitcast<vec4<f32>>(vec4<u32>(prev, stamp, 0u));
        prev = vec2<u32>(child, stamp);
    }
    blocks[kept] = child;
    blocks[kept + 1u] = stamp;
}
