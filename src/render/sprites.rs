//! Sprite textures: the built-in procedural set (generated on first use) and PNGs from
//! disk, each uploaded premultiplied and linear (`Rgba16Float`) with a full mip chain.
//!
//! A PNG that is missing or broken never stops the frame: [`SpriteLibrary::resolve`]
//! returns the built-in soft disc and an error that names the file and the problem. A PNG
//! that changes on disk is reloaded after [`SpriteLibrary::invalidate`].

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use image::{Rgba, Rgba32FImage};

use crate::effect::{SixWayMaps, Sprite};
use crate::gpu::GpuContext;
use crate::render::sixway_maps;
use crate::render::sprite_trim::{self, Trim};

/// Side of a built-in sprite (one frame), pixels.
pub const BUILT_IN_SIZE: u32 = 128;
/// Frames per side of the built-in flame sheet.
pub const FLAME_SHEET_GRID: u32 = 4;
/// The texture format sprites are stored in (linear, premultiplied alpha).
pub const SPRITE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// An uploaded sprite texture.
#[derive(Debug)]
pub struct SpriteTexture {
    /// Unique id (bind groups are cached by it).
    pub id: u64,
    /// View over all mips.
    pub view: wgpu::TextureView,
    /// Width and height of mip 0.
    pub size: (u32, u32),
    /// ∫ premultiplied brightness over the sprite's quad [-1, 1]² (4 × the mean), the
    /// splat's energy per unit of colour.
    pub integral: f32,
    /// The largest premultiplied channel of mip 0 over cells of `cell` × `cell` texels
    /// (row-major, at most 256 cells a side): what [`SpriteTexture::trim`] fits the
    /// drawn quads to.
    coverage: Vec<f32>,
    /// Texels per coverage cell side (a power of two).
    cell: u32,
}

/// A texel whose premultiplied channels are all at or below this, at intensity 1, draws
/// nothing visible (an 8-bit display step is 1/255 and bloom thresholds are far above);
/// quads are trimmed to the texels above it (divided by the emitter's intensity).
pub const TRIM_THRESHOLD: f32 = 1.0 / 1024.0;

/// The layout of a compute draw path's sprite group: the texture (filterable) at binding
/// 0, its sampler at 1.
pub fn compute_sprite_layout(ctx: &GpuContext, label: &str) -> wgpu::BindGroupLayout {
    let compute = |entry: wgpu::BindGroupLayoutEntry| wgpu::BindGroupLayoutEntry {
        visibility: wgpu::ShaderStages::COMPUTE,
        ..entry
    };
    crate::gpu::bind_group_layout(
        ctx,
        label,
        &[
            compute(crate::gpu::fragment_texture_entry(0, true)),
            compute(crate::gpu::fragment_sampler_entry(1)),
        ],
    )
}

/// A draw path's bind groups of sprites (texture at binding 0, sampler at 1 of its
/// layout), cached by sprite id.
pub struct SpriteGroups {
    label: &'static str,
    layout: wgpu::BindGroupLayout,
    groups: std::collections::HashMap<u64, wgpu::BindGroup>,
}

impl SpriteGroups {
    /// An empty cache of groups of `layout`.
    pub fn new(label: &'static str, layout: wgpu::BindGroupLayout) -> Self {
        Self {
            label,
            layout,
            groups: std::collections::HashMap::new(),
        }
    }

    /// Creates `sprite`'s group with `sampler` unless it exists.
    pub fn ensure(&mut self, ctx: &GpuContext, sprite: &SpriteTexture, sampler: &wgpu::Sampler) {
        self.groups.entry(sprite.id).or_insert_with(|| {
            ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(self.label),
                layout: &self.layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::TextureView(&sprite.view),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::Sampler(sampler),
                    },
                ],
            })
        });
    }

    /// Drops the groups of sprites not in `drawn` once there are many (a reloaded PNG is
    /// a new sprite).
    pub fn keep_drawn(&mut self, drawn: impl Iterator<Item = u64>) {
        if self.groups.len() > 32 {
            let live: std::collections::HashSet<u64> = drawn.collect();
            self.groups.retain(|id, _| live.contains(id));
        }
    }

    /// Builds what a compute draw path's `items` need this frame: each look variant's
    /// pipelines in `pipelines` (made by `make` on first use; `None` where they fail,
    /// logged as `what`'s) and each sprite's group with `sampler`.
    pub(crate) fn prepare<'a, P>(
        &mut self,
        ctx: &GpuContext,
        (what, sampler): (&str, &wgpu::Sampler),
        pipelines: &mut std::collections::HashMap<crate::render::variant::LookVariant, Option<P>>,
        items: impl Iterator<Item = &'a crate::render::DrawItem> + Clone,
        make: impl Fn(crate::render::variant::LookVariant) -> P,
    ) {
        for d in items.clone() {
            let v = d.variant;
            pipelines.entry(v).or_insert_with(|| {
                crate::render::scoped_variant(ctx, format_args!("{what} variant {v:?}"), || make(v))
            });
            self.ensure(ctx, &d.sprite, sampler);
        }
        self.keep_drawn(items.map(|d| d.sprite.id));
    }

    /// The group of sprite `id`, if made.
    pub fn get(&self, id: u64) -> Option<&wgpu::BindGroup> {
        self.groups.get(&id)
    }
}

impl SpriteTexture {
    /// The part of every frame that holds something above `threshold`, as a `rows ×
    /// cols` flipbook (1 × 1 without one): the union over all frames, grown by one texel
    /// for bilinear filtering ([`sprite_trim::trim`]). Billboards are cut to it (plus a
    /// mip margin, in the shader): a flame-tongue sheet covers half its square, so half of
    /// its fill was spent on nothing.
    pub fn trim(&self, rows: u32, cols: u32, threshold: f32) -> Trim {
        sprite_trim::trim(&self.coverage, self.cell, self.size, rows, cols, threshold)
    }
}

/// The largest premultiplied channel of `img` over cells of `cell` × `cell` texels
/// (row-major), with `cell` the power of two that makes at most 256 cells a side (so
/// that cells do not straddle the frames of power-of-two flipbooks).
pub fn coverage(img: &Rgba32FImage) -> (Vec<f32>, u32) {
    let (w, h) = img.dimensions();
    let cell = (w.max(h) / 256).max(1).next_power_of_two();
    let cells_x = w.div_ceil(cell);
    let mut coverage = vec![0.0f32; (cells_x * h.div_ceil(cell)) as usize];
    for (x, y, p) in img.enumerate_pixels() {
        let i = ((y / cell) * cells_x + x / cell) as usize;
        let m = p.0.iter().fold(0.0f32, |a, &c| a.max(c));
        if let Some(c) = coverage.get_mut(i) {
            *c = c.max(m);
        }
    }
    (coverage, cell)
}

/// A sprite that could not be loaded.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error(
    "sprite {path}: {reason} — drawing the built-in soft disc instead; fix the file or the path \
        (relative to the preset)"
)]
pub struct SpriteError {
    /// The file as resolved.
    pub path: String,
    /// What went wrong.
    pub reason: String,
}

/// Built-in and file sprites, uploaded once and shared by every emitter that uses them.
pub struct SpriteLibrary {
    built_in: HashMap<Sprite, Arc<SpriteTexture>>,
    files: HashMap<PathBuf, Result<Arc<SpriteTexture>, SpriteError>>,
    /// Six-way maps (built-in, and pairs of files by their resolved paths), each pair in
    /// one texture: RTBA on the left, LBFE on the right (`sixway_maps::combined`).
    lit: HashMap<SixWayMaps, Result<Arc<SpriteTexture>, SpriteError>>,
    /// Trilinear, clamp-to-edge.
    pub sampler: wgpu::Sampler,
    next_id: u64,
    /// Changes whenever the set of file sprites changes (what to watch).
    generation: u64,
}

impl SpriteLibrary {
    /// An empty library (built-ins are generated on first use).
    pub fn new(ctx: &GpuContext) -> Self {
        let sampler = ctx.device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("SpriteLibrary::sampler"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Nearest,
            ..Default::default()
        });
        Self {
            built_in: HashMap::new(),
            files: HashMap::new(),
            lit: HashMap::new(),
            sampler,
            next_id: 1,
            generation: 0,
        }
    }

    /// The texture for `sprite`; PNG paths are relative to `base_dir` (the preset's
    /// folder; the working directory when `None`). A file that fails to load gives the
    /// soft disc and the error.
    pub fn resolve(
        &mut self,
        ctx: &GpuContext,
        sprite: &Sprite,
        base_dir: Option<&Path>,
    ) -> (Arc<SpriteTexture>, Option<SpriteError>) {
        let Sprite::Image(rel) = sprite else {
            return (self.built_in(ctx, sprite), None);
        };
        let path = resolve_path(rel, base_dir);
        if !self.files.contains_key(&path) {
            let loaded = load_png(&path).map(|img| {
                let id = self.take_id();
                Arc::new(upload(ctx, &img, id, &path.display().to_string()))
            });
            if let Err(e) = &loaded {
                log::warn!("{e}");
            }
            self.files.insert(path.clone(), loaded);
            self.generation += 1;
        }
        match self.files.get(&path) {
            Some(Ok(t)) => (t.clone(), None),
            Some(Err(e)) => {
                let e = e.clone();
                (self.built_in(ctx, &Sprite::SoftDisc), Some(e))
            }
            None => (self.built_in(ctx, &Sprite::SoftDisc), None),
        }
    }

    /// The six-way maps `maps` in one texture (RTBA left, LBFE right); PNG paths are
    /// relative to `base_dir`. A pair that fails to load gives the built-in puff and the
    /// error.
    pub fn resolve_lit(
        &mut self,
        ctx: &GpuContext,
        maps: &SixWayMaps,
        base_dir: Option<&Path>,
    ) -> (Arc<SpriteTexture>, Option<SpriteError>) {
        let key = match maps {
            SixWayMaps::Images { rtba, lbfe } => SixWayMaps::Images {
                rtba: resolve_path(rtba, base_dir).display().to_string(),
                lbfe: resolve_path(lbfe, base_dir).display().to_string(),
            },
            built_in => built_in.clone(),
        };
        if !self.lit.contains_key(&key) {
            let images = match &key {
                SixWayMaps::Puff => Ok(sixway_maps::puff(sixway_maps::PUFF_SEED)),
                SixWayMaps::PuffSheet => Ok(sixway_maps::puff_sheet(sixway_maps::PUFF_SEED)),
                SixWayMaps::Images { rtba, lbfe } => {
                    sixway_maps::load_pair(Path::new(rtba), Path::new(lbfe))
                }
            };
            let id = self.take_id();
            let label = format!("six-way {key:?}");
            let loaded =
                images.map(|m| Arc::new(upload(ctx, &sixway_maps::combined(&m), id, &label)));
            if let Err(e) = &loaded {
                log::warn!("{e}");
            }
            self.lit.insert(key.clone(), loaded);
            self.generation += 1;
        }
        match self.lit.get(&key) {
            Some(Ok(t)) => (t.clone(), None),
            Some(Err(e)) => {
                let e = e.clone();
                (self.resolve_lit(ctx, &SixWayMaps::Puff, None).0, Some(e))
            }
            None => (self.built_in(ctx, &Sprite::SoftDisc), None),
        }
    }

    /// Forgets cached files among `changed` (they reload on the next `resolve`). Returns
    /// true when any was cached.
    pub fn invalidate(&mut self, changed: &[PathBuf]) -> bool {
        let before = self.files.len();
        self.files.retain(|p, _| {
            !changed
                .iter()
                .any(|c| c == p || (c.file_name() == p.file_name() && same_file(c, p)))
        });
        let lit_before = self.lit.len();
        self.lit.retain(|m, _| match m {
            SixWayMaps::Images { rtba, lbfe } => ![rtba, lbfe]
                .iter()
                .any(|p| changed.iter().any(|c| same_path(c, Path::new(p)))),
            _ => true,
        });
        let dropped = before != self.files.len() || lit_before != self.lit.len();
        if dropped {
            self.generation += 1;
        }
        dropped
    }

    /// Changes whenever the set of file sprites (and so [`Self::watched_dirs`]) may have.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// Existing folders holding the file sprites in use, missing ones included (to watch
    /// for changes: a PNG created or fixed there is picked up).
    pub fn watched_dirs(&self) -> Vec<PathBuf> {
        let lit = self.lit.keys().flat_map(|m| match m {
            SixWayMaps::Images { rtba, lbfe } => vec![PathBuf::from(rtba), PathBuf::from(lbfe)],
            _ => Vec::new(),
        });
        let mut dirs: Vec<PathBuf> = self
            .files
            .keys()
            .cloned()
            .chain(lit)
            .filter_map(|p| p.parent().map(Path::to_path_buf))
            .map(|d| {
                if d.as_os_str().is_empty() {
                    PathBuf::from(".")
                } else {
                    d
                }
            })
            .collect();
        dirs.retain(|d| d.is_dir());
        dirs.sort();
        dirs.dedup();
        dirs
    }

    fn take_id(&mut self) -> u64 {
        self.next_id += 1;
        self.next_id
    }

    fn built_in(&mut self, ctx: &GpuContext, sprite: &Sprite) -> Arc<SpriteTexture> {
        let key = match sprite {
            Sprite::Image(_) => Sprite::SoftDisc,
            s => s.clone(),
        };
        if let Some(t) = self.built_in.get(&key) {
            return t.clone();
        }
        let id = self.take_id();
        let img = generate(&key);
        let tex = Arc::new(upload(ctx, &img, id, key.label()));
        self.built_in.insert(key, tex.clone());
        tex
    }
}

/// Whether `changed` names `p` (the same path, or the same file by another path).
fn same_path(changed: &Path, p: &Path) -> bool {
    changed == p || (changed.file_name() == p.file_name() && same_file(changed, p))
}

fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

/// `rel` against `base_dir` (absolute paths are kept).
pub fn resolve_path(rel: &str, base_dir: Option<&Path>) -> PathBuf {
    let rel = Path::new(rel);
    match base_dir {
        Some(dir) if rel.is_relative() => dir.join(rel),
        _ => rel.to_path_buf(),
    }
}

/// Reads the PNG at `path`, at most `max_side` pixels a side; an error names the file
/// and the problem.
pub fn read_png(path: &Path, max_side: u32) -> Result<image::DynamicImage, SpriteError> {
    let err = |reason: String| SpriteError {
        path: path.display().to_string(),
        reason,
    };
    let bytes = std::fs::read(path).map_err(|e| err(format!("cannot read it ({e})")))?;
    let img = image::load_from_memory_with_format(&bytes, image::ImageFormat::Png)
        .map_err(|e| err(format!("not a readable PNG ({e})")))?;
    let (w, h) = (img.width(), img.height());
    if w == 0 || h == 0 || w > max_side || h > max_side {
        return Err(err(format!(
            "{w}×{h} pixels; sprites must be 1..={max_side} a side"
        )));
    }
    Ok(img)
}

/// Loads a PNG as linear, premultiplied RGBA.
pub fn load_png(path: &Path) -> Result<Rgba32FImage, SpriteError> {
    let img = read_png(path, 8192)?;
    let (w, h) = (img.width(), img.height());
    let rgba = img.to_rgba8();
    let mut out = Rgba32FImage::new(w, h);
    for (src, dst) in rgba.pixels().zip(out.pixels_mut()) {
        let a = f32::from(src[3]) / 255.0;
        let lin = |c: u8| srgb_to_linear(f32::from(c) / 255.0) * a;
        *dst = Rgba([lin(src[0]), lin(src[1]), lin(src[2]), a]);
    }
    Ok(out)
}

#[cfg(feature = "editor")]
/// A linear premultiplied image back to straight-alpha sRGB bytes (what `load_png` reads).
pub fn to_png_rgba(img: &Rgba32FImage) -> image::RgbaImage {
    image::RgbaImage::from_fn(img.width(), img.height(), |x, y| {
        let p = img.get_pixel(x, y);
        let a = p[3].clamp(0.0, 1.0);
        let c = |v: f32| {
            let straight = if a > 0.0 {
                (v / a).clamp(0.0, 1.0)
            } else {
                0.0
            };
            (linear_to_srgb(straight) * 255.0).round() as u8
        };
        Rgba([c(p[0]), c(p[1]), c(p[2]), (a * 255.0).round() as u8])
    })
}

#[cfg(feature = "editor")]
fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The mip chain of `img` (halving with a triangle filter down to 1 × 1).
pub fn mip_chain(img: &Rgba32FImage) -> Vec<Rgba32FImage> {
    let mut levels = vec![img.clone()];
    while let Some(last) = levels.last() {
        let (w, h) = last.dimensions();
        if w == 1 && h == 1 {
            break;
        }
        let next = image::imageops::resize(
            last,
            (w / 2).max(1),
            (h / 2).max(1),
            image::imageops::FilterType::Triangle,
        );
        levels.push(next);
    }
    levels
}

/// 4 × the mean premultiplied brightness ((r + g + b) / 3) — ∫ over the quad [-1, 1]².
pub fn brightness_integral(img: &Rgba32FImage) -> f32 {
    let n = (img.width() * img.height()).max(1) as f64;
    let sum: f64 = img
        .pixels()
        .map(|p| f64::from(p[0] + p[1] + p[2]) / 3.0)
        .sum();
    (4.0 * sum / n) as f32
}

fn upload(ctx: &GpuContext, img: &Rgba32FImage, id: u64, label: &str) -> SpriteTexture {
    let levels = mip_chain(img);
    let (w, h) = img.dimensions();
    let (coverage, cell) = coverage(img);
    let texture = crate::gpu::texture_2d(
        &ctx.device,
        &format!("sprite {label}"),
        (w, h),
        levels.len() as u32,
        SPRITE_FORMAT,
        wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
    );
    for (mip, level) in levels.iter().enumerate() {
        let (lw, lh) = level.dimensions();
        let halfs: Vec<half::f16> = level
            .as_raw()
            .iter()
            .map(|&v| half::f16::from_f32(v))
            .collect();
        ctx.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &texture,
                mip_level: mip as u32,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            bytemuck::cast_slice(&halfs),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(lw * 8),
                rows_per_image: Some(lh),
            },
            wgpu::Extent3d {
                width: lw,
                height: lh,
                depth_or_array_layers: 1,
            },
        );
    }
    SpriteTexture {
        id,
        view: texture.create_view(&Default::default()),
        size: (w, h),
        integral: brightness_integral(img),
        cell,
        coverage,
    }
}

/// The built-in sprite `sprite` as a linear, premultiplied image (white light; the
/// colour comes from the gradient). `Image` gives the soft disc.
pub fn generate(sprite: &Sprite) -> Rgba32FImage {
    let n = BUILT_IN_SIZE;
    match sprite {
        Sprite::FlameSheet => {
            let g = FLAME_SHEET_GRID;
            let mut sheet = Rgba32FImage::new(n * g, n * g);
            for fy in 0..g {
                for fx in 0..g {
                    let phase = (fy * g + fx) as f32 / (g * g) as f32;
                    let frame = paint(n, |x, y| flame(x, y, phase, 1.0));
                    image::imageops::replace(
                        &mut sheet,
                        &frame,
                        i64::from(fx * n),
                        i64::from(fy * n),
                    );
                }
            }
            sheet
        }
        Sprite::Point => paint(n, |x, y| {
            let r = (x * x + y * y).sqrt();
            // 1.5-texel anti-aliased edge at r = 0.5.
            (0.5 - r) * n as f32 / 3.0 + 0.5
        }),
        Sprite::Spark => paint(n, |x, y| {
            let r2 = x * x + y * y;
            if r2 >= 1.0 {
                0.0
            } else {
                (1.5 * (-r2 * 14.0).exp() + 0.25 * (1.0 - r2) * (1.0 - r2)).min(1.0)
            }
        }),
        Sprite::FlameWisp => paint(n, |x, y| flame(x, y, 0.0, 0.0)),
        Sprite::SmokePuff => paint(n, |x, y| {
            let r2 = x * x + y * y;
            if r2 >= 1.0 {
                return 0.0;
            }
            let body = (1.0 - r2) * (1.0 - r2);
            let lumps = fbm(x * 2.5 + 7.1, y * 2.5 - 3.3, 4);
            (body * (0.35 + 1.1 * lumps)).clamp(0.0, 1.0)
        }),
        Sprite::SoftDisc | Sprite::Image(_) => paint(n, |x, y| {
            let r2 = x * x + y * y;
            if r2 >= 1.0 {
                0.0
            } else {
                (1.0 - r2) * (1.0 - r2)
            }
        }),
    }
}

/// An `n`² image whose alpha is `alpha(x, y)` over [-1, 1]² (y up), white premultiplied.
fn paint(n: u32, alpha: impl Fn(f32, f32) -> f32) -> Rgba32FImage {
    Rgba32FImage::from_fn(n, n, |i, j| {
        let x = (i as f32 + 0.5) / n as f32 * 2.0 - 1.0;
        let y = 1.0 - (j as f32 + 0.5) / n as f32 * 2.0;
        let a = alpha(x, y).clamp(0.0, 1.0);
        Rgba([a, a, a, a])
    })
}

/// A flame tongue: wide, dense base; a wavering tip. `phase` ∈ [0, 1) animates the
/// waver (a loop), `amount` scales it.
fn flame(x: f32, y: f32, phase: f32, amount: f32) -> f32 {
    // v: 0 at the bottom edge, 1 at the top.
    let v = (y + 1.0) * 0.5;
    let tau = std::f32::consts::TAU;
    let sway = amount * 0.18 * v * v * (tau * (phase + v * 0.8)).sin();
    let lick = amount * 0.06 * v * (tau * (2.0 * phase + v * 2.3)).sin();
    let xs = x - sway - lick;
    // Half-width: round base, pointed tip.
    let width = 0.62 * (1.0 - v).powf(0.85) * (v * 5.0).min(1.0).sqrt() + 1e-3;
    let edge = 1.0 - (xs / width).abs();
    if edge <= 0.0 {
        return 0.0;
    }
    let detail = 0.75 + 0.5 * fbm(x * 3.0 + phase * 11.0, y * 3.0 - phase * 17.0, 3);
    let fade = (1.0 - v).powf(0.6) * (v * 8.0).min(1.0);
    (edge.powf(0.7) * fade * detail).clamp(0.0, 1.0)
}

/// Value-noise fbm in [0, 1] (a fixed hash: the built-ins are identical everywhere).
fn fbm(x: f32, y: f32, octaves: u32) -> f32 {
    let mut sum = 0.0;
    let mut amp = 0.5;
    let mut norm = 0.0;
    let (mut fx, mut fy) = (x, y);
    for _ in 0..octaves {
        sum += amp * value_noise(fx, fy);
        norm += amp;
        amp *= 0.5;
        fx = fx * 2.03 + 1.7;
        fy = fy * 2.03 - 0.9;
    }
    sum / norm
}

fn value_noise(x: f32, y: f32) -> f32 {
    let (ix, iy) = (x.floor(), y.floor());
    let (fx, fy) = (x - ix, y - iy);
    let s = |t: f32| t * t * (3.0 - 2.0 * t);
    let h = |a: f32, b: f32| {
        let mut v = (a as i32 as u32).wrapping_mul(0x9E37_79B1)
            ^ (b as i32 as u32).wrapping_mul(0x85EB_CA77);
        v ^= v >> 15;
        v = v.wrapping_mul(0x2C1B_3C6D);
        v ^= v >> 12;
        (v & 0xffff) as f32 / 65535.0
    };
    let a = h(ix, iy);
    let b = h(ix + 1.0, iy);
    let c = h(ix, iy + 1.0);
    let d = h(ix + 1.0, iy + 1.0);
    let (sx, sy) = (s(fx), s(fy));
    a + (b - a) * sx + (c - a) * sy + (a - b - c + d) * sx * sy
}

#[cfg(feature = "editor")]
/// Writes the built-in sprites into `out` (created if missing) as straight-alpha sRGB
/// PNGs, and the built-in six-way smoke maps (the puff and its sheet) as linear RGBA PNG
/// pairs in Unity's packing: `*_sixway_rtba.png` (right, top, back, alpha) and
/// `*_sixway_lbfe.png` (left, bottom, front, emissive). Returns the files written.
pub fn write_built_ins(out: &Path) -> Result<Vec<PathBuf>, SpriteError> {
    let err = |path: &Path, e: &dyn std::fmt::Display| SpriteError {
        path: path.display().to_string(),
        reason: e.to_string(),
    };
    std::fs::create_dir_all(out).map_err(|e| err(out, &e))?;
    let mut written = Vec::new();
    let mut save = |img: image::RgbaImage, name: String| {
        let path = out.join(name);
        img.save(&path).map_err(|e| err(&path, &e))?;
        written.push(path);
        Ok::<(), SpriteError>(())
    };
    for sprite in Sprite::BUILT_IN {
        let name = sprite
            .label()
            .split(' ')
            .take(2)
            .collect::<Vec<_>>()
            .join("_");
        save(to_png_rgba(&generate(&sprite)), format!("{name}.png"))?;
    }
    use sixway_maps::{PUFF_SEED, puff, puff_sheet, to_png_linear};
    for (name, maps) in [
        ("smoke_puff", puff(PUFF_SEED)),
        ("smoke_puff_sheet", puff_sheet(PUFF_SEED)),
    ] {
        for (packing, img) in [("rtba", &maps.rtba), ("lbfe", &maps.lbfe)] {
            save(to_png_linear(img), format!("{name}_sixway_{packing}.png"))?;
        }
    }
    Ok(written)
}
