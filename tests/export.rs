//! `ignis export`: compositing, flipbook = sequence, loops, motion vectors, framing and
//! determinism, on the real adapter (lavapipe in CI) at small sizes.
#![cfg(feature = "editor")]

mod common;

use std::path::Path;

use common::{gpu, run_ok};
use ignis::effect::Effect;
use ignis::export::{AlphaMode, CameraMode, ExportSettings, Format, Layout, Passes};

/// A sequence of `frames` frames of 64×64 into `out`, starting warm.
fn sequence(out: &Path, frames: u32, duration: f64) -> ExportSettings {
    let mut s = ExportSettings::new(out.to_path_buf());
    s.layout = Layout::Sequence;
    s.frame_size = (64, 64);
    s.frames = Some(frames);
    s.duration_secs = Some(duration);
    s.start_secs = 1.5;
    s
}

fn export(effect: &Effect, settings: ExportSettings) -> ignis::export::Summary {
    let ctx = gpu();
    ignis::export::run(&ctx, effect, Some("presets".into()), settings, |_| {}).expect("export")
}

fn preset(name: &str) -> Effect {
    ignis::preset::load(format!("presets/{name}.ron").as_ref()).expect("preset")
}

fn rgba8(path: &Path) -> image::RgbaImage {
    image::open(path).expect("png").to_rgba8()
}

/// An image's pixels as linear floats (colour decoded from sRGB, alpha as is).
fn linear(img: &image::RgbaImage) -> Vec<[f32; 4]> {
    let lin = ignis::export::srgb_to_linear;
    img.pixels()
        .map(|p| {
            let c = p.0.map(|v| f32::from(v) / 255.0);
            [lin(c[0]), lin(c[1]), lin(c[2]), c[3]]
        })
        .collect()
}

fn frame_path(dir: &Path, pass: &str, k: u32) -> std::path::PathBuf {
    dir.join(format!("campfire_{pass}_{k:04}.png"))
}

/// The campfire exported with premultiplied alpha and composited over a coloured
/// background with `C + B·(1 − A)` (in linear light) matches the campfire rendered over
/// that background: within 1/255 mean and 4/255 max (8-bit sRGB).
#[test]
fn premultiplied_export_composites_like_the_render_over_a_background() {
    let effect = preset("campfire");
    let dir = tempfile::tempdir().expect("tempdir");
    let (clear, over) = (dir.path().join("clear"), dir.path().join("over"));
    let b = [0.20f32, 0.35, 0.60];
    export(&effect, sequence(&clear, 3, 1.5));
    export(
        &effect,
        ExportSettings {
            background: Some(b),
            ..sequence(&over, 3, 1.5)
        },
    );
    let srgb = |v: f32| (255.0 * ignis::export::linear_to_srgb(v)).round();
    let (mut sum, mut worst, mut n, mut covered) = (0.0f64, 0.0f32, 0usize, 0usize);
    for k in 0..3 {
        let fire = linear(&rgba8(&frame_path(&clear, "color", k)));
        let reference = rgba8(&frame_path(&over, "color", k));
        for (c, r) in fire.iter().zip(reference.pixels()) {
            covered += usize::from(c[3] > 0.1);
            for ch in 0..3 {
                let composited = srgb((c[ch] + b[ch] * (1.0 - c[3])).min(1.0));
                let d = (composited - f32::from(r.0[ch])).abs();
                sum += f64::from(d);
                worst = worst.max(d);
                n += 1;
            }
        }
    }
    let mean = sum / n as f64;
    assert!(
        covered > 50,
        "the smoke covers {covered} pixels: too few to test alpha"
    );
    assert!(mean <= 1.0, "mean error {mean:.3}/255");
    assert!(worst <= 4.0, "worst error {worst}/255");
}

/// Straight alpha is the premultiplied colour divided by a coverage that also counts the
/// light: `A' = max(A, min(1, max C))`, and `rgb·A'` gives the premultiplied colour back
/// (in linear light, to the 8-bit quantisation) — an export that forgot to divide, or
/// divided by the wrong coverage, fails.
#[test]
fn straight_alpha_is_the_premultiplied_colour_over_its_coverage() {
    let effect = preset("campfire");
    let dir = tempfile::tempdir().expect("tempdir");
    let (pre, straight) = (dir.path().join("pre"), dir.path().join("straight"));
    export(&effect, sequence(&pre, 2, 1.5));
    export(
        &effect,
        ExportSettings {
            alpha: AlphaMode::Straight,
            ..sequence(&straight, 2, 1.5)
        },
    );
    let (mut sum, mut worst, mut n, mut divided) = (0.0f64, 0.0f32, 0usize, 0usize);
    for k in 0..2 {
        let c = linear(&rgba8(&frame_path(&pre, "color", k)));
        let s = linear(&rgba8(&frame_path(&straight, "color", k)));
        for (c, s) in c.iter().zip(&s) {
            let coverage = c[3].max(c[0].max(c[1]).max(c[2]).min(1.0));
            assert!(
                (s[3] - coverage).abs() <= 1.5 / 255.0,
                "alpha {} for {c:?}",
                s[3]
            );
            if s[3] < 0.98 && s[3] > 0.05 {
                divided += 1;
            }
            for ch in 0..3 {
                let d = (s[ch] * s[3] - c[ch]).abs();
                sum += f64::from(d);
                worst = worst.max(d);
                n += 1;
            }
        }
    }
    let mean = sum / n as f64;
    assert!(divided > 50, "only {divided} partly covered pixels");
    assert!(mean <= 0.5 / 255.0, "mean error {:.3}/255", mean * 255.0);
    assert!(worst <= 6.0 / 255.0, "worst error {:.2}/255", worst * 255.0);
}

/// Frame `k` of `pass` in an EXR export in `dir`: linear RGBA per pixel.
fn exr(dir: &Path, pass: &str, k: u32) -> Vec<[f32; 4]> {
    let path = dir.join(format!("campfire_{pass}_{k:04}.exr"));
    let image = exr::prelude::read_first_rgba_layer_from_file(
        &path,
        |size, _| {
            (
                size.width(),
                vec![[0.0f32; 4]; size.width() * size.height()],
            )
        },
        |(w, px), at, (r, g, b, a): (f32, f32, f32, f32)| {
            px[at.y() * *w + at.x()] = [r, g, b, a];
        },
    )
    .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    image.layer_data.channel_data.pixels.1
}

/// A preset's exposure scales the exported light and leaves coverage alone: the campfire
/// at exposure 2.5 is 2.5× its light at exposure 1 (EXR, linear), alpha unchanged.
#[test]
fn exposure_scales_the_exported_light() {
    let effect = preset("campfire");
    let mut bright = effect.clone();
    bright.post.exposure = 2.5;
    let dir = tempfile::tempdir().expect("tempdir");
    let (one, more) = (dir.path().join("one"), dir.path().join("more"));
    for (e, out) in [(&effect, &one), (&bright, &more)] {
        let settings = ExportSettings {
            format: Format::Exr,
            camera: CameraMode::Preset,
            ..sequence(out, 2, 1.5)
        };
        export(e, settings);
    }
    let (mut lit, mut worst) = (0usize, 0.0f32);
    for k in 0..2 {
        for (a, b) in exr(&one, "color", k).iter().zip(&exr(&more, "color", k)) {
            for c in 0..3 {
                worst = worst.max((b[c] - 2.5 * a[c]).abs() / (1.0 + b[c]));
            }
            assert!((a[3] - b[3]).abs() < 1e-3, "coverage {} → {}", a[3], b[3]);
            lit += usize::from(a[0] > 0.05);
        }
    }
    assert!(lit > 50, "only {lit} lit pixels");
    assert!(worst < 2e-3, "light not 2.5×: relative error {worst}");
}

/// The emissive pass is the colour pass's additive light: the colour pass minus the
/// emissive pass is what the same frames give with every additive layer at intensity 0
/// (the smoke alone: the flames still simulate and still give birth to it), and that
/// export's emissive pass is black.
#[test]
fn the_emissive_pass_is_the_colour_passs_additive_light() {
    let mut effect = preset("campfire");
    // The smoke lit by the night alone: the flames' light on it would go with them.
    for e in &mut effect.emitters {
        if let Some(l) = e.look.lit.as_mut() {
            l.self_light = 0.0;
        }
    }
    let mut dark = effect.clone();
    for e in &mut dark.emitters {
        if e.look.blend == ignis::effect::BlendMode::Additive {
            e.look.intensity = 0.0;
        }
    }
    let dir = tempfile::tempdir().expect("tempdir");
    let (lit, smoke) = (dir.path().join("lit"), dir.path().join("smoke"));
    let passes = Passes {
        color: true,
        emissive: true,
        ..Passes::NONE
    };
    for (e, out) in [(&effect, &lit), (&dark, &smoke)] {
        // The preset's own camera: a fitted one would frame the dark flames differently.
        let settings = ExportSettings {
            passes,
            format: Format::Exr,
            camera: CameraMode::Preset,
            ..sequence(out, 2, 1.5)
        };
        export(e, settings);
    }
    let (mut light, mut worst, mut smoky) = (0.0f32, 0.0f32, 0usize);
    for k in 0..2 {
        let (color, emissive) = (exr(&lit, "color", k), exr(&lit, "emissive", k));
        let (alone, none) = (exr(&smoke, "color", k), exr(&smoke, "emissive", k));
        for i in 0..color.len() {
            for c in 0..3 {
                worst = worst.max((color[i][c] - emissive[i][c] - alone[i][c]).abs());
                assert!(
                    none[i][c].abs() < 1e-6,
                    "emissive light without additive layers"
                );
            }
            light += emissive[i][0];
            smoky += usize::from(alone[i][3] > 0.05);
        }
    }
    assert!(
        light > 10.0 && smoky > 50,
        "light {light}, smoky pixels {smoky}"
    );
    assert!(
        worst < 2e-3,
        "colour − emissive differs from the smoke alone by {worst}"
    );
}

/// Frame k of a flipbook is frame k of the sequence export with the same settings.
#[test]
fn flipbook_cells_are_the_sequence_frames() {
    let effect = preset("torch");
    let dir = tempfile::tempdir().expect("tempdir");
    let (book, seq) = (dir.path().join("book"), dir.path().join("seq"));
    let mut s = sequence(&seq, 6, 1.0);
    s.frame_size = (48, 40);
    export(&effect, s.clone());
    export(
        &effect,
        ExportSettings {
            layout: Layout::Flipbook { cols: 3, rows: 2 },
            out_dir: book.clone(),
            ..s
        },
    );
    let atlas = rgba8(&book.join("torch_color.png"));
    assert_eq!(atlas.dimensions(), (144, 80));
    for k in 0..6 {
        let frame = rgba8(&seq.join(format!("torch_color_{k:04}.png")));
        let (x, y) = ((k % 3) * 48, (k / 3) * 40);
        let cell = image::imageops::crop_imm(&atlas, x, y, 48, 40).to_image();
        assert!(cell == frame, "cell {k} differs from sequence frame {k}");
    }
}

/// The export's preview (what the editor shows while it runs) is, once it is done, the
/// colour atlas it wrote; before its first frame there is none to show.
#[test]
fn the_preview_is_the_written_colour_atlas() {
    let ctx = gpu();
    let dir = tempfile::tempdir().expect("tempdir");
    let settings = ExportSettings {
        layout: Layout::Flipbook { cols: 2, rows: 2 },
        frame_size: (40, 32),
        ..sequence(dir.path(), 4, 1.0)
    };
    let effect = preset("torch");
    let mut export = ignis::export::Export::new(&ctx, &effect, Some("presets".into()), settings)
        .expect("export");
    assert!(
        export
            .preview()
            .is_none_or(|p| p.pixels().all(|p| p[3] == 0))
    );
    while export.step().expect("step").is_some() {}
    let atlas = rgba8(&dir.path().join("torch_color.png"));
    assert!(atlas.pixels().any(|p| p[3] > 0), "an empty atlas");
    assert!(
        export.preview() == Some(atlas),
        "the preview is not the atlas written"
    );
}

/// An export reports its progress after every step, one step of work more each time,
/// and ends with all of it done (three steps a frame: framed, probed, rendered).
#[test]
fn progress_counts_every_step_to_the_total() {
    let ctx = gpu();
    let dir = tempfile::tempdir().expect("tempdir");
    let mut seen = Vec::new();
    ignis::export::run(
        &ctx,
        &preset("torch"),
        Some("presets".into()),
        sequence(dir.path(), 4, 1.0),
        |p| seen.push((p.done, p.total)),
    )
    .expect("export");
    let steps: Vec<u32> = seen.iter().map(|&(done, _)| done).collect();
    assert_eq!(steps, (1..=12).collect::<Vec<_>>(), "{seen:?}");
    assert!(seen.iter().all(|&(_, total)| total == 12), "{seen:?}");
}

/// The mean absolute difference of two images' channels, in 8-bit steps.
fn difference(a: &image::RgbaImage, b: &image::RgbaImage) -> f64 {
    let sum: u64 = a
        .as_raw()
        .iter()
        .zip(b.as_raw())
        .map(|(x, y)| u64::from(x.abs_diff(*y)))
        .sum();
    sum as f64 / a.as_raw().len() as f64
}

/// (last → first, median consecutive) differences of a sequence's colour frames.
fn seam(dir: &Path, frames: u32) -> (f64, f64) {
    let imgs: Vec<_> = (0..frames)
        .map(|k| rgba8(&frame_path(dir, "color", k)))
        .collect();
    let mut consecutive: Vec<f64> = imgs.windows(2).map(|w| difference(&w[0], &w[1])).collect();
    consecutive.sort_by(f64::total_cmp);
    let last_first = difference(&imgs[frames as usize - 1], &imgs[0]);
    (last_first, consecutive[consecutive.len() / 2])
}

/// With `--loop` the last frame flows into the first (no larger a step than the median
/// between consecutive frames); without it the jump is larger.
#[test]
fn a_loop_closes_and_a_plain_span_does_not() {
    let effect = preset("campfire");
    let dir = tempfile::tempdir().expect("tempdir");
    let (looped, plain) = (dir.path().join("loop"), dir.path().join("plain"));
    let s = sequence(&plain, 16, 16.0 / 30.0);
    let plain_summary = export(&effect, s.clone());
    let loop_summary = export(
        &effect,
        ExportSettings {
            looped: true,
            out_dir: looped.clone(),
            ..s
        },
    );
    let (loop_seam, loop_median) = seam(&looped, 16);
    let (plain_seam, plain_median) = seam(&plain, 16);
    // The sidecar's seam figures are the written frames' own (in 8-bit steps; it measures
    // the frames before they are rounded to 8 bits).
    for (summary, (last_first, median)) in [
        (&plain_summary, (plain_seam, plain_median)),
        (&loop_summary, (loop_seam, loop_median)),
    ] {
        let s = &summary.sidecar.seam;
        assert!(
            (s.last_to_first - last_first).abs() < 0.05 + 0.02 * last_first
                && (s.median_consecutive - median).abs() < 0.05 + 0.02 * median,
            "sidecar {s:?}, files {last_first:.3} and {median:.3}"
        );
    }
    assert!(
        loop_seam <= loop_median,
        "loop: last → first {loop_seam:.3} > median consecutive {loop_median:.3}"
    );
    assert!(
        plain_seam > plain_median,
        "no loop: last → first {plain_seam:.3} ≤ median consecutive {plain_median:.3}"
    );
}

/// Warping frame i of the spark fountain by its motion pass predicts frame i + 1 better
/// than frame i does: the mean error drops by at least a third. The warp splats each
/// pixel bilinearly where its motion takes it; at 384² the sparks are a few pixels
/// apart, as a flipbook's frames would be.
/// The loop's own seam — the end of the span meeting its start, where the cross-fade
/// works — is as smooth as its other steps. The writer starts a loop after its smallest
/// step, so the last → first comparison cannot see a jump; but the jump would still lie
/// between two consecutive written frames: every consecutive step of a loop stays within
/// 1.5× the median (measured: 1.19×; 4.8× with the cross-fade removed).
#[test]
fn the_loops_cross_fade_smooths_its_own_seam() {
    let effect = preset("campfire");
    let dir = tempfile::tempdir().expect("tempdir");
    let settings = ExportSettings {
        looped: true,
        ..sequence(dir.path(), 16, 16.0 / 30.0)
    };
    export(&effect, settings);
    let imgs: Vec<_> = (0..16)
        .map(|k| rgba8(&frame_path(dir.path(), "color", k)))
        .collect();
    let mut steps: Vec<f64> = imgs.windows(2).map(|w| difference(&w[0], &w[1])).collect();
    steps.sort_by(f64::total_cmp);
    let (median, largest) = (steps[steps.len() / 2], steps[steps.len() - 1]);
    assert!(
        largest <= 1.5 * median,
        "a step of {largest:.3} against the median {median:.3}: a jump inside the loop"
    );
}

#[test]
fn motion_vectors_predict_the_next_frame() {
    const SIZE: u32 = 384;
    let effect = preset("spark_fountain");
    let dir = tempfile::tempdir().expect("tempdir");
    let mut s = sequence(dir.path(), 4, 4.0 / 30.0);
    s.frame_size = (SIZE, SIZE);
    s.passes = Passes {
        color: true,
        motion: true,
        ..Passes::NONE
    };
    let summary = export(&effect, s);
    let scale = summary.sidecar.motion_vector_scale;
    let path = |pass: &str, k: u32| dir.path().join(format!("spark_fountain_{pass}_{k:04}.png"));
    let (mut warped_err, mut still_err) = (0.0f64, 0.0f64);
    for i in 0..3 {
        let now = rgba8(&path("color", i));
        let next = rgba8(&path("color", i + 1));
        let motion = rgba8(&path("motion", i));
        let n = SIZE as usize;
        let mut warped = vec![[0.0f32; 4]; n * n];
        for (x, y, p) in now.enumerate_pixels() {
            if p.0 == [0; 4] {
                continue;
            }
            let m = motion.get_pixel(x, y).0;
            let rg = [f32::from(m[0]) / 255.0, f32::from(m[1]) / 255.0];
            let uv = ignis::export::decode_motion(rg, scale);
            let (fx, fy) = (
                x as f32 + uv[0] * SIZE as f32,
                y as f32 + uv[1] * SIZE as f32,
            );
            let (x0, y0) = (fx.floor(), fy.floor());
            let (ax, ay) = (fx - x0, fy - y0);
            for (dx, dy, w) in [
                (0, 0, (1.0 - ax) * (1.0 - ay)),
                (1, 0, ax * (1.0 - ay)),
                (0, 1, (1.0 - ax) * ay),
                (1, 1, ax * ay),
            ] {
                let (tx, ty) = (x0 as i64 + dx, y0 as i64 + dy);
                if (0..n as i64).contains(&tx) && (0..n as i64).contains(&ty) {
                    let q = &mut warped[ty as usize * n + tx as usize];
                    for (qc, pc) in q.iter_mut().zip(p.0) {
                        *qc += w * f32::from(pc);
                    }
                }
            }
        }
        for ((w, a), b) in warped.iter().zip(now.pixels()).zip(next.pixels()) {
            for ((wc, ac), bc) in w.iter().zip(a.0).zip(b.0) {
                warped_err += f64::from((wc.min(255.0) - f32::from(bc)).abs());
                still_err += f64::from(ac.abs_diff(bc));
            }
        }
    }
    assert!(still_err > 1e5, "the sparks hardly move: {still_err}");
    assert!(
        warped_err <= still_err * 2.0 / 3.0,
        "warped error {warped_err:.0} vs unwarped {still_err:.0} ({:.3})",
        warped_err / still_err
    );
}

/// With `--camera fit` (and `ortho`) no frame has a lit or covered pixel on its border,
/// and the frames are tight: the lit pixels of the whole span reach within a tenth of the
/// frame of its edges along their longer side, and keep the shape they have through the
/// preset's own camera from far away (their box's height over width within a fifth of
/// it).
#[test]
fn fitted_frames_crop_nothing() {
    let effect = preset("campfire");
    let lit_box = |effect: &Effect, camera: CameraMode, size: u32| {
        let dir = tempfile::tempdir().expect("tempdir");
        let mut s = sequence(dir.path(), 12, 4.0);
        s.start_secs = 0.0;
        s.camera = camera;
        s.frame_size = (size, size);
        export(effect, s);
        let (mut lo, mut hi, mut lit) = ((size, size), (0u32, 0u32), 0);
        for k in 0..12 {
            let img = rgba8(&frame_path(dir.path(), "color", k));
            for (x, y, p) in img.enumerate_pixels().filter(|(_, _, p)| p.0 != [0; 4]) {
                // The preset's own camera may cut the fire at the frame's edge.
                let border =
                    camera != CameraMode::Preset && (x == 0 || y == 0 || x == 63 || y == 63);
                assert!(
                    !border,
                    "{camera:?}: frame {k} pixel ({x}, {y}) on the border is {:?}",
                    p.0
                );
                (lo, hi, lit) = (
                    (lo.0.min(x), lo.1.min(y)),
                    (hi.0.max(x), hi.1.max(y)),
                    lit + 1,
                );
            }
        }
        assert!(lit > 500, "{camera:?}: only {lit} lit pixels");
        (f64::from(hi.0 - lo.0 + 1), f64::from(hi.1 - lo.1 + 1))
    };
    // The preset's camera four times as far back sees the whole fire, small.
    let mut far = effect.clone();
    far.camera.distance_m *= 4.0;
    let (w, h) = lit_box(&far, CameraMode::Preset, 256);
    for camera in [CameraMode::Fit, CameraMode::Ortho] {
        let (fw, fh) = lit_box(&effect, camera, 64);
        assert!(
            fw.max(fh) >= 0.8 * 64.0,
            "{camera:?}: the lit box is {fw} × {fh} of 64 × 64"
        );
        let shape = (fh / fw) / (h / w);
        assert!(
            (shape - 1.0).abs() < 0.2,
            "{camera:?}: the lit box is {fw} × {fh}, through the preset's camera {w} × {h}"
        );
    }
}

/// Two exports of the same preset, seed and settings write byte-identical files (PNG,
/// EXR and the sidecar).
#[test]
fn exports_are_byte_identical() {
    let effect = preset("torch");
    let dir = tempfile::tempdir().expect("tempdir");
    for format in [Format::Png8, Format::Exr] {
        let runs: Vec<Vec<Vec<u8>>> = ["a", "b"]
            .iter()
            .map(|run| {
                let mut s = sequence(&dir.path().join(format!("{format:?}{run}")), 4, 0.5);
                s.layout = Layout::Flipbook { cols: 2, rows: 2 };
                s.format = format;
                s.alpha = AlphaMode::Straight;
                s.looped = true;
                s.passes.emissive = true;
                s.passes.motion = true;
                let summary = export(&effect, s);
                assert_eq!(summary.files.len(), 4, "{:?}", summary.files);
                summary
                    .files
                    .iter()
                    .map(|f| std::fs::read(f).expect("read"))
                    .collect()
            })
            .collect();
        assert!(runs[0] == runs[1], "{format:?}: the two exports differ");
    }
}

/// The command line: a flipbook with its sidecar; impossible settings refused with the
/// option named and nothing written.
#[test]
fn the_export_command_writes_a_flipbook_and_refuses_bad_settings() {
    let dir = tempfile::tempdir().expect("tempdir");
    run_ok(
        std::process::Command::new(env!("CARGO_BIN_EXE_ignis"))
            .args(["export", "presets/torch.ron", "--flipbook", "4x2"])
            .args(["--frame-size", "32x32", "--passes", "color,motion", "--out"])
            .arg(dir.path()),
    );
    let json = std::fs::read_to_string(dir.path().join("torch.json")).expect("sidecar");
    let v: serde_json::Value = serde_json::from_str(&json).expect("json");
    assert_eq!(v["columns"], 4);
    assert_eq!(v["rows"], 2);
    assert_eq!(v["frame_count"], 8);
    assert_eq!(v["frame_width"], 32);
    assert_eq!(v["alpha"], "premultiplied");
    assert_eq!(v["format"], "png");
    assert_eq!(v["passes"], serde_json::json!(["color", "motion"]));
    assert!(v["motion_vector_scale"].as_f64().is_some_and(|s| s > 0.0));
    assert_eq!(
        rgba8(&dir.path().join("torch_color.png")).dimensions(),
        (128, 64)
    );

    let bad = tempfile::tempdir().expect("tempdir");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_ignis"))
        .args([
            "export",
            "presets/torch.ron",
            "--flipbook",
            "2x2",
            "--frames",
            "9",
            "--out",
        ])
        .arg(bad.path().join("x"))
        .output()
        .expect("run ignis");
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--frames 9"), "{err}");
    assert!(
        !bad.path().join("x").exists(),
        "a refused export wrote files"
    );
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_ignis"))
        .args([
            "export",
            "presets/torch.ron",
            "--sequence",
            "--frames",
            "1",
            "--loop",
        ])
        .arg("--out")
        .arg(bad.path().join("y"))
        .output()
        .expect("run ignis");
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--loop needs at least 2 frames"), "{err}");
    // 8 frames of 2048 (16,384 pixels) fit an atlas; 8 of 2049 do not.
    let mut atlas = ExportSettings::new(bad.path().join("z"));
    atlas.layout = Layout::Flipbook { cols: 8, rows: 1 };
    atlas.frame_size = (2048, 16);
    atlas.validate().expect("a 16384-pixel atlas");
    atlas.frame_size = (2049, 16);
    let err = atlas
        .validate()
        .expect_err("a 16392-pixel atlas")
        .to_string();
    assert!(
        err.contains("16392x16") && err.contains("at most 16384"),
        "{err}"
    );
    atlas.layout = Layout::Flipbook { cols: 1, rows: 8 };
    atlas.frame_size = (16, 2049);
    let err = atlas
        .validate()
        .expect_err("a 16392-pixel column")
        .to_string();
    assert!(err.contains("16x16392"), "{err}");
}

/// `--passes sixway`: the lit smoke's six-way lightmaps in Unity's packing, named in the
/// sidecar. A flat-mapped puff gives, in each channel, the map of that axis times the
/// albedo's luminance (a unit white light from the camera's right, top, back, left,
/// bottom, front), its coverage in RTBA's alpha and its own glow in LBFE's.
#[test]
fn the_sixway_passes_hold_each_axis_in_unitys_packing() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mut effect = common::still_smoke(
        common::flat_maps(dir.path()),
        ignis::effect::Lighting::default(),
        ignis::effect::DrawPath::Billboard,
    );
    effect.emitters[0].name = "campfire".into();
    if let Some(l) = effect.emitters[0].look.lit.as_mut() {
        l.emission = 0.5;
    }
    effect.name = "campfire".into();
    let out = dir.path().join("out");
    let settings = ExportSettings {
        passes: Passes {
            color: true,
            sixway: true,
            ..Passes::NONE
        },
        format: Format::Exr,
        start_secs: 0.1,
        ..sequence(&out, 1, 0.1)
    };
    let summary = export(&effect, settings);
    let names: Vec<String> = summary
        .files
        .iter()
        .map(|f| f.display().to_string())
        .collect();
    let sidecar = std::fs::read_to_string(out.join("campfire.json")).expect("sidecar");
    let json: serde_json::Value = serde_json::from_str(&sidecar).expect("json");
    assert_eq!(
        json["passes"],
        serde_json::json!(["color", "sixway_rtba", "sixway_lbfe"]),
        "{names:?}"
    );
    let packing = json["sixway_packing"].as_str().unwrap_or_default();
    assert!(
        packing.contains("R lit from the camera's right") && packing.contains("A emissive"),
        "{packing}"
    );
    let (w, h) = (64usize, 64usize);
    let centre = |pass: &str| exr(&out, pass, 0)[h / 2 * w + w / 2];
    let y = |c: [f32; 3]| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    let albedo = y(common::ALBEDO);
    let map = |b: u8| albedo * f32::from(b) / 255.0;
    let (rtba, lbfe) = (centre("sixway_rtba"), centre("sixway_lbfe"));
    let want_rtba = [
        map(common::FLAT_RTBA[0]),
        map(common::FLAT_RTBA[1]),
        map(common::FLAT_RTBA[2]),
        1.0,
    ];
    let want_lbfe = [
        map(common::FLAT_LBFE[0]),
        map(common::FLAT_LBFE[1]),
        map(common::FLAT_LBFE[2]),
        0.5,
    ];
    for c in 0..4 {
        assert!(
            (rtba[c] - want_rtba[c]).abs() < 2e-3,
            "RTBA {rtba:?}, want {want_rtba:?}"
        );
        assert!(
            (lbfe[c] - want_lbfe[c]).abs() < 2e-3,
            "LBFE {lbfe:?}, want {want_lbfe:?}"
        );
    }
}

/// `--passes distortion`: the campfire's heat haze as RG offsets around 0.5, its scale in
/// the sidecar; where there is no haze (the frame's corners, and every pixel of an effect
/// without haze) exactly 0.5; the colour pass is not refracted (the same as without it).
#[test]
fn the_distortion_pass_holds_the_heat_haze_offsets() {
    let dir = tempfile::tempdir().expect("tempdir");
    let passes = |distortion| Passes {
        distortion,
        ..Passes::COLOR
    };
    let run = |effect: &Effect, name: &str, distortion: bool| {
        let out = dir.path().join(name);
        let settings = ExportSettings {
            passes: passes(distortion),
            format: Format::Exr,
            ..sequence(&out, 1, 0.1)
        };
        export(effect, settings);
        out
    };
    let campfire = preset("campfire");
    let out = run(&campfire, "hazed", true);
    let sidecar = std::fs::read_to_string(out.join("campfire.json")).expect("sidecar");
    let json: serde_json::Value = serde_json::from_str(&sidecar).expect("json");
    assert_eq!(json["passes"], serde_json::json!(["color", "distortion"]));
    assert_eq!(json["distortion_scale"], serde_json::json!(0.1));
    let d = exr(&out, "distortion", 0);
    let largest = d
        .iter()
        .map(|p| (p[0] - 0.5).abs().max((p[1] - 0.5).abs()))
        .fold(0.0f32, f32::max);
    assert!(largest > 1e-3, "the haze wrote no offset ({largest})");
    for corner in [0, 63, 64 * 63, 64 * 64 - 1] {
        assert_eq!(&d[corner][..2], &[0.5, 0.5], "pixel {corner}");
    }
    let plain = run(&campfire, "plain", false);
    assert!(
        exr(&out, "color", 0) == exr(&plain, "color", 0),
        "the colour pass was refracted"
    );
    let mut torch = preset("torch");
    torch.name = "campfire".into();
    let none = run(&torch, "none", true);
    let d = exr(&none, "distortion", 0);
    assert!(d.iter().all(|p| p[0] == 0.5 && p[1] == 0.5));
}
