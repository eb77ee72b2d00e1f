//! Turning rendered frames into files: each pass's pixels in its stored form (sRGB or
//! linear colour, straight or premultiplied alpha, encoded motion), quantised to 8- or
//! 16-bit PNG or half-float EXR (`writer.rs` lays them out as files). Files are written
//! beside their final name and renamed into place: none is left half-written.

use std::path::{Path, PathBuf};

use super::ExportError;
use super::export_settings::{AlphaMode, DISTORTION_SCALE, ExportSettings, Format};
use super::frames::RawFrame;

/// What turns a rendered frame into stored pixels and file names (shared by the
/// writer's threads).
#[derive(Clone, Debug)]
pub(super) struct Encoder {
    pub settings: ExportSettings,
    /// The file names' stem (the preset's name).
    pub stem: String,
    /// Decoded motion in frame UV = (value − 0.5) × this.
    pub motion_scale: f32,
}

impl Encoder {
    /// The colour pass of `frame` in stored values.
    pub fn color_pixels(&self, frame: &RawFrame) -> Vec<[f32; 4]> {
        let alpha = self.settings.alpha;
        let format = self.settings.format;
        frame
            .color
            .iter()
            .map(|&c| store_color(c, alpha, format))
            .collect()
    }

    /// The stored values of pass `name` of `frame`.
    pub fn pass_pixels(&self, name: &str, frame: &RawFrame) -> Vec<[f32; 4]> {
        let format = self.settings.format;
        match name {
            "emissive" => frame
                .emissive
                .iter()
                .map(|&[r, g, b, _]| store_light([r, g, b], format))
                .collect(),
            "distortion" => frame
                .distortion
                .iter()
                .map(|d| {
                    let e = |k: usize| (0.5 + d[k] / DISTORTION_SCALE).clamp(0.0, 1.0);
                    [e(0), e(1), 0.5, 1.0]
                })
                .collect(),
            // Lightmaps: linear and straight, as they were packed.
            "sixway_rtba" => frame.sixway[0].clone(),
            "sixway_lbfe" => frame.sixway[1].clone(),
            "motion" => {
                let (w, h) = self.settings.frame_size;
                let to_uv = [1.0 / w as f32, 1.0 / h as f32];
                frame
                    .motion
                    .iter()
                    .map(|m| {
                        let e =
                            |k: usize| (0.5 + m[k] * to_uv[k] / self.motion_scale).clamp(0.0, 1.0);
                        [e(0), e(1), 0.0, 1.0]
                    })
                    .collect()
            }
            _ => self.color_pixels(frame),
        }
    }

    /// Where output frame `j` of pass `name` of a sequence waits for its final name.
    pub fn pending(&self, name: &str, j: u32) -> PathBuf {
        let ext = self.settings.format.extension();
        self.settings
            .out_dir
            .join(format!(".{}_{name}_{j:04}.{ext}.pending", self.stem))
    }

    /// The path of the file called `stem`.
    pub fn path(&self, stem: &str) -> PathBuf {
        self.settings
            .out_dir
            .join(format!("{stem}.{}", self.settings.format.extension()))
    }
}

/// Stored pixels as an 8-bit sRGB image (previews).
pub(super) fn preview_image(
    size: (u32, u32),
    pixels: &[[f32; 4]],
    format: Format,
) -> Option<image::RgbaImage> {
    let to8 = |v: f32| {
        let v = if format == Format::Exr {
            linear_to_srgb(v)
        } else {
            v
        };
        (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
    };
    let bytes = pixels
        .iter()
        .flat_map(|p| {
            [
                to8(p[0]),
                to8(p[1]),
                to8(p[2]),
                (p[3].clamp(0.0, 1.0) * 255.0 + 0.5) as u8,
            ]
        })
        .collect();
    image::RgbaImage::from_raw(size.0, size.1, bytes)
}

/// `atlas` (cells of `size`, `cols` a row) with cell k taken from cell `source(k)`, for
/// the first `frames` cells.
pub(super) fn rotate_cells(
    atlas: &[[f32; 4]],
    size: (u32, u32),
    cols: u32,
    frames: u32,
    source: impl Fn(u32) -> u32,
) -> Vec<[f32; 4]> {
    let mut out = atlas.to_vec();
    let (w, h) = (size.0 as usize, size.1 as usize);
    let stride = cols as usize * w;
    let origin = |k: u32| ((k % cols) as usize * w, (k / cols) as usize * h);
    for k in 0..frames {
        let ((dx, dy), (sx, sy)) = (origin(k), origin(source(k)));
        for y in 0..h {
            let (d, s) = ((dy + y) * stride + dx, (sy + y) * stride + sx);
            out[d..d + w].copy_from_slice(&atlas[s..s + w]);
        }
    }
    out
}

/// A premultiplied linear colour in its stored form.
fn store_color(c: [f32; 4], alpha: AlphaMode, format: Format) -> [f32; 4] {
    let a = c[3].clamp(0.0, 1.0);
    let (rgb, a) = match alpha {
        AlphaMode::Premultiplied => ([c[0], c[1], c[2]], a),
        AlphaMode::Straight => {
            // Coverage that also counts the light: additive light alone gets alpha.
            let a = a.max(c[0].max(c[1]).max(c[2]).clamp(0.0, 1.0));
            let inv = if a > 0.0 { 1.0 / a } else { 0.0 };
            ([c[0] * inv, c[1] * inv, c[2] * inv], a)
        }
    };
    let [r, g, b, _] = store_light(rgb, format);
    [r, g, b, a]
}

/// Linear light in its stored form: sRGB-encoded and clipped at 1 for PNG (through a
/// table for 8 bits: within a hundredth of a step), linear for EXR; opaque.
fn store_light(rgb: [f32; 3], format: Format) -> [f32; 4] {
    let e = |v: f32| match format {
        Format::Exr => v.max(0.0),
        Format::Png8 => srgb_table(v.clamp(0.0, 1.0)),
        Format::Png16 => linear_to_srgb(v.clamp(0.0, 1.0)),
    };
    [e(rgb[0]), e(rgb[1]), e(rgb[2]), 1.0]
}

/// Entries of the sRGB table over linear 0..1.
const SRGB_STEPS: usize = 4096;

/// `linear_to_srgb` interpolated in a table (`v` in 0..1).
fn srgb_table(v: f32) -> f32 {
    static TABLE: std::sync::OnceLock<Vec<f32>> = std::sync::OnceLock::new();
    let t = TABLE.get_or_init(|| {
        (0..=SRGB_STEPS)
            .map(|i| linear_to_srgb(i as f32 / SRGB_STEPS as f32))
            .collect()
    });
    let x = v * SRGB_STEPS as f32;
    let i = (x as usize).min(SRGB_STEPS - 1);
    let f = x - i as f32;
    t[i] + (t[i + 1] - t[i]) * f
}

/// The sRGB transfer function (linear 0..1 → encoded 0..1).
pub fn linear_to_srgb(v: f32) -> f32 {
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// The inverse sRGB transfer function (encoded 0..1 → linear).
pub fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.040_45 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// Motion in frame UV units (x right, y down) from a motion pass's stored RG.
pub fn decode_motion(rg: [f32; 2], motion_scale: f32) -> [f32; 2] {
    rg.map(|v| (v - 0.5) * motion_scale)
}

/// Writes `pixels` (stored values) as an image of `size` in `format`, atomically
/// (`preset::write_atomic`: no half-written file under `path`).
pub(super) fn write_image(
    path: &Path,
    size: (u32, u32),
    pixels: &[[f32; 4]],
    format: Format,
) -> Result<(), ExportError> {
    let fail = |message: String| ExportError::Write {
        path: path.to_path_buf(),
        message,
    };
    let bytes = encode_image(size, pixels, format).map_err(fail)?;
    crate::preset::write_atomic(path, &bytes).map_err(|e| fail(e.to_string()))
}

/// `pixels` (stored values) encoded as a file of `format`.
fn encode_image(size: (u32, u32), pixels: &[[f32; 4]], format: Format) -> Result<Vec<u8>, String> {
    let (w, h) = size;
    let mut out = std::io::Cursor::new(Vec::new());
    match format {
        Format::Png8 => {
            // Non-negative: + 0.5 and truncation round as `round` would.
            let q = |v: f32| (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
            let raw = pixels.iter().flat_map(|p| p.map(q)).collect();
            image::RgbaImage::from_raw(w, h, raw)
                .ok_or("size mismatch")?
                .write_to(&mut out, image::ImageFormat::Png)
                .map_err(|e| e.to_string())?;
        }
        Format::Png16 => {
            let q = |v: f32| (v.clamp(0.0, 1.0) * 65535.0 + 0.5) as u16;
            let raw = pixels.iter().flat_map(|p| p.map(q)).collect();
            image::ImageBuffer::<image::Rgba<u16>, Vec<u16>>::from_raw(w, h, raw)
                .ok_or("size mismatch")?
                .write_to(&mut out, image::ImageFormat::Png)
                .map_err(|e| e.to_string())?;
        }
        Format::Exr => {
            use exr::prelude::{Image, SpecificChannels, Vec2, WritableImage, f16};
            let at = |x: usize, y: usize| pixels[y * w as usize + x].map(f16::from_f32);
            let channels = SpecificChannels::rgba(|Vec2(x, y)| {
                let [r, g, b, a] = at(x, y);
                (r, g, b, a)
            });
            // One thread: blocks in a fixed order, so the same frames give the same bytes.
            Image::from_channels((w as usize, h as usize), channels)
                .write()
                .non_parallel()
                .to_buffered(&mut out)
                .map_err(|e| e.to_string())?;
        }
    }
    Ok(out.into_inner())
}

/// Box-filters a frame's stored colour down to at most 64×64 (seam statistics).
pub(super) fn thumbnail(pixels: &[[f32; 4]], size: (u32, u32)) -> Vec<[f32; 4]> {
    let (w, h) = (size.0 as usize, size.1 as usize);
    let (tw, th) = (w.min(64), h.min(64));
    let mut out = vec![[0.0f32; 4]; tw * th];
    let mut counts = vec![0u32; tw * th];
    let column: Vec<usize> = (0..w).map(|x| x * tw / w).collect();
    for (y, row) in pixels.chunks(w.max(1)).enumerate() {
        let base = (y * th / h.max(1)) * tw;
        for (p, &c) in row.iter().zip(&column) {
            let o = &mut out[base + c];
            for k in 0..4 {
                o[k] += p[k];
            }
            counts[base + c] += 1;
        }
    }
    for (o, n) in out.iter_mut().zip(counts) {
        *o = o.map(|v| v / n.max(1) as f32);
    }
    out
}

/// The mean absolute difference of two images' channels, in 8-bit steps.
pub(super) fn mean_difference(a: &[[f32; 4]], b: &[[f32; 4]]) -> f64 {
    let sum: f64 = a
        .iter()
        .zip(b)
        .map(|(p, q)| (0..4).map(|k| f64::from((p[k] - q[k]).abs())).sum::<f64>())
        .sum();
    255.0 * sum / (4 * a.len().max(1)) as f64
}

/// The median of `v` (0 when empty).
pub(super) fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The table's interpolation stays on the transfer function it samples, at its knots
    /// and between them.
    #[test]
    fn the_srgb_table_follows_the_transfer_function() {
        for i in 0..=10_000 {
            let v = i as f32 / 10_000.0;
            let (got, want) = (srgb_table(v), linear_to_srgb(v));
            assert!((got - want).abs() < 2e-5, "{v}: {got} against {want}");
        }
    }

    /// A 128 × 96 frame box-filters to 64 × 64: each thumbnail pixel the mean of the 2 × 1
    /// or 2 × 2 pixels it covers (rows 3 to 2: 96 rows onto 64, alternately 1 and 2).
    #[test]
    fn a_thumbnail_is_the_mean_of_the_pixels_it_covers() {
        let (w, h) = (128u32, 96u32);
        let pixels: Vec<[f32; 4]> = (0..w * h)
            .map(|i| [(i % w) as f32, (i / w) as f32, 1.0, 0.5])
            .collect();
        let t = thumbnail(&pixels, (w, h));
        assert_eq!(t.len(), 64 * 64);
        for (k, p) in t.iter().enumerate() {
            let (x, y) = (k % 64, k / 64);
            let rows: Vec<usize> = (0..h as usize)
                .filter(|r| r * 64 / h as usize == y)
                .collect();
            let mean_row = rows.iter().sum::<usize>() as f32 / rows.len() as f32;
            assert_eq!(*p, [2.0 * x as f32 + 0.5, mean_row, 1.0, 0.5], "({x}, {y})");
        }
    }

    /// The mean absolute difference over every channel, in 8-bit steps; the median the
    /// middle value (the upper of the two middles for an even count).
    #[test]
    fn seam_statistics_are_mean_differences_and_medians() {
        let a = [[0.0, 0.5, 1.0, 1.0], [0.2, 0.2, 0.2, 0.2]];
        let b = [[1.0, 0.5, 0.0, 1.0], [0.1, 0.3, 0.2, 0.2]];
        // (1 + 0 + 1 + 0 + 0.1 + 0.1 + 0 + 0) / 8 × 255.
        let want = 2.2 / 8.0 * 255.0;
        assert!((mean_difference(&a, &b) - want).abs() < 1e-4);
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 3.0);
        assert_eq!(median(&mut []), 0.0);
    }

    /// Cells rotated in an atlas of two rows: every pixel of cell k is cell
    /// `source(k)`'s, and the cells past `frames` stay as they were.
    #[test]
    fn rotated_cells_move_whole_across_rows() {
        let (size, cols, rows) = ((3u32, 2u32), 2u32, 3u32);
        let (w, h) = (size.0 as usize, size.1 as usize);
        let stride = cols as usize * w;
        // Each pixel holds its cell, x and y.
        let atlas: Vec<[f32; 4]> = (0..stride * rows as usize * h)
            .map(|i| {
                let (x, y) = (i % stride, i / stride);
                let cell = (y / h) * cols as usize + x / w;
                [cell as f32, (x % w) as f32, (y % h) as f32, 1.0]
            })
            .collect();
        let out = rotate_cells(&atlas, size, cols, 5, |k| (k + 2) % 5);
        for (i, p) in out.iter().enumerate() {
            let (x, y) = (i % stride, i / stride);
            let cell = ((y / h) * cols as usize + x / w) as u32;
            let want = if cell < 5 { (cell + 2) % 5 } else { cell };
            assert_eq!(
                *p,
                [want as f32, (x % w) as f32, (y % h) as f32, 1.0],
                "pixel {x}, {y}"
            );
        }
    }
}
