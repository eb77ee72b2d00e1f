//! Finding a value in a preset's text by its field path (`emitters[1].shape.radius_m`),
//! with ron's own parser and positions: the text is deserialised by a probe that walks
//! down the path (every other value skipped) and stops with a marker error at the value
//! itself, and ron's span for that error is where the value is. Works on any text ron
//! reads up to that value (comments, `Some(…)` or not, struct names, attributes).

use serde::de::{self, DeserializeSeed, Deserializer, IgnoredAny, MapAccess, SeqAccess, Visitor};

use super::{TextPos, ron_options};

/// The marker error the probe stops with.
const FOUND: &str = "ignis: the value is here";

/// One step of a field path.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Seg<'a> {
    Field(&'a str),
    Index(usize),
}

/// `emitters[1].look.color_over_life[2].t` → its segments.
fn segments(path: &str) -> Vec<Seg<'_>> {
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

/// A value found in the text.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Located {
    /// Where it starts.
    pub pos: TextPos,
    /// Its text when it is a number or a name (for messages: `1e39` as written).
    pub literal: Option<String>,
}

/// The value at `path` in `text`, or `None` when the text does not hold it (a field left
/// at its default) or ron cannot read the text up to it.
pub(super) fn value_at(text: &str, path: &str) -> Option<Located> {
    let segs = segments(path);
    let mut de = ron::Deserializer::from_str_with_options(text, &ron_options()).ok()?;
    let err = match (Probe { path: &segs }).deserialize(&mut de) {
        Ok(()) => return None,
        Err(e) => de.span_error(e),
    };
    if !matches!(&err.code, ron::Error::Message(m) if m == FOUND) {
        return None;
    }
    let start = byte_offset(text, err.span.start)?;
    let end = byte_offset(text, err.span.end)?.max(start);
    // ron reads an integer's sign, and a string's opening quote (`"`, `r#"`), as tokens
    // of their own: the value starts there.
    let before = &text[..start];
    let start = match before.strip_suffix(['-', '+']) {
        Some(b) => b.len(),
        None => match before.strip_suffix('"') {
            Some(b) => {
                let b = b.trim_end_matches('#');
                b.strip_suffix('r').unwrap_or(b).len()
            }
            None => start,
        },
    };
    // A newtype variant's span (`Constant(-5)`) starts at its parenthesis: a scalar inside
    // starts after it.
    let (start, end) = match text[start..].strip_prefix('(') {
        Some(rest) => {
            let inner = skip_blank(rest);
            let cut = inner.find([',', ')']).unwrap_or(inner.len());
            let token = &inner[..cut];
            // A tuple (`(0.0, -inf)`) is the value itself, not a newtype around a scalar.
            let tuple = inner[cut..].starts_with(',');
            if tuple || token.trim().is_empty() || token.contains([':', '(', '[', '"']) {
                (start, end)
            } else {
                let at = text.len() - inner.len();
                (at, at + token.trim_end().len())
            }
        }
        None => (start, end),
    };
    let literal = text
        .get(start..end)
        .map(str::trim)
        .filter(|s| !s.is_empty() && s.chars().all(|c| c.is_alphanumeric() || "+-._".contains(c)))
        .map(str::to_owned);
    Some(Located {
        pos: text_pos(text, start),
        literal,
    })
}

/// `s` after its leading whitespace and comments.
fn skip_blank(mut s: &str) -> &str {
    loop {
        s = s.trim_start();
        if let Some(rest) = s.strip_prefix("/*") {
            s = rest.find("*/").map_or("", |i| &rest[i + 2..]);
        } else if let Some(rest) = s.strip_prefix("//") {
            s = rest.find('\n').map_or("", |i| &rest[i..]);
        } else {
            return s;
        }
    }
}

/// The line and column of byte `offset`.
fn text_pos(text: &str, offset: usize) -> TextPos {
    let before = &text[..offset];
    TextPos {
        line: 1 + before.matches('\n').count(),
        column: 1 + before.chars().rev().take_while(|&c| c != '\n').count(),
    }
}

/// The value at `path`, or the deepest enclosing value the text holds (the document when
/// nothing of the path is there).
pub(super) fn locate(text: &str, path: &str) -> Option<Located> {
    let mut prefix = path;
    loop {
        if let Some(found) = value_at(text, prefix) {
            let exact = prefix.len() == path.len();
            return Some(Located {
                literal: found.literal.filter(|_| exact),
                ..found
            });
        }
        if prefix.is_empty() {
            return None;
        }
        prefix = match prefix.rfind(['.', '[']) {
            Some(i) => &prefix[..i],
            None => "",
        };
    }
}

/// The byte offset of a ron position (1-based line, 1-based column in characters).
fn byte_offset(text: &str, p: ron::error::Position) -> Option<usize> {
    let line_start = if p.line <= 1 {
        0
    } else {
        text.match_indices('\n').nth(p.line - 2)?.0 + 1
    };
    let line = &text[line_start..];
    let within = line
        .char_indices()
        .nth(p.col.saturating_sub(1))
        .map_or(line.len(), |(i, _)| i);
    Some(line_start + within)
}

/// Deserialises any value, walking into the path's next segment; at the path's end,
/// stops with [`FOUND`].
struct Probe<'p, 'a> {
    path: &'p [Seg<'a>],
}

impl<'de> DeserializeSeed<'de> for Probe<'_, '_> {
    type Value = ();

    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<(), D::Error> {
        if self.path.is_empty() {
            // Read the value's first token, so that ron's span is the value.
            return d.deserialize_any(Found);
        }
        d.deserialize_any(self)
    }
}

/// Stops with [`FOUND`] at whatever value it is given.
struct Found;

/// Visitor methods that all stop with [`FOUND`].
macro_rules! found {
    ($($name:ident($($arg:ty),*)),* $(,)?) => {
        $(fn $name<E: de::Error>(self $(, _: $arg)*) -> Result<(), E> {
            Err(E::custom(FOUND))
        })*
    };
}

impl<'de> Visitor<'de> for Found {
    type Value = ();

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("any value")
    }

    found!(
        visit_bool(bool),
        visit_i64(i64),
        visit_i128(i128),
        visit_u64(u64),
        visit_u128(u128),
        visit_f64(f64),
        visit_char(char),
        visit_str(&str),
        visit_bytes(&[u8]),
        visit_unit(),
        visit_none(),
    );

    fn visit_map<A: MapAccess<'de>>(self, _: A) -> Result<(), A::Error> {
        Err(de::Error::custom(FOUND))
    }
    fn visit_seq<A: SeqAccess<'de>>(self, _: A) -> Result<(), A::Error> {
        Err(de::Error::custom(FOUND))
    }
    // `Some(x)` is where `x` is.
    fn visit_some<D: Deserializer<'de>>(self, d: D) -> Result<(), D::Error> {
        d.deserialize_any(self)
    }
    fn visit_newtype_struct<D: Deserializer<'de>>(self, d: D) -> Result<(), D::Error> {
        d.deserialize_any(self)
    }
    fn visit_enum<A: de::EnumAccess<'de>>(self, _: A) -> Result<(), A::Error> {
        Err(de::Error::custom(FOUND))
    }
}

impl<'de> Visitor<'de> for Probe<'_, '_> {
    type Value = ();

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("any value")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<(), A::Error> {
        while let Some(key) = map.next_key::<String>()? {
            if self.path.first() == Some(&Seg::Field(&key)) {
                map.next_value_seed(Probe {
                    path: &self.path[1..],
                })?;
            } else {
                map.next_value::<IgnoredAny>()?;
            }
        }
        Ok(())
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<(), A::Error> {
        let mut i = 0;
        loop {
            let more = if self.path.first() == Some(&Seg::Index(i)) {
                seq.next_element_seed(Probe {
                    path: &self.path[1..],
                })?
            } else {
                seq.next_element::<IgnoredAny>()?.map(|_| ())
            };
            if more.is_none() {
                return Ok(());
            }
            i += 1;
        }
    }

    fn visit_some<D: Deserializer<'de>>(self, d: D) -> Result<(), D::Error> {
        d.deserialize_any(self)
    }

    fn visit_newtype_struct<D: Deserializer<'de>>(self, d: D) -> Result<(), D::Error> {
        d.deserialize_any(self)
    }

    // Scalars: the path goes on past them, so it is not in the text.
    fn visit_bool<E>(self, _: bool) -> Result<(), E> {
        Ok(())
    }
    fn visit_i64<E>(self, _: i64) -> Result<(), E> {
        Ok(())
    }
    fn visit_u64<E>(self, _: u64) -> Result<(), E> {
        Ok(())
    }
    fn visit_f64<E>(self, _: f64) -> Result<(), E> {
        Ok(())
    }
    fn visit_str<E>(self, _: &str) -> Result<(), E> {
        Ok(())
    }
    fn visit_unit<E>(self) -> Result<(), E> {
        Ok(())
    }
    fn visit_none<E>(self) -> Result<(), E> {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "// a preset\n(\n    version: 1,\n    name: \"x\",\n    emitters: [\n        (name: \"a\", rate: 5.0),\n        (\n            name: \"b\", // the second\n            shape: Disc(radius_m: -1e39, normal: (0.0, 1.0, 0.0)),\n            ramp: [(t: 0.0), (t: 2.5)],\n            opt: Some(3),\n        ),\n    ],\n)\n";

    fn at(path: &str) -> Option<(usize, usize, Option<String>)> {
        value_at(TEXT, path).map(|l| (l.pos.line, l.pos.column, l.literal))
    }

    #[test]
    fn values_are_found_where_ron_reads_them() {
        assert_eq!(at("version"), Some((3, 14, Some("1".into()))));
        assert_eq!(at("emitters[0].rate"), Some((6, 27, Some("5.0".into()))));
        assert_eq!(
            at("emitters[1].shape.radius_m"),
            Some((9, 35, Some("-1e39".into())))
        );
        assert_eq!(
            at("emitters[1].ramp[1].t"),
            Some((10, 34, Some("2.5".into())))
        );
        assert_eq!(at("emitters[1].opt"), Some((11, 23, Some("3".into()))));
        assert_eq!(at("emitters[1].missing"), None);
        assert_eq!(at("emitters[2]"), None);
    }

    #[test]
    fn a_missing_value_is_located_at_its_deepest_enclosing_value() {
        let l = locate(TEXT, "emitters[1].shape.normal_x.y").expect("located");
        assert_eq!((l.pos.line, l.literal), (9, None));
        let l = locate(TEXT, "seed").expect("located");
        assert_eq!(l.pos.line, 2, "the document");
    }
}
