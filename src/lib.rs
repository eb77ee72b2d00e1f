//! ignis — design real-time GPU fire effects.
//!
//! The library holds everything the binary, the tests and the benches share: the effect
//! model and presets, the shader library, the GPU simulation (update pass) with its CPU
//! reference, and the renderer (billboard pass + tonemap).

pub mod editor;
pub mod effect;
pub mod gpu;
pub mod headless;
pub mod preset;
pub mod render;
pub mod rng;
pub mod shaders;
pub mod sim;

pub use effect::Effect;
pub mod bench;
pub mod hot_reload;
