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
use crate::gpu::timer::{GpuTimer, PassTimer, median};
use crate::headless::Headless;
use crate::render::tiles::TileStages;
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
    /// Passes over every row (each row reports its fastest pass).
    pub passes: usize,
    /// Where to save a close-up of the largest difference of each row whose image
    /// differs from the billboards' by more than 8/255 (none when `None`).
    pub diff_crops: Option<PathBuf>,
    /// Time the parts of each frame inside one submission per frame, frames back to back
    /// (as a frame loop runs them), instead of each part apart with the GPU idle between.
    pub pipelined: bool,
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
    /// The frame of every pass, ms (the row's parts are its fastest pass's).
    pass_frame_ms: Vec<f64>,
    /// Where the row draws some of its layers on the tiles: the record timed apart with
    /// the tiles stopped after each stage, as what each stage adds (ms): up to the
    /// projection (with the sort and the splat), the binning, the shade.
    tile_stages_ms: Option<[f64; 3]>,
}

/// Frames run before the timed ones of each row.
const UNTIMED_FRAMES: usize = 10;

/// What a row takes away from the preset, to measure what it costs in the same run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Without {
    /// Nothing: the preset as it is.
    Nothing,
    /// Lit layers drawn unlit (`lit: None`).
    Lighting,
    /// The heat-haze layers removed (no distortion target, no refraction).
    Haze,
}

impl Without {
    /// Whether `effect` has what this takes away (the row is measured only then).
    fn applies_to(self, effect: &Effect) -> bool {
        let any = |f: fn(&crate::effect::Emitter) -> bool| effect.emitters.iter().any(f);
        match self {
            Self::Nothing => true,
            Self::Lighting => any(|e| e.look.lit.is_some()),
            Self::Haze => any(|e| e.look.heat_haze.is_some()),
        }
    }

    /// `effect` without it.
    fn strip(self, effect: &mut Effect) {
        match self {
            Self::Nothing => {}
            Self::Lighting => effect.emitters.iter_mut().for_each(|e| e.look.lit = None),
            Self::Haze => effect.emitters.retain(|e| e.look.heat_haze.is_none()),
        }
    }
}

/// The path choices measured: a label, the path forced on every emitter, and what is
/// taken away (measured only for presets that have it: its cost is the full rows' minus
/// these, in one run). The billboards first: the other paths' images are compared with
/// theirs.
const PATHS: [(&str, Option<DrawPath>, Without); 8] = [
    ("billboard", Some(DrawPath::Billboard), Without::Nothing),
    ("auto", None, Without::Nothing),
    ("splat", Some(DrawPath::Splat), Without::Nothing),
    ("tiles", Some(DrawPath::Tiles), Without::Nothing),
    (
        "billboard unlit",
        Some(DrawPath::Billboard),
        Without::Lighting,
    ),
    ("tiles unlit", Some(DrawPath::Tiles), Without::Lighting),
    (
        "billboard no haze",
        Some(DrawPath::Billboard),
        Without::Haze,
    ),
    ("auto no haze", None, Without::Haze),
];

/// Runs every preset, size and path, `opts.passes` times over.
pub fn run(ctx: &GpuContext, opts: &PresetsOptions) -> Result<Report, PlayerError> {
    let timer = GpuTimer::new(ctx);
    let effects: Vec<(&PathBuf, Effect)> = opts
        .presets
        .iter()
        .filter_map(|path| match crate::preset::load(path) {
            Ok(e) => Some((path, e)),
            Err(e) => {
                log::warn!("skipping {}: {e}", path.display());
                None
            }
        })
        .collect();
    // The first preset's rows are measured once and dropped: a process's first rows
    // were up to twice as slow on the H100 (first use of each path's pipelines and
    // memory, the GPU's clocks).
    if let (Some((path, effect)), Some(&size)) = (effects.first(), opts.sizes.first()) {
        for choice in PATHS.into_iter().filter(|c| c.2.applies_to(effect)) {
            measure(ctx, &timer, path, effect, size, choice, opts)?;
        }
    }
    // Passes over the whole run: the lent H100 has slow states that double every part of
    // a frame for seconds at a time; a row's fastest pass is its own cost.
    let mut rows: Vec<Row> = Vec::new();
    for pass in 0..opts.passes.max(1) {
        let mut k = 0;
        for (path, effect) in &effects {
            for &size in &opts.sizes {
                let mut reference = None;
                for (label, forced, without) in PATHS {
                    if !without.applies_to(effect) {
                        continue;
                    }
                    let (mut row, mut run) = measure(
                        ctx,
                        &timer,
                        path,
                        effect,
                        size,
                        (label, forced, without),
                        opts,
                    )?;
                    println!(
                        "pass {pass}: {} {}x{} {label}: frame {:.3} ms",
                        row.preset, size.0, size.1, row.frame_ms
                    );
                    if pass == 0 {
                        // Images are deterministic: the first pass compares them.
                        let image = run.render(size)?;
                        let reference = reference.get_or_insert(image.clone());
                        (row.diff_mean, row.diff_max) = image_diff(reference, &image);
                        if row.diff_max > 8 && without == Without::Nothing {
                            report_difference(reference, &image, &row, opts);
                        }
                        row.pass_frame_ms = vec![row.frame_ms];
                        rows.push(row);
                    } else if let Some(kept) = rows.get_mut(k) {
                        keep_fastest(kept, row);
                    }
                    k += 1;
                }
            }
        }
    }
    Ok(report(ctx, &timer, opts, &rows))
}

/// Adds a later pass's `row` to `kept`: its frame to the list, and its parts when faster.
fn keep_fastest(kept: &mut Row, mut row: Row) {
    let mut passes = std::mem::take(&mut kept.pass_frame_ms);
    passes.push(row.frame_ms);
    if row.frame_ms < kept.frame_ms {
        (row.diff_mean, row.diff_max) = (kept.diff_mean, kept.diff_max);
        *kept = row;
    }
    kept.pass_frame_ms = passes;
}

/// Prints where `image` differs most from `reference` and, when asked, saves a close-up
/// of both (side by side, 8× enlarged) into `opts.diff_crops`.
fn report_difference(
    reference: &image::RgbaImage,
    image: &image::RgbaImage,
    row: &Row,
    opts: &PresetsOptions,
) {
    let (mut at, mut worst, mut over) = ((0, 0), 0u8, 0usize);
    for (x, y, p) in image.enumerate_pixels() {
        let q = reference.get_pixel(x, y);
        let d =
            p.0.iter()
                .zip(q.0)
                .map(|(a, b)| a.abs_diff(b))
                .max()
                .unwrap_or(0);
        over += usize::from(d > 8);
        if d > worst {
            (at, worst) = ((x, y), d);
        }
    }
    println!(
        "  {} {} {}: {over} pixels over 8/255, the largest {worst}/255 at {at:?}: {:?} \
            (billboards {:?})",
        row.preset,
        row.size,
        row.path,
        image.get_pixel(at.0, at.1).0,
        reference.get_pixel(at.0, at.1).0
    );
    let Some(dir) = &opts.diff_crops else {
        return;
    };
    const SIDE: u32 = 24;
    let x0 =
        at.0.saturating_sub(SIDE / 2)
            .min(image.width().saturating_sub(SIDE));
    let y0 =
        at.1.saturating_sub(SIDE / 2)
            .min(image.height().saturating_sub(SIDE));
    let crop = |img: &image::RgbaImage| {
        let c = image::imageops::crop_imm(img, x0, y0, SIDE, SIDE).to_image();
        image::imageops::resize(&c, SIDE * 8, SIDE * 8, image::imageops::FilterType::Nearest)
    };
    let mut pair = image::RgbaImage::new(SIDE * 16 + 8, SIDE * 8);
    image::imageops::overlay(&mut pair, &crop(reference), 0, 0);
    image::imageops::overlay(&mut pair, &crop(image), i64::from(SIDE * 8 + 8), 0);
    let name = format!(
        "{}-{}-{}.png",
        row.preset.replace(' ', "_"),
        row.size,
        row.path
    );
    if let Err(e) = std::fs::create_dir_all(dir)
        .and_then(|()| pair.save(dir.join(&name)).map_err(std::io::Error::other))
    {
        log::warn!("could not save {name}: {e}");
    }
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

/// One row, and the player it ran (its next frame is the same simulated moment for
/// every path: the image the rows compare).
fn measure(
    ctx: &GpuContext,
    timer: &GpuTimer,
    path: &Path,
    effect: &Effect,
    size: (u32, u32),
    (label, forced, without): (&'static str, Option<DrawPath>, Without),
    opts: &PresetsOptions,
) -> Result<(Row, Headless), PlayerError> {
    let mut effect = effect.clone();
    without.strip(&mut effect);
    for e in &mut effect.emitters {
        if let Some(p) = forced {
            e.look.draw_path = p;
        }
    }
    let settings = crate::PlayerSettings {
        asset_dir: path.parent().map(Path::to_path_buf),
        ..crate::composite::Composite::player_settings()
    };
    let name = effect.name.clone();
    let mut run =
        Headless::with_settings(ctx, effect.clone(), ShaderLibrary::discover(None), settings)?;
    for _ in 0..warm_up_frames(&effect) {
        run.advance(1.0 / 60.0);
    }
    let camera = run.camera.view(size);
    let parts = match PassTimer::new(ctx).filter(|_| opts.pipelined) {
        Some(mut pass_timer) => pipelined_parts(&mut run, &mut pass_timer, &camera, opts.frames),
        None => apart_parts(&mut run, timer, &camera, opts.frames),
    };
    let [update_ms, sort_ms, draw_ms, composite_ms] = parts.map(|mut p| median(&mut p));
    let tile_stages_ms = tile_stages(&mut run, timer, &camera, opts.frames);
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
        pass_frame_ms: Vec::new(),
        tile_stages_ms,
    };
    Ok((row, run))
}

/// What each of the tiles' stages adds to the record (ms: up to the projection, the
/// binning, the shade; medians of `frames` records of the state the row's frames left,
/// each timed apart), where some of the frame's layers are on the tiles.
fn tile_stages(
    run: &mut Headless,
    timer: &GpuTimer,
    camera: &crate::render::Camera,
    frames: usize,
) -> Option<[f64; 3]> {
    if !run.player.draw_items().iter().any(|d| d.tiles) {
        return None;
    }
    let mut upto = [0.0; 3];
    for (ms, stages) in upto
        .iter_mut()
        .zip([TileStages::Project, TileStages::Bin, TileStages::All])
    {
        run.player.tile_pass()?.set_stages(stages);
        let mut times: Vec<f64> = (0..frames.max(1))
            .map(|_| {
                timer.time(&run.ctx, |enc| {
                    run.composite
                        .record_player(enc, &mut run.player, camera, None)
                })
            })
            .collect();
        *ms = median(&mut times);
    }
    Some([upto[0], upto[1] - upto[0], upto[2] - upto[1]])
}

/// Each part's times over `frames` frames after `UNTIMED_FRAMES` untimed ones (the steps
/// the warm-up planned, and the GPU's clocks up from idle), each part timed apart.
fn apart_parts(
    run: &mut Headless,
    timer: &GpuTimer,
    camera: &crate::render::Camera,
    frames: usize,
) -> [Vec<f64>; 4] {
    let mut parts: [Vec<f64>; 4] = Default::default();
    for frame in 0..frames + UNTIMED_FRAMES {
        if frame == UNTIMED_FRAMES {
            parts = Default::default();
        }
        let times = run.timed_frame(timer, 1.0 / 60.0, camera);
        for (p, t) in parts.iter_mut().zip(times) {
            p.push(t);
        }
    }
    parts
}

/// Each part's times as [`apart_parts`] gives them, from the same number of frames
/// submitted back to back ([`Headless::pipelined_frame`]; the images the rows compare are
/// then of the same moment): the frames the pass timer's ring had room for, after the
/// untimed ones.
fn pipelined_parts(
    run: &mut Headless,
    timer: &mut PassTimer,
    camera: &crate::render::Camera,
    frames: usize,
) -> [Vec<f64>; 4] {
    let mut parts: [Vec<f64>; 4] = Default::default();
    // Measurements completed before this count are the untimed frames'.
    let mut seen = u64::MAX;
    let keep = |timer: &PassTimer, seen: &mut u64, parts: &mut [Vec<f64>; 4]| {
        if timer.completed != *seen {
            *seen = timer.completed;
            for (p, (_, ms)) in parts.iter_mut().zip(&timer.latest) {
                p.push(*ms);
            }
        }
    };
    for frame in 0..frames + UNTIMED_FRAMES {
        run.pipelined_frame(timer, 1.0 / 60.0, camera);
        if frame == UNTIMED_FRAMES {
            seen = timer.completed;
        } else if frame > UNTIMED_FRAMES {
            keep(timer, &mut seen, &mut parts);
        }
    }
    let _ = run.ctx.device.poll(wgpu::PollType::wait_indefinitely());
    timer.poll(&run.ctx);
    keep(timer, &mut seen, &mut parts);
    parts
}

fn report(ctx: &GpuContext, timer: &GpuTimer, opts: &PresetsOptions, rows: &[Row]) -> Report {
    let mut r = Report::new("ignis presets: what the shipped effects cost", ctx);
    r.para(&format!(
        "Each preset in steady state (played past its last burst and longest lifetime at \
         60 fps; an effect of bursts alone a quarter of its longest lifetime after its last \
         burst), then 10 untimed frames, then {} frames; medians of each part, {} ({:?}): update, sort + \
         splat + the tiles' project, bin and shade (the player's record), particle draws \
         (billboards, the splat's and the tiles' composite into the target), composite \
         (heat haze + bloom + tonemap). `frame` is their sum. `auto` is the preset's own draw-path \
         choice; `billboard`, `splat` and `tiles` force every emitter onto one path (same \
         process, same run); for presets with lit smoke, `billboard unlit` and `tiles \
         unlit` draw it unlit (no six-way shading, no light pass): the lit layers' cost is \
         the difference; for presets with heat haze, `billboard no haze` and `auto no haze` \
         remove its layers (no distortion target, no refraction): the haze costs the \
         difference. Every row is measured in {} passes over the whole run (the \
         lent H100 has slow states that double every part of a frame for seconds at a time): \
         the parts shown are the row's fastest pass's, and every pass's frame is listed. The \
         last column compares the next frame's image with the billboards' (8-bit levels; the \
         first pass's, images are deterministic). Where a row draws on the tiles, the \
         record is timed again, apart, with the tiles stopped after each stage: what the \
         projection (with the sort and the splat before it), the binning and the shade each \
         add.",
        opts.frames,
        if opts.pipelined && PassTimer::available(ctx) {
            "timed inside one submission per frame, frames submitted back to back as a frame \
             loop runs them (`--pipelined`)"
        } else {
            "each part timed apart (submitted alone, the GPU idle between)"
        },
        timer.source,
        opts.passes.max(1)
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
                w.pass_frame_ms
                    .iter()
                    .map(|ms| format!("{ms:.2}"))
                    .collect::<Vec<_>>()
                    .join(" / "),
                format!("{:.2} / {}", w.diff_mean, w.diff_max),
                w.tile_stages_ms.map_or("-".to_owned(), |[p, b, s]| {
                    format!("{p:.3} / {b:.3} / {s:.3}")
                }),
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
            "frame ms of each pass",
            "vs billboards (mean / max, of 255)",
            "tiles: to project / bin / shade ms",
        ],
        &table,
    );
    r.json["records"] = serde_json::to_value(rows).unwrap_or_default();
    r
}
