//! Looking at a playing [`Player`]: its clock, each instance's emitters (pool, live
//! window, spawn accounting), and blocking readbacks of counts and positions for tools
//! and tests. None of these is needed to play an effect.

use glam::Vec3;

use crate::gpu::types::Particle;
use crate::render::{BillboardPass, DrawItem, FrameResources};
use crate::runtime::instances::Backing;
use crate::runtime::{InstanceId, Player, PlayerError};
use crate::sim::gpu_sim::{SimError, SimState};
use crate::sim::planner::SpawnStats;

/// What the player's clock did at the last [`Player::record`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ClockStats {
    /// Steps the last record ran.
    pub steps: u32,
    /// The size of each, seconds.
    pub step_secs: f32,
    /// Steps dropped since the start because a frame asked for too many (a hitch).
    pub dropped_steps: u64,
}

/// One emitter of one instance.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EmitterStats {
    /// Slots in the emitter's pool.
    pub capacity: u32,
    /// Slots the update and the draw visit: the part of the ring that can hold living
    /// particles.
    pub visited: u32,
    /// The first of them (the range wraps at the capacity).
    pub first_visited: u32,
    /// Spawn accounting (born, dropped, cut short).
    pub spawn: SpawnStats,
}

/// An emitter's particles counted on the GPU.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ParticleCount {
    /// Alive after the last step.
    pub alive: u32,
    /// Killed since the start for a non-finite position or velocity (an unstable
    /// integrator or an extreme force; 0 for batched instances, which do not count).
    pub nonfinite: u32,
    /// An emitter fed by events: the children its parents' events asked for since the
    /// start, and those the per-step caps dropped.
    pub events: Option<EventCount>,
}

/// The children an emitter's events asked for and dropped (see [`ParticleCount`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EventCount {
    /// Children asked for since the start.
    pub asked: u32,
    /// Children dropped by the per-step caps since the start.
    pub dropped: u32,
}

impl Player {
    /// Sprite files that failed to load at the last `record` (the emitter draws with a
    /// built-in sprite instead): the emitter's index, and a message naming the file.
    pub fn sprite_errors(&self) -> Vec<(usize, String)> {
        self.frame
            .sprite_errors
            .iter()
            .map(|(i, e)| (*i, e.to_string()))
            .collect()
    }

    /// What the clock did at the last [`Player::record`].
    pub fn clock_stats(&self) -> ClockStats {
        ClockStats {
            steps: self.last_steps.0,
            step_secs: self.last_steps.1,
            dropped_steps: self.stepper.dropped_steps,
        }
    }

    /// An instance's simulated time, seconds (`None`: removed).
    pub fn time_secs(&self, id: InstanceId) -> Option<f64> {
        self.with_state(id, |s| s.planner().time_secs)
    }

    /// Each emitter of an instance (`None`: removed).
    pub fn emitter_stats(&self, id: InstanceId) -> Option<Vec<EmitterStats>> {
        self.with_state(id, |s| {
            (0..self.effect.emitters.len())
                .map(|i| {
                    let (capacity, window) = s
                        .emitter_buffers(i)
                        .map_or((0, Default::default()), |b| (b.capacity, b.window));
                    EmitterStats {
                        capacity,
                        visited: window.len,
                        first_visited: window.first_slot,
                        spawn: s
                            .planner()
                            .emitters
                            .get(i)
                            .map(|p| p.stats)
                            .unwrap_or_default(),
                    }
                })
                .collect()
        })
    }

    /// Counts each emitter's particles of an instance (a blocking readback: it waits for
    /// the GPU; for tools, not every frame).
    pub fn count_particles(&self, id: InstanceId) -> Result<Vec<ParticleCount>, PlayerError> {
        let instance = self.instances.get(id).ok_or(PlayerError::NoInstance)?;
        let emitters = self.effect.emitters.iter().enumerate();
        let mut counts = Vec::with_capacity(self.effect.emitters.len());
        for (i, e) in emitters {
            let count = match &instance.state {
                _ if !e.enabled => ParticleCount::default(),
                Backing::Own(sim) => {
                    let [alive, nonfinite] = sim.read_counters(i)?;
                    let events = sim.read_event_header(i)?.map(|h| EventCount {
                        asked: h.total,
                        dropped: h.dropped,
                    });
                    ParticleCount {
                        alive,
                        nonfinite,
                        events,
                    }
                }
                Backing::Batched { .. } => ParticleCount {
                    alive: self
                        .particles(id, i)?
                        .iter()
                        .filter(|p| p.is_alive())
                        .count() as u32,
                    nonfinite: 0,
                    events: None,
                },
            };
            counts.push(count);
        }
        Ok(counts)
    }

    /// The world-space positions of an instance's living particles, over every emitter
    /// with particles of its own (a blocking readback; to frame a camera, say).
    pub fn particle_positions(&self, id: InstanceId) -> Result<Vec<Vec3>, PlayerError> {
        Ok(self
            .particle_motion(id)?
            .into_iter()
            .map(|(p, _)| p)
            .collect())
    }

    /// The world-space position and velocity (m/s) of an instance's living particles,
    /// over every emitter with particles of its own (a blocking readback: the export's
    /// framing and motion scale).
    #[doc(hidden)]
    pub fn particle_motion(&self, id: InstanceId) -> Result<Vec<(Vec3, Vec3)>, PlayerError> {
        let origins = self.origins(id)?;
        let mut out = Vec::new();
        for (i, e) in self.effect.emitters.iter().enumerate() {
            // Stateless pools hold spawn records, not positions.
            if !e.enabled || e.stateless {
                continue;
            }
            let origin = origins.get(i).copied().unwrap_or_default();
            let alive = self
                .particles(id, i)?
                .into_iter()
                .filter(Particle::is_alive);
            out.extend(alive.map(|p| {
                (
                    self.to_host(p.position() + origin),
                    self.to_host(p.velocity()),
                )
            }));
        }
        Ok(out)
    }

    /// Emitter `emitter`'s particles in instance `id`, in the emitter's simulation space
    /// (a blocking readback, for tests that compare instances bit for bit).
    #[doc(hidden)]
    pub fn particles(&self, id: InstanceId, emitter: usize) -> Result<Vec<Particle>, PlayerError> {
        let instance = self.instances.get(id).ok_or(PlayerError::NoInstance)?;
        let read = match &instance.state {
            Backing::Own(sim) => sim.read_particles(emitter),
            Backing::Batched { batch, slot } => match self.batches.get(*batch) {
                Some(b) => b.read_particles(*slot, emitter),
                None => Err(SimError::Readback("no such batch".into())),
            },
        };
        Ok(read?)
    }

    /// The instances each batch's buffers hold now, batch by batch (they grow at the
    /// record after an instance finds them full; for tests of the growth).
    #[doc(hidden)]
    pub fn batch_buffer_slots(&self) -> Vec<u32> {
        self.batches.iter().map(|b| b.buffer_slots()).collect()
    }

    /// Emitter `emitter`'s trail ring in instance `id` (a blocking readback; none without
    /// a trail — an emitter with one runs a simulation of its own).
    #[doc(hidden)]
    pub fn trail(
        &self,
        id: InstanceId,
        emitter: usize,
    ) -> Result<Option<crate::sim::gpu_sim::TrailRing>, PlayerError> {
        let instance = self.instances.get(id).ok_or(PlayerError::NoInstance)?;
        match &instance.state {
            Backing::Own(sim) => Ok(sim.read_trail(emitter)?),
            Backing::Batched { .. } => Ok(None),
        }
    }

    /// The effect instance `id` runs: the player's, with the instance's seed and its
    /// emitters placed in the world (tests compare it with a simulation of its own).
    #[doc(hidden)]
    pub fn instance_effect(&self, id: InstanceId) -> Option<&crate::Effect> {
        self.instances.get(id).map(|i| i.effect())
    }

    /// The tile rasteriser, when the device has one (tests force its lists to overflow).
    #[doc(hidden)]
    pub fn tile_pass(&mut self) -> Option<&mut crate::render::TilePass> {
        self.tiles.as_mut()
    }

    /// The compute splat (tests compare its resolves).
    #[doc(hidden)]
    pub fn splat_pass(&mut self) -> &mut crate::render::SplatPass {
        &mut self.splat
    }

    /// The draws prepared by the last record (tests look at the paths and layers chosen).
    #[doc(hidden)]
    pub fn draw_items(&self) -> &[DrawItem] {
        &self.items
    }

    /// The draw resources, to switch the optimisations tests compare against (the live
    /// window, sprite trimming, indexed quads).
    #[doc(hidden)]
    pub fn draw_resources(&mut self) -> (&mut FrameResources, &mut BillboardPass) {
        (&mut self.frame, &mut self.billboard)
    }

    /// `f` of the instance's state as the draw passes see it.
    pub(super) fn with_state<T>(
        &self,
        id: InstanceId,
        f: impl FnOnce(&dyn SimState) -> T,
    ) -> Option<T> {
        match &self.instances.get(id)?.state {
            Backing::Own(sim) => Some(f(sim.as_ref())),
            Backing::Batched { batch, slot } => {
                let member = self.batches.get(*batch)?.member(*slot)?;
                Some(f(&member))
            }
        }
    }
}
