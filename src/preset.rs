//! Presets as RON: versioned loading with located errors, validation, atomic saving.

use std::io::Write as _;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::effect::{CURRENT_VERSION, Effect, ValidationError};

/// Why a preset could not be loaded or saved.
#[derive(Debug, thiserror::Error)]
pub enum PresetError {
    /// The file could not be read or written.
    #[error("{path}: {reason}")]
    Io {
        /// The file.
        path: String,
        /// What went wrong.
        reason: String,
    },
    /// RON syntax or a type/field problem at a position.
    #[error("{path}:{line}:{column}: {field}{message}")]
    Parse {
        /// The file.
        path: String,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// The field path followed by ": ", or empty.
        field: String,
        /// What was expected.
        message: String,
    },
    /// Values out of range.
    #[error("{path}: invalid preset:\n{}", .errors.iter().map(|e| format!("  {e}")).collect::<Vec<_>>().join("\n"))]
    Invalid {
        /// The file.
        path: String,
        /// Every problem found.
        errors: Vec<ValidationError>,
    },
}

#[derive(Deserialize)]
struct VersionProbe {
    #[serde(default = "one")]
    version: u32,
}

fn one() -> u32 {
    1
}

/// Parses and validates preset text; `path` only names the file in errors.
pub fn parse_str(text: &str, path: &str) -> Result<Effect, PresetError> {
    // Read the version first so a future file gets a clear message, not a field error.
    if let Ok(probe) = ron::from_str::<VersionProbe>(text)
        && probe.version > CURRENT_VERSION
    {
        return Err(PresetError::Parse {
            path: path.to_owned(),
            line: 1,
            column: 1,
            field: "version: ".into(),
            message: format!(
                "version {} is newer than this build supports (up to {CURRENT_VERSION}); update ignis",
                probe.version
            ),
        });
    }
    let effect = deserialize(text, path)?;
    let effect = migrate(effect);
    effect.validate().map_err(|errors| PresetError::Invalid {
        path: path.to_owned(),
        errors,
    })?;
    Ok(effect)
}

/// Brings an older format version up to [`CURRENT_VERSION`]. Version 1 is the first
/// format, so there is nothing to migrate yet; each future change adds a step here and a
/// fixture under `tests/fixtures/`.
fn migrate(mut effect: Effect) -> Effect {
    effect.version = CURRENT_VERSION;
    effect
}

fn deserialize(text: &str, path: &str) -> Result<Effect, PresetError> {
    let located = |span: ron::error::Position, field: String, message: String| PresetError::Parse {
        path: path.to_owned(),
        line: span.line,
        column: span.col,
        field,
        message,
    };
    let mut de = ron::Deserializer::from_str_with_options(text, &ron_options())
        .map_err(|e| located(e.span.start, String::new(), e.code.to_string()))?;
    let result: Result<Effect, _> = serde_path_to_error::deserialize(&mut de);
    match result {
        Ok(effect) => {
            de.end().map_err(|e| {
                let s = de.span_error(e);
                located(s.span.start, String::new(), s.code.to_string())
            })?;
            Ok(effect)
        }
        Err(err) => {
            let field = err.path().to_string();
            let inner = err.into_inner();
            let message = explain(&inner);
            let span = de.span_error(inner);
            let field = if field.is_empty() || field == "." {
                String::new()
            } else {
                format!("{field}: ")
            };
            Err(located(span.span.start, field, message))
        }
    }
}

fn ron_options() -> ron::Options {
    ron::Options::default().with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME)
}

/// ron's message, plus the closest known field for a misspelt one.
fn explain(e: &ron::Error) -> String {
    if let ron::Error::NoSuchStructField {
        expected, found, ..
    } = e
    {
        let best = expected
            .iter()
            .min_by_key(|k| strsim::levenshtein(k, found))
            .filter(|k| strsim::levenshtein(k, found) <= 4);
        return match best {
            Some(k) => format!("unknown field `{found}`; did you mean `{k}`?"),
            None => format!(
                "unknown field `{found}`; expected one of {}",
                expected.join(", ")
            ),
        };
    }
    e.to_string()
}

/// Loads a preset file.
pub fn load(path: &Path) -> Result<Effect, PresetError> {
    let shown = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| PresetError::Io {
        path: shown.clone(),
        reason: e.to_string(),
    })?;
    let text = String::from_utf8(bytes).map_err(|e| PresetError::Io {
        path: shown.clone(),
        reason: format!(
            "not valid UTF-8 text (byte {})",
            e.utf8_error().valid_up_to()
        ),
    })?;
    parse_str(&text, &shown)
}

/// The RON text of an effect (named fields, enums by name).
pub fn to_ron(effect: &Effect) -> Result<String, PresetError> {
    let config = ron::ser::PrettyConfig::new()
        .depth_limit(6)
        .struct_names(false)
        .separate_tuple_members(false)
        .enumerate_arrays(false);
    ron::Options::default()
        .to_string_pretty(effect, config)
        .map_err(|e| PresetError::Io {
            path: effect.name.clone(),
            reason: e.to_string(),
        })
}

/// Validates and saves atomically: a temporary file in the same folder, fsync, rename.
/// A failure at any point leaves the previous file untouched.
pub fn save(effect: &Effect, path: &Path) -> Result<(), PresetError> {
    let shown = path.display().to_string();
    effect.validate().map_err(|errors| PresetError::Invalid {
        path: shown.clone(),
        errors,
    })?;
    let text = format!(
        "// ignis effect preset (format version {CURRENT_VERSION}).\n{}\n",
        to_ron(effect)?
    );
    write_atomic(path, text.as_bytes()).map_err(|e| PresetError::Io {
        path: shown,
        reason: e.to_string(),
    })
}

/// Writes `bytes` to `path` via a temporary sibling file, fsync and rename.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "preset".into());
    let tmp: PathBuf = dir.join(format!(".{name}.tmp-{}", std::process::id()));
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        drop(f);
        std::fs::rename(&tmp, path)?;
        // Persist the rename itself.
        if let Ok(d) = std::fs::File::open(dir) {
            let _ = d.sync_all();
        }
        Ok(())
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
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
