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
/// the card's own keys fit, or when no nested table does.
pub fn name_nested(card: &toml::Table, message: &str) -> String {
    let Some(field) = unknown_field(message) else {
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
    for (k, text) in lines.enumerate() {
        let key = text.trim_start();
        if key.starts_with('[') {
            return None;
        }
        let quoted = [format!("\"{field}\""), format!("'{field}'")];
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::MaterialSpec;
    use std::collections::BTreeMap;

    #[derive(Debug, serde::Deserialize)]
    #[allow(dead_code)]
    struct Scene {
        materials: BTreeMap<String, MaterialSpec>,
    }

    fn message(src: &str) -> String {
        let e = toml::from_str::<Scene>(src).unwrap_err();
        describe(Path::new("s.toml"), src, &e)
    }

    #[test]
    fn an_unknown_key_in_a_material_card_is_placed_on_its_line() {
        let src = "# a scene\n[materials.rubber]\nlaw = \"neo_hookean\"\ndensity = \"1000 kg/m^3\"\n  shear_modulas = \"1 kPa\"\n\n[materials.other]\nlaw = \"neo_hookean\"\n";
        let m = message(src);
        assert!(
            m.starts_with("s.toml: TOML parse error at line 5, column 3\n"),
            "{m}"
        );
        assert!(
            m.contains("\n5 |   shear_modulas = \"1 kPa\"\n  |   ^^^^^^^^^^^^^\n"),
            "{m}"
        );
        assert!(
            m.contains("unknown field `shear_modulas`, expected one of"),
            "{m}"
        );
        // quoted, with spaces before `=`
        let m = message(&src.replace("  shear_modulas =", "\"shear_modulas\"   ="));
        assert!(m.contains("line 5, column 1"), "{m}");
    }

    #[test]
    fn a_nested_field_named_like_a_card_key_is_not_placed_on_the_card_s_key() {
        // a Prony term's unknown `density`: the card's own `density` (line 3) is valid
        let card = "[materials.a]\nlaw = \"ogden\"\ndensity = \"1000 kg/m^3\"\nmu = [\"1 kPa\"]\nalpha = [2.0]\nbulk_modulus = \"1 MPa\"\n";
        for prony in [
            "[[materials.a.prony]]\nmodulus = \"1 kPa\"\ndensity = 3.0\n",
            "prony = [{ modulus = \"1 kPa\", tau = \"1 ms\" }, { modulus = \"1 kPa\", density = 2.0 }]\n",
        ] {
            let src = if prony.starts_with('[') {
                format!("{card}{prony}")
            } else {
                card.replace("mu =", &format!("{prony}mu ="))
            };
            let m = message(&src);
            assert!(!m.contains("line 3"), "{m}");
            assert!(m.contains("in `prony` (entry "), "{m}");
            assert!(m.contains("unknown field `density`, expected"), "{m}");
        }
        // the nested term's own line is not found from the card's header: toml's place stays
        let m = message(&format!(
            "{card}[[materials.a.prony]]\nmodulus = \"1 kPa\"\ntaux = 1.0\n"
        ));
        assert!(
            m.contains("in `prony` (entry 1): unknown field `taux`"),
            "{m}"
        );
    }

    #[test]
    fn carets_count_characters_and_keep_tabs() {
        let src = "[materials.rubber]\nlaw = \"neo_hookean\"\n\t\"dénsité x\" = 1.0\n";
        let m = message(src);
        assert!(m.contains("line 3, column 2\n"), "{m}");
        assert!(m.contains("\n  | \t^^^^^^^^^^^\n"), "{m}");
    }

    #[test]
    fn other_errors_are_toml_s_own() {
        // a missing field, and a syntax error
        let src = "[materials.rubber]\nlaw = \"neo_hookean\"\n[materials.b]\nbogus = 1\n";
        let e = toml::from_str::<Scene>(src).unwrap_err();
        assert_eq!(
            describe(Path::new("s.toml"), src, &e),
            format!("s.toml: {}", e.to_string().trim_end())
        );
        let src = "[materials.rubber\n";
        let e = toml::from_str::<Scene>(src).unwrap_err();
        assert_eq!(
            describe(Path::new("s.toml"), src, &e),
            format!("s.toml: {}", e.to_string().trim_end())
        );
    }
}
