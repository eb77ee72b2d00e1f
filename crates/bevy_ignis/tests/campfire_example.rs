//! The example as a user runs it, headless: `campfire --frames 90 --screenshot FILE`
//! renders Bevy's scene with the campfire and torches into an image; the picture shows
//! the night sky, the lit ground and meshes, and the fire.
//!
//! `cargo test` builds the examples before the tests; this test runs the built binary.

use std::path::PathBuf;
use std::process::Command;

fn example_binary() -> PathBuf {
    // target/<profile>/deps/campfire_example-… → target/<profile>/examples/campfire
    let exe = std::env::current_exe().expect("test path");
    let profile = exe.parent().and_then(|d| d.parent()).expect("target dir");
    let path = profile.join("examples").join("campfire");
    assert!(
        path.is_file(),
        "{} is not built (cargo test builds the examples)",
        path.display()
    );
    path
}

#[test]
fn the_campfire_example_shows_the_scene_and_the_fire() {
    let dir = tempfile::tempdir().expect("temp dir");
    let png = dir.path().join("campfire.png");
    let output = Command::new(example_binary())
        .args(["--frames", "90", "--screenshot"])
        .arg(&png)
        .output()
        .expect("running the example");
    assert!(
        output.status.success(),
        "the example failed ({}):\n{}",
        output.status,
        String::from_utf8_lossy(&output.stderr)
    );
    let image = image::open(&png).expect("a PNG").to_rgb8();
    assert_eq!(image.dimensions(), (960, 540));
    let (mut sky, mut ground, mut fire) = (0, 0, 0);
    for (_, y, p) in image.enumerate_pixels() {
        let [r, g, b] = p.0.map(i32::from);
        if y < 60 && r < 12 && g < 12 && b < 24 && b >= r {
            sky += 1;
        }
        // The ground, lit by the moon and the fire's glow: dim, not black, not saturated.
        if y > 420 && (12..160).contains(&r) && (r - b).abs() < 80 {
            ground += 1;
        }
        if r > 200 && g > 90 && r >= g && g > b + 30 {
            fire += 1;
        }
    }
    eprintln!("campfire example: sky {sky}, ground {ground}, fire {fire} pixels");
    assert!(sky > 30_000, "{sky} sky pixels");
    assert!(ground > 30_000, "{ground} lit ground pixels");
    assert!(fire > 1_000, "{fire} fire pixels");
}
