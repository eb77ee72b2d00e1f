//! The `ignis` command line: `edit` (the default), `render`, `export`, `tune`, `check`,
//! `sprites` and `bench`. The binary's `main` calls [`main`].

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context as _, bail};
use clap::{Parser, Subcommand};

mod bench;
use bench::{BenchKind, bench};

use crate::editor::EditOptions;
use crate::editor::window::editor_profile::AdaptSetting;
use crate::effect::Effect;
use crate::gpu::{GpuContext, ProfileKind, ProfileRequest};
use crate::headless::Headless;
use crate::shaders::{ENTRY_FILES, ShaderLibrary};

#[derive(Parser)]
#[command(name = "ignis", version, about = "Design real-time GPU fire effects")]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// The choices that differ between GPUs and software adapters (the runtime's:
    /// timestamps, tile rasteriser, splat density; the editor's: render scale, draft glow,
    /// UI painter, retained window): gpu or software (default: from the adapter's type).
    #[arg(long, global = true)]
    adapter_profile: Option<ProfileArg>,
    /// Set single fields of the adapter profile, comma-separated FIELD=VALUE (fields:
    /// timestamps, render_scale, draft, lean_painter, retained_window, tile_raster,
    /// splat_dense_only).
    #[arg(long, global = true, value_delimiter = ',')]
    adapt: Vec<AdaptSetting>,
}

/// `--adapter-profile`'s values.
#[derive(Clone, Copy, clap::ValueEnum)]
enum ProfileArg {
    Gpu,
    Software,
}

impl From<ProfileArg> for ProfileKind {
    fn from(p: ProfileArg) -> Self {
        match p {
            ProfileArg::Gpu => ProfileKind::Gpu,
            ProfileArg::Software => ProfileKind::Software,
        }
    }
}

/// The headless context, with the profile asked for on the command line.
fn context(profile: &ProfileRequest) -> anyhow::Result<GpuContext> {
    Ok(GpuContext::headless()?.with_request(profile))
}

#[derive(Subcommand)]
enum Command {
    /// Open the editor window (the default when no command is given).
    Edit {
        /// Preset file (default: the embedded campfire).
        preset: Option<PathBuf>,
        /// Render this many frames in the window, then exit (prints the frame times).
        #[arg(long)]
        frames: Option<u32>,
        /// After the last frame, save the window's image (UI included) as a PNG.
        /// Without --frames, exits after 60 frames.
        #[arg(long)]
        screenshot: Option<PathBuf>,
        /// Initial window size in logical pixels, WxH.
        #[arg(long, default_value = "1280x720", value_parser = parse_size)]
        size: (u32, u32),
        /// Shader folder (default: ./shaders if present, else the embedded copies).
        #[arg(long)]
        shader_dir: Option<PathBuf>,
        /// Render the viewport at this fraction of its size, 0.1..=1 (default: the
        /// adapter profile's: 1 on GPUs, 0.5 on software adapters).
        #[arg(long)]
        render_scale: Option<f32>,
        /// With --frames: drain the GPU after each frame stage and print the median time
        /// of each (slower; for finding where the time goes).
        #[arg(long)]
        profile: bool,
        /// Open exactly these panel sections at start, comma-separated (emitter,
        /// randomness, forces, events, time, look, view, stats) — for screenshots.
        #[arg(long, value_delimiter = ',')]
        sections: Option<Vec<String>>,
        /// Select this emitter (by name) at start.
        #[arg(long)]
        select: Option<String>,
        /// Draft viewport: large additive sprites at half resolution, alpha-blended
        /// layers at half theirs (default: on for software adapters, off elsewhere).
        #[arg(long)]
        draft: Option<bool>,
        /// Start with View → Test scene on: a ground, a box and a step in the viewport's
        /// depth (depth collision, soft edges and occlusion against them).
        #[arg(long)]
        test_scene: bool,
        /// Destroy the GPU device after this frame, to test the recovery (the editor
        /// recreates it and keeps the effect).
        #[arg(long, hide = true)]
        lose_device_at: Option<u32>,
        /// With --lose-device-at N: edit the effect twice before the loss and undo once
        /// after it (a recovery test; the report says what it ended with).
        #[arg(long, hide = true)]
        edit_around_loss: bool,
        /// Start Time ▸ Measure this effect at launch over this span, seconds (with
        /// --frames and --screenshot: a picture of its chart).
        #[arg(long)]
        measure_span: Option<f64>,
    },
    /// Write the built-in procedural sprites as PNGs (straight alpha), to start a
    /// texture from, and the built-in six-way smoke maps (linear RTBA/LBFE pairs).
    Sprites {
        /// Output folder.
        #[arg(long, default_value = "sprites")]
        out: PathBuf,
    },
    /// Render PNG frames of an effect headless.
    Render {
        /// Preset file (default: the embedded campfire).
        preset: Option<PathBuf>,
        /// Number of frames to write.
        #[arg(long, default_value_t = 60)]
        frames: u32,
        /// Image size, WxH.
        #[arg(long, default_value = "640x480", value_parser = parse_size)]
        size: (u32, u32),
        /// Output folder.
        #[arg(long, default_value = "frames")]
        out: PathBuf,
        /// Override the preset's seed.
        #[arg(long)]
        seed: Option<u32>,
        /// Simulated frame rate (frames per simulated second).
        #[arg(long, default_value_t = 60.0)]
        fps: f64,
        /// Start at this time (seconds): the frames before it are simulated as fast as
        /// the GPU goes and not written (frame numbers count from time 0).
        #[arg(long, default_value_t = 0.0)]
        start: f64,
        /// Write only the last frame (after simulating all of them).
        #[arg(long)]
        last_only: bool,
        /// Shader folder (default: ./shaders if present, else the embedded copies).
        #[arg(long)]
        shader_dir: Option<PathBuf>,
    },
    /// Export a flipbook or an image sequence for game engines: real alpha, emissive and
    /// motion-vector passes, seamless loops, a JSON sidecar.
    Export(crate::export::cli::ExportArgs),
    /// The speed–accuracy trade on an effect: every setting's image error against a
    /// converged reference next to its cost, the frontier, and the cheapest settings
    /// within a budget as a tuned preset.
    Tune(crate::tune::cli::TuneArgs),
    /// Measure: `accuracy` (integrators' error vs cost), `perf` (throughput), `presets`
    /// (the shipped effects), `runtime` (instances in a host's frame), `export` or
    /// `adapters` (software adaptations).
    Bench {
        #[command(subcommand)]
        kind: BenchKind,
    },
    /// Validate presets and shaders without opening a window.
    Check {
        /// Files or folders (.ron presets, .wgsl shaders). Default: presets/ and shaders/.
        paths: Vec<PathBuf>,
    },
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = crate::export::cli::parse_pair(s)?;
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        return Err(format!("size {s} must be between 1x1 and 16384x16384"));
    }
    Ok((w, h))
}

/// Parses the command line and runs the command (the `ignis` binary's whole `main`); exits
/// with status 1 and the error's chain on stderr when the command fails.
pub fn main() {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = Cli::parse();
    let adapter_profile = ProfileRequest {
        kind: cli.adapter_profile.map(ProfileKind::from),
        settings: AdaptSetting::adapter_settings(&cli.adapt),
    };
    let editor_settings = cli.adapt;
    let result = match cli.command {
        None => edit(EditOptions {
            window_size: (1280, 720),
            adapter_profile,
            editor_settings,
            ..Default::default()
        }),
        Some(Command::Edit {
            preset,
            frames,
            screenshot,
            size,
            shader_dir,
            render_scale,
            profile,
            sections,
            select,
            draft,
            test_scene,
            lose_device_at,
            edit_around_loss,
            measure_span,
        }) => edit(EditOptions {
            frames: frames.or(screenshot.as_ref().map(|_| 60)),
            preset,
            screenshot,
            shader_dir,
            window_size: size,
            render_scale,
            profile,
            sections,
            select,
            draft,
            test_scene,
            lose_device_at,
            edit_around_loss,
            measure_span,
            adapter_profile,
            editor_settings,
        }),
        Some(Command::Render {
            preset,
            frames,
            size,
            out,
            seed,
            fps,
            start,
            last_only,
            shader_dir,
        }) => render(
            preset.as_deref(),
            frames,
            size,
            &out,
            seed,
            (fps, start),
            last_only,
            shader_dir.as_deref(),
            &adapter_profile,
        ),
        Some(Command::Export(args)) => export(&args, &adapter_profile),
        Some(Command::Tune(args)) => tune(&args, &adapter_profile),
        Some(Command::Check { paths }) => check(&paths),
        Some(Command::Sprites { out }) => write_sprites(&out),
        Some(Command::Bench { kind }) => bench(kind, &adapter_profile),
    };
    if let Err(err) = result {
        eprintln!("error: {err:#}");
        std::process::exit(1);
    }
}

fn edit(options: EditOptions) -> anyhow::Result<()> {
    if options.frames == Some(0) {
        bail!("--frames must be at least 1");
    }
    if let Some(s) = options.render_scale
        && !(s.is_finite() && (0.1..=1.0).contains(&s))
    {
        bail!("--render-scale must be between 0.1 and 1, got {s}");
    }
    if let Some(report) = crate::editor::run(options)? {
        println!("{report}");
    }
    Ok(())
}

fn load_effect(preset: Option<&Path>) -> anyhow::Result<Effect> {
    match preset {
        Some(p) => Ok(crate::preset::load(p)?),
        None => Ok(Effect::default_campfire()),
    }
}

#[allow(clippy::too_many_arguments)]
fn render(
    preset: Option<&Path>,
    frames: u32,
    size: (u32, u32),
    out: &Path,
    seed: Option<u32>,
    (fps, start): (f64, f64),
    last_only: bool,
    shader_dir: Option<&Path>,
    profile: &ProfileRequest,
) -> anyhow::Result<()> {
    if !(fps.is_finite() && fps > 0.0) {
        bail!("--fps must be a positive number, got {fps}");
    }
    if !(start.is_finite() && (0.0..=86_400.0).contains(&start)) {
        bail!("--start must be a time in seconds between 0 and 86400, got {start}");
    }
    if start * fps > 10_000_000.0 {
        bail!("--start {start} at --fps {fps} is more than 10 million frames to simulate");
    }
    let mut effect = load_effect(preset)?;
    if let Some(s) = seed {
        effect.seed = s;
    }
    let ctx = context(profile)?;
    let lib = ShaderLibrary::discover(shader_dir);
    // PNG sprites are relative to the preset file.
    let settings = crate::PlayerSettings {
        asset_dir: preset.and_then(Path::parent).map(Path::to_path_buf),
        ..crate::composite::Composite::player_settings()
    };
    let mut run = Headless::with_settings(&ctx, effect, lib, settings)?;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    // The frames before --start: simulated, not written.
    let skipped = run.seek(start, 1.0 / fps);
    let start = Instant::now();
    let mut written = 0;
    // Simulate + draw + read back, per written frame (PNG encoding excluded).
    let mut frame_ms = Vec::new();
    for f in 0..frames {
        let t = Instant::now();
        run.advance(1.0 / fps);
        if !last_only || f + 1 == frames {
            let image = run.render(size)?;
            frame_ms.push(t.elapsed().as_secs_f64() * 1000.0);
            let path = out.join(format!("frame_{:04}.png", skipped + u64::from(f)));
            image
                .save(&path)
                .with_context(|| format!("writing {}", path.display()))?;
            written += 1;
        }
    }
    let elapsed = start.elapsed().as_secs_f64();
    println!(
        "rendered {frames} frames ({written} written to {}) of \"{}\" at {}x{}: {} particles \
            alive, {:.2} ms per frame on {}",
        out.display(),
        run.effect().name,
        size.0,
        size.1,
        run.alive()?,
        elapsed * 1000.0 / frames.max(1) as f64,
        ctx.info.name
    );
    if frame_ms.len() >= 10 {
        // The steady state: the last 30 written frames.
        let tail = frame_ms.len().saturating_sub(30);
        let mut last = frame_ms[tail..].to_vec();
        let median = crate::gpu::timer::median(&mut last);
        println!(
            "last {} frames: median {median:.2} ms simulate + draw + read back ({:.1} fps), PNG \
                writing excluded",
            last.len(),
            1000.0 / median
        );
    }
    Ok(())
}

/// `ignis tune`: the options and the preset checked first (nothing is written on a bad
/// one), the sweep with a progress bar, the table, then the files.
fn tune(args: &crate::tune::cli::TuneArgs, profile: &ProfileRequest) -> anyhow::Result<()> {
    let budget = args.budget()?;
    let effect = crate::preset::load(&args.preset)?;
    let opts = args.options(&effect)?;
    let ctx = context(profile)?;
    let mut sweep = crate::tune::Sweep::new(&ctx, &effect, opts)?;
    let bar = indicatif::ProgressBar::new(1).with_style(
        indicatif::ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} frames {elapsed}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar.set_message(format!("tuning \"{}\"", effect.name));
    let start = Instant::now();
    crate::tune::run_sweep(&mut sweep, |done, total| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
    })?;
    bar.finish_and_clear();
    for (label, why) in &sweep.skipped {
        eprintln!("skipped {label}: {why}");
    }
    let report = crate::tune::TuneReport::new(&sweep, budget, &ctx.info.name)?;
    println!("{}", report.markdown());
    let files = report.write(&effect, &args.out)?;
    if let Some(e) = report.over_budget() {
        bail!("{e} (the measurements are in {})", args.out.display());
    }
    println!(
        "{} candidates in {:.1} s on {}; wrote {}",
        report.results.len(),
        start.elapsed().as_secs_f64(),
        ctx.info.name,
        files
            .iter()
            .map(|f| f.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    );
    Ok(())
}

fn export(args: &crate::export::cli::ExportArgs, profile: &ProfileRequest) -> anyhow::Result<()> {
    let settings = args.settings().map_err(anyhow::Error::msg)?;
    let effect = load_effect(args.preset.as_deref())?;
    let ctx = context(profile)?;
    let asset_dir = args
        .preset
        .as_deref()
        .and_then(Path::parent)
        .map(Path::to_path_buf);
    let bar = indicatif::ProgressBar::new(1).with_style(
        indicatif::ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} {elapsed}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar.set_message(format!("exporting \"{}\"", effect.name));
    let start = Instant::now();
    let summary = crate::export::run(&ctx, &effect, asset_dir, settings, |p| {
        bar.set_length(u64::from(p.total));
        bar.set_position(u64::from(p.done));
    })?;
    bar.finish_and_clear();
    let s = &summary.sidecar;
    println!(
        "exported {} frames of \"{}\" ({}x{}, {}) to {} in {:.2} s on {}: {}",
        s.frame_count,
        s.preset,
        s.frame_width,
        s.frame_height,
        s.passes.join(", "),
        args.out.display(),
        start.elapsed().as_secs_f64(),
        ctx.info.name,
        summary
            .files
            .iter()
            .filter_map(|f| f.file_name())
            .map(|f| f.to_string_lossy().into_owned())
            .collect::<Vec<_>>()
            .join(" ")
    );
    println!(
        "seam: last → first frame {:.2}, consecutive frames {:.2} (median, 8-bit steps){}",
        s.seam.last_to_first,
        s.seam.median_consecutive,
        if s.looped { ", looped" } else { "" }
    );
    Ok(())
}

/// A file-name-safe tag for the adapter ("llvmpipe", "nvidia-h100-…").
fn adapter_tag(ctx: &GpuContext) -> String {
    let name: String = ctx
        .info
        .name
        .to_lowercase()
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
        .collect();
    name.split('-')
        .filter(|s| !s.is_empty())
        .take(3)
        .collect::<Vec<_>>()
        .join("-")
}

/// Prints a bench report and writes it as `out/NAME.md` and `.json` (NAME defaults to
/// `KIND-<adapter>`).
fn save_report(
    report: &crate::bench::Report,
    out: &Path,
    name: Option<String>,
    kind: &str,
    ctx: &GpuContext,
) -> anyhow::Result<()> {
    let name = name.unwrap_or_else(|| format!("{kind}-{}", adapter_tag(ctx)));
    report.save(out, &name)?;
    println!("{}", report.markdown);
    println!("wrote {}/{name}.md and .json", out.display());
    Ok(())
}

/// The preset files of `paths` (folders listed; `presets/` when none are given).
fn preset_files(paths: Vec<PathBuf>) -> Vec<PathBuf> {
    let paths = if paths.is_empty() {
        vec![PathBuf::from("presets")]
    } else {
        paths
    };
    paths
        .iter()
        .flat_map(|p| {
            if p.is_dir() {
                crate::preset::list(p)
            } else {
                vec![p.clone()]
            }
        })
        .collect()
}

fn check(paths: &[PathBuf]) -> anyhow::Result<()> {
    let paths: Vec<PathBuf> = if paths.is_empty() {
        vec![PathBuf::from("presets"), PathBuf::from("shaders")]
    } else {
        paths.to_vec()
    };
    let mut presets = Vec::new();
    let mut shader_dirs = Vec::new();
    for p in &paths {
        if p.is_dir() {
            presets.extend(crate::preset::list(p));
            if std::fs::read_dir(p)?
                .flatten()
                .any(|e| e.path().extension().is_some_and(|x| x == "wgsl"))
            {
                shader_dirs.push(p.clone());
            }
        } else if p.extension().is_some_and(|x| x == "wgsl") {
            shader_dirs.push(p.parent().unwrap_or(Path::new(".")).to_path_buf());
        } else if p.exists() {
            presets.push(p.clone());
        } else {
            bail!("{}: no such file or folder", p.display());
        }
    }
    shader_dirs.sort();
    shader_dirs.dedup();
    let mut failures = 0;
    for p in &presets {
        match crate::preset::load(p) {
            Ok(e) => {
                println!("ok   {} ({} emitters)", p.display(), e.emitters.len());
                // Valid but unstable at its step: a warning, not a failure.
                for w in e.stability_warnings() {
                    eprintln!("WARN {}: {w}", p.display());
                }
            }
            Err(e) => {
                failures += 1;
                eprintln!("FAIL {e}");
            }
        }
    }
    for dir in &shader_dirs {
        let lib = ShaderLibrary::from_dir(dir);
        for entry in ENTRY_FILES {
            match lib.compose(entry) {
                Ok(c) => println!("ok   {} ({} files)", lib.display_path(entry), c.files.len()),
                Err(e) => {
                    failures += 1;
                    eprintln!("FAIL {e}");
                }
            }
        }
    }
    if failures > 0 {
        bail!(
            "{failures} of {} checks failed",
            presets.len() + shader_dirs.len() * ENTRY_FILES.len()
        );
    }
    println!(
        "checked {} presets and {} shader folders: all valid",
        presets.len(),
        shader_dirs.len()
    );
    Ok(())
}

/// `ignis sprites`: the built-in sprites and six-way smoke maps as PNGs.
fn write_sprites(out: &Path) -> anyhow::Result<()> {
    for path in crate::render::sprites::write_built_ins(out)? {
        println!("wrote {}", path.display());
    }
    Ok(())
}
