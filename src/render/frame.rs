//! Per-frame resources shared by both draw paths: the camera and per-emitter look
//! uniforms, the bind-group layouts, and bind groups over the state buffers (cached by
//! buffer generation and parity).

use std::collections::HashMap;

use crate::effect::{BlendMode, DrawPath, Effect, Look, MAX_COLOR_STOPS, SPLAT_BELOW_PX, Sprite};
use crate::gpu::GpuContext;
use crate::gpu::types::{CameraUniform, LookUniform, PARAMS_STRIDE};
use crate::render::OrbitCamera;
use crate::sim::{GpuSim, Modules};

/// One emitter to draw this frame.
#[derive(Clone, Copy, Debug)]
pub struct DrawItem {
    /// Emitter index (the look uniform's slot).
    pub index: usize,
    /// Key of the cached particle bind group.
    pub key: (u64, usize, bool),
    /// Slots (instances / invocations).
    pub capacity: u32,
    /// Blend mode.
    pub blend: BlendMode,
    /// The path chosen for this frame.
    pub splat: bool,
}

/// Uniform buffers, layouts and bind groups for the draw passes.
pub struct FrameResources {
    /// Group 0: camera + look (dynamic offset).
    pub frame_layout: wgpu::BindGroupLayout,
    /// Group 1: previous and current state.
    pub particle_layout: wgpu::BindGroupLayout,
    camera: wgpu::Buffer,
    looks: wgpu::Buffer,
    look_slots: usize,
    /// The group-0 bind group.
    pub frame_group: wgpu::BindGroup,
    particle_groups: HashMap<(u64, usize, bool), wgpu::BindGroup>,
    /// Bound as the draw order of emitters that are not sorted.
    no_order: wgpu::Buffer,
}

/// ∫ sprite coverage over the unit quad [-1, 1]² (keep in sync with `sprite_coverage`
/// in `shaders/look.wgsl`), by midpoint quadrature on a 256² grid.
pub fn sprite_integral(sprite: Sprite) -> f32 {
    let n = 256;
    let h = 2.0 / n as f64;
    let mut sum = 0.0;
    for j in 0..n {
        for i in 0..n {
            let x = -1.0 + (i as f64 + 0.5) * h;
            let y = -1.0 + (j as f64 + 0.5) * h;
            let r2 = x * x + y * y;
            if r2 >= 1.0 {
                continue;
            }
            sum += match sprite {
                Sprite::Point => f64::from(u8::from(r2 < 0.25)),
                Sprite::Spark => {
                    (1.5 * (-r2 * 14.0).exp() + 0.25 * (1.0 - r2) * (1.0 - r2)).min(1.0)
                }
                Sprite::SoftDisc => (1.0 - r2) * (1.0 - r2),
            };
        }
    }
    (sum * h * h) as f32
}

/// The look uniform of an emitter (gradient padded to `MAX_COLOR_STOPS`).
pub fn look_uniform(look: &Look) -> LookUniform {
    let mut u = LookUniform::default();
    let stops = &look.color_over_life[..look.color_over_life.len().min(MAX_COLOR_STOPS)];
    for (i, s) in stops.iter().enumerate() {
        u.colors[i] = s.rgba;
        u.stops[i / 4][i % 4] = s.t;
    }
    if stops.is_empty() {
        u.colors[0] = [1.0; 4];
    }
    u.size_intensity = [
        look.size_start_m,
        look.size_end_m,
        look.intensity,
        stops.len().max(1) as f32,
    ];
    u.sprite_blend = [
        look.sprite.index(),
        match look.blend {
            BlendMode::Additive => 0,
            BlendMode::Alpha => 1,
        },
        0,
        0,
    ];
    u.extra = [sprite_integral(look.sprite), 0.0, 0.0, 0.0];
    u
}

impl FrameResources {
    /// Creates the layouts and uniform buffers.
    pub fn new(ctx: &GpuContext) -> Self {
        let d = &ctx.device;
        let all = wgpu::ShaderStages::VERTEX_FRAGMENT | wgpu::ShaderStages::COMPUTE;
        let uniform = |binding, dynamic| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: all,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: dynamic,
                min_binding_size: None,
            },
            count: None,
        };
        let storage = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: true },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let frame_layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("FrameResources::frame_layout"),
            entries: &[uniform(0, false), uniform(1, true)],
        });
        let particle_layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("FrameResources::particle_layout"),
            entries: &[storage(0), storage(1), storage(2)],
        });
        let camera = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("FrameResources::camera"),
            size: size_of::<CameraUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let (looks, frame_group) = Self::look_buffer(ctx, &frame_layout, &camera, 4);
        Self {
            frame_layout,
            particle_layout,
            camera,
            looks,
            look_slots: 4,
            frame_group,
            particle_groups: HashMap::new(),
            no_order: d.create_buffer(&wgpu::BufferDescriptor {
                label: Some("FrameResources::no_order"),
                size: 16,
                usage: wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            }),
        }
    }

    fn look_buffer(
        ctx: &GpuContext,
        layout: &wgpu::BindGroupLayout,
        camera: &wgpu::Buffer,
        slots: usize,
    ) -> (wgpu::Buffer, wgpu::BindGroup) {
        let looks = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("FrameResources::looks"),
            size: slots as u64 * PARAMS_STRIDE,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("FrameResources::frame_group"),
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: camera.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &looks,
                        offset: 0,
                        size: wgpu::BufferSize::new(size_of::<LookUniform>() as u64),
                    }),
                },
            ],
        });
        (looks, group)
    }

    /// The dynamic offset of emitter `index`'s look uniform.
    pub fn look_offset(index: usize) -> u32 {
        (index as u64 * PARAMS_STRIDE) as u32
    }

    /// The particle bind group for a draw item.
    pub fn particle_group(&self, key: (u64, usize, bool)) -> Option<&wgpu::BindGroup> {
        self.particle_groups.get(&key)
    }

    /// Uploads this frame's uniforms and returns what to draw, with each emitter's path.
    #[allow(clippy::too_many_arguments)]
    pub fn prepare(
        &mut self,
        ctx: &GpuContext,
        sim: &GpuSim,
        effect: &Effect,
        camera: &OrbitCamera,
        size: (u32, u32),
        alpha: f32,
        sort: &mut crate::render::sort::SortPass,
    ) -> Vec<DrawItem> {
        let aspect = size.0 as f32 / size.1.max(1) as f32;
        let cam = camera.uniform(size, alpha);
        ctx.queue
            .write_buffer(&self.camera, 0, bytemuck::bytes_of(&cam));
        let n = effect.emitters.len();
        if n > self.look_slots {
            self.look_slots = n.next_power_of_two();
            let (looks, group) =
                Self::look_buffer(ctx, &self.frame_layout, &self.camera, self.look_slots);
            self.looks = looks;
            self.frame_group = group;
        }
        let mut blocks = vec![0u8; n * PARAMS_STRIDE as usize];
        let mut items = Vec::new();
        for (i, e) in effect.emitters.iter().enumerate() {
            let origin = sim
                .planner
                .emitters
                .get(i)
                .map(|p| p.origin())
                .unwrap_or_default();
            let mut u = look_uniform(&e.look);
            u.clip_from_sim = camera.clip_from_sim(aspect, origin).to_cols_array_2d();
            if Modules::of(e).contains(Modules::STATELESS) {
                // Closed-form evaluation at the render time (between the last two steps).
                let t =
                    sim.planner.time_secs - (1.0 - alpha as f64) * sim.planner.last_dt_secs as f64;
                let a = e.forces.constant_acceleration();
                let w = e.forces.wind_m_per_s;
                u.extra[1] = 1.0;
                u.motion_a = [a.x, a.y, a.z, e.forces.drag_per_sec];
                u.motion_b = [w[0], w[1], w[2], t.rem_euclid(4096.0) as f32];
            }
            let at = i * PARAMS_STRIDE as usize;
            blocks[at..at + size_of::<LookUniform>()].copy_from_slice(bytemuck::bytes_of(&u));
            let Some(b) = sim.emitter_buffers(i) else {
                continue;
            };
            if !e.enabled {
                continue;
            }
            // Alpha-blended emitters are drawn back to front through the sort's order.
            let sorted = e.look.blend == BlendMode::Alpha;
            let order = if sorted {
                &sort.buffers(ctx, b.generation, b.capacity).values
            } else {
                &self.no_order
            };
            let key = (b.generation, b.parity, sorted);
            self.particle_groups.entry(key).or_insert_with(|| {
                ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("FrameResources::particle_group"),
                    layout: &self.particle_layout,
                    entries: &[
                        wgpu::BindGroupEntry {
                            binding: 0,
                            resource: b.previous.as_entire_binding(),
                        },
                        wgpu::BindGroupEntry {
                            binding: 1,
                            resource: b.current.as_entire_binding(),
                        },
                        wgpu::BindGroupEntry {
                            binding: 2,
                            resource: order.as_entire_binding(),
                        },
                    ],
                })
            });
            // Projected size at the emitter's distance decides the automatic path.
            let distance = (camera.eye() - glam::Vec3::from(e.transform.position_m))
                .length()
                .max(1e-3);
            let size_m = e.look.size_start_m.max(e.look.size_end_m);
            let size_px = size_m * cam.viewport[2] / distance;
            let additive = e.look.blend == BlendMode::Additive;
            let splat = additive
                && match e.look.draw_path {
                    DrawPath::Auto => size_px < SPLAT_BELOW_PX,
                    DrawPath::Billboard => false,
                    DrawPath::Splat => true,
                };
            items.push(DrawItem {
                index: i,
                key,
                capacity: b.capacity,
                blend: e.look.blend,
                splat,
            });
        }
        if !blocks.is_empty() {
            ctx.queue.write_buffer(&self.looks, 0, &blocks);
        }
        let live: std::collections::HashSet<u64> = items.iter().map(|d| d.key.0).collect();
        self.particle_groups.retain(|k, _| live.contains(&k.0));
        items
    }
}
