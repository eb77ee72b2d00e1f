//! The real editor window under Xvfb: `ignis edit --frames 60 --screenshot FILE` must
//! exit 0 and its PNG must show egui's side panel and a fire in the viewport.
//!
//! Needs `xvfb-run` (packages `xvfb` and `xauth`) and a Vulkan driver (lavapipe is fine);
//! the test fails, rather than skips, when they are missing.

use std::path::PathBuf;
use std::process::Command;

fn on_path(program: &str) -> Option<PathBuf> {
    std::env::var_os("PATH").and_then(|paths| {
        std::env::split_paths(&paths)
            .map(|dir| dir.join(program))
            .find(|p| p.is_file())
    })
}

#[test]
fn the_editor_window_shows_the_panel_and_the_fire() {
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
        .args(["edit", "--frames", "60", "--screenshot"])
        .arg(&png)
        .output()
        .expect("running xvfb-run");
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        output.status.success(),
        "ignis edit failed ({}):\n{stdout}\n{stderr}",
        output.status
    );
    let report = stdout
        .lines()
        .find(|l| l.starts_with("edit: 60 frames, median frame"))
        .unwrap_or_else(|| panic!("no frame report in the output:\n{stdout}\n{stderr}"));
    println!("{report}");

    let image = image::open(&png)
        .expect("the screenshot is a PNG")
        .to_rgba8();
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
    assert!(warm > 3000, "only {warm} warm pixels in the viewport");
    assert!(
        dark > 880 * 720 / 3,
        "the viewport background should be dark ({dark} dark pixels)"
    );
}
