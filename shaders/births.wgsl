// births.wgsl — ages of tiny-state particles from their emitter's birth table. Plumbing,
// not a hook.
//
// Contract: the including file declares `births: array<Birth>` (read-only storage): a
// ring of the steps whose particles may still be alive, oldest first, entry `seq` at
// index seq & mask. `table` = (first sequence number, entries, mask); `oldest` is the
// oldest entry's first counter and `span` the counters from it to the newest spawn (both
// from the uniform, so a lookup starts without a dependent load).
#import "common.wgsl"

// The entry that spawned the particle with spawn counter `c` (low 32 bits), or one with
// `count` = 0 when none did (never spawned, from a step that is surely dead, or from
// before a restart of the pool).
fn birth_entry(c: u32, table: vec3<u32>, oldest: u32, span: u32) -> Birth {
    // Counters relative to the oldest entry's (wrapping: every counter that can be asked
    // about lies within a capacity of the newest, far less than 2^31).
    let d = c - oldest;
    if table.y == 0u || d >= span {
        return Birth(0u, 0u, 0.0, 0.0, 0.0, 0.0, 0.0, 0u);
    }
    // The last entry whose first counter is ≤ c: a guess from the table's mean births per
    // step first (right at a steady rate: two independent loads instead of a search of
    // log2(entries) dependent ones), then a binary search between the bounds it leaves.
    var lo = 0u;
    var hi = table.y;
    let g = min(u32(f32(d) * f32(table.y) / f32(span)), table.y - 1u);
    var b = births[(table.x + g) & table.z];
    let next = births[(table.x + min(g + 1u, table.y - 1u)) & table.z];
    if b.first - oldest <= d {
        lo = g;
        if g + 1u < hi && next.first - oldest > d {
            return b;
        }
    } else {
        hi = g;
    }
    while hi - lo > 1u {
        let mid = (lo + hi) >> 1u;
        if births[(table.x + mid) & table.z].first - oldest <= d {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return births[(table.x + lo) & table.z];
}

// The age at time `now` (double-single: hi, lo) of the particle with counter `c` that
// entry `b` spawned, or −1 when `b` did not spawn it.
fn birth_age(b: Birth, c: u32, now: vec2<f32>) -> f32 {
    let k = c - b.first;
    if k >= b.count {
        return -1.0;
    }
    let f = clamp(b.frac0 + f32(k) * b.frac_step, 0.0, 1.0);
    return (now.x - b.t0_hi) + (now.y - b.t0_lo) - b.dt * f;
}
