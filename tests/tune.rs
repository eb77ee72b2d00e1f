//! `ignis tune` on a real adapter: the image error measure (zero against itself, a known
//! change computed independently), the references converge, the frontier is a frontier,
//! the tuned preset meets its budget when measured again, a module that does nothing is
//! flagged, the same seed gives the same particles at every step, and bad options are
//! refused with nothing written.

// `ignis tune` and the `ignis` binary: the default `editor` feature.
#![cfg(feature = "editor")]

mod common;

use std::path::{Path, PathBuf};

use common::*;
use ignis::effect::{Effect, Vortex};
use ignis::testing::headless::Headless;
use ignis::testing::shaders::ShaderLibrary;
use ignis::tune::*;

fn preset_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("presets/{name}.ron"))
}

fn preset(name: &str) -> Effect {
    ignis::preset::load(&preset_path(name)).expect("shipped preset")
}

/// Small and short: lavapipe runs a whole sweep in seconds. Three rates, not four: the
/// finest reference (1/3840 s at 240 steps a second) would double the sweep's time.
fn small(span_secs: f64) -> SweepOptions {
    SweepOptions {
        span_secs,
        size: (96, 54),
        fps: 15.0,
        cost_frames: 2,
        check_reference: true,
        asset_dir: Some(preset_path("campfire").parent().expect("dir").into()),
        rates: vec![30, 60, 120],
    }
}

/// Frames of `effect` as the display shows them (8-bit sRGB, RGB), played at `opts.fps`.
fn frames_of(effect: &Effect, opts: &SweepOptions) -> Vec<Vec<u8>> {
    let ctx = gpu();
    // The preset's sprite paths are relative to its folder.
    let settings = ignis::PlayerSettings {
        asset_dir: opts.asset_dir.clone(),
        ..ignis::testing::composite::Composite::player_settings()
    };
    let mut run =
        Headless::with_settings(&ctx, effect.clone(), ShaderLibrary::embedded(), settings)
            .expect("play");
    (0..opts.frames())
        .map(|_| {
            run.advance(1.0 / opts.fps);
            let img = run.render(opts.size).expect("render");
            img.pixels().flat_map(|p| [p[0], p[1], p[2]]).collect()
        })
        .collect()
}

#[test]
fn an_effect_against_itself_has_no_error_and_a_known_change_the_one_computed_here() {
    let ctx = gpu();
    let opts = small(0.6);
    let effect = preset("torch");
    let same = measure_pair(&ctx, &effect, &effect, &opts).expect("measure");
    assert_eq!((same.mean, same.max), (0.0, 0), "{same:?}");
    // The flame's colour at half: the error computed here from the two runs' frames.
    let mut dim = effect.clone();
    let flames = dim
        .emitters
        .iter()
        .position(|e| e.name == "flame")
        .expect("the torch's flame");
    for stop in &mut dim.emitters[flames].look.color_over_life {
        for c in &mut stop.rgba[..3] {
            *c *= 0.5;
        }
    }
    let measured = measure_pair(&ctx, &effect, &dim, &opts).expect("measure");
    let (a, b) = (frames_of(&effect, &opts), frames_of(&dim, &opts));
    let (mut sum, mut n, mut max) = (0u64, 0u64, 0u8);
    let mut frame_means = Vec::new();
    for (fa, fb) in a.iter().zip(&b) {
        let d: u64 = fa
            .iter()
            .zip(fb)
            .map(|(x, y)| u64::from(x.abs_diff(*y)))
            .sum();
        frame_means.push(d as f64 / fa.len() as f64);
        sum += d;
        n += fa.len() as u64;
        max = max.max(
            fa.iter()
                .zip(fb)
                .map(|(x, y)| x.abs_diff(*y))
                .max()
                .unwrap_or(0),
        );
    }
    assert!(sum > 0, "halving the flames' colour changes the image");
    assert!(
        (measured.mean - sum as f64 / n as f64).abs() < 1e-12,
        "{measured:?}"
    );
    assert_eq!(measured.max, max);
    let worst = frame_means
        .iter()
        .enumerate()
        .fold((0, 0.0), |w, (i, &m)| if m > w.1 { (i, m) } else { w });
    assert_eq!(measured.worst_frame, worst.0);
}

/// The sweep over the campfire (with a vortex of strength 0 added to its flames): the
/// references converge, the frontier is a frontier holding the cheapest and the most
/// accurate candidates, the zero vortex contributes nothing and is flagged, and the tuned
/// preset loads, meets its budget measured again on its own, and costs no more than the
/// effect as authored where that already met the budget.
#[test]
fn a_sweep_of_the_campfire_gives_a_frontier_and_a_tuned_preset_within_budget() {
    let ctx = gpu();
    let mut effect = preset("campfire");
    let flames = effect
        .emitters
        .iter()
        .position(|e| e.name == "flames")
        .expect("flames");
    effect.emitters[flames].forces.vortex = Some(Vortex {
        swirl_m_per_s2: 0.0,
        ..Vortex::default()
    });
    let opts = small(0.6);
    let mut sweep = Sweep::new(&ctx, &effect, opts.clone()).expect("sweep");
    let mut calls = 0;
    run_sweep(&mut sweep, |done, total| {
        assert!(done <= total, "{done}/{total}");
        calls += 1;
    })
    .expect("run");
    assert!(calls > 100, "progress after each frame of work: {calls}");
    let budget = Budget::ErrorMean(2.0);
    let report = TuneReport::new(&sweep, budget, &ctx.info.name).expect("report");
    check_reference_converges(&report);
    check_frontier(&report);
    check_zero_vortex(&report, &effect.emitters[flames].name, 2.0);
    check_tuned(&ctx, &report, &effect, &opts, 2.0);
    check_impossible_budget(&sweep, &effect, &ctx.info.name);
}

/// A budget no candidate meets: the error names the best reached; the measurements are
/// written, no tuned preset.
fn check_impossible_budget(sweep: &Sweep, effect: &Effect, adapter: &str) {
    let report = TuneReport::new(sweep, Budget::ErrorMean(1e-6), adapter).expect("report");
    assert_eq!(report.chosen, None);
    let best = report
        .results
        .iter()
        .map(|m| m.error.mean)
        .fold(f64::INFINITY, f64::min);
    let message = report.over_budget().expect("over budget").to_string();
    assert!(
        message.contains("no candidate is within") && message.contains(&format!("{best:.3}/255")),
        "{message}"
    );
    let dir = tempfile::tempdir().expect("tempdir");
    let files = report.write(effect, dir.path()).expect("write");
    assert_eq!(files.len(), 3, "{files:?}");
    assert!(!dir.path().join("campfire.tuned.ron").exists());
}

/// A second preset's references converge too (the campfire's are checked with its sweep):
/// the sweep's first run, stopped there. The torch's reference differs from itself at half
/// its step by 0.011–0.021/255 on lavapipe, its finest candidates by ~0.1/255, so the
/// bound is the absolute one, [`CONVERGED_MEAN`].
#[test]
fn the_torch_references_converge() {
    let ctx = gpu();
    let mut sweep = Sweep::new(&ctx, &preset("torch"), small(0.5)).expect("sweep");
    while sweep.reference_check().is_none() {
        assert!(
            !sweep.step().expect("step"),
            "the sweep ended before its check"
        );
    }
    let check = sweep.reference_check().expect("checked");
    assert!(
        check.mean > 0.0 && check.mean < CONVERGED_MEAN,
        "reference vs half its step: {} (/255 mean)",
        check.mean
    );
}

/// A reference within this of itself at half its step (mean, in 8-bit levels) has
/// converged whatever the candidates' errors: the f32 round-off the flames' turbulence
/// amplifies.
const CONVERGED_MEAN: f64 = 0.05;

fn check_reference_converges(report: &TuneReport) {
    let check = report.reference_check.expect("checked");
    let smallest = report
        .results
        .iter()
        .map(|m| m.error.mean)
        .fold(f64::INFINITY, f64::min);
    assert!(smallest > 0.0, "every candidate differs from its reference");
    // Converged: far below the best candidate's error, or below a twentieth of an 8-bit
    // level on average, where the finest candidates' errors (~0.1/255 for the torch) are
    // the f32 round-off that the flames' turbulence amplifies, as is the reference's
    // difference from itself at half its step (the torch: 0.011–0.021/255).
    assert!(
        check.mean < 0.1 * smallest || check.mean < CONVERGED_MEAN,
        "reference vs half its step {} against the smallest candidate error {smallest}",
        check.mean
    );
}

fn check_frontier(report: &TuneReport) {
    let r = &report.results;
    let front = &report.frontier;
    assert!(!front.is_empty());
    for &i in front {
        for (j, m) in r.iter().enumerate() {
            let dominates = m.error.mean <= r[i].error.mean
                && m.frame_ms <= r[i].frame_ms
                && (m.error.mean, m.frame_ms) != (r[i].error.mean, r[i].frame_ms);
            assert!(!dominates, "{} dominated by {}", r[i].label, r[j].label);
        }
    }
    let cheapest = (0..r.len())
        .min_by(|&a, &b| r[a].frame_ms.total_cmp(&r[b].frame_ms))
        .expect("results");
    let most_accurate = (0..r.len())
        .min_by(|&a, &b| r[a].error.mean.total_cmp(&r[b].error.mean))
        .expect("results");
    assert!(front.contains(&cheapest), "the cheapest is on the frontier");
    assert!(
        front
            .iter()
            .any(|&i| r[i].error.mean == r[most_accurate].error.mean),
        "the most accurate is on the frontier"
    );
    // Every axis was tried: six integrators at three steps, the state layouts, the draw
    // paths, the modules.
    let first = r.iter().filter(|m| m.round == 1).count();
    assert!(first >= 27, "{first} candidates in the first round");
    assert!(
        r.iter().any(|m| m.round == 2),
        "combinations along the frontier"
    );
}

fn check_zero_vortex(report: &TuneReport, flames: &str, budget: f64) {
    let label = format!("{flames}: vortex");
    let row = report
        .modules
        .iter()
        .find(|m| m.label == label)
        .unwrap_or_else(|| panic!("no {label} row in {:?}", report.modules));
    assert_eq!(
        row.contribution.mean, 0.0,
        "a vortex of strength 0 changes nothing"
    );
    assert!(row.not_needed, "{row:?}");
    // Flagged exactly where the contribution is below the budget's error; the others
    // show on screen (measured, not assumed).
    for m in &report.modules {
        assert_eq!(m.not_needed, m.contribution.mean < budget, "{m:?}");
    }
    assert!(
        report.modules.iter().any(|m| m.contribution.mean > 0.1),
        "{:?}",
        report.modules
    );
}

fn check_tuned(
    ctx: &ignis::testing::gpu::GpuContext,
    report: &TuneReport,
    effect: &Effect,
    opts: &SweepOptions,
    budget: f64,
) {
    let dir = tempfile::tempdir().expect("tempdir");
    let files = report.write(effect, dir.path()).expect("write");
    assert_eq!(files.len(), 4);
    let tuned_path = dir.path().join("campfire.tuned.ron");
    let text = std::fs::read_to_string(&tuned_path).expect("tuned preset");
    assert!(text.starts_with("// Tuned by `ignis tune`"), "{text}");
    let tuned = ignis::preset::load(&tuned_path).expect("the tuned preset loads");
    tuned.validate().expect("and validates");
    let again = measure_against_reference(ctx, effect, &tuned, opts).expect("measure");
    let chosen = &report.results[report.chosen.expect("a candidate within the budget")];
    assert!(again.mean <= budget, "measured again: {again:?}");
    assert_eq!(
        again.mean, chosen.error.mean,
        "the same frames as in the sweep"
    );
    let authored = &report.results[report.authored];
    if authored.error.mean <= budget {
        assert!(chosen.frame_ms <= authored.frame_ms);
    }
    let svg = std::fs::read_to_string(dir.path().join("campfire.frontier.svg")).expect("svg");
    assert!(svg.contains("<svg") && svg.contains("frontier"));
}

/// Births are keyed by spawn counter: the campfire's flames at every step a sweep uses,
/// and at a sixteenth of the finest, hold the same particle in every slot alive in both
/// (same lifetime bits, drawn from the key), and the same number spawned.
#[test]
fn the_same_seed_gives_the_same_particles_at_every_step() {
    let ctx = gpu();
    let effect = preset("campfire");
    let flames = effect
        .emitters
        .iter()
        .position(|e| e.name == "flames")
        .expect("flames");
    let play = |step: f32| {
        let mut e = effect.clone();
        e.time.step_secs = step;
        let mut sim =
            ignis::testing::sim::GpuSim::new(&ctx, ShaderLibrary::embedded(), &e).expect("sim");
        let steps = (1.0 / step).round() as u32;
        sim.step(&e, step, steps).expect("step");
        let spawned = sim.planner.emitters[flames].stats.spawned;
        (sim.read_particles(flames).expect("read"), spawned)
    };
    let (base, spawned) = play(1.0 / 120.0);
    for step in [1.0 / 30.0, 1.0 / 60.0, 1.0 / 240.0, 1.0 / 3840.0] {
        let (other, n) = play(step);
        assert_eq!(n, spawned, "spawned at step {step}");
        let mut both = 0;
        for (slot, (a, b)) in base.iter().zip(&other).enumerate() {
            if a.is_alive() && b.is_alive() {
                both += 1;
                assert_eq!(
                    a.vel_life[3].to_bits(),
                    b.vel_life[3].to_bits(),
                    "slot {slot} at step {step}: another particle"
                );
            }
        }
        assert!(both > 1000, "{both} slots alive in both at step {step}");
    }
}

/// Bad options: a clear error naming the option, and nothing written.
#[test]
fn bad_options_are_refused_with_nothing_written() {
    let exe = env!("CARGO_BIN_EXE_ignis");
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("out");
    let campfire = preset_path("campfire");
    let missing = dir.path().join("missing.ron");
    let cases: [(&[&str], &str); 8] = [
        (&["--budget-error", "0"], "--budget-error"),
        (&["--budget-error=-1"], "--budget-error"),
        (&["--budget-ms", "0"], "--budget-ms"),
        (&["--span", "0"], "--span"),
        (&["--span=-2"], "--span"),
        (&["--size", "0x0"], "--size"),
        (&["--rates", "0"], "--rates"),
        (&["--rates", "60,5000"], "--rates"),
    ];
    for (args, option) in cases {
        let o = std::process::Command::new(exe)
            .arg("tune")
            .arg(&campfire)
            .args(args)
            .arg("--out")
            .arg(&out)
            .output()
            .expect("run ignis");
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{args:?} accepted");
        assert!(stderr.contains(option), "{args:?}: {stderr}");
        assert!(!out.exists(), "{args:?} wrote {}", out.display());
    }
    let o = std::process::Command::new(exe)
        .arg("tune")
        .arg(&missing)
        .arg("--out")
        .arg(&out)
        .output()
        .expect("run ignis");
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(stderr.contains("missing.ron"), "{stderr}");
    assert!(!out.exists());
}
