// tile_lists.wgsl — the tile rasteriser's lists per tile (imported by tiles.wgsl). Each
// bin's list (its sprites in draw order, each with the tiles of the bin it covers) is split
// into one list per 16×16 tile, in the same order, so that a tile's shade reads exactly
// its own sprites instead of filtering the bin's. Three passes over chunks of 256 entries
// of the bins' lists: count per chunk and tile (`tiles_count`), place every tile's list and
// each chunk's part of it within its bin's lists (`tiles_scan`), place the bins' lists one
// after another (`tiles_starts`), write (`tiles_scatter`). The order within a chunk
// comes from bit masks (an entry's place is the bits before its own): deterministic, no
// atomics on the order. A bin with a short list, or whose tile lists do not fit, is shaded
// from its bin list.
//
// Contract: the bindings and `meta_*` of tiles.wgsl. `bin_meta` holds, after the bins'
// starts, the words the `tl_*` functions place; `job.counts2.w` is the chunks' capacity;
// `dispatch_args` slot MAX_ITEMS holds the chunk passes' arguments (`bin_starts`).

// Entries per chunk (one per invocation).
const CHUNK: u32 = 256u;
// Bins with shorter lists are shaded from them (each tile filters a few chunks): their
// tile lists would cost more than they save.
const TL_MIN_ENTRIES: u32 = 4096u;
// `tl_bin_start` of a bin without tile lists.
const TL_NONE: u32 = 0xFFFFFFFFu;

fn tl_base() -> u32 {
    return meta_start(bin_count()) + 1u;
}

// The first chunk of bin b (b = bins: the chunks in all).
fn tl_chunk_first(b: u32) -> u32 {
    return tl_base() + b;
}

// Where bin b's tile lists start among the tile list entries.
fn tl_bin_start(b: u32) -> u32 {
    return tl_base() + bin_count() + 1u + b;
}

// Tile t of bin b (row-major in the bin): its entries.
fn tl_tile_total(b: u32, t: u32) -> u32 {
    return tl_base() + 2u * bin_count() + 1u + b * 64u + t;
}

// Tile t of bin b: where its list starts within the bin's lists.
fn tl_tile_local(b: u32, t: u32) -> u32 {
    return tl_base() + 66u * bin_count() + 1u + b * 64u + t;
}

// Chunk g's entries over tile t of its bin.
fn tl_chunk_count(g: u32, t: u32) -> u32 {
    return tl_base() + 130u * bin_count() + 1u + g * 64u + t;
}

// Where chunk g's entries over tile t go in the tile's list.
fn tl_chunk_offset(g: u32, t: u32) -> u32 {
    return tl_chunk_count(job.counts2.w + g, t);
}

// Tile list entry i (a sprite).
fn tl_entry(i: u32) -> u32 {
    return tl_chunk_count(2u * job.counts2.w, 0u) + i;
}

// Entries the tile lists hold.
fn tl_capacity() -> u32 {
    return arrayLength(&bin_meta) - tl_entry(0u);
}

// Bin b's tile list entries in all (its last tile's list ends there).
fn tl_bin_entries(b: u32) -> u32 {
    return bin_meta[tl_tile_local(b, 63u)] + bin_meta[tl_tile_total(b, 63u)];
}

// Whether bin b has tile lists, all written.
fn tile_lists_fit(b: u32) -> bool {
    let start = bin_meta[tl_bin_start(b)];
    let entries = tl_bin_entries(b);
    return start != TL_NONE && entries <= tl_capacity() && start <= tl_capacity() - entries;
}

// The chunks of each complete bin list of TL_MIN_ENTRIES or more (after `bin_starts`
// placed the lists) and the chunk passes' dispatch arguments. Every invocation of the
// workgroup calls it.
fn count_chunks(lid: u32) {
    let chunks = scan_bins(lid, SCAN_CHUNKS);
    if lid == 0u {
        bin_meta[tl_chunk_first(bin_count())] = chunks;
        atomicStore(&dispatch_args[4u * MAX_ITEMS], min(chunks, 256u));
        atomicStore(&dispatch_args[4u * MAX_ITEMS + 1u], (chunks + 255u) / 256u);
        atomicStore(&dispatch_args[4u * MAX_ITEMS + 2u], 1u);
    }
}

// The bin chunk g belongs to: the last with its first chunk at or before g.
fn chunk_bin(g: u32) -> u32 {
    var lo = 0u;
    var hi = bin_count();
    while hi - lo > 1u {
        let mid = (lo + hi) / 2u;
        if bin_meta[tl_chunk_first(mid)] <= g {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return lo;
}

// Per tile of the chunk's bin, a bit per entry of the chunk over it.
var<workgroup> tile_bits: array<atomic<u32>, 512>;

// One entry of a chunk: its bin, the entry (sprite, tiles) and the tiles it covers.
struct ChunkEntry {
    b: u32,
    valid: bool,
    entry: vec2<u32>,
    tiles: vec4<u32>,
}

// The chunk this workgroup reads (workgroups 256 across), or none past the last.
fn chunk_of(wg: vec3<u32>, lid: u32) -> u32 {
    if lid == 0u {
        shared_count = bin_meta[tl_chunk_first(bin_count())];
    }
    return select(0xFFFFFFFFu, wg.y * 256u + wg.x, wg.y * 256u + wg.x < workgroupUniformLoad(&shared_count));
}

// Reads entry `lid` of chunk g and marks the tiles it covers in `tile_bits`. Every
// invocation of the workgroup calls it.
fn mark_chunk(g: u32, lid: u32) -> ChunkEntry {
    atomicStore(&tile_bits[lid], 0u);
    atomicStore(&tile_bits[lid + 256u], 0u);
    if lid == 0u {
        shared_bin = chunk_bin(g);
    }
    var c: ChunkEntry;
    c.b = workgroupUniformLoad(&shared_bin);
    let at = (g - bin_meta[tl_chunk_first(c.b)]) * CHUNK + lid;
    c.valid = at < bin_meta[meta_total(c.b)];
    if c.valid {
        c.entry = bin_lists[bin_meta[meta_start(c.b)] + at];
        c.tiles = (vec4<u32>(c.entry.y) >> vec4<u32>(0u, 3u, 6u, 9u)) & vec4<u32>(7u);
        for (var y = c.tiles.y; y <= c.tiles.w; y++) {
            for (var x = c.tiles.x; x <= c.tiles.z; x++) {
                atomicOr(&tile_bits[(y * BIN_TILES + x) * 8u + lid / 32u], 1u << (lid % 32u));
            }
        }
    }
    workgroupBarrier();
    return c;
}

// Counts, for one chunk (workgroup), its entries over each tile of its bin.
@compute @workgroup_size(256)
fn tiles_count(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let g = chunk_of(wg, lid);
    if g == 0xFFFFFFFFu {
        return;
    }
    let c = mark_chunk(g, lid);
    if lid < 64u {
        var n = 0u;
        for (var w = 0u; w < 8u; w++) {
            n += countOneBits(atomicLoad(&tile_bits[lid * 8u + w]));
        }
        bin_meta[tl_chunk_count(g, lid)] = n;
    }
}

var<workgroup> tile_part: array<u32, 256>;

// Places, for one bin (workgroup), each tile's list (the bin's tiles one after another, at
// room handed out for the bin) and each chunk's part of it: four invocations per tile,
// each summing a quarter of the bin's chunks.
@compute @workgroup_size(256)
fn tiles_scan(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let b = wg.x;
    let t = lid % 64u;
    let r = lid / 64u;
    let first = bin_meta[tl_chunk_first(b)];
    if lid == 0u {
        shared_count = bin_meta[tl_chunk_first(b + 1u)] - first;
    }
    let n = workgroupUniformLoad(&shared_count);
    if n == 0u {
        // No tile lists: the bin's tiles filter its list.
        if lid == 0u {
            bin_meta[tl_bin_start(b)] = TL_NONE;
        }
        return;
    }
    let lo = first + n * r / 4u;
    let hi = first + n * (r + 1u) / 4u;
    var sum = 0u;
    for (var g = lo; g < hi; g++) {
        sum += bin_meta[tl_chunk_count(g, t)];
    }
    tile_part[lid] = sum;
    workgroupBarrier();
    var running = 0u;
    for (var q = 0u; q < r; q++) {
        running += tile_part[q * 64u + t];
    }
    for (var g = lo; g < hi; g++) {
        bin_meta[tl_chunk_offset(g, t)] = running;
        running += bin_meta[tl_chunk_count(g, t)];
    }
    workgroupBarrier();
    if r == 3u {
        tile_part[t] = running;
    }
    workgroupBarrier();
    if lid == 0u {
        var at = 0u;
        for (var k = 0u; k < 64u; k++) {
            bin_meta[tl_tile_local(b, k)] = at;
            bin_meta[tl_tile_total(b, k)] = tile_part[k];
            at += tile_part[k];
        }
        // Listed: `tiles_starts` places it.
        bin_meta[tl_bin_start(b)] = 0u;
    }
}

// Places the bins' tile lists one after another, in bin order (one workgroup): bins past
// the lists' capacity keep their places and are shaded from their bin lists
// (`tile_lists_fit`), the same bins whatever the scheduling.
@compute @workgroup_size(256)
fn tiles_starts(@builtin(local_invocation_index) lid: u32) {
    scan_bins(lid, SCAN_TILE_LISTS);
}

// Writes one chunk's (workgroup) entries into the lists of the tiles they cover, each at
// its place: the chunk's part of the tile's list, then the entries of the chunk before it
// over the same tile.
@compute @workgroup_size(256)
fn tiles_scatter(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let g = chunk_of(wg, lid);
    if g == 0xFFFFFFFFu {
        return;
    }
    let c = mark_chunk(g, lid);
    if !c.valid {
        return;
    }
    let start = bin_meta[tl_bin_start(c.b)];
    let w = lid / 32u;
    let below = (1u << (lid % 32u)) - 1u;
    for (var y = c.tiles.y; y <= c.tiles.w; y++) {
        for (var x = c.tiles.x; x <= c.tiles.z; x++) {
            let t = y * BIN_TILES + x;
            var rank = countOneBits(atomicLoad(&tile_bits[t * 8u + w]) & below);
            for (var i = 0u; i < w; i++) {
                rank += countOneBits(atomicLoad(&tile_bits[t * 8u + i]));
            }
            let at = start + bin_meta[tl_tile_local(c.b, t)] + bin_meta[tl_chunk_offset(g, t)] + rank;
            if at < tl_capacity() {
                bin_meta[tl_entry(at)] = c.entry.x;
            }
        }
    }
}

// The first of `count` tile list entries from `start` (sorted) at or above sprite `v`.
fn tl_lower_bound(start: u32, count: u32, v: u32) -> u32 {
    var lo = 0u;
    var hi = count;
    while lo < hi {
        let mid = (lo + hi) / 2u;
        if bin_meta[tl_entry(start + mid)] < v {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    return lo;
}

// The job's item's run of tile t of bin b's list: (first entry, entries). The list is in
// sprite order, items one after another.
fn tl_item_run(b: u32, t: u32) -> vec2<u32> {
    let start = bin_meta[tl_bin_start(b)] + bin_meta[tl_tile_local(b, t)];
    let count = bin_meta[tl_tile_total(b, t)];
    var lo = 0u;
    var hi = count;
    if job.counts2.x > 0u {
        lo = tl_lower_bound(start, count, job.counts.x);
    }
    if job.counts2.x + 1u < job.counts2.y {
        hi = tl_lower_bound(start, count, job.counts.x + job.counts.y);
    }
    return vec2<u32>(start + lo, hi - lo);
}
