//! Fields of one card: cut by columns (fixed format) or at commas (free format), then read as
//! integers, reals or text. A blank field takes the default. Every error names the file, the
//! line, the keyword and the field (and its columns in fixed format).
//!
//! Reals follow Fortran's list input as LS-DYNA reads it: `1.5`, `1.`, `.5`, `1.5e-3`,
//! `1.5E-3`, `1.5d-3`. Integers may not have a decimal point.

use crate::lex::{parse_real, Block, Card, Format, Loc};

/// A field of a card layout: its name and standard width in columns.
pub type Field = (&'static str, usize);

/// A card cut into fields.
#[derive(Clone, Debug)]
pub struct Fields {
    at: Loc,
    keyword: String,
    names: &'static [Field],
    values: Vec<String>,
    /// Columns of each field (1-based, inclusive), None in free format.
    cols: Vec<Option<(usize, usize)>>,
}

/// Cut a card into the fields of `layout`; a missing card (`None`) is a blank one, every
/// field at its default.
pub fn fields(
    block: &Block,
    card: Option<&Card>,
    layout: &'static [Field],
) -> Result<Fields, String> {
    let (text, at) = match card {
        Some(c) => (c.text.as_str(), c.at.clone()),
        None => ("", block.at.clone()),
    };
    let card = Card {
        text: String::new(),
        at,
    };
    if text.contains('\t') {
        return Err(format!(
            "{}: *{}: a tab character in a card; LS-DYNA reads cards by columns, so use spaces (or separate the fields with commas)",
            card.at, block.name
        ));
    }
    let mut values = Vec::with_capacity(layout.len());
    let mut cols = Vec::with_capacity(layout.len());
    if text.contains(',') {
        let parts: Vec<&str> = text.split(',').collect();
        if parts.len() > layout.len() && parts[layout.len()..].iter().any(|p| !p.trim().is_empty())
        {
            return Err(format!(
                "{}: *{}: {} comma-separated fields, but this card has {} ({})",
                card.at,
                block.name,
                parts.len(),
                layout.len(),
                layout.iter().map(|f| f.0).collect::<Vec<_>>().join(" ")
            ));
        }
        for k in 0..layout.len() {
            values.push(parts.get(k).map_or("", |p| p.trim()).to_string());
            cols.push(None);
        }
    } else {
        if !text.is_ascii() {
            // Fixed columns count characters as LS-DYNA does (bytes of an ASCII deck): a
            // non-ASCII character would shift every later field.
            let col = text
                .char_indices()
                .find(|(_, c)| !c.is_ascii())
                .map_or(0, |(i, _)| i)
                + 1;
            return Err(format!(
                "{}: *{}: a character that is not ASCII in column {col} of a fixed-format card; LS-DYNA reads such cards column by column, so write the line in ASCII (or comma-separated)",
                card.at, block.name
            ));
        }
        let mut start = 0;
        for &(_, w) in layout {
            let w = block.format.width(w);
            let end = (start + w).min(text.len());
            let v = if start < text.len() {
                text.get(start..end).unwrap_or("")
            } else {
                ""
            };
            values.push(v.trim().to_string());
            cols.push(Some((start + 1, start + w)));
            start += w;
        }
        if text.len() > start && !text[start.min(text.len())..].trim().is_empty() {
            return Err(format!(
                "{}: *{}: text beyond column {start} (`{}`); this card has {} fields of {} ({})",
                card.at,
                block.name,
                text[start..].trim(),
                layout.len(),
                match block.format {
                    Format::Long => "20 columns (long format)".to_string(),
                    f =>
                        layout
                            .iter()
                            .map(|x| f.width(x.1).to_string())
                            .collect::<Vec<_>>()
                            .join("/")
                            + " columns",
                },
                layout.iter().map(|f| f.0).collect::<Vec<_>>().join(" ")
            ));
        }
    }
    if !block.params.is_empty() || values.iter().any(|v| v.contains('&')) {
        for (k, v) in values.iter_mut().enumerate() {
            match crate::params::substitute(v, &block.params) {
                Ok(Some(x)) => *v = x,
                Ok(None) => {}
                Err(e) => {
                    let cols = match cols[k] {
                        Some((a, b)) => format!(" (columns {a}-{b})"),
                        None => String::new(),
                    };
                    return Err(format!(
                        "{}: *{}, field {}{cols}: {e}",
                        card.at, block.name, layout[k].0
                    ));
                }
            }
        }
    }
    Ok(Fields {
        at: card.at,
        keyword: block.name.clone(),
        names: layout,
        values,
        cols,
    })
}

impl Fields {
    fn index(&self, name: &str) -> usize {
        self.names
            .iter()
            .position(|f| f.0 == name)
            .unwrap_or_else(|| panic!("field {name} not in layout of *{}", self.keyword))
    }

    /// `FILE:LINE: *KEYWORD, field `NAME` (columns a-b)`.
    pub fn at(&self, name: &str) -> String {
        let i = self.index(name);
        match self.cols[i] {
            Some((a, b)) => format!(
                "{}: *{}, field {name} (columns {a}-{b})",
                self.at, self.keyword
            ),
            None => format!("{}: *{}, field {name}", self.at, self.keyword),
        }
    }

    /// Where the card is.
    pub fn loc(&self) -> &Loc {
        &self.at
    }

    /// The raw text of a field (trimmed; empty when blank).
    pub fn raw(&self, name: &str) -> &str {
        &self.values[self.index(name)]
    }

    /// Whether a field is blank.
    pub fn blank(&self, name: &str) -> bool {
        self.raw(name).is_empty()
    }

    /// A real, or `None` when blank.
    pub fn real_opt(&self, name: &str) -> Result<Option<f64>, String> {
        let s = self.raw(name);
        if s.is_empty() {
            return Ok(None);
        }
        parse_real(s)
            .map(Some)
            .ok_or_else(|| format!("{}: `{s}` is not a number", self.at(name)))
    }

    /// A real, `default` when blank.
    pub fn real(&self, name: &str, default: f64) -> Result<f64, String> {
        Ok(self.real_opt(name)?.unwrap_or(default))
    }

    /// A required real.
    pub fn real_req(&self, name: &str) -> Result<f64, String> {
        self.real_opt(name)?
            .ok_or_else(|| format!("{}: a value is required", self.at(name)))
    }

    /// An integer, or `None` when blank.
    pub fn int_opt(&self, name: &str) -> Result<Option<i64>, String> {
        let s = self.raw(name);
        if s.is_empty() {
            return Ok(None);
        }
        if let Ok(v) = s.parse::<i64>() {
            return Ok(Some(v));
        }
        // LS-DYNA reads "1." in an integer field of free format as 1; accept an exact integer.
        match parse_real(s) {
            Some(v) if v.fract() == 0.0 && v.abs() < 9.0e15 => Ok(Some(v as i64)),
            _ => Err(format!("{}: `{s}` is not an integer", self.at(name))),
        }
    }

    /// An integer, `default` when blank.
    pub fn int(&self, name: &str, default: i64) -> Result<i64, String> {
        Ok(self.int_opt(name)?.unwrap_or(default))
    }

    /// A required integer.
    pub fn int_req(&self, name: &str) -> Result<i64, String> {
        self.int_opt(name)?
            .ok_or_else(|| format!("{}: a value is required", self.at(name)))
    }

    /// Text (trimmed).
    pub fn text(&self, name: &str) -> String {
        self.raw(name).to_string()
    }

    /// Every non-blank field with its name, for messages about fields palpa does not use.
    pub fn given(&self, names: &[&str]) -> Vec<(String, String)> {
        names
            .iter()
            .filter(|n| !self.blank(n))
            .map(|n| (n.to_string(), self.raw(n).to_string()))
            .collect()
    }

    /// An error at a field.
    pub fn err(&self, name: &str, msg: impl std::fmt::Display) -> String {
        format!("{}: {msg}", self.at(name))
    }

    /// A real field that must be zero (blank) or equal to `default`, with the reason if not.
    pub fn must_be(&self, name: &str, default: f64, why: &str) -> Result<(), String> {
        let v = self.real(name, default)?;
        if v != default {
            return Err(self.err(name, format!("{v} is not supported: {why}")));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    fn block(format: Format, text: &str) -> Block {
        let at = Loc {
            file: Arc::new("d.k".into()),
            line: 3,
        };
        Block {
            name: "MAT_ELASTIC".into(),
            line: "*MAT_ELASTIC".into(),
            format,
            at: at.clone(),
            cards: vec![Card {
                text: text.into(),
                at,
            }],
            palpa: Vec::new(),
            params: Default::default(),
        }
    }

    const L: &[Field] = &[("MID", 10), ("RO", 10), ("E", 10), ("PR", 10)];

    #[test]
    fn non_ascii_in_a_fixed_format_card_is_an_error_not_a_panic() {
        // U+FFFD is what a Latin-1 byte becomes when the deck is read; it sits across the
        // boundary of the second field.
        let b = block(
            Format::Standard,
            "         1  1.0e-6\u{fffd}  2.0e-3       0.3",
        );
        let e = fields(&b, Some(&b.cards[0]), L).unwrap_err();
        assert!(
            e.contains("d.k:3") && e.contains("not ASCII in column 19"),
            "{e}"
        );
        // Free format is cut at commas, where any text is fine.
        let b = block(Format::Standard, "1,1e-6,2e-3,0.3");
        assert!(fields(&b, Some(&b.cards[0]), L).is_ok());
    }

    #[test]
    fn fixed_free_and_long_formats() {
        let b = block(Format::Standard, "         1    1.0e-6    2.0d-3       0.3");
        let f = fields(&b, Some(&b.cards[0]), L).unwrap();
        assert_eq!(f.int("MID", 0).unwrap(), 1);
        assert_eq!(f.real_req("RO").unwrap(), 1e-6);
        assert_eq!(f.real_req("E").unwrap(), 2e-3);
        assert_eq!(f.real("PR", 0.0).unwrap(), 0.3);
        let b = block(Format::Standard, "1,1e-6,,0.45");
        let f = fields(&b, Some(&b.cards[0]), L).unwrap();
        assert!(f.blank("E"));
        assert_eq!(f.real("PR", 0.0).unwrap(), 0.45);
        let b = block(Format::Long, "                   7              1.5e-6");
        let f = fields(&b, Some(&b.cards[0]), L).unwrap();
        assert_eq!(f.int_req("MID").unwrap(), 7);
        assert_eq!(f.real_req("RO").unwrap(), 1.5e-6);
        let b = block(Format::Standard, "         1       abc");
        let f = fields(&b, Some(&b.cards[0]), L).unwrap();
        let e = f.real_req("RO").unwrap_err();
        assert!(
            e.contains("d.k:3") && e.contains("field RO (columns 11-20)") && e.contains("`abc`"),
            "{e}"
        );
        let b = block(Format::Standard, "1\t2");
        assert!(fields(&b, Some(&b.cards[0]), L)
            .unwrap_err()
            .contains("tab"));
        let b = block(Format::Standard, "1,2,3,4,5");
        assert!(fields(&b, Some(&b.cards[0]), L)
            .unwrap_err()
            .contains("5 comma-separated"));
    }
}
