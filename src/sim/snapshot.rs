//! Snapshots of a [`GpuSim`]: its particle state copied on the GPU and its planning cloned
//! on the CPU, so that a seek can start from the nearest earlier moment instead of time 0.
//! With fixed steps a simulation's state after `n` steps does not depend on how the steps
//! were grouped into frames, so a snapshot stands for "after step `n`" whatever frame
//! rate produced it.

use std::collections::VecDeque;

use crate::gpu::types::Birth;

use super::gpu_sim::GpuSim;
use super::planner::EffectPlanner;

/// A simulation's state after some step.
pub struct SimSnapshot {
    planner: EffectPlanner,
    emitters: Vec<EmitterSnapshot>,
    bytes: u64,
}

/// One emitter's part: copies of both state buffers (the draws read the older one too)
/// and the CPU side of its pool.
struct EmitterSnapshot {
    /// The pool it was taken from (a restore into another pool is refused).
    generation: u64,
    buffers: [wgpu::Buffer; 2],
    current: usize,
    births_mirror: VecDeque<(u64, Birth)>,
    whole_pool_until: f64,
    spawned_end: u64,
    /// A child's event-list header (its ring head, the last step's children and stamp,
    /// the dropped count): the list's entries are rewritten every step before use.
    event_header: Option<wgpu::Buffer>,
    /// The trail's ring (the positions the ribbon draws, or a ribbon per parent's links).
    trail: Option<wgpu::Buffer>,
    /// Each scan's scratch of a parent (the last child of each parent slot, which a ribbon
    /// per parent links its next child to).
    scans: Vec<wgpu::Buffer>,
}

impl SimSnapshot {
    /// GPU memory it holds.
    pub fn bytes(&self) -> u64 {
        self.bytes
    }
}

impl GpuSim {
    /// Records copies of the state into `enc` (valid once `enc` is submitted) and clones
    /// the planning: the simulation after its last recorded step.
    pub fn snapshot(&self, enc: &mut wgpu::CommandEncoder) -> SimSnapshot {
        let mut bytes = 0;
        // A copy of the first `size` bytes of `b`, recorded into `enc`.
        let mut copy_of = |enc: &mut wgpu::CommandEncoder, b: &wgpu::Buffer, size: u64| {
            let copy = self.ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("SimSnapshot::copy"),
                size,
                usage: wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            enc.copy_buffer_to_buffer(b, 0, &copy, 0, size);
            bytes += size;
            copy
        };
        let emitters = self
            .emitters
            .iter()
            .map(|s| {
                let buffers = s.buffers.each_ref().map(|b| copy_of(enc, b, b.size()));
                let hooks = s.hooks.as_ref();
                let header = size_of::<crate::sim::event_scan::EventHeader>() as u64;
                let event_header = hooks
                    .and_then(|ev| ev.list.as_ref())
                    .map(|list| copy_of(enc, list, header));
                let trail = hooks
                    .and_then(|ev| ev.trail.as_ref())
                    .map(|ring| copy_of(enc, ring, ring.size()));
                let scans = hooks
                    .map(|ev| {
                        ev.scans
                            .iter()
                            .map(|s| copy_of(enc, &s.blocks, s.blocks.size()))
                            .collect()
                    })
                    .unwrap_or_default();
                EmitterSnapshot {
                    trail,
                    scans,
                    event_header,
                    generation: s.generation,
                    buffers,
                    current: s.current,
                    births_mirror: s.births_mirror.clone(),
                    whole_pool_until: s.whole_pool_until,
                    spawned_end: s.spawned_end,
                }
            })
            .collect();
        SimSnapshot {
            planner: self.planner.clone(),
            emitters,
            bytes,
        }
    }

    /// Puts the simulation back to `snapshot` (copies recorded into `enc`); false, and
    /// nothing changed, when a pool was rebuilt since it was taken.
    pub fn restore(&mut self, enc: &mut wgpu::CommandEncoder, snapshot: &SimSnapshot) -> bool {
        let same = self.emitters.len() == snapshot.emitters.len()
            && self
                .emitters
                .iter()
                .zip(&snapshot.emitters)
                .all(|(s, k)| s.generation == k.generation);
        if !same {
            return false;
        }
        for (s, k) in self.emitters.iter_mut().zip(&snapshot.emitters) {
            for (b, copy) in s.buffers.iter().zip(&k.buffers) {
                enc.copy_buffer_to_buffer(copy, 0, b, 0, b.size());
            }
            enc.clear_buffer(&s.counters, 0, None);
            let list = s.hooks.as_ref().and_then(|ev| ev.list.as_ref());
            if let (Some(list), Some(header)) = (list, &k.event_header) {
                enc.copy_buffer_to_buffer(header, 0, list, 0, header.size());
            } else if let Some(list) = list {
                enc.clear_buffer(list, 0, None);
            }
            let ring = s.hooks.as_ref().and_then(|ev| ev.trail.as_ref());
            if let (Some(ring), Some(copy)) = (ring, &k.trail)
                && ring.size() == copy.size()
            {
                enc.copy_buffer_to_buffer(copy, 0, ring, 0, ring.size());
            }
            let scans = s.hooks.as_ref().map_or(&[][..], |ev| &ev.scans[..]);
            for (scan, copy) in scans.iter().zip(&k.scans) {
                if scan.blocks.size() == copy.size() {
                    enc.copy_buffer_to_buffer(copy, 0, &scan.blocks, 0, copy.size());
                }
            }
            s.current = k.current;
            s.whole_pool_until = k.whole_pool_until;
            s.spawned_end = k.spawned_end;
            // The tiny state's birth table: the entries the next steps may read.
            s.births_mirror.clone_from(&k.births_mirror);
            for (seq, entry) in &s.births_mirror {
                s.write_birth(&self.ctx.queue, *seq, entry);
            }
        }
        self.planner.clone_from(&snapshot.planner);
        true
    }
}
