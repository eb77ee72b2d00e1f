//! Trails on the GPU: each particle's last positions in a ring written by the update
//! (`shaders/trail_on.wgsl`), or a ribbon per parent's links written by the event scan
//! (`shaders/events.wgsl`), read by the billboards' ribbon (`shaders/trail.wgsl`). This
//! file makes the ring buffer, mirrors the shaders' choice of points and reads links.

use crate::effect::TrailMode;
use crate::gpu::GpuContext;

/// Bytes before the ring's entries: points, steps between points, padding.
const HEADER_BYTES: u64 = 16;

/// Bytes of a ring of `points` entries per slot for `capacity` slots.
pub fn ring_bytes(capacity: u32, points: u32) -> u64 {
    HEADER_BYTES + u64::from(capacity) * u64::from(points) * 16
}

/// A ring of `points` entries per slot for `capacity` slots, its header written (`mode`:
/// positions, or per parent one link per slot, see [`Link`]).
pub fn ring_buffer(
    ctx: &GpuContext,
    capacity: u32,
    points: u32,
    every: u32,
    mode: TrailMode,
) -> wgpu::Buffer {
    let size = ring_bytes(capacity, points);
    let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("trail_ring"),
        size,
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_DST
            | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    ctx.queue.write_buffer(
        &buffer,
        0,
        bytemuck::cast_slice(&[points, every.max(1), mode as u32, 0]),
    );
    buffer
}

/// The ring entries the ribbon of a particle draws after its own position, nearest
/// first, once `steps` steps have run (the CPU mirror of `trail_point` in
/// `shaders/trail.wgsl`): the `points − 1` newest entries recorded before the last step.
pub fn trail_indices(points: u32, every: u32, steps: u64) -> Vec<u32> {
    let every = every.max(1);
    let last = steps.saturating_sub(1) as u32;
    let before = last.wrapping_sub(1);
    let k = before - before % every;
    (1..points)
        .map(|j| (k / every + points - (j - 1) % points) % points)
        .collect()
}

/// One slot's entry of a ribbon per parent (`TRAIL_PER_PARENT` in
/// `shaders/trail_ring.wgsl`): the child its parent spawned before it and its own birth.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Link {
    /// The previous child's slot (none for a parent's first child).
    pub prev: Option<u32>,
    /// The previous child's birth stamp (the step's number + 1).
    pub prev_stamp: u32,
    /// This particle's birth stamp (0: never linked).
    pub stamp: u32,
}

impl Link {
    /// The link in a ring entry (its f32 lanes hold u32 bits).
    pub fn from_entry(entry: [f32; 4]) -> Self {
        let [prev, prev_stamp, stamp, _] = entry.map(f32::to_bits);
        Self {
            prev: (prev != u32::MAX).then_some(prev),
            prev_stamp,
            stamp,
        }
    }

    /// The previous child when the ribbon draws the segment to it: its slot still holds
    /// the child linked (`links[prev].stamp` is the stamp linked) — the draw also asks
    /// that it lives.
    pub fn drawn_prev(&self, links: &[Link]) -> Option<u32> {
        let prev = self.prev?;
        (links.get(prev as usize)?.stamp == self.prev_stamp).then_some(prev)
    }
}
