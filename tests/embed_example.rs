//! The embedding example as a user runs it: `examples/embed` opens a real window under
//! Xvfb, renders 90 frames and saves a screenshot, which must show the host's scene (its
//! lit ground and boxes) and the fire (warm, bright pixels above it).
//!
//! `cargo test` builds the examples before the tests; this test runs the built binary.
//! Needs `xvfb-run` (packages `xvfb` and `xauth`) and a Vulkan driver; it fails, rather
//! than skips, when they are missing.

use std::path::PathBuf;
use std::process::Command;

fn example_binary() -> PathBuf {
    // target/<profile>/deps/embed_example-… → target/<profile>/examples/embed
    let exe = std::env::current_exe().expect("test path");
    let profile = exe.parent().and_then(|d| d.parent()).expect("target dir");
    let path = profile.join("examples").join("embed");
    assert!(
        path.is_file(),
        "{} is not built (cargo test builds the examples)",
        path.display()
    );
    path
}

#[test]
fn the_embed_example_shows_the_host_scene_and_the_fire() {
    let dir = tempfile::tempdir().expect("temp dir");
    let png = dir.path().join("embed.png");
    let output = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1280x720x24"])
        .arg(example_binary())
        .args(["--frames", "90", "--screenshot"])
        .arg(&png)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("running xvfb-run (apt-get install xvfb xauth)");
    assert!(
        output.status.success(),
        "the example failed ({}):\n{}",
        output.status,
        String::from_utf8_lossy(&output.stderr)
    );
    let image = image::open(&png).expect("a PNG").to_rgb8();
    assert_eq!(image.dimensions(), (1280, 720));
    let (mut ground, mut fire, mut sky) = (0, 0, 0);
    for (_, y, p) in image.enumerate_pixels() {
        let [r, g, b] = p.0.map(i32::from);
        // The night sky: near black, a touch of blue.
        if y < 150 && r < 16 && g < 16 && b < 40 && b >= r {
            sky += 1;
        }
        // The host's ground and boxes, lit: grey-brown, neither black nor saturated.
        if y > 500 && (20..200).contains(&r) && (r - b).abs() < 60 && (r - g).abs() < 40 {
            ground += 1;
        }
        // Fire: bright, warm, red ≥ green > blue.
        if r > 200 && g > 90 && r >= g && g > b + 30 {
            fire += 1;
        }
    }
    assert!(sky > 50_000, "{sky} sky pixels");
    assert!(ground > 50_000, "{ground} lit ground pixels");
    assert!(fire > 1_500, "{fire} fire pixels");
    eprintln!("embed: sky {sky}, ground {ground}, fire {fire} pixels");
}
