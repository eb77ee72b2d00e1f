//! Fuzzing the two parsers that read what users write: the preset loader (RON) and the
//! shader composer (`#import` resolution), with proptest over arbitrary and mutated text.
//! Neither may panic or hang: every input gives an effect or a located error.
//! `PROPTEST_CASES` sets the cases (CI: the default 256 each; long runs: see
//! `docs/architecture.md#tests`). Every case runs under a time limit ([`CASE_LIMIT`]): a
//! hang fails the test instead of stalling CI. Inputs that once failed are kept as
//! regression tests.
#![cfg(feature = "editor")]

use proptest::prelude::*;

use ignis::testing::shaders::ShaderLibrary;

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

/// How long one case may take (a parse takes microseconds to milliseconds).
const CASE_LIMIT: std::time::Duration = std::time::Duration::from_secs(10);

/// Runs `work` on a thread of its own and returns its result, or an error naming the
/// input when it has not finished within [`CASE_LIMIT`] (the hung thread is left behind;
/// the test fails).
fn within_limit<T: Send + 'static>(
    what: &str,
    work: impl FnOnce() -> T + Send + 'static,
) -> Result<T, TestCaseError> {
    within(CASE_LIMIT, what, work)
}

/// [`within_limit`] with another limit.
fn within<T: Send + 'static>(
    limit: std::time::Duration,
    what: &str,
    work: impl FnOnce() -> T + Send + 'static,
) -> Result<T, TestCaseError> {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(work());
    });
    rx.recv_timeout(limit)
        .map_err(|_| TestCaseError::fail(format!("no result within {limit:?}: {what}")))
}

const PRESETS: [&str; 3] = [
    include_str!("../presets/campfire.ron"),
    include_str!("../presets/torch.ron"),
    include_str!("../presets/spark_fountain.ron"),
];

proptest! {
    #[test]
    fn the_preset_loader_never_panics_on_arbitrary_text(text in "\\PC{0,400}") {
        let input = text.clone();
        within_limit(&text, move || ignis::preset::parse_str(&input, "fuzz.ron").is_ok())?;
    }

    #[test]
    fn the_preset_loader_never_panics_on_mutated_presets(
        which in 0usize..3,
        edits in prop::collection::vec((0.0f64..1.0, any::<u8>(), any::<u8>()), 1..12),
        cut in 0.0f64..1.0,
    ) {
        let text = mutated(PRESETS[which], &edits, 0.5 + cut / 2.0);
        let input = text.clone();
        let parsed = within_limit(&text, move || {
            ignis::preset::parse_str(&input, "fuzz.ron").map_err(|e| e.to_string())
        })?;
        if let Err(e) = parsed {
            // A located, non-empty message.
            prop_assert!(!e.is_empty());
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
        let composed = within_limit(&format!("{files:?}"), move || {
            lib.compose("entry.wgsl").map(|_| ()).map_err(|e| e.to_string())
        })?;
        if let Err(e) = composed {
            prop_assert!(!e.is_empty());
        }
    }
}

/// The time limit fails a case that hangs (a case that sleeps past it), and passes one
/// that finishes.
#[test]
fn a_hung_case_fails_instead_of_stalling() {
    let limit = std::time::Duration::from_millis(50);
    let hung = within(limit, "sleeps", move || std::thread::sleep(limit * 20));
    assert!(hung.is_err_and(|e| e.to_string().contains("no result within")));
    assert_eq!(within(limit, "returns", || 7).ok(), Some(7));
}

/// The text at a 1-based line and character column.
fn text_at(text: &str, line: usize, column: usize) -> &str {
    let start: usize = text
        .split_inclusive('\n')
        .take(line - 1)
        .map(str::len)
        .sum();
    let rest = &text[start..];
    let offset = rest
        .char_indices()
        .nth(column - 1)
        .map_or(rest.len(), |(i, _)| i);
    &rest[offset..]
}

/// Inputs of the kinds that break hand-written parsers and position arithmetic, kept as
/// regressions: every one gives an effect or a located error, and every value validation
/// refuses is located exactly where its text is — after CRLF line ends, multi-byte
/// characters, comments, signs and exponents.
#[test]
fn loader_regressions_locate_values_exactly_or_fail_cleanly() {
    let campfire = PRESETS[0];
    let rate = "spawn_rate_per_sec: Constant(2000.0)";
    assert!(campfire.contains(rate), "the campfire's flame rate");
    let negative = campfire.replacen(rate, "spawn_rate_per_sec: Constant(-5)", 1);
    let variants = [
        negative.clone(),
        negative.replace('\n', "\r\n"),
        negative.replacen("(\n", "( // ünïcödé ✓ 🔥\n", 1),
        negative.replacen("-5", "/* was 2000 */ -5", 1),
        negative.replacen("-5", "-5e0", 1),
        campfire.replacen(rate, "spawn_rate_per_sec: Constant(1e39)", 1),
    ];
    for text in &variants {
        let err = ignis::preset::parse_str(text, "r.ron").expect_err("invalid");
        let ignis::preset::PresetError::Invalid {
            errors, positions, ..
        } = &err
        else {
            panic!("not a validation error: {err}");
        };
        let p = positions[0].unwrap_or_else(|| panic!("unlocated: {err}"));
        let at = text_at(text, p.line, p.column);
        assert!(
            at.starts_with(errors[0].value.as_str()),
            "{err}: the text at {p} is {:?}",
            &at[..at.len().min(20)]
        );
    }
    // Broken text: an error with a position inside the text, never a panic.
    let deep = format!(
        "(version: 1, emitters: {}{})",
        "[".repeat(300),
        "]".repeat(300)
    );
    let broken = [
        String::new(),
        "\u{feff}".to_owned(),
        "\0".to_owned(),
        deep,
        "(version: 99999999999999999999999, emitters: [])".to_owned(),
        "(version: -1, emitters: [])".to_owned(),
        "(version: \"1\", emitters: [])".to_owned(),
        "(inner: (version: 9), emitters: [".to_owned(),
        "(version: 1, name: r##\"a\"#, emitters: [])".to_owned(),
        "(version: 1, /* never closed".to_owned(),
        "(version: 1, name: \"runs\n over\n lines, emitters: [])".to_owned(),
        "(version: 1, emitters: [Some((name: \"x\"".to_owned(),
        "#![enable(implicit_some)] (version: 2)".to_owned(),
    ];
    for text in &broken {
        let err = ignis::preset::parse_str(text, "r.ron").expect_err("broken");
        if let Some(p) = err.position() {
            let lines = text.split('\n').count().max(1);
            assert!(p.line >= 1 && p.line <= lines && p.column >= 1, "{err}");
        }
    }
}
