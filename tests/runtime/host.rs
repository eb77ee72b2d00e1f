//! The test's host programs: colour and depth targets of their own, opaque quads that
//! write depth, and `ignis::Player`s drawing after them. [`HostKind`] makes hosts as
//! others write them: reversed-Z, z-up, MSAA 4×, a depth-stencil format, downlevel
//! device limits.

use glam::{Mat4, Quat, Vec3};
use ignis::{Camera, HostTargets, Player, PlayerSettings};

use ignis::effect::Effect;

pub const SIZE: (u32, u32) = (160, 120);
// f32 light: sums of many additive particles are then exact to ~1e-6, not to f16's
// rounding at every blend (needs FLOAT32_BLENDABLE: lavapipe and NVIDIA have it).
pub const COLOR: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
pub const DEPTH: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
const NEAR_M: f32 = 0.05;
const FAR_M: f32 = 50.0;

/// How a host is written.
#[derive(Clone, Debug)]
pub struct HostKind {
    /// Its colour format (an MSAA host's: `Rgba16Float`, which every adapter multisamples).
    pub color: wgpu::TextureFormat,
    /// Its depth format.
    pub depth: wgpu::TextureFormat,
    /// Samples per pixel of both attachments.
    pub samples: u32,
    /// Depth 1 at the near plane, 0 far (Bevy's and many engines' convention).
    pub reversed_z: bool,
    /// +Z is up in its world; the player is told so.
    pub z_up: bool,
    /// The host keeps only `proj * view` and the eye (`Camera::from_view_proj`).
    pub view_proj_only: bool,
    /// The device's limits (`None`: enough for the tile rasteriser).
    pub limits: Option<wgpu::Limits>,
    /// Its depth is a transient attachment (`TRANSIENT_ATTACHMENT`: cleared and
    /// discarded by its one pass, never sampled).
    pub transient_depth: bool,
}

impl Default for HostKind {
    fn default() -> Self {
        Self {
            color: COLOR,
            depth: DEPTH,
            samples: 1,
            reversed_z: false,
            z_up: false,
            view_proj_only: false,
            limits: None,
            transient_depth: false,
        }
    }
}

impl HostKind {
    /// A y-up scene's point or direction in this host's world.
    pub fn world(&self, v: Vec3) -> Vec3 {
        if self.z_up { z_up() * v } else { v }
    }

    /// Bytes per colour texel read back.
    fn texel(&self) -> u32 {
        self.color.block_copy_size(None).unwrap_or(16)
    }
}

/// The rotation that takes a y-up scene into a z-up world (+Y to +Z).
pub fn z_up() -> Quat {
    Quat::from_rotation_arc(Vec3::Y, Vec3::Z)
}

/// A flat-coloured quad of the host's scene: four corners (a fan) and a colour.
pub struct Quad(pub [Vec3; 4], pub [f32; 3]);

/// The test's host program: a colour target (and its resolve when multisampled), a
/// depth buffer it writes and the particles sample, and a pipeline for its opaque quads.
pub struct Host {
    pub kind: HostKind,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    color: wgpu::Texture,
    resolve: Option<wgpu::Texture>,
    pub depth: wgpu::Texture,
    /// The one view of `depth` every frame hands over, as a host keeps its views.
    pub depth_view: wgpu::TextureView,
    quads: wgpu::RenderPipeline,
    pub camera: Camera,
    clip_from_world: Mat4,
    proj: Mat4,
}

/// What a host frame read back: linear RGBA per pixel and (single-sample `Depth32Float`
/// hosts) the depth buffer.
pub struct Frame {
    pub rgba: Vec<[f32; 4]>,
    pub depth: Vec<f32>,
}

/// A device on the default adapter with f32 blending and `limits` (default: the storage
/// buffers the tile rasteriser binds).
pub fn host_device(limits: Option<wgpu::Limits>) -> (wgpu::Device, wgpu::Queue) {
    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = pollster::block_on(wgpu::util::initialize_adapter_from_env_or_default(
        &instance, None,
    ))
    .expect("GPU tests need an adapter (CI installs mesa-vulkan-drivers)");
    let limits = limits.unwrap_or(wgpu::Limits {
        max_storage_buffers_per_shader_stage: ignis::testing::render::tiles::STORAGE_BUFFERS_NEEDED,
        ..Default::default()
    });
    pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        required_features: wgpu::Features::FLOAT32_BLENDABLE,
        required_limits: limits,
        ..Default::default()
    }))
    .expect("a device with FLOAT32_BLENDABLE")
}

const HOST_WGSL: &str = "
@group(0) @binding(0) var<uniform> clip_from_world: mat4x4<f32>;
struct V { @builtin(position) p: vec4<f32>, @location(0) c: vec3<f32> }
@vertex fn vs(@location(0) p: vec3<f32>, @location(1) c: vec3<f32>) -> V {
    return V(clip_from_world * vec4<f32>(p, 1.0), c);
}
@fragment fn fs(v: V) -> @location(0) vec4<f32> { return vec4<f32>(v.c, 1.0); }
";

impl Host {
    /// The plain host: y-up, ordinary depth, one sample, looking from `eye` at `target`.
    pub fn new(eye: Vec3, target: Vec3) -> Self {
        Self::of(HostKind::default(), eye, target)
    }

    /// A host of `kind`, looking from `eye` at `target` (given y-up: a z-up host turns
    /// them into its world).
    pub fn of(kind: HostKind, eye: Vec3, target: Vec3) -> Self {
        let (device, queue) = host_device(kind.limits.clone());
        let color = target_texture(&device, &kind, kind.color, kind.samples);
        let resolve = (kind.samples > 1).then(|| target_texture(&device, &kind, kind.color, 1));
        let depth = target_texture(&device, &kind, kind.depth, kind.samples);
        let depth_view = depth.create_view(&Default::default());
        let quads = quad_pipeline(&device, &kind);
        let (eye, target) = (kind.world(eye), kind.world(target));
        let view = glam::camera::rh::view::look_at_mat4(eye, target, kind.world(Vec3::Y));
        let aspect = SIZE.0 as f32 / SIZE.1 as f32;
        let (near, far) = if kind.reversed_z {
            (FAR_M, NEAR_M)
        } else {
            (NEAR_M, FAR_M)
        };
        let proj = glam::camera::rh::proj::directx::perspective(0.9, aspect, near, far);
        let camera = if kind.view_proj_only {
            Camera::from_view_proj((proj * view).to_cols_array_2d(), eye.to_array(), SIZE)
        } else {
            Camera::new(view, proj, SIZE)
        };
        Self {
            kind,
            device,
            queue,
            color,
            resolve,
            depth,
            depth_view,
            quads,
            camera,
            clip_from_world: proj * view,
            proj,
        }
    }

    pub fn settings(&self) -> PlayerSettings {
        PlayerSettings {
            depth_format: Some(self.kind.depth),
            depth_compare: if self.kind.reversed_z {
                wgpu::CompareFunction::GreaterEqual
            } else {
                wgpu::CompareFunction::LessEqual
            },
            sample_count: self.kind.samples,
            world_up: self.kind.world(Vec3::Y),
            asset_dir: Some(concat!(env!("CARGO_MANIFEST_DIR"), "/presets").into()),
            ..PlayerSettings::new(self.kind.color)
        }
    }

    pub fn player(&self, effect: &Effect) -> Player {
        Player::new(&self.device, &self.queue, effect, self.settings()).expect("player")
    }

    /// An instance transform given y-up, in this host's world (the same motion in the
    /// turned world: the identity stays the identity).
    pub fn place(&self, y_up: Mat4) -> Mat4 {
        if self.kind.z_up {
            let r = Mat4::from_quat(z_up());
            r * y_up * r.inverse()
        } else {
            y_up
        }
    }

    /// One host frame: clear to `background`, draw `quads` (writing depth), then every
    /// player's compute work and draw — with the depth handed over for soft edges when
    /// `soft` — and read colour (and depth) back.
    pub fn frame(
        &self,
        background: [f64; 3],
        quads: &[Quad],
        players: &mut [&mut Player],
        soft: bool,
    ) -> Frame {
        let depth = &self.depth_view;
        let mut enc = self.device.create_command_encoder(&Default::default());
        self.draw_opaque(&mut enc, background, quads, |_| {});
        for p in players.iter_mut() {
            p.record(&mut enc, &self.camera, soft.then_some(depth))
                .expect("record");
        }
        let color = self.color.create_view(&Default::default());
        let resolve = self
            .resolve
            .as_ref()
            .map(|r| r.create_view(&Default::default()));
        let targets = HostTargets {
            color: &color,
            resolve_target: resolve.as_ref(),
            depth: Some(depth),
        };
        {
            let mut pass = targets.begin_pass(&mut enc);
            for p in players.iter() {
                p.draw(&mut pass);
            }
        }
        self.read_back(enc)
    }

    /// Records the opaque pass: clears colour and depth to `background` and the far
    /// plane, draws `quads` writing depth, then lets `more` draw in the same pass.
    pub fn draw_opaque(
        &self,
        enc: &mut wgpu::CommandEncoder,
        background: [f64; 3],
        quads: &[Quad],
        more: impl FnOnce(&mut wgpu::RenderPass<'_>),
    ) {
        let vertices = self.vertices(quads);
        let uniform = wgpu::util::DeviceExt::create_buffer_init(
            &self.device,
            &wgpu::util::BufferInitDescriptor {
                label: None,
                contents: bytemuck::bytes_of(&self.clip_from_world),
                usage: wgpu::BufferUsages::UNIFORM,
            },
        );
        let group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &self.quads.get_bind_group_layout(0),
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: uniform.as_entire_binding(),
            }],
        });
        let color = self.color.create_view(&Default::default());
        let resolve = self
            .resolve
            .as_ref()
            .map(|r| r.create_view(&Default::default()));
        let [r, g, b] = background;
        let mut pass =
            self.begin_opaque(enc, &color, resolve.as_ref(), &self.depth_view, [r, g, b]);
        pass.set_pipeline(&self.quads);
        pass.set_bind_group(0, &group, &[]);
        pass.set_vertex_buffer(0, vertices.slice(..));
        pass.draw(0..quads.len() as u32 * 6, 0..1);
        more(&mut pass);
    }

    /// The opaque pass: clears both attachments, stores colour, and stores depth unless
    /// it is a transient attachment (which must be discarded).
    fn begin_opaque<'e>(
        &self,
        enc: &'e mut wgpu::CommandEncoder,
        color: &wgpu::TextureView,
        resolve: Option<&wgpu::TextureView>,
        depth: &wgpu::TextureView,
        [r, g, b]: [f64; 3],
    ) -> wgpu::RenderPass<'e> {
        let store = if (self.depth.usage()).contains(wgpu::TextureUsages::TRANSIENT_ATTACHMENT) {
            wgpu::StoreOp::Discard
        } else {
            wgpu::StoreOp::Store
        };
        let far = if self.kind.reversed_z { 0.0 } else { 1.0 };
        enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("test host opaque pass"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: color,
                depth_slice: None,
                resolve_target: resolve,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color { r, g, b, a: 1.0 }),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(far),
                    store,
                }),
                stencil_ops: self
                    .kind
                    .depth
                    .has_stencil_aspect()
                    .then_some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(0),
                        store,
                    }),
            }),
            ..Default::default()
        })
    }

    /// Submits `enc` with copies of the colour (resolved) and, where it can be copied,
    /// the depth, and reads them back.
    pub fn read_back(&self, mut enc: wgpu::CommandEncoder) -> Frame {
        let shown = self.resolve.as_ref().unwrap_or(&self.color);
        let texel = self.kind.texel();
        let rgba = read_texture(self, &mut enc, shown, texel);
        let depth_readable = self.kind.samples == 1
            && self.kind.depth == DEPTH
            && self.depth.usage().contains(wgpu::TextureUsages::COPY_SRC);
        let depth = depth_readable.then(|| read_texture(self, &mut enc, &self.depth, 4));
        self.queue.submit([enc.finish()]);
        let bytes = map(self, &rgba.0, rgba.1, texel);
        let rgba = if texel == 8 {
            let halves: Vec<half::f16> = bytemuck::pod_collect_to_vec(&bytes);
            halves
                .chunks_exact(4)
                .map(|c| [c[0], c[1], c[2], c[3]].map(f32::from))
                .collect()
        } else {
            bytemuck::pod_collect_to_vec(&bytes)
        };
        Frame {
            rgba,
            depth: depth.map_or_else(Vec::new, |(buffer, row)| {
                map(self, &buffer, row, 4)
                    .chunks_exact(4)
                    .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                    .collect()
            }),
        }
    }

    fn vertices(&self, quads: &[Quad]) -> wgpu::Buffer {
        let mut data: Vec<f32> = Vec::new();
        for Quad(c, rgb) in quads {
            for i in [0, 1, 2, 0, 2, 3] {
                data.extend_from_slice(&self.kind.world(c[i]).to_array());
                data.extend_from_slice(rgb);
            }
        }
        data.resize(data.len().max(6), 0.0);
        wgpu::util::DeviceExt::create_buffer_init(
            &self.device,
            &wgpu::util::BufferInitDescriptor {
                label: None,
                contents: bytemuck::cast_slice(&data),
                usage: wgpu::BufferUsages::VERTEX,
            },
        )
    }

    /// The pixel coordinates (x right, y down, 0 at the target's corner) of world point
    /// `p` in this host's world.
    pub fn pixel_of(&self, p: Vec3) -> glam::Vec2 {
        let clip = self.clip_from_world * p.extend(1.0);
        let ndc = clip.truncate().truncate() / clip.w;
        let size = glam::vec2(SIZE.0 as f32, SIZE.1 as f32);
        glam::vec2(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5) * size
    }

    /// The view-space distance in front of the camera of (y-up) point `p`.
    pub fn distance_of(&self, eye: Vec3, target: Vec3, p: Vec3) -> f64 {
        let forward = (target - eye).normalize().as_dvec3();
        (p - eye).as_dvec3().dot(forward)
    }

    /// The view-space distance of a depth-buffer value (the projection's inverse).
    pub fn distance_at_depth(&self, depth: f32) -> f64 {
        let p = self.proj.as_dmat4().inverse() * glam::DVec4::new(0.0, 0.0, f64::from(depth), 1.0);
        -p.z / p.w
    }
}

/// A target of the test size: `format`, `samples`, copyable when single-sample; a depth
/// target is sampleable (unless the kind makes it transient).
fn target_texture(
    device: &wgpu::Device,
    kind: &HostKind,
    format: wgpu::TextureFormat,
    samples: u32,
) -> wgpu::Texture {
    let mut usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
    if samples == 1 && (format == kind.color || format == DEPTH) {
        usage |= wgpu::TextureUsages::COPY_SRC;
    }
    if format.has_depth_aspect() {
        usage = if kind.transient_depth {
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TRANSIENT_ATTACHMENT
        } else {
            usage | wgpu::TextureUsages::TEXTURE_BINDING
        };
    }
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some("test host target"),
        size: wgpu::Extent3d {
            width: SIZE.0,
            height: SIZE.1,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: samples,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

/// The host's opaque pipeline for `kind`'s formats, samples and depth direction.
fn quad_pipeline(device: &wgpu::Device, kind: &HostKind) -> wgpu::RenderPipeline {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("test host"),
        source: wgpu::ShaderSource::Wgsl(HOST_WGSL.into()),
    });
    let attributes = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3];
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("test host quads"),
        layout: None,
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[Some(wgpu::VertexBufferLayout {
                array_stride: 24,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &attributes,
            })],
        },
        primitive: Default::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: kind.depth,
            depth_write_enabled: Some(true),
            depth_compare: Some(if kind.reversed_z {
                wgpu::CompareFunction::Greater
            } else {
                wgpu::CompareFunction::Less
            }),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: wgpu::MultisampleState {
            count: kind.samples,
            ..Default::default()
        },
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs"),
            compilation_options: Default::default(),
            targets: &[Some(kind.color.into())],
        }),
        multiview_mask: None,
        cache: None,
    })
}

fn read_texture(
    host: &Host,
    enc: &mut wgpu::CommandEncoder,
    texture: &wgpu::Texture,
    texel: u32,
) -> (wgpu::Buffer, u32) {
    let row = (SIZE.0 * texel).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
    let buffer = host.device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: u64::from(row * SIZE.1),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    enc.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: None,
            },
        },
        texture.size(),
    );
    (buffer, row)
}

pub fn map(host: &Host, buffer: &wgpu::Buffer, row: u32, texel: u32) -> Vec<u8> {
    buffer
        .slice(..)
        .map_async(wgpu::MapMode::Read, |r| r.expect("map"));
    host.device
        .poll(wgpu::PollType::wait_indefinitely())
        .expect("poll");
    let bytes = buffer.slice(..).get_mapped_range().expect("mapped");
    let mut out = Vec::new();
    for y in 0..SIZE.1 as usize {
        out.extend_from_slice(&bytes[y * row as usize..][..(SIZE.0 * texel) as usize]);
    }
    out
}
