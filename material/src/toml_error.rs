//! Messages for TOML input errors that point at the offending key.
//!
//! A card that serde reads through an untyped `toml::Value` (a material card is tagged by its
//! `law`, so [`crate::spec::MaterialSpec`] looks at the whole table before it knows its type)
//! loses the positions of its keys: toml then reports an unknown key at its table's header
//! (`[materials.rubber]`), which can be many lines above it. When toml's message names an
//! unknown field and points at a table header, [`describe`] points at the line of that key in
//! that table instead, in toml's own layout (line, column, the line with the key underlined).
//! Every other error is toml's message as it is.

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
    let key_len = text[column - 1..]
        .find(|c: char| c == '=' || c.is_whitespace())
        .unwrap_or(text.len() - column + 1)
        .max(1);
    format!(
        "{}: TOML parse error at line {line}, column {column}\n{gutter} |\n{line} | {text}\n{gutter} | {}{}\n{}",
        path.display(),
        " ".repeat(column - 1),
        "^".repeat(key_len),
        e.message().trim_end()
    )
}

/// The field of serde's ``unknown field `NAME`, expected ...``.
fn unknown_field(message: &str) -> Option<&str> {
    let rest = message.strip_prefix("unknown field `")?;
    rest.split('`').next().filter(|f| !f.is_empty())
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
