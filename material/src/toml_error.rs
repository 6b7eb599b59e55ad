//! Messages for TOML input errors that point at the offending key.
//!
//! A card that serde reads through an untyped `toml::Value` (a material card is tagged by its
//! `law`, so [`crate::spec::MaterialSpec`] looks at the whole table before it knows its type)
//! loses the positions of its keys: toml then reports an unknown key at its table's header
//! (`[materials.rubber]`), which can be many lines above it. When toml's message names an
//! unknown field and points at a table header, [`describe`] points at the line of that key in
//! that table instead, in toml's own layout (line, column, the line with the key underlined).
//! Every other error is toml's message as it is.
//!
//! The field may belong to a table nested in the card (a Prony term's `modulus` and `tau`), and
//! its name may also be a key of the card itself (`density`). [`name_nested`] tells the two
//! apart by the fields serde expected, and names the nested table in the message, which
//! [`describe`] then leaves at the header rather than underline the card's own, valid key.

use std::path::Path;

/// `FILE: <toml's message>`, with an unknown field placed on its own line (see the module doc).
pub fn describe(path: &Path, src: &str, e: &toml::de::Error) -> String {
    let whole = format!("{}: {}", path.display(), e.to_string().trim_end());
    let located = e
        .span()
        .zip(unknown_field(e.message()))
        .and_then(|(span, field)| key_in_table(src, span.start, field));
    let Some((line, column, text)) = located else {
        return whole;
    };
    let gutter = " ".repeat(line.to_string().len());
    // the indentation as it is (tabs stay tabs, so the carets line up), then one caret a
    // character of the key, quotes included
    let (indent, key) = text.split_at(column - 1);
    let key_chars = match key.strip_prefix(['"', '\'']) {
        Some(rest) => 2 + rest.chars().take_while(|&c| c != '"' && c != '\'').count(),
        None => key
            .chars()
            .take_while(|&c| c != '=' && !c.is_whitespace())
            .count(),
    };
    let pad: String = indent
        .chars()
        .map(|c| if c == '\t' { '\t' } else { ' ' })
        .collect();
    format!(
        "{}: TOML parse error at line {line}, column {}\n{gutter} |\n{line} | {text}\n{gutter} | {pad}{}\n{}",
        path.display(),
        indent.chars().count() + 1,
        "^".repeat(key_chars.max(1)),
        e.message().trim_end()
    )
}

/// The field of serde's ``unknown field `NAME`, expected ...``.
fn unknown_field(message: &str) -> Option<&str> {
    let rest = message.strip_prefix("unknown field `")?;
    rest.split('`').next().filter(|f| !f.is_empty())
}

/// The fields serde's message lists after `expected` (none for "there are no fields").
fn expected_fields(message: &str) -> Vec<&str> {
    message
        .split_once(", expected")
        .map_or(Vec::new(), |(_, rest)| {
            rest.split('`').skip(1).step_by(2).collect()
        })
}

/// serde's message for a card read from `card`, with ``in `KEY` (entry N): `` before it when
/// the struct that refused the unknown field is a table nested in the card (its keys, not the
/// card's, are the expected fields and the unknown one). The message is returned as it is when
/// the card's own keys fit, or when no nested table does (or the card is no table).
pub fn name_nested(card: &toml::Value, message: &str) -> String {
    let (Some(field), Some(card)) = (unknown_field(message), card.as_table()) else {
        return message.to_string();
    };
    let expected = expected_fields(message);
    let fits = |t: &toml::Table, skip: &str| {
        t.contains_key(field)
            && t.keys()
                .all(|k| k == field || k == skip || expected.contains(&k.as_str()))
    };
    if fits(card, "law") {
        return message.to_string();
    }
    for (key, value) in card {
        let place = match value {
            toml::Value::Table(t) if fits(t, "") => format!("`{key}`"),
            toml::Value::Array(items) => match items
                .iter()
                .position(|item| item.as_table().is_some_and(|t| fits(t, "")))
            {
                Some(i) => format!("`{key}` (entry {})", i + 1),
                None => continue,
            },
            _ => continue,
        };
        return format!("in {place}: {message}");
    }
    message.to_string()
}

/// When byte `at` of `src` lies on a table header (`[a.b]` or `[[a]]`), the first line of that
/// table that sets `field` (bare or quoted): its 1-based line and column and its text.
fn key_in_table<'a>(src: &'a str, at: usize, field: &str) -> Option<(usize, usize, &'a str)> {
    let start = src.get(..at)?.rfind('\n').map_or(0, |i| i + 1);
    let first = src[..start].matches('\n').count();
    let mut lines = src[start..].lines();
    if !lines.next()?.trim_start().starts_with('[') {
        return None;
    }
    let quoted = [format!("\"{field}\""), format!("'{field}'")];
    for (k, text) in lines.enumerate() {
        let key = text.trim_start();
        if key.starts_with('[') {
            return None;
        }
        let sets = [field, &quoted[0], &quoted[1]].into_iter().any(|n| {
            key.strip_prefix(n)
                .is_some_and(|rest| rest.trim_start().starts_with('='))
        });
        if sets {
            return Some((first + k + 2, text.len() - key.len() + 1, text));
        }
    }
    None
}
