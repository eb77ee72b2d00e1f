//! WGSL hot reload on a real adapter: valid edits change the simulation, broken edits are
//! reported at file:line and leave the last good pipeline (and the particles) running,
//! fixes restore; the file watcher sees editor-style saves.
// The editor, the `ignis` binary or the benches: the default `editor` feature.
#![cfg(feature = "editor")]

mod common;

use std::path::Path;
use std::time::{Duration, Instant};

use common::*;
use ignis::effect::Effect;
use ignis::testing::composite::Composite;
use ignis::testing::gpu::GpuContext;
use ignis::testing::gpu::types::Particle;
use ignis::testing::hot_reload::{FileWatcher, ShaderReloader, wgsl_names};
use ignis::testing::shaders::{EMBEDDED, ShaderLibrary};
use ignis::{InstanceId, Player, PlayerSettings};

struct Rig {
    ctx: GpuContext,
    dir: tempfile::TempDir,
    /// Reloads its shaders.
    live: (Player, InstanceId),
    /// Built from the same files and never reloaded.
    control: (Player, InstanceId),
    composite: Composite,
    reloader: ShaderReloader,
}

/// An editor-style player (its own simulation) built from the WGSL in `dir`, with its one
/// instance.
fn player(ctx: &GpuContext, dir: &Path, effect: &Effect) -> (Player, InstanceId) {
    let settings = PlayerSettings {
        batch_instances: false,
        shader_dir: Some(dir.to_path_buf()),
        ..Composite::player_settings()
    };
    let mut player = Player::new(&ctx.device, &ctx.queue, effect, settings).expect("player");
    let id = player
        .add_instance(glam::Mat4::IDENTITY, effect.seed)
        .expect("instance");
    (player, id)
}

impl Rig {
    fn new() -> Self {
        let ctx = gpu();
        let dir = tempfile::tempdir().expect("tempdir");
        for (name, text) in EMBEDDED {
            std::fs::write(dir.path().join(name), text).expect("write");
        }
        let lib = ShaderLibrary::from_dir(dir.path());
        let mut e = plain_emitter();
        e.forces.buoyancy_m_per_s2 = 3.0;
        e.speed_m_per_s = ignis::effect::Range::new(0.5, 1.0);
        e.spread_deg = 30.0;
        let mut effect = bare_effect(e);
        effect.time.mode = ignis::effect::TimeMode::FixedStep;
        effect.time.step_secs = 1.0 / 120.0;
        let mut live = player(&ctx, dir.path(), &effect);
        let mut control = player(&ctx, dir.path(), &effect);
        play_steps(&ctx, &mut live.0, 30);
        play_steps(&ctx, &mut control.0, 30);
        let composite = Composite::new(&ctx, &lib).expect("composite");
        let reloader = ShaderReloader::new(&lib);
        Self {
            ctx,
            dir,
            live,
            control,
            composite,
            reloader,
        }
    }

    fn path(&self, name: &str) -> std::path::PathBuf {
        self.dir.path().join(name)
    }

    fn edit(&self, name: &str, from: &str, to: &str) {
        let text = std::fs::read_to_string(self.path(name)).expect("read");
        assert!(text.contains(from), "{name} lacks {from:?}");
        std::fs::write(self.path(name), text.replacen(from, to, 1)).expect("write");
    }

    fn reload(&mut self, changed: &[&str]) -> ignis::testing::hot_reload::ReloadReport {
        self.reload_at(changed, Instant::now())
    }

    fn reload_at(
        &mut self,
        changed: &[&str],
        noticed: Instant,
    ) -> ignis::testing::hot_reload::ReloadReport {
        let changed: Vec<String> = changed.iter().map(|s| (*s).to_owned()).collect();
        self.reloader.reload(
            &self.ctx,
            self.dir.path(),
            &mut self.live.0,
            &mut self.composite,
            &changed,
            noticed,
        )
    }

    /// The live player's particles.
    fn live_particles(&self) -> Vec<Particle> {
        self.live.0.particles(self.live.1, 0).expect("read")
    }

    /// Steps both players and returns their states.
    fn step_both(&mut self, steps: u32) -> (Vec<Particle>, Vec<Particle>) {
        play_steps(&self.ctx, &mut self.live.0, steps);
        play_steps(&self.ctx, &mut self.control.0, steps);
        (
            self.live_particles(),
            self.control.0.particles(self.control.1, 0).expect("read"),
        )
    }
}

fn original(name: &str) -> &'static str {
    EMBEDDED
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, t)| *t)
        .expect("embedded")
}

const ZERO_FORCE: &str = "fn acceleration(pos: vec3<f32>, vel: vec3<f32>, age: f32, life: f32, \
    time: f32) -> vec3<f32> {\n    return vec3<f32>(0.0);";
const FORCE_FN: &str = "fn acceleration(pos: vec3<f32>, vel: vec3<f32>, age: f32, life: f32, \
    time: f32) -> vec3<f32> {";

/// A valid edit (the force function returns zero) changes the simulated state after the
/// reload: velocities stop changing. The particles survive the reload.
#[test]
fn valid_edit_changes_behaviour() {
    let mut rig = Rig::new();
    let before = rig.live_particles();
    rig.edit("forces.wgsl", FORCE_FN, ZERO_FORCE);
    let report = rig.reload(&["forces.wgsl"]);
    assert_eq!(
        report.rebuilt,
        vec!["update.wgsl"],
        "{:?}",
        rig.reloader.errors
    );
    assert!(rig.reloader.errors.is_empty());
    let (live, control) = rig.step_both(20);
    let mut checked = 0;
    for ((b, l), c) in before.iter().zip(&live).zip(&control) {
        if b.is_alive() && l.is_alive() && l.pos_age[3] > b.pos_age[3] {
            // Same particle: with zero force its velocity is unchanged.
            assert_eq!(b.velocity(), l.velocity());
            assert_ne!(l.velocity(), c.velocity(), "control still accelerates");
            checked += 1;
        }
    }
    assert!(checked > 50, "only {checked} particles survived the reload");
}

/// Every kind of broken edit: an error naming the file (and line where the source has
/// one), the old pipeline keeps producing exactly the control's state, and the fix
/// restores the new behaviour.
#[test]
fn broken_edits_keep_the_last_good_pipeline() {
    let mut rig = Rig::new();
    type Break = (
        &'static str,
        &'static str,
        &'static str,
        Option<&'static str>,
    );
    let cases: Vec<Break> = vec![
        // (file, from, to, expected "file:line" substring)
        (
            "forces.wgsl",
            "a -= params.accel_drag.w * over_life.y * (vel - wind);",
            "a -= params.accel_drag.w * over_life.y * (vel - wind;",
            Some("forces.wgsl:"),
        ),
        (
            "forces.wgsl",
            FORCE_FN,
            "fn acceleration(pos: vec3<f32>, vel: vec3<f32>, age: f32, life: f32, time: f32) -> \
                f32 {",
            Some("forces.wgsl:"),
        ),
        (
            "forces.wgsl",
            "#import \"noise.wgsl\"",
            "#import \"nope.wgsl\"",
            Some("forces.wgsl:"),
        ),
        (
            "update.wgsl",
            "@group(0) @binding(3) var<storage, read_write> counters",
            "@group(0) @binding(7) var<storage, read_write> counters",
            None,
        ),
        ("update.wgsl", "fn main(", "fn main_renamed(", None),
        (
            "integrators.wgsl",
            "let s = dt / 6.0;",
            "let s = dt / undefined_thing;",
            Some("integrators.wgsl:"),
        ),
    ];
    for (file, from, to, located) in cases {
        rig.edit(file, from, to);
        let report = rig.reload(&[file]);
        assert_eq!(
            report.failed,
            vec!["update.wgsl"],
            "{file}: {from} → {to} did not fail"
        );
        let err = rig
            .reloader
            .errors
            .get("update.wgsl")
            .expect("error kept")
            .to_string();
        assert!(err.contains(file), "error does not name {file}: {err}");
        if let Some(loc) = located {
            let (f, line, col) = rig.reloader.errors["update.wgsl"]
                .location()
                .expect("located");
            assert!(f.ends_with(file) && line > 0 && col > 0, "{err}");
            assert!(err.contains(loc));
        }
        // The old pipeline keeps running: identical to the control.
        let (live, control) = rig.step_both(10);
        assert_eq!(
            live, control,
            "{file}: state diverged after a failed reload"
        );
        // Fix it: restore the original file.
        std::fs::write(rig.path(file), original(file)).expect("write");
        let report = rig.reload(&[file]);
        assert_eq!(
            report.rebuilt,
            vec!["update.wgsl"],
            "fix of {file} not picked up: {:?}",
            rig.reloader.errors
        );
        assert!(rig.reloader.errors.is_empty());
    }
    // After all that, the fix of a behaviour change still takes effect.
    rig.edit("forces.wgsl", FORCE_FN, ZERO_FORCE);
    assert_eq!(rig.reload(&["forces.wgsl"]).rebuilt, vec!["update.wgsl"]);
    let (live, control) = rig.step_both(5);
    assert_ne!(live, control);
}

/// A deleted file and a file saved empty fail cleanly (the file is named) and restore.
#[test]
fn deleted_and_empty_files() {
    let mut rig = Rig::new();
    std::fs::remove_file(rig.path("forces.wgsl")).expect("rm");
    let report = rig.reload(&["forces.wgsl"]);
    assert_eq!(report.failed, vec!["update.wgsl"]);
    assert!(
        rig.reloader.errors["update.wgsl"]
            .to_string()
            .contains("forces.wgsl")
    );
    let (live, control) = rig.step_both(5);
    assert_eq!(live, control);

    std::fs::write(rig.path("forces.wgsl"), "").expect("write");
    let report = rig.reload(&["forces.wgsl"]);
    assert_eq!(report.failed, vec!["update.wgsl"]);

    std::fs::write(rig.path("tonemap.wgsl"), "").expect("write");
    let report = rig.reload(&["tonemap.wgsl"]);
    assert!(report.failed.contains(&"tonemap.wgsl"));
    assert!(
        rig.reloader.errors["tonemap.wgsl"]
            .to_string()
            .contains("empty")
    );

    for f in ["forces.wgsl", "tonemap.wgsl"] {
        std::fs::write(rig.path(f), original(f)).expect("write");
    }
    let report = rig.reload(&["forces.wgsl", "tonemap.wgsl"]);
    assert!(report.failed.is_empty(), "{:?}", rig.reloader.errors);
    assert!(rig.reloader.errors.is_empty());
}

/// Each of the composite's own shaders saved empty fails its reload, named, and reloads
/// cleanly once restored: the composite rebuilds every pipeline it owns.
#[test]
fn the_composites_shaders_each_reload() {
    let mut rig = Rig::new();
    for f in [
        "tonemap.wgsl",
        "bloom.wgsl",
        "clear.wgsl",
        "test_scene.wgsl",
    ] {
        std::fs::write(rig.path(f), "").expect("write");
        let report = rig.reload(&[f]);
        assert!(
            report.failed.contains(&f),
            "{f} saved empty: {:?}",
            report.failed
        );
        std::fs::write(rig.path(f), original(f)).expect("write");
        let report = rig.reload(&[f]);
        assert!(
            report.failed.is_empty(),
            "{f} restored: {:?}",
            rig.reloader.errors
        );
    }
}

/// Only pipelines that depend on a changed file are rebuilt.
#[test]
fn only_dependent_pipelines_rebuild() {
    let mut rig = Rig::new();
    assert_eq!(rig.reload(&["forces.wgsl"]).rebuilt, vec!["update.wgsl"]);
    assert_eq!(rig.reload(&["tonemap.wgsl"]).rebuilt, vec!["tonemap.wgsl"]);
    assert_eq!(rig.reload(&["count.wgsl"]).rebuilt, vec!["count.wgsl"]);
    let mut look = rig.reload(&["look.wgsl"]).rebuilt;
    look.sort();
    assert_eq!(
        look,
        vec!["billboard.wgsl", "light.wgsl", "splat.wgsl", "tiles.wgsl"]
    );
    let mut all = rig.reload(&["common.wgsl"]).rebuilt;
    all.sort();
    assert_eq!(
        all,
        vec![
            "billboard.wgsl",
            "count.wgsl",
            "events.wgsl",
            "light.wgsl",
            "sort.wgsl",
            "splat.wgsl",
            "tiles.wgsl",
            "update.wgsl"
        ]
    );
}

fn wait_for(w: &FileWatcher, name: &str) -> Duration {
    let start = Instant::now();
    loop {
        let changed = wgsl_names(&w.wait(Duration::from_millis(100)));
        if changed.iter().any(|n| n == name) {
            return start.elapsed();
        }
        assert!(
            start.elapsed() < Duration::from_secs(5),
            "no change event for {name}"
        );
    }
}

fn save_via_rename(dir: &Path, name: &str, text: &str) {
    let tmp = dir.join(format!(".{name}.swp"));
    std::fs::write(&tmp, text).expect("write tmp");
    std::fs::rename(&tmp, dir.join(name)).expect("rename");
}

/// The watcher sees a plain overwrite, an editor's rename-replace save and two quick saves
/// (the reload then reads the last content); the end-to-end latency — file written →
/// new pipeline in use — is a fraction of a second (median of 5 printed).
#[test]
fn watcher_sees_editor_saves_and_reload_latency_is_small() {
    let mut rig = Rig::new();
    let watcher = FileWatcher::new(&[rig.dir.path()]).expect("watch");
    // Rename-replace.
    save_via_rename(
        rig.dir.path(),
        "forces.wgsl",
        &original("forces.wgsl").replacen(FORCE_FN, ZERO_FORCE, 1),
    );
    wait_for(&watcher, "forces.wgsl");
    // Two quick saves: broken, then valid; after the debounce the valid one is read.
    std::fs::write(rig.path("forces.wgsl"), "fn broken(").expect("write");
    std::fs::write(rig.path("forces.wgsl"), original("forces.wgsl")).expect("write");
    wait_for(&watcher, "forces.wgsl");
    let report = rig.reload(&["forces.wgsl"]);
    assert_eq!(
        report.rebuilt,
        vec!["update.wgsl"],
        "{:?}",
        rig.reloader.errors
    );

    let mut latencies = Vec::new();
    for i in 0..5 {
        let text = if i % 2 == 0 {
            original("forces.wgsl").replacen(FORCE_FN, ZERO_FORCE, 1)
        } else {
            original("forces.wgsl").to_owned()
        };
        let written = Instant::now();
        std::fs::write(rig.path("forces.wgsl"), text).expect("write");
        wait_for(&watcher, "forces.wgsl");
        let report = rig.reload_at(&["forces.wgsl"], written);
        assert_eq!(report.rebuilt, vec!["update.wgsl"]);
        latencies.push(rig.reloader.last_latency.expect("latency").as_secs_f64() * 1e3);
    }
    latencies.sort_by(f64::total_cmp);
    eprintln!(
        "hot reload latency (file written → new pipeline in use), ms: {latencies:?}; median {:.1}",
        latencies[2]
    );
    assert!(
        latencies[2] < 1000.0,
        "median reload latency {} ms",
        latencies[2]
    );
}
