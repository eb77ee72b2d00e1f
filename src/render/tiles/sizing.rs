//! The tile rasteriser's sizes: the grid of tiles and bins, each item's sprites in whole
//! blocks, and the lists' capacities.

use super::*;

/// Tiles and bins across a target of `size` pixels.
pub(super) fn grid(size: (u32, u32), cell: u32) -> (u32, u32) {
    (size.0.div_ceil(cell).max(1), size.1.div_ceil(cell).max(1))
}

/// Tiles across a target of `size` pixels.
pub(super) fn grid_tiles(size: (u32, u32)) -> u64 {
    let (tx, ty) = grid(size, TILE_PX);
    u64::from(tx) * u64::from(ty)
}

/// Bins across a target of `size` pixels.
pub(super) fn grid_bins(size: (u32, u32)) -> u64 {
    let (bx, by) = grid(size, BIN_PX);
    u64::from(bx) * u64::from(by)
}

/// Sprites a chunk holds on a device whose storage bindings take `limit` bytes: at most
/// `CHUNK_SPRITES`, a power of two.
pub(super) fn chunk_sprites(limit: u64) -> u32 {
    let fit = (limit / SPRITE_BYTES).clamp(u64::from(2 * BLOCK), u64::from(CHUNK_SPRITES));
    1 << fit.ilog2()
}

/// Entries for the bins' lists of `chunk`'s sprites (pieces of `order`'s items) at `size`:
/// every bin for each when that is small, else about twice what their projected sizes
/// cover (a bin whose list does not fit is shaded from the sprites directly).
pub(super) fn list_entries(
    order: &[&DrawItem],
    chunk: &Chunk,
    size: (u32, u32),
    limit: u64,
) -> u32 {
    let every = grid_bins(size) * u64::from(chunk.sprites());
    let covered: f64 = chunk
        .pieces
        .iter()
        .map(|p| {
            let side = (f64::from(order[p.item].size_px) * 1.5 / f64::from(BIN_PX)).ceil() + 1.0;
            f64::from(p.quads) * side * side
        })
        .sum();
    let estimate = (2.0 * covered) as u64;
    let cap = (limit.min(MAX_LIST_BYTES) / LIST_ENTRY_BYTES).min(u64::from(u32::MAX));
    // In powers of two: room to grow before the buffer is made again.
    every
        .min(estimate.max(1 << 20).next_power_of_two())
        .min(cap)
        .max(1) as u32
}

/// Chunks the tile lists' passes read at most: every bin's list in chunks of `CHUNK`
/// (`job.counts2.w`).
pub(super) fn chunk_capacity(list_capacity: u32, size: (u32, u32)) -> u32 {
    (u64::from(list_capacity).div_ceil(CHUNK) + grid_bins(size)) as u32
}

/// `bin_meta` words for the tiles' lists (tile_lists.wgsl `tl_*`): the chunks and places
/// per bin, tile and chunk, then the lists' entries — twice the bins' lists' (a sprite
/// over several tiles is listed on each), within the storage binding's limit. Lists that
/// do not fit are shaded from the bins' lists. `bin_words`: the bins' words before them;
/// `limit`: the storage binding's limit in bytes.
/// `entries`: the lists' entries when set (tests), else twice the bins'.
pub(super) fn tile_list_words(
    (list_capacity, entries): (u32, Option<u32>),
    size: (u32, u32),
    bin_words: u64,
    limit: u64,
) -> u64 {
    let bins = grid_bins(size);
    let chunks = u64::from(chunk_capacity(list_capacity, size));
    let places = 130 * bins + 1 + 128 * chunks;
    let room = (limit / 4).saturating_sub(bin_words + places);
    let entries = entries.map_or(2 * u64::from(list_capacity), u64::from);
    places + entries.min(room)
}

/// The frame's tile items in draw order: alpha-blended first (as given: back to front),
/// then the light by emitter (as the billboards draw them).
pub(super) fn draw_order(items: &[DrawItem]) -> Vec<&DrawItem> {
    let mut order: Vec<&DrawItem> = items.iter().filter(|d| d.tiles).collect();
    order.sort_by_key(|d| d.draw_key());
    order
}
