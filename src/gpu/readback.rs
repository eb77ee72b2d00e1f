//! Reading back: a mappable buffer's bytes ([`map_read`]), and a texture's copy into one
//! with rows padded to wgpu's alignment, and the rows without their padding.

use super::{GpuContext, GpuError};

/// A texture's copy on its way to the CPU.
pub struct TextureReadback {
    /// The mappable buffer the copy lands in.
    pub buffer: wgpu::Buffer,
    /// Width and height in texels.
    pub size: (u32, u32),
    /// Bytes per padded row.
    pub bytes_per_row: u32,
    /// Bytes per texel.
    pub texel_bytes: u32,
}

impl TextureReadback {
    /// Records a copy of `texture` (an uncompressed colour format, `COPY_SRC`) into a new
    /// buffer.
    pub fn record(
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        texture: &wgpu::Texture,
        label: &str,
    ) -> Self {
        let (w, h) = (texture.width(), texture.height());
        let texel_bytes = texture.format().block_copy_size(None).unwrap_or(4);
        let bytes_per_row = (w * texel_bytes).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: u64::from(bytes_per_row) * u64::from(h),
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
            buffer,
            size: (w, h),
            bytes_per_row,
            texel_bytes,
        }
    }

    /// The rows of the mapped `bytes` without their padding (`None` if too short).
    pub fn rows<'a>(&self, bytes: &'a [u8]) -> Option<Vec<&'a [u8]>> {
        (0..self.size.1 as usize)
            .map(|y| {
                let start = y * self.bytes_per_row as usize;
                bytes.get(start..start + (self.size.0 * self.texel_bytes) as usize)
            })
            .collect()
    }
}

/// Maps a `MAP_READ` buffer and copies its bytes out (blocking).
pub fn map_read(ctx: &GpuContext, staging: &wgpu::Buffer) -> Result<Vec<u8>, GpuError> {
    let (tx, rx) = std::sync::mpsc::channel();
    staging.slice(..).map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    ctx.device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| GpuError::Readback(e.to_string()))?;
    rx.recv()
        .map_err(|e| GpuError::Readback(e.to_string()))?
        .map_err(|e| GpuError::Readback(e.to_string()))?;
    let data = staging
        .slice(..)
        .get_mapped_range()
        .map_err(|e| GpuError::Readback(e.to_string()))?
        .to_vec();
    staging.unmap();
    Ok(data)
}
