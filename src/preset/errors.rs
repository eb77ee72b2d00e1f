//! Error messages for presets that do not load: ron's error turned into the file,
//! `line:column`, the field path and what was found there (ron's errors say what was
//! expected, not what was found, nor the field path of a syntax error nor which bracket
//! is left open: the tokens of `tokens.rs` supply those), and the closest known name for a
//! misspelt field or variant.

use crate::effect::ValidationError;

use super::TextPos;
use super::tokens::{Tok, Token, path_at, unclosed_bracket};

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

/// Turns a ron error into (position, field path, message) with consistent wording, the text
/// that was found, and the closest known name for a misspelt field or variant.
pub(super) fn explain(
    code: &ron::Error,
    at: TextPos,
    serde_path: &str,
    tokens: &[Token],
    text: &str,
) -> (TextPos, String, String) {
    use ron::Error as E;
    // The token the error points into or at (ron points at the whitespace before a value).
    let inside = tokens.iter().position(|t| t.pos < at && at < t.end_pos);
    let next = tokens.iter().position(|t| t.pos >= at);
    let token_path = |i: usize| path_at(tokens, text, i);
    let (mut pos, mut field) = match inside.or(next) {
        Some(i) => (tokens[i].pos, serde_path.to_owned()),
        None => (at, serde_path.to_owned()),
    };
    if field.ends_with('?') || field.is_empty() {
        field = match inside.or(next) {
            Some(i) => token_path(i),
            None => field.trim_end_matches('?').trim_end_matches('.').to_owned(),
        };
    }
    let found = |i: Option<usize>| -> String {
        match i.map(|i| &tokens[i]) {
            Some(t) => {
                let s = &text[t.start..t.end];
                let short: String = s.chars().take(40).collect();
                if short.len() < s.len() {
                    format!(", found `{short}…`")
                } else {
                    format!(", found `{short}`")
                }
            }
            None => ", found the end of the file".to_owned(),
        }
    };
    // A number ron stopped reading in the middle of ("capacity: 20.5" reads 20, then wants a
    // comma): the field takes an integer.
    let bad_integer = |i: usize| -> Option<(TextPos, String, String)> {
        let t = &tokens[i];
        let s = &text[t.start..t.end];
        if t.kind != Tok::Word
            || !s.starts_with(|c: char| c.is_ascii_digit() || c == '-' || c == '+')
        {
            return None;
        }
        let why = if s.starts_with('-') {
            "expected a whole number ≥ 0"
        } else {
            "expected a whole number (this field takes no fractions or exponents)"
        };
        Some((t.pos, token_path(i), format!("{why}, found `{s}`")))
    };
    if let Some(located) = inside.and_then(bad_integer) {
        return located;
    }
    if matches!(code, E::InvalidIntegerDigit { .. })
        && let Some(located) = next.and_then(bad_integer)
    {
        return located;
    }
    if tokens.is_empty() {
        pos = TextPos { line: 1, column: 1 };
    }
    // A string that swallowed the text after it (a missing closing quote).
    let runaway = next
        .and_then(|i| i.checked_sub(1))
        .map(|i| &tokens[i])
        .filter(|t| t.kind == Tok::Str && t.pos.line != t.end_pos.line)
        .map(|t| {
            format!(
                " (the string starting at {} runs over several lines: is a closing `\"` missing?)",
                t.pos
            )
        })
        .unwrap_or_default();
    let end_of_text = next.is_none() && inside.is_none() && !tokens.is_empty();
    let message = match code {
        E::ExpectedStringEnd if end_of_text => {
            "a string is never closed (a `\"` is missing)".to_owned()
        }
        E::UnclosedBlockComment => "a `/*` comment is never closed".to_owned(),
        E::ExceededRecursionLimit => "nested too deeply (more than 128 levels of brackets)".into(),
        _ if end_of_text => {
            // Point just after the last thing in the file.
            if let Some(last) = tokens.last() {
                pos = last.end_pos;
            }
            let unclosed = unclosed_bracket(tokens);
            match unclosed {
                Some(t) => format!(
                    "unexpected end of file: `{}` opened at {} is never closed (is the file \
                     truncated?)",
                    &text[t.start..t.end],
                    t.pos
                ),
                None => "unexpected end of file (is the file truncated?)".to_owned(),
            }
        }
        E::ExpectedInteger => format!("expected a whole number{}", found(next)),
        E::IntegerOutOfBounds => format!(
            "expected a whole number in 0..={}{}",
            u32::MAX,
            found(inside.or(next))
        ),
        E::ExpectedFloat => format!("expected a number{}", found(next)),
        E::ExpectedBoolean => format!("expected `true` or `false`{}", found(next)),
        E::ExpectedString | E::ExpectedStringEnd => {
            format!("expected a string in double quotes{}", found(next))
        }
        E::ExpectedArray => format!("expected a list `[…]`{}", found(next)),
        E::ExpectedStructLike | E::ExpectedNamedStructLike(_) => {
            if serde_path.is_empty() && tokens.is_empty() {
                "the file is empty; a preset is `(version: 1, name: …, emitters: [ … ])`".to_owned()
            } else {
                format!("expected `(` opening a group of fields{}", found(next))
            }
        }
        E::ExpectedComma => format!("expected `,` between values{}{runaway}", found(next)),
        E::ExpectedArrayEnd => {
            format!(
                "expected `,` or `]` closing the list{}{runaway}",
                found(next)
            )
        }
        E::ExpectedStructLikeEnd => format!("expected `,` or `)`{}{runaway}", found(next)),
        E::ExpectedMapColon => format!("expected `:` after the field name{}", found(next)),
        E::ExpectedIdentifier => format!("expected a field or variant name{}", found(next)),
        E::TrailingCharacters => format!(
            "unexpected text after the preset's closing `)`{}",
            found(next)
        ),
        E::Eof => "unexpected end of file".to_owned(),
        E::ExpectedDifferentLength { expected, found } => {
            match expected.strip_prefix("an array of length ") {
                Some(n) => format!("expected {n} values, found {found}"),
                None => format!("expected {expected}, found {found} values"),
            }
        }
        E::InvalidValueForType { expected, found } => format!("expected {expected}, found {found}"),
        E::NoSuchEnumVariant {
            expected, found, ..
        } => {
            let names = quoted_list(expected);
            match closest(expected, found) {
                Some(k) => {
                    format!("unknown variant `{found}`; did you mean `{k}`? (one of {names})")
                }
                None => format!("unknown variant `{found}`; expected one of {names}"),
            }
        }
        E::NoSuchStructField {
            expected, found, ..
        } => {
            let names = quoted_list(expected);
            // Point at the misspelt name itself.
            if let Some(i) = tokens
                .iter()
                .position(|t| t.pos >= at && &text[t.start..t.end] == found.as_str())
            {
                pos = tokens[i].pos;
            }
            match closest(expected, found) {
                Some(k) => format!("unknown field `{found}`; did you mean `{k}`?"),
                None => format!("unknown field `{found}`; expected one of {names}"),
            }
        }
        E::MissingStructField { field: f, .. } => format!("missing required field `{f}`"),
        E::DuplicateStructField { field: f, .. } => {
            format!("field `{f}` is given twice; keep one")
        }
        other => {
            let s = other.to_string();
            let mut chars = s.chars();
            match chars.next() {
                Some(c) => format!("{}{}", c.to_lowercase(), chars.as_str()),
                None => s,
            }
        }
    };
    (pos, field, message)
}

pub(super) fn quoted_list(names: &[&str]) -> String {
    names
        .iter()
        .map(|n| format!("`{n}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The known name closest to `found` (case-insensitive edit distance ≤ 4, or a prefix).
pub(super) fn closest<'a>(expected: &[&'a str], found: &str) -> Option<&'a str> {
    let lower = found.to_lowercase();
    expected
        .iter()
        .map(|k| (strsim::levenshtein(&k.to_lowercase(), &lower), *k))
        .filter(|(d, k)| *d <= 4.min(k.len().max(found.len()) / 2 + 1) || k.starts_with(found))
        .min_by_key(|(d, _)| *d)
        .map(|(_, k)| k)
}
