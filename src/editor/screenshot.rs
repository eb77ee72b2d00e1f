//! Reading the window's image back to a PNG (`ignis edit --screenshot`).

use std::path::PathBuf;

use anyhow::{Context as _, anyhow};

use crate::gpu::GpuContext;
use crate::sim::gpu_sim::map_read;

/// A copy of a frame on its way to the CPU.
pub struct Screenshot {
    /// Where the PNG goes.
    pub path: PathBuf,
    buffer: wgpu::Buffer,
    size: (u32, u32),
    bytes_per_row: u32,
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
        let (w, h) = (texture.width(), texture.height());
        let bytes_per_row = (w * 4).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("editor::screenshot"),
            size: bytes_per_row as u64 * h as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        encoder.copy_texture_to_buffer(
            texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(bytes_per_row),
                    rows_per_image: Some(h),
                },
            },
            texture.size(),
        );
        Self {
            path,
            buffer,
            size: (w, h),
            bytes_per_row,
            format: texture.format(),
        }
    }
}

/// Waits for the copy (submitted by the caller), converts to RGBA8 and writes the PNG.
pub fn read_back(ctx: &GpuContext, shot: Screenshot) -> anyhow::Result<image::RgbaImage> {
    let bytes = map_read(ctx, &shot.buffer)?;
    let (w, h) = shot.size;
    let swap_red_blue = match shot.format {
        wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb => true,
        wgpu::TextureFormat::Rgba8Unorm | wgpu::TextureFormat::Rgba8UnormSrgb => false,
        other => return Err(anyhow!("cannot save a screenshot of a {other:?} surface")),
    };
    let mut pixels = Vec::with_capacity((w * h * 4) as usize);
    for y in 0..h as usize {
        let start = y * shot.bytes_per_row as usize;
        let row = bytes
            .get(start..start + (w * 4) as usize)
            .ok_or_else(|| anyhow!("screenshot readback is too short"))?;
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
