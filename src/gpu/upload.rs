//! [`Uploads`]: a player's per-frame parameter uploads through reused staging memory.
//!
//! `Queue::write_buffer` stages each write in a buffer of its own, freshly allocated, and
//! copies it before the whole submission. A player uploads a parameter block per
//! instance, emitter and step, and a look per instance and emitter, every frame: through
//! a staging belt those bytes go into mapped chunks that are reused once the GPU has
//! copied them (no allocation and no fresh pages per frame), and the copies are recorded
//! in the host's encoder, in order with the work that reads them.

use wgpu::util::StagingBelt;

/// Bytes of one staging chunk (a frame of 100 torch instances uploads about 600 KiB).
const CHUNK_BYTES: u64 = 1 << 20;

/// Staging memory for the uploads recorded into a host's encoder.
pub struct Uploads {
    belt: StagingBelt,
}

impl Uploads {
    /// Uploads on `device`.
    pub fn new(device: &wgpu::Device) -> Self {
        Self {
            belt: StagingBelt::new(device.clone(), CHUNK_BYTES),
        }
    }

    /// Mapped memory whose `bytes` are copied into `target` at `offset` by a copy recorded
    /// now into `enc` (outside any pass); `None` for zero bytes. `offset` and `bytes` are
    /// multiples of 4.
    pub fn write(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        target: &wgpu::Buffer,
        offset: u64,
        bytes: u64,
    ) -> Option<wgpu::BufferViewMut> {
        let size = wgpu::BufferSize::new(bytes)?;
        Some(self.belt.write_buffer(enc, target, offset, size))
    }

    /// Copies `data` into `target` at `offset` by a copy recorded now into `enc` (outside
    /// any pass), in order with the commands around it. `offset` and the length of `data`
    /// are multiples of 4.
    pub fn write_bytes(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        target: &wgpu::Buffer,
        offset: u64,
        data: &[u8],
    ) {
        if let Some(mut view) = self.write(enc, target, offset, data.len() as u64) {
            view.copy_from_slice(data);
        }
    }

    /// Closes this frame's chunks: they are mapped for reuse once `enc`'s commands are
    /// submitted and copied. Call it after the last [`Uploads::write`] into `enc`.
    pub fn finish(&mut self, enc: &wgpu::CommandEncoder) {
        self.belt.finish_and_recall_on_submit(enc);
    }
}
