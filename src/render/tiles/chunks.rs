//! The frame's tile items in chunks: each chunk's sprites fit the tile buffers (a frame of
//! any count is drawn chunk after chunk, each shaded over the tiles the ones before it
//! left), and an item larger than a chunk is drawn in pieces.

use super::*;

/// Quads `base..base + quads` of item `item` (an index into the frame's draw order).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Piece {
    pub(super) item: usize,
    pub(super) base: u32,
    pub(super) quads: u32,
    /// Sprites per quad: 2 for a lit item (its six-way light after its quads), else 1.
    pub(super) per_quad: u32,
}

impl Piece {
    /// The sprites the piece takes, in whole blocks.
    pub(super) fn sprites(&self) -> u32 {
        (self.quads * self.per_quad).next_multiple_of(BLOCK)
    }
}

/// One pass of the tile passes: at most `MAX_ITEMS` pieces, in draw order.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub(super) struct Chunk {
    pub(super) pieces: Vec<Piece>,
}

impl Chunk {
    /// Each piece's first sprite, then the chunk's sprites (whole blocks).
    pub(super) fn firsts(&self) -> Vec<u32> {
        let mut firsts = vec![0u32];
        for p in &self.pieces {
            firsts.push(firsts[firsts.len() - 1] + p.sprites());
        }
        firsts
    }

    /// The chunk's sprites (whole blocks).
    pub(super) fn sprites(&self) -> u32 {
        self.pieces.iter().map(Piece::sprites).sum()
    }
}

/// The (quads, sprites per quad) of each item of `order`.
pub(super) fn shapes(order: &[&DrawItem]) -> Vec<(u32, u32)> {
    let shape = |d: &&DrawItem| (d.width * d.members, if d.variant.lit { 2 } else { 1 });
    order.iter().map(shape).collect()
}

/// The quads of items of `shapes` (quads, sprites per quad: 1 or 2) in chunks of at most
/// `capacity` sprites (at least two blocks) and `MAX_ITEMS` pieces, in draw order; items
/// without quads take none.
pub(super) fn plan(shapes: &[(u32, u32)], capacity: u32) -> Vec<Chunk> {
    let capacity = (capacity / BLOCK).max(2) * BLOCK;
    let mut chunks = vec![Chunk::default()];
    let mut used = 0u32;
    for (item, &(quads, per_quad)) in shapes.iter().enumerate() {
        let mut base = 0;
        while base < quads {
            let full = chunks.last().is_some_and(|c| c.pieces.len() == MAX_ITEMS);
            if full || capacity - used < per_quad * BLOCK {
                chunks.push(Chunk::default());
                used = 0;
            }
            let n = (quads - base).min((capacity - used) / per_quad);
            let piece = Piece {
                item,
                base,
                quads: n,
                per_quad,
            };
            used += piece.sprites();
            if let Some(c) = chunks.last_mut() {
                c.pieces.push(piece);
            }
            base += n;
        }
    }
    chunks.retain(|c| !c.pieces.is_empty());
    chunks
}

#[cfg(test)]
mod tests {
    use super::*;

    fn piece(item: usize, base: u32, quads: u32) -> Piece {
        Piece {
            item,
            base,
            quads,
            per_quad: 1,
        }
    }

    #[test]
    fn items_fill_chunks_in_order_and_split_where_a_chunk_ends() {
        let quads = [1500u32, 5000, 0, 10];
        let shapes: Vec<(u32, u32)> = quads.iter().map(|&n| (n, 1)).collect();
        let chunks = plan(&shapes, 4096);
        let pieces: Vec<Vec<Piece>> = chunks.iter().map(|c| c.pieces.clone()).collect();
        // 1500 quads take two blocks; 5000 are split at the chunks' ends (2048, then 4096
        // sprites of room); the empty item takes nothing.
        assert_eq!(
            pieces,
            [
                vec![piece(0, 0, 1500), piece(1, 0, 2048)],
                vec![piece(1, 2048, 2952), piece(3, 0, 10)],
            ]
        );
        assert_eq!(chunks[0].firsts(), [0, 2048, 4096]);
        assert_eq!(chunks[1].firsts(), [0, 3072, 4096]);
        assert_eq!([chunks[0].sprites(), chunks[1].sprites()], [4096, 4096]);
        // Every quad once.
        let per_item = |i: usize| -> u32 {
            pieces
                .iter()
                .flatten()
                .filter(|p| p.item == i)
                .map(|p| p.quads)
                .sum()
        };
        assert_eq!([per_item(0), per_item(1), per_item(2), per_item(3)], quads);
    }

    #[test]
    fn one_chunk_holds_at_most_max_items_pieces() {
        let chunks = plan(&vec![(8, 1); MAX_ITEMS + 3], 1 << 20);
        let lens: Vec<usize> = chunks.iter().map(|c| c.pieces.len()).collect();
        assert_eq!(lens, [MAX_ITEMS, 3]);
    }

    #[test]
    fn a_frame_within_a_chunk_is_one_chunk_of_whole_items() {
        let chunks = plan(&[(3000, 1), (7, 1)], 1 << 20);
        assert_eq!(chunks.len(), 1);
        assert_eq!(chunks[0].pieces, [piece(0, 0, 3000), piece(1, 0, 7)]);
    }

    #[test]
    fn a_lit_item_takes_two_sprites_a_quad() {
        // 3000 lit quads: 6000 sprites; 4096 a chunk: 2048 quads, then 952.
        let chunks = plan(&[(3000, 2)], 4096);
        let quads: Vec<u32> = chunks.iter().map(|c| c.pieces[0].quads).collect();
        assert_eq!(quads, [2048, 952]);
        assert_eq!(chunks[1].firsts(), [0, 2048]);
    }
}
