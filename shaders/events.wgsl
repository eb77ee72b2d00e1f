// events.wgsl — the event scan: one workgroup turns one parent rule's records (written by
// the parent's update this step, events_on.wgsl) into its child's spawn list, in slot
// order over the parent's window: an exclusive prefix sum of the children per slot, so
// the list is the same whatever the scheduling. At most `cap` children a step; the rest
// are counted as dropped. The first scan of a step into a child (its header's stamp is an
// older step's) moves the child's ring head past the last step's children and starts an
// empty list stamped with this step's number; each scan appends its children, so a child
// fed by several events gets them in update order. A child none of whose parents ran this
// step sees a stale stamp and spawns nothing.
//
// Group 0: binding 0 the parent's SimParams (dynamic offset), 1 its event records, 2 the
// child's list (header + entries), 3 this rule's ScanConfig.
// Mirrored by `scan_events` in src/sim/events.rs.
#import "common.wgsl"
#import "params.wgsl"
#import "event_types.wgsl"

struct ScanConfig {
    // The rule's index in the parent's records, the child's capacity, the most children
    // a step, unused.
    rule_capacity_cap: vec4<u32>,
    // xyz: the parent's simulation origin minus the child's, w: the inherited fraction
    // of the parent's velocity.
    delta_inherit: vec4<f32>,
}

@group(0) @binding(1) var<storage, read> event_out: EventOut;
@group(0) @binding(2) var<storage, read_write> event_in: EventIn;
@group(0) @binding(3) var<uniform> cfg: ScanConfig;

const GROUP: u32 = 256u;
var<workgroup> sums: array<u32, GROUP>;
var<workgroup> running: u32;
// Where this scan's children start in the list (after earlier scans' of this step).
var<workgroup> start: u32;

@compute @workgroup_size(256)
fn main(@builtin(local_invocation_index) lid: u32) {
    let first = params.update_window.x;
    let len = params.update_window.y;
    let capacity = params.capacity;
    let rule = cfg.rule_capacity_cap.x;
    let cap = cfg.rule_capacity_cap.z;
    if lid == 0u {
        if event_in.stamp != params.tiny_b.z {
            event_in.head = (event_in.head + event_in.count) % cfg.rule_capacity_cap.y;
            event_in.count = 0u;
            event_in.stamp = params.tiny_b.z;
        }
        start = event_in.count;
    }
    workgroupBarrier();
    let first_entry = workgroupUniformLoad(&start);
    for (var base = 0u; base < len; base += GROUP) {
        let i = base + lid;
        var n = 0u;
        var rec = EventRecord(vec4<f32>(0.0), vec4<f32>(0.0));
        if i < len {
            var slot = first + i;
            if slot >= capacity {
                slot -= capacity;
            }
            rec = event_out.records[rule * capacity + slot];
            n = bitcast<u32>(rec.pos_count.w);
        }
        // Inclusive scan of the chunk (Hillis–Steele).
        sums[lid] = n;
        workgroupBarrier();
        for (var d = 1u; d < GROUP; d *= 2u) {
            var v = sums[lid];
            if lid >= d {
                v += sums[lid - d];
            }
            workgroupBarrier();
            sums[lid] = v;
            workgroupBarrier();
        }
        let at = running + sums[lid] - n;
        for (var k = 0u; k < n && at + k < cap; k++) {
            event_in.list[first_entry + at + k] = EventSpawn(
                vec4<f32>(rec.pos_count.xyz + cfg.delta_inherit.xyz, rec.vel_key.w),
                vec4<f32>(rec.vel_key.xyz * cfg.delta_inherit.w, bitcast<f32>(k)),
            );
        }
        let chunk = sums[GROUP - 1u];
        workgroupBarrier();
        if lid == 0u {
            running += chunk;
        }
        workgroupBarrier();
    }
    if lid == 0u {
        let total = running;
        let n = min(total, cap);
        event_in.count = first_entry + n;
        event_in.dropped += total - n;
        event_in.total += total;
    }
}
