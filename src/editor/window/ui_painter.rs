//! Painting egui's output: egui-wgpu's renderer, or a lean painter for CPU adapters.
//!
//! Why two: on Mesa's llvmpipe (lavapipe), egui-wgpu 0.37's fragment shader costs about
//! 80 ns per pixel against 13 ns for a plain `color × textureSample` (measured at
//! 1280×720 on the 2-core development machine). Its shader branches on a uniform
//! (`predictable_texture_filtering`) and llvmpipe runs both sides, including four
//! `textureLoad`s and integer modulos, for every pixel; a full 1280×720 editor frame
//! then takes ~170 ms in egui alone. [`LeanPainter`] draws the same meshes with a
//! branch-free shader. Real GPUs keep egui-wgpu's renderer
//! ([`crate::editor::window::editor_profile::EditorProfile::lean_painter`]).

use std::collections::HashMap;

use bytemuck::{Pod, Zeroable};
use egui::epaint::{ImageDelta, Primitive};
use egui::{
    ClippedPrimitive, ImageData, TextureFilter, TextureId, TextureOptions, TextureWrapMode,
};

/// The painter in use.
pub enum UiPainter {
    /// egui-wgpu's renderer.
    EguiWgpu(Box<egui_wgpu::Renderer>),
    /// The lean painter.
    Lean(Box<LeanPainter>),
}

impl UiPainter {
    /// A painter drawing into `format` targets: the lean one, or egui-wgpu's.
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat, lean: bool) -> Self {
        if lean {
            Self::Lean(Box::new(LeanPainter::new(device, format)))
        } else {
            Self::EguiWgpu(Box::new(egui_wgpu::Renderer::new(
                device,
                format,
                egui_wgpu::RendererOptions::default(),
            )))
        }
    }

    /// Name for logs and the Stats section.
    pub fn name(&self) -> &'static str {
        match self {
            Self::EguiWgpu(_) => "egui-wgpu",
            Self::Lean(_) => "lean",
        }
    }

    /// Applies one texture update from egui (call for every delta, every frame).
    pub fn update_texture(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        id: TextureId,
        delta: &ImageDelta,
    ) {
        match self {
            Self::EguiWgpu(r) => r.update_texture(device, queue, id, delta),
            Self::Lean(r) => r.update_texture(device, queue, id, delta),
        }
    }

    /// Frees a texture egui no longer uses.
    pub fn free_texture(&mut self, id: &TextureId) {
        match self {
            Self::EguiWgpu(r) => r.free_texture(id),
            Self::Lean(r) => r.free_texture(id),
        }
    }

    /// Shows `view` (gamma-encoded RGBA8) under a new egui texture id, or under `id`.
    pub fn set_native_texture(
        &mut self,
        device: &wgpu::Device,
        view: &wgpu::TextureView,
        id: Option<TextureId>,
    ) -> TextureId {
        let filter = wgpu::FilterMode::Linear;
        match (self, id) {
            (Self::EguiWgpu(r), Some(id)) => {
                r.update_egui_texture_from_wgpu_texture(device, view, filter, id);
                id
            }
            (Self::EguiWgpu(r), None) => r.register_native_texture(device, view, filter),
            (Self::Lean(r), id) => r.set_native_texture(device, view, id),
        }
    }

    /// Uploads the meshes; returns command buffers to submit before the frame's.
    pub fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        paint_jobs: &[ClippedPrimitive],
        screen: &egui_wgpu::ScreenDescriptor,
    ) -> Vec<wgpu::CommandBuffer> {
        match self {
            Self::EguiWgpu(r) => r.update_buffers(device, queue, encoder, paint_jobs, screen),
            Self::Lean(r) => {
                r.prepare(device, queue, paint_jobs, screen);
                Vec::new()
            }
        }
    }

    /// Draws the prepared meshes into `target` in a render pass of its own that starts
    /// with `load` (a clear, or what the target holds).
    pub fn paint(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        paint_jobs: &[ClippedPrimitive],
        screen: &egui_wgpu::ScreenDescriptor,
        load: wgpu::LoadOp<wgpu::Color>,
    ) {
        let mut pass =
            crate::gpu::color_pass(encoder, target, load, "UiPainter::paint").forget_lifetime();
        self.render(&mut pass, paint_jobs, screen);
    }

    /// Draws the prepared meshes.
    pub fn render(
        &self,
        pass: &mut wgpu::RenderPass<'static>,
        paint_jobs: &[ClippedPrimitive],
        screen: &egui_wgpu::ScreenDescriptor,
    ) {
        match self {
            Self::EguiWgpu(r) => r.render(pass, paint_jobs, screen),
            Self::Lean(r) => r.render(pass, screen),
        }
    }
}

/// Keep in sync with `VertexIn` in [`LEAN_SHADER`]; same layout as `epaint::Vertex`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct GpuVertex {
    pos: [f32; 2],
    uv: [f32; 2],
    /// Premultiplied sRGB-encoded RGBA.
    color: [u8; 4],
}

/// Keep in sync with `Locals` in [`LEAN_SHADER`].
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct Locals {
    screen_size_points: [f32; 2],
    _pad: [f32; 2],
}

/// egui's colours and textures are gamma-encoded and premultiplied; the output is too
/// (`fs_gamma`), or decoded for sRGB targets (`fs_linear`). No branch at all, so
/// llvmpipe runs only what each pixel needs; every texture here has one level, so the
/// explicit level 0 spares llvmpipe the derivatives (~0.3 ms of the 868×720 viewport
/// image's 4.5 ms).
const LEAN_SHADER: &str = r#"
struct Locals {
    screen_size_points: vec2<f32>,
    pad: vec2<f32>,
}
@group(0) @binding(0) var<uniform> locals: Locals;
@group(1) @binding(0) var tex: texture_2d<f32>;
@group(1) @binding(1) var tex_sampler: sampler;

struct VertexIn {
    @location(0) pos: vec2<f32>,
    @location(1) uv: vec2<f32>,
    @location(2) color: u32,
}

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) color: vec4<f32>,
}

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    var out: VertexOut;
    let ndc = v.pos / locals.screen_size_points * vec2<f32>(2.0, -2.0) + vec2<f32>(-1.0, 1.0);
    out.clip = vec4<f32>(ndc, 0.0, 1.0);
    out.uv = v.uv;
    out.color = unpack4x8unorm(v.color);
    return out;
}

@fragment
fn fs_gamma(in: VertexOut) -> @location(0) vec4<f32> {
    return in.color * textureSampleLevel(tex, tex_sampler, in.uv, 0.0);
}

@fragment
fn fs_linear(in: VertexOut) -> @location(0) vec4<f32> {
    let c = in.color * textureSampleLevel(tex, tex_sampler, in.uv, 0.0);
    let lo = c.rgb / 12.92;
    let hi = pow((c.rgb + 0.055) / 1.055, vec3<f32>(2.4));
    return vec4<f32>(select(hi, lo, c.rgb < vec3<f32>(0.04045)), c.a);
}
"#;

struct LeanTexture {
    /// `None` for native textures (owned by someone else; opaque: drawn without blending).
    texture: Option<wgpu::Texture>,
    options: TextureOptions,
    bind_group: wgpu::BindGroup,
}

struct Draw {
    scissor: [u32; 4],
    indices: std::ops::Range<u32>,
    base_vertex: i32,
    texture: TextureId,
}

/// A minimal egui painter: one pipeline, premultiplied alpha, scissor per mesh.
/// Paint callbacks are not supported (the editor uses none).
pub struct LeanPainter {
    pipeline: wgpu::RenderPipeline,
    /// The same without blending, for native textures (the viewport image, opaque): no
    /// framebuffer read under ~60 % of the window.
    opaque_pipeline: wgpu::RenderPipeline,
    locals: wgpu::Buffer,
    locals_group: wgpu::BindGroup,
    texture_layout: wgpu::BindGroupLayout,
    samplers: HashMap<TextureOptions, wgpu::Sampler>,
    textures: HashMap<TextureId, LeanTexture>,
    next_native_id: u64,
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    draws: Vec<Draw>,
}

/// Premultiplied alpha, as egui-wgpu blends.
const PREMULTIPLIED: wgpu::BlendState = wgpu::BlendState {
    color: wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::OneMinusSrcAlpha,
        operation: wgpu::BlendOperation::Add,
    },
    alpha: wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::OneMinusDstAlpha,
        dst_factor: wgpu::BlendFactor::One,
        operation: wgpu::BlendOperation::Add,
    },
};

/// egui's triangles into `format`: positions, UVs and a packed colour per vertex.
fn lean_pipeline(
    device: &wgpu::Device,
    (module, layout): (&wgpu::ShaderModule, &wgpu::PipelineLayout),
    format: wgpu::TextureFormat,
    label: &str,
    blend: Option<wgpu::BlendState>,
) -> wgpu::RenderPipeline {
    let attributes = wgpu::vertex_attr_array![0 => Float32x2, 1 => Float32x2, 2 => Uint32];
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &[Some(wgpu::VertexBufferLayout {
                array_stride: size_of::<GpuVertex>() as u64,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &attributes,
            })],
        },
        primitive: wgpu::PrimitiveState {
            topology: wgpu::PrimitiveTopology::TriangleList,
            cull_mode: None,
            ..Default::default()
        },
        depth_stencil: None,
        multisample: wgpu::MultisampleState::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some(if format.is_srgb() {
                "fs_linear"
            } else {
                "fs_gamma"
            }),
            compilation_options: Default::default(),
            targets: &[Some(wgpu::ColorTargetState {
                format,
                blend,
                write_mask: wgpu::ColorWrites::ALL,
            })],
        }),
        multiview_mask: None,
        cache: None,
    })
}

impl LeanPainter {
    /// Builds the pipeline for `format` targets.
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("LeanPainter::shader"),
            source: wgpu::ShaderSource::Wgsl(LEAN_SHADER.into()),
        });
        let locals_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("LeanPainter::locals_layout"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: wgpu::BufferSize::new(size_of::<Locals>() as u64),
                },
                count: None,
            }],
        });
        let texture_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("LeanPainter::texture_layout"),
            entries: &[
                crate::gpu::fragment_texture_entry(0, true),
                crate::gpu::fragment_sampler_entry(1),
            ],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("LeanPainter::pipeline_layout"),
            bind_group_layouts: &[Some(&locals_layout), Some(&texture_layout)],
            immediate_size: 0,
        });
        let make = |label: &str, blend: Option<wgpu::BlendState>| {
            lean_pipeline(device, (&module, &layout), format, label, blend)
        };
        let pipeline = make("LeanPainter::pipeline", Some(PREMULTIPLIED));
        let opaque_pipeline = make("LeanPainter::opaque_pipeline", None);
        let locals = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("LeanPainter::locals"),
            size: size_of::<Locals>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let locals_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("LeanPainter::locals_group"),
            layout: &locals_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: locals.as_entire_binding(),
            }],
        });
        Self {
            pipeline,
            opaque_pipeline,
            locals,
            locals_group,
            texture_layout,
            samplers: HashMap::new(),
            textures: HashMap::new(),
            next_native_id: 0,
            vertices: vertex_or_index_buffer(device, 1 << 16, wgpu::BufferUsages::VERTEX),
            indices: vertex_or_index_buffer(device, 1 << 16, wgpu::BufferUsages::INDEX),
            draws: Vec::new(),
        }
    }

    fn bind_group(
        &mut self,
        device: &wgpu::Device,
        view: &wgpu::TextureView,
        options: TextureOptions,
    ) -> wgpu::BindGroup {
        let sampler = self
            .samplers
            .entry(options)
            .or_insert_with(|| create_sampler(device, options));
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("LeanPainter::texture_group"),
            layout: &self.texture_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(view),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::Sampler(sampler),
                },
            ],
        })
    }

    fn update_texture(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        id: TextureId,
        delta: &ImageDelta,
    ) {
        let ImageData::Color(image) = &delta.image;
        let [w, h] = image.size.map(|v| v as u32);
        if w == 0 || h == 0 || image.pixels.len() != (w * h) as usize {
            log::warn!("egui texture {id:?}: ignoring a malformed {w}x{h} update");
            return;
        }
        let (texture, origin) = match (delta.pos, self.textures.get(&id)) {
            (
                Some(pos),
                Some(LeanTexture {
                    texture: Some(t), ..
                }),
            ) => (
                t.clone(),
                wgpu::Origin3d {
                    x: pos[0] as u32,
                    y: pos[1] as u32,
                    z: 0,
                },
            ),
            (Some(_), _) => {
                log::warn!("egui texture {id:?}: partial update of an unknown texture");
                return;
            }
            (None, _) => (
                crate::gpu::texture_2d(
                    device,
                    "LeanPainter::texture",
                    (w, h),
                    1,
                    // Gamma-encoded bytes, sampled as they are (like egui-wgpu).
                    wgpu::TextureFormat::Rgba8Unorm,
                    wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                ),
                wgpu::Origin3d::ZERO,
            ),
        };
        let bytes: Vec<u8> = image.pixels.iter().flat_map(|c| c.to_array()).collect();
        queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &texture,
                mip_level: 0,
                origin,
                aspect: wgpu::TextureAspect::All,
            },
            &bytes,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(4 * w),
                rows_per_image: Some(h),
            },
            wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
        );
        let reuse = delta.pos.is_some()
            && self
                .textures
                .get(&id)
                .is_some_and(|t| t.options == delta.options);
        if !reuse {
            let view = texture.create_view(&Default::default());
            let bind_group = self.bind_group(device, &view, delta.options);
            self.textures.insert(
                id,
                LeanTexture {
                    texture: Some(texture),
                    options: delta.options,
                    bind_group,
                },
            );
        }
    }

    fn free_texture(&mut self, id: &TextureId) {
        self.textures.remove(id);
    }

    fn set_native_texture(
        &mut self,
        device: &wgpu::Device,
        view: &wgpu::TextureView,
        id: Option<TextureId>,
    ) -> TextureId {
        let id = id.unwrap_or_else(|| {
            self.next_native_id += 1;
            TextureId::User(self.next_native_id)
        });
        let options = TextureOptions::LINEAR;
        let bind_group = self.bind_group(device, view, options);
        self.textures.insert(
            id,
            LeanTexture {
                texture: None,
                options,
                bind_group,
            },
        );
        id
    }

    fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        paint_jobs: &[ClippedPrimitive],
        screen: &egui_wgpu::ScreenDescriptor,
    ) {
        let ppp = screen.pixels_per_point;
        let [w, h] = screen.size_in_pixels;
        queue.write_buffer(
            &self.locals,
            0,
            bytemuck::bytes_of(&Locals {
                screen_size_points: [w as f32 / ppp, h as f32 / ppp],
                _pad: [0.0; 2],
            }),
        );
        let mut vertices: Vec<GpuVertex> = Vec::new();
        let mut indices: Vec<u32> = Vec::new();
        self.draws.clear();
        for job in paint_jobs {
            let Primitive::Mesh(mesh) = &job.primitive else {
                continue;
            };
            if mesh.indices.is_empty() {
                continue;
            }
            let clip = job.clip_rect;
            let x0 = ((clip.min.x * ppp).round().max(0.0) as u32).min(w);
            let y0 = ((clip.min.y * ppp).round().max(0.0) as u32).min(h);
            let x1 = ((clip.max.x * ppp).round().max(0.0) as u32).clamp(x0, w);
            let y1 = ((clip.max.y * ppp).round().max(0.0) as u32).clamp(y0, h);
            if x1 == x0 || y1 == y0 {
                continue;
            }
            let first = indices.len() as u32;
            let base_vertex = vertices.len() as i32;
            vertices.extend(mesh.vertices.iter().map(|v| GpuVertex {
                pos: [v.pos.x, v.pos.y],
                uv: [v.uv.x, v.uv.y],
                color: v.color.to_array(),
            }));
            indices.extend_from_slice(&mesh.indices);
            self.draws.push(Draw {
                scissor: [x0, y0, x1 - x0, y1 - y0],
                indices: first..indices.len() as u32,
                base_vertex,
                texture: mesh.texture_id,
            });
        }
        let vertex_bytes: &[u8] = bytemuck::cast_slice(&vertices);
        let index_bytes: &[u8] = bytemuck::cast_slice(&indices);
        if vertex_bytes.len() as u64 > self.vertices.size() {
            self.vertices = vertex_or_index_buffer(
                device,
                (vertex_bytes.len() as u64).next_power_of_two(),
                wgpu::BufferUsages::VERTEX,
            );
        }
        if index_bytes.len() as u64 > self.indices.size() {
            self.indices = vertex_or_index_buffer(
                device,
                (index_bytes.len() as u64).next_power_of_two(),
                wgpu::BufferUsages::INDEX,
            );
        }
        if !vertex_bytes.is_empty() {
            queue.write_buffer(&self.vertices, 0, vertex_bytes);
            queue.write_buffer(&self.indices, 0, index_bytes);
        }
    }

    fn render(&self, pass: &mut wgpu::RenderPass<'static>, screen: &egui_wgpu::ScreenDescriptor) {
        let [w, h] = screen.size_in_pixels;
        pass.set_viewport(0.0, 0.0, w as f32, h as f32, 0.0, 1.0);
        pass.set_bind_group(0, &self.locals_group, &[]);
        pass.set_vertex_buffer(0, self.vertices.slice(..));
        pass.set_index_buffer(self.indices.slice(..), wgpu::IndexFormat::Uint32);
        let mut opaque = None;
        for draw in &self.draws {
            let Some(texture) = self.textures.get(&draw.texture) else {
                continue;
            };
            let is_opaque = texture.texture.is_none();
            if opaque != Some(is_opaque) {
                pass.set_pipeline(if is_opaque {
                    &self.opaque_pipeline
                } else {
                    &self.pipeline
                });
                opaque = Some(is_opaque);
            }
            let [x, y, sw, sh] = draw.scissor;
            pass.set_scissor_rect(x, y, sw, sh);
            pass.set_bind_group(1, &texture.bind_group, &[]);
            pass.draw_indexed(draw.indices.clone(), draw.base_vertex, 0..1);
        }
        pass.set_scissor_rect(0, 0, w, h);
    }
}

fn vertex_or_index_buffer(
    device: &wgpu::Device,
    size: u64,
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("LeanPainter::mesh_buffer"),
        size,
        usage: usage | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

fn create_sampler(device: &wgpu::Device, options: TextureOptions) -> wgpu::Sampler {
    let filter = |f: TextureFilter| match f {
        TextureFilter::Nearest => wgpu::FilterMode::Nearest,
        TextureFilter::Linear => wgpu::FilterMode::Linear,
    };
    let address_mode = match options.wrap_mode {
        TextureWrapMode::ClampToEdge => wgpu::AddressMode::ClampToEdge,
        TextureWrapMode::Repeat => wgpu::AddressMode::Repeat,
        TextureWrapMode::MirroredRepeat => wgpu::AddressMode::MirrorRepeat,
    };
    device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some("LeanPainter::sampler"),
        mag_filter: filter(options.magnification),
        min_filter: filter(options.minification),
        address_mode_u: address_mode,
        address_mode_v: address_mode,
        ..Default::default()
    })
}
