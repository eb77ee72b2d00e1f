// alive_count.wgsl — the workgroup reduction shared by update.wgsl and count.wgsl: every
// invocation of the workgroup calls `add_alive_in_workgroup` (uniform control flow, it
// contains a barrier), and one global atomic per workgroup adds the group's total to
// `counters[0]`. The including file declares `counters`.

var<workgroup> wg_alive: atomic<u32>;

fn add_alive_in_workgroup(alive: u32, lid: u32) {
    if alive > 0u {
        atomicAdd(&wg_alive, alive);
    }
    workgroupBarrier();
    if lid == 0u {
        let n = atomicLoad(&wg_alive);
        if n > 0u {
            atomicAdd(&counters[0], n);
        }
    }
}
