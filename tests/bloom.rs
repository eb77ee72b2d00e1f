//! The bloom chain (`shaders/bloom.wgsl`) against the same chain computed on the CPU:
//! the soft threshold while halving (or quartering, in draft) the HDR image, the draft
//! glow layer added in, the five-tap downsamples and the tent upsamples added back up,
//! every level rounded to half floats as its texture stores them. Every pixel of the
//! result, on images of odd sizes with light at their edges, within half-float rounding.

mod common;

use common::*;
use half::f16;
use ignis::effect::Bloom;
use ignis::testing::gpu::GpuContext;
use ignis::testing::render::bloom::BloomPass;
use ignis::testing::shaders::ShaderLibrary;

/// An RGB image: width, height, row-major pixels.
#[derive(Clone)]
struct Image {
    w: u32,
    h: u32,
    px: Vec<[f32; 3]>,
}

impl Image {
    fn new(w: u32, h: u32, f: impl Fn(u32, u32) -> [f32; 3]) -> Self {
        let px = (0..w * h).map(|i| f(i % w, i / w)).collect();
        Self { w, h, px }
    }

    /// The pixel at (x, y), clamped to the image (`textureLoad` of a clamped index).
    fn at(&self, x: i64, y: i64) -> [f32; 3] {
        let x = x.clamp(0, i64::from(self.w) - 1) as u32;
        let y = y.clamp(0, i64::from(self.h) - 1) as u32;
        self.px[(y * self.w + x) as usize]
    }

    /// A bilinear sample at texture coordinates (u, v), clamped to the edge.
    fn tap(&self, u: f32, v: f32) -> [f32; 3] {
        let (x, y) = (u * self.w as f32 - 0.5, v * self.h as f32 - 0.5);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let mut c = [0.0; 3];
        for (dx, dy, w) in [
            (0, 0, (1.0 - fx) * (1.0 - fy)),
            (1, 0, fx * (1.0 - fy)),
            (0, 1, (1.0 - fx) * fy),
            (1, 1, fx * fy),
        ] {
            let p = self.at(x0 + dx, y0 + dy);
            (0..3).for_each(|k| c[k] += w * p[k]);
        }
        c
    }
}

fn half(x: f32) -> f32 {
    f16::from_f32(x).to_f32()
}

fn add(a: [f32; 3], b: [f32; 3], k: f32) -> [f32; 3] {
    [a[0] + k * b[0], a[1] + k * b[1], a[2] + k * b[2]]
}

/// The first level: the HDR image averaged over blocks of `d`×`d` pixels (2, or 4 in
/// draft), the glow layer's same block added, kept above the soft threshold.
fn prefilter(hdr: &Image, d: u32, glow: Option<&Image>, threshold: f32) -> Image {
    let knee = (0.5 * threshold.max(1e-3)).max(1e-5);
    let (w, h) = ((hdr.w / d).max(1), (hdr.h / d).max(1));
    Image::new(w, h, |x, y| {
        let mut c = [0.0; 3];
        for j in 0..d {
            for i in 0..d {
                let p = hdr.at(i64::from(x * d + i), i64::from(y * d + j));
                c = add(c, p, 1.0 / (d * d) as f32);
            }
        }
        if let Some(g) = glow {
            // The glow layer is half the HDR image: a block of d / 2 of its texels.
            let n = d / 2;
            let (mx, my) = (i64::from(g.w) - 1, i64::from(g.h) - 1);
            for j in 0..n {
                for i in 0..n {
                    let (gx, gy) = (i64::from(x * n + i), i64::from(y * n + j));
                    c = add(c, g.at(gx.min(mx), gy.min(my)), 1.0 / (n * n) as f32);
                }
            }
        }
        let l = c[0].max(c[1]).max(c[2]);
        let soft = (l - threshold + knee).clamp(0.0, 2.0 * knee);
        let soft = soft * soft / (4.0 * knee);
        let k = (soft.max(l - threshold) / l.max(1e-5)).max(0.0);
        c.map(|v| half(v * k))
    })
}

/// Level `src` halved to `w`×`h`: the centre tap four times and the four diagonal ones.
fn down(src: &Image, w: u32, h: u32) -> Image {
    let (tx, ty) = (1.0 / src.w as f32, 1.0 / src.h as f32);
    Image::new(w, h, |x, y| {
        let (u, v) = ((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
        let mut c = [0.0; 3];
        c = add(c, src.tap(u, v), 4.0);
        for (sx, sy) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
            c = add(c, src.tap(u + sx * tx, v + sy * ty), 1.0);
        }
        c.map(|v| half(v / 8.0))
    })
}

/// Level `src` doubled onto `below` (the down level of the size written) with the 3×3
/// tent, added to it.
fn up(src: &Image, below: &Image) -> Image {
    let (w, h) = (below.w, below.h);
    let (tx, ty) = (1.0 / src.w as f32, 1.0 / src.h as f32);
    Image::new(w, h, |x, y| {
        let (u, v) = ((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
        let mut c = [0.0; 3];
        for (sx, sy, k) in [
            (0.0, 0.0, 4.0),
            (-1.0, 0.0, 2.0),
            (1.0, 0.0, 2.0),
            (0.0, -1.0, 2.0),
            (0.0, 1.0, 2.0),
            (-1.0, -1.0, 1.0),
            (1.0, -1.0, 1.0),
            (-1.0, 1.0, 1.0),
            (1.0, 1.0, 1.0),
        ] {
            c = add(c, src.tap(u + sx * tx, v + sy * ty), k);
        }
        let base = below.at(i64::from(x), i64::from(y));
        add(base, c, 1.0 / 16.0).map(half)
    })
}

/// The chain's result on the CPU: what the tonemap adds.
fn bloom_cpu(hdr: &Image, glow: Option<&Image>, settings: &Bloom, draft: bool) -> Image {
    let quarter = draft && settings.levels > 1;
    let d = if quarter { 4 } else { 2 };
    let levels = settings.levels - u32::from(quarter);
    let mut downs = vec![prefilter(hdr, d, glow, settings.threshold)];
    let (w, h) = (downs[0].w, downs[0].h);
    let levels = levels.clamp(1, 32 - w.min(h).leading_zeros());
    for m in 1..levels {
        let last = &downs[m as usize - 1];
        downs.push(down(last, (w >> m).max(1), (h >> m).max(1)));
    }
    let mut result = downs.pop().expect("a level");
    while let Some(below) = downs.pop() {
        result = up(&result, &below);
    }
    result
}

/// An HDR texture of `img` (alpha 1).
fn upload(ctx: &GpuContext, img: &Image) -> wgpu::TextureView {
    let data: Vec<f16> = img
        .px
        .iter()
        .flat_map(|p| [p[0], p[1], p[2], 1.0].map(f16::from_f32))
        .collect();
    let format = wgpu::TextureFormat::Rgba16Float;
    texture_with(ctx, (img.w, img.h), format, bytemuck::cast_slice(&data))
        .create_view(&Default::default())
}

const READ: &str = r#"
@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var<storage, read_write> out: array<vec4<f32>>;
@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let d = textureDimensions(src);
    if any(id.xy >= d) {
        return;
    }
    out[id.y * d.x + id.x] = textureLoad(src, id.xy, 0);
}
"#;

/// The GPU chain's result for `hdr` (and the glow layer), `w`×`h` pixels.
fn bloom_gpu(
    ctx: &GpuContext,
    (hdr, glow): (&Image, Option<&Image>),
    settings: &Bloom,
    draft: bool,
    (w, h): (u32, u32),
) -> Vec<[f32; 3]> {
    let mut pass = BloomPass::new(ctx, &ShaderLibrary::embedded()).expect("bloom pass");
    let hdr_view = upload(ctx, hdr);
    let glow_view = glow.map(|g| upload(ctx, g));
    let d = &ctx.device;
    let module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("bloom readback"),
        source: wgpu::ShaderSource::Wgsl(READ.into()),
    });
    let pipeline = d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("bloom readback"),
        layout: None,
        module: &module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    let size = u64::from(w * h) * 16;
    let out = d.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let staging = d.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc = d.create_command_encoder(&Default::default());
    let size_px = (hdr.w, hdr.h);
    let result = pass
        .record(
            ctx,
            &mut enc,
            &hdr_view,
            glow_view.as_ref(),
            size_px,
            settings,
            draft,
        )
        .expect("a result");
    let group = bind_in_order(
        ctx,
        &pipeline,
        [
            wgpu::BindingResource::TextureView(result),
            out.as_entire_binding(),
        ],
    );
    {
        let mut cp = enc.begin_compute_pass(&Default::default());
        cp.set_pipeline(&pipeline);
        cp.set_bind_group(0, &group, &[]);
        cp.dispatch_workgroups(w.div_ceil(8), h.div_ceil(8), 1);
    }
    enc.copy_buffer_to_buffer(&out, 0, &staging, 0, size);
    ctx.queue.submit([enc.finish()]);
    let bytes = ignis::testing::sim::gpu_sim::map_read(ctx, &staging).expect("readback");
    let texels: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
    texels.iter().map(|t| [t[0], t[1], t[2]]).collect()
}

/// A 70×46 HDR image: a dim gradient through the threshold's knee, three channels
/// apart, and bright dots in the middle, on the edges and in a corner.
fn scene() -> Image {
    Image::new(70, 46, |x, y| {
        let t = (x + y * 70) as f32 / (70.0 * 46.0);
        let mut c = [1.4 * t, 0.9 * (1.0 - t), 0.3 + 0.8 * t * t];
        for (dx, dy, v) in [
            (30, 20, [9.0, 4.0, 1.0]),
            (0, 11, [3.0, 6.0, 2.0]),
            (69, 45, [5.0, 1.0, 7.0]),
            (51, 0, [2.5, 2.5, 2.5]),
        ] {
            if (x, y) == (dx, dy) {
                c = v;
            }
        }
        c
    })
}

/// The draft glow layer: half the HDR image's size, light in one corner.
fn glow_layer() -> Image {
    Image::new(35, 23, |x, y| {
        let r = ((x as f32 - 30.0).powi(2) + (y as f32 - 4.0).powi(2)).sqrt();
        [2.0 / (1.0 + r), 1.0 / (1.0 + r), 0.2]
    })
}

#[test]
fn the_bloom_chain_matches_its_cpu_mirror_at_every_pixel() {
    let ctx = gpu();
    let hdr = scene();
    let glow = glow_layer();
    let settings = Bloom {
        threshold: 0.9,
        intensity: 0.3,
        levels: 4,
    };
    // A target smaller than the blocks averaged (3×3 in draft: one pixel of a 4×4 block,
    // its glow layer one texel): the reads clamp to the images' edges.
    let tiny = Image::new(3, 3, |x, y| [1.0 + x as f32, 2.0 + y as f32, 3.0]);
    let tiny_glow = Image::new(1, 1, |_, _| [0.5, 0.25, 4.0]);
    let cases = [
        (&hdr, false, None),
        (&hdr, false, Some(&glow)),
        (&hdr, true, Some(&glow)),
        (&tiny, true, Some(&tiny_glow)),
    ];
    for (hdr, draft, glow) in cases {
        let want = bloom_cpu(hdr, glow, &settings, draft);
        let got = bloom_gpu(&ctx, (hdr, glow), &settings, draft, (want.w, want.h));
        let mut worst = (0.0f32, 0, [0.0; 3], [0.0; 3]);
        for (i, (g, w)) in got.iter().zip(&want.px).enumerate() {
            for k in 0..3 {
                // Half-float rounding at every level: a few parts in a thousand.
                let err = (g[k] - w[k]).abs() / (w[k].abs() + 0.05);
                if err > worst.0 {
                    worst = (err, i, *g, *w);
                }
            }
        }
        let (err, i, g, w) = worst;
        let (x, y) = (i as u32 % want.w, i as u32 / want.w);
        println!(
            "{}x{}, draft {draft}, glow {}: worst {err:.5}",
            hdr.w,
            hdr.h,
            glow.is_some()
        );
        assert!(
            err < 4e-3,
            "{}x{}, draft {draft}, glow {}: ({x}, {y}) of {}x{}: GPU {g:?}, CPU {w:?}",
            hdr.w,
            hdr.h,
            glow.is_some(),
            want.w,
            want.h
        );
        let lit = want.px.iter().filter(|p| p[0] > 0.01).count();
        assert!(
            lit * 4 >= want.px.len(),
            "the bloom lights the image: {lit}"
        );
    }
}
