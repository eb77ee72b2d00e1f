//! The runtime as a host uses it: a test host with its own colour and depth targets and
//! its own opaque geometry, and `ignis::Player`s drawing inside its render pass.
//! Occlusion by the host's depth, soft edges against it, instances that add up and stay
//! independent, and a runtime-only build without the editor's crates.

mod common;

use glam::{DVec3, Mat4, Vec3, vec3};
use ignis::effect::{BlendMode, ColorStop, Effect, Sprite};
use ignis::{Camera, Player, PlayerSettings};

const SIZE: (u32, u32) = (160, 120);
// f32 light: sums of many additive particles are then exact to ~1e-6, not to f16's
// rounding at every blend (needs FLOAT32_BLENDABLE: lavapipe and NVIDIA have it).
const COLOR: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
const DEPTH: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// A flat-coloured quad of the host's scene: four corners (a fan) and a colour.
struct Quad([Vec3; 4], [f32; 3]);

/// The test's host program: an HDR colour target, a depth buffer it writes and the
/// particles sample, and a pipeline for its opaque quads.
struct Host {
    device: wgpu::Device,
    queue: wgpu::Queue,
    color: wgpu::Texture,
    depth: wgpu::Texture,
    quads: wgpu::RenderPipeline,
    camera: Camera,
    clip_from_world: Mat4,
}

/// What a host frame read back: linear RGBA per pixel and the depth buffer.
struct Frame {
    rgba: Vec<[f32; 4]>,
    depth: Vec<f32>,
}

/// The host's own device: the default adapter, with f32 blending.
fn host_device() -> (wgpu::Device, wgpu::Queue) {
    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = pollster::block_on(wgpu::util::initialize_adapter_from_env_or_default(
        &instance, None,
    ))
    .expect("GPU tests need an adapter (CI installs mesa-vulkan-drivers)");
    // The storage buffers the tile rasteriser binds (a device with the default 8 draws
    // every quad as a billboard).
    let limits = wgpu::Limits {
        max_storage_buffers_per_shader_stage: ignis::render::tiles::STORAGE_BUFFERS_NEEDED,
        ..Default::default()
    };
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
    fn new(eye: Vec3, target: Vec3) -> Self {
        let (device, queue) = host_device();
        let texture = |format, usage| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some("test host target"),
                size: wgpu::Extent3d {
                    width: SIZE.0,
                    height: SIZE.1,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: usage
                    | wgpu::TextureUsages::RENDER_ATTACHMENT
                    | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            })
        };
        let color = texture(COLOR, wgpu::TextureUsages::empty());
        let depth = texture(DEPTH, wgpu::TextureUsages::TEXTURE_BINDING);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("test host"),
            source: wgpu::ShaderSource::Wgsl(HOST_WGSL.into()),
        });
        let attributes = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3];
        let quads = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
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
                format: DEPTH,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs"),
                compilation_options: Default::default(),
                targets: &[Some(COLOR.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        let view = glam::camera::rh::view::look_at_mat4(eye, target, Vec3::Y);
        let proj = glam::camera::rh::proj::directx::perspective(
            0.9,
            SIZE.0 as f32 / SIZE.1 as f32,
            0.05,
            50.0,
        );
        Self {
            device,
            queue,
            color,
            depth,
            quads,
            camera: Camera::new(view, proj, SIZE),
            clip_from_world: proj * view,
        }
    }

    fn settings(&self) -> PlayerSettings {
        PlayerSettings {
            depth_format: Some(DEPTH),
            asset_dir: Some(concat!(env!("CARGO_MANIFEST_DIR"), "/presets").into()),
            ..PlayerSettings::new(COLOR)
        }
    }

    fn player(&self, effect: &Effect) -> Player {
        Player::new(&self.device, &self.queue, effect, self.settings()).expect("player")
    }

    /// One host frame: clear to `background`, draw `quads` (writing depth), then every
    /// player's compute work and draw — with the depth handed over for soft edges when
    /// `soft` — and read colour and depth back.
    fn frame(
        &self,
        background: [f64; 3],
        quads: &[Quad],
        players: &mut [&mut Player],
        soft: bool,
    ) -> Frame {
        let color = self.color.create_view(&Default::default());
        let depth = self.depth.create_view(&Default::default());
        let mut enc = self.device.create_command_encoder(&Default::default());
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
        {
            let [r, g, b] = background;
            let clear = wgpu::Color { r, g, b, a: 1.0 };
            let mut pass = begin(&mut enc, &color, &depth, Some(clear));
            pass.set_pipeline(&self.quads);
            pass.set_bind_group(0, &group, &[]);
            pass.set_vertex_buffer(0, vertices.slice(..));
            pass.draw(0..quads.len() as u32 * 6, 0..1);
        }
        for p in players.iter_mut() {
            p.record(&mut enc, &self.camera, soft.then_some(&depth));
        }
        {
            let mut pass = begin(&mut enc, &color, &depth, None);
            for p in players.iter() {
                p.draw(&mut pass);
            }
        }
        let rgba = read_texture(self, &mut enc, &self.color, 16);
        let depth = read_texture(self, &mut enc, &self.depth, 4);
        self.queue.submit([enc.finish()]);
        Frame {
            rgba: bytemuck::pod_collect_to_vec(&map(self, &rgba.0, rgba.1, 16)),
            depth: map(self, &depth.0, depth.1, 4)
                .chunks_exact(4)
                .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                .collect(),
        }
    }

    fn vertices(&self, quads: &[Quad]) -> wgpu::Buffer {
        let mut data: Vec<f32> = Vec::new();
        for Quad(c, rgb) in quads {
            for i in [0, 1, 2, 0, 2, 3] {
                data.extend_from_slice(&c[i].to_array());
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

    /// The view-space distance in front of the camera of world point `p`.
    fn distance_of(&self, eye: Vec3, target: Vec3, p: Vec3) -> f64 {
        let forward = (target - eye).normalize().as_dvec3();
        (p - eye).as_dvec3().dot(forward)
    }

    /// The view-space distance of a depth-buffer value (the projection's inverse).
    fn distance_at_depth(&self, depth: f32) -> f64 {
        let proj = glam::camera::rh::proj::directx::perspective(
            0.9,
            SIZE.0 as f32 / SIZE.1 as f32,
            0.05,
            50.0,
        );
        let p = proj.as_dmat4().inverse() * glam::DVec4::new(0.0, 0.0, f64::from(depth), 1.0);
        -p.z / p.w
    }
}

fn begin<'a>(
    enc: &'a mut wgpu::CommandEncoder,
    color: &'a wgpu::TextureView,
    depth: &'a wgpu::TextureView,
    clear: Option<wgpu::Color>,
) -> wgpu::RenderPass<'a> {
    enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("test host pass"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: color,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: clear.map_or(wgpu::LoadOp::Load, wgpu::LoadOp::Clear),
                store: wgpu::StoreOp::Store,
            },
        })],
        // The opaque pass clears and writes depth; the particles' pass only reads it.
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: depth,
            depth_ops: clear.map(|_| wgpu::Operations {
                load: wgpu::LoadOp::Clear(1.0),
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        }),
        ..Default::default()
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

fn map(host: &Host, buffer: &wgpu::Buffer, row: u32, texel: u32) -> Vec<u8> {
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

fn preset(name: &str) -> Effect {
    let path = format!("{}/presets/{name}.ron", env!("CARGO_MANIFEST_DIR"));
    ignis::preset::load(path.as_ref()).expect("shipped preset")
}

/// The campfire without events or trails (its smoke at 90 a second of its own), so that
/// its instances batch.
fn batchable_campfire() -> Effect {
    let mut effect = preset("campfire");
    for e in &mut effect.emitters {
        e.events.clear();
        e.look.trail = None;
    }
    effect.emitters[0].spawn_rate_per_sec = ignis::effect::Param::Constant(90.0);
    assert!(ignis::sim::batch::batchable(&effect));
    effect
}

fn advance(players: &mut [&mut Player], host: &Host, frames: u32) {
    for _ in 0..frames {
        let mut enc = host.device.create_command_encoder(&Default::default());
        for p in players.iter_mut() {
            p.advance(1.0 / 60.0);
            p.record(&mut enc, &host.camera, None);
        }
        host.queue.submit([enc.finish()]);
    }
}

fn differs(a: [f32; 4], b: [f32; 4], by: f32) -> bool {
    (0..3).any(|c| (a[c] - b[c]).abs() > by)
}

#[test]
fn host_geometry_in_front_hides_the_fire_exactly() {
    hides_the_fire_exactly(&preset("campfire"), false);
}

/// The compute splat (small additive particles) tests the host's depth at every pixel it
/// lights; without the depth view the player draws billboards, which the pass tests.
#[test]
fn host_geometry_hides_splatted_particles_exactly() {
    let mut effect = preset("campfire");
    for e in &mut effect.emitters {
        if e.look.blend == BlendMode::Additive {
            e.look.draw_path = ignis::effect::DrawPath::Splat;
        }
    }
    hides_the_fire_exactly(&effect, true);
    hides_the_fire_exactly(&effect, false);
}

/// The tile rasteriser tests the host's depth at every pixel it shades, as the splat.
#[test]
fn host_geometry_hides_tiled_particles_exactly() {
    let mut effect = preset("campfire");
    for e in &mut effect.emitters {
        e.look.draw_path = ignis::effect::DrawPath::Tiles;
    }
    hides_the_fire_exactly(&effect, true);
    hides_the_fire_exactly(&effect, false);
}

/// An opaque wall between the camera and the left half of `effect`: the pixels behind it
/// are exactly the host's, and fire shows beside it. `depth`: the host hands its depth
/// over.
fn hides_the_fire_exactly(effect: &Effect, depth: bool) {
    let (eye, target) = (vec3(0.0, 0.7, 3.0), vec3(0.0, 0.5, 0.0));
    let host = Host::new(eye, target);
    let mut fire = host.player(effect);
    fire.add_instance(Mat4::IDENTITY, 3).expect("instance");
    advance(&mut [&mut fire], &host, 90);
    let wall = Quad(
        [
            vec3(-3.0, -1.0, 1.2),
            vec3(0.0, -1.0, 1.2),
            vec3(0.0, 3.0, 1.2),
            vec3(-3.0, 3.0, 1.2),
        ],
        [0.2, 0.3, 0.4],
    );
    let bg = [0.05, 0.04, 0.03];
    let host_only = host.frame(bg, std::slice::from_ref(&wall), &mut [], depth);
    let with_fire = host.frame(bg, std::slice::from_ref(&wall), &mut [&mut fire], depth);
    let no_wall = host.frame(bg, &[], &mut [&mut fire], depth);
    let is_wall = |p: [f32; 4]| !differs(p, [0.2, 0.3, 0.4, 1.0], 1e-3);
    let (mut wall_px, mut fire_behind, mut fire_beside) = (0, 0, 0);
    for i in 0..host_only.rgba.len() {
        if is_wall(host_only.rgba[i]) {
            wall_px += 1;
            assert_eq!(
                with_fire.rgba[i], host_only.rgba[i],
                "pixel {i} behind the wall is not exactly the host's (depth view: {depth})"
            );
            fire_behind += usize::from(differs(no_wall.rgba[i], host_only.rgba[i], 0.05));
        } else {
            fire_beside += usize::from(differs(with_fire.rgba[i], host_only.rgba[i], 0.05));
        }
    }
    assert!(wall_px > 4000, "the wall covers {wall_px} pixels");
    assert!(
        fire_behind > 150,
        "only {fire_behind} wall pixels would show fire without it"
    );
    assert!(
        fire_beside > 150,
        "only {fire_beside} pixels beside the wall hold fire"
    );
    let splatted = fire.draw_items().iter().any(|d| d.splat);
    let wants_splat = effect
        .emitters
        .iter()
        .any(|e| e.look.draw_path == ignis::effect::DrawPath::Splat);
    assert_eq!(splatted, wants_splat && depth, "the splat ran");
    let tiled = fire.draw_items().iter().any(|d| d.tiles);
    let wants_tiles = effect
        .emitters
        .iter()
        .any(|e| e.look.draw_path == ignis::effect::DrawPath::Tiles);
    assert_eq!(tiled, wants_tiles && depth, "the tiles ran");
}

/// One still, additive disc at (0, 0.2, 0), 1 m wide: its lower part crosses the ground.
fn still_disc(soft_m: f32) -> Effect {
    let mut e = common::plain_emitter();
    e.capacity = 16;
    e.spawn_rate_per_sec = ignis::effect::Param::Constant(4.0);
    e.lifetime_secs = ignis::effect::Range::new(100.0, 100.0);
    e.transform.position_m = [0.0, 0.2, 0.0];
    e.look.sprite = Sprite::SoftDisc;
    e.look.flipbook = None;
    e.look.streak = None;
    e.look.size_m = ignis::effect::Param::Constant(1.0);
    e.look.rotation_random_deg = 0.0;
    e.look.spin_deg_per_s = ignis::effect::Param::Constant(0.0);
    e.look.blend = BlendMode::Additive;
    e.look.intensity = 1.0;
    e.look.color_over_life = vec![
        ColorStop {
            t: 0.0,
            rgba: [0.25, 0.2, 0.15, 1.0],
        },
        ColorStop {
            t: 1.0,
            rgba: [0.25, 0.2, 0.15, 1.0],
        },
    ];
    e.look.soft_ground_m = soft_m;
    common::bare_effect(e)
}

#[test]
fn soft_edges_fade_over_the_soft_distance_from_the_host_depth() {
    soft_edges_fade(ignis::effect::DrawPath::Billboard);
    soft_edges_fade(ignis::effect::DrawPath::Tiles);
}

/// A disc crossing the host's ground, drawn by `path`: it fades as the depth says.
fn soft_edges_fade(path: ignis::effect::DrawPath) {
    let (eye, target) = (vec3(0.0, 0.6, 2.5), vec3(0.0, 0.15, 0.0));
    let host = Host::new(eye, target);
    let soft_m = 0.4;
    let disc = |soft_m| {
        let mut e = still_disc(soft_m);
        e.emitters[0].look.draw_path = path;
        e
    };
    let mut hard = host.player(&disc(0.0));
    let mut soft = host.player(&disc(soft_m));
    hard.add_instance(Mat4::IDENTITY, 1).expect("instance");
    soft.add_instance(Mat4::IDENTITY, 1).expect("instance");
    advance(&mut [&mut hard, &mut soft], &host, 60);
    // A black ground at y = 0 that writes depth.
    let ground = Quad(
        [
            vec3(-5.0, 0.0, 5.0),
            vec3(5.0, 0.0, 5.0),
            vec3(5.0, 0.0, -5.0),
            vec3(-5.0, 0.0, -5.0),
        ],
        [0.0; 3],
    );
    let a = host.frame(
        [0.0; 3],
        std::slice::from_ref(&ground),
        &mut [&mut hard],
        true,
    );
    let b = host.frame(
        [0.0; 3],
        std::slice::from_ref(&ground),
        &mut [&mut soft],
        true,
    );
    let particle = host.distance_of(eye, target, vec3(0.0, 0.2, 0.0));
    let (mut faded, mut worst) = (0, 0.0f32);
    for i in 0..a.rgba.len() {
        let scene = host.distance_at_depth(a.depth[i]);
        let fade = ((scene - particle) / f64::from(soft_m)).clamp(0.0, 1.0) as f32;
        for c in 0..3 {
            let expected = a.rgba[i][c] * fade;
            let err = (b.rgba[i][c] - expected).abs();
            worst = worst.max(err);
            assert!(
                err <= 1.0 / 255.0,
                "pixel {i} channel {c}: {} where hard × fade = {} × {fade} = {expected}",
                b.rgba[i][c],
                a.rgba[i][c]
            );
        }
        faded += usize::from(a.rgba[i][0] > 0.05 && (0.1..0.9).contains(&fade));
    }
    assert!(faded > 100, "only {faded} lit pixels are within the fade");
    eprintln!("soft edges ({path:?}): {faded} pixels in the fade, worst error {worst:.5}");
}

/// The torch's additive layers (its smoke is alpha-blended: not a sum).
fn additive_torch() -> Effect {
    let mut torch = preset("torch");
    torch
        .emitters
        .retain(|e| e.look.blend == BlendMode::Additive);
    torch.drop_dangling_events();
    torch
}

#[test]
fn instances_add_up_and_stay_independent() {
    // Batched instances (full state), and one simulation per instance (tiny state).
    let mut tiny = additive_torch();
    for e in &mut tiny.emitters {
        e.tiny_state = true;
    }
    for effect in [additive_torch(), tiny] {
        instances_add_up(&effect);
    }
}

fn instances_add_up(effect: &Effect) {
    let (eye, target) = (vec3(0.0, 1.3, 3.0), vec3(0.0, 1.0, 0.0));
    let host = Host::new(eye, target);
    // One behind the other, so that their light overlaps on screen.
    let left = Mat4::from_translation(vec3(-0.02, 0.0, 0.0));
    let right =
        Mat4::from_rotation_translation(glam::Quat::from_rotation_y(0.5), vec3(0.03, 0.05, -0.4));
    let mut both = host.player(effect);
    let mut only_a = host.player(effect);
    let mut only_b = host.player(effect);
    let a = both.add_instance(left, 1).expect("instance");
    let b = both.add_instance(right, 2).expect("instance");
    let a_alone = only_a.add_instance(left, 1).expect("instance");
    only_b.add_instance(right, 2).expect("instance");
    advance(&mut [&mut both, &mut only_a, &mut only_b], &host, 60);
    let sum = host.frame([0.0; 3], &[], &mut [&mut both], false);
    let fa = host.frame([0.0; 3], &[], &mut [&mut only_a], false);
    let fb = host.frame([0.0; 3], &[], &mut [&mut only_b], false);
    let (mut lit, mut worst, mut total) = (0, 0.0f32, 0.0f64);
    for i in 0..sum.rgba.len() {
        for c in 0..3 {
            let expected = fa.rgba[i][c] + fb.rgba[i][c];
            let err = (sum.rgba[i][c] - expected).abs();
            worst = worst.max(err);
            total += f64::from(err);
        }
        lit += usize::from(fa.rgba[i][0] > 0.05 && fb.rgba[i][0] > 0.05);
    }
    let mean = total / (sum.rgba.len() * 3) as f64;
    eprintln!("instances: {lit} pixels lit by both, error mean {mean:.6} max {worst:.5}");
    assert!(lit > 50, "the instances overlap on only {lit} pixels");
    assert!(
        mean <= 1.0 / 255.0 && worst <= 1.0 / 255.0,
        "mean {mean}, max {worst}"
    );

    // Removing an instance leaves the other's particles bit-identical to a player that
    // never had it.
    assert!(both.remove_instance(b));
    assert!(!both.remove_instance(b), "a removed handle is refused");
    let c = both.add_instance(right, 9).expect("instance");
    assert_ne!(b, c);
    assert!(
        !both.set_transform(b, left),
        "the old handle does not reach the new instance"
    );
    advance(&mut [&mut both, &mut only_a], &host, 45);
    for e in 0..effect.emitters.len() {
        let kept = both.particles(a, e).expect("read");
        let alone = only_a.particles(a_alone, e).expect("read");
        assert!(
            kept.iter().any(|p| p.is_alive()),
            "emitter {e} has particles"
        );
        assert_eq!(
            bytemuck::cast_slice::<_, u8>(&kept),
            bytemuck::cast_slice::<_, u8>(&alone),
            "emitter {e} of the kept instance differs from the instance alone"
        );
    }
    assert_eq!(both.instance_count(), 2);
}

#[test]
fn a_batched_instance_steps_exactly_as_a_simulation_of_its_own() {
    let (eye, target) = (vec3(0.0, 1.0, 4.0), vec3(0.0, 0.5, 0.0));
    let host = Host::new(eye, target);
    let effect = batchable_campfire();
    let mut player = host.player(&effect);
    let places = [
        Mat4::from_translation(vec3(-1.0, 0.0, 0.0)),
        Mat4::from_rotation_translation(glam::Quat::from_rotation_y(1.0), vec3(1.0, 0.2, -0.5)),
        Mat4::from_translation(vec3(0.0, 0.0, -2.0)),
    ];
    let ids: Vec<_> = (0..3)
        .map(|k| {
            player
                .add_instance(places[k], 10 + k as u32)
                .expect("instance")
        })
        .collect();
    // A slot freed and taken again mid-run: the newcomer starts from an empty segment.
    advance(&mut [&mut player], &host, 20);
    assert!(player.remove_instance(ids[1]));
    let late = player.add_instance(places[1], 77).expect("instance");
    let ctx = ignis::gpu::GpuContext::from_device(&host.device, &host.queue);
    // The instance's own simulation, stepped as the player's clock stepped it from frame
    // `from` (a clock's steps per frame depend on its history: it is replayed).
    let own = |id, from: u32, frames: u32| {
        let placed = player.instance_effect(id).expect("instance").clone();
        let mut sim =
            ignis::sim::GpuSim::new(&ctx, ignis::shaders::ShaderLibrary::embedded(), &placed)
                .expect("sim");
        let mut stepper = ignis::sim::Stepper::default();
        for frame in 0..from + frames {
            let plan = stepper.advance(1.0 / 60.0, &placed.time);
            if frame >= from {
                sim.step(&placed, plan.dt_secs, plan.steps).expect("step");
            }
        }
        sim
    };
    let first = own(ids[0], 0, 50);
    let newcomer = own(late, 20, 30);
    advance(&mut [&mut player], &host, 30);
    for e in 0..effect.emitters.len() {
        for (id, sim) in [(ids[0], &first), (late, &newcomer)] {
            let batched = player.particles(id, e).expect("read");
            let alone = sim.read_particles(e).expect("read");
            assert!(
                alone.iter().any(|p| p.is_alive()),
                "emitter {e} has particles"
            );
            let differ: Vec<usize> = (0..alone.len())
                .filter(|&k| bytemuck::bytes_of(&batched[k]) != bytemuck::bytes_of(&alone[k]))
                .collect();
            assert!(
                differ.is_empty(),
                "emitter {e}: {} of {} slots differ from the instance's own simulation, \
                 first {:?}: {:?} vs {:?}",
                differ.len(),
                alone.len(),
                differ.first(),
                differ.first().map(|&k| batched[k]),
                differ.first().map(|&k| alone[k]),
            );
        }
    }
}

#[test]
fn large_pools_batch_as_many_instances_as_a_binding_holds() {
    // 2^20 slots of 32 bytes per instance: the test host's device has wgpu's default
    // limits (128 MiB per storage binding), which hold four, and a batch allocates at most
    // 64 MiB of state (an instance's two buffers here): each instance has a batch.
    let host = Host::new(vec3(0.0, 1.0, 4.0), vec3(0.0, 0.5, 0.0));
    let mut effect = still_disc(0.0);
    effect.emitters[0].capacity = 1 << 20;
    let mut player = host.player(&effect);
    let ids: Vec<_> = (0..5)
        .map(|k| player.add_instance(Mat4::from_translation(vec3(k as f32, 0.0, 0.0)), k))
        .collect::<Result<_, _>>()
        .expect("instances");
    // 40 frames: 2/3 s at 4 spawns per second.
    advance(&mut [&mut player], &host, 40);
    for id in ids {
        let particles = player.particles(id, 0).expect("read");
        assert_eq!(particles.len(), 1 << 20);
        assert_eq!(
            particles.iter().filter(|p| p.is_alive()).count(),
            2,
            "{id:?}"
        );
    }
}

#[test]
fn a_moving_instance_spawns_where_it_is_and_keeps_world_motion() {
    let (eye, target) = (vec3(0.0, 1.0, 4.0), vec3(0.0, 0.5, 0.0));
    let host = Host::new(eye, target);
    let mut fire = host.player(&preset("campfire"));
    let id = fire.add_instance(Mat4::IDENTITY, 5).expect("instance");
    advance(&mut [&mut fire], &host, 30);
    let moved = Mat4::from_translation(vec3(2.0, 0.0, 0.0));
    assert!(fire.set_transform(id, moved));
    assert_eq!(fire.transform(id), Some(moved));
    // The flames (emitter 1): the newest are born around x = 2, the older ones stay.
    advance(&mut [&mut fire], &host, 6);
    let flames = fire.particles(id, 1).expect("read");
    let alive: Vec<DVec3> = flames
        .iter()
        .filter(|p| p.is_alive())
        .map(|p| {
            DVec3::new(
                p.pos_age[0].into(),
                p.pos_age[1].into(),
                p.pos_age[2].into(),
            )
        })
        .collect();
    let near_new = alive.iter().filter(|p| (p.x - 2.0).abs() < 0.6).count();
    let near_old = alive.iter().filter(|p| p.x.abs() < 0.6).count();
    assert!(near_new > 10, "{near_new} flames near the new place");
    assert!(
        near_old > 10,
        "{near_old} flames still rise where they were born"
    );
}

#[test]
fn the_runtime_build_pulls_in_no_editor_crates() {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = std::process::Command::new(cargo)
        .args([
            "tree",
            "--offline",
            "--locked",
            "--no-default-features",
            "--edges",
            "normal",
            "--prefix",
            "none",
        ])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("running cargo tree");
    let tree = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "cargo tree failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(tree.lines().any(|l| l.starts_with("wgpu ")), "{tree}");
    for banned in ["egui", "winit", "clap", "plotters", "notify", "egui-wgpu"] {
        let found: Vec<&str> = tree
            .lines()
            .filter(|l| l.split(' ').next() == Some(banned))
            .collect();
        assert!(found.is_empty(), "the runtime pulls in {banned}: {found:?}");
    }
}

/// Live edits of a batched player: a parameter edit keeps every instance's particles; an
/// edit that resizes a pool restarts the instances (their shared buffers are laid out by
/// the pools), which then play the new effect; an invalid effect is refused and changes
/// nothing.
#[test]
fn edits_reach_every_batched_instance() {
    let host = Host::new(vec3(0.0, 1.0, 4.0), vec3(0.0, 0.5, 0.0));
    let effect = preset("torch");
    let mut player = host.player(&effect);
    let ids = [0.0, 2.0].map(|x| {
        player
            .add_instance(Mat4::from_translation(vec3(x, 0.0, 0.0)), 5)
            .expect("instance")
    });
    advance(&mut [&mut player], &host, 30);
    let alive = |p: &Player| -> Vec<u32> {
        ids.iter()
            .map(|id| {
                p.count_particles(*id)
                    .expect("count")
                    .iter()
                    .map(|c| c.alive)
                    .sum()
            })
            .collect()
    };
    let before: Vec<_> = ids
        .iter()
        .map(|id| player.particles(*id, 0).expect("read"))
        .collect();
    assert!(
        alive(&player).iter().all(|n| *n > 0),
        "{:?}",
        alive(&player)
    );

    let mut brighter = effect.clone();
    brighter.emitters[0].spawn_rate_per_sec = brighter.emitters[0].spawn_rate_per_sec.scaled(2.0);
    brighter.emitters[0].look.intensity *= 1.5;
    player.set_effect(&brighter).expect("a parameter edit");
    for (id, b) in ids.iter().zip(&before) {
        assert_eq!(
            &player.particles(*id, 0).expect("read"),
            b,
            "particles kept"
        );
        let placed = player.instance_effect(*id).expect("there");
        assert_eq!(
            placed.emitters[0].spawn_rate_per_sec,
            brighter.emitters[0].spawn_rate_per_sec
        );
    }

    let mut invalid = brighter.clone();
    invalid.emitters[0].lifetime_secs = ignis::effect::Range::new(-1.0, 1.0);
    assert!(matches!(
        player.set_effect(&invalid),
        Err(ignis::PlayerError::Invalid(_))
    ));
    assert_eq!(player.effect(), &brighter, "a refused edit changes nothing");

    let mut larger = brighter.clone();
    larger.emitters[0].capacity *= 2;
    player.set_effect(&larger).expect("a pool edit");
    assert_eq!(alive(&player), [0, 0], "the instances restarted");
    advance(&mut [&mut player], &host, 30);
    assert!(
        alive(&player).iter().all(|n| *n > 0),
        "{:?}",
        alive(&player)
    );
    let stats = player.emitter_stats(ids[1]).expect("there");
    assert_eq!(stats[0].capacity, larger.emitters[0].capacity);
}

/// A batch's smoke is sorted together: an instance added to a batch that already draws
/// sorted smoke shows its own smoke (the sort's buffers grow with the batch, and the draw
/// follows them), and the smoke of every instance is drawn once.
#[test]
fn an_instance_added_to_a_sorted_batch_shows_its_smoke() {
    let host = Host::new(vec3(0.0, 1.5, 4.0), vec3(0.0, 1.2, 0.0));
    let mut smoke = preset("torch");
    smoke.emitters.retain(|e| e.look.blend == BlendMode::Alpha);
    assert!(!smoke.emitters.is_empty(), "the torch has smoke");
    let at = |x: f32| Mat4::from_translation(vec3(x, 0.0, 0.0));
    let mut player = host.player(&smoke);
    player.add_instance(at(-1.2), 1).expect("instance");
    player.add_instance(at(0.0), 2).expect("instance");
    advance(&mut [&mut player], &host, 90);
    let bg = [0.0; 3];
    // Pixels of the right third of the frame that hold smoke.
    let right_third = |f: &Frame| {
        (0..f.rgba.len())
            .filter(|i| (i % SIZE.0 as usize) * 3 / SIZE.0 as usize == 2)
            .filter(|i| differs(f.rgba[*i], [0.0, 0.0, 0.0, 1.0], 0.01))
            .count()
    };
    let before = host.frame(bg, &[], &mut [&mut player], false);
    assert_eq!(right_third(&before), 0, "nothing is drawn on the right yet");
    player.add_instance(at(1.2), 3).expect("instance");
    advance(&mut [&mut player], &host, 90);
    let after = host.frame(bg, &[], &mut [&mut player], false);
    let shown = right_third(&after);
    assert!(
        shown > 100,
        "the new instance's smoke covers only {shown} pixels"
    );
}

/// A frame runs every step it needs, on both sides of the parameter ring's 32 steps: a
/// preset whose step needs 16, 40 or 72 steps a frame plays at real time (nothing dropped),
/// batched and with a simulation of its own, and its particles are bit-identical to a
/// simulation stepped that many steps in separate submissions. (Steps of 2^-10 and 2^-12
/// s: frames of whole steps, exactly.)
#[test]
fn a_frame_runs_every_step_it_needs_beyond_one_chunk() {
    let host = Host::new(vec3(0.0, 1.0, 4.0), vec3(0.0, 0.5, 0.0));
    let ctx = ignis::gpu::GpuContext::from_device(&host.device, &host.queue);
    for (effect, label) in [
        (batchable_campfire(), "batched"),
        (preset("campfire"), "own"),
    ] {
        for (steps_per_frame, step) in [
            (16u32, 1.0 / 1024.0),
            (40, 1.0 / 4096.0),
            (72, 1.0 / 4096.0),
        ] {
            let mut effect = effect.clone();
            effect.time.step_secs = step;
            effect.time.max_substeps = 128;
            let frame_secs = f64::from(steps_per_frame) * f64::from(step);
            let mut player = host.player(&effect);
            let id = player.add_instance(Mat4::IDENTITY, 3).expect("instance");
            let frames = 6;
            for _ in 0..frames {
                let mut enc = host.device.create_command_encoder(&Default::default());
                player.advance(frame_secs);
                player.record(&mut enc, &host.camera, None);
                host.queue.submit([enc.finish()]);
            }
            let stats = player.clock_stats();
            assert_eq!(
                (stats.steps, stats.dropped_steps),
                (steps_per_frame, 0),
                "{label}, {steps_per_frame} steps a frame"
            );
            let time = player.time_secs(id).expect("instance");
            assert_eq!(
                time,
                f64::from(frames) * frame_secs,
                "{label}, {steps_per_frame} steps a frame"
            );
            let placed = player.instance_effect(id).expect("instance").clone();
            let mut sim =
                ignis::sim::GpuSim::new(&ctx, ignis::shaders::ShaderLibrary::embedded(), &placed)
                    .expect("sim");
            for _ in 0..frames {
                sim.step(&placed, step, steps_per_frame).expect("step");
            }
            let flames = sim.read_particles(1).expect("read");
            assert!(
                flames.iter().any(|p| p.is_alive()),
                "{label}: the flames live"
            );
            for e in 0..effect.emitters.len() {
                let played = player.particles(id, e).expect("read");
                let alone = sim.read_particles(e).expect("read");
                assert!(
                    bytemuck::cast_slice::<_, u8>(&played) == bytemuck::cast_slice::<_, u8>(&alone),
                    "{label}, {steps_per_frame} steps a frame: emitter {e} differs"
                );
            }
        }
    }
}
