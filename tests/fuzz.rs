//! Fuzzing the two parsers that read what users write: the preset loader (RON) and the
//! shader composer (`#import` resolution), with proptest over arbitrary and mutated text.
//! Neither may panic or hang: every input gives an effect or a located error.
//! `PROPTEST_CASES` sets the cases (CI: the default 256 each; long runs: see
//! `docs/architecture.md#tests`). Inputs that once failed are kept as regression tests.
#![cfg(feature = "editor")]

use proptest::prelude::*;

use ignis::shaders::ShaderLibrary;

/// A shipped preset with `edits` applied: (position fraction, byte) replacements,
/// insertions and a truncation — text close to valid RON, where parsers break.
fn mutated(base: &str, edits: &[(f64, u8, u8)], cut: f64) -> String {
    let mut bytes = base.as_bytes().to_vec();
    for &(at, byte, kind) in edits {
        if bytes.is_empty() {
            break;
        }
        let i = ((at * bytes.len() as f64) as usize).min(bytes.len() - 1);
        match kind % 3 {
            0 => bytes[i] = byte,
            1 => bytes.insert(i, byte),
            _ => {
                bytes.remove(i);
            }
        }
    }
    bytes.truncate(((cut * bytes.len() as f64) as usize).max(1));
    String::from_utf8_lossy(&bytes).into_owned()
}

const PRESETS: [&str; 3] = [
    include_str!("../presets/campfire.ron"),
    include_str!("../presets/torch.ron"),
    include_str!("../presets/spark_fountain.ron"),
];

proptest! {
    #[test]
    fn the_preset_loader_never_panics_on_arbitrary_text(text in "\\PC{0,400}") {
        let _ = ignis::preset::parse_str(&text, "fuzz.ron");
    }

    #[test]
    fn the_preset_loader_never_panics_on_mutated_presets(
        which in 0usize..3,
        edits in prop::collection::vec((0.0f64..1.0, any::<u8>(), any::<u8>()), 1..12),
        cut in 0.0f64..1.0,
    ) {
        let text = mutated(PRESETS[which], &edits, 0.5 + cut / 2.0);
        if let Err(e) = ignis::preset::parse_str(&text, "fuzz.ron") {
            // A located, non-empty message.
            prop_assert!(!e.to_string().is_empty());
        }
    }

    #[test]
    fn the_shader_composer_never_panics_or_loops(
        files in prop::collection::vec(
            prop::collection::vec(
                prop_oneof![
                    Just("#import \"a.wgsl\"".to_owned()),
                    Just("#import \"b.wgsl\"".to_owned()),
                    Just("#import \"entry.wgsl\"".to_owned()),
                    Just("#import \"missing.wgsl\"".to_owned()),
                    Just("#import \"../outside.wgsl\"".to_owned()),
                    Just("#import".to_owned()),
                    Just("#import \"a.wgsl".to_owned()),
                    "\\PC{0,40}",
                    Just("fn f() -> f32 { return 1.0; }".to_owned()),
                    Just("@compute @workgroup_size(1) fn main() {}".to_owned()),
                ],
                0..8,
            ),
            3,
        ),
    ) {
        let dir = tempfile::tempdir().expect("tempdir");
        for (name, lines) in ["entry.wgsl", "a.wgsl", "b.wgsl"].iter().zip(&files) {
            std::fs::write(dir.path().join(name), lines.join("\n")).expect("write");
        }
        let lib = ShaderLibrary::from_dir(dir.path());
        if let Err(e) = lib.compose("entry.wgsl") {
            prop_assert!(!e.to_string().is_empty());
        }
    }
}
