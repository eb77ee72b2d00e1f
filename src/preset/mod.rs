//! Presets as RON: versioned loading with located errors, validation, atomic saving.
//!
//! A preset file (`presets/NAME.ron`) holds one [`Effect`]. The loader
//!
//! 1. reads the top-level `version` field first (without deserialising anything else), refuses
//!    versions newer than [`CURRENT_VERSION`] with a message saying to update ignis, and picks
//!    the reader for that version (the private `migrate` documents how older versions are
//!    brought up to date);
//! 2. deserialises with `serde_path_to_error`, so type errors, unknown fields (with the
//!    closest known name), missing fields and syntax errors name the file, `line:column`, the
//!    field path and what was expected;
//! 3. validates ranges and finiteness ([`Effect::validate`]) and locates every offending
//!    value in the text, so `emitters[1].spawn_rate_per_sec = -5: must be ≥ 0` also says
//!    where the `-5` is.
//!
//! [`save`] validates first, refuses to overwrite a file that does not load (that file may be
//! someone's unsaved work with a typo, or a newer version), and writes through a temporary
//! file in the same folder, fsync and rename, so a crash or a full disk never leaves a
//! half-written or empty preset. The text it writes ([`to_ron`]) is laid out like the
//! hand-written presets and loads back with the same options the loader uses.
//!
//! What the `ron` crate does and what is ours:
//! - Reading, writing and every position: `ron`. Values are found in the text by ron's own
//!   parser (`locate.rs`: a probe deserialiser that walks a field path and stops at the
//!   value, where ron's span says it is) — the version, the values validation refuses.
//! - The saved text's layout (`layout.rs`) is ours: ron's pretty-printer breaks lines by
//!   nesting depth, not width, so a preset's small groups (vectors, ranges, colour stops)
//!   would each take several lines. It re-lays out ron's own compact output.
//! - Error wording (`errors.rs`) over a tolerant tokenizer (`tokens.rs`) is ours: ron's
//!   errors say what was expected but not what was found there, nor the field path of a
//!   syntax error, nor which bracket a truncated file left open. Both are fuzzed
//!   (`tests/fuzz.rs`).

use std::path::{Path, PathBuf};

use crate::effect::{CURRENT_VERSION, Effect};

mod atomic;
mod errors;
mod explain;
mod layout;
mod locate;
mod tokens;
mod v1;
mod v2;

pub use atomic::{write_atomic, write_atomic_with};
pub use errors::PresetError;
use errors::clean_path;
use explain::explain;
pub use layout::to_ron;
use tokens::{Token, parse_integer, tokenize};

/// Files larger than this are refused before reading (no preset comes near it).
pub const MAX_PRESET_BYTES: u64 = 16 * 1024 * 1024;

/// A position in a preset's text: 1-based line and column (columns count characters).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct TextPos {
    /// 1-based line.
    pub line: usize,
    /// 1-based column, in characters.
    pub column: usize,
}

impl std::fmt::Display for TextPos {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}", self.line, self.column)
    }
}

/// Parses and validates preset text; `path` only names the file in errors.
pub fn parse_str(text: &str, path: &str) -> Result<Effect, PresetError> {
    let tokens = tokenize(text);
    // Read the version first: a future file gets a clear message, not a field error about a
    // field this build has never heard of.
    let version = locate::value_at(text, "version")
        .map(|v| (v.literal.as_deref().and_then(parse_integer), v.pos));
    let parse_err = |pos: TextPos, field: &str, message: String| PresetError::Parse {
        path: path.to_owned(),
        line: pos.line,
        column: pos.column,
        field: if field.is_empty() {
            String::new()
        } else {
            format!("{field}: ")
        },
        message,
    };
    let effect = match version {
        Some((Some(v), pos)) if v > u64::from(CURRENT_VERSION) => {
            return Err(PresetError::TooNew {
                path: path.to_owned(),
                line: pos.line,
                column: pos.column,
                found: v,
                supported: CURRENT_VERSION,
            });
        }
        Some((Some(0), pos)) => {
            return Err(parse_err(
                pos,
                "version",
                "found 0; the first preset format is version 1".into(),
            ));
        }
        Some((Some(v), _)) => migrate(v, text, path, &tokens)?,
        // Not a plain integer: the deserialiser says what is wrong with it.
        Some((None, _)) => deserialize::<Effect>(text, path, &tokens)?,
        None => {
            // Syntax errors first (a truncated file may have lost more than its version),
            // worded for a preset; any format's fields are fine, as the version is unknown.
            if deserialize::<serde::de::IgnoredAny>(text, path, &tokens).is_err() {
                deserialize::<Effect>(text, path, &tokens)?;
            }
            let pos = locate::value_at(text, "").map_or(TextPos { line: 1, column: 1 }, |d| d.pos);
            return Err(parse_err(
                pos,
                "",
                format!(
                    "missing required field `version` (write `version: {CURRENT_VERSION},` as the \
                     first field; it says which format the file is in)"
                ),
            ));
        }
    };
    if locate::value_at(text, "emitters").is_none()
        && let Some(document) = locate::value_at(text, "")
    {
        return Err(parse_err(
            document.pos,
            "",
            "missing required field `emitters` (a preset lists at least one emitter)".into(),
        ));
    }
    effect.validate().map_err(|mut errors| {
        let mut positions = Vec::with_capacity(errors.len());
        for e in &mut errors {
            let found = locate::locate(text, &e.path);
            positions.push(found.as_ref().map(|f| f.pos));
            // Show the number as written (`1e39`, `5.0`), and say why a huge literal is
            // not finite.
            if let Some(lit) = found.and_then(|f| f.literal) {
                if e.value.ends_with("inf") && lit.parse::<f64>().is_ok_and(f64::is_finite) {
                    e.problem = format!(
                        "{} ({lit} does not fit in a 32-bit float, whose largest value is about \
                         3.4e38)",
                        e.problem
                    );
                }
                e.value = lit;
            }
        }
        PresetError::Invalid {
            path: path.to_owned(),
            errors,
            positions,
        }
    })?;
    Ok(effect)
}

/// Reads a file of format `version` (1..=[`CURRENT_VERSION`]) and brings it up to the current
/// format.
///
/// Versions 1 and 2 are read through their frozen types (`v1.rs`, `v2.rs`) and converted
/// field by field into the same effect in today's model. When the format changes again
/// (version 4):
///
/// 1. copy the version-3 types that change into a frozen `mod v3` and keep them unchanged
///    from then on (and point the older conversions at them, or chain them);
/// 2. add `3 => deserialize::<v3::Effect>(…).map(Effect::from)` below, with the conversion
///    written out field by field (renamed fields, new fields with the value that reproduces
///    the old look, changed units);
/// 3. keep `tests/fixtures/v1…` and `v2/…` loading (their tests compare them with what the
///    conversion should give).
fn migrate(version: u64, text: &str, path: &str, tokens: &[Token]) -> Result<Effect, PresetError> {
    match version {
        1 => deserialize::<v1::Effect>(text, path, tokens).map(Effect::from),
        2 => deserialize::<v2::Effect>(text, path, tokens).map(Effect::from),
        3 => deserialize::<Effect>(text, path, tokens),
        // `parse_str` refuses 0 and versions above CURRENT_VERSION before calling this.
        other => Err(PresetError::Parse {
            path: path.to_owned(),
            line: 1,
            column: 1,
            field: "version: ".into(),
            message: format!("no reader for format version {other}"),
        }),
    }
}

/// The options used for both reading and writing presets: `Option` fields are written
/// without `Some(…)` and read either way.
fn ron_options() -> ron::Options {
    ron::Options::default().with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME)
}

fn deserialize<T: serde::de::DeserializeOwned>(
    text: &str,
    path: &str,
    tokens: &[Token],
) -> Result<T, PresetError> {
    let located = |pos: TextPos, field: String, message: String| PresetError::Parse {
        path: path.to_owned(),
        line: pos.line,
        column: pos.column,
        field: if field.is_empty() {
            field
        } else {
            format!("{field}: ")
        },
        message,
    };
    let to_pos = |p: ron::error::Position| TextPos {
        line: p.line,
        column: p.col,
    };
    let mut de = match ron::Deserializer::from_str_with_options(text, &ron_options()) {
        Ok(de) => de,
        Err(e) => {
            let (pos, field, message) = explain(&e.code, to_pos(e.span.start), "", tokens, text);
            return Err(located(pos, field, message));
        }
    };
    let result: Result<T, _> = serde_path_to_error::deserialize(&mut de);
    match result {
        Ok(value) => {
            if let Err(e) = de.end() {
                let s = de.span_error(e);
                let (pos, field, message) =
                    explain(&s.code, to_pos(s.span.start), "", tokens, text);
                return Err(located(pos, field, message));
            }
            Ok(value)
        }
        Err(err) => {
            let field = clean_path(err.path());
            let inner = err.into_inner();
            let spanned = de.span_error(inner);
            let (pos, field, message) = explain(
                &spanned.code,
                to_pos(spanned.span.start),
                &field,
                tokens,
                text,
            );
            Err(located(pos, field, message))
        }
    }
}

/// Loads a preset file.
pub fn load(path: &Path) -> Result<Effect, PresetError> {
    let shown = path.display().to_string();
    let io = |reason: String| PresetError::Io {
        path: shown.clone(),
        reason,
    };
    let meta = std::fs::metadata(path).map_err(|e| io(e.to_string()))?;
    if meta.is_dir() {
        return Err(io("is a folder, not a preset file".into()));
    }
    if meta.len() > MAX_PRESET_BYTES {
        return Err(io(format!(
            "{} bytes is too large for a preset (at most {MAX_PRESET_BYTES})",
            meta.len()
        )));
    }
    let bytes = std::fs::read(path).map_err(|e| io(e.to_string()))?;
    let text = match String::from_utf8(bytes) {
        Ok(text) => text,
        Err(e) => {
            let valid = e.utf8_error().valid_up_to();
            let bytes = e.as_bytes();
            let before = String::from_utf8_lossy(&bytes[..valid]);
            let pos = pos_after(&before);
            return Err(PresetError::Parse {
                path: shown,
                line: pos.line,
                column: pos.column,
                field: String::new(),
                message: format!(
                    "not valid UTF-8 text (byte 0x{:02x} at offset {valid}); presets are UTF-8 \
                     text files",
                    bytes.get(valid).copied().unwrap_or(0)
                ),
            });
        }
    };
    parse_str(&text, &shown)
}

/// The position just after `s` (where the next character would be).
fn pos_after(s: &str) -> TextPos {
    let line = 1 + s.matches('\n').count();
    let column = 1 + s.chars().rev().take_while(|&c| c != '\n').count();
    TextPos { line, column }
}

/// The first line of every file [`save`] writes.
pub fn file_header() -> String {
    format!(
        "// ignis effect preset, format version {CURRENT_VERSION}. Written by ignis {}.\n\
         // Units are in the field names; see docs/presets.md for every field and its default.\n",
        env!("CARGO_PKG_VERSION")
    )
}

/// Validates and saves atomically: a temporary file in the same folder, fsync, rename.
///
/// Refuses (and changes nothing) when the effect is invalid, or when `path` exists but does
/// not load as a preset — overwriting it would lose whatever it holds (use
/// [`save_replacing`] after asking the user). A failure at any point leaves the previous file
/// untouched and no temporary file behind.
pub fn save(effect: &Effect, path: &Path) -> Result<(), PresetError> {
    let text = checked_text(effect, path)?;
    if path.exists()
        && let Err(e) = load(path)
    {
        return Err(PresetError::WouldClobber {
            path: path.display().to_string(),
            reason: e.to_string(),
        });
    }
    write_text(path, &text)
}

/// Like [`save`], but an existing file that does not load is kept as `NAME.ron.bak` (replacing
/// an older backup) instead of refusing. For callers that asked the user first.
pub fn save_replacing(effect: &Effect, path: &Path) -> Result<(), PresetError> {
    let text = checked_text(effect, path)?;
    if path.exists() && load(path).is_err() {
        let mut backup = path.as_os_str().to_owned();
        backup.push(".bak");
        std::fs::rename(path, &backup).map_err(|e| PresetError::Io {
            path: path.display().to_string(),
            reason: format!(
                "cannot keep the old file as {}: {e}",
                Path::new(&backup).display()
            ),
        })?;
    }
    write_text(path, &text)
}

fn checked_text(effect: &Effect, path: &Path) -> Result<String, PresetError> {
    effect.validate().map_err(|errors| PresetError::Invalid {
        path: path.display().to_string(),
        positions: vec![None; errors.len()],
        errors,
    })?;
    Ok(format!("{}{}\n", file_header(), to_ron(effect)?))
}

fn write_text(path: &Path, text: &str) -> Result<(), PresetError> {
    write_atomic(path, text.as_bytes()).map_err(|e| PresetError::Io {
        path: path.display().to_string(),
        reason: format!("not saved (the previous file, if any, is unchanged): {e}"),
    })
}

/// A file-name-safe version of an effect name.
pub fn file_stem(name: &str) -> String {
    let stem: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect();
    if stem.is_empty() {
        "effect".to_owned()
    } else {
        stem
    }
}

/// Every `.ron` file in `dir`, sorted by name.
pub fn list(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "ron"))
        .collect();
    v.sort();
    v
}

// ---------------------------------------------------------------------------------------------
// A small, forgiving RON lexer and tree: reads the version before deserialising, finds the
// field path at an error position, locates validation errors, and lays out saved files.

impl Effect {
    /// The embedded default effect (a campfire: flames, embers and smoke).
    pub fn default_campfire() -> Effect {
        // The default preset file is the source of truth; it is embedded so `ignis` runs anywhere.
        match parse_str(DEFAULT_PRESET_RON, "presets/campfire.ron") {
            Ok(effect) => effect,
            Err(err) => {
                log::error!("embedded default preset is invalid ({err}); using built-in defaults");
                Effect::default()
            }
        }
    }
}

/// The default campfire preset, embedded in the binary.
pub const DEFAULT_PRESET_RON: &str = include_str!("../../presets/campfire.ron");

#[cfg(test)]
mod tests {
    use super::tokens::{Tok, path_at};
    use super::*;

    #[test]
    fn tokens_skip_comments_and_keep_positions() {
        let text = "// c\n( /* x /* nested */ */ a: \"s,)\", b: r#\"q\"#)";
        let toks = tokenize(text);
        let kinds: Vec<Tok> = toks.iter().map(|t| t.kind).collect();
        assert_eq!(
            kinds,
            [
                Tok::Open(b'('),
                Tok::Word,
                Tok::Colon,
                Tok::Str,
                Tok::Comma,
                Tok::Word,
                Tok::Colon,
                Tok::Str,
                Tok::Close(b')')
            ]
        );
        assert_eq!(toks[0].pos, TextPos { line: 2, column: 1 });
        assert_eq!(&text[toks[7].start..toks[7].end], "r#\"q\"#");
    }

    #[test]
    fn version_is_found_in_broken_files() {
        let text = "(name: \"x\", inner: (version: 7), version: 3, emitters: [(";
        let found = locate::value_at(text, "version").expect("found");
        let (v, pos) = (found.literal.as_deref().and_then(parse_integer), found.pos);
        assert_eq!(v, Some(3));
        assert_eq!(
            pos,
            TextPos {
                line: 1,
                column: 43
            }
        );
        assert_eq!(locate::value_at("(name: 1)", "version"), None);
        for (word, n) in [("7", 7), ("0x3E7", 999), ("0b11", 3), ("1_000u32", 1000)] {
            assert_eq!(parse_integer(word), Some(n), "{word}");
        }
        assert_eq!(parse_integer("1.5"), None);
        assert_eq!(parse_integer("\"1\""), None);
    }

    #[test]
    fn path_at_follows_fields_lists_and_some() {
        let text = "(a: [(x: 1), (y: Some((z: 2.5)))], b: (1, 2))";
        let toks = tokenize(text);
        let find = |s: &str| {
            toks.iter()
                .position(|t| &text[t.start..t.end] == s)
                .expect("token")
        };
        assert_eq!(path_at(&toks, text, find("2.5")), "a[1].y.z");
        assert_eq!(path_at(&toks, text, find("2")), "b[1]");
    }

    #[test]
    fn locate_finds_values_and_falls_back_to_parents() {
        let text = "(\n  a: [(x: 1), (y: Some((z: 2.5)))],\n  b: (1, 2),\n)";
        let at = |line, column| TextPos { line, column };
        let locate = |path: &str| {
            let l = locate::locate(text, path).expect("located");
            (l.pos, l.literal)
        };
        assert_eq!(locate("a[1].y.z"), (at(2, 28), Some("2.5".into())));
        assert_eq!(locate("b[1]"), (at(3, 10), Some("2".into())));
        assert_eq!(locate("a[0].missing"), (at(2, 7), None));
    }
}
