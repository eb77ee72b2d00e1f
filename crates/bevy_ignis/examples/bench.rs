//! The frame cost of N torch entities in a Bevy app: the plugin's GPU time (its
//! `render/ignis` diagnostics span: every torch's steps, sort and splat recorded, then
//! drawn; GPU timestamps where the adapter has them) and the CPU time of a whole frame,
//! against a frame with no torch, per entity.
//!
//! `cargo run --release --example bench -- --instances 1,10,100 --size 1920x1080
//! --frames 100 --out bench.md` prints a table and writes it to `--out` (`--presets DIR`:
//! the presets folder, by default the repository's).

use std::path::PathBuf;
use std::time::Instant;

use bevy::camera::{Hdr, RenderTarget};
use bevy::diagnostic::{DiagnosticPath, DiagnosticsStore};
use bevy::prelude::*;
use bevy::render::diagnostic::RenderDiagnosticsPlugin;
use bevy::render::render_resource::TextureFormat;
use bevy_ignis::IgnisEffect;

// The shared headless app (this example adds a plugin: `headless_app_with`).
#[allow(dead_code)]
#[path = "common/headless.rs"]
mod headless;

/// One measured configuration.
struct Row {
    torches: u32,
    gpu_ms: Option<f64>,
    frame_cpu_ms: f64,
}

fn main() -> Result<(), String> {
    let (mut counts, mut size, mut frames, mut out) = (vec![1, 10, 100], (1920, 1080), 100, None);
    let mut presets = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../presets");
    let mut msaa = 4;
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let value = args.next().ok_or(format!("{arg} needs a value"))?;
        match arg.as_str() {
            "--instances" => counts = value.split(',').filter_map(|n| n.parse().ok()).collect(),
            "--size" => {
                let (w, h) = value.split_once('x').ok_or("--size WxH")?;
                size = (
                    w.parse().map_err(|_| "--size WxH")?,
                    h.parse().map_err(|_| "--size WxH")?,
                );
            }
            "--frames" => frames = value.parse().map_err(|_| "--frames N")?,
            "--out" => out = Some(PathBuf::from(value)),
            "--presets" => presets = PathBuf::from(value),
            "--msaa" => msaa = value.parse().map_err(|_| "--msaa 1|2|4|8")?,
            other => return Err(format!("unknown argument {other:?}")),
        }
    }
    let presets =
        std::fs::canonicalize(&presets).map_err(|e| format!("{}: {e}", presets.display()))?;
    let empty = measure(&presets, 0, (size, msaa), frames)?;
    let mut rows = Vec::new();
    let mut adapter = String::new();
    for n in counts {
        let (row, name) = measure(&presets, n, (size, msaa), frames)?;
        adapter = name;
        rows.push(row);
    }
    let table = table(&rows, empty.0.frame_cpu_ms, &adapter, (size, msaa), frames);
    println!("{table}");
    if let Some(path) = out {
        std::fs::write(&path, &table).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    Ok(())
}

/// Plays `torches` torches on a grid 1 m apart (as `ignis bench runtime`) into an HDR
/// camera of `size` with `msaa` samples; warms up for their lifetime, then times `frames` frames.
fn measure(
    presets: &std::path::Path,
    torches: u32,
    (size, msaa): ((u32, u32), u32),
    frames: usize,
) -> Result<(Row, String), String> {
    let mut app = headless::headless_app_with(presets, false, |app| {
        app.add_plugins(RenderDiagnosticsPlugin);
    });
    let image = Image::new_target_texture(size.0, size.1, TextureFormat::Rgba8UnormSrgb, None);
    let target = app.world_mut().resource_mut::<Assets<Image>>().add(image);
    let side = (torches as f32).sqrt().ceil().max(1.0) as u32;
    let world = app.world_mut();
    let torch = world.resource::<AssetServer>().load("torch.ron");
    for i in 0..torches {
        let at = Vec3::new(
            (i % side) as f32 - side as f32 / 2.0,
            0.0,
            -((i / side) as f32),
        );
        world.spawn((
            IgnisEffect::new(torch.clone(), i + 1),
            Transform::from_translation(at),
        ));
    }
    let eye = Vec3::new(0.0, 1.0 + side as f32 * 0.6, side as f32 * 0.9 + 3.0);
    let look = Transform::from_translation(eye)
        .looking_at(Vec3::new(0.0, 1.0, -(side as f32) / 2.0), Vec3::Y);
    world.spawn((
        Camera3d::default(),
        Hdr,
        Msaa::from_samples(msaa),
        RenderTarget::from(target),
        look,
    ));
    for _ in 0..240 {
        app.update();
    }
    let mut cpu = Vec::with_capacity(frames);
    for _ in 0..frames {
        let start = Instant::now();
        app.update();
        cpu.push(start.elapsed().as_secs_f64() * 1e3);
    }
    let store = app.world().resource::<DiagnosticsStore>();
    let gpu: Vec<f64> = store
        .get(&DiagnosticPath::new("render/ignis/elapsed_gpu"))
        .map(|d| {
            let all: Vec<f64> = d.values().copied().collect();
            all[all.len().saturating_sub(frames)..].to_vec()
        })
        .unwrap_or_default();
    let adapter = app
        .world()
        .resource::<bevy::render::renderer::RenderAdapterInfo>()
        .name
        .clone();
    let gpu_ms = (!gpu.is_empty()).then(|| median(gpu));
    Ok((
        Row {
            torches,
            gpu_ms,
            frame_cpu_ms: median(cpu),
        },
        adapter,
    ))
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

fn table(
    rows: &[Row],
    empty_ms: f64,
    adapter: &str,
    (size, msaa): ((u32, u32), u32),
    frames: usize,
) -> String {
    let mut s = format!(
        "# bevy_ignis: torches in a Bevy 0.20 frame\n\n{adapter}, {}×{}, HDR, MSAA {msaa}×; medians of {frames} frames \
         after 240 frames of warm-up.\n\n`cargo run --release --example bench -- --size {}x{} --msaa {msaa} --frames {frames}`\n\n\
         | torches | ignis GPU time (record + draw) | Bevy frame CPU time | CPU per torch over an empty frame |\n|---|---|---|---|\n",
        size.0, size.1, size.0, size.1
    );
    s += &format!("| 0 | – | {empty_ms:.3} ms | – |\n");
    for r in rows {
        let gpu = r
            .gpu_ms
            .map_or("no timestamps".to_owned(), |g| format!("{g:.3} ms"));
        let per = (r.frame_cpu_ms - empty_ms) * 1e3 / f64::from(r.torches.max(1));
        s += &format!(
            "| {} | {gpu} | {:.3} ms | {per:.1} µs |\n",
            r.torches, r.frame_cpu_ms
        );
    }
    s
}
