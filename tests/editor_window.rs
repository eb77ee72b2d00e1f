//! The real editor window under Xvfb: `ignis edit --frames 60 --screenshot FILE` must
//! exit 0 and its PNG must show egui's side panel and a fire in the viewport.
//!
//! Needs `xvfb-run` (packages `xvfb` and `xauth`) and a Vulkan driver (lavapipe is fine);
//! the test fails, rather than skips, when they are missing.
// The editor, the `ignis` binary or the benches: the default `editor` feature.
#![cfg(feature = "editor")]

use std::path::PathBuf;
use std::process::Command;

fn on_path(program: &str) -> Option<PathBuf> {
    std::env::var_os("PATH").and_then(|paths| {
        std::env::split_paths(&paths)
            .map(|dir| dir.join(program))
            .find(|p| p.is_file())
    })
}

/// Runs `ignis edit --frames N --screenshot … EXTRA…` under Xvfb; returns the frame
/// report (its first line and the lines after it) and the screenshot.
fn run_editor(frames: u32, extra: &[&str]) -> (String, image::RgbaImage) {
    let xvfb_run = on_path("xvfb-run").unwrap_or_else(|| {
        panic!(
            "xvfb-run is not on PATH: this test opens a real window under a virtual X server; \
             install it with `apt-get install xvfb xauth`"
        )
    });
    let dir = tempfile::tempdir().expect("temp dir");
    let png = dir.path().join("editor.png");
    let output = Command::new(xvfb_run)
        .args(["-a", "-s", "-screen 0 1280x720x24"])
        .arg(env!("CARGO_BIN_EXE_ignis"))
        .args(["edit", "--frames", &frames.to_string(), "--screenshot"])
        .arg(&png)
        .args(extra)
        .output()
        .expect("running xvfb-run");
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        output.status.success(),
        "ignis edit failed ({}):\n{stdout}\n{stderr}",
        output.status
    );
    let prefix = format!("edit: {frames} frames, median frame");
    let report = stdout
        .find(&prefix)
        .map(|at| stdout[at..].to_owned())
        .unwrap_or_else(|| panic!("no frame report in the output:\n{stdout}\n{stderr}"));
    let image = image::open(&png)
        .expect("the screenshot is a PNG")
        .to_rgba8();
    (report, image)
}

/// Checks the screenshot: egui's panel on the right, a fire on a dark viewport.
fn assert_panel_and_fire(image: &image::RgbaImage, min_warm_pixels: usize) {
    assert_eq!(image.dimensions(), (1280, 720));

    // egui's dark panel fill (grey 27) covers most of the rightmost 300 pixels.
    let mut panel = 0;
    let mut strip = 0;
    for y in 0..720 {
        for x in 980..1280 {
            let [r, g, b, _] = image.get_pixel(x, y).0;
            strip += 1;
            if r == g && g == b && (20..=36).contains(&r) {
                panel += 1;
            }
        }
    }
    assert!(
        panel * 2 > strip,
        "only {panel} of {strip} pixels on the right look like egui's panel"
    );

    // Warm fire pixels (red ≥ green ≥ blue, bright, saturated) in the viewport.
    let mut warm = 0;
    let mut dark = 0;
    for y in 0..720 {
        for x in 0..880 {
            let [r, g, b, _] = image.get_pixel(x, y).0;
            if r > 180 && r >= g && g >= b && r as i32 - b as i32 > 80 {
                warm += 1;
            }
            if r.max(g).max(b) < 40 {
                dark += 1;
            }
        }
    }
    assert!(
        warm > min_warm_pixels,
        "only {warm} warm pixels in the viewport"
    );
    assert!(
        dark > 880 * 720 / 3,
        "the viewport background should be dark ({dark} dark pixels)"
    );
}

#[test]
fn the_editor_window_shows_the_panel_and_the_fire() {
    // The retained window image asked for: the check below applies on any adapter.
    let (report, image) = run_editor(60, &["--adapt", "retained_window=true"]);
    println!("{report}");
    assert_panel_and_fire(&image, 3000);
    assert_viewport_only_repaints(&report, 20);
}

/// With the retained window image (the software adapter profile's, and asked for by the
/// test on any adapter), a playing effect repaints only the viewport and the timeline under it: the rest of the
/// window is repainted when it changes (the first frames, new glyphs in egui's font atlas),
/// not every frame — a label outside those that changed every frame would make every
/// frame a full repaint.
fn assert_viewport_only_repaints(report: &str, at_least: u32) {
    let Some(line) = report.lines().find(|l| l.starts_with("retained UI:")) else {
        panic!("no retained-UI line with the retained window on: {report}");
    };
    let live: u32 = line
        .split(", ")
        .nth(1)
        .and_then(|part| part.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("unreadable retained-UI line: {line}"));
    assert!(
        live >= at_least,
        "only {live} frames repainted over the viewport alone: {line}"
    );
}

#[test]
fn egui_wgpus_own_painter_draws_the_same_window() {
    // The default painter on a software adapter is the lean one; egui-wgpu's must work
    // too (it is the default on hardware GPUs), with or without the retained window
    // image. Few frames: it is slow on llvmpipe.
    let (report, image) = run_editor(12, &["--adapt", "lean_painter=false"]);
    println!("{report}");
    assert_panel_and_fire(&image, 1000);
}

/// A lost GPU device (destroyed after frame 10): the editor says so, recreates the device,
/// its pipelines and its painter in the same window, and goes on playing the same effect —
/// the panel and a fire are on screen at the end, and the run reports one recovery.
#[test]
fn the_editor_recovers_from_a_lost_device() {
    let (report, image) = run_editor(40, &["--lose-device-at", "10"]);
    println!("{report}");
    assert!(
        report.contains("GPU device lost and recreated 1 time(s)"),
        "no recovery in the report: {report}"
    );
    assert_panel_and_fire(&image, 1000);
    // The notice: the panel's error box (dark red, rgb(70, 24, 24)) near its top.
    let notice = (0..200)
        .flat_map(|y| (980..1280).map(move |x| (x, y)))
        .filter(|&(x, y)| image.get_pixel(x, y).0[..3] == [70, 24, 24])
        .count();
    assert!(
        notice > 2000,
        "no device-lost notice in the panel ({notice} pixels)"
    );
}

/// A device lost after two edits keeps the effect and its undo history: an undo after
/// the recovery goes back to the first edit, in the panel and in what the new device
/// plays.
#[test]
fn a_lost_device_keeps_the_edits_and_their_undo_history() {
    let (report, image) = run_editor(40, &["--lose-device-at", "10", "--edit-around-loss"]);
    println!("{report}");
    assert!(
        report.contains("GPU device lost and recreated 1 time(s)"),
        "no recovery in the report: {report}"
    );
    assert!(
        report.contains(
            "edits around the loss: 1 undo step(s) left, flames intensity 0.3 in \
            the panel, 0.3 playing"
        ),
        "the edits or their history were not kept: {report}"
    );
    assert_panel_and_fire(&image, 1000);
}
