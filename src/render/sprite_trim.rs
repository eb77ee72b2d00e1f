//! The part of a sprite's frame that draws something visible, which billboards are cut
//! to: an axis-aligned rectangle and, for shapes that leave its corners empty (a flame
//! tongue's tip, a puff's round edge), four diagonal cuts — an octagon, the eight-sided
//! bounding shape (8-DOP) of the visible texels. A billboard outside it would only shade
//! and blend texels that add nothing, and on GPUs whose raster is the bottleneck (an
//! H100's) that fill is the cost of the large layers.
//!
//! The bounds are conservative: every texel above the threshold, grown by one texel for
//! bilinear filtering, lies inside; the shader grows them further by the mip margin
//! (`shaders/quad.wgsl`, `quad_corner`).

/// Billboards take the octagon where it draws at most this share of the rectangle's
/// fill: a round puff's (0.84) pays for its eight vertices, the flame sheet's tongues
/// (0.92, their tips sway across the frames) do not.
pub const OCTAGON_SHARE: f32 = 0.9;

/// A sprite's visible part within one flipbook frame, in frame-local texture coordinates
/// (u right, v down, 0..1): the union over every frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Trim {
    /// `[u0, v0, u1, v1]`.
    pub rect: [f32; 4],
    /// `[min(u + v), max(u + v), min(u − v), max(u − v)]` over the visible part.
    pub diag: [f32; 4],
}

impl Trim {
    /// The whole frame: nothing cut.
    pub const WHOLE: Trim = Trim {
        rect: [0.0, 0.0, 1.0, 1.0],
        diag: [0.0, 2.0, -1.0, 1.0],
    };

    /// The corners' cuts before any margin, as the shader reads them: the legs of the cut
    /// triangles at (u0, v0), (u1, v0), (u1, v1), (u0, v1), in frame units, rounded down
    /// to 8 bits (cutting less stays conservative).
    pub fn cuts(&self) -> [f32; 4] {
        let [u0, v0, u1, v1] = self.rect;
        [
            self.diag[0] - (u0 + v0),
            (u1 - v0) - self.diag[3],
            (u1 + v1) - self.diag[1],
            self.diag[2] - (u0 - v1),
        ]
        .map(|t| (t.clamp(0.0, 1.0) * 255.0).floor() / 255.0)
    }

    /// [`Trim::cuts`] packed as WGSL's `pack4x8unorm` packs them (the first in the lowest
    /// byte).
    pub fn packed_cuts(&self) -> u32 {
        self.cuts()
            .iter()
            .enumerate()
            .map(|(i, t)| ((t * 255.0).round() as u32) << (8 * i))
            .sum()
    }

    /// The octagon's eight corners in order around it (some may coincide), with its
    /// bounds grown by `margin` in u and v (the mip margin) and cut to the frame: the
    /// shader's construction (`shaders/sprite_trim.wgsl`, `octagon_corner`).
    pub fn octagon(&self, margin: f32) -> [[f32; 2]; 8] {
        let lo = [
            (self.rect[0] - margin).max(0.0),
            (self.rect[1] - margin).max(0.0),
        ];
        let hi = [
            (self.rect[2] + margin).min(1.0),
            (self.rect[3] + margin).min(1.0),
        ];
        // Where the frame clipped the margin, the corner moved less and its cut shrinks.
        let glo = [self.rect[0] - margin - lo[0], self.rect[1] - margin - lo[1]];
        let ghi = [hi[0] - self.rect[2] - margin, hi[1] - self.rect[3] - margin];
        let c = self.cuts();
        let mut t = [
            c[0] + glo[0] + glo[1],
            c[1] + ghi[0] + glo[1],
            c[2] + ghi[0] + ghi[1],
            c[3] + glo[0] + ghi[1],
        ]
        .map(|x| x.max(0.0));
        let (w, h) = (hi[0] - lo[0], hi[1] - lo[1]);
        // Two cuts along one edge never overlap (cutting less stays conservative).
        for (a, b, len) in [(0, 1, w), (1, 2, h), (3, 2, w), (0, 3, h)] {
            let k = (len / (t[a] + t[b]).max(1e-12)).min(1.0);
            t[a] *= k;
            t[b] *= k;
        }
        [
            [lo[0] + t[0], lo[1]],
            [hi[0] - t[1], lo[1]],
            [hi[0], lo[1] + t[1]],
            [hi[0], hi[1] - t[2]],
            [hi[0] - t[2], hi[1]],
            [lo[0] + t[3], hi[1]],
            [lo[0], hi[1] - t[3]],
            [lo[0], lo[1] + t[0]],
        ]
    }

    /// The octagon's area over the rectangle's (both unmargined): the share of the
    /// rectangle's fill an octagon draws.
    pub fn octagon_share(&self) -> f32 {
        let rect = (self.rect[2] - self.rect[0]) * (self.rect[3] - self.rect[1]);
        if rect <= 0.0 {
            return 1.0;
        }
        polygon_area(&self.octagon(0.0)) / rect
    }
}

/// The area of a simple polygon (the shoelace formula).
fn polygon_area(p: &[[f32; 2]]) -> f32 {
    let n = p.len();
    let twice: f32 = (0..n)
        .map(|i| {
            let (a, b) = (p[i], p[(i + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum();
    0.5 * twice.abs()
}

/// The visible part of a `rows × cols` flipbook (1 × 1 without one) of `size` texels,
/// from its `coverage`: the largest premultiplied channel over cells of `cell` × `cell`
/// texels (row-major). Cells above `threshold` count, grown by one texel for bilinear
/// filtering; [`Trim::WHOLE`] when none does.
pub fn trim(
    coverage: &[f32],
    cell: u32,
    size: (u32, u32),
    rows: u32,
    cols: u32,
    threshold: f32,
) -> Trim {
    let (w, h) = size;
    let (rows, cols) = (rows.max(1) as f32, cols.max(1) as f32);
    let (sx, sy) = (cols / w as f32, rows / h as f32);
    let cells_x = w.div_ceil(cell.max(1));
    let mut rect = [f32::MAX, f32::MAX, f32::MIN, f32::MIN];
    let mut diag = [f32::MAX, f32::MIN, f32::MAX, f32::MIN];
    for (i, _) in coverage.iter().enumerate().filter(|(_, c)| **c > threshold) {
        let (gx, gy) = (i as u32 % cells_x, i as u32 / cells_x);
        // The cell's texels grown by one, frame-local (the frame of the cell's centre).
        let (x0, y0) = ((gx * cell) as f32, (gy * cell) as f32);
        let (x1, y1) = (
            ((gx + 1) * cell).min(w) as f32,
            ((gy + 1) * cell).min(h) as f32,
        );
        let (cx, cy) = (
            ((x0 + x1) * 0.5 * sx).floor(),
            ((y0 + y1) * 0.5 * sy).floor(),
        );
        let (u0, v0) = (x0 * sx - cx - sx, y0 * sy - cy - sy);
        let (u1, v1) = (x1 * sx - cx + sx, y1 * sy - cy + sy);
        rect = [
            rect[0].min(u0),
            rect[1].min(v0),
            rect[2].max(u1),
            rect[3].max(v1),
        ];
        diag = [
            diag[0].min(u0 + v0),
            diag[1].max(u1 + v1),
            diag[2].min(u0 - v1),
            diag[3].max(u1 - v0),
        ];
    }
    if rect[0] > rect[2] {
        return Trim::WHOLE;
    }
    Trim {
        rect: [
            rect[0].max(0.0),
            rect[1].max(0.0),
            rect[2].min(1.0),
            rect[3].min(1.0),
        ],
        diag,
    }
}
