//! A tolerant tokenizer for preset text, for what ron's errors do not say: the text found
//! where an error points, the field path of a syntax error, an unclosed bracket or a
//! runaway string. Never fails (fuzzed by `tests/fuzz.rs`); the values themselves are
//! located with ron's own parser (`locate.rs`).

use super::TextPos;

/// Kinds of RON tokens (comments and whitespace are dropped).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Tok {
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
pub(super) struct Token {
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

pub(super) fn is_word_char(c: char) -> bool {
    c.is_alphanumeric() || matches!(c, '_' | '.' | '+' | '-')
}

/// Splits RON text into tokens. Never fails: an unterminated string or comment ends the
/// token list (the deserialiser reports it).
pub(super) fn tokenize(text: &str) -> Vec<Token> {
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
/// Index of the first token of the document's value (after `#![…]` attributes).
pub(super) fn value_start(tokens: &[Token]) -> usize {
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

/// A RON unsigned integer literal: decimal, `0x`/`0o`/`0b`, `_` separators, optional
/// `u32`/`u64` suffix.
pub(super) fn parse_integer(word: &str) -> Option<u64> {
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
pub(super) fn unclosed_bracket(tokens: &[Token]) -> Option<&Token> {
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
pub(super) fn path_at(tokens: &[Token], text: &str, upto: usize) -> String {
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
