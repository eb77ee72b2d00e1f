//! The host's own rendering, which ignis knows nothing about: lit boxes into an HDR
//! target with a depth buffer, an ACES tonemap to the window, and a screenshot.

use glam::{Mat4, Vec3, vec3};

pub const HDR: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
pub const DEPTH: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

pub struct Scene {
    lit: wgpu::RenderPipeline,
    tonemap: wgpu::RenderPipeline,
    vertices: (wgpu::Buffer, u32),
    uniforms: (wgpu::Buffer, wgpu::BindGroup),
    pub hdr: wgpu::TextureView,
    /// The depth the opaque pass writes and the particles test against and sample.
    pub depth: wgpu::TextureView,
    tone_group: wgpu::BindGroup,
}

impl Scene {
    /// A ground, two boxes and a post under each of `posts`.
    pub fn new(
        device: &wgpu::Device,
        format: wgpu::TextureFormat,
        size: (u32, u32),
        posts: &[Vec3],
    ) -> Self {
        let mut mesh = cuboid(
            vec3(0.0, -0.05, 0.0),
            vec3(8.0, 0.05, 8.0),
            [0.35, 0.33, 0.3],
        );
        mesh.extend(cuboid(
            vec3(-1.2, 0.3, 1.1),
            Vec3::splat(0.3),
            [0.6, 0.45, 0.3],
        ));
        mesh.extend(cuboid(
            vec3(1.4, 0.4, 0.6),
            vec3(0.4, 0.4, 0.25),
            [0.5, 0.5, 0.55],
        ));
        for post in posts {
            mesh.extend(cuboid(
                *post + Vec3::Y * 0.45,
                vec3(0.04, 0.45, 0.04),
                [0.3, 0.2, 0.12],
            ));
        }
        let vertices = wgpu::util::DeviceExt::create_buffer_init(
            device,
            &wgpu::util::BufferInitDescriptor {
                label: Some("host vertices"),
                contents: bytemuck::cast_slice(&mesh),
                usage: wgpu::BufferUsages::VERTEX,
            },
        );
        let shader = device.create_shader_module(wgpu::include_wgsl!("scene.wgsl"));
        let lit = pipeline(device, &shader, ("vs_lit", "fs_lit"), HDR, true);
        let tonemap = pipeline(device, &shader, ("vs_full", "fs_tonemap"), format, false);
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("host uniforms"),
            size: 80,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let group = bind(
            device,
            &lit.get_bind_group_layout(0),
            buffer.as_entire_binding(),
        );
        let (hdr, depth, tone_group) = targets(device, &tonemap, size);
        let count = mesh.len() as u32;
        Self {
            lit,
            tonemap,
            vertices: (vertices, count),
            uniforms: (buffer, group),
            hdr,
            depth,
            tone_group,
        }
    }

    pub fn resize(&mut self, device: &wgpu::Device, size: (u32, u32)) {
        (self.hdr, self.depth, self.tone_group) = targets(device, &self.tonemap, size);
    }

    /// The opaque pass: clears, draws the boxes lit by the moon and a warm light at
    /// `fire` (xyz, w: strength), writes depth.
    pub fn draw_opaque(
        &self,
        queue: &wgpu::Queue,
        enc: &mut wgpu::CommandEncoder,
        clip_from_world: Mat4,
        fire: [f32; 4],
    ) {
        let uniforms = [clip_from_world.to_cols_array().as_slice(), &fire].concat();
        queue.write_buffer(&self.uniforms.0, 0, bytemuck::cast_slice(&uniforms));
        let mut pass = self.pass(enc);
        pass.set_pipeline(&self.lit);
        pass.set_bind_group(0, &self.uniforms.1, &[]);
        pass.set_vertex_buffer(0, self.vertices.0.slice(..));
        pass.draw(0..self.vertices.1, 0..1);
    }

    /// The opaque pass over the HDR image and the depth: clears both, writes depth and
    /// stores it (the particles sample it after).
    fn pass<'a>(&'a self, enc: &'a mut wgpu::CommandEncoder) -> wgpu::RenderPass<'a> {
        let sky = wgpu::Color {
            r: 0.004,
            g: 0.006,
            b: 0.015,
            a: 1.0,
        };
        enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            color_attachments: &[Some(attachment(&self.hdr, wgpu::LoadOp::Clear(sky)))],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            ..Default::default()
        })
    }

    /// The host's tonemap from the HDR image to `target`.
    pub fn tonemap(&self, enc: &mut wgpu::CommandEncoder, target: &wgpu::TextureView) {
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            color_attachments: &[Some(attachment(
                target,
                wgpu::LoadOp::Clear(wgpu::Color::BLACK),
            ))],
            ..Default::default()
        });
        pass.set_pipeline(&self.tonemap);
        pass.set_bind_group(0, &self.tone_group, &[]);
        pass.draw(0..3, 0..1);
    }
}

/// The HDR colour and depth targets (the depth also sampled: soft edges) and the
/// tonemap's bind group over the colour.
fn targets(
    device: &wgpu::Device,
    tonemap: &wgpu::RenderPipeline,
    (width, height): (u32, u32),
) -> (wgpu::TextureView, wgpu::TextureView, wgpu::BindGroup) {
    let make = |format| {
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        let size = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        };
        let desc = wgpu::TextureDescriptor {
            label: None,
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        };
        device
            .create_texture(&desc)
            .create_view(&Default::default())
    };
    let hdr = make(HDR);
    let group = bind(
        device,
        &tonemap.get_bind_group_layout(0),
        wgpu::BindingResource::TextureView(&hdr),
    );
    (hdr, make(DEPTH), group)
}

fn bind(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    resource: wgpu::BindingResource,
) -> wgpu::BindGroup {
    let entries = [wgpu::BindGroupEntry {
        binding: 0,
        resource,
    }];
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout,
        entries: &entries,
    })
}

fn attachment(
    view: &wgpu::TextureView,
    load: wgpu::LoadOp<wgpu::Color>,
) -> wgpu::RenderPassColorAttachment<'_> {
    wgpu::RenderPassColorAttachment {
        view,
        depth_slice: None,
        resolve_target: None,
        ops: wgpu::Operations {
            load,
            store: wgpu::StoreOp::Store,
        },
    }
}

fn pipeline(
    device: &wgpu::Device,
    module: &wgpu::ShaderModule,
    (vs, fs): (&str, &str),
    format: wgpu::TextureFormat,
    lit: bool,
) -> wgpu::RenderPipeline {
    let attributes = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x3];
    let buffers = [Some(wgpu::VertexBufferLayout {
        array_stride: 36,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &attributes,
    })];
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(vs),
        layout: None,
        vertex: wgpu::VertexState {
            module,
            entry_point: Some(vs),
            compilation_options: Default::default(),
            buffers: if lit { &buffers } else { &[] },
        },
        primitive: wgpu::PrimitiveState {
            cull_mode: lit.then_some(wgpu::Face::Back),
            ..Default::default()
        },
        depth_stencil: lit.then(|| wgpu::DepthStencilState {
            format: DEPTH,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Less),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some(fs),
            compilation_options: Default::default(),
            targets: &[Some(format.into())],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// A box: 36 vertices of (position, normal, colour), counter-clockwise outside.
fn cuboid(center: Vec3, half: Vec3, color: [f32; 3]) -> Vec<[f32; 9]> {
    let mut out = Vec::with_capacity(36);
    for axis in [Vec3::X, Vec3::Y, Vec3::Z] {
        for n in [axis, -axis] {
            let (u, v) = n.any_orthonormal_pair();
            for (a, b) in [
                (-1.0, -1.0),
                (1.0, -1.0),
                (1.0, 1.0),
                (-1.0, -1.0),
                (1.0, 1.0),
                (-1.0, 1.0),
            ] {
                let p = center + half * (n + u * a + v * b);
                out.push([p.x, p.y, p.z, n.x, n.y, n.z, color[0], color[1], color[2]]);
            }
        }
    }
    out
}

/// Copies the window's frame into a buffer (rows padded to 256 bytes).
pub fn read_back(
    device: &wgpu::Device,
    enc: &mut wgpu::CommandEncoder,
    texture: &wgpu::Texture,
) -> (wgpu::Buffer, u32) {
    let row = (texture.width() * 4).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: u64::from(row * texture.height()),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let layout = wgpu::TexelCopyBufferLayout {
        offset: 0,
        bytes_per_row: Some(row),
        rows_per_image: None,
    };
    enc.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout,
        },
        texture.size(),
    );
    (buffer, row)
}

/// Waits for `read_back`'s copy and writes it as an RGB PNG.
pub fn save_png(
    device: &wgpu::Device,
    (buffer, row): (wgpu::Buffer, u32),
    (w, h): (u32, u32),
    format: wgpu::TextureFormat,
    path: &str,
) -> Result<(), Box<dyn std::error::Error>> {
    buffer.slice(..).map_async(wgpu::MapMode::Read, |_| {});
    device.poll(wgpu::PollType::wait_indefinitely())?;
    let bytes = buffer.slice(..).get_mapped_range()?;
    let bgra = matches!(
        format,
        wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb
    );
    let mut rgb = Vec::with_capacity((w * h * 3) as usize);
    for y in 0..h as usize {
        for px in bytes[y * row as usize..][..w as usize * 4].chunks_exact(4) {
            rgb.extend_from_slice(&if bgra {
                [px[2], px[1], px[0]]
            } else {
                [px[0], px[1], px[2]]
            });
        }
    }
    image::save_buffer(path, &rgb, w, h, image::ExtendedColorType::Rgb8)?;
    Ok(())
}
