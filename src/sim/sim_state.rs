//! What the draw passes read of a simulation ([`SimState`]): each emitter's buffers and
//! where its live particles are ([`EmitterBuffers`]), and a trail's ring read back.

use crate::gpu::types::StateLayout;
use crate::sim::planner::{EffectPlanner, LiveWindow};

/// A trail's ring read back ([`crate::sim::gpu_sim::GpuSim::read_trail`]).
#[derive(Clone, Debug, PartialEq)]
pub struct TrailRing {
    /// Entries per slot.
    pub points: u32,
    /// Steps between recorded points.
    pub every_steps: u32,
    /// `points` entries per slot, point-major (every slot's point 0, then every slot's
    /// point 1, …: `shaders/trail_ring.wgsl`): position (simulation space) and age.
    pub entries: Vec<[f32; 4]>,
}

impl TrailRing {
    /// Point `r` of `slot` (see [`TrailRing::entries`]).
    pub fn entry(&self, slot: usize, r: usize) -> [f32; 4] {
        let slots = self.entries.len() / self.points.max(1) as usize;
        self.entries[r * slots + slot]
    }
}

/// Read-only views of an emitter's state buffers, for the draw passes.
pub struct EmitterBuffers<'a> {
    /// State before the last step.
    pub previous: &'a wgpu::Buffer,
    /// State after the last step.
    pub current: &'a wgpu::Buffer,
    /// Slots.
    pub capacity: u32,
    /// Changes whenever the buffers are recreated (bind-group caches key on it).
    pub generation: u64,
    /// Which of the pair is current (0 or 1).
    pub parity: usize,
    /// How the state is stored (packed and tiny are read through `PackedParticle` views).
    pub layout: StateLayout,
    /// The tiny state's birth table (a placeholder for the other layouts).
    pub births: &'a wgpu::Buffer,
    /// Tiny state: `LookUniform::tiny`, `tiny_b` and `tiny_c` — the current state's time
    /// (double-single hi, lo; f32 bits), the birth table's first sequence number and
    /// entries; the table's index mask, the last step's size (f32 bits), the oldest
    /// entry's first counter and the counters spanned; the span before the last step.
    pub tiny: [[u32; 4]; 3],
    /// Particles spawned so far (the ring's position: packed state re-derives lifetimes).
    pub spawned_total: u64,
    /// Lifetime range of the emitter.
    pub life_range: (f32, f32),
    /// Effect seed and emitter salt.
    pub seed_salt: (u32, u32),
    /// The slots that can hold living particles (draws and the sort visit only these).
    pub window: LiveWindow,
    /// Where this pool's slots start in the buffers (a batched instance's segment; else 0).
    pub slot_base: u32,
    /// The trail's ring of positions (an emitter with a trail).
    pub trail: Option<&'a wgpu::Buffer>,
    /// The number of the last step (the trail's newest entries are older).
    pub last_step: u32,
}

/// What the draw passes read of a simulation: its pools and its planner (a
/// [`crate::sim::gpu_sim::GpuSim`], or one instance of an [`crate::sim::batch::InstanceBatch`]).
pub trait SimState {
    /// Buffers of emitter `index` for drawing.
    fn emitter_buffers(&self, index: usize) -> Option<EmitterBuffers<'_>>;
    /// The CPU planning: times, origins, spawn counters.
    fn planner(&self) -> &EffectPlanner;
}
