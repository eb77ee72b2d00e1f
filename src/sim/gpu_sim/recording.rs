//! Recording a simulation's steps: the parameter blocks of each step, their copies and
//! dispatches (the update, the event scans and the hooks), a tiny state's births.

use super::*;
use crate::gpu::commands::CountedCompute;

impl GpuSim {
    /// Runs `steps` steps of `dt_secs` (spawning, integrating, ageing) on the GPU.
    pub fn step(&mut self, effect: &Effect, dt_secs: f32, steps: u32) -> Result<(), SimError> {
        self.sync(effect)?;
        let mut remaining = steps as usize;
        while remaining > 0 {
            let chunk = remaining.min(STEPS_PER_SUBMIT);
            let plans: Vec<Vec<Option<SimParams>>> = (0..chunk)
                .map(|_| self.planner.plan_step(effect, dt_secs))
                .collect();
            self.record_and_submit(effect, &plans);
            remaining -= chunk;
        }
        Ok(())
    }

    /// Records the planned steps (one `SimParams` per enabled emitter and step) and submits.
    pub fn record_and_submit(&mut self, effect: &Effect, plans: &[Vec<Option<SimParams>>]) {
        let mut enc = self
            .ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("GpuSim::step"),
            });
        self.record(&mut enc, effect, plans);
        self.ctx.queue.submit([enc.finish()]);
    }

    /// Plans `steps` steps of `dt_secs` ([`GpuSim::record`] records any number: the
    /// params ring holds 32 steps, later ones are copied in by the encoder).
    pub fn plan(
        &mut self,
        effect: &Effect,
        dt_secs: f32,
        steps: usize,
    ) -> Vec<Vec<Option<SimParams>>> {
        (0..steps)
            .map(|_| self.planner.plan_step(effect, dt_secs))
            .collect()
    }

    /// Uploads the planned blocks and records their dispatches into `enc`. Submit `enc`
    /// before the next call (the blocks share one buffer).
    pub fn record(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        effect: &Effect,
        plans: &[Vec<Option<SimParams>>],
    ) {
        enc.push_debug_group("update particles");
        let mut pass = None;
        self.record_into(enc, &mut pass, effect, plans);
        drop(pass);
        enc.pop_debug_group();
    }

    /// [`GpuSim::record`] into an open compute pass of `enc` (opened on first need), so
    /// that several simulations (a player's instances) share one pass. A simulation that
    /// counts alive particles ends the pass before its last step to clear its counters.
    /// Plans beyond the params ring's 32 steps run in further chunks: the pass is ended
    /// and the encoder copies each chunk's blocks into the ring before its steps.
    pub fn record_into(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        pass: &mut Option<wgpu::ComputePass<'static>>,
        effect: &Effect,
        plans: &[Vec<Option<SimParams>>],
    ) {
        let n_emitters = self.emitters.len();
        for e in 0..n_emitters {
            if self.emitters[e].layout == StateLayout::Tiny {
                self.upload_births(e, plans);
            }
        }
        self.write_scan_configs(effect);
        self.point_depth_colliders();
        let chunks: Vec<(Vec<u8>, Vec<u32>)> = plans
            .chunks(STEPS_PER_SUBMIT)
            .map(|chunk| self.param_blocks(chunk))
            .collect();
        // Written before the submission runs: the first chunk's blocks into the ring, the
        // others after one another into `later_chunks`.
        if let Some((first, _)) = chunks.first() {
            self.ctx.queue.write_buffer(&self.params_buffer, 0, first);
        }
        let later: Vec<u8> = chunks
            .iter()
            .skip(1)
            .flat_map(|c| c.0.iter().copied())
            .collect();
        let staging = self.later_chunks_buffer(later.len() as u64);
        if let Some(buffer) = &staging {
            self.ctx.queue.write_buffer(buffer, 0, &later);
        }
        let mut at = 0u64;
        for (c, (chunk, (blocks, windows))) in
            plans.chunks(STEPS_PER_SUBMIT).zip(&chunks).enumerate()
        {
            if let (true, Some(buffer)) = (c > 0, &staging) {
                // The chunk's blocks into the ring once the steps before have run.
                drop(pass.take());
                let len = blocks.len() as u64;
                enc.copy_buffer_to_buffer(buffer, at, &self.params_buffer, 0, len);
                at += len;
            }
            self.dispatch_steps(enc, pass, effect, chunk, windows, c + 1 == chunks.len());
        }
    }

    /// Points each emitter's depth collider at the host's depth, seen from its
    /// simulation space.
    fn point_depth_colliders(&mut self) {
        let update = Arc::clone(&self.update);
        let layout = &lock(&update).depth_layout;
        for (e, em) in self.emitters.iter_mut().enumerate() {
            if let Some(depth) = &mut em.depth {
                let origin = self
                    .planner
                    .emitters
                    .get(e)
                    .map(|p| p.origin())
                    .unwrap_or_default();
                depth.update(&self.ctx, layout, self.host_depth.as_ref(), origin);
            }
        }
    }

    /// `later_chunks`, at least `bytes` long (`None` for none).
    fn later_chunks_buffer(&mut self, bytes: u64) -> Option<wgpu::Buffer> {
        if bytes == 0 {
            return None;
        }
        if self.later_chunks.as_ref().is_none_or(|b| b.size() < bytes) {
            self.later_chunks = Some(self.ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("GpuSim::later_chunks"),
                size: bytes.next_power_of_two(),
                usage: wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }));
        }
        self.later_chunks.clone()
    }

    /// The parameter blocks of up to 32 steps' plans, as the params ring holds them, and
    /// each (step, emitter)'s update window.
    fn param_blocks(&self, plans: &[Vec<Option<SimParams>>]) -> (Vec<u8>, Vec<u32>) {
        let n_emitters = self.emitters.len();
        let mut blocks = vec![0u8; plans.len() * n_emitters * PARAMS_STRIDE as usize];
        let mut windows = vec![0u32; plans.len() * n_emitters];
        for (s, plan) in plans.iter().enumerate() {
            for (e, params) in plan.iter().enumerate() {
                if let (Some(p), Some(em)) = (params, self.emitters.get(e)) {
                    let mut p = *p;
                    // State written from outside the planner, or kept at old slots by a
                    // capacity change: every slot may be alive.
                    let clock = self
                        .planner
                        .emitters
                        .get(e)
                        .map_or(f64::INFINITY, |pl| pl.clock_secs());
                    if em.gpu_fed
                        || clock < em.whole_pool_until
                        || p.capacity != em.capacity
                        || p.update_window[1] > em.capacity
                    {
                        p.update_window[..2].copy_from_slice(&[0, em.capacity]);
                    }
                    windows[s * n_emitters + e] = p.update_window[1];
                    if em.layout == StateLayout::Tiny {
                        p.flags = em.births_mask;
                    }
                    let at = (s * n_emitters + e) * PARAMS_STRIDE as usize;
                    blocks[at..at + size_of::<SimParams>()].copy_from_slice(bytemuck::bytes_of(&p));
                }
            }
        }
        (blocks, windows)
    }

    /// Records the steps of `plans` (one chunk, its blocks in the params ring);
    /// `last_chunk`: the record's last steps (the alive counter is cleared before its
    /// last step).
    fn dispatch_steps(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        pass: &mut Option<wgpu::ComputePass<'static>>,
        effect: &Effect,
        plans: &[Vec<Option<SimParams>>],
        windows: &[u32],
        last_chunk: bool,
    ) {
        let n_emitters = self.emitters.len();
        let order = effect.update_order();
        // One compute pass for as many dispatches as possible (wgpu orders dependent
        // dispatches inside a pass): on lavapipe each pass costs about as much as a small
        // dispatch. GPUs end it where the alive counter must be cleared first.
        let clear_counters = update_counts(&self.update);
        let update = Arc::clone(&self.update);
        let update = lock(&update);
        for (s, plan) in plans.iter().enumerate() {
            if clear_counters && last_chunk && s + 1 == plans.len() {
                // The update counts alive particles (COUNT_ALIVE) into the counter: clear
                // it before the last step only, whose count is the one read (one break
                // of the pass per record, not one per emitter and step).
                drop(pass.take());
                for (em, params) in self.emitters.iter().zip(plan) {
                    if params.is_some() && !em.stateless {
                        enc.clear_buffer(&em.counters, 0, Some(4));
                    }
                }
            }
            for &e in &order {
                let (Some(Some(p)), Some(em)) = (plan.get(e), self.emitters.get_mut(e)) else {
                    continue;
                };
                em.spawned_end = (u64::from(p.spawn_base_hi) << 32 | u64::from(p.spawn_base_lo))
                    + u64::from(p.spawn_count);
                let Some(pipeline) = pipeline_key(effect, e).and_then(|k| update.pipelines.get(&k))
                else {
                    continue;
                };
                let offset = ((s * n_emitters + e) as u64 * PARAMS_STRIDE) as u32;
                // Stateless: spawn records only, written in place into buffer 0 (group 1
                // reads buffer 1 and writes buffer 0); nothing else is touched.
                let (group, slots) = if em.stateless {
                    (&em.bind_groups[1], p.spawn_count)
                } else {
                    (&em.bind_groups[em.current], windows[s * n_emitters + e])
                };
                // Tiny state: one invocation per pair of slots the window touches.
                let invocations = if em.layout == StateLayout::Tiny {
                    (slots / 2 + 2).min(em.capacity.div_ceil(2))
                } else {
                    slots.div_ceil(SLOTS_PER_INVOCATION)
                };
                if !em.stateless {
                    em.current = 1 - em.current;
                }
                // An empty window: nothing in the pool can be alive, both buffers hold the
                // same dead slots, so the swap above is all a step does (and the cleared
                // counter says zero).
                if slots > 0 {
                    let pass = crate::gpu::compute_pass(pass, enc, "GpuSim::update");
                    pass.set_pipeline(pipeline);
                    pass.set_bind_group(0, group, &[offset]);
                    if let Some(ev) = &em.hooks {
                        pass.set_bind_group(1, &ev.hooks, &[]);
                    }
                    if let Some(depth) = &em.depth {
                        pass.set_bind_group(2, depth.group(), &[]);
                    }
                    let (x, y) = dispatch_size(invocations);
                    pass.dispatch(x, y, 1);
                }
                // The parent's events become its children's spawn lists, the same step.
                if let (Some(ev), Some(scan)) = (&em.hooks, &update.hooks.scan) {
                    record_scans(
                        crate::gpu::compute_pass(pass, enc, "GpuSim::events"),
                        ev,
                        scan,
                        offset,
                        slots,
                    );
                }
            }
        }
    }

    /// Writes each scan's settings: the rule, the child's capacity and cap, the offset
    /// between the parent's and the child's simulation spaces, the inherited velocity.
    fn write_scan_configs(&mut self, effect: &Effect) {
        let origin = |j: usize| {
            self.planner
                .emitters
                .get(j)
                .map(|p| p.origin())
                .unwrap_or_default()
        };
        let mut configs = Vec::new();
        for (i, (s, e)) in self.emitters.iter().zip(&effect.emitters).enumerate() {
            let Some(hooks) = &s.hooks else {
                continue;
            };
            for (k, (scan, ev)) in hooks.scans.iter().zip(&e.events).enumerate() {
                let delta = (origin(i) - origin(scan.child)).as_vec3();
                let child_capacity = self.emitters.get(scan.child).map_or(1, |c| c.capacity);
                let cfg = ScanConfig {
                    rule_capacity_cap: [
                        k as u32,
                        child_capacity,
                        crate::sim::event_scan::step_cap(effect, i, k),
                        scan_flags(ev.inherit_color, scan.linked),
                    ],
                    delta_inherit: [delta.x, delta.y, delta.z, ev.inherit_velocity],
                    cap: [
                        ev.max_per_sec,
                        crate::effect::cap_burst(ev.max_per_sec),
                        0.0,
                        0.0,
                    ],
                };
                configs.push((i, k, cfg));
            }
        }
        for (i, k, cfg) in configs {
            let Some(scan) = self.emitters[i]
                .hooks
                .as_mut()
                .and_then(|h| h.scans.get_mut(k))
            else {
                continue;
            };
            if scan.written != Some(cfg) {
                self.ctx
                    .queue
                    .write_buffer(&scan.config, 0, bytemuck::bytes_of(&cfg));
                scan.written = Some(cfg);
            }
        }
    }

    /// Emitter `index`'s hook buffers (events, trail), if it has any.
    pub(super) fn hooks(&self, index: usize) -> Option<&EmitterHooks> {
        self.emitters.get(index).and_then(|s| s.hooks.as_ref())
    }

    /// Writes the birth-table entries of the batches `plans` spawned for tiny emitter `e`
    /// (each step's window of the table must stay intact until the submit has run: a table
    /// too small for the span of this submit's windows is replaced by a larger one).
    fn upload_births(&mut self, e: usize, plans: &[Vec<Option<SimParams>>]) {
        let steps: Vec<SimParams> = plans
            .iter()
            .filter_map(|p| p.get(e).copied().flatten())
            .collect();
        let (Some(first), Some(last)) = (steps.first(), steps.last()) else {
            return;
        };
        let mut fresh = Vec::new();
        for p in &steps {
            if p.spawn_count > 0 {
                // The step's own batch is the newest of its window.
                let seq = u64::from(p.tiny[2]) + u64::from(p.tiny[3]) - 1;
                let entry = Birth {
                    first: p.spawn_base_lo,
                    count: p.spawn_count,
                    t0_hi: f32::from_bits(p.tiny[0]),
                    t0_lo: f32::from_bits(p.tiny[1]),
                    dt: p.dt_secs,
                    frac0: p.spawn_frac0,
                    frac_step: p.spawn_frac_step,
                    pad: 0,
                };
                self.emitters[e].births_mirror.push_back((seq, entry));
                fresh.push((seq, entry));
            }
        }
        let lo = u64::from(first.tiny[2]);
        let hi = u64::from(last.tiny[2]) + u64::from(last.tiny[3]);
        let span = hi.saturating_sub(lo);
        let size = u64::from(self.emitters[e].births_mask) + 1;
        if span > size {
            let entries = (span * 2)
                .next_power_of_two()
                .min(u64::from(u32::MAX / 2 + 1)) as u32;
            let births = self.births_buffer(entries);
            let s = &self.emitters[e];
            let bind_groups = self.bind_groups(&s.buffers, &s.counters, &births, &s.curves);
            let generation = next_generation();
            let s = &mut self.emitters[e];
            s.births = births;
            s.births_mask = entries - 1;
            s.bind_groups = bind_groups;
            // The draws' bind groups key on the generation.
            s.generation = generation;
            fresh = s
                .births_mirror
                .iter()
                .copied()
                .filter(|(q, _)| *q >= lo)
                .collect();
        }
        let s = &self.emitters[e];
        for (seq, entry) in fresh {
            s.write_birth(&self.ctx.queue, seq, &entry);
        }
        // Later submits read from the last step's window on.
        let keep = u64::from(last.tiny[2]);
        let s = &mut self.emitters[e];
        while s.births_mirror.front().is_some_and(|(q, _)| *q < keep) {
            s.births_mirror.pop_front();
        }
    }
}

/// Records the scans of a parent's events (`ev`) after its update: per event the three
/// passes of `events.wgsl` over the blocks of the parent's window of `slots` slots, with
/// the step's parameter block at `offset`.
fn record_scans(
    pass: &mut wgpu::ComputePass<'static>,
    ev: &EmitterHooks,
    scan: &[wgpu::ComputePipeline; 3],
    offset: u32,
    slots: u32,
) {
    let blocks = slots.div_ceil(crate::sim::event_scan::EVENT_SCAN_BLOCK);
    for group in ev.scans.iter().filter_map(|sc| sc.group.as_ref()) {
        pass.set_bind_group(0, group, &[offset]);
        for (pipeline, groups) in scan.iter().zip([blocks, 1, blocks]) {
            if groups > 0 {
                pass.set_pipeline(pipeline);
                let (x, y) = dispatch_groups(groups);
                pass.dispatch(x, y, 1);
            }
        }
    }
}
