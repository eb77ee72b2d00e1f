//! `ignis bench …`: the bench kinds' arguments, and each bench run and its report saved.

use std::path::{Path, PathBuf};

use super::{adapter_tag, context, parse_size, preset_files, save_report};
use crate::gpu::ProfileRequest;

#[derive(clap::Subcommand)]
pub(super) enum BenchKind {
    /// Every shipped preset in steady state at 1080p and 4K: update, sort, draw and
    /// composite times, with each draw path forced in the same run.
    Presets {
        /// Preset files or folders (default: presets/).
        paths: Vec<PathBuf>,
        /// Render sizes, comma-separated WxH.
        #[arg(long, value_delimiter = ',', default_value = "1920x1080,3840x2160", value_parser = parse_size)]
        sizes: Vec<(u32, u32)>,
        /// Timed frames per row (medians are reported).
        #[arg(long, default_value_t = 15)]
        frames: usize,
        /// Passes over every row (each row reports its fastest pass).
        #[arg(long, default_value_t = 3)]
        passes: usize,
        /// Save a close-up of where a path's image differs from the billboards' by more
        /// than 8/255 into this folder.
        #[arg(long)]
        diff_crops: Option<PathBuf>,
        /// Time each frame's parts inside one submission, frames back to back (as a frame
        /// loop runs them; GPU timestamps only), not each part apart with the GPU idle
        /// between: a GPU that lowers its clocks when idle is then measured at work.
        #[arg(long)]
        pipelined: bool,
        /// Output folder.
        #[arg(long, default_value = "bench/results")]
        out: PathBuf,
        /// File name stem (default: presets-<adapter>).
        #[arg(long)]
        name: Option<String>,
    },
    /// What each software-adapter adaptation takes off the editor's frame: interleaved
    /// editor runs with and without it (needs a display: run under xvfb-run).
    Adapters {
        /// The preset the editor opens (default: the embedded campfire).
        preset: Option<PathBuf>,
        /// Frames per editor run.
        #[arg(long, default_value_t = 90)]
        frames: u32,
        /// Interleaved rounds.
        #[arg(long, default_value_t = 5)]
        rounds: usize,
        /// Window size, WxH.
        #[arg(long, default_value = "1280x720", value_parser = parse_size)]
        size: (u32, u32),
        /// Output folder.
        #[arg(long, default_value = "bench/results")]
        out: PathBuf,
        /// File name stem (default: adapters-<adapter>).
        #[arg(long)]
        name: Option<String>,
    },
    /// How long exports take: an 8×8 flipbook of 256² frames, 120 frames at 1080p.
    Export {
        /// The effect exported (default: presets/campfire.ron).
        #[arg(long, default_value = "presets/campfire.ron")]
        preset: PathBuf,
        /// Output folder.
        #[arg(long, default_value = "bench/results")]
        out: PathBuf,
        /// File name stem (default: export-<adapter>).
        #[arg(long)]
        name: Option<String>,
    },
    /// The runtime's cost in a host frame for 1, 10, 100 instances, and 100 instances
    /// against one emitter with the same particles.
    Runtime {
        /// The effect played (default: presets/torch.ron).
        #[arg(long, default_value = "presets/torch.ron")]
        preset: PathBuf,
        /// Instance counts.
        #[arg(long, value_delimiter = ',', default_value = "1,10,100")]
        counts: Vec<u32>,
        /// The host's target size, WxH.
        #[arg(long, default_value = "1920x1080", value_parser = parse_size)]
        size: (u32, u32),
        /// Measured frames per row (the median is reported).
        #[arg(long, default_value_t = 15)]
        frames: usize,
        /// Output folder.
        #[arg(long, default_value = "bench/results")]
        out: PathBuf,
        /// File name stem (default: runtime-<adapter>).
        #[arg(long)]
        name: Option<String>,
    },
    /// Error against exact / high-precision references, next to GPU cost, per integrator and dt.
    Accuracy {
        /// Particles per error run.
        #[arg(long, default_value_t = 2048)]
        particles: u32,
        /// Particles for the cost runs (0 = 1M on a CPU adapter, 16M on a GPU).
        #[arg(long, default_value_t = 0)]
        cost_capacity: u32,
        /// Timed repeats per cost point (the median is reported).
        #[arg(long, default_value_t = 5)]
        repeats: usize,
        /// Output folder for the Markdown, JSON, CSV and SVG files.
        #[arg(long, default_value = "bench/results")]
        out: PathBuf,
        /// File name stem (default: accuracy-<adapter>).
        #[arg(long)]
        name: Option<String>,
    },
    /// Update / draw / composite throughput from 64² particles to the device's limit.
    Perf {
        /// Texture sides (capacity = side²); default: the thesis's 64…4096, and beyond on a GPU.
        #[arg(long, value_delimiter = ',')]
        sides: Vec<u32>,
        /// Render resolution, WxH.
        #[arg(long, default_value = "1920x1080", value_parser = parse_size)]
        size: (u32, u32),
        /// Timed repeats (the median is reported).
        #[arg(long, default_value_t = 7)]
        repeats: usize,
        /// Particles for the module-cost table (0 = 1M on a CPU adapter, 16M on a GPU).
        #[arg(long, default_value_t = 0)]
        module_capacity: u32,
        /// Output folder.
        #[arg(long, default_value = "bench/results")]
        out: PathBuf,
        /// File name stem (default: perf-<adapter>).
        #[arg(long)]
        name: Option<String>,
    },
}

pub(super) fn bench(kind: BenchKind, profile: &ProfileRequest) -> anyhow::Result<()> {
    let ctx = context(profile)?;
    match kind {
        BenchKind::Presets {
            paths,
            sizes,
            frames,
            passes,
            diff_crops,
            pipelined,
            out,
            name,
        } => {
            let opts = crate::bench::presets::PresetsOptions {
                presets: preset_files(paths),
                sizes,
                frames: frames.max(1),
                passes: passes.max(1),
                diff_crops,
                pipelined,
            };
            let report = crate::bench::presets::run(&ctx, &opts)?;
            save_report(&report, &out, name, "presets", &ctx)?;
        }
        BenchKind::Adapters {
            preset,
            frames,
            rounds,
            size,
            out,
            name,
        } => {
            let opts = crate::bench::adapters::AdaptersOptions {
                preset,
                frames: frames.max(10),
                rounds: rounds.max(1),
                size,
            };
            let report = crate::bench::adapters::run(&ctx, &opts)?;
            save_report(&report, &out, name, "adapters", &ctx)?;
        }
        BenchKind::Export { preset, out, name } => {
            let effect = crate::preset::load(&preset)?;
            let asset_dir = preset.parent().map(Path::to_path_buf);
            let report = crate::bench::export::run(&ctx, &effect, asset_dir)?;
            save_report(&report, &out, name, "export", &ctx)?;
        }
        BenchKind::Runtime {
            preset,
            counts,
            size,
            frames,
            out,
            name,
        } => {
            let opts = crate::bench::runtime::RuntimeOptions {
                effect: crate::preset::load(&preset)?,
                asset_dir: preset.parent().unwrap_or(Path::new(".")).to_path_buf(),
                counts,
                size,
                frames: frames.max(1),
            };
            let report = crate::bench::runtime::run(&ctx, &opts)?;
            save_report(&report, &out, name, "runtime", &ctx)?;
        }
        BenchKind::Accuracy {
            particles,
            cost_capacity,
            repeats,
            out,
            name,
        } => {
            let opts = crate::bench::accuracy::AccuracyOptions {
                particles: particles.max(16),
                cost_capacity,
                repeats: repeats.max(1),
            };
            accuracy(&ctx, &opts, &out, name)?;
        }
        BenchKind::Perf {
            sides,
            size,
            repeats,
            module_capacity,
            out,
            name,
        } => {
            let opts = crate::bench::perf::PerfOptions::for_adapter(
                &ctx,
                sides,
                size,
                repeats,
                module_capacity,
            );
            let report = crate::bench::perf::run(&ctx, &opts)?;
            save_report(&report, &out, name, "perf", &ctx)?;
        }
    }
    Ok(())
}

/// `ignis bench accuracy`: the report beside its CSV and plot.
fn accuracy(
    ctx: &crate::gpu::GpuContext,
    opts: &crate::bench::accuracy::AccuracyOptions,
    out: &Path,
    name: Option<String>,
) -> anyhow::Result<()> {
    let report = crate::bench::accuracy::run(ctx, opts, out)?;
    let name = name.unwrap_or_else(|| format!("accuracy-{}", adapter_tag(ctx)));
    report.save(out, &name)?;
    println!("{}", report.markdown);
    println!(
        "wrote {}/{name}.md, .json, accuracy.csv, accuracy.svg",
        out.display()
    );
    Ok(())
}
