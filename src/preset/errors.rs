//! Why a preset did not load or save ([`PresetError`]): the file, `line:column`, the field
//! path and the message (`explain.rs` words ron's errors).

use crate::effect::ValidationError;

use super::TextPos;

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
    /// The file's format version is newer than this build reads.
    #[error(
        "{path}:{line}:{column}: version: this preset is format version {found}, but this build \
         of ignis reads versions up to {supported}; update ignis to open it"
    )]
    TooNew {
        /// The file.
        path: String,
        /// 1-based line of the version number.
        line: usize,
        /// 1-based column of the version number.
        column: usize,
        /// The version the file declares.
        found: u64,
        /// The newest version this build reads ([`crate::effect::CURRENT_VERSION`]).
        supported: u32,
    },
    /// Values out of range. Every problem is listed, each on its own line, located in the
    /// text where the effect came from a file.
    #[error("{}", display_invalid(path, errors, positions))]
    Invalid {
        /// The file.
        path: String,
        /// Every problem found.
        errors: Vec<ValidationError>,
        /// Where each of `errors` is in the text (same length and order as `errors`; `None`
        /// when the effect did not come from text, e.g. when saving).
        positions: Vec<Option<TextPos>>,
    },
    /// Saving would overwrite a file that does not load as a preset (someone's work with a
    /// typo, or a newer format). The file was left untouched.
    #[error(
        "{path}: not saved: the existing file does not load as a preset and would be lost \
         ({reason}); save under another name, or fix or move the file first"
    )]
    WouldClobber {
        /// The file that was kept.
        path: String,
        /// Why the existing file does not load.
        reason: String,
    },
}

pub(super) fn display_invalid(
    path: &str,
    errors: &[ValidationError],
    positions: &[Option<TextPos>],
) -> String {
    errors
        .iter()
        .enumerate()
        .map(|(i, e)| match positions.get(i).copied().flatten() {
            Some(p) => format!("{path}:{p}: {e}"),
            None => format!("{path}: {e}"),
        })
        .collect::<Vec<_>>()
        .join("\n")
}

impl PresetError {
    /// The `(line, column)` of the (first) problem, where it has one.
    pub fn position(&self) -> Option<TextPos> {
        match self {
            PresetError::Parse { line, column, .. } | PresetError::TooNew { line, column, .. } => {
                Some(TextPos {
                    line: *line,
                    column: *column,
                })
            }
            PresetError::Invalid { positions, .. } => positions.iter().flatten().next().copied(),
            PresetError::Io { .. } | PresetError::WouldClobber { .. } => None,
        }
    }
}

/// The serde path as `emitters[1].look.blend`: enum variant names and unknown segments left
/// out (an empty string when nothing is known).
pub(super) fn clean_path(path: &serde_path_to_error::Path) -> String {
    use serde_path_to_error::Segment;
    let mut out = String::new();
    let mut complete = true;
    for seg in path.iter() {
        match seg {
            Segment::Seq { index } => out.push_str(&format!("[{index}]")),
            Segment::Map { key } => {
                if !out.is_empty() {
                    out.push('.');
                }
                out.push_str(key);
            }
            Segment::Enum { .. } => {}
            Segment::Unknown => complete = false,
        }
    }
    if complete { out } else { format!("{out}?") }
}
