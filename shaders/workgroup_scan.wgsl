// workgroup_scan.wgsl — prefix sums over a workgroup of 256 invocations (a raking scan in
// workgroup memory: 16 rows of 16), shared by the event scan (events.wgsl) and the tiles'
// binning (tiles.wgsl).

// The values, row r's k-th at r · 17 + k: one pad word per row, so the 16 invocations
// that each walk a row touch 16 different banks at every step.
var<workgroup> sums: array<u32, 272>;
// The rows' totals, then their exclusive offsets.
var<workgroup> row_offsets: array<u32, 16>;

// Where invocation `lid`'s value is kept.
fn scan_cell(lid: u32) -> u32 {
    return lid + lid / 16u;
}

// The inclusive sum of `v` over invocations 0..=lid; every invocation of the workgroup
// must call it. `workgroup_total()` then holds the total (read it before the next call).
fn workgroup_inclusive(lid: u32, v: u32) -> u32 {
    sums[scan_cell(lid)] = v;
    workgroupBarrier();
    // Sixteen invocations each scan a row in place…
    if lid < 16u {
        var acc = 0u;
        for (var k = 0u; k < 16u; k++) {
            acc += sums[lid * 17u + k];
            sums[lid * 17u + k] = acc;
        }
        row_offsets[lid] = acc;
    }
    workgroupBarrier();
    // …one turns the rows' totals into their offsets…
    if lid == 0u {
        var acc = 0u;
        for (var r = 0u; r < 16u; r++) {
            let t = row_offsets[r];
            row_offsets[r] = acc;
            acc += t;
        }
    }
    workgroupBarrier();
    // …and each invocation adds its row's. Each reads only its own cell, so the last one
    // writes the total back in place.
    let sum = sums[scan_cell(lid)] + row_offsets[lid / 16u];
    if lid == 255u {
        sums[scan_cell(255u)] = sum;
    }
    workgroupBarrier();
    return sum;
}

// The total of the last `workgroup_inclusive`.
fn workgroup_total() -> u32 {
    return sums[scan_cell(255u)];
}

// One chunk of a running exclusive scan over many chunks of 256: the place of `v` after
// `*running` and the earlier invocations' values; `*running` grows by the chunk's total.
// Every invocation calls it with the same `*running`.
fn running_exclusive(lid: u32, v: u32, running: ptr<function, u32>) -> u32 {
    let at = *running + workgroup_inclusive(lid, v) - v;
    *running += workgroup_total();
    workgroupBarrier();
    return at;
}
