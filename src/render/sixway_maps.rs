//! Six-way lightmaps: the built-in smoke puff ray-marched from a procedural density (noise
//! in a sphere, deterministic from a seed) with absorption and single scattering toward
//! each of the six axis directions, and the PNG pairs users bring (EmberGen, Houdini).
//!
//! Frame of a sprite: x to the right, y up, z away from the viewer (the back). A map "lit
//! from +X" is the puff seen from the front with a white directional light on its right.
//! Values are straight (not premultiplied): the scattered light over the coverage, so 1
//! is a white puff fully lit, and a back-lit puff's thin rim reads near 1 where its thick
//! core reads dark. Packing (Unity's Six Way shader, EmberGen's export): RTBA — right,
//! top, back, alpha — and LBFE — left, bottom, front, emissive.

use std::path::Path;

use image::{Rgba, Rgba32FImage};

use crate::render::sprites::{SpriteError, read_png};

/// Side of the built-in puff, pixels (and density cells per side).
pub const PUFF_SIZE: u32 = 128;
/// Side of one frame of the built-in puff sheet, pixels.
pub const SHEET_FRAME: u32 = 64;
/// Frames per side of the built-in puff sheet.
pub const SHEET_GRID: u32 = 4;
/// The built-in maps' seed.
pub const PUFF_SEED: u32 = 7;
/// Extinction at density 1, per unit of the sprite's half-width: a puff's dense core
/// takes about e⁻⁸ of the light through it.
pub const EXTINCTION: f32 = 16.0;

/// A frame's (or a flipbook's) six-way maps, straight and linear.
#[derive(Clone, Debug, PartialEq)]
pub struct SixWayImages {
    /// Lit from the right (+X), top (+Y), back (+Z); alpha: coverage.
    pub rtba: Rgba32FImage,
    /// Lit from the left (−X), bottom (−Y), front (−Z); alpha: emissive mask.
    pub lbfe: Rgba32FImage,
}

/// The puff's density at `p` ∈ [−1, 1]³ (sprite frame) at normalised age `age` ∈ [0, 1]
/// (the sheet's billow: it grows and thins), for `seed`. 0 outside its noisy sphere.
pub fn puff_density(seed: u32, age: f32, p: [f32; 3]) -> f32 {
    let [x, y, z] = p;
    let r = (x * x + y * y + z * z).sqrt();
    let radius = 0.62 + 0.28 * age;
    let o = age * 0.9;
    let n = fbm3(seed, [x * 2.2 + o, y * 2.2 - 0.6 * o, z * 2.2 + 0.3 * o], 4);
    // The edge wobbles with the noise; inside, lumps of denser smoke.
    let edge = radius * (0.75 + 0.5 * n) - r;
    if edge <= 0.0 {
        return 0.0;
    }
    let body = (edge / 0.25).min(1.0);
    let lumps = (n - 0.25).max(0.0) * 1.6;
    body * lumps * (1.0 - 0.55 * age)
}

/// The built-in puff's maps (one frame, `PUFF_SIZE` square).
pub fn puff(seed: u32) -> SixWayImages {
    render_frame(seed, 0.25, PUFF_SIZE)
}

/// The built-in puff sheet: `SHEET_GRID`² frames of `SHEET_FRAME` pixels, row-major from
/// the top left, the puff's age going from 0 to 1.
pub fn puff_sheet(seed: u32) -> SixWayImages {
    let (g, n) = (SHEET_GRID, SHEET_FRAME);
    let mut out = SixWayImages {
        rtba: Rgba32FImage::new(g * n, g * n),
        lbfe: Rgba32FImage::new(g * n, g * n),
    };
    for f in 0..g * g {
        let frame = render_frame(seed, f as f32 / (g * g - 1) as f32, n);
        let (x, y) = (i64::from(f % g * n), i64::from(f / g * n));
        image::imageops::replace(&mut out.rtba, &frame.rtba, x, y);
        image::imageops::replace(&mut out.lbfe, &frame.lbfe, x, y);
    }
    out
}

/// The density of one frame on an `n`³ grid (cell centres; x fastest, then y down the
/// image rows, then z from the front).
fn density_grid(seed: u32, age: f32, n: usize) -> Vec<f32> {
    let c = |i: usize| (i as f32 + 0.5) / n as f32 * 2.0 - 1.0;
    let mut grid = vec![0.0; n * n * n];
    for (k, slab) in grid.chunks_mut(n * n).enumerate() {
        for (j, row) in slab.chunks_mut(n).enumerate() {
            for (i, v) in row.iter_mut().enumerate() {
                *v = puff_density(seed, age, [c(i), -c(j), c(k)]);
            }
        }
    }
    grid
}

/// Ray-marches one frame: per pixel, along the view (front to back), the light each
/// cell scatters toward the eye from each of the six lights, attenuated on its way in
/// (the optical depth from the cell to the edge, toward the light) and out.
fn render_frame(seed: u32, age: f32, size: u32) -> SixWayImages {
    let n = size as usize;
    let rho = density_grid(seed, age, n);
    let step = 2.0 / n as f32 * EXTINCTION;
    let at = |i: usize, j: usize, k: usize| (k * n + j) * n + i;
    // Optical depth along x and y up to and including each cell (prefix sums).
    let (mut px, mut py) = (rho.clone(), rho.clone());
    for k in 0..n {
        for j in 0..n {
            for i in 1..n {
                px[at(i, j, k)] = px[at(i - 1, j, k)] + rho[at(i, j, k)];
            }
        }
        for i in 0..n {
            for j in 1..n {
                py[at(i, j, k)] = py[at(i, j - 1, k)] + rho[at(i, j, k)];
            }
        }
    }
    let mut out = SixWayImages {
        rtba: Rgba32FImage::new(size, size),
        lbfe: Rgba32FImage::new(size, size),
    };
    for j in 0..n {
        for i in 0..n {
            let column: f32 = (0..n).map(|k| rho[at(i, j, k)]).sum();
            let (mut before, mut lit) = (0.0f32, [0.0f32; 6]);
            for k in 0..n {
                let d = rho[at(i, j, k)];
                if d > 0.0 {
                    let (a, half) = (at(i, j, k), 0.5 * d);
                    // Cells' optical depth toward each light: +X (right), +Y (top: row
                    // 0), +Z (back), −X, −Y, −Z; half of this cell's own.
                    let right = px[at(n - 1, j, k)] - px[a] + half;
                    let left = px[a] - half;
                    let top = py[a] - half;
                    let bottom = py[at(i, n - 1, k)] - py[a] + half;
                    let back = column - before - half;
                    let front = before + half;
                    let eye = (-(before + half) * step).exp();
                    let scatter = (1.0 - (-d * step).exp()) * eye;
                    for (l, tau) in lit.iter_mut().zip([right, top, back, left, bottom, front]) {
                        *l += scatter * (-tau * step).exp();
                    }
                }
                before += d;
            }
            let alpha = 1.0 - (-column * step).exp();
            let s = |v: f32| {
                if alpha > 1e-6 {
                    (v / alpha).min(1.0)
                } else {
                    0.0
                }
            };
            let glow = (column * step / 4.0).min(1.0);
            let (x, y) = (i as u32, j as u32);
            out.rtba
                .put_pixel(x, y, Rgba([s(lit[0]), s(lit[1]), s(lit[2]), alpha]));
            out.lbfe
                .put_pixel(x, y, Rgba([s(lit[3]), s(lit[4]), s(lit[5]), glow]));
        }
    }
    out
}

/// The two maps side by side in one texture for the draw paths — RTBA on the left, LBFE
/// on the right — each multiplied by the coverage (premultiplied, so mips average them
/// as the blending will).
pub fn combined(maps: &SixWayImages) -> Rgba32FImage {
    let (w, h) = maps.rtba.dimensions();
    Rgba32FImage::from_fn(2 * w, h, |x, y| {
        let a = maps.rtba.get_pixel(x % w, y)[3];
        let p = if x < w {
            maps.rtba.get_pixel(x, y)
        } else {
            maps.lbfe.get_pixel(x - w, y)
        };
        let alpha = if x < w { a } else { p[3] * a };
        Rgba([p[0] * a, p[1] * a, p[2] * a, alpha])
    })
}

#[cfg(feature = "editor")]
/// An image of the maps as 8-bit linear bytes (what [`load_pair`] reads back).
pub fn to_png_linear(img: &Rgba32FImage) -> image::RgbaImage {
    image::RgbaImage::from_fn(img.width(), img.height(), |x, y| {
        let p = img.get_pixel(x, y);
        Rgba(p.0.map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8))
    })
}

/// Reads a pair of six-way PNGs (linear, straight; 8 or 16 bits; at most 4096 a side),
/// which must be the same size. An error names the file and the problem.
pub fn load_pair(rtba: &Path, lbfe: &Path) -> Result<SixWayImages, SpriteError> {
    let load = |path: &Path| read_png(path, 4096).map(image::DynamicImage::into_rgba32f);
    let (a, b) = (load(rtba)?, load(lbfe)?);
    if a.dimensions() != b.dimensions() {
        return Err(SpriteError {
            path: lbfe.display().to_string(),
            reason: format!(
                "{}×{} pixels, but its RTBA map {} is {}×{}: the pair must match",
                b.width(),
                b.height(),
                rtba.display(),
                a.width(),
                a.height()
            ),
        });
    }
    Ok(SixWayImages { rtba: a, lbfe: b })
}

/// Value-noise fbm in [0, 1] over 3-D space, seeded.
fn fbm3(seed: u32, p: [f32; 3], octaves: u32) -> f32 {
    let (mut sum, mut amp, mut norm) = (0.0, 0.5, 0.0);
    let mut q = p;
    for o in 0..octaves {
        sum += amp * value_noise3(seed.wrapping_add(o * 0x9E37), q);
        norm += amp;
        amp *= 0.5;
        q = [q[0] * 2.03 + 1.7, q[1] * 2.03 - 0.9, q[2] * 2.03 + 0.4];
    }
    sum / norm
}

/// Trilinear value noise in [0, 1], smoothstep-weighted, from a hash of the lattice.
fn value_noise3(seed: u32, p: [f32; 3]) -> f32 {
    let f = p.map(f32::floor);
    let t = [p[0] - f[0], p[1] - f[1], p[2] - f[2]].map(|t| t * t * (3.0 - 2.0 * t));
    let base = f.map(|v| v as i32);
    let h = |dx: i32, dy: i32, dz: i32| {
        let [x, y, z] = [base[0] + dx, base[1] + dy, base[2] + dz].map(|v| v as u32);
        let mut v = x.wrapping_mul(0x9E37_79B1)
            ^ y.wrapping_mul(0x85EB_CA77)
            ^ z.wrapping_mul(0xC2B2_AE3D)
            ^ seed.wrapping_mul(0x27D4_EB2F);
        v ^= v >> 15;
        v = v.wrapping_mul(0x2C1B_3C6D);
        v ^= v >> 12;
        v = v.wrapping_mul(0x297A_2D39);
        v ^= v >> 15;
        (v & 0xffff) as f32 / 65535.0
    };
    let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
    let x00 = lerp(h(0, 0, 0), h(1, 0, 0), t[0]);
    let x10 = lerp(h(0, 1, 0), h(1, 1, 0), t[0]);
    let x01 = lerp(h(0, 0, 1), h(1, 0, 1), t[0]);
    let x11 = lerp(h(0, 1, 1), h(1, 1, 1), t[0]);
    lerp(lerp(x00, x10, t[1]), lerp(x01, x11, t[1]), t[2])
}
