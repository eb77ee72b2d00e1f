//! GPU plumbing: the device context and the structs shared with WGSL.

pub mod context;
pub mod timer;
pub mod types;

pub use context::{GpuContext, GpuError};
