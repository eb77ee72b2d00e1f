//! The simulation: CPU-side planning (time, exact spawn counts), the GPU update pass over
//! ping-pong buffers, and a CPU reference of the same maths for tests.

pub mod batch;
pub mod cpu_reference;
pub mod depth_collision;
pub mod event_scan;
pub mod gpu_sim;
pub mod hooks;
pub mod modules;
pub mod planner;
pub mod sim_state;
pub mod snapshot;
pub mod stepper;
pub mod trails;
pub mod update_pass;

pub use cpu_reference::CpuSim;
pub use gpu_sim::{GpuSim, SimError};
pub use modules::Modules;
pub use planner::{EffectPlanner, EmitterPlanner};
pub use stepper::Stepper;
