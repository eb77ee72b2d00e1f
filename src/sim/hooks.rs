//! The update's hooks (group 1 of an emitter's update with events or a trail): each
//! emitter's hook buffers — its event counts and records (a parent), the spawn list its
//! parents' events fill (a child), its trail's ring — with their bind groups, and the
//! layouts and pipelines of the event scan that runs between a parent's update and its
//! children's. What the buffers hold: `crate::sim::event_scan` and `crate::sim::trails`.

use crate::effect::{Effect, MAX_EVENTS_PER_EMITTER, TrailMode};
use crate::gpu::types::SimParams;
use crate::gpu::{GpuContext, compute_storage_entry};
use crate::shaders::{ShaderError, ShaderLibrary, create_checked};
use crate::sim::event_scan::{
    EVENT_SCAN_BLOCK, EventHeader, EventRule, EventSpawn, RECORD_WORDS, RULES_BYTES, ScanConfig,
    rules_of, step_cap,
};

/// The layouts and the scan pipeline (one per update pass).
pub struct HookPipes {
    /// Group 1 of an update with hooks: the event records (written), the spawn list
    /// (read), the trail's ring (written).
    pub hooks_layout: wgpu::BindGroupLayout,
    scan_layout: wgpu::BindGroupLayout,
    scan_pipeline_layout: wgpu::PipelineLayout,
    /// The scan's three passes (count the blocks, scan their sums, write the list),
    /// built from `events.wgsl`.
    pub scan: Option<[wgpu::ComputePipeline; 3]>,
    /// Bound in group 1 for a role an emitter does not have (one per binding: a buffer
    /// cannot be bound read-only and writable in one dispatch).
    placeholders: [wgpu::Buffer; 3],
}

impl HookPipes {
    /// The layouts; the scan is built by [`HookPipes::rebuild`].
    pub fn new(ctx: &GpuContext, params_entry: wgpu::BindGroupLayoutEntry) -> Self {
        let device = &ctx.device;
        let hooks_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("HookPipes::hooks_layout"),
            entries: &[
                compute_storage_entry(0, false),
                compute_storage_entry(1, true),
                compute_storage_entry(2, false),
            ],
        });
        let scan_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("HookPipes::scan_layout"),
            entries: &[
                params_entry,
                compute_storage_entry(1, true),
                compute_storage_entry(2, false),
                compute_storage_entry(4, false),
                compute_storage_entry(5, false),
                wgpu::BindGroupLayoutEntry {
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ..crate::gpu::fragment_buffer_entry(3, wgpu::BufferBindingType::Uniform)
                },
            ],
        });
        let scan_pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("HookPipes::scan_pipeline_layout"),
            bind_group_layouts: &[Some(&scan_layout)],
            immediate_size: 0,
        });
        // Larger than either binding's fixed part (rules + one record; header + one entry).
        let placeholders = [0, 1, 2].map(|_| storage_buffer(device, "HookPipes::placeholder", 256));
        Self {
            hooks_layout,
            scan_layout,
            scan_pipeline_layout,
            scan: None,
            placeholders,
        }
    }

    /// Builds the scan from `lib` (on error the old one stays); the files it read.
    pub fn rebuild(
        &mut self,
        ctx: &GpuContext,
        lib: &ShaderLibrary,
    ) -> Result<Vec<String>, ShaderError> {
        let src = lib.compose("events.wgsl")?;
        let scan = create_checked(&ctx.device, &src, lib, |module| {
            ["count_blocks", "scan_blocks", "write_list"].map(|entry| {
                crate::gpu::compute_pipeline(
                    ctx,
                    "HookPipes::scan",
                    &self.scan_pipeline_layout,
                    module,
                    entry,
                    &[],
                )
            })
        })?;
        self.scan = Some(scan);
        Ok(src.files)
    }
}

/// A storage buffer of `size` bytes that can be cleared, written and read back.
fn storage_buffer(device: &wgpu::Device, label: &str, size: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size,
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_DST
            | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    })
}

/// What an emitter's hook buffers were made for: capacity, rules, list length, the
/// trail's ring (points, steps between them, mode), and which rules' children are linked
/// into ribbons per parent.
type HooksKey = (
    u32,
    [EventRule; MAX_EVENTS_PER_EMITTER],
    u32,
    Option<(u32, u32, TrailMode)>,
    [bool; MAX_EVENTS_PER_EMITTER],
);

/// One emitter's hook buffers: its event records (a parent), its spawn list (a child) and
/// its trail's ring (see `crate::sim::trails`).
pub struct EmitterHooks {
    /// Rules, counts and records (a parent; `EventOut` in `shaders/event_types.wgsl`).
    pub records: Option<wgpu::Buffer>,
    /// Header and list (a child).
    pub list: Option<wgpu::Buffer>,
    /// The trail's ring of positions (an emitter with a trail).
    pub trail: Option<wgpu::Buffer>,
    /// Group 1 of the update.
    pub hooks: wgpu::BindGroup,
    /// Per rule of this parent: the child, its config buffer and the scan's bind group.
    pub scans: Vec<Scan>,
    /// What the buffers were made for.
    key: HooksKey,
}

/// One rule's scan.
pub struct Scan {
    /// The child emitter.
    pub child: usize,
    /// The rule's `ScanConfig`.
    pub config: wgpu::Buffer,
    /// The scan's scratch: where its children start in the list, then one sum (then
    /// offset) per block of the parent's window.
    pub blocks: wgpu::Buffer,
    /// Group 0 of the scan (the parent's params at a dynamic offset).
    pub group: Option<wgpu::BindGroup>,
    /// Whether the scan links the children into ribbons per parent (its scratch keeps
    /// each parent slot's last child).
    pub linked: bool,
    /// What `config` holds (written again only when it changes: the simulation spaces'
    /// origins move only at a restart).
    pub written: Option<ScanConfig>,
}

/// The hooks group of one emitter: its records, its spawn list and its trail ring, each a
/// placeholder when the emitter has none.
fn hooks_group(
    device: &wgpu::Device,
    pipes: &HookPipes,
    buffers: [&Option<wgpu::Buffer>; 3],
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry> = buffers
        .iter()
        .zip(&pipes.placeholders)
        .enumerate()
        .map(|(binding, (buffer, placeholder))| wgpu::BindGroupEntry {
            binding: binding as u32,
            resource: buffer.as_ref().unwrap_or(placeholder).as_entire_binding(),
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("EmitterHooks::hooks"),
        layout: &pipes.hooks_layout,
        entries: &entries,
    })
}

impl Scan {
    /// The scan of one event rule into `child`'s list, for a parent of `capacity` slots.
    fn new(device: &wgpu::Device, child: usize, linked: bool, capacity: u32) -> Self {
        Scan {
            child,
            config: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("EmitterHooks::scan_config"),
                size: size_of::<ScanConfig>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            // Where the list starts, a sum per block, the cap's bucket and this step's
            // allowance, and for a ribbon per parent each parent slot's last child.
            blocks: storage_buffer(
                device,
                "EmitterHooks::scan_blocks",
                4 * (3
                    + u64::from(capacity.div_ceil(EVENT_SCAN_BLOCK))
                    + if linked { 2 * u64::from(capacity) } else { 0 }),
            ),
            group: None,
            linked,
            written: None,
        }
    }
}

impl EmitterHooks {
    /// Buffers for emitter `i` of `effect` with `capacity` slots (reusing `old`'s when
    /// they fit: same capacity, rules and list).
    pub fn sync(
        ctx: &GpuContext,
        pipes: &HookPipes,
        effect: &Effect,
        i: usize,
        capacity: u32,
        old: Option<EmitterHooks>,
    ) -> Option<EmitterHooks> {
        let e = effect.emitters.get(i)?;
        let list_len: u32 = effect
            .event_sources(i)
            .iter()
            .map(|&(p, k)| step_cap(effect, p, k))
            .sum();
        let trail = e.look.trail.as_ref().map(|t| {
            let layout = t.layout(effect.time.nominal_step_secs());
            (layout.points, layout.every, t.mode)
        });
        if e.events.is_empty() && list_len == 0 && trail.is_none() {
            return None;
        }
        let rules = rules_of(e);
        let children: Vec<usize> = e
            .events
            .iter()
            .filter_map(|ev| effect.event_target(ev))
            .collect();
        let mut linked = [false; MAX_EVENTS_PER_EMITTER];
        for (l, &child) in linked.iter_mut().zip(&children) {
            *l = effect.emitters[child].look.ribbon_per_parent();
        }
        let key = (capacity, rules, list_len, trail, linked);
        if let Some(old) = old.filter(|o| o.key == key) {
            return Some(old);
        }
        let device = &ctx.device;
        let records = (!e.events.is_empty()).then(|| {
            let (fixed, per_slot) = record_bytes();
            let size = fixed + per_slot * u64::from(capacity);
            let b = storage_buffer(device, "EmitterHooks::records", size);
            ctx.queue.write_buffer(&b, 0, bytemuck::cast_slice(&rules));
            b
        });
        let list = (list_len > 0).then(|| {
            let size = size_of::<EventHeader>() as u64
                + u64::from(list_len) * size_of::<EventSpawn>() as u64;
            // New buffers are zeroed: head 0, count 0, stamp 0.
            storage_buffer(device, "EmitterHooks::list", size)
        });
        let trail = trail.map(|(points, every, mode)| {
            crate::sim::trails::ring_buffer(ctx, capacity, points, every, mode)
        });
        let hooks = hooks_group(device, pipes, [&records, &list, &trail]);
        let scans = children
            .into_iter()
            .zip(linked)
            .map(|(child, linked)| Scan::new(device, child, linked, capacity))
            .collect();
        Some(EmitterHooks {
            records,
            list,
            trail,
            hooks,
            scans,
            key,
        })
    }

    /// Group 0 of each scan of this parent: `params` (the update's parameter blocks),
    /// the children's lists (`lists[child]`) and their ribbons' rings (`ribbons[child]`,
    /// an emitter drawn as a ribbon per parent).
    pub fn bind_scans(
        &mut self,
        device: &wgpu::Device,
        pipes: &HookPipes,
        params: &wgpu::Buffer,
        lists: &[Option<wgpu::Buffer>],
        ribbons: &[Option<wgpu::Buffer>],
    ) {
        let Some(records) = &self.records else {
            return;
        };
        for scan in &mut self.scans {
            let Some(Some(list)) = lists.get(scan.child) else {
                scan.group = None;
                continue;
            };
            scan.group = Some(
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("EmitterHooks::scan"),
                    layout: &pipes.scan_layout,
                    entries: &[
                        wgpu::BindGroupEntry {
                            binding: 0,
                            resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                                buffer: params,
                                offset: 0,
                                size: wgpu::BufferSize::new(size_of::<SimParams>() as u64),
                            }),
                        },
                        wgpu::BindGroupEntry {
                            binding: 1,
                            resource: records.as_entire_binding(),
                        },
                        wgpu::BindGroupEntry {
                            binding: 2,
                            resource: list.as_entire_binding(),
                        },
                        wgpu::BindGroupEntry {
                            binding: 3,
                            resource: scan.config.as_entire_binding(),
                        },
                        wgpu::BindGroupEntry {
                            binding: 4,
                            resource: scan.blocks.as_entire_binding(),
                        },
                        wgpu::BindGroupEntry {
                            binding: 5,
                            resource: ribbons
                                .get(scan.child)
                                .and_then(Option::as_ref)
                                .unwrap_or(&pipes.placeholders[2])
                                .as_entire_binding(),
                        },
                    ],
                }),
            );
        }
    }
}

/// The bytes of a parent's event records: (the rules, then per slot) — a count (one word)
/// and a record (`RECORD_WORDS` words) per rule and slot.
pub fn record_bytes() -> (u64, u64) {
    (
        RULES_BYTES,
        4 * (1 + RECORD_WORDS) * MAX_EVENTS_PER_EMITTER as u64,
    )
}
