//! The layout of saved presets: ron's own compact output, re-laid out like a
//! hand-written preset — a group on one line when it fits in [`LINE_WIDTH`] columns, one
//! field or item per line otherwise. Hand-written because ron's pretty-printer breaks
//! lines by nesting depth, not by width: vectors, ranges and colour stops would each take
//! several lines, or long groups stay on one.

use crate::effect::Effect;

use super::tokens::{Tok, Token, tokenize, value_start};
use super::{PresetError, TextPos, ron_options};

/// Lines longer than this are broken, one field or item per line.
pub(super) const LINE_WIDTH: usize = 100;

/// The RON text of an effect, laid out like a hand-written preset: named fields, enums by
/// name, `Option`s without `Some(…)`, every field written out (so the file's meaning never
/// depends on this build's defaults), small groups on one line and larger ones one field per
/// line. [`super::parse_str`] reads it back to an equal effect.
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
pub(super) fn inline(node: &Node, text: &str) -> String {
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

pub(super) fn node_prefix(node: &Node) -> &str {
    node.prefix.as_deref().unwrap_or("")
}

pub(super) fn brackets(open: u8) -> (char, char) {
    match open {
        b'[' => ('[', ']'),
        b'{' => ('{', '}'),
        _ => ('(', ')'),
    }
}

/// Writes `node` starting at column `col` (after a `key: `), broken over lines at `indent`
/// when it does not fit.
pub(super) fn write_node(
    node: &Node,
    text: &str,
    indent: usize,
    col: usize,
    out: &mut String,
    force: bool,
) {
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

/// A parsed RON value with positions (prefix names and `Some(…)` unwrapped).
#[derive(Clone, Debug)]
pub(super) struct Node {
    pos: TextPos,
    prefix: Option<String>,
    body: Body,
}

#[derive(Clone, Debug)]
pub(super) enum Body {
    /// A number, string, identifier…: its byte range in the text.
    Atom(std::ops::Range<usize>),
    /// `(name: value, …)` with each name's position.
    Fields(Vec<(String, TextPos, Node)>),
    /// `(a, b)`, `[a, b]` or `{k: v}` (values only), with the opening byte.
    Items(Vec<Node>, u8),
}

pub(super) struct Tree {
    root: Node,
}

impl Tree {
    /// Parses the whole document; `None` when it is not well-formed.
    fn parse(tokens: &[Token], text: &str) -> Option<Tree> {
        let mut i = value_start(tokens);
        let root = parse_value(tokens, text, &mut i, 0)?;
        Some(Tree { root })
    }
}

pub(super) const MAX_DEPTH: usize = 128;

pub(super) fn parse_value(
    tokens: &[Token],
    text: &str,
    i: &mut usize,
    depth: usize,
) -> Option<Node> {
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

pub(super) fn parse_group(
    tokens: &[Token],
    text: &str,
    i: &mut usize,
    depth: usize,
) -> Option<Node> {
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
