//! `*PARAMETER`: named values that cards use as `&NAME` (or `-&NAME`, negated).
//!
//! Each `*PARAMETER` card holds up to four pairs `PRMR VAL` of 10-column fields (or comma
//! separated): `PRMR` is a type letter, `R` (real), `I` (integer) or `C` (character), followed by
//! the name, e.g. `R   YOUNG` then `1.0e-3`. A parameter applies to the keywords after its
//! definition (LS-DYNA requires the definition first); a name is not case-sensitive. A reference
//! to an undefined parameter and a second definition of a name are errors naming both places.
//! `*PARAMETER_EXPRESSION` (values computed from formulas) is not evaluated: the keyword reader
//! refuses it.

use crate::lex::{parse_real, Card, Lexed, Params};
use std::sync::Arc;

/// Read the `*PARAMETER` keywords and give every later keyword the parameters then defined.
pub fn expand(lexed: &mut Lexed) -> Result<(), String> {
    let mut current: Arc<Params> = Arc::new(Params::new());
    for b in &mut lexed.blocks {
        b.params = current.clone();
        if b.name != "PARAMETER" && b.name != "PARAMETER_LOCAL" {
            continue;
        }
        let mut map = (*current).clone();
        for card in &b.cards {
            for (name, value) in pairs(card, &b.name)? {
                if let Some((_, first)) = map.get(&name) {
                    return Err(format!(
                        "{}: *{}: parameter `{name}` is defined again (first at {first})",
                        card.at, b.name
                    ));
                }
                map.insert(name, (value, card.at.clone()));
            }
        }
        current = Arc::new(map);
    }
    Ok(())
}

/// The (name, value) pairs of one `*PARAMETER` card.
fn pairs(card: &Card, kw: &str) -> Result<Vec<(String, String)>, String> {
    let text = card.text.trim_end();
    let fields: Vec<String> = if text.contains(',') {
        text.split(',').map(|s| s.trim().to_string()).collect()
    } else {
        (0..8)
            .map(|k| {
                text.get(10 * k..(10 * k + 10).min(text.len()))
                    .unwrap_or("")
                    .trim()
                    .to_string()
            })
            .collect()
    };
    let mut out = Vec::new();
    for k in (0..fields.len()).step_by(2) {
        let prmr = fields[k].as_str();
        if prmr.is_empty() {
            continue;
        }
        let mut chars = prmr.chars();
        let ty = chars.next().unwrap().to_ascii_uppercase();
        let name = chars.as_str().trim().to_ascii_uppercase();
        let cols = if text.contains(',') {
            String::new()
        } else {
            format!(" (columns {}-{})", 10 * k + 1, 10 * k + 10)
        };
        if !matches!(ty, 'R' | 'I' | 'C') || name.is_empty() {
            return Err(format!(
                "{}: *{kw}, field PRMR{}{cols}: `{prmr}` is not a type letter R, I or C followed by a name",
                card.at,
                k / 2 + 1
            ));
        }
        let value = fields.get(k + 1).cloned().unwrap_or_default();
        if value.is_empty() {
            return Err(format!(
                "{}: *{kw}: parameter `{name}` has no value",
                card.at
            ));
        }
        match ty {
            'R' if parse_real(&value).is_none() => {
                return Err(format!(
                    "{}: *{kw}: real parameter `{name}`: `{value}` is not a number",
                    card.at
                ))
            }
            'I' if value.parse::<i64>().is_err() => {
                return Err(format!(
                    "{}: *{kw}: integer parameter `{name}`: `{value}` is not an integer",
                    card.at
                ))
            }
            _ => {}
        }
        out.push((name, value));
    }
    Ok(out)
}

/// A field's text with a parameter reference replaced by its value; `Ok(None)` if the field
/// refers to none, an error naming the field if the parameter is not defined.
pub fn substitute(value: &str, params: &Params) -> Result<Option<String>, String> {
    let (neg, rest) = match value.strip_prefix('-') {
        Some(r) => (true, r),
        None => (false, value),
    };
    let Some(name) = rest.strip_prefix('&') else {
        return Ok(None);
    };
    let key = name.trim().to_ascii_uppercase();
    let (v, _) = params.get(&key).ok_or_else(|| {
        format!(
            "parameter `&{}` is not defined (by a *PARAMETER before it)",
            name.trim()
        )
    })?;
    Ok(Some(match (neg, v.strip_prefix('-')) {
        (false, _) => v.clone(),
        (true, Some(pos)) => pos.to_string(),
        (true, None) => format!("-{v}"),
    }))
}
