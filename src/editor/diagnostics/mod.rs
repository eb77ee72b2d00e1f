//! What the editor measures and shows about the running effect: frame and simulation
//! statistics ([`stats`]), the particle inspector and the state view ([`inspector`]), each
//! emitter's GPU cost ([`emitter_cost`]) and `--profile`'s stage timings
//! ([`stage_profiler`]).

pub mod emitter_cost;
pub mod inspector;
pub mod stage_profiler;
pub mod stats;
