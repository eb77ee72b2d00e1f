//! Shader composition and validation: every entry file validates, Rust and WGSL struct
//! layouts agree, errors point at the right file, line and column.

use ignis::testing::gpu::types::{CameraUniform, LookUniform, Particle, SimParams, ToneUniform};
use ignis::testing::shaders::{EMBEDDED, ENTRY_FILES, ShaderError, ShaderLibrary};

fn project_shaders() -> ShaderLibrary {
    ShaderLibrary::from_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/shaders"))
}

/// Every pipeline's entry file composes and validates with naga, from disk and embedded.
#[test]
fn every_entry_validates() {
    for lib in [project_shaders(), ShaderLibrary::embedded()] {
        for entry in ENTRY_FILES {
            if let Err(e) = lib.compose(entry) {
                panic!("{entry}: {e}");
            }
        }
    }
    // Every .wgsl on disk is embedded and reached by some entry.
    let dir = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/shaders"));
    let mut reached = std::collections::HashSet::new();
    for entry in ENTRY_FILES {
        reached.extend(project_shaders().compose(entry).expect("valid").files);
    }
    // The packed-state update: update.wgsl with state_packed.wgsl as its state I/O.
    let packed = project_shaders()
        .compose_with("update.wgsl", &[ignis::testing::shaders::PACKED_STATE_IO])
        .unwrap_or_else(|e| panic!("packed update: {e}"));
    assert!(packed.files.iter().any(|f| f == "state_packed.wgsl"));
    assert!(!packed.files.iter().any(|f| f == "state_full.wgsl"));
    // The tiny-state update: state_tiny.wgsl (and the birth table) as its state I/O.
    let tiny = project_shaders()
        .compose_with("update.wgsl", &[ignis::testing::shaders::TINY_STATE_IO])
        .unwrap_or_else(|e| panic!("tiny update: {e}"));
    assert!(tiny.files.iter().any(|f| f == "state_tiny.wgsl"));
    assert!(!tiny.files.iter().any(|f| f == "state_full.wgsl"));
    // Hot reload's dependencies of the update pass include the variants.
    let deps = project_shaders().dependencies("update.wgsl").expect("deps");
    assert!(deps.iter().any(|f| f == "state_packed.wgsl"));
    assert!(deps.iter().any(|f| f == "state_tiny.wgsl"));
    assert!(deps.iter().any(|f| f == "params_instanced.wgsl"));
    // A runtime player's batched instances: an array of parameters (params_instanced.wgsl).
    let instanced = project_shaders()
        .compose_with("update.wgsl", &[ignis::testing::shaders::PARAMS_INSTANCED])
        .unwrap_or_else(|e| panic!("update with batched instances: {e}"));
    assert!(instanced.files.iter().any(|f| f == "params_instanced.wgsl"));
    assert!(!instanced.files.iter().any(|f| f == "params.wgsl"));
    // The update's hooks, each composed in place of its empty twin: events (records and
    // bindings), a trail (the ring of positions), collision with the host's depth.
    use ignis::testing::shaders::{DEPTH_IO, EVENTS_IO, TRAIL_IO};
    for (off, on) in [EVENTS_IO, TRAIL_IO, DEPTH_IO] {
        let hooked = project_shaders()
            .compose_with("update.wgsl", &[(off, on)])
            .unwrap_or_else(|e| panic!("update with {on}: {e}"));
        assert!(hooked.files.iter().any(|f| f == on));
        assert!(!hooked.files.iter().any(|f| f == off));
        reached.extend(hooked.files);
    }
    // The splat's accumulation in one u64 per pixel (devices with 64-bit atomics).
    let splat64 = project_shaders()
        .compose_with("splat.wgsl", &[ignis::testing::shaders::SPLAT_ACCUM64])
        .unwrap_or_else(|e| panic!("splat with 64-bit atomics: {e}"));
    assert!(splat64.files.iter().any(|f| f == "splat_accum64.wgsl"));
    assert!(!splat64.files.iter().any(|f| f == "splat_accum.wgsl"));
    reached.extend(splat64.files);
    reached.extend(packed.files);
    reached.extend(tiny.files);
    reached.extend(instanced.files);
    for f in std::fs::read_dir(dir).expect("shaders/") {
        let name = f.expect("entry").file_name().to_string_lossy().into_owned();
        if name.ends_with(".wgsl") {
            assert!(
                EMBEDDED.iter().any(|(n, _)| *n == name),
                "{name} is not embedded"
            );
            assert!(
                reached.contains(&name),
                "{name} is not imported by any pipeline"
            );
        }
    }
}

/// `size_of` of every GPU-shared Rust struct equals naga's layout of the WGSL struct.
#[test]
fn rust_and_wgsl_struct_sizes_agree() {
    let lib = project_shaders();
    let update = lib.compose("update.wgsl").expect("update");
    let billboard = lib.compose("billboard.wgsl").expect("billboard");
    let tonemap = lib.compose("tonemap.wgsl").expect("tonemap");
    let scan = lib.compose("events.wgsl").expect("events");
    use ignis::testing::sim::event_scan::{EventRule, EventSpawn, ScanConfig};
    let cases = [
        (&scan, "EventRule", size_of::<EventRule>()),
        (&scan, "EventSpawn", size_of::<EventSpawn>()),
        (&scan, "ScanConfig", size_of::<ScanConfig>()),
        (&update, "Particle", size_of::<Particle>()),
        (&update, "SimParams", size_of::<SimParams>()),
        (
            &update,
            "PackedParticle",
            size_of::<ignis::testing::gpu::types::PackedParticle>(),
        ),
        (
            &update,
            "Birth",
            size_of::<ignis::testing::gpu::types::Birth>(),
        ),
        (&billboard, "CameraUniform", size_of::<CameraUniform>()),
        (&billboard, "LookUniform", size_of::<LookUniform>()),
        (&tonemap, "ToneUniform", size_of::<ToneUniform>()),
    ];
    for (composed, name, rust) in cases {
        let wgsl = composed
            .struct_size(name)
            .unwrap_or_else(|| panic!("{name} not found"));
        assert_eq!(
            wgsl as usize, rust,
            "{name}: WGSL {wgsl} bytes, Rust {rust} bytes"
        );
    }
}

fn temp_copy() -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("tempdir");
    for (name, text) in EMBEDDED {
        std::fs::write(dir.path().join(name), text).expect("write");
    }
    dir
}

fn located(err: &ShaderError) -> (String, u32, u32) {
    match err.location() {
        Some((f, l, c)) => (f.to_owned(), l, c),
        None => panic!("error has no location: {err}"),
    }
}

/// A syntax error in an imported file is reported at that file's line and column, with
/// a caret snippet.
#[test]
fn errors_point_at_the_imported_file() {
    let dir = temp_copy();
    let path = dir.path().join("forces.wgsl");
    let text = std::fs::read_to_string(&path).expect("read");
    let broken = text.replace(
        "a -= params.accel_drag.w * over_life.y * (vel - wind);",
        "a -= params.accel_drag.w * over_life.y * (vel - wind;",
    );
    assert_ne!(text, broken);
    std::fs::write(&path, &broken).expect("write");
    let line = broken
        .lines()
        .position(|l| l.contains("(vel - wind;"))
        .expect("line") as u32
        + 1;
    let err = ShaderLibrary::from_dir(dir.path())
        .compose("update.wgsl")
        .expect_err("must fail");
    let (file, l, col) = located(&err);
    assert!(file.ends_with("forces.wgsl"), "{file}");
    assert_eq!(l, line, "{err}");
    assert!(col > 1);
    let shown = err.to_string();
    assert!(
        shown.contains(&format!("forces.wgsl:{line}:{col}")),
        "{shown}"
    );
    assert!(shown.contains('^'), "no caret: {shown}");
}

/// Type errors (validation), missing imports and unknown identifiers are located too.
#[test]
fn validation_and_import_errors_are_located() {
    let dir = temp_copy();
    let lib = ShaderLibrary::from_dir(dir.path());
    let forces = dir.path().join("forces.wgsl");
    let original = std::fs::read_to_string(&forces).expect("read");

    // A type error: vec3 returned where f32 expected.
    std::fs::write(
        &forces,
        original.replace(
            "fn acceleration(pos: vec3<f32>, vel: vec3<f32>, age: f32, life: f32, time: f32) -> \
                vec3<f32> {",
            "fn acceleration(pos: vec3<f32>, vel: vec3<f32>, age: f32, life: f32, time: f32) -> \
                f32 {",
        ),
    )
    .expect("write");
    let err = lib.compose("update.wgsl").expect_err("type error");
    assert!(located(&err).0.ends_with("forces.wgsl"), "{err}");

    // A missing import is reported at the #import line.
    std::fs::write(
        &forces,
        original.replace("#import \"common.wgsl\"", "#import \"nope.wgsl\""),
    )
    .expect("write");
    let err = lib.compose("update.wgsl").expect_err("missing import");
    let (file, line, _) = located(&err);
    assert!(file.ends_with("forces.wgsl"), "{err}");
    let want = original
        .lines()
        .position(|l| l.contains("#import \"common.wgsl\""))
        .expect("import") as u32
        + 1;
    assert_eq!(line, want);
    assert!(err.to_string().contains("nope.wgsl"));

    // An empty file.
    std::fs::write(dir.path().join("tonemap.wgsl"), "").expect("write");
    assert!(lib.compose("tonemap.wgsl").is_err());
}

/// The bench's bare variant (module code removed) still validates, and really lacks the
/// module code.
#[test]
fn bare_variant_validates_without_module_code() {
    let bare = project_shaders().without_modules().expect("bare");
    for entry in ENTRY_FILES {
        if let Err(e) = bare.compose(entry) {
            panic!("bare {entry}: {e}");
        }
    }
    let update = bare.compose("update.wgsl").expect("update").source;
    assert!(!update.contains("if MOD_COLLISIONS"));
    assert!(!update.contains("if MOD_TURBULENCE"));
    assert!(
        update.contains("if MOD_DRAG"),
        "drag is not an optional-module block"
    );
}
