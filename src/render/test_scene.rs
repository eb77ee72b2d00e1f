//! The editor's test scene (`shaders/test_scene.wgsl`): the ground and a few props — a box
//! and a step — drawn opaque into the HDR target and into a depth buffer of their own,
//! which the player is then handed as a host's depth (depth collision, soft edges,
//! occlusion). The props are the viewport's, not the preset's.

use crate::gpu::commands::CountedRender;
use wgpu::util::DeviceExt;

use crate::gpu::GpuContext;
use crate::render::{Camera, HDR_FORMAT};
use crate::shaders::{ShaderError, ShaderLibrary, create_checked};

/// The depth format of the scene's depth buffer.
pub const SCENE_DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// An axis-aligned box of the test scene: its lower and upper corners (m).
pub type Prop = ([f32; 3], [f32; 3]);

/// The props: the ground's slab (its top at y = 0), a 0.6 m box on −x and a 0.25 m step
/// on +x, where the spark fountain's side jets come down.
pub const PROPS: [Prop; 3] = [
    ([-12.0, -0.1, -12.0], [12.0, 0.0, 12.0]),
    ([-1.9, 0.0, -0.3], [-1.3, 0.6, 0.3]),
    ([1.0, 0.0, -0.8], [3.0, 0.25, 0.8]),
];

/// Light strength of the props (HDR: grey enough beside the fire's light).
const LIGHT: f32 = 0.35;

/// The pipeline, the props' triangles and the depth buffer (kept while its size holds).
pub struct TestScene {
    pipeline: wgpu::RenderPipeline,
    uniform: wgpu::Buffer,
    group: wgpu::BindGroup,
    vertices: wgpu::Buffer,
    count: u32,
    depth: Option<((u32, u32), wgpu::TextureView)>,
}

/// `Scene` in `shaders/test_scene.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct SceneUniform {
    clip_from_world: [[f32; 4]; 4],
    sun: [f32; 4],
}

impl TestScene {
    /// Builds the pipeline from `lib` and uploads the props.
    pub fn new(ctx: &GpuContext, lib: &ShaderLibrary) -> Result<Self, ShaderError> {
        let device = &ctx.device;
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("TestScene::uniform"),
            size: size_of::<SceneUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let pipeline = pipeline(ctx, lib)?;
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("TestScene::group"),
            layout: &pipeline.get_bind_group_layout(0),
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: uniform.as_entire_binding(),
            }],
        });
        let triangles: Vec<[f32; 6]> = PROPS.iter().flat_map(box_triangles).collect();
        let vertices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("TestScene::vertices"),
            contents: bytemuck::cast_slice(&triangles),
            usage: wgpu::BufferUsages::VERTEX,
        });
        Ok(Self {
            pipeline,
            uniform,
            group,
            vertices,
            count: triangles.len() as u32,
            depth: None,
        })
    }

    /// Draws the props seen by `camera` into `hdr` (kept: drawn over what it holds) and
    /// the scene's depth (cleared); returns the depth for the player.
    pub fn record(
        &mut self,
        ctx: &GpuContext,
        enc: &mut wgpu::CommandEncoder,
        hdr: &wgpu::TextureView,
        camera: &Camera,
    ) -> wgpu::TextureView {
        let size = camera.size_px();
        let depth = match self.depth.take() {
            Some((s, view)) if s == size => view,
            _ => crate::gpu::texture_2d(
                &ctx.device,
                "TestScene::depth",
                size,
                1,
                SCENE_DEPTH_FORMAT,
                wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            )
            .create_view(&Default::default()),
        };
        let sun = glam::Vec3::new(0.4, 1.0, 0.6).normalize();
        let uniform = SceneUniform {
            clip_from_world: camera.clip_from_world_mat4().to_cols_array_2d(),
            sun: sun.extend(LIGHT).to_array(),
        };
        ctx.queue
            .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("TestScene"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: hdr,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            ..Default::default()
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.group, &[]);
        pass.set_vertex_buffer(0, self.vertices.slice(..));
        pass.counted_draw(0..self.count, 0..1);
        drop(pass);
        self.depth = Some((size, depth.clone()));
        depth
    }
}

/// The pipeline: opaque, depth-tested and written, no culling.
fn pipeline(ctx: &GpuContext, lib: &ShaderLibrary) -> Result<wgpu::RenderPipeline, ShaderError> {
    let composed = lib.compose("test_scene.wgsl")?;
    create_checked(&ctx.device, &composed, lib, |module| {
        crate::gpu::render_pipeline(
            ctx,
            crate::gpu::PipelineParts {
                label: "TestScene",
                layout: None,
                module,
                entries: ("vs_main", "fs_main"),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: 24,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3],
                })],
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: SCENE_DEPTH_FORMAT,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::Less),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: Default::default(),
                targets: &[Some(HDR_FORMAT.into())],
            },
        )
    })
}

/// A box's 12 triangles: position and outward normal per vertex.
fn box_triangles((lo, hi): &Prop) -> Vec<[f32; 6]> {
    let corner = |x: usize, y: usize, z: usize| {
        [
            if x == 0 { lo[0] } else { hi[0] },
            if y == 0 { lo[1] } else { hi[1] },
            if z == 0 { lo[2] } else { hi[2] },
        ]
    };
    let mut out = Vec::with_capacity(36);
    for axis in 0..3 {
        for side in 0..2 {
            let mut normal = [0.0; 3];
            normal[axis] = if side == 0 { -1.0 } else { 1.0 };
            // The face's four corners: the axis fixed at `side`, the other two varying.
            let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
            let at = |i: usize, j: usize| {
                let mut c = [0; 3];
                c[axis] = side;
                c[a] = i;
                c[b] = j;
                corner(c[0], c[1], c[2])
            };
            for (i, j) in [(0, 0), (1, 0), (1, 1), (0, 0), (1, 1), (0, 1)] {
                let p = at(i, j);
                out.push([p[0], p[1], p[2], normal[0], normal[1], normal[2]]);
            }
        }
    }
    out
}
