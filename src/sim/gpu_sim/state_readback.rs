//! Reading a simulation back (and writing particles in): an emitter's particles, counters,
//! trail ring and event header, and the blocking buffer readbacks under them.

use super::*;
use crate::gpu::commands::CountedCompute;

impl GpuSim {
    /// Emitter `index`'s trail ring (a blocking readback): points per slot, steps between
    /// them, and the entries (`points` per slot: position, and the age then).
    pub fn read_trail(&self, index: usize) -> Result<Option<TrailRing>, SimError> {
        let Some(ring) = self.hooks(index).and_then(|h| h.trail.as_ref()) else {
            return Ok(None);
        };
        let bytes = read_buffer(&self.ctx, ring, ring.size())?;
        let header: [u32; 4] = bytemuck::pod_read_unaligned(&bytes[..16]);
        Ok(Some(TrailRing {
            points: header[0],
            every_steps: header[1],
            entries: bytemuck::pod_collect_to_vec(&bytes[16..]),
        }))
    }

    /// Emitter `index`'s spawn-list header (a child of an event): this step's children,
    /// and those the events asked for and the cap dropped since the start.
    pub fn read_event_header(&self, index: usize) -> Result<Option<EventHeader>, SimError> {
        let Some(list) = self.hooks(index).and_then(|h| h.list.as_ref()) else {
            return Ok(None);
        };
        let bytes = read_buffer(&self.ctx, list, size_of::<EventHeader>() as u64)?;
        Ok(Some(bytemuck::pod_read_unaligned(&bytes)))
    }

    /// Overwrites emitter `index`'s current (and previous) state (benches and tests that
    /// need an exact initial condition). `particles` is truncated to the capacity.
    pub fn write_particles(
        &mut self,
        index: usize,
        particles: &[Particle],
    ) -> Result<(), SimError> {
        let s = self
            .emitters
            .get(index)
            .ok_or_else(|| SimError::Readback(format!("no emitter {index}")))?;
        let n = particles.len().min(s.capacity as usize);
        if s.layout != StateLayout::Full {
            return Err(SimError::Readback(
                "write_particles needs full (unpacked) state".into(),
            ));
        }
        for b in &s.buffers {
            self.ctx
                .queue
                .write_buffer(b, 0, bytemuck::cast_slice(&particles[..n]));
        }
        if let Some(s) = self.emitters.get_mut(index) {
            s.whole_pool_until = f64::INFINITY;
        }
        Ok(())
    }

    /// Reads emitter `index`'s current state back (blocking; tests and tools).
    pub fn read_particles(&self, index: usize) -> Result<Vec<Particle>, SimError> {
        let s = self
            .emitters
            .get(index)
            .ok_or_else(|| SimError::Readback(format!("no emitter {index}")))?;
        let bytes = read_buffer(&self.ctx, &s.buffers[s.current], s.layout.bytes(s.capacity))?;
        if s.layout == StateLayout::Full {
            return Ok(bytemuck::pod_collect_to_vec(&bytes));
        }
        let planner = self.planner.emitters.get(index);
        let total = planner.map_or(0, |p| p.spawned_total());
        let life_of =
            |slot: u32| packed_life(s.capacity, total, (s.seed, s.salt), s.life_range, slot);
        let packed: Vec<PackedParticle> = bytemuck::pod_collect_to_vec(&bytes);
        if s.layout == StateLayout::Packed {
            return Ok(packed
                .iter()
                .enumerate()
                .map(|(slot, q)| q.unpack(life_of(slot as u32).1))
                .collect());
        }
        // Tiny: ages from the birth table's batches, as the GPU computes them.
        let now = planner.map_or(0.0, |p| p.clock_secs());
        Ok((0..s.capacity)
            .map(|slot| {
                let words: [u32; 5] = bytemuck::cast(packed[(slot / 2) as usize]);
                let (c, life) = life_of(slot);
                let age = planner.and_then(|p| p.birth_age(c, now));
                match (tiny_decode(words, slot), age) {
                    (Some((pos, vel)), Some(age)) if age >= 0.0 && age < f64::from(life) => {
                        Particle {
                            pos_age: [pos[0], pos[1], pos[2], age as f32],
                            vel_life: [vel[0], vel[1], vel[2], life],
                        }
                    }
                    _ => Particle::default(),
                }
            })
            .collect())
    }

    /// `[alive after the last step, non-finite kills so far]` of emitter `index` (blocking).
    ///
    /// GPUs count in the update pass (a workgroup reduction). On CPU adapters the alive
    /// count is computed now, by a counting pass over the current state (the update pass
    /// does not count there: only the stats need it); tiny-state emitters are counted from
    /// the unpacked state. Stateless emitters are counted on the CPU from their spawn
    /// records' ages.
    pub fn read_counters(&self, index: usize) -> Result<[u32; 2], SimError> {
        let s = self
            .emitters
            .get(index)
            .ok_or_else(|| SimError::Readback(format!("no emitter {index}")))?;
        if s.layout == StateLayout::Tiny && !update_counts(&self.update) {
            // Counted from the unpacked state (the on-demand count pass has no birth table).
            let alive = self
                .read_particles(index)?
                .iter()
                .filter(|p| p.is_alive())
                .count();
            let bytes = read_buffer(&self.ctx, &s.counters, 8)?;
            let v: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
            return Ok([alive as u32, v[1]]);
        }
        if s.stateless {
            let now = self.planner.time_secs.rem_euclid(4096.0) as f32;
            let alive = self
                .read_particles(index)?
                .iter()
                .filter(|r| {
                    let mut age = now - r.pos_age[3];
                    if age < 0.0 {
                        age += 4096.0;
                    }
                    r.vel_life[3] > 0.0 && age < r.vel_life[3]
                })
                .count() as u32;
            return Ok([alive, 0]);
        }
        // GPUs count in the update pass itself; CPU adapters count here, on demand.
        let update = lock(&self.update);
        if let Some(count) = update.count.as_ref().filter(|_| !update.count_alive) {
            let group = self
                .ctx
                .device
                .create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("GpuSim::count_group"),
                    layout: &update.count_layout,
                    entries: &[
                        wgpu::BindGroupEntry {
                            binding: 0,
                            resource: s.buffers[s.current].as_entire_binding(),
                        },
                        wgpu::BindGroupEntry {
                            binding: 1,
                            resource: s.counters.as_entire_binding(),
                        },
                        wgpu::BindGroupEntry {
                            binding: 2,
                            resource: s.buffers[s.current].as_entire_binding(),
                        },
                    ],
                });
            let mut enc = self.ctx.device.create_command_encoder(&Default::default());
            enc.clear_buffer(&s.counters, 0, Some(4));
            {
                let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("GpuSim::count"),
                    timestamp_writes: None,
                });
                pass.set_pipeline(&count[usize::from(s.layout == StateLayout::Packed)]);
                pass.set_bind_group(0, &group, &[]);
                let (x, y) = dispatch_size(s.capacity);
                pass.dispatch(x, y, 1);
            }
            self.ctx.queue.submit([enc.finish()]);
        }
        let bytes = read_buffer(&self.ctx, &s.counters, 8)?;
        let v: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
        Ok([v[0], v[1]])
    }
}

/// Copies `size` bytes of `buffer` to the CPU (blocking).
pub fn read_buffer(
    ctx: &GpuContext,
    buffer: &wgpu::Buffer,
    size: u64,
) -> Result<Vec<u8>, SimError> {
    let staging = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    enc.copy_buffer_to_buffer(buffer, 0, &staging, 0, size);
    ctx.queue.submit([enc.finish()]);
    map_read(ctx, &staging)
}

/// Maps a `MAP_READ` buffer and copies its bytes out (blocking): `gpu::readback::map_read`
/// with the simulation's error.
pub fn map_read(ctx: &GpuContext, staging: &wgpu::Buffer) -> Result<Vec<u8>, SimError> {
    Ok(crate::gpu::readback::map_read(ctx, staging)?)
}
