// workgroup_scan.wgsl — prefix sums over a workgroup of 256 invocations (Hillis–Steele
// in workgroup memory), shared by the event scan (events.wgsl) and the
// tiles' binning (tiles.wgsl).

var<workgroup> sums: array<u32, 256>;

// The inclusive sum of `v` over invocations 0..=lid; every invocation of the workgroup
// must call it. `sums[255]` then holds the total (read it before the next call).
fn workgroup_inclusive(lid: u32, v: u32) -> u32 {
    sums[lid] = v;
    workgroupBarrier();
    for (var d = 1u; d < 256u; d *= 2u) {
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

// One chunk of a running exclusive scan over many chunks of 256: the place of `v` after
// `*running` and the earlier invocations' values; `*running` grows by the chunk's total.
// Every invocation calls it with the same `*running`.
fn running_exclusive(lid: u32, v: u32, running: ptr<function, u32>) -> u32 {
    let at = *running + workgroup_inclusive(lid, v) - v;
    *running += sums[255];
    workgroupBarrier();
    return at;
}
