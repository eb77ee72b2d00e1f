//! The runtime: a [`Player`] plays one effect, as any number of instances, inside a
//! host's wgpu frame — its compute work in the host's encoder, its particles in the
//! host's render pass, tested against the host's depth buffer.

mod device_check;
mod editing;
mod effect_light;
mod frame_commands;
mod heat_haze;
mod host_depth;
mod host_targets;
mod inspect;
mod instances;
mod layers;
mod lighting;
mod particle_info;
mod player;
mod remap;
mod seeking;

pub use crate::render::Camera;
pub use crate::render::matrix::IntoMat4;
pub use crate::render::scene_lighting::{MAX_POINT_LIGHTS, PointLight, SceneLighting};
pub use device_check::{MissingLimit, STORAGE_BUFFERS_REQUIRED, required_limits};
pub use editing::PLAYER_SHADERS;
pub use effect_light::EffectLight;
pub use host_targets::HostTargets;
pub use inspect::{ClockStats, EmitterStats, EventCount, ParticleCount};
pub use instances::InstanceId;
pub use layers::Layers;
pub(crate) use layers::Resolves;
pub use particle_info::ParticleInfo;
pub use player::{Player, PlayerError, PlayerSettings};
