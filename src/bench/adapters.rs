//! `ignis bench adapters`: what each software-adapter adaptation takes off the editor's
//! frame. The editor runs as a child process (`ignis edit --frames N`, in the window of
//! the display the bench runs under — `xvfb-run` on a machine without one) with the
//! software profile, and with the software profile but one field set back to the GPU's;
//! the runs are interleaved round by round so that drift in the machine's speed falls on
//! every variant alike. An adaptation pays when the frame without it is at least
//! [`KEEP_THRESHOLD`] slower.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::editor::window::editor_profile::AdaptSetting;
use crate::gpu::{GpuContext, ProfileSetting};

use super::Report;

/// The share of the software frame an adaptation must take off to be kept.
pub const KEEP_THRESHOLD: f64 = 0.10;

/// What to run.
#[derive(Clone, Debug)]
pub struct AdaptersOptions {
    /// The preset the editor opens (`None`: the embedded campfire, the default frame).
    pub preset: Option<PathBuf>,
    /// Frames per editor run (the editor reports their median after a short warm-up).
    pub frames: u32,
    /// Interleaved rounds (every variant runs once per round).
    pub rounds: usize,
    /// The window's size, WxH.
    pub size: (u32, u32),
}

/// One variant: the software profile with these fields set.
struct Variant {
    label: String,
    settings: Vec<AdaptSetting>,
    /// Median frame of each round's run, ms.
    frames_ms: Vec<f64>,
}

/// Runs the interleaved rounds and builds the report.
pub fn run(ctx: &GpuContext, opts: &AdaptersOptions) -> anyhow::Result<Report> {
    let exe = std::env::current_exe()?;
    let mut variants = vec![Variant {
        label: "software profile (all adaptations)".into(),
        settings: Vec::new(),
        frames_ms: Vec::new(),
    }];
    // Timestamps are a capability (trustworthy or not), not a speed choice.
    for s in AdaptSetting::software_to_gpu()
        .into_iter()
        .filter(|s| !matches!(s, AdaptSetting::Adapter(ProfileSetting::Timestamps(_))))
    {
        variants.push(Variant {
            label: format!("without {}", s.field()),
            settings: vec![s],
            frames_ms: Vec::new(),
        });
    }
    variants.push(Variant {
        label: "GPU profile (none)".into(),
        settings: AdaptSetting::software_to_gpu(),
        frames_ms: Vec::new(),
    });
    for round in 0..opts.rounds {
        // Rotate the order each round: no variant always runs first or last.
        let n = variants.len();
        for k in 0..n {
            let v = &mut variants[(k + round) % n];
            let ms = editor_median_ms(&exe, opts, &v.settings)?;
            println!("round {}: {} {ms:.1} ms", round + 1, v.label);
            v.frames_ms.push(ms);
        }
    }
    Ok(report(ctx, opts, &variants))
}

/// One editor run's median frame, ms.
fn editor_median_ms(
    exe: &Path,
    opts: &AdaptersOptions,
    settings: &[AdaptSetting],
) -> anyhow::Result<f64> {
    let mut cmd = Command::new(exe);
    cmd.args(["--adapter-profile", "software", "edit", "--frames"])
        .arg(opts.frames.to_string())
        .arg("--size")
        .arg(format!("{}x{}", opts.size.0, opts.size.1));
    if !settings.is_empty() {
        let list: Vec<String> = settings.iter().map(ToString::to_string).collect();
        cmd.arg("--adapt").arg(list.join(","));
    }
    if let Some(p) = &opts.preset {
        cmd.arg(p);
    }
    let out = cmd.output()?;
    let stdout = String::from_utf8_lossy(&out.stdout);
    if !out.status.success() {
        anyhow::bail!(
            "the editor failed ({}); it needs a display (run the bench under xvfb-run):\n{}",
            out.status,
            String::from_utf8_lossy(&out.stderr)
        );
    }
    stdout
        .split("median frame ")
        .nth(1)
        .and_then(|rest| rest.split(" ms").next())
        .and_then(|ms| ms.parse().ok())
        .ok_or_else(|| anyhow::anyhow!("no median frame in the editor's report:\n{stdout}"))
}

fn median(values: &[f64]) -> f64 {
    let mut v = values.to_vec();
    crate::gpu::timer::median(&mut v)
}

fn report(ctx: &GpuContext, opts: &AdaptersOptions, variants: &[Variant]) -> Report {
    let mut r = Report::new("Software-adapter adaptations: the editor's frame", ctx);
    let base = &variants[0];
    r.para(&format!(
        "The editor ({}, window {}x{}) for {} frames per run, {} interleaved rounds; each \
         figure is the median over rounds of a run's median frame. \"Takes off\" is the \
         share of the frame without the adaptation that it saves, from the per-round \
         ratios (same round, same machine state); kept at ≥ {:.0} %.",
        opts.preset
            .as_deref()
            .map_or("the default campfire".into(), |p| p.display().to_string()),
        opts.size.0,
        opts.size.1,
        opts.frames,
        opts.rounds,
        KEEP_THRESHOLD * 100.0
    ));
    let mut rows = Vec::new();
    let mut json = Vec::new();
    for v in variants {
        let ratios: Vec<f64> = v
            .frames_ms
            .iter()
            .zip(&base.frames_ms)
            .map(|(without, with)| 1.0 - with / without)
            .collect();
        let off = median(&ratios);
        let verdict = if v.settings.len() == 1 {
            if off >= KEEP_THRESHOLD {
                "keep"
            } else {
                "remove"
            }
        } else {
            ""
        };
        rows.push(vec![
            v.label.clone(),
            format!("{:.1}", median(&v.frames_ms)),
            if std::ptr::eq(v, base) {
                String::new()
            } else {
                format!("{:.0} %", off * 100.0)
            },
            verdict.into(),
        ]);
        json.push(serde_json::json!({
            "variant": v.label,
            "settings": v.settings.iter().map(ToString::to_string).collect::<Vec<_>>(),
            "frames_ms": v.frames_ms,
            "median_ms": median(&v.frames_ms),
            "takes_off": off,
        }));
    }
    r.table(&["variant", "frame (ms)", "takes off", "verdict"], &rows);
    r.json["variants"] = serde_json::Value::Array(json);
    r
}
