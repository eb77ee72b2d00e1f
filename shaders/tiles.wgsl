// tiles.wgsl — pass 2, large sprites on the compute units: a tile rasteriser. The quads
// the billboards would draw (quad.wgsl builds both) are projected once, binned into
// 128-pixel bins in draw order — counted per block of sprites, scanned into each list's
// place, then written (`bin_count_blocks`, `bin_scan`, `bin_starts`, `bin`: memory and
// work in proportion to the sprites' footprints, no atomics on the order) — and each
// 16×16-pixel tile is shaded by one workgroup (a dense bin's list split first into a list
// per tile, tile_lists.wgsl):
// the sprites over it, in order, blended in registers — premultiplied "over" for
// alpha-blended layers (back to front, the sort's order), added for light — and the
// tile's colour and coverage written once per emitter. A full-screen draw in the
// host's pass composites the result: dst · T + C.
//
// Contract:
// - groups 0 and 1: particle_bindings.wgsl (camera, looks, ramps; the state and the sort's order).
// - group 2: the emitter's sprite and sampler (shade).
// - group 3 (compute): 0 `sprites` (one TileSprite per quad of the frame's tile items),
//   2 `bin_lists` (per bin, the sprites over it in draw order, one list after another,
//   `job.counts.w` entries in all), 3 `bin_meta` (the counts and scans, `meta_*`, then the
//   tiles' lists, `tl_*`), 4 `accum` (per pixel: C.rg, C.b and the coverage
//   1 − T as f16 pairs; valid in the tiles shaded this frame only), 1 `touched` (the
//   resolve's draw arguments, a flag per tile, the list of tiles shaded this frame, each
//   item's list of bins), 5 `scene_depth` (the host's depth, when
//   its size is the viewport's), 6 `job` (this dispatch's item: dynamic offset).
// - The resolve (a render pipeline): group 0 as above, group 1: 0 `accum_in`, 1
//   `touched_in` (the same buffers, read-only). The compute resolve (`resolve_over`, where
//   the adapter can): the same, and group 2 binding 2 `resolve_image`, the target.
// - DEPTH_TEST: as splat.wgsl (0 none, 1 nearer or level passes, 2 reversed Z).
#import "common.wgsl"
#import "sprite_project.wgsl"
#import "workgroup_scan.wgsl"
#import "tile_lists.wgsl"

#import "particle_bindings.wgsl"
@group(2) @binding(0) var sprite_tex: texture_2d<f32>;
@group(2) @binding(1) var sprite_sampler: sampler;
@group(3) @binding(0) var<storage, read_write> sprites: array<TileSprite>;
@group(3) @binding(1) var<storage, read_write> touched: array<atomic<u32>>;
// A bin list entry: x the sprite, y the first and last tile of the bin it covers (x0, y0,
// x1, y1, 3 bits each).
@group(3) @binding(2) var<storage, read_write> bin_lists: array<vec2<u32>>;
@group(3) @binding(3) var<storage, read_write> bin_meta: array<u32>;
@group(3) @binding(4) var<storage, read_write> accum: array<vec2<u32>>;
@group(3) @binding(5) var scene_depth: texture_depth_2d;
@group(3) @binding(6) var<storage, read> job: TileJob;
// The bin passes only: each item's shade dispatch arguments (x: its bins, y: 64 tiles
// each, z: 1), the indirect arguments of the shade; then (slot MAX_ITEMS) the tile lists'
// chunk passes' (`count_chunks`).
@group(3) @binding(7) var<storage, read_write> dispatch_args: array<atomic<u32>>;
// The resolve's view of `accum` and `touched`.
@group(1) @binding(0) var<storage, read> accum_in: array<vec2<u32>>;
@group(1) @binding(1) var<storage, read> touched_in: array<u32>;
// The compute resolve's target (the HDR image, read and written in place).
@group(2) @binding(2) var resolve_image: texture_storage_2d<rgba16float, read_write>;

override DEPTH_TEST: u32 = 0u;
// The adapter's blending rounds f16 toward zero (lavapipe), not to nearest.
override F16_ROUND_DOWN: bool = false;

// Pixels per tile side (one workgroup each) and tiles per bin side (keep in sync with
// src/render/tiles.rs).
const TILE: u32 = 16u;
const BIN_TILES: u32 = 8u;
const BIN: u32 = 128u;
// Tile items a frame holds at most (keep in sync with src/render/tiles.rs).
const MAX_ITEMS: u32 = 55u;
// `touched`: the draw arguments (4), then a flag per tile, then the shaded tiles' list.
const TOUCHED_FLAGS: u32 = 4u;
// Sprites a bin workgroup lists (keep in sync with src/render/tiles.rs); each item's
// sprites start at a multiple of it, so that a block holds one item's.
const BLOCK: u32 = 1024u;
// Bins a target holds at most (keep in sync with src/render/tiles.rs).
const MAX_BINS: u32 = 2048u;

// One dispatch's work, an item of the chunk (an emitter's quads, or a piece of them where
// a frame's sprites are drawn in chunks): x the item's first sprite, y its quads, z
// sprites this chunk (each item's rounded up to whole blocks), w the capacity of the bin
// lists (entries); `counts2`: the item's index, the items, the blocks of BLOCK sprites,
// the chunks the tile lists' passes read at most; `base.x`: the item's first quad of its
// emitter's; `firsts`: every item's first sprite, then the chunk's sprites.
struct TileJob {
    counts: vec4<u32>,
    counts2: vec4<u32>,
    base: vec4<u32>,
    firsts: array<vec4<u32>, 14>,
}

// Item k's first sprite (k = items: the frame's sprite count).
fn item_first(k: u32) -> u32 {
    return job.firsts[k >> 2u][k & 3u];
}

// Projects quad `q` of the job's item into sprite `job.counts.x + q`: its map, colour,
// frames and pixel bounds (empty when it draws nothing). Written once, the projective
// fields only for a projective map.
@compute @workgroup_size(256)
fn project(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let q = (wg.y * nwg.x + wg.x) * 256u + lid;
    let index = job.counts.x + q;
    // A lit item's sprites are followed by their six-way light (`lit_record`).
    let records = select(job.counts.y, 2u * job.counts.y, LIT);
    if q >= job.counts.y {
        // The rest of the item's last block: no sprite.
        if q >= records && q < (records + BLOCK - 1u) / BLOCK * BLOCK {
            sprites[index].bounds = vec4<i32>(1, 1, 0, 0);
        }
        return;
    }
    // The particle is loaded once for both records.
    let qd = load_quad(job.base.x + q);
    if LIT {
        lit_record(qd, index + job.counts.y);
    }
    let s = project_quad(qd);
    sprites[index].bounds = s.bounds;
    if s.bounds.x > s.bounds.z {
        return;
    }
    sprites[index].map = s.map;
    sprites[index].offset = s.offset;
    sprites[index].uv_box = s.uv_box;
    sprites[index].color = s.color;
    sprites[index].frames = s.frames;
    sprites[index].grad = s.grad;
    if SOFT {
        sprites[index].ground = s.ground;
    }
    // A projective map's rows; a turned camera-facing sprite's snapped corners.
    if s.offset.z != 2.0 {
        sprites[index].map_z = s.map_z;
        sprites[index].z_row = s.z_row;
    }
    if s.offset.z == 0.0 {
        sprites[index].w_row = s.w_row;
    }
}

// Writes lit quad `qd`'s six-way light (lit.wgsl, packed) into sprite `at`: a record
// with no pixels (the bins skip it) in five of its fields, read by `sprite_light`.
fn lit_record(qd: Quad, at: u32) {
    sprites[at].bounds = vec4<i32>(1, 1, 0, 0);
    if !qd.d.alive {
        return;
    }
    let l = quad_sixway(qd);
    sprites[at].map = l[0];
    sprites[at].offset = l[1];
    sprites[at].uv_box = l[2];
    sprites[at].color = l[3];
    sprites[at].frames = l[4];
}


var<workgroup> bits: array<atomic<u32>, 8>;
// The shade's hits waiting for a batch: fewer than CACHE carried over plus a chunk's.
var<workgroup> hits: array<u32, 320>;
var<workgroup> shared_total: u32;
var<workgroup> shared_count: u32;
var<workgroup> shared_flag: u32;
// The sprite cache of the shade: the fields the pixels read of up to CACHE sprites.
const CACHE: u32 = 64u;
var<workgroup> cache_map: array<vec4<f32>, 64>;
var<workgroup> cache_offset: array<vec4<f32>, 64>;
var<workgroup> cache_box: array<vec4<f32>, 64>;
var<workgroup> cache_color: array<vec4<f32>, 64>;
var<workgroup> cache_frames: array<vec4<f32>, 64>;
var<workgroup> cache_grad: array<vec4<f32>, 64>;
var<workgroup> cache_ground: array<vec4<f32>, 64>;
var<workgroup> cache_bounds: array<vec4<i32>, 64>;

// Reads sprite `i`'s fields into slot `k` of the cache.
fn cache_sprite(k: u32, i: u32) {
    cache_map[k] = sprites[i].map;
    cache_offset[k] = sprites[i].offset;
    cache_box[k] = sprites[i].uv_box;
    cache_color[k] = sprites[i].color;
    cache_frames[k] = sprites[i].frames;
    cache_grad[k] = sprites[i].grad;
    if SOFT {
        cache_ground[k] = sprites[i].ground;
    }
    cache_bounds[k] = sprites[i].bounds;
}
var<workgroup> shared_bin: u32;
var<workgroup> item_hit: array<atomic<u32>, 64>;

// An order-keeping compaction over the workgroup: how many invocations before `lid` have
// `hit`; `shared_total` gets their number (read it with workgroupUniformLoad). Every
// invocation of the workgroup must call it; one bit per invocation, two barriers.
fn compact(lid: u32, hit: bool) -> u32 {
    if lid < 8u {
        atomicStore(&bits[lid], 0u);
    }
    workgroupBarrier();
    let w = lid >> 5u;
    if hit {
        atomicOr(&bits[w], 1u << (lid & 31u));
    }
    workgroupBarrier();
    var before = countOneBits(atomicLoad(&bits[w]) & ((1u << (lid & 31u)) - 1u));
    for (var i = 0u; i < w; i++) {
        before += countOneBits(atomicLoad(&bits[i]));
    }
    if lid == 255u {
        shared_total = before + u32(hit);
    }
    return before;
}

// Whether pixel rectangle `a` (x0, y0, x1, y1, inclusive; empty when x0 > x1 or y0 > y1)
// overlaps the non-empty `b`.
fn overlaps(a: vec4<i32>, b: vec4<i32>) -> bool {
    return all(a.xy <= a.zw) && all(a.xy <= b.zw) && all(b.xy <= a.zw);
}

// `bin_meta`, per frame: the entries of each bin and block (bin-major), then their place
// in the bin's list, then each bin's entries, then where each bin's list starts in
// `bin_lists` (and, after the last bin, every list's end).
fn meta_count(b: u32, c: u32) -> u32 {
    return b * job.counts2.z + c;
}

fn meta_local(b: u32, c: u32) -> u32 {
    return (bin_count() + b) * job.counts2.z + c;
}

fn meta_total(b: u32) -> u32 {
    return 2u * bin_count() * job.counts2.z + b;
}

fn meta_start(b: u32) -> u32 {
    return 2u * bin_count() * job.counts2.z + bin_count() + b;
}

// The bins a sprite's pixel rectangle covers (x0, y0, x1, y1; empty when x0 > x1).
fn bins_of(r: vec4<i32>) -> vec4<u32> {
    if r.x > r.z || r.y > r.w {
        return vec4<u32>(1u, 1u, 0u, 0u);
    }
    return vec4<u32>(r) / BIN;
}

var<workgroup> hist: array<atomic<u32>, MAX_BINS>;

// Counts, for one block of BLOCK sprites (workgroup x), the block's sprites over each bin.
@compute @workgroup_size(256)
fn bin_count_blocks(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let c = wg.x;
    let bins = bin_count();
    let bins_x = (u32(camera.viewport.x) + BIN - 1u) / BIN;
    for (var b = lid; b < bins; b += 256u) {
        atomicStore(&hist[b], 0u);
    }
    workgroupBarrier();
    let end = min((c + 1u) * BLOCK, job.counts.z);
    for (var i = c * BLOCK + lid; i < end; i += 256u) {
        let r = bins_of(sprites[i].bounds);
        for (var y = r.y; y <= r.w; y++) {
            for (var x = r.x; x <= r.z; x++) {
                atomicAdd(&hist[y * bins_x + x], 1u);
            }
        }
    }
    workgroupBarrier();
    for (var b = lid; b < bins; b += 256u) {
        bin_meta[meta_count(b, c)] = atomicLoad(&hist[b]);
    }
}


// One bin (workgroup x): each block's place in the bin's list (an exclusive scan of the
// counts in block order) and the bin's entries; each item with sprites over the bin adds
// the bin to its shade (its indirect dispatch: one workgroup row per bin, one workgroup
// per tile).
@compute @workgroup_size(256)
fn bin_scan(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let b = wg.x;
    let blocks = job.counts2.z;
    if lid < 64u {
        atomicStore(&item_hit[lid], 0u);
    }
    var running = 0u;
    for (var base = 0u; base < blocks; base += 256u) {
        let c = base + lid;
        var v = 0u;
        if c < blocks {
            v = bin_meta[meta_count(b, c)];
        }
        let at = running_exclusive(lid, v, &running);
        if c < blocks {
            bin_meta[meta_local(b, c)] = at;
            if v > 0u {
                atomicOr(&item_hit[item_of(c * BLOCK)], 1u);
            }
        }
    }
    if lid == 0u {
        bin_meta[meta_total(b)] = running;
    }
    if lid < job.counts2.y && atomicLoad(&item_hit[lid]) != 0u {
        let slot = atomicAdd(&dispatch_args[4u * lid], 1u);
        atomicStore(&touched[item_bins(lid) + slot], b);
    }
}

// Where each bin's list starts: an exclusive scan of the bins' entries (one workgroup);
// then the chunks of the tile lists' passes.
@compute @workgroup_size(256)
fn bin_starts(@builtin(local_invocation_index) lid: u32) {
    let entries = scan_bins(lid, SCAN_LISTS);
    if lid == 0u {
        bin_meta[meta_start(bin_count())] = entries;
    }
    count_chunks(lid);
}

// What `scan_bins` scans: the bins' list entries (into `meta_start`), the chunks of the
// tile lists' passes (into `tl_chunk_first`), the bins' tile list entries (into
// `tl_bin_start`, listed bins only).
const SCAN_LISTS: u32 = 0u;
const SCAN_CHUNKS: u32 = 1u;
const SCAN_TILE_LISTS: u32 = 2u;

// Bin b's value for the scan `what`, and whether its place is written.
fn scan_value(what: u32, b: u32) -> vec2<u32> {
    switch what {
        case SCAN_LISTS: {
            return vec2<u32>(bin_meta[meta_total(b)], 1u);
        }
        case SCAN_CHUNKS: {
            // Complete lists of TL_MIN_ENTRIES or more only.
            let n = bin_meta[meta_total(b)];
            let listed = n >= TL_MIN_ENTRIES && bin_meta[meta_start(b)] + n <= job.counts.w;
            return vec2<u32>(select(0u, (n + CHUNK - 1u) / CHUNK, listed), 1u);
        }
        default: {
            let listed = bin_meta[tl_bin_start(b)] != TL_NONE;
            return vec2<u32>(select(0u, tl_bin_entries(b), listed), u32(listed));
        }
    }
}

// An exclusive scan over the bins of `scan_value(what, ·)` (one workgroup; every
// invocation calls it): each bin's place written where `what` says; returns the total.
fn scan_bins(lid: u32, what: u32) -> u32 {
    let bins = bin_count();
    var running = 0u;
    for (var base = 0u; base < bins; base += 256u) {
        let b = base + lid;
        var v = vec2<u32>(0u);
        if b < bins {
            v = scan_value(what, b);
        }
        let at = running_exclusive(lid, v.x, &running);
        if v.y != 0u {
            switch what {
                case SCAN_LISTS: {
                    bin_meta[meta_start(b)] = at;
                }
                case SCAN_CHUNKS: {
                    bin_meta[tl_chunk_first(b)] = at;
                }
                default: {
                    bin_meta[tl_bin_start(b)] = at;
                }
            }
        }
    }
    return running;
}

// Lists, for one bin and one block of BLOCK sprites (workgroup z) with some over the bin,
// the block's sprites over the bin in draw order (an order-keeping compaction:
// deterministic, whatever the scheduling) at the place the scans gave the block. A list
// past the lists' capacity is not written: the shade then reads the bin's sprites
// directly.
@compute @workgroup_size(256)
fn bin(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let b = wg.y * nwg.x + wg.x;
    let c = wg.z;
    if lid == 0u {
        shared_count = bin_meta[meta_count(b, c)];
    }
    if workgroupUniformLoad(&shared_count) == 0u {
        return;
    }
    let lo = vec2<i32>(wg.xy * BIN);
    let rect = vec4<i32>(lo, lo + i32(BIN) - 1);
    let start = c * BLOCK;
    let end = min(start + BLOCK, job.counts.z);
    let region = bin_meta[meta_start(b)] + bin_meta[meta_local(b, c)];
    var count = 0u;
    for (var base = start; base < end; base += 256u) {
        let i = base + lid;
        var r = vec4<i32>(1, 1, 0, 0);
        if i < end {
            r = sprites[i].bounds;
        }
        let hit = overlaps(r, rect);
        let at = compact(lid, hit);
        if hit && region + count + at < job.counts.w {
            // The tiles of this bin it covers ride along: the shade tests them without
            // reading the sprite.
            let t = vec4<u32>(clamp((r - vec4<i32>(lo, lo)) / i32(TILE), vec4<i32>(0), vec4<i32>(i32(BIN_TILES) - 1)));
            bin_lists[region + count + at] = vec2<u32>(i, t.x | (t.y << 3u) | (t.z << 6u) | (t.w << 9u));
        }
        count += workgroupUniformLoad(&shared_total);
    }
}

// The item sprite `i` belongs to (a search of the items' first sprites).
fn item_of(i: u32) -> u32 {
    var lo = 0u;
    var hi = job.counts2.y;
    while hi - lo > 1u {
        let mid = (lo + hi) / 2u;
        if item_first(mid) <= i {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return lo;
}

// Bins across the target.
fn bin_count() -> u32 {
    return ((u32(camera.viewport.x) + BIN - 1u) / BIN) * ((u32(camera.viewport.y) + BIN - 1u) / BIN);
}

// Where item k's list of bins is in `touched`, after the resolve's arguments, the tile
// flags and the tile list.
fn item_bins(k: u32) -> u32 {
    return TOUCHED_FLAGS + 2u * tile_count() + k * bin_count();
}

// Tiles across the target.
fn tile_count() -> u32 {
    return ((u32(camera.viewport.x) + TILE - 1u) / TILE) * ((u32(camera.viewport.y) + TILE - 1u) / TILE);
}


// Whether a sprite at NDC depth `z` is in front of the host's geometry at pixel `p`.
fn visible(p: vec2<i32>, z: f32) -> bool {
    let dims = textureDimensions(scene_depth);
    if DEPTH_TEST == 0u || dims.x != u32(camera.viewport.x) || dims.y != u32(camera.viewport.y) {
        return true;
    }
    let d = textureLoad(scene_depth, p, 0);
    return select(z >= d, z <= d, DEPTH_TEST == 1u);
}

// Sprite `i` (cached in slot `k` of the workgroup's sprite cache) at pixel `p`: its
// premultiplied colour and coverage (zero where it draws nothing).
fn sprite_light(i: u32, k: u32, p: vec2<i32>) -> vec4<f32> {
    // Outside the pixel rectangle the quad's centres lie in: nothing (most of a tile, for
    // small sprites; whole warps skip the rest).
    let r = cache_bounds[k];
    if any(p < r.xy) || any(p > r.zw) {
        return vec4<f32>(0.0);
    }
    let pc = vec2<f32>(p) + 0.5;
    let ca = cache_map[k];
    let cb = cache_offset[k];
    var sp: SpritePoint;
    if cb.z != 0.0 {
        sp = affine_point(ca, cb, pc);
    } else {
        sp = projective_point(ca, cb, sprites[i].map_z, sprites[i].z_row, sprites[i].w_row, pc);
    }
    var outside = box_outside(sp, pc, cb, cache_box[k]);
    if near_box_edge(sp, cb, cache_box[k]) {
        // Near a turned sprite's edge: the rasteriser's own decision, in integers.
        let covers = quad_covers(sprites[i].map_z, sprites[i].z_row, pc);
        outside = select(outside, covers == 0, covers >= 0);
    }
    if outside || depth_misses(sp, p) {
        return vec4<f32>(0.0);
    }
    let grad = cache_grad[k];
    let ddx = sp.ddx * grad.xy;
    let ddy = sp.ddy * grad.xy;
    let frames = cache_frames[k];
    let color = cache_color[k];
    var a: f32;
    var rgb: vec3<f32>;
    if LIT {
        let c = lit_light(i, sp.uv * grad.xy, frames, grad.z, ddx, ddy);
        a = color.a * c.a;
        rgb = c.rgb + color.rgb * c.w;
    } else {
        let tex = sprite_texel(sp.uv * grad.xy, frames, grad.z, ddx, ddy);
        a = color.a * tex.a;
        rgb = color.rgb * tex.rgb;
    }
    if SOFT || SOFT_DEPTH {
        let fade = soft_fade(p, sp.uv, sp.z, cache_ground[k], grad.w);
        a *= fade;
        rgb *= fade;
    }
    return vec4<f32>(rgb, a);
}

// Lit sprite `i`'s texel at `uv` (frame coordinates with the atlas scale applied;
// `frames`: the two frames' atlas offsets, `next` the second's weight), under the
// six-way light of its record (`lit_record`).
fn lit_light(i: u32, uv: vec2<f32>, frames: vec4<f32>, next: f32, ddx: vec2<f32>, ddy: vec2<f32>) -> LitTexel {
    let r = sprites[i + job.counts.y];
    let l = array<vec4<f32>, 5>(r.map, r.offset, r.uv_box, r.color, r.frames);
    let half = vec2<f32>(0.5, 1.0);
    let dx = ddx * half;
    let dy = ddy * half;
    var rtba = textureSampleGrad(sprite_tex, sprite_sampler, rtba_uv(uv + frames.xy), dx, dy);
    var lbfe = textureSampleGrad(sprite_tex, sprite_sampler, lbfe_uv(uv + frames.xy), dx, dy);
    if FLIPBOOK && FLIP_BLEND {
        rtba = mix(rtba, textureSampleGrad(sprite_tex, sprite_sampler, rtba_uv(uv + frames.zw), dx, dy), next);
        lbfe = mix(lbfe, textureSampleGrad(sprite_tex, sprite_sampler, lbfe_uv(uv + frames.zw), dx, dy), next);
    }
    return LitTexel(sixway_rgb(l, rtba, lbfe), rtba.a, lbfe.a);
}

// A lit sprite's texel: its lit colour, coverage and emissive mask (premultiplied).
struct LitTexel {
    rgb: vec3<f32>,
    a: f32,
    w: f32,
}

// Light `c` (premultiplied colour, coverage) blended into `acc` (rgb: premultiplied colour,
// a: coverage, 1 − the transmittance); no light leaves `acc` as it is.
fn blend(acc: vec4<f32>, c: vec4<f32>) -> vec4<f32> {
    var out = vec4<f32>(acc.rgb + c.rgb, acc.a);
    if SORTED {
        out = vec4<f32>(acc.rgb * (1.0 - c.a) + c.rgb, acc.a + c.a * (1.0 - acc.a));
    }
    // Rounded to f16 after every sprite, as the billboards' blending stores each one into
    // the f16 target: faint light on bright pixels is kept or lost as the billboards' is.
    return vec4<f32>(to_f16(out.rg), to_f16(out.ba));
}

// Lane groups of the shade: 32 invocations (a warp on most GPUs), 8×4 pixels of the tile.
const GROUP: u32 = 32u;

// The top-left pixel of lane group `g` of the tile at `origin` (two groups across, four
// down).
fn group_corner(origin: vec2<i32>, g: u32) -> vec2<i32> {
    return origin + vec2<i32>(i32(g % 2u) * 8, i32(g / 2u) * 4);
}
// Per lane group, the cached sprites over its pixels (CACHE bits).
var<workgroup> group_masks: array<atomic<u32>, 16>;

// Shades a batch: hits `at`..`at + count` (count ≤ CACHE) read into the sprite cache, each
// lane group listing the sprites over its pixels, then blended into `acc` at pixel `p` of
// the tile at `origin`, in order. Every invocation calls it; its last reads of the cache
// need a barrier before the cache is written again.
fn shade_batch(lid: u32, count: u32, at: u32, origin: vec2<i32>, p: vec2<i32>, inside: bool, acc: vec4<f32>) -> vec4<f32> {
    if lid < count {
        cache_sprite(lid, hits[at + lid]);
    }
    if lid < 16u {
        atomicStore(&group_masks[lid], 0u);
    }
    workgroupBarrier();
    // Lane l of group g tests sprites l and l + 32 against the group's pixels.
    let g = lid / GROUP;
    let corner = group_corner(origin, g);
    let block = vec4<i32>(corner, corner + vec2<i32>(7, 3));
    for (var k = lid % GROUP; k < count; k += GROUP) {
        if overlaps(cache_bounds[k], block) {
            atomicOr(&group_masks[2u * g + k / 32u], 1u << (k % 32u));
        }
    }
    workgroupBarrier();
    if !inside {
        return acc;
    }
    let low = shade_listed(atomicLoad(&group_masks[2u * g]), 0u, at, p, acc);
    return shade_listed(atomicLoad(&group_masks[2u * g + 1u]), 32u, at, p, low);
}

// The cached sprites of `mask` (bit k: cache slot `first + k`, hit `at + first + k`)
// blended into `acc` at pixel `p` in order, one at a time. One sprite's light in the loop
// (not four fetched together) keeps the shade's registers few and the GPU's occupancy
// high: on an H200 the shade of 100 distant torches took 1.7 ms against 2.7 with four
// (bench/results/tiles-shade/).
fn shade_listed(mask: u32, first: u32, at: u32, p: vec2<i32>, acc_in: vec4<f32>) -> vec4<f32> {
    var acc = acc_in;
    var m = mask;
    while m != 0u {
        acc = blend(acc, next_light(&m, first, at, p));
    }
    return acc;
}

// The light at `p` of the first sprite of `*m` (not empty), taken off `*m`.
fn next_light(m: ptr<function, u32>, first: u32, at: u32, p: vec2<i32>) -> vec4<f32> {
    let k = first + firstTrailingBit(*m);
    *m &= *m - 1u;
    return sprite_light(hits[at + k], k, p);
}
// Non-negative values rounded to f16 as the adapter's blending stores them: to nearest,
// or toward zero where F16_ROUND_DOWN says (lavapipe).
fn to_f16(v: vec2<f32>) -> vec2<f32> {
    var bits = pack2x16float(v);
    if !F16_ROUND_DOWN {
        return unpack2x16float(bits);
    }
    let p = unpack2x16float(bits);
    if p.x > v.x && (bits & 0xFFFFu) != 0u {
        bits -= 1u;
    }
    if p.y > v.y && (bits >> 16u) != 0u {
        bits -= 0x10000u;
    }
    return unpack2x16float(bits);
}

// Shades one tile with the job's item: its sprites over the tile, in draw order, into the
// tile's pixels of `accum`.
@compute @workgroup_size(16, 16)
fn shade(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    // Workgroup (x, y): tile y of the x-th bin holding some of this item's sprites.
    let bins_x = (u32(camera.viewport.x) + BIN - 1u) / BIN;
    if lid == 0u {
        shared_bin = atomicLoad(&touched[item_bins(job.counts2.x) + wg.x]);
    }
    let b = workgroupUniformLoad(&shared_bin);
    // This tile within its bin, and across the target.
    let local = vec2<u32>(wg.y % BIN_TILES, wg.y / BIN_TILES);
    let tile_xy = vec2<u32>(b % bins_x, b / bins_x) * BIN_TILES + local;
    let tiles_x = (u32(camera.viewport.x) + TILE - 1u) / TILE;
    if tile_xy.x >= tiles_x || tile_xy.y * TILE >= u32(camera.viewport.y) {
        return;
    }
    // The item's sprites.
    let first = job.counts.x;
    let end = first + job.counts.y;
    if end == first {
        return;
    }
    let origin = vec2<i32>(tile_xy * TILE);
    let p = group_corner(origin, lid / GROUP) + vec2<i32>(i32(lid % 8u), i32(lid / 8u % 4u));
    let inside = all(vec2<f32>(p) < camera.viewport.xy);
    let pixel = u32(p.y) * u32(camera.viewport.x) + u32(p.x);
    // A tile no earlier item shaded starts empty: `accum` is not cleared between frames,
    // and only shaded tiles are read (here and by the resolve).
    let t = tile_xy.y * tiles_x + tile_xy.x;
    if lid == 0u {
        shared_flag = atomicLoad(&touched[TOUCHED_FLAGS + t]);
    }
    let earlier = workgroupUniformLoad(&shared_flag) != 0u;
    var acc = vec4<f32>(0.0);
    if inside && earlier {
        let v = accum[pixel];
        acc = vec4<f32>(unpack2x16float(v.x), unpack2x16float(v.y));
    }
    // The item's entries in the bin's list: its blocks', one after another. A bin whose
    // list did not fit the lists' capacity is shaded from the item's sprites directly
    // (slower, never a sprite lost).
    let c0 = first / BLOCK;
    let c1 = (end - 1u) / BLOCK;
    let overflow = bin_meta[meta_start(b + 1u)] > job.counts.w;
    if lid == 0u {
        let before = bin_meta[meta_local(b, c0)];
        shared_bin = bin_meta[meta_start(b)] + before;
        shared_count = select(bin_meta[meta_local(b, c1)] + bin_meta[meta_count(b, c1)] - before, end - first, overflow);
        // Where the bin's tile lists were written: the tile's own list.
        shared_flag = u32(!overflow && tile_lists_fit(b));
        if shared_flag != 0u {
            let run = tl_item_run(b, wg.y);
            shared_bin = run.x;
            shared_count = run.y;
        }
    }
    let listed = workgroupUniformLoad(&shared_flag) != 0u;
    let region = workgroupUniformLoad(&shared_bin);
    let n = workgroupUniformLoad(&shared_count);
    var shaded: Shaded;
    if listed {
        shaded = Shaded(shade_tile_run(lid, region, n, origin, p, inside, acc), n > 0u);
    } else {
        let run = BinRun(region, overflow, first, local);
        shaded = shade_bin_run(lid, n, run, origin, p, inside, acc);
    }
    if inside && shaded.any {
        accum[pixel] = vec2<u32>(pack2x16float(shaded.acc.rg), pack2x16float(shaded.acc.ba));
    }
    list_shaded_tile(lid, shaded.any, t);
}

// A tile's pixel after the item's sprites, and whether any sprite was over the tile.
struct Shaded {
    acc: vec4<f32>,
    any: bool,
}

// The item's run of a bin's list as a tile filters it: entries from `region` of
// `bin_lists`, or (`overflow`: the list did not fit) the item's sprites from `first`;
// `local`: the tile within the bin.
struct BinRun {
    region: u32,
    overflow: bool,
    first: u32,
    local: vec2<u32>,
}

// The item's sprites over the tile at `origin` blended into `acc` at pixel `p`, found by
// filtering the `n` entries (or sprites) of the bin's run chunk by chunk (an
// order-keeping compaction) and shaded batch by batch. Every invocation of the workgroup
// calls it with the same `n`.
fn shade_bin_run(lid: u32, n: u32, run: BinRun, origin: vec2<i32>, p: vec2<i32>, inside: bool, acc_in: vec4<f32>) -> Shaded {
    var acc = acc_in;
    var shaded = false;
    // Hits waiting in `hits` (the same in every invocation).
    var pending = 0u;
    let tile_rect = vec4<i32>(origin, origin + i32(TILE) - 1);
    // The next chunk's entry is read while this one is shaded (its latency hidden).
    var next = vec2<u32>(0u);
    if !run.overflow && lid < n {
        next = bin_lists[run.region + lid];
    }
    for (var base = 0u; base < n; base += 256u) {
        // The chunk's sprites of this item over this tile, in order.
        let i = base + lid;
        let e = next;
        if !run.overflow && i + 256u < n {
            next = bin_lists[run.region + i + 256u];
        }
        var hit = false;
        var s = 0u;
        if i < n && run.overflow {
            s = run.first + i;
            hit = overlaps(sprites[s].bounds, tile_rect);
        } else if i < n {
            s = e.x;
            let t = (vec4<u32>(e.y) >> vec4<u32>(0u, 3u, 6u, 9u)) & vec4<u32>(7u);
            hit = all(run.local >= t.xy) && all(run.local <= t.zw);
        }
        let at = compact(lid, hit);
        if hit {
            hits[pending + at] = s;
        }
        pending += workgroupUniformLoad(&shared_total);
        shaded = shaded || pending > 0u;
        // Whole batches of CACHE hits: their records read once into workgroup memory
        // (one invocation each), then every pixel reads them from there. Fewer wait for
        // the next chunk's.
        var done = 0u;
        while pending - done >= CACHE {
            acc = shade_batch(lid, CACHE, done, origin, p, inside, acc);
            workgroupBarrier();
            done += CACHE;
        }
        if done > 0u {
            // The rest (fewer than CACHE) to the front.
            var v = 0u;
            if lid < pending - done {
                v = hits[done + lid];
            }
            workgroupBarrier();
            if lid < pending - done {
                hits[lid] = v;
            }
            pending -= done;
        }
        workgroupBarrier();
    }
    // The last hits.
    if pending > 0u {
        acc = shade_batch(lid, pending, 0u, origin, p, inside, acc);
    }
    return Shaded(acc, shaded);
}

// The first item to shade tile `t` lists it for the resolve.
fn list_shaded_tile(lid: u32, shaded: bool, t: u32) {
    if lid == 0u && shaded && atomicExchange(&touched[TOUCHED_FLAGS + t], 1u) == 0u {
        let k = atomicAdd(&touched[1], 1u);
        atomicStore(&touched[TOUCHED_FLAGS + tile_count() + k], t);
    }
}

// The job's item's `n` sprites over this tile from tile list entry `start` (the tile's
// own list) blended into `acc`, batch by batch (the next batch's sprites read ahead).
fn shade_tile_run(lid: u32, start: u32, n: u32, origin: vec2<i32>, p: vec2<i32>, inside: bool, acc_in: vec4<f32>) -> vec4<f32> {
    var acc = acc_in;
    var next = 0u;
    if lid < min(n, CACHE) {
        next = bin_meta[tl_entry(start + lid)];
    }
    for (var base = 0u; base < n; base += CACHE) {
        let count = min(CACHE, n - base);
        if lid < count {
            hits[lid] = next;
        }
        if lid < CACHE && base + CACHE + lid < n {
            next = bin_meta[tl_entry(start + base + CACHE + lid)];
        }
        acc = shade_batch(lid, count, 0u, origin, p, inside, acc);
        workgroupBarrier();
    }
    return acc;
}

// The resolve: the shaded tiles (one instance each, two triangles) composited over the
// target (premultiplied: dst · T + C, as `over` blending of (C, 1 − T)). Only tiles some
// sprite touched are drawn: the GPU's fragment work is the fire's footprint, not the screen.
@vertex
fn vs_resolve(@builtin(vertex_index) vi: u32, @builtin(instance_index) inst: u32) -> @builtin(position) vec4<f32> {
    let size = vec2<u32>(camera.viewport.xy);
    let tiles_x = (size.x + TILE - 1u) / TILE;
    let tiles = tiles_x * ((size.y + TILE - 1u) / TILE);
    let t = touched_in[TOUCHED_FLAGS + tiles + inst];
    // Corners 0 1 2, 2 1 3 of the tile, clamped to the target.
    let c = vec2<u32>(u32(vi == 1u || vi >= 4u), u32(vi == 2u || vi == 3u || vi == 5u));
    let px = min((vec2<u32>(t % tiles_x, t / tiles_x) + c) * TILE, size);
    let ndc = vec2<f32>(px) / vec2<f32>(size) * vec2<f32>(2.0, -2.0) + vec2<f32>(-1.0, 1.0);
    return vec4<f32>(ndc, 0.0, 1.0);
}

@fragment
fn fs_resolve(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let v = accum_in[u32(frag.y) * u32(camera.viewport.x) + u32(frag.x)];
    return vec4<f32>(unpack2x16float(v.x), unpack2x16float(v.y));
}

// The compute resolve: the same composite by every compute unit instead of the raster (the
// H100 keeps only a sliver of its chip for that), one workgroup per tile; untouched tiles
// return at once.
@compute @workgroup_size(16, 16)
fn resolve_over(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>) {
    let size = vec2<u32>(camera.viewport.xy);
    let tiles_x = (size.x + TILE - 1u) / TILE;
    let px = wg.xy * TILE + lid.xy;
    if touched_in[TOUCHED_FLAGS + wg.y * tiles_x + wg.x] == 0u || any(px >= size) {
        return;
    }
    let v = accum_in[px.y * size.x + px.x];
    let src = vec4<f32>(unpack2x16float(v.x), unpack2x16float(v.y));
    let dst = textureLoad(resolve_image, vec2<i32>(px));
    textureStore(resolve_image, vec2<i32>(px), dst * (1.0 - src.a) + src);
}
