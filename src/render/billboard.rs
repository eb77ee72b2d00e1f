//! The billboard pass: one instanced draw of camera-facing quads per emitter, vertex
//! pulling from the state buffer the update pass just wrote.

use std::collections::HashMap;

use crate::effect::{BlendMode, Effect, Look, MAX_COLOR_STOPS};
use crate::gpu::GpuContext;
use crate::gpu::types::{CameraUniform, LookUniform, PARAMS_STRIDE};
use crate::render::{HDR_FORMAT, OrbitCamera};
use crate::shaders::{ShaderError, ShaderLibrary, create_checked};
use crate::sim::GpuSim;

/// Instanced billboards into the HDR target.
pub struct BillboardPass {
    frame_layout: wgpu::BindGroupLayout,
    particle_layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    additive: wgpu::RenderPipeline,
    alpha: wgpu::RenderPipeline,
    camera: wgpu::Buffer,
    looks: wgpu::Buffer,
    look_slots: usize,
    frame_group: wgpu::BindGroup,
    particle_groups: HashMap<(u64, usize), wgpu::BindGroup>,
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
    u
}

impl BillboardPass {
    /// Builds both blend pipelines from `lib`.
    pub fn new(ctx: &GpuContext, lib: &ShaderLibrary) -> Result<Self, ShaderError> {
        let d = &ctx.device;
        let uniform = |binding, dynamic| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: dynamic,
                min_binding_size: None,
            },
            count: None,
        };
        let storage = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::VERTEX,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: true },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let frame_layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("BillboardPass::frame_layout"),
            entries: &[uniform(0, false), uniform(1, true)],
        });
        let particle_layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("BillboardPass::particle_layout"),
            entries: &[storage(0), storage(1)],
        });
        let pipeline_layout = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("BillboardPass::pipeline_layout"),
            bind_group_layouts: &[Some(&frame_layout), Some(&particle_layout)],
            immediate_size: 0,
        });
        let (additive, alpha) = Self::build(ctx, lib, &pipeline_layout)?;
        let camera = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("BillboardPass::camera"),
            size: size_of::<CameraUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let (looks, frame_group) = Self::look_buffer(ctx, &frame_layout, &camera, 4);
        Ok(Self {
            frame_layout,
            particle_layout,
            pipeline_layout,
            additive,
            alpha,
            camera,
            looks,
            look_slots: 4,
            frame_group,
            particle_groups: HashMap::new(),
        })
    }

    fn look_buffer(
        ctx: &GpuContext,
        layout: &wgpu::BindGroupLayout,
        camera: &wgpu::Buffer,
        slots: usize,
    ) -> (wgpu::Buffer, wgpu::BindGroup) {
        let looks = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("BillboardPass::looks"),
            size: slots as u64 * PARAMS_STRIDE,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("BillboardPass::frame_group"),
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

    fn build(
        ctx: &GpuContext,
        lib: &ShaderLibrary,
        layout: &wgpu::PipelineLayout,
    ) -> Result<(wgpu::RenderPipeline, wgpu::RenderPipeline), ShaderError> {
        let composed = lib.compose("billboard.wgsl")?;
        let make = |module: &wgpu::ShaderModule, blend: wgpu::BlendState, label| {
            ctx.device
                .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                    label: Some(label),
                    layout: Some(layout),
                    vertex: wgpu::VertexState {
                        module,
                        entry_point: Some("vs_main"),
                        compilation_options: Default::default(),
                        buffers: &[],
                    },
                    primitive: wgpu::PrimitiveState::default(),
                    depth_stencil: None,
                    multisample: wgpu::MultisampleState::default(),
                    fragment: Some(wgpu::FragmentState {
                        module,
                        entry_point: Some("fs_main"),
                        compilation_options: Default::default(),
                        targets: &[Some(wgpu::ColorTargetState {
                            format: HDR_FORMAT,
                            blend: Some(blend),
                            write_mask: wgpu::ColorWrites::ALL,
                        })],
                    }),
                    multiview_mask: None,
                    cache: None,
                })
        };
        let additive_blend = wgpu::BlendState {
            color: wgpu::BlendComponent {
                src_factor: wgpu::BlendFactor::One,
                dst_factor: wgpu::BlendFactor::One,
                operation: wgpu::BlendOperation::Add,
            },
            alpha: wgpu::BlendComponent {
                src_factor: wgpu::BlendFactor::Zero,
                dst_factor: wgpu::BlendFactor::One,
                operation: wgpu::BlendOperation::Add,
            },
        };
        create_checked(&ctx.device, &composed, lib, |module| {
            (
                make(module, additive_blend, "BillboardPass::additive"),
                make(
                    module,
                    wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING,
                    "BillboardPass::alpha",
                ),
            )
        })
    }

    /// Rebuilds the pipelines; keeps the old ones on error.
    pub fn rebuild(&mut self, ctx: &GpuContext, lib: &ShaderLibrary) -> Result<(), ShaderError> {
        let (additive, alpha) = Self::build(ctx, lib, &self.pipeline_layout)?;
        self.additive = additive;
        self.alpha = alpha;
        Ok(())
    }

    /// Clears `target` and draws every enabled emitter (alpha-blended layers first, then
    /// additive ones on top).
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &mut self,
        ctx: &GpuContext,
        enc: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        sim: &GpuSim,
        effect: &Effect,
        camera: &OrbitCamera,
        aspect: f32,
        alpha: f32,
    ) {
        ctx.queue.write_buffer(
            &self.camera,
            0,
            bytemuck::bytes_of(&camera.uniform(aspect, alpha)),
        );
        let n = effect.emitters.len();
        if n > self.look_slots {
            self.look_slots = n.next_power_of_two();
            let (looks, group) =
                Self::look_buffer(ctx, &self.frame_layout, &self.camera, self.look_slots);
            self.looks = looks;
            self.frame_group = group;
        }
        let mut blocks = vec![0u8; n * PARAMS_STRIDE as usize];
        for (i, e) in effect.emitters.iter().enumerate() {
            let at = i * PARAMS_STRIDE as usize;
            let mut u = look_uniform(&e.look);
            let origin = sim
                .planner
                .emitters
                .get(i)
                .map(|p| p.origin())
                .unwrap_or_default();
            u.clip_from_sim = camera.clip_from_sim(aspect, origin).to_cols_array_2d();
            blocks[at..at + size_of::<LookUniform>()].copy_from_slice(bytemuck::bytes_of(&u));
        }
        if !blocks.is_empty() {
            ctx.queue.write_buffer(&self.looks, 0, &blocks);
        }
        // Bind groups over the state buffers, cached by buffer generation and parity.
        let mut draws = Vec::new();
        for (i, e) in effect.emitters.iter().enumerate() {
            let Some(b) = sim.emitter_buffers(i) else {
                continue;
            };
            if !e.enabled {
                continue;
            }
            let key = (b.generation, b.parity);
            self.particle_groups.entry(key).or_insert_with(|| {
                ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("BillboardPass::particle_group"),
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
                    ],
                })
            });
            draws.push((i, key, b.capacity, e.look.blend));
        }
        let live: std::collections::HashSet<u64> = draws.iter().map(|d| d.1.0).collect();
        self.particle_groups.retain(|k, _| live.contains(&k.0));
        draws.sort_by_key(|d| match d.3 {
            BlendMode::Alpha => 0,
            BlendMode::Additive => 1,
        });

        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("BillboardPass::pass"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        for (i, key, capacity, blend) in draws {
            let Some(group) = self.particle_groups.get(&key) else {
                continue;
            };
            pass.set_pipeline(match blend {
                BlendMode::Additive => &self.additive,
                BlendMode::Alpha => &self.alpha,
            });
            pass.set_bind_group(0, &self.frame_group, &[(i as u64 * PARAMS_STRIDE) as u32]);
            pass.set_bind_group(1, group, &[]);
            pass.draw(0..6, 0..capacity);
        }
    }
}
