//! The runtime: a [`Player`] plays one effect, as any number of instances, inside a
//! host's wgpu frame — its compute work in the host's encoder, its particles in the
//! host's render pass, tested against the host's depth buffer.

mod instances;
mod player;

pub use crate::render::Camera;
pub use instances::InstanceId;
pub use player::{Player, PlayerError, PlayerSettings};
