//! The composite's tonemap against its closed form: every display pixel is
//! `srgb(aces(exposure · (hdr + low_alpha + bloom_strength · bloom)))`, each layer sampled at
//! the pixel's centre, within one level of an 8-bit image.

mod common;

use common::*;
use half::f16;
use ignis::testing::gpu::GpuContext;
use ignis::testing::render::tonemap::TonemapPass;
use ignis::testing::shaders::ShaderLibrary;

const W: u32 = 64;
const H: u32 = 4;

/// Narkowicz's ACES fit, as the shader writes it.
fn aces(x: f32) -> f32 {
    ((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0)
}

/// The sRGB transfer function (encoding).
fn srgb(x: f32) -> f32 {
    if x <= 0.003_130_8 {
        x * 12.92
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// A W×H Rgba16Float texture whose pixel (x, y) holds `f(x, y)` in RGB, alpha 1.
fn hdr_texture(ctx: &GpuContext, f: impl Fn(u32, u32) -> [f32; 3]) -> wgpu::TextureView {
    let mut data = Vec::new();
    for y in 0..H {
        for x in 0..W {
            let [r, g, b] = f(x, y);
            data.extend([r, g, b, 1.0].map(f16::from_f32));
        }
    }
    let texture = common::texture_with(
        ctx,
        (W, H),
        wgpu::TextureFormat::Rgba16Float,
        bytemuck::cast_slice(&data),
    );
    texture.create_view(&Default::default())
}

/// The tonemap of `hdr` with the optional layers, read back as RGBA bytes.
fn tonemap(
    ctx: &GpuContext,
    hdr: &wgpu::TextureView,
    bloom: Option<(&wgpu::TextureView, f32)>,
    low_alpha: Option<&wgpu::TextureView>,
    exposure: f32,
) -> Vec<u8> {
    let pass = TonemapPass::new(ctx, &ShaderLibrary::embedded()).expect("tonemap pass");
    let out = ignis::testing::gpu::texture_2d(
        &ctx.device,
        "display",
        (W, H),
        1,
        wgpu::TextureFormat::Rgba8Unorm,
        wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC,
    );
    let view = out.create_view(&Default::default());
    let staging = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: u64::from(W * H * 4),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    pass.record(
        ctx,
        &mut enc,
        hdr,
        bloom,
        low_alpha,
        None,
        (&view, (W, H)),
        exposure,
    );
    enc.copy_texture_to_buffer(
        out.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &staging,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(W * 4),
                rows_per_image: Some(H),
            },
        },
        wgpu::Extent3d {
            width: W,
            height: H,
            depth_or_array_layers: 1,
        },
    );
    ctx.queue.submit([enc.finish()]);
    ignis::testing::sim::gpu_sim::map_read(ctx, &staging).expect("readback")
}

/// The largest difference, in levels, between the image and `want(x, y)` (linear RGB
/// before exposure), and where.
fn worst(image: &[u8], exposure: f32, want: impl Fn(u32, u32) -> [f32; 3]) -> (i32, u32, u32) {
    let mut worst = (0, 0, 0);
    for y in 0..H {
        for x in 0..W {
            let lin = want(x, y);
            for c in 0..3 {
                let expect = (srgb(aces(lin[c] * exposure)) * 255.0).round() as i32;
                let got = i32::from(image[((y * W + x) * 4) as usize + c]);
                if (got - expect).abs() > worst.0 {
                    worst = ((got - expect).abs(), x, y);
                }
            }
        }
    }
    worst
}

/// HDR values from black to 12 across the image, three channels apart: the display image is
/// the closed form within one level, at two exposures.
#[test]
fn the_tonemap_is_aces_then_srgb() {
    let ctx = gpu();
    let value = |x: u32, y: u32| {
        let t = (x + y * W) as f32 / (W * H) as f32;
        [12.0 * t * t, 3.0 * t, 0.05 + 0.2 * t]
    };
    let hdr = hdr_texture(&ctx, value);
    for exposure in [1.0, 0.35] {
        let image = tonemap(&ctx, &hdr, None, None, exposure);
        let (diff, x, y) = worst(&image, exposure, value);
        assert!(
            diff <= 1,
            "exposure {exposure}: {diff} levels off at ({x}, {y})"
        );
        assert!(image[0] < 30, "black stays dark: {}", image[0]);
    }
}

/// The smoke layer and the bloom add to the HDR image before the curve (the bloom scaled by
/// its strength), each sampled at the pixel's centre: gradients in both layers land on the
/// pixels they belong to.
#[test]
fn the_low_alpha_and_bloom_layers_add_at_their_pixels() {
    let ctx = gpu();
    let base = |x: u32, _y: u32| [0.02 * x as f32, 0.1, 0.0];
    let alpha = |x: u32, y: u32| [0.0, 0.015 * x as f32, 0.05 * y as f32];
    let bloom = |x: u32, _y: u32| [0.01 * (W - x) as f32, 0.0, 0.03 * x as f32];
    let (hdr, a, b) = (
        hdr_texture(&ctx, base),
        hdr_texture(&ctx, alpha),
        hdr_texture(&ctx, bloom),
    );
    let strength = 0.7;
    let image = tonemap(&ctx, &hdr, Some((&b, strength)), Some(&a), 1.0);
    let sum = |x, y| {
        let (h, s, g) = (base(x, y), alpha(x, y), bloom(x, y));
        [0, 1, 2].map(|c| h[c] + s[c] + strength * g[c])
    };
    let (diff, x, y) = worst(&image, 1.0, sum);
    assert!(diff <= 1, "{diff} levels off at ({x}, {y})");
}
