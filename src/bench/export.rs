//! `ignis bench export`: how long exports take — an 8×8 flipbook of 256² frames and a
//! sequence of 120 1080p frames (colour only, then with the emissive and motion passes),
//! wall time of the whole export (framing, rendering, encoding, writing) into a
//! temporary folder.

use std::time::Instant;

use crate::bench::Report;
use crate::effect::Effect;
use crate::export::{ExportError, ExportSettings, Layout, Passes};
use crate::gpu::GpuContext;

/// One measured export.
struct Row {
    label: String,
    frames: u32,
    secs: f64,
}

/// Runs the bench on `effect` (sprites relative to `asset_dir`) and returns its report.
pub fn run(
    ctx: &GpuContext,
    effect: &Effect,
    asset_dir: Option<std::path::PathBuf>,
) -> Result<Report, ExportError> {
    let dir = std::env::temp_dir().join(format!("ignis-bench-export-{}", std::process::id()));
    let all = Passes {
        color: true,
        emissive: true,
        motion: true,
        sixway: false,
        distortion: false,
    };
    let mut configs = Vec::new();
    for passes in [Passes::COLOR, all] {
        let names = passes.names().join(" + ");
        let mut book = ExportSettings::new(dir.join("book"));
        book.passes = passes;
        configs.push((format!("8×8 flipbook of 256×256 frames, {names}"), book));
        let mut seq = ExportSettings::new(dir.join("seq"));
        seq.layout = Layout::Sequence;
        seq.frame_size = (1920, 1080);
        seq.frames = Some(120);
        seq.passes = passes;
        configs.push((format!("120 frames of 1920×1080, {names}"), seq));
    }
    // Build the pipelines (every pass) once before timing anything.
    let mut warm = ExportSettings::new(dir.join("warm"));
    warm.frame_size = (32, 32);
    warm.frames = Some(1);
    warm.passes = all;
    crate::export::run(ctx, effect, asset_dir.clone(), warm, |_| {})?;
    let mut rows = Vec::new();
    for (label, settings) in configs {
        let frames = settings.frame_count();
        let start = Instant::now();
        crate::export::run(ctx, effect, asset_dir.clone(), settings, |_| {})?;
        rows.push(Row {
            label,
            frames,
            secs: start.elapsed().as_secs_f64(),
        });
        let _ = std::fs::remove_dir_all(&dir);
    }
    let mut r = Report::new("ignis export: how long an export takes", ctx);
    r.para(&format!(
        "`{}`, seed {}, camera fitted to the span, premultiplied 8-bit PNG. Wall time of the \
            whole export: sampling the span, rendering it small to frame it, rendering every \
            frame, reading it back, encoding and writing the files (after one small export has \
            built the pipelines).",
        effect.name, effect.seed
    ));
    let table: Vec<Vec<String>> = rows
        .iter()
        .map(|x| {
            vec![
                x.label.clone(),
                format!("{:.2}", x.secs),
                format!("{:.1}", 1e3 * x.secs / f64::from(x.frames.max(1))),
            ]
        })
        .collect();
    r.table(&["export", "seconds", "ms per frame"], &table);
    r.json["export"] = serde_json::json!(
        rows.iter()
            .map(|x| serde_json::json!({"export": x.label, "frames": x.frames, "secs": x.secs}))
            .collect::<Vec<_>>()
    );
    Ok(r)
}
