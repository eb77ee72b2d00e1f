// births.wgsl — ages of tiny-state particles from their emitter's birth table. Plumbing,
// not a hook.
//
// Contract: the including file declares `births: array<Birth>` (read-only storage): a
// ring of the steps whose particles may still be alive, oldest first, entry `seq` at
// index seq & mask. `table` = (first sequence number, entries, mask).
#import "common.wgsl"

// The age at time `now` (double-single: hi, lo) of the particle with spawn counter `c`
// (low 32 bits), or −1 when no step of the table spawned it (never spawned, or from a step
// that is surely dead, or from before a restart of the pool).
fn birth_age(c: u32, now: vec2<f32>, table: vec3<u32>) -> f32 {
    if table.y == 0u {
        return -1.0;
    }
    // Counters relative to the oldest entry's (wrapping: every counter that can be asked
    // about lies within a capacity of the newest, far less than 2^31).
    let oldest = births[table.x & table.z].first;
    let d = c - oldest;
    // The last entry whose first counter is ≤ c: first a guess from the table's mean
    // births per step (right at a steady rate, so about three loads instead of a search
    // of log2(entries)), then a binary search between the bounds it leaves.
    var lo = 0u;
    var hi = table.y;
    let newest = births[(table.x + table.y - 1u) & table.z];
    let span = max(newest.first + newest.count - oldest, 1u);
    let g = min(u32(f32(d) * f32(table.y) / f32(span)), table.y - 1u);
    if births[(table.x + g) & table.z].first - oldest <= d {
        lo = g;
        if g + 1u < hi && births[(table.x + g + 1u) & table.z].first - oldest > d {
            hi = g + 1u;
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
    let b = births[(table.x + lo) & table.z];
    let k = c - b.first;
    if k >= b.count {
        return -1.0;
    }
    let f = clamp(b.frac0 + f32(k) * b.frac_step, 0.0, 1.0);
    return (now.x - b.t0_hi) + (now.y - b.t0_lo) - b.dt * f;
}
