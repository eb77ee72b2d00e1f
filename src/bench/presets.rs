//! `ignis bench presets`: what designers' effects cost. Every shipped preset at the given
//! sizes, in steady state (played past its last burst and longest lifetime at 60 fps),
//! each frame's parts timed apart on the GPU (timestamps where the adapter has them):
//! update, sort + splat, particle draws, composite (bloom and tonemap). Each preset runs
//! with its own draw-path choice and again with every emitter forced to billboards and to
//! the splat, in the same process, so the paths' ratio comes from one run. One record per
//! preset, size and path in the JSON.

use std::path::{Path, PathBuf};

use crate::effect::{DrawPath, Effect};
use crate::gpu::GpuContext;
use crate::gpu::timer::{GpuTimer, median};
use crate::headless::Headless;
use crate::runtime::PlayerError;
use crate::shaders::ShaderLibrary;

use super::Report;

/// What to run.
#[derive(Clone, Debug)]
pub struct PresetsOptions {
    /// The presets (files).
    pub presets: Vec<PathBuf>,
    /// Render sizes.
    pub sizes: Vec<(u32, u32)>,
    /// Timed frames per row (medians are reported).
    pub frames: usize,
}

/// One preset at one size with one path choice.
#[derive(Clone, Debug, serde::Serialize)]
struct Row {
    preset: String,
    size: String,
    path: &'static str,
    update_ms: f64,
    sort_ms: f64,
    draw_ms: f64,
    composite_ms: f64,
    frame_ms: f64,
    /// The last frame against the billboards' (8-bit levels): mean and largest
    /// difference of a channel.
    diff_mean: f64,
    diff_max: u8,
}

/// Frames run before the timed ones of each row.
const UNTIMED_FRAMES: usize = 10;

/// The path choices measured. The billboards first: the other paths' images are
/// compared with theirs.
const PATHS: [(&str, Option<DrawPath>); 4] = [
    ("billboard", Some(DrawPath::Billboard)),
    ("auto", None),
    ("splat", Some(DrawPath::Splat)),
    ("tiles", Some(DrawPath::Tiles)),
];

/// Runs every preset, size and path.
pub fn run(ctx: &GpuContext, opts: &PresetsOptions) -> Result<Report, PlayerError> {
    let timer = GpuTimer::new(ctx);
    // The first preset's rows are measured once and dropped: a process's first rows
    // were up to twice as slow on the H100 (first use of each path's pipelines and
    // memory, the GPU's clocks).
    if let (Some(path), Some(&size)) = (opts.presets.first(), opts.sizes.first())
        && let Ok(effect) = crate::preset::load(path)
    {
        for choice in PATHS {
            measure(ctx, &timer, path, &effect, size, choice, opts)?;
        }
    }
    let mut rows = Vec::new();
    for path in &opts.presets {
        let effect = match crate::preset::load(path) {
            Ok(e) => e,
            Err(e) => {
                log::warn!("skipping {}: {e}", path.display());
                continue;
            }
        };
        for &size in &opts.sizes {
            let mut reference = None;
            for (label, forced) in PATHS {
                let (mut row, image) =
                    measure(ctx, &timer, path, &effect, size, (label, forced), opts)?;
                let reference = reference.get_or_insert(image.clone());
                (row.diff_mean, row.diff_max) = image_diff(reference, &image);
                println!(
                    "{} {}x{} {label}: frame {:.3} ms, image vs billboards {:.3}/255 mean, {}/255 max",
                    row.preset, size.0, size.1, row.frame_ms, row.diff_mean, row.diff_max
                );
                rows.push(row);
            }
        }
    }
    Ok(report(ctx, &timer, opts, &rows))
}

/// The frames a preset needs to reach its steady state at 60 fps: past its last burst and
/// longest lifetime; an effect of bursts alone (nothing left then) is measured a quarter
/// of its longest lifetime after its last burst, in full bloom.
fn warm_up_frames(effect: &Effect) -> usize {
    let (longest, last_burst) = (effect.longest_lifetime_secs(), effect.last_burst_secs());
    let continuous = effect
        .emitters
        .iter()
        .any(|e| e.enabled && e.spawn_rate_per_sec.bounds().1 > 0.0);
    let secs = if continuous {
        longest + last_burst
    } else {
        last_burst + 0.25 * longest
    };
    (secs * 60.0).ceil() as usize + usize::from(continuous) * 10
}

/// Mean and largest difference of two images' channels, in 8-bit levels.
fn image_diff(a: &image::RgbaImage, b: &image::RgbaImage) -> (f64, u8) {
    let (mut sum, mut max) = (0u64, 0u8);
    for (x, y) in a.as_raw().iter().zip(b.as_raw()) {
        let d = x.abs_diff(*y);
        sum += u64::from(d);
        max = max.max(d);
    }
    (sum as f64 / a.as_raw().len().max(1) as f64, max)
}

/// One row, and the frame after it (the same simulated moment for every path).
fn measure(
    ctx: &GpuContext,
    timer: &GpuTimer,
    path: &Path,
    effect: &Effect,
    size: (u32, u32),
    (label, forced): (&'static str, Option<DrawPath>),
    opts: &PresetsOptions,
) -> Result<(Row, image::RgbaImage), PlayerError> {
    let mut effect = effect.clone();
    if let Some(p) = forced {
        for e in &mut effect.emitters {
            e.look.draw_path = p;
        }
    }
    let settings = crate::PlayerSettings {
        asset_dir: path.parent().map(Path::to_path_buf),
        ..crate::render::Composite::player_settings()
    };
    let name = effect.name.clone();
    let mut run =
        Headless::with_settings(ctx, effect.clone(), ShaderLibrary::discover(None), settings)?;
    for _ in 0..warm_up_frames(&effect) {
        run.advance(1.0 / 60.0);
    }
    let camera = run.camera.view(size);
    let mut parts: [Vec<f64>; 4] = Default::default();
    // Ten frames untimed first: the steps the warm-up planned, and the GPU's clocks up
    // from idle.
    for frame in 0..opts.frames + UNTIMED_FRAMES {
        if frame == UNTIMED_FRAMES {
            parts = Default::default();
        }
        run.player.advance(1.0 / 60.0);
        let Headless {
            player, composite, ..
        } = &mut run;
        parts[0].push(timer.time(ctx, |enc| player.simulate(enc)));
        parts[1].push(timer.time(ctx, |enc| player.record(enc, &camera, None)));
        let mut layered = crate::Layers::NONE;
        parts[2].push(timer.time(ctx, |enc| {
            layered = composite.draw_particles(ctx, enc, player, &camera);
        }));
        parts[3].push(timer.time(ctx, |enc| composite.post(ctx, enc, player, layered)));
    }
    let [update_ms, sort_ms, draw_ms, composite_ms] = parts.map(|mut p| median(&mut p));
    let image = run.render(size)?;
    let row = Row {
        preset: name,
        size: format!("{}x{}", size.0, size.1),
        path: label,
        update_ms,
        sort_ms,
        draw_ms,
        composite_ms,
        frame_ms: update_ms + sort_ms + draw_ms + composite_ms,
        diff_mean: 0.0,
        diff_max: 0,
    };
    Ok((row, image))
}

fn report(ctx: &GpuContext, timer: &GpuTimer, opts: &PresetsOptions, rows: &[Row]) -> Report {
    let mut r = Report::new("ignis presets: what the shipped effects cost", ctx);
    r.para(&format!(
        "Each preset in steady state (played past its last burst and longest lifetime at \
         60 fps; an effect of bursts alone a quarter of its longest lifetime after its last \
         burst), then 10 untimed frames, then {} frames; medians of each part, timed apart ({:?}): update, sort + \
         splat + the tiles' project, bin and shade (the player's record), particle draws \
         (billboards, the splat's and the tiles' composite into the target), composite \
         (bloom + tonemap). `frame` is their sum. `auto` is the preset's own draw-path \
         choice; `billboard`, `splat` and `tiles` force every emitter onto one path (same \
         process, same run). The last column compares the next frame's image with the \
         billboards' (8-bit levels).",
        opts.frames, timer.source
    ));
    let table: Vec<Vec<String>> = rows
        .iter()
        .map(|w| {
            vec![
                w.preset.clone(),
                w.size.clone(),
                w.path.to_owned(),
                format!("{:.3}", w.update_ms),
                format!("{:.3}", w.sort_ms),
                format!("{:.3}", w.draw_ms),
                format!("{:.3}", w.composite_ms),
                format!("{:.3}", w.frame_ms),
                format!("{:.2} / {}", w.diff_mean, w.diff_max),
            ]
        })
        .collect();
    r.table(
        &[
            "preset",
            "size",
            "path",
            "update ms",
            "sort + splat + tiles ms",
            "draw ms",
            "composite ms",
            "frame ms",
            "vs billboards (mean / max, of 255)",
        ],
        &table,
    );
    r.json["records"] = serde_json::to_value(rows).unwrap_or_default();
    r
}
