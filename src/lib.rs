//! ignis — design real-time GPU fire effects, and play them in any wgpu program.
//!
//! The library is the runtime: load a preset made in the ignis editor, create a
//! [`Player`] for it on your own `wgpu::Device`, add instances, and each frame record its
//! simulation into your encoder and draw it inside your own render pass, depth-tested
//! against your depth buffer.
//!
//! ```no_run
//! # fn frame(device: &wgpu::Device, queue: &wgpu::Queue,
//! #          color: &wgpu::TextureView, depth: &wgpu::TextureView) -> Result<(), ignis::PlayerError> {
//! use ignis::{Camera, Player, PlayerSettings};
//!
//! // Once: the effect, a player on the host's device and formats, an instance.
//! let effect = ignis::preset::load("presets/torch.ron".as_ref())?;
//! let settings = PlayerSettings {
//!     depth_format: Some(wgpu::TextureFormat::Depth32Float),
//!     ..PlayerSettings::new(wgpu::TextureFormat::Rgba16Float)
//! };
//! let mut player = Player::new(device, queue, &effect, settings)?;
//! let torch = player.add_instance(glam::Mat4::from_translation(glam::vec3(2.0, 1.5, 0.0)), 7)?;
//!
//! // Every frame: advance, record the compute work, draw in the host's pass.
//! player.set_transform(torch, glam::Mat4::from_translation(glam::vec3(2.0, 1.5, 0.1)));
//! player.advance(1.0 / 60.0);
//! let camera = Camera::new(
//!     glam::camera::rh::view::look_at_mat4(glam::vec3(0.0, 2.0, 6.0), glam::Vec3::ZERO, glam::Vec3::Y),
//!     glam::camera::rh::proj::directx::perspective(0.8, 16.0 / 9.0, 0.1, 100.0),
//!     (1280, 720),
//! );
//! let mut encoder = device.create_command_encoder(&Default::default());
//! // ... the host's opaque pass writes `depth` here ...
//! player.record(&mut encoder, &camera, Some(depth))?;
//! {
//!     // Colour loaded, depth read-only: the particles test against it and sample it.
//!     let targets = ignis::HostTargets { color, resolve_target: None, depth: Some(depth) };
//!     let mut pass = targets.begin_pass(&mut encoder);
//!     player.draw(&mut pass);
//! }
//! queue.submit([encoder.finish()]);
//! # Ok(())
//! # }
//! ```
//!
//! `docs/embedding.md` describes the frame's order of calls, what the host provides,
//! threading and costs. [`effect`] is the effect model a preset holds (what a tool built
//! on ignis edits), [`preset`] reads and writes it as RON.
#![deny(missing_docs)]

pub(crate) mod runtime;

pub use effect::Effect;
/// The math library of the API (`Mat4`, `Vec3`): hosts on another `glam` version use this one
/// or pass plain `[[f32; 4]; 4]` arrays.
pub use glam;
pub use gpu::commands::CommandCounts;
pub use gpu::{
    AdapterProfile, GpuError, INT64_ATOMICS, ProfileKind, ProfileRequest, ProfileSetting,
};
pub use runtime::{
    Camera, ClockStats, EffectLight, EmitterStats, EventCount, HostTargets, InstanceId, IntoMat4,
    Layers, MAX_POINT_LIGHTS, MissingLimit, PLAYER_SHADERS, ParticleCount, ParticleInfo, Player,
    PlayerError, PlayerSettings, PointLight, STORAGE_BUFFERS_REQUIRED, SceneLighting,
    required_limits,
};
pub use shaders::ShaderError;
pub use sim::SimError;
pub use sim::planner::SpawnStats;

pub mod effect;
pub mod preset;

pub(crate) mod composite;
pub(crate) mod gpu;
pub(crate) mod headless;
pub(crate) mod render;
pub(crate) mod rng;
pub(crate) mod shaders;
pub(crate) mod sim;

#[cfg(feature = "editor")]
pub(crate) mod bench;
#[cfg(feature = "editor")]
pub mod cli;
#[cfg(feature = "editor")]
pub(crate) mod editor;
#[cfg(feature = "editor")]
pub mod export;
#[cfg(feature = "editor")]
pub(crate) mod hot_reload;
#[cfg(feature = "editor")]
pub mod tune;

#[doc(hidden)]
pub mod testing;
