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

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::effect::{CURRENT_VERSION, Effect, ValidationError};

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
        /// The newest version this build reads ([`CURRENT_VERSION`]).
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

fn display_invalid(
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

/// Parses and validates preset text; `path` only names the file in errors.
pub fn parse_str(text: &str, path: &str) -> Result<Effect, PresetError> {
    let tokens = tokenize(text);
    // Read the version first: a future file gets a clear message, not a field error about a
    // field this build has never heard of.
    let version = scan_version(&tokens, text);
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
            // Syntax errors first (a truncated file may have lost more than its version).
            deserialize::<Effect>(text, path, &tokens)?;
            let pos = root_pos(&tokens);
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
    let tree = Tree::parse(&tokens, text);
    if let Some(Node {
        body: Body::Fields(fields),
        pos,
        ..
    }) = tree.as_ref().map(|t| &t.root)
        && !fields.iter().any(|(name, _, _)| name == "emitters")
    {
        return Err(parse_err(
            *pos,
            "",
            "missing required field `emitters` (a preset lists at least one emitter)".into(),
        ));
    }
    effect.validate().map_err(|mut errors| {
        let mut positions = Vec::with_capacity(errors.len());
        for e in &mut errors {
            let Some(tree) = tree.as_ref() else {
                positions.push(None);
                continue;
            };
            let (pos, literal) = tree.locate(&e.path, text);
            positions.push(Some(pos));
            // Show the number as written (`1e39`, `5.0`), and say why a huge literal is
            // not finite.
            if let Some(lit) = literal {
                if e.value.ends_with("inf") && lit.parse::<f64>().is_ok_and(f64::is_finite) {
                    e.problem = format!(
                        "{} ({lit} does not fit in a 32-bit float, whose largest value is about \
                         3.4e38)",
                        e.problem
                    );
                }
                e.value = lit.to_owned();
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
/// Version 1 is the first format, so there is nothing to convert yet. When the format
/// changes (version 2):
///
/// 1. copy today's serde types into a frozen `mod v1` (only the parts that change need their
///    own types) and keep them unchanged from then on;
/// 2. add `1 => deserialize::<v1::Effect>(…).map(Effect::from)` below, with the conversion
///    written out field by field (renamed fields, new fields with the value that reproduces
///    the old look, changed units);
/// 3. keep `tests/fixtures/v1_campfire.ron` loading (its test compares it with what the
///    conversion should give), and add a `v2_…` fixture for the next change.
fn migrate(version: u64, text: &str, path: &str, tokens: &[Token]) -> Result<Effect, PresetError> {
    match version {
        1 => {
            let mut effect = deserialize::<Effect>(text, path, tokens)?;
            effect.version = CURRENT_VERSION;
            Ok(effect)
        }
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

/// The serde path as `emitters[1].look.blend`: enum variant names and unknown segments left
/// out (an empty string when nothing is known).
fn clean_path(path: &serde_path_to_error::Path) -> String {
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
fn explain(
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

fn quoted_list(names: &[&str]) -> String {
    names
        .iter()
        .map(|n| format!("`{n}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The known name closest to `found` (case-insensitive edit distance ≤ 4, or a prefix).
fn closest<'a>(expected: &[&'a str], found: &str) -> Option<&'a str> {
    let lower = found.to_lowercase();
    expected
        .iter()
        .map(|k| (strsim::levenshtein(&k.to_lowercase(), &lower), *k))
        .filter(|(d, k)| *d <= 4.min(k.len().max(found.len()) / 2 + 1) || k.starts_with(found))
        .min_by_key(|(d, _)| *d)
        .map(|(_, k)| k)
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

/// Lines longer than this are broken, one field or item per line.
const LINE_WIDTH: usize = 100;

/// The RON text of an effect, laid out like a hand-written preset: named fields, enums by
/// name, `Option`s without `Some(…)`, every field written out (so the file's meaning never
/// depends on this build's defaults), small groups on one line and larger ones one field per
/// line. [`parse_str`] reads it back to an equal effect.
pub fn to_ron(effect: &Effect) -> Result<String, PresetError> {
    let compact = ron_options()
        .to_string(effect)
        .map_err(|e| PresetError::Io {
            path: effect.name.clone(),
            reason: format!("cannot write as RON: {e}"),
        })?;
    let tokens = tokenize(&compact);
    match Tree::parse(&tokens, &compact) {
        Some(tree) => {
            let mut out = String::new();
            write_node(&tree.root, &compact, 0, 0, &mut out, true);
            Ok(out)
        }
        // Not expected; ron's own layout is still valid RON.
        None => ron_options()
            .to_string_pretty(effect, ron::ser::PrettyConfig::new().struct_names(false))
            .map_err(|e| PresetError::Io {
                path: effect.name.clone(),
                reason: format!("cannot write as RON: {e}"),
            }),
    }
}

/// The text a node takes on one line.
fn inline(node: &Node, text: &str) -> String {
    match &node.body {
        Body::Atom(range) => text[range.clone()].to_owned(),
        Body::Fields(fields) => {
            let inner: Vec<String> = fields
                .iter()
                .map(|(k, _, v)| format!("{k}: {}", inline(v, text)))
                .collect();
            format!("{}({})", node_prefix(node), inner.join(", "))
        }
        Body::Items(items, open) => {
            let inner: Vec<String> = items.iter().map(|v| inline(v, text)).collect();
            let (o, c) = brackets(*open);
            format!("{}{o}{}{c}", node_prefix(node), inner.join(", "))
        }
    }
}

fn node_prefix(node: &Node) -> &str {
    node.prefix.as_deref().unwrap_or("")
}

fn brackets(open: u8) -> (char, char) {
    match open {
        b'[' => ('[', ']'),
        b'{' => ('{', '}'),
        _ => ('(', ')'),
    }
}

/// Writes `node` starting at column `col` (after a `key: `), broken over lines at `indent`
/// when it does not fit.
fn write_node(node: &Node, text: &str, indent: usize, col: usize, out: &mut String, force: bool) {
    let one_line = inline(node, text);
    // One column for the trailing comma.
    let fits = col + one_line.chars().count() < LINE_WIDTH;
    let children = match &node.body {
        Body::Atom(_) => 0,
        Body::Fields(f) => f.len(),
        Body::Items(i, _) => i.len(),
    };
    if (fits && !force) || children == 0 {
        out.push_str(&one_line);
        return;
    }
    let pad = "    ".repeat(indent + 1);
    out.push_str(node_prefix(node));
    match &node.body {
        Body::Atom(_) => {}
        Body::Fields(fields) => {
            out.push_str("(\n");
            for (k, _, v) in fields {
                out.push_str(&pad);
                out.push_str(k);
                out.push_str(": ");
                let c = pad.len() + k.chars().count() + 2;
                write_node(v, text, indent + 1, c, out, false);
                out.push_str(",\n");
            }
            out.push_str(&"    ".repeat(indent));
            out.push(')');
        }
        Body::Items(items, open) => {
            let (o, c) = brackets(*open);
            out.push(o);
            out.push('\n');
            for v in items {
                out.push_str(&pad);
                write_node(v, text, indent + 1, pad.len(), out, false);
                out.push_str(",\n");
            }
            out.push_str(&"    ".repeat(indent));
            out.push(c);
        }
    }
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

/// Writes `bytes` to `path` via a temporary sibling file, fsync and rename.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    write_atomic_with(path, |w| w.write_all(bytes))
}

static TMP_COUNTER: AtomicU64 = AtomicU64::new(0);

/// Writes `path` atomically with the content `fill` writes: `fill` writes a new temporary
/// file in the same folder, which is then flushed, fsynced and renamed over `path` (and the
/// folder fsynced, so the rename itself survives a crash). If `fill` or any later step fails
/// (a full disk, a crash before the rename), `path` keeps its previous content and the
/// temporary file is removed (also when `fill` panics). A symlink at `path` is followed: its target is replaced. An
/// existing file's permissions are kept.
pub fn write_atomic_with(
    path: &Path,
    fill: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let target: PathBuf = match std::fs::symlink_metadata(path) {
        Ok(m) if m.file_type().is_symlink() => std::fs::canonicalize(path)?,
        _ => path.to_path_buf(),
    };
    let dir = target
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = target
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "preset".into());
    let mut tmp = TempFile {
        path: dir.join(format!(
            ".{name}.tmp-{}-{}",
            std::process::id(),
            TMP_COUNTER.fetch_add(1, Ordering::Relaxed)
        )),
        renamed: false,
    };
    let file = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&tmp.path)?;
    let mut w = std::io::BufWriter::new(file);
    fill(&mut w)?;
    let file = w.into_inner().map_err(|e| e.into_error())?;
    if let Ok(old) = std::fs::metadata(&target) {
        file.set_permissions(old.permissions())?;
    }
    file.sync_all()?;
    drop(file);
    std::fs::rename(&tmp.path, &target)?;
    tmp.renamed = true;
    // Persist the rename itself (not possible on every platform; best effort).
    if let Ok(d) = std::fs::File::open(dir) {
        let _ = d.sync_all();
    }
    Ok(())
}

/// Removes the temporary file when a write fails or panics before the rename.
struct TempFile {
    path: PathBuf,
    renamed: bool,
}

impl Drop for TempFile {
    fn drop(&mut self) {
        if !self.renamed {
            let _ = std::fs::remove_file(&self.path);
        }
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

/// Kinds of RON tokens (comments and whitespace are dropped).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Tok {
    /// `(`, `[` or `{` (the byte).
    Open(u8),
    /// `)`, `]` or `}` (the byte).
    Close(u8),
    /// `,`
    Comma,
    /// `:`
    Colon,
    /// An identifier, number, `true`/`false`, `NaN`, `inf`…
    Word,
    /// A string, raw string or character literal.
    Str,
    /// Anything else (`#`, `!`, stray characters).
    Other,
}

/// One token of a preset's text.
#[derive(Clone, Debug, PartialEq, Eq)]
struct Token {
    /// What it is.
    pub kind: Tok,
    /// Byte range in the text.
    pub start: usize,
    /// End of the byte range (exclusive).
    pub end: usize,
    /// Position of its first character.
    pub pos: TextPos,
    /// Position just after its last character.
    pub end_pos: TextPos,
}

fn is_word_char(c: char) -> bool {
    c.is_alphanumeric() || matches!(c, '_' | '.' | '+' | '-')
}

/// Splits RON text into tokens. Never fails: an unterminated string or comment ends the
/// token list (the deserialiser reports it).
fn tokenize(text: &str) -> Vec<Token> {
    let mut tokens = Vec::new();
    let chars: Vec<(usize, char)> = text.char_indices().collect();
    let mut i = 0;
    let mut line = 1;
    let mut col = 1;
    // Advances over chars[i..j], updating the position.
    let advance = |i: &mut usize, j: usize, line: &mut usize, col: &mut usize| {
        for &(_, c) in &chars[*i..j.min(chars.len())] {
            if c == '\n' {
                *line += 1;
                *col = 1;
            } else {
                *col += 1;
            }
        }
        *i = j.min(chars.len());
    };
    let byte = |k: usize| chars.get(k).map_or(text.len(), |&(b, _)| b);
    let at = |k: usize| chars.get(k).map(|&(_, c)| c);
    while i < chars.len() {
        let c = chars[i].1;
        let start_pos = TextPos { line, column: col };
        let mut j = i + 1;
        let kind = match c {
            c if c.is_whitespace() => {
                advance(&mut i, j, &mut line, &mut col);
                continue;
            }
            '/' if at(i + 1) == Some('/') => {
                while j < chars.len() && chars[j].1 != '\n' {
                    j += 1;
                }
                advance(&mut i, j, &mut line, &mut col);
                continue;
            }
            '/' if at(i + 1) == Some('*') => {
                let mut depth = 1;
                j = i + 2;
                while j < chars.len() && depth > 0 {
                    if chars[j].1 == '/' && at(j + 1) == Some('*') {
                        depth += 1;
                        j += 2;
                    } else if chars[j].1 == '*' && at(j + 1) == Some('/') {
                        depth -= 1;
                        j += 2;
                    } else {
                        j += 1;
                    }
                }
                if depth > 0 {
                    break;
                }
                advance(&mut i, j, &mut line, &mut col);
                continue;
            }
            '(' | '[' | '{' => Tok::Open(c as u8),
            ')' | ']' | '}' => Tok::Close(c as u8),
            ',' => Tok::Comma,
            ':' => Tok::Colon,
            '"' => {
                let mut closed = false;
                while j < chars.len() {
                    match chars[j].1 {
                        '\\' => j += 2,
                        '"' => {
                            j += 1;
                            closed = true;
                            break;
                        }
                        _ => j += 1,
                    }
                }
                if !closed {
                    break;
                }
                Tok::Str
            }
            '\'' => {
                j = if at(i + 1) == Some('\\') {
                    i + 4
                } else {
                    i + 3
                };
                while j <= chars.len() && at(j - 1) != Some('\'') && j < i + 12 {
                    j += 1;
                }
                Tok::Str
            }
            c if is_word_char(c) => {
                while j < chars.len() && is_word_char(chars[j].1) {
                    j += 1;
                }
                let word = &text[byte(i)..byte(j)];
                // Raw strings r"…", r#"…"#, br"…" and raw identifiers r#name.
                if matches!(word, "r" | "br" | "b") && matches!(at(j), Some('#' | '"')) {
                    let mut hashes = 0;
                    while at(j + hashes) == Some('#') {
                        hashes += 1;
                    }
                    if at(j + hashes) == Some('"') && (word != "b" || hashes == 0) {
                        let mut k = j + hashes + 1;
                        let mut closed = false;
                        while k < chars.len() {
                            if word == "b" && chars[k].1 == '\\' {
                                k += 2;
                                continue;
                            }
                            if chars[k].1 == '"' && (0..hashes).all(|h| at(k + 1 + h) == Some('#'))
                            {
                                k += 1 + hashes;
                                closed = true;
                                break;
                            }
                            k += 1;
                        }
                        if !closed {
                            break;
                        }
                        j = k;
                        Tok::Str
                    } else {
                        j += hashes;
                        while j < chars.len() && is_word_char(chars[j].1) {
                            j += 1;
                        }
                        Tok::Word
                    }
                } else {
                    Tok::Word
                }
            }
            _ => Tok::Other,
        };
        let start = byte(i);
        advance(&mut i, j, &mut line, &mut col);
        tokens.push(Token {
            kind,
            start,
            end: byte(i),
            pos: start_pos,
            end_pos: TextPos { line, column: col },
        });
    }
    tokens
}

/// The position of the document's opening `(` (or 1:1).
fn root_pos(tokens: &[Token]) -> TextPos {
    tokens
        .iter()
        .find(|t| t.kind == Tok::Open(b'('))
        .map_or(TextPos { line: 1, column: 1 }, |t| t.pos)
}

/// Index of the first token of the document's value (after `#![…]` attributes).
fn value_start(tokens: &[Token]) -> usize {
    let mut i = 0;
    while tokens.get(i).is_some_and(|t| t.kind == Tok::Other) {
        // `#` `!` `[ … ]`
        i += 1;
        while tokens.get(i).is_some_and(|t| t.kind == Tok::Other) {
            i += 1;
        }
        if tokens.get(i).is_some_and(|t| t.kind == Tok::Open(b'[')) {
            let mut depth = 0;
            while let Some(t) = tokens.get(i) {
                match t.kind {
                    Tok::Open(_) => depth += 1,
                    Tok::Close(_) => depth -= 1,
                    _ => {}
                }
                i += 1;
                if depth == 0 {
                    break;
                }
            }
        }
    }
    i
}

/// Finds the top-level `version: N` without deserialising: `Some((Some(N), pos))` for an
/// integer, `Some((None, pos))` for another value, `None` when there is no such field. Works
/// on broken and truncated files too.
fn scan_version(tokens: &[Token], text: &str) -> Option<(Option<u64>, TextPos)> {
    let mut i = value_start(tokens);
    // An optional struct name before the opening parenthesis.
    if tokens.get(i).is_some_and(|t| t.kind == Tok::Word) {
        i += 1;
    }
    if tokens.get(i)?.kind != Tok::Open(b'(') {
        return None;
    }
    i += 1;
    let mut depth = 1usize;
    while let Some(t) = tokens.get(i) {
        match t.kind {
            Tok::Open(_) => depth += 1,
            Tok::Close(_) => {
                depth -= 1;
                if depth == 0 {
                    return None;
                }
            }
            Tok::Word
                if depth == 1
                    && &text[t.start..t.end] == "version"
                    && tokens.get(i + 1).is_some_and(|c| c.kind == Tok::Colon) =>
            {
                let v = tokens.get(i + 2)?;
                let word = &text[v.start..v.end];
                let n = if v.kind == Tok::Word {
                    parse_integer(word)
                } else {
                    None
                };
                return Some((n, v.pos));
            }
            _ => {}
        }
        i += 1;
    }
    None
}

/// A RON unsigned integer literal: decimal, `0x`/`0o`/`0b`, `_` separators, optional
/// `u32`/`u64` suffix.
fn parse_integer(word: &str) -> Option<u64> {
    let w = word.replace('_', "");
    let w = w.trim_end_matches("u32").trim_end_matches("u64");
    let w = w.strip_prefix('+').unwrap_or(w);
    match w.get(..2) {
        Some("0x") => u64::from_str_radix(&w[2..], 16).ok(),
        Some("0o") => u64::from_str_radix(&w[2..], 8).ok(),
        Some("0b") => u64::from_str_radix(&w[2..], 2).ok(),
        _ => w.parse().ok(),
    }
}

/// The innermost bracket still open at the end of the text.
fn unclosed_bracket(tokens: &[Token]) -> Option<&Token> {
    let mut stack = Vec::new();
    for t in tokens {
        match t.kind {
            Tok::Open(_) => stack.push(t),
            Tok::Close(_) => {
                stack.pop();
            }
            _ => {}
        }
    }
    stack.pop()
}

/// The field path (`emitters[1].capacity`) of the value that token `upto` belongs to,
/// from the brackets, field names and commas before it. Works on broken files.
fn path_at(tokens: &[Token], text: &str, upto: usize) -> String {
    enum Kind {
        Struct(Option<String>),
        Seq(usize),
        Transparent,
    }
    let mut stack: Vec<Kind> = Vec::new();
    let word = |k: usize| tokens.get(k).map(|t| &text[t.start..t.end]);
    let is = |k: usize, kind: Tok| tokens.get(k).is_some_and(|t| t.kind == kind);
    let last = upto.min(tokens.len().saturating_sub(1));
    for (k, t) in tokens.iter().enumerate().take(last + 1) {
        match t.kind {
            Tok::Open(_) if k == upto => {}
            Tok::Open(b'(') => {
                let after_some = k > 0 && is(k - 1, Tok::Word) && word(k - 1) == Some("Some");
                if after_some {
                    stack.push(Kind::Transparent);
                } else if (is(k + 1, Tok::Word) && is(k + 2, Tok::Colon))
                    || is(k + 1, Tok::Close(b')'))
                {
                    stack.push(Kind::Struct(None));
                } else {
                    stack.push(Kind::Seq(0));
                }
            }
            Tok::Open(_) => stack.push(Kind::Seq(0)),
            Tok::Close(_) if k < upto => {
                stack.pop();
            }
            Tok::Comma if k < upto => match stack.last_mut() {
                Some(Kind::Seq(n)) => *n += 1,
                Some(Kind::Struct(f)) => *f = None,
                _ => {}
            },
            Tok::Word if is(k + 1, Tok::Colon) => {
                if let Some(Kind::Struct(f)) = stack.last_mut() {
                    *f = word(k).map(str::to_owned);
                }
            }
            _ => {}
        }
    }
    let mut out = String::new();
    // The outermost frame is the document itself; its field is the first path segment.
    for frame in &stack {
        match frame {
            Kind::Struct(Some(f)) => {
                if !out.is_empty() {
                    out.push('.');
                }
                out.push_str(f);
            }
            Kind::Seq(n) if !out.is_empty() => out.push_str(&format!("[{n}]")),
            _ => {}
        }
    }
    out
}

/// A parsed RON value with positions (prefix names and `Some(…)` unwrapped).
#[derive(Clone, Debug)]
struct Node {
    pos: TextPos,
    prefix: Option<String>,
    body: Body,
}

#[derive(Clone, Debug)]
enum Body {
    /// A number, string, identifier…: its byte range in the text.
    Atom(std::ops::Range<usize>),
    /// `(name: value, …)` with each name's position.
    Fields(Vec<(String, TextPos, Node)>),
    /// `(a, b)`, `[a, b]` or `{k: v}` (values only), with the opening byte.
    Items(Vec<Node>, u8),
}

struct Tree {
    root: Node,
}

impl Tree {
    /// Parses the whole document; `None` when it is not well-formed.
    fn parse(tokens: &[Token], text: &str) -> Option<Tree> {
        let mut i = value_start(tokens);
        let root = parse_value(tokens, text, &mut i, 0)?;
        Some(Tree { root })
    }

    /// The position of the value at a validation path like `emitters[1].shape.radius_m`, or
    /// of the deepest enclosing value present in the text (a field left at its default).
    ///
    /// Also returns the literal text when the exact value was found and is a number or name.
    fn locate<'t>(&self, path: &str, text: &'t str) -> (TextPos, Option<&'t str>) {
        let mut node = &self.root;
        let mut exact = true;
        for seg in path_segments(path) {
            let next = match (&node.body, seg) {
                (Body::Fields(fields), Seg::Field(name)) => {
                    fields.iter().find(|(k, _, _)| k == name).map(|(_, _, v)| v)
                }
                (Body::Items(items, _), Seg::Index(i)) => items.get(i),
                _ => None,
            };
            match next {
                Some(n) => node = n,
                None => {
                    exact = false;
                    break;
                }
            }
        }
        let literal = match &node.body {
            Body::Atom(r) if exact && !text[r.clone()].starts_with(['"', '\'', 'r', 'b']) => {
                text.get(r.clone())
            }
            _ => None,
        };
        (node.pos, literal)
    }
}

enum Seg<'a> {
    Field(&'a str),
    Index(usize),
}

fn path_segments(path: &str) -> Vec<Seg<'_>> {
    let mut out = Vec::new();
    for part in path.split('.') {
        let (name, rest) = part.split_once('[').unwrap_or((part, ""));
        if !name.is_empty() {
            out.push(Seg::Field(name));
        }
        for idx in rest.split('[') {
            if let Ok(i) = idx.trim_end_matches(']').parse() {
                out.push(Seg::Index(i));
            }
        }
    }
    out
}

const MAX_DEPTH: usize = 128;

fn parse_value(tokens: &[Token], text: &str, i: &mut usize, depth: usize) -> Option<Node> {
    if depth > MAX_DEPTH {
        return None;
    }
    let t = tokens.get(*i)?;
    let pos = t.pos;
    match t.kind {
        Tok::Word
            if tokens
                .get(*i + 1)
                .is_some_and(|n| n.kind == Tok::Open(b'(')) =>
        {
            let name = text[t.start..t.end].to_owned();
            *i += 1;
            let mut node = parse_group(tokens, text, i, depth)?;
            if name == "Some"
                && let Body::Items(items, _) = &node.body
                && items.len() == 1
            {
                return items.first().cloned();
            }
            node.pos = pos;
            node.prefix = Some(name);
            Some(node)
        }
        Tok::Word | Tok::Str => {
            *i += 1;
            Some(Node {
                pos,
                prefix: None,
                body: Body::Atom(t.start..t.end),
            })
        }
        Tok::Open(_) => parse_group(tokens, text, i, depth),
        _ => None,
    }
}

fn parse_group(tokens: &[Token], text: &str, i: &mut usize, depth: usize) -> Option<Node> {
    let open = tokens.get(*i)?;
    let pos = open.pos;
    let Tok::Open(o) = open.kind else {
        return None;
    };
    let close = match o {
        b'(' => b')',
        b'[' => b']',
        _ => b'}',
    };
    *i += 1;
    let is = |k: usize, kind: Tok| tokens.get(k).is_some_and(|t| t.kind == kind);
    let named =
        o == b'(' && ((is(*i, Tok::Word) && is(*i + 1, Tok::Colon)) || is(*i, Tok::Close(b')')));
    let mut fields = Vec::new();
    let mut items = Vec::new();
    loop {
        if is(*i, Tok::Close(close)) {
            *i += 1;
            break;
        }
        if named {
            let k = tokens.get(*i)?;
            if k.kind != Tok::Word || !is(*i + 1, Tok::Colon) {
                return None;
            }
            let name = text[k.start..k.end].to_owned();
            *i += 2;
            let v = parse_value(tokens, text, i, depth + 1)?;
            fields.push((name, k.pos, v));
        } else {
            let v = parse_value(tokens, text, i, depth + 1)?;
            if o == b'{' {
                // A map entry: key `:` value.
                if !is(*i, Tok::Colon) {
                    return None;
                }
                *i += 1;
                items.push(parse_value(tokens, text, i, depth + 1)?);
            } else {
                items.push(v);
            }
        }
        if is(*i, Tok::Comma) {
            *i += 1;
        } else if !is(*i, Tok::Close(close)) {
            return None;
        }
    }
    Some(Node {
        pos,
        prefix: None,
        body: if named {
            Body::Fields(fields)
        } else {
            Body::Items(items, o)
        },
    })
}

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
pub const DEFAULT_PRESET_RON: &str = include_str!("../presets/campfire.ron");

#[cfg(test)]
mod tests {
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
        let toks = tokenize(text);
        let (v, pos) = scan_version(&toks, text).expect("found");
        assert_eq!(v, Some(3));
        assert_eq!(
            pos,
            TextPos {
                line: 1,
                column: 43
            }
        );
        assert_eq!(scan_version(&tokenize("(name: 1)"), "(name: 1)"), None);
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
        let toks = tokenize(text);
        let tree = Tree::parse(&toks, text).expect("tree");
        let at = |line, column| TextPos { line, column };
        assert_eq!(tree.locate("a[1].y.z", text), (at(2, 28), Some("2.5")));
        assert_eq!(tree.locate("b[1]", text), (at(3, 10), Some("2")));
        assert_eq!(tree.locate("a[0].missing", text), (at(2, 7), None));
    }
}
