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

/// Entries for the bins' lists of `chunk`'s sprites at `size` (`size_px`: the largest
/// projected size of the sprites of the draw order's item `i`): every bin for each when
/// that is small, else about twice what their projected sizes cover (a bin whose list does
/// not fit is shaded from the sprites directly).
pub(super) fn list_entries(
    size_px: impl Fn(usize) -> f32,
    chunk: &Chunk,
    size: (u32, u32),
    limit: u64,
) -> u32 {
    let every = grid_bins(size) * u64::from(chunk.sprites());
    let covered: f64 = chunk
        .pieces
        .iter()
        .map(|p| {
            let side = (f64::from(size_px(p.item)) * 1.5 / f64::from(BIN_PX)).ceil() + 1.0;
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

#[cfg(test)]
mod tests {
    use super::*;

    /// One chunk of items of `quads` unlit quads each, as the frame plans it.
    fn chunk(quads: &[u32]) -> Chunk {
        let shapes: Vec<(u32, u32)> = quads.iter().map(|&q| (q, 1)).collect();
        let mut chunks = chunks::plan(&shapes, CHUNK_SPRITES);
        assert!(chunks.len() <= 1, "{quads:?} in one chunk");
        chunks.pop().unwrap_or_default()
    }

    #[test]
    fn the_grids_cover_the_target_in_whole_cells() {
        assert_eq!(grid((1920, 1080), TILE_PX), (120, 68));
        assert_eq!(grid((1920, 1080), BIN_PX), (15, 9));
        assert_eq!(grid((129, 1), BIN_PX), (2, 1));
        assert_eq!(grid((0, 0), BIN_PX), (1, 1));
        assert_eq!(grid_tiles((1920, 1080)), 120 * 68);
        assert_eq!(grid_bins((1920, 1080)), 15 * 9);
        assert_eq!(grid_bins((129, 257)), 2 * 3);
    }

    #[test]
    fn a_chunk_holds_what_a_binding_takes_in_a_power_of_two() {
        // wgpu's default binding (128 MiB): 699,050 sprites of 192 bytes, so 2^19.
        assert_eq!(chunk_sprites(128 << 20), 1 << 19);
        assert_eq!(chunk_sprites(SPRITE_BYTES << 20), 1 << 20);
        assert_eq!(chunk_sprites((SPRITE_BYTES << 20) - 1), 1 << 19);
        // At most CHUNK_SPRITES, at least two blocks.
        assert_eq!(chunk_sprites(u64::MAX), CHUNK_SPRITES);
        assert_eq!(chunk_sprites(0), 2 * BLOCK);
    }

    #[test]
    fn bin_lists_take_every_bin_when_small_else_twice_the_covered_bins() {
        let size = (1920, 1080);
        let big = 256 << 20;
        // 100 sprites of 10 px in one block: every bin for each (135 bins × 1024).
        assert_eq!(
            list_entries(|_| 10.0, &chunk(&[100]), size, big),
            135 * 1024
        );
        // 100,000 sprites of 200 px cover 4 × 4 bins each: twice 1.6M, to 2^22.
        let one = chunk(&[100_000]);
        assert_eq!(list_entries(|_| 200.0, &one, size, big), 1 << 22);
        // With 400,000 of 10 px after them (2 × 2 bins each): twice 3.2M, to 2^23.
        let two = chunk(&[100_000, 400_000]);
        let sizes = |i: usize| [200.0, 10.0][i];
        assert_eq!(list_entries(sizes, &two, size, big), 1 << 23);
        // Within the binding (8 bytes an entry), and never none.
        assert_eq!(list_entries(sizes, &two, size, 1 << 20), 1 << 17);
        assert_eq!(list_entries(sizes, &chunk(&[]), size, big), 1);
    }

    #[test]
    fn tile_lists_take_their_places_then_twice_the_bins_entries_within_the_binding() {
        let size = (1920, 1080);
        // ⌈1000 / 256⌉ chunks of the bins' lists, and one more per bin.
        assert_eq!(chunk_capacity(1000, size), 4 + 135);
        let places = 130 * 135 + 1 + 128 * (4 + 135);
        let limit = 1 << 30;
        assert_eq!(
            tile_list_words((1000, None), size, 5000, limit),
            places + 2000
        );
        assert_eq!(
            tile_list_words((1000, Some(7)), size, 5000, limit),
            places + 7
        );
        // Room for 100 entries after the bins' words and the places.
        let tight = 4 * (5000 + places + 100);
        assert_eq!(
            tile_list_words((1000, None), size, 5000, tight),
            places + 100
        );
        assert_eq!(tile_list_words((1000, None), size, 5000, 0), places);
    }
}
