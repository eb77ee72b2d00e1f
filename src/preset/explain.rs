//! Error messages for presets that do not parse: ron's error turned into `line:column`, the
//! field path and what was found there (ron's errors say what was expected, not what was
//! found, nor the field path of a syntax error nor which bracket is left open: the tokens of
//! `tokens.rs` supply those), and the closest known name for a misspelt field or variant.

use ron::Error as E;

use super::TextPos;
use super::tokens::{Tok, Token, path_at, unclosed_bracket};

/// Turns a ron error into (position, field path, message) with consistent wording, the text
/// that was found, and the closest known name for a misspelt field or variant.
pub(super) fn explain(
    code: &ron::Error,
    at: TextPos,
    serde_path: &str,
    tokens: &[Token],
    text: &str,
) -> (TextPos, String, String) {
    let site = Site::new(tokens, text, at);
    if let Some(located) = site.inside.and_then(|i| site.bad_integer(i)) {
        return located;
    }
    if matches!(code, E::InvalidIntegerDigit { .. })
        && let Some(located) = site.next.and_then(|i| site.bad_integer(i))
    {
        return located;
    }
    let (moved, message) = match syntax_message(code, &site, serde_path) {
        Some(found) => found,
        None => value_message(code, &site),
    };
    (moved.unwrap_or(site.pos()), site.field(serde_path), message)
}

/// Where a ron error points, among the preset's tokens.
struct Site<'a> {
    tokens: &'a [Token],
    text: &'a str,
    at: TextPos,
    /// The token the error points into (ron points at the whitespace before a value).
    inside: Option<usize>,
    /// The first token at or after the error.
    next: Option<usize>,
}

impl<'a> Site<'a> {
    fn new(tokens: &'a [Token], text: &'a str, at: TextPos) -> Self {
        Self {
            tokens,
            text,
            at,
            inside: tokens.iter().position(|t| t.pos < at && at < t.end_pos),
            next: tokens.iter().position(|t| t.pos >= at),
        }
    }

    /// The token's text.
    fn text_of(&self, t: &Token) -> &'a str {
        &self.text[t.start..t.end]
    }

    /// Where the message points: the token the error is in or before.
    fn pos(&self) -> TextPos {
        if self.tokens.is_empty() {
            return TextPos { line: 1, column: 1 };
        }
        self.inside
            .or(self.next)
            .map_or(self.at, |i| self.tokens[i].pos)
    }

    /// The field path: serde's, or where serde knows none, the tokens'.
    fn field(&self, serde_path: &str) -> String {
        if !(serde_path.ends_with('?') || serde_path.is_empty()) {
            return serde_path.to_owned();
        }
        match self.inside.or(self.next) {
            Some(i) => path_at(self.tokens, self.text, i),
            None => serde_path
                .trim_end_matches('?')
                .trim_end_matches('.')
                .to_owned(),
        }
    }

    /// ", found `…`" for token `i` (the end of the file for none).
    fn found(&self, i: Option<usize>) -> String {
        let Some(t) = i.map(|i| &self.tokens[i]) else {
            return ", found the end of the file".to_owned();
        };
        let s = self.text_of(t);
        let short: String = s.chars().take(40).collect();
        if short.len() < s.len() {
            format!(", found `{short}…`")
        } else {
            format!(", found `{short}`")
        }
    }

    /// A number ron stopped reading in the middle of ("capacity: 20.5" reads 20, then
    /// wants a comma): the field takes an integer.
    fn bad_integer(&self, i: usize) -> Option<(TextPos, String, String)> {
        let t = &self.tokens[i];
        let s = self.text_of(t);
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
        let path = path_at(self.tokens, self.text, i);
        Some((t.pos, path, format!("{why}, found `{s}`")))
    }

    /// A string that swallowed the text after it (a missing closing quote), said as a
    /// parenthesis (empty for none).
    fn runaway(&self) -> String {
        self.next
            .and_then(|i| i.checked_sub(1))
            .map(|i| &self.tokens[i])
            .filter(|t| t.kind == Tok::Str && t.pos.line != t.end_pos.line)
            .map(|t| {
                format!(
                    " (the string starting at {} runs over several lines: is a closing `\"` \
                        missing?)",
                    t.pos
                )
            })
            .unwrap_or_default()
    }

    /// The error is past the last token.
    fn at_end(&self) -> bool {
        self.next.is_none() && self.inside.is_none() && !self.tokens.is_empty()
    }
}

/// The message for a syntax error (a bracket, a separator, a string, the end of the file),
/// with the position when it is not the site's; `None` for other errors.
fn syntax_message(
    code: &ron::Error,
    site: &Site<'_>,
    serde_path: &str,
) -> Option<(Option<TextPos>, String)> {
    let (found, runaway) = (site.found(site.next), site.runaway());
    let message = match code {
        E::ExpectedStringEnd if site.at_end() => {
            "a string is never closed (a `\"` is missing)".to_owned()
        }
        E::UnclosedBlockComment => "a `/*` comment is never closed".to_owned(),
        E::ExceededRecursionLimit => "nested too deeply (more than 128 levels of brackets)".into(),
        _ if site.at_end() => return Some(end_of_file(site)),
        E::ExpectedString | E::ExpectedStringEnd => {
            format!("expected a string in double quotes{found}")
        }
        E::ExpectedArray => format!("expected a list `[…]`{found}"),
        E::ExpectedStructLike | E::ExpectedNamedStructLike(_) => {
            if serde_path.is_empty() && site.tokens.is_empty() {
                "the file is empty; a preset is `(version: 1, name: …, emitters: [ … ])`".to_owned()
            } else {
                format!("expected `(` opening a group of fields{found}")
            }
        }
        E::ExpectedComma => format!("expected `,` between values{found}{runaway}"),
        E::ExpectedArrayEnd => format!("expected `,` or `]` closing the list{found}{runaway}"),
        E::ExpectedStructLikeEnd => format!("expected `,` or `)`{found}{runaway}"),
        E::ExpectedMapColon => format!("expected `:` after the field name{found}"),
        E::ExpectedIdentifier => format!("expected a field or variant name{found}"),
        E::TrailingCharacters => {
            format!("unexpected text after the preset's closing `)`{found}")
        }
        E::Eof => "unexpected end of file".to_owned(),
        _ => return None,
    };
    Some((None, message))
}

/// The file ends before the preset does: pointed just after the last thing in the file,
/// naming the bracket left open.
fn end_of_file(site: &Site<'_>) -> (Option<TextPos>, String) {
    let message = match unclosed_bracket(site.tokens) {
        Some(t) => format!(
            "unexpected end of file: `{}` opened at {} is never closed (is the file \
             truncated?)",
            site.text_of(t),
            t.pos
        ),
        None => "unexpected end of file (is the file truncated?)".to_owned(),
    };
    (site.tokens.last().map(|t| t.end_pos), message)
}

/// The message for a value of the wrong kind, an unknown name, a missing or repeated
/// field, or anything else ron reports (its own words), with the position when it is not
/// the site's (a misspelt field's name).
fn value_message(code: &ron::Error, site: &Site<'_>) -> (Option<TextPos>, String) {
    let found = site.found(site.next);
    let message = match code {
        E::ExpectedInteger => format!("expected a whole number{found}"),
        E::IntegerOutOfBounds => format!(
            "expected a whole number in 0..={}{}",
            u32::MAX,
            site.found(site.inside.or(site.next))
        ),
        E::ExpectedFloat => format!("expected a number{found}"),
        E::ExpectedBoolean => format!("expected `true` or `false`{found}"),
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
        } => return unknown_field(site, expected, found),
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
    (None, message)
}

/// An unknown field `found`: pointed at the misspelt name itself, with the closest of
/// `expected`.
fn unknown_field(site: &Site<'_>, expected: &[&str], found: &str) -> (Option<TextPos>, String) {
    let pos = site
        .tokens
        .iter()
        .find(|t| t.pos >= site.at && site.text_of(t) == found)
        .map(|t| t.pos);
    let message = match closest(expected, found) {
        Some(k) => format!("unknown field `{found}`; did you mean `{k}`?"),
        None => format!(
            "unknown field `{found}`; expected one of {}",
            quoted_list(expected)
        ),
    };
    (pos, message)
}

/// `names` as "`a`, `b`, `c`".
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
