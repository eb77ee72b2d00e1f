//! Back-to-front ordering of alpha-blended emitters on the GPU: depth keys, then a
//! bitonic sort of (key, slot) pairs. The billboard pass draws alpha emitters through the
//! sorted slot order; nothing is sorted when no emitter blends with alpha.
//!
//! Only the emitter's live window of the ring is sorted (the slots that can hold living
//! particles), and the network runs mostly in workgroup memory: 512-element blocks are
//! sorted, and merges finished, in one dispatch each ([`sort_dispatches`]), so a 2048-slot
//! sort is 6 dispatches instead of 66.

use crate::gpu::commands::CountedCompute;
use std::collections::HashMap;

use bytemuck::{Pod, Zeroable};

use crate::gpu::types::StateLayout;
use crate::gpu::{GpuContext, Uploads};
use crate::shaders::{ShaderError, ShaderLibrary, create_checked};
use crate::sim::gpu_sim::{dispatch_size, map_read};

/// Keep in sync with `SortStep` in `shaders/sort.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct SortStep {
    /// Bitonic stage size.
    pub k: u32,
    /// Compare distance.
    pub j: u32,
    /// Power-of-two element count.
    pub count: u32,
    /// Slots that hold particles.
    pub capacity: u32,
    /// Unused (each member has its own eye).
    pub eye: [f32; 4],
    /// Camera forward axis.
    pub forward: [f32; 4],
    /// Elements per member (the widest window), members, local mode (0 sort, 1 merge),
    /// unused.
    pub window: [u32; 4],
}

/// One instance of a sort (keep in sync with `SortMember` in `shaders/sort.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SortMember {
    /// The camera position in the instance's simulation space (w unused).
    pub eye: [f32; 4],
    /// First slot of its live window, the window's length, the first slot of its segment
    /// in the state buffer, unused.
    pub window: [u32; 4],
}

/// One sort of a frame: an emitter's slots over a group of instances whose pools are
/// segments of one state buffer.
#[derive(Clone, Debug)]
pub struct SortJob {
    /// Names the sort buffers (the pool's generation).
    pub key: u64,
    /// The current state.
    pub state: wgpu::Buffer,
    /// How it is stored.
    pub layout: StateLayout,
    /// Slots of each instance's pool.
    pub capacity: u32,
    /// Elements per member: the widest live window.
    pub width: u32,
    /// The instances, by segment.
    pub members: Vec<SortMember>,
}

/// Members one sort holds at most.
const MAX_MEMBERS: usize = crate::render::frame::LOOKS_PER_DRAW;

const STRIDE: u64 = 256;

/// The (k, j) stages of a bitonic sort of `n` (a power of two) elements.
pub fn bitonic_stages(n: u32) -> Vec<(u32, u32)> {
    let mut v = Vec::new();
    let mut k = 2;
    while k <= n {
        let mut j = k / 2;
        while j > 0 {
            v.push((k, j));
            j /= 2;
        }
        k *= 2;
    }
    v
}

/// Elements a workgroup sorts in its own memory (`BLOCK` in `sort.wgsl`).
pub const LOCAL_BLOCK: u32 = 512;

/// One dispatch of the split bitonic network.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SortDispatch {
    /// Sort each 512-element block completely (every stage with k ≤ `k`), in workgroup
    /// memory.
    Local {
        /// The largest stage size (≤ 512).
        k: u32,
    },
    /// One compare-and-swap stage at distance `j` ≥ 512 over the whole array.
    Global {
        /// Stage size.
        k: u32,
        /// Compare distance.
        j: u32,
    },
    /// Finish stage `k` (distances 256 … 1) in workgroup memory.
    Merge {
        /// Stage size.
        k: u32,
    },
}

/// The dispatches that sort `n` (a power of two) elements: the bitonic network of
/// [`bitonic_stages`], with every run of stages whose distance is below the block size
/// done in one workgroup-memory dispatch.
pub fn sort_dispatches(n: u32) -> Vec<SortDispatch> {
    let mut v = vec![SortDispatch::Local {
        k: n.min(LOCAL_BLOCK),
    }];
    let mut k = LOCAL_BLOCK * 2;
    while k <= n {
        let mut j = k / 2;
        while j >= LOCAL_BLOCK {
            v.push(SortDispatch::Global { k, j });
            j /= 2;
        }
        v.push(SortDispatch::Merge { k });
        k *= 2;
    }
    v
}

/// The dispatches of a sort of `n` elements: the split network, or every stage of the
/// plain one as a global dispatch.
fn network(n: u32, split: bool) -> Vec<SortDispatch> {
    if split {
        sort_dispatches(n)
    } else {
        bitonic_stages(n)
            .into_iter()
            .map(|(k, j)| SortDispatch::Global { k, j })
            .collect()
    }
}

/// Sort buffers of one emitter.
pub struct SortBuffers {
    /// Elements the buffers hold (a power of two ≥ the capacity).
    size: u32,
    /// Elements sorted now (a power of two ≤ `size`; the steps are written for it).
    count: u32,
    /// The steps are written for the split network (else the plain one).
    split: bool,
    capacity: u32,
    /// Sorted slot indices (farthest first), bound by the billboard pass.
    pub values: wgpu::Buffer,
    steps: wgpu::Buffer,
    /// The members of the sort (`SortMember`s).
    members: wgpu::Buffer,
    group: wgpu::BindGroup,
    /// The depth keys' state bind groups, by state buffer (the two of a ping-pong pair).
    state_groups: Vec<(wgpu::Buffer, wgpu::BindGroup)>,
}

/// The depth-key and bitonic pipelines, and per-emitter sort buffers.
pub struct SortPass {
    layout: wgpu::BindGroupLayout,
    state_layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    /// The depth keys per state layout (`StateLayout::index`: full, packed, tiny).
    keys: [wgpu::ComputePipeline; 3],
    bitonic: wgpu::ComputePipeline,
    bitonic_local: wgpu::ComputePipeline,
    buffers: HashMap<u64, SortBuffers>,
    /// Run the split network (workgroup-memory blocks; on by default). Off runs every
    /// stage as its own global dispatch — the plain network, for the bench's comparison.
    pub split_network: bool,
}

/// Arbitrary keys with their own sort buffers ([`SortPass::key_sort`]): the GPU sort
/// outside a frame, for tests and the bench.
pub struct KeySort {
    buffers: SortBuffers,
    keys: wgpu::Buffer,
    state_group: wgpu::BindGroup,
    len: usize,
}

impl KeySort {
    /// Uploads `keys` (the same length as at creation) again, before the next submission.
    pub fn reset_keys(&self, ctx: &GpuContext, keys: &[u32]) {
        let n = keys.len().min(self.len);
        ctx.queue
            .write_buffer(&self.keys, 0, bytemuck::cast_slice(&keys[..n]));
    }
}

impl SortPass {
    /// Builds the pipelines from `lib`.
    pub fn new(ctx: &GpuContext, lib: &ShaderLibrary) -> Result<Self, ShaderError> {
        let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty,
            count: None,
        };
        let storage = |read_only| wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let layout = crate::gpu::bind_group_layout(
            ctx,
            "SortPass::layout",
            &[
                entry(
                    0,
                    wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage { read_only: true },
                        has_dynamic_offset: true,
                        min_binding_size: wgpu::BufferSize::new(size_of::<SortStep>() as u64),
                    },
                ),
                entry(1, storage(false)),
                entry(2, storage(false)),
                entry(3, storage(true)),
            ],
        );
        let state_layout = crate::gpu::bind_group_layout(
            ctx,
            "SortPass::state_layout",
            &[entry(0, storage(true)), entry(1, storage(true))],
        );
        let pipeline_layout = ctx
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("SortPass::pipeline_layout"),
                bind_group_layouts: &[Some(&layout), Some(&state_layout)],
                immediate_size: 0,
            });
        let (keys, bitonic, bitonic_local) = Self::build(ctx, lib, &pipeline_layout)?;
        Ok(Self {
            layout,
            state_layout,
            pipeline_layout,
            keys,
            bitonic,
            bitonic_local,
            buffers: HashMap::new(),
            split_network: true,
        })
    }

    fn build(
        ctx: &GpuContext,
        lib: &ShaderLibrary,
        layout: &wgpu::PipelineLayout,
    ) -> Result<
        (
            [wgpu::ComputePipeline; 3],
            wgpu::ComputePipeline,
            wgpu::ComputePipeline,
        ),
        ShaderError,
    > {
        let composed = lib.compose("sort.wgsl")?;
        create_checked(&ctx.device, &composed, lib, |module| {
            let make = |entry: &str, constants: &[(&str, f64)]| {
                ctx.device
                    .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                        label: Some(entry),
                        layout: Some(layout),
                        module,
                        entry_point: Some(entry),
                        compilation_options: wgpu::PipelineCompilationOptions {
                            constants,
                            ..Default::default()
                        },
                        cache: None,
                    })
            };
            // The state layout is a constant, not a branch on the step block: a CPU adapter
            // would run every layout's decode for every key (see look.wgsl).
            let keys = [StateLayout::Full, StateLayout::Packed, StateLayout::Tiny]
                .map(|l| make("depth_keys", &[("STATE_LAYOUT", f64::from(l.index()))]));
            (keys, make("bitonic", &[]), make("bitonic_local", &[]))
        })
    }

    /// Rebuilds the pipelines; keeps the old ones on error.
    pub fn rebuild(&mut self, ctx: &GpuContext, lib: &ShaderLibrary) -> Result<(), ShaderError> {
        let (keys, bitonic, bitonic_local) = Self::build(ctx, lib, &self.pipeline_layout)?;
        self.keys = keys;
        self.bitonic = bitonic;
        self.bitonic_local = bitonic_local;
        Ok(())
    }

    /// The sort buffers for a pool (`generation` identifies it), created on first use.
    pub fn buffers(&mut self, ctx: &GpuContext, generation: u64, capacity: u32) -> &SortBuffers {
        let stale = self
            .buffers
            .get(&generation)
            .is_none_or(|b| b.capacity != capacity);
        if stale {
            let b = self.create(ctx, capacity);
            self.buffers.insert(generation, b);
        }
        &self.buffers[&generation]
    }

    /// Forgets the buffers of pools that no longer exist.
    pub fn retain(&mut self, live: &std::collections::HashSet<u64>) {
        self.buffers.retain(|g, _| live.contains(g));
    }

    fn create(&self, ctx: &GpuContext, capacity: u32) -> SortBuffers {
        let size = capacity.max(2).next_power_of_two();
        let make = |label| {
            ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size as u64 * 4,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_SRC
                    | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let keys = make("SortPass::keys");
        let values = make("SortPass::values");
        let members = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("SortPass::members"),
            size: (MAX_MEMBERS * size_of::<SortMember>()) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let steps = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("SortPass::steps"),
            size: (bitonic_stages(size).len() as u64 + 1) * STRIDE,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self::write_steps(
            ctx,
            &steps,
            &network(size, self.split_network),
            size,
            capacity,
        );
        let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("SortPass::group"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &steps,
                        offset: 0,
                        size: wgpu::BufferSize::new(size_of::<SortStep>() as u64),
                    }),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: keys.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: values.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: members.as_entire_binding(),
                },
            ],
        });
        // `keys` lives on through the bind group.
        drop(keys);
        SortBuffers {
            size,
            count: size,
            split: self.split_network,
            capacity,
            values,
            steps,
            members,
            group,
            state_groups: Vec::new(),
        }
    }

    /// Writes the uniform block of every dispatch of a sort of `count` elements (after
    /// the depth-key block at offset 0).
    fn write_steps(
        ctx: &GpuContext,
        steps: &wgpu::Buffer,
        dispatches: &[SortDispatch],
        count: u32,
        capacity: u32,
    ) {
        let blocks = step_blocks(dispatches, count, capacity);
        ctx.queue.write_buffer(steps, STRIDE, &blocks);
    }

    fn record_stages(&self, pass: &mut wgpu::ComputePass<'_>, b: &SortBuffers) {
        // The network the buffers' steps were written for.
        for (i, d) in network(b.count, b.split).iter().enumerate() {
            pass.set_bind_group(0, &b.group, &[((i as u64 + 1) * STRIDE) as u32]);
            let (pipeline, threads) = match d {
                SortDispatch::Global { .. } => (&self.bitonic, b.count),
                _ => (&self.bitonic_local, b.count.div_ceil(2)),
            };
            pass.set_pipeline(pipeline);
            let (x, y) = dispatch_size(threads);
            pass.dispatch(x, y, 1);
        }
    }

    /// Makes `job`'s buffers and uploads its head block, its members and (when the
    /// network changed) its steps through `uploads`, with copies recorded into `enc`
    /// (outside a pass); `false` when it has nothing to sort. [`SortPass::dispatch`]
    /// records the sort itself.
    fn upload(
        &mut self,
        ctx: &GpuContext,
        (enc, uploads): (&mut wgpu::CommandEncoder, &mut Uploads),
        job: &SortJob,
        forward: glam::Vec3,
    ) -> bool {
        let members = &job.members[..job.members.len().min(MAX_MEMBERS)];
        let elements = job.width * members.len() as u32;
        if elements == 0 {
            return false;
        }
        let size = self
            .buffers(ctx, job.key, job.capacity * members.len() as u32)
            .size;
        let count = elements.max(2).next_power_of_two().min(size);
        let split = self.split_network;
        let Some(b) = self.buffers.get_mut(&job.key) else {
            return false;
        };
        if count != b.count || b.split != split {
            let steps = step_blocks(&network(count, split), count, job.capacity);
            uploads.write_bytes(enc, &b.steps, STRIDE, &steps);
            b.count = count;
            b.split = split;
        }
        Self::ensure_state_group(ctx, &self.state_layout, b, &job.state);
        let head = SortStep {
            k: 0,
            j: 0,
            count,
            capacity: job.capacity,
            eye: [0.0; 4],
            forward: forward.extend(0.0).to_array(),
            window: [job.width, members.len() as u32, 0, 0],
        };
        uploads.write_bytes(enc, &b.steps, 0, bytemuck::bytes_of(&head));
        uploads.write_bytes(enc, &b.members, 0, bytemuck::cast_slice(members));
        true
    }

    /// A bind group of `state` for `b`'s sorts (the two last kept).
    fn ensure_state_group(
        ctx: &GpuContext,
        layout: &wgpu::BindGroupLayout,
        b: &mut SortBuffers,
        state: &wgpu::Buffer,
    ) {
        if b.state_groups.iter().any(|(s, _)| s == state) {
            return;
        }
        let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("SortPass::state_group"),
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: state.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: state.as_entire_binding(),
                },
            ],
        });
        if b.state_groups.len() >= 2 {
            b.state_groups.remove(0);
        }
        b.state_groups.push((state.clone(), group));
    }

    /// Records depth keys for `job`'s slots (every member's live window of its current
    /// state, each seen from its own eye, along `forward`) and the sort, after its
    /// [`SortPass::upload`]; afterwards the first entries of `values` (the buffers of
    /// `job.key`) hold the state-buffer indices of those slots farthest first (dead
    /// slots after the living, then padding).
    fn dispatch(&self, pass: &mut wgpu::ComputePass<'_>, job: &SortJob) {
        let Some(b) = self.buffers.get(&job.key) else {
            return;
        };
        let Some((_, state_group)) = b.state_groups.iter().find(|(s, _)| *s == job.state) else {
            return;
        };
        let Some(keys) = self.keys.get(job.layout.index() as usize) else {
            return;
        };
        pass.set_pipeline(keys);
        pass.set_bind_group(0, &b.group, &[0]);
        pass.set_bind_group(1, state_group, &[]);
        let (x, y) = dispatch_size(b.count);
        pass.dispatch(x, y, 1);
        self.record_stages(pass, b);
    }

    /// Uploads arbitrary keys (values: their indices) for sorting outside a frame. Sizes
    /// need not be powers of two: padding keys are 0xFFFFFFFF.
    pub fn key_sort(&self, ctx: &GpuContext, keys: &[u32]) -> KeySort {
        let b = self.create(ctx, keys.len().max(1) as u32);
        let mut padded = keys.to_vec();
        padded.resize(b.count as usize, u32::MAX);
        let iota: Vec<u32> = (0..b.count).collect();
        let keys_buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("SortPass::key_sort_keys"),
            size: b.count as u64 * 4,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_SRC
                | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        ctx.queue
            .write_buffer(&keys_buffer, 0, bytemuck::cast_slice(&padded));
        ctx.queue
            .write_buffer(&b.values, 0, bytemuck::cast_slice(&iota));
        let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("SortPass::key_sort_group"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &b.steps,
                        offset: 0,
                        size: wgpu::BufferSize::new(size_of::<SortStep>() as u64),
                    }),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: keys_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: b.values.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: b.members.as_entire_binding(),
                },
            ],
        });
        // The pipeline layout has the particle group; the bitonic stages do not read it.
        let dummy = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("SortPass::no_state"),
            size: 32,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let state_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("SortPass::no_state_group"),
            layout: &self.state_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: dummy.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: dummy.as_entire_binding(),
                },
            ],
        });
        KeySort {
            buffers: SortBuffers { group, ..b },
            keys: keys_buffer,
            state_group,
            len: keys.len(),
        }
    }

    /// Records the sort of `k` (the network the pass was created with) into `enc`.
    /// The keys are sorted in place; [`KeySort::reset_keys`] uploads them again.
    pub fn record_key_sort(&self, enc: &mut wgpu::CommandEncoder, k: &KeySort) {
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("SortPass::key_sort"),
            timestamp_writes: None,
        });
        pass.set_bind_group(1, &k.state_group, &[]);
        self.record_stages(&mut pass, &k.buffers);
    }

    /// Sorts arbitrary keys on the GPU (tests): returns (sorted keys, their original
    /// indices).
    pub fn sort_keys(
        &mut self,
        ctx: &GpuContext,
        keys: &[u32],
    ) -> Result<(Vec<u32>, Vec<u32>), crate::sim::SimError> {
        let k = self.key_sort(ctx, keys);
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        self.record_key_sort(&mut enc, &k);
        ctx.queue.submit([enc.finish()]);
        let count = k.buffers.count as u64;
        let read = |buffer: &wgpu::Buffer| -> Result<Vec<u32>, crate::sim::SimError> {
            let staging = ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("SortPass::readback"),
                size: count * 4,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let mut enc = ctx.device.create_command_encoder(&Default::default());
            enc.copy_buffer_to_buffer(buffer, 0, &staging, 0, count * 4);
            ctx.queue.submit([enc.finish()]);
            Ok(bytemuck::pod_collect_to_vec(&map_read(ctx, &staging)?))
        };
        let mut keys_out = read(&k.keys)?;
        let mut values = read(&k.buffers.values)?;
        keys_out.truncate(k.len);
        values.truncate(k.len);
        Ok((keys_out, values))
    }

    /// Sorts the alpha-blended items back to front for `camera` (nothing runs when there
    /// is none) and forgets the buffers of pools no longer drawn.
    /// Their uploads go through `uploads` (copies recorded into `enc` first), and every
    /// sort of the frame shares one compute pass.
    pub fn record_items(
        &mut self,
        ctx: &GpuContext,
        (enc, uploads): (&mut wgpu::CommandEncoder, &mut Uploads),
        items: &[crate::render::DrawItem],
        camera: &crate::render::Camera,
    ) {
        let mut jobs = Vec::new();
        for job in items.iter().filter_map(|d| d.sort.as_ref()) {
            if self.upload(ctx, (enc, uploads), job, camera.forward()) {
                jobs.push(job);
            }
        }
        if !jobs.is_empty() {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("SortPass::sort"),
                timestamp_writes: None,
            });
            for job in jobs {
                self.dispatch(&mut pass, job);
            }
        }
        let live: std::collections::HashSet<u64> = items.iter().map(|d| d.key.0).collect();
        self.retain(&live);
    }
}

/// The uniform blocks of every dispatch of a sort of `count` elements, `STRIDE` apart.
fn step_blocks(dispatches: &[SortDispatch], count: u32, capacity: u32) -> Vec<u8> {
    let mut blocks = vec![0u8; dispatches.len() * STRIDE as usize];
    for (i, d) in dispatches.iter().enumerate() {
        let (k, j, mode) = match *d {
            SortDispatch::Local { k } => (k, 0, 0),
            SortDispatch::Global { k, j } => (k, j, 0),
            SortDispatch::Merge { k } => (k, 0, 1),
        };
        let s = SortStep {
            k,
            j,
            count,
            capacity,
            window: [0, 0, mode, 0],
            ..Default::default()
        };
        let at = i * STRIDE as usize;
        blocks[at..at + size_of::<SortStep>()].copy_from_slice(bytemuck::bytes_of(&s));
    }
    blocks
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The split network performs exactly the stages of the plain bitonic network, in
    /// order: local sorts expand to every stage with k ≤ 512, merges to j = 256 … 1.
    #[test]
    fn dispatches_expand_to_the_bitonic_network() {
        for n in [2u32, 4, 256, 512, 1024, 2048, 1 << 16] {
            let mut expanded = Vec::new();
            for d in sort_dispatches(n) {
                match d {
                    SortDispatch::Local { k } => {
                        let mut kk = 2;
                        while kk <= k {
                            let mut j = kk / 2;
                            while j > 0 {
                                expanded.push((kk, j));
                                j /= 2;
                            }
                            kk *= 2;
                        }
                    }
                    SortDispatch::Global { k, j } => expanded.push((k, j)),
                    SortDispatch::Merge { k } => {
                        let mut j = LOCAL_BLOCK / 2;
                        while j > 0 {
                            expanded.push((k, j));
                            j /= 2;
                        }
                    }
                }
            }
            assert_eq!(expanded, bitonic_stages(n), "n = {n}");
        }
        assert_eq!(sort_dispatches(2048).len(), 6);
        assert_eq!(bitonic_stages(2048).len(), 66);
    }
}
