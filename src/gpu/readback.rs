//! Reading a texture back: a copy into a mappable buffer with rows padded to wgpu's
//! alignment, and the rows without their padding.

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
