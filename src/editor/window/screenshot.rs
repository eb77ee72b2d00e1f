//! Reading the window's image back to a PNG (`ignis edit --screenshot`).

use std::path::PathBuf;

use anyhow::{Context as _, anyhow};

use crate::gpu::{GpuContext, TextureReadback};
use crate::sim::gpu_sim::map_read;

/// A copy of a frame on its way to the CPU.
pub struct Screenshot {
    /// Where the PNG goes.
    pub path: PathBuf,
    copy: TextureReadback,
    format: wgpu::TextureFormat,
}

impl Screenshot {
    /// Records a copy of `texture` (a `COPY_SRC` frame) into a readback buffer.
    pub fn record(
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        texture: &wgpu::Texture,
        path: PathBuf,
    ) -> Self {
        Self {
            path,
            copy: TextureReadback::record(&ctx.device, encoder, texture, "editor::screenshot"),
            format: texture.format(),
        }
    }
}

/// Waits for the copy (submitted by the caller), converts to RGBA8 and writes the PNG.
pub fn read_back(ctx: &GpuContext, shot: Screenshot) -> anyhow::Result<image::RgbaImage> {
    let bytes = map_read(ctx, &shot.copy.buffer)?;
    let (w, h) = shot.copy.size;
    let swap_red_blue = match shot.format {
        wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb => true,
        wgpu::TextureFormat::Rgba8Unorm | wgpu::TextureFormat::Rgba8UnormSrgb => false,
        other => return Err(anyhow!("cannot save a screenshot of a {other:?} surface")),
    };
    let rows = shot
        .copy
        .rows(&bytes)
        .ok_or_else(|| anyhow!("screenshot readback is too short"))?;
    let mut pixels = Vec::with_capacity((w * h * 4) as usize);
    for row in rows {
        for px in row.chunks_exact(4) {
            let (r, b) = if swap_red_blue {
                (px[2], px[0])
            } else {
                (px[0], px[2])
            };
            // The window is opaque; some surfaces leave alpha undefined.
            pixels.extend_from_slice(&[r, px[1], b, 255]);
        }
    }
    let image = image::RgbaImage::from_raw(w, h, pixels)
        .ok_or_else(|| anyhow!("screenshot size mismatch"))?;
    if let Some(dir) = shot.path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    image
        .save(&shot.path)
        .with_context(|| format!("writing {}", shot.path.display()))?;
    Ok(image)
}
