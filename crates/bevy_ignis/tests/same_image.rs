//! The plugin draws what the plain runtime draws: the same preset and seed, camera,
//! target size and depth give the same image within 1/255 on average. Pausing Bevy's
//! virtual time holds the effect still.

mod common;

use bevy::prelude::*;
use bevy::render::view::Msaa;
use bevy_ignis::{IgnisEffect, ignis};
use common::SIZE;

const EYE: [f32; 3] = [0.3, 1.2, 2.6];
const LOOK_AT: [f32; 3] = [0.0, 1.1, 0.0];
const SEED: u32 = 5;

#[test]
fn the_plugin_draws_what_the_runtime_draws() {
    // The plugin: 45 frames, then Bevy's virtual time paused while the image is read.
    let mut app = common::app(&common::presets(), false);
    let target = common::camera(&mut app, EYE.into(), LOOK_AT.into());
    let camera = app
        .world_mut()
        .query_filtered::<Entity, With<Camera3d>>()
        .single(app.world())
        .expect("camera");
    app.world_mut().entity_mut(camera).insert(Msaa::Off);
    let preset = common::load(&mut app, "torch.ron");
    app.world_mut()
        .spawn(IgnisEffect::new(preset.clone(), SEED));
    common::run(&mut app, 45);
    app.world_mut().resource_mut::<Time<Virtual>>().pause();
    common::run(&mut app, 2);
    let vp = common::players(&app).any_of(preset.id()).expect("player");
    let (id, _) = *vp.instances.values().next().expect("instance");
    let secs = vp.player.time_secs(id).expect("time");
    let plugin = common::capture(&mut app, &target);
    let vp = common::players(&app).any_of(preset.id()).expect("player");
    assert_eq!(
        vp.player.time_secs(id),
        Some(secs),
        "paused virtual time moved the effect"
    );
    let frames = (secs * 60.0).round() as u32;
    assert!(frames >= 40, "the effect ran {frames} frames");

    let runtime = runtime_image(frames);
    let mean = (plugin.iter().zip(&runtime))
        .map(|(a, b)| (0..3).map(|c| f64::from(a[c].abs_diff(b[c]))).sum::<f64>())
        .sum::<f64>()
        / (3 * plugin.len()) as f64;
    let lit = runtime.iter().filter(|p| p[0] > 60).count();
    eprintln!("plugin vs runtime: {mean:.4}/255 mean over {lit} lit pixels, {frames} frames");
    assert!(lit > 200, "only {lit} lit pixels");
    assert!(
        mean < 1.0,
        "the plugin's image differs by {mean}/255 on average"
    );
}

/// The plain runtime on a device of its own: an sRGB target cleared to black, a
/// reversed-Z depth cleared to 0 (far), Bevy's default projection, `frames` frames.
fn runtime_image(frames: u32) -> Vec<[u8; 4]> {
    use ignis::glam::{Mat4, Vec3, camera::rh};
    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = pollster::block_on(wgpu::util::initialize_adapter_from_env_or_default(
        &instance, None,
    ))
    .expect("adapter");
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        required_limits: adapter.limits(),
        ..Default::default()
    }))
    .expect("device");
    let texture = |format, usage| {
        device.create_texture(&wgpu::TextureDescriptor {
            label: None,
            size: wgpu::Extent3d {
                width: SIZE.0,
                height: SIZE.1,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: usage | wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        })
    };
    let color = texture(
        wgpu::TextureFormat::Rgba8UnormSrgb,
        wgpu::TextureUsages::COPY_SRC,
    );
    let depth = texture(
        wgpu::TextureFormat::Depth32Float,
        wgpu::TextureUsages::TEXTURE_BINDING,
    );
    let (color_view, depth_view) = (
        color.create_view(&Default::default()),
        depth.create_view(&Default::default()),
    );
    let effect = ignis::preset::load(&common::presets().join("torch.ron")).expect("preset");
    let settings = ignis::PlayerSettings {
        depth_format: Some(wgpu::TextureFormat::Depth32Float),
        depth_compare: wgpu::CompareFunction::GreaterEqual,
        asset_dir: Some(common::presets()),
        ..ignis::PlayerSettings::new(wgpu::TextureFormat::Rgba8UnormSrgb)
    };
    let mut player = ignis::Player::new(&device, &queue, &effect, settings).expect("player");
    player
        .add_instance(Mat4::IDENTITY.to_cols_array_2d(), SEED)
        .expect("instance");
    let view = rh::view::look_at_mat4(Vec3::from(EYE), Vec3::from(LOOK_AT), Vec3::Y);
    let aspect = SIZE.0 as f32 / SIZE.1 as f32;
    let proj =
        rh::proj::directx::perspective_infinite_reverse(std::f32::consts::FRAC_PI_4, aspect, 0.1);
    let camera = ignis::Camera::new(view, proj, SIZE);
    for frame in 0..frames {
        let mut enc = device.create_command_encoder(&Default::default());
        clear(&mut enc, &color_view, &depth_view);
        player.advance(1.0 / 60.0);
        player
            .record(&mut enc, &camera, Some(&depth_view))
            .expect("record");
        if frame + 1 == frames {
            let targets = ignis::HostTargets {
                color: &color_view,
                resolve_target: None,
                depth: Some(&depth_view),
            };
            player.draw_to(&mut enc, &targets);
        }
        queue.submit([enc.finish()]);
    }
    read(&device, &queue, &color)
}

/// Clears colour to black and depth to 0 (reversed Z's far plane), as Bevy's frame does.
fn clear(enc: &mut wgpu::CommandEncoder, color: &wgpu::TextureView, depth: &wgpu::TextureView) {
    enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: color,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: depth,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(0.0),
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        }),
        ..Default::default()
    });
}

fn read(device: &wgpu::Device, queue: &wgpu::Queue, color: &wgpu::Texture) -> Vec<[u8; 4]> {
    let row = (SIZE.0 * 4).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: u64::from(row * SIZE.1),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut enc = device.create_command_encoder(&Default::default());
    enc.copy_texture_to_buffer(
        color.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: None,
            },
        },
        color.size(),
    );
    queue.submit([enc.finish()]);
    buffer
        .slice(..)
        .map_async(wgpu::MapMode::Read, |r| r.expect("map"));
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .expect("poll");
    let bytes = buffer.slice(..).get_mapped_range().expect("mapped");
    (0..SIZE.1 as usize)
        .flat_map(|y| {
            bytes[y * row as usize..][..SIZE.0 as usize * 4]
                .chunks_exact(4)
                .map(|c| [c[0], c[1], c[2], c[3]])
                .collect::<Vec<_>>()
        })
        .collect()
}
