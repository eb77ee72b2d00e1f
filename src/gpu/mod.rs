//! GPU plumbing: the device context and the structs shared with WGSL.

pub mod context;
pub mod timer;
pub mod types;

pub use context::{GpuContext, GpuError};

/// A compute-stage storage-buffer binding (read-only or read-write), the most common
/// layout entry of the compute passes.
pub fn compute_storage_entry(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}
