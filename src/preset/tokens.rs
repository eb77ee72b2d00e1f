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
    let lex = Lexer {
        text,
        chars: text.char_indices().collect(),
    };
    let mut tokens = Vec::new();
    let (mut i, mut pos) = (0, TextPos { line: 1, column: 1 });
    while i < lex.chars.len() {
        let c = lex.chars[i].1;
        let (kind, j) = match c {
            c if c.is_whitespace() => (None, i + 1),
            '/' if lex.at(i + 1) == Some('/') => (None, lex.line_comment_end(i)),
            '/' if lex.at(i + 1) == Some('*') => match lex.block_comment_end(i) {
                Some(j) => (None, j),
                None => break,
            },
            '(' | '[' | '{' => (Some(Tok::Open(c as u8)), i + 1),
            ')' | ']' | '}' => (Some(Tok::Close(c as u8)), i + 1),
            ',' => (Some(Tok::Comma), i + 1),
            ':' => (Some(Tok::Colon), i + 1),
            '"' => match lex.string_end(i) {
                Some(j) => (Some(Tok::Str), j),
                None => break,
            },
            '\'' => (Some(Tok::Str), lex.char_end(i)),
            c if is_word_char(c) => match lex.word_end(i) {
                Some((kind, j)) => (Some(kind), j),
                None => break,
            },
            _ => (Some(Tok::Other), i + 1),
        };
        let (start, start_pos) = (lex.byte(i), pos);
        i = lex.advance(i, j, &mut pos);
        if let Some(kind) = kind {
            tokens.push(Token {
                kind,
                start,
                end: lex.byte(i),
                pos: start_pos,
                end_pos: pos,
            });
        }
    }
    tokens
}

/// The text being split into tokens, as characters with their byte offsets.
struct Lexer<'a> {
    text: &'a str,
    chars: Vec<(usize, char)>,
}

impl Lexer<'_> {
    /// The byte offset of character `k` (the text's length past the end).
    fn byte(&self, k: usize) -> usize {
        self.chars.get(k).map_or(self.text.len(), |&(b, _)| b)
    }

    /// Character `k`, if there is one.
    fn at(&self, k: usize) -> Option<char> {
        self.chars.get(k).map(|&(_, c)| c)
    }

    /// Moves `pos` over characters `i..j`; returns where it stopped (`j`, or the end).
    fn advance(&self, i: usize, j: usize, pos: &mut TextPos) -> usize {
        let j = j.min(self.chars.len());
        for &(_, c) in &self.chars[i..j] {
            if c == '\n' {
                pos.line += 1;
                pos.column = 1;
            } else {
                pos.column += 1;
            }
        }
        j
    }

    /// The end of the `//` comment at `i` (its line's end).
    fn line_comment_end(&self, i: usize) -> usize {
        let mut j = i + 1;
        while j < self.chars.len() && self.chars[j].1 != '\n' {
            j += 1;
        }
        j
    }

    /// The end of the `/* */` comment at `i` (nested ones included); `None` when it is
    /// never closed.
    fn block_comment_end(&self, i: usize) -> Option<usize> {
        let mut depth = 1;
        let mut j = i + 2;
        while j < self.chars.len() && depth > 0 {
            if self.chars[j].1 == '/' && self.at(j + 1) == Some('*') {
                depth += 1;
                j += 2;
            } else if self.chars[j].1 == '*' && self.at(j + 1) == Some('/') {
                depth -= 1;
                j += 2;
            } else {
                j += 1;
            }
        }
        (depth == 0).then_some(j)
    }

    /// The end of the string at `i` (past its closing quote); `None` when it is never
    /// closed.
    fn string_end(&self, i: usize) -> Option<usize> {
        let mut j = i + 1;
        while j < self.chars.len() {
            match self.chars[j].1 {
                '\\' => j += 2,
                '"' => return Some(j + 1),
                _ => j += 1,
            }
        }
        None
    }

    /// The end of the character literal at `i`.
    fn char_end(&self, i: usize) -> usize {
        let mut j = if self.at(i + 1) == Some('\\') {
            i + 4
        } else {
            i + 3
        };
        while j <= self.chars.len() && self.at(j - 1) != Some('\'') && j < i + 12 {
            j += 1;
        }
        j
    }

    /// The word at `i` and where it ends: a name or number, or a raw string (`r"…"`,
    /// `r#"…"#`, `br"…"`, `b"…"`) or raw identifier (`r#name`); `None` for a raw string
    /// that is never closed.
    fn word_end(&self, i: usize) -> Option<(Tok, usize)> {
        let mut j = i + 1;
        while j < self.chars.len() && is_word_char(self.chars[j].1) {
            j += 1;
        }
        let word = &self.text[self.byte(i)..self.byte(j)];
        if !(matches!(word, "r" | "br" | "b") && matches!(self.at(j), Some('#' | '"'))) {
            return Some((Tok::Word, j));
        }
        let mut hashes = 0;
        while self.at(j + hashes) == Some('#') {
            hashes += 1;
        }
        if self.at(j + hashes) == Some('"') && (word != "b" || hashes == 0) {
            return self
                .raw_string_end(j + hashes + 1, hashes, word == "b")
                .map(|k| (Tok::Str, k));
        }
        j += hashes;
        while j < self.chars.len() && is_word_char(self.chars[j].1) {
            j += 1;
        }
        Some((Tok::Word, j))
    }

    /// The end of a raw string whose text starts at `k`, closed by `"` and `hashes` `#`s
    /// (`escapes`: a byte string, where `\` escapes); `None` when it is never closed.
    fn raw_string_end(&self, mut k: usize, hashes: usize, escapes: bool) -> Option<usize> {
        while k < self.chars.len() {
            if escapes && self.chars[k].1 == '\\' {
                k += 2;
                continue;
            }
            if self.chars[k].1 == '"' && (0..hashes).all(|h| self.at(k + 1 + h) == Some('#')) {
                return Some(k + 1 + hashes);
            }
            k += 1;
        }
        None
    }
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
