//! Trails on the GPU: each particle's last positions in a ring written by the update
//! (`shaders/trail_on.wgsl`) and read by the billboards' ribbon (`shaders/trail.wgsl`).
//! This file makes the ring buffer and mirrors the shaders' choice of points.

use crate::gpu::GpuContext;

/// Bytes before the ring's entries: points, steps between points, padding.
const HEADER_BYTES: u64 = 16;

/// Bytes of a ring of `points` entries per slot for `capacity` slots.
pub fn ring_bytes(capacity: u32, points: u32) -> u64 {
    HEADER_BYTES + u64::from(capacity) * u64::from(points) * 16
}

/// A ring of `points` entries per slot for `capacity` slots, its header written.
pub fn ring_buffer(ctx: &GpuContext, capacity: u32, points: u32, every: u32) -> wgpu::Buffer {
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
        bytemuck::cast_slice(&[points, every.max(1), 0, 0]),
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
