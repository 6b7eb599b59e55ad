//! The keyword format, line by line (LS-DYNA Keyword User's Manual, vol. I, "General card
//! format"): a line starting with `*` opens a keyword, a line starting with `$` is a comment,
//! every other line is a card of the current keyword. Cards are read by columns (fixed format),
//! or split at commas when the line has one (free format).
//!
//! Field widths: the standard format gives each field 10 columns (8 for the ids and node
//! numbers of `*NODE` and `*ELEMENT_*`, 16 for `*NODE` coordinates, 20 for `*DEFINE_CURVE`
//! points); `*KEYWORD LONG=Y` (or a keyword written with a trailing `+`) makes every field 20
//! columns wide, `*KEYWORD I10=Y` (or a trailing `%`) makes the 8-column fields 10 wide, and a
//! trailing `-` returns one keyword to the standard format (on `*INCLUDE`, the included file).
//!
//! `*INCLUDE` reads another file in place (its name relative to the including file, then to the
//! `*INCLUDE_PATH` directories); `*END` ends the file it is in. A comment line that starts with
//! `$palpa:` carries data that only palpa reads (see [`crate::annotate`]); LS-DYNA skips it.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Where a line is: file and 1-based line number.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Loc {
    /// The file.
    pub file: Arc<PathBuf>,
    /// Line number (1-based).
    pub line: usize,
}

impl std::fmt::Display for Loc {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}", self.file.display(), self.line)
    }
}

/// Column widths of a keyword's cards.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// 8/10/16/20 columns as the manual lists them.
    Standard,
    /// Every field 20 columns (`LONG=Y`, `+`).
    Long,
    /// Fields narrower than 10 widened to 10 (`I10=Y`, `%`).
    I10,
}

impl Format {
    /// The width of a field whose standard width is `w`.
    pub fn width(self, w: usize) -> usize {
        match self {
            Format::Standard => w,
            Format::Long => 20,
            Format::I10 => w.max(10),
        }
    }
}

/// One card (data line) of a keyword.
#[derive(Clone, Debug)]
pub struct Card {
    /// The text (trailing `\r` removed).
    pub text: String,
    /// Where it is.
    pub at: Loc,
}

/// A keyword with its cards.
#[derive(Clone, Debug)]
pub struct Block {
    /// The keyword, upper case, without `*`, format suffix or options (e.g. `MAT_ELASTIC_TITLE`).
    pub name: String,
    /// The keyword line as written.
    pub line: String,
    /// Column widths of its cards.
    pub format: Format,
    /// Where the keyword line is.
    pub at: Loc,
    /// Its cards, in order (blank lines included: a blank card takes every default).
    pub cards: Vec<Card>,
    /// `$palpa:` comments inside the keyword: (where, text after `$palpa:`).
    pub palpa: Vec<(Loc, String)>,
    /// The `*PARAMETER` values defined before this keyword.
    pub params: Arc<Params>,
}

/// Parameters in effect: upper-case name -> (value text, where it was defined), see
/// [`crate::params`].
pub type Params = BTreeMap<String, (String, Loc)>;

/// Parse a real as LS-DYNA does (Fortran list input: `1.5`, `1.`, `.5`, `1.5e-3`, `1.5d-3`);
/// `None` for a blank, malformed or non-finite field.
pub fn parse_real(s: &str) -> Option<f64> {
    let t = s.trim();
    if t.is_empty() {
        return None;
    }
    let t = t.replace(['d', 'D'], "e");
    t.parse::<f64>().ok().filter(|v| v.is_finite())
}

/// Every keyword of a deck and its included files, in reading order.
#[derive(Clone, Debug, Default)]
pub struct Lexed {
    /// The keywords.
    pub blocks: Vec<Block>,
    /// The files read (the deck first).
    pub files: Vec<PathBuf>,
    /// `$palpa:` comments before the first keyword of the deck.
    pub header_palpa: Vec<(Loc, String)>,
}

/// Read a deck and its includes (the `*PARAMETER` values are given to the blocks after,
/// by [`crate::params::expand`]).
pub fn read(path: &Path) -> Result<Lexed, String> {
    let mut out = Lexed::default();
    let mut search: Vec<PathBuf> = Vec::new();
    read_file(path, None, &mut out, &mut search, Format::Standard, 0)?;
    Ok(out)
}

/// Split the keyword line into (name, format override, rest).
fn keyword_name(line: &str) -> (String, Option<Format>, String) {
    let body = line[1..].trim_end();
    let (tok, rest) = match body.find(char::is_whitespace) {
        Some(i) => (&body[..i], body[i..].trim()),
        None => (body, ""),
    };
    let mut name = tok.to_ascii_uppercase();
    let mut fmt = None;
    let mut rest = rest.to_string();
    for (suffix, f) in [
        ('+', Format::Long),
        ('%', Format::I10),
        ('-', Format::Standard),
    ] {
        if name.len() > 1 && name.ends_with(suffix) {
            name.pop();
            fmt = Some(f);
        } else if rest == suffix.to_string() {
            rest.clear();
            fmt = Some(f);
        }
    }
    (name, fmt, rest)
}

fn read_file(
    path: &Path,
    from: Option<&Loc>,
    out: &mut Lexed,
    search: &mut Vec<PathBuf>,
    mut deck_format: Format,
    depth: usize,
) -> Result<Format, String> {
    let at = |from: Option<&Loc>| from.map(|l| format!("{l}: ")).unwrap_or_default();
    if depth > 20 {
        return Err(format!(
            "{}*INCLUDE nested more than 20 deep (does a file include itself?)",
            at(from)
        ));
    }
    let bytes = std::fs::read(path).map_err(|e| {
        format!(
            "{}cannot read the deck file {}: {e}",
            at(from),
            path.display()
        )
    })?;
    let text = String::from_utf8_lossy(&bytes);
    let file = Arc::new(path.to_path_buf());
    out.files.push(path.to_path_buf());
    let dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    let mut current: Option<Block> = None;
    let mut lines = text.split('\n').enumerate().peekable();
    let flush = |cur: &mut Option<Block>, out: &mut Lexed| {
        if let Some(b) = cur.take() {
            out.blocks.push(b);
        }
    };
    while let Some((i, raw)) = lines.next() {
        let line = raw.strip_suffix('\r').unwrap_or(raw);
        let loc = Loc {
            file: file.clone(),
            line: i + 1,
        };
        if let Some(rest) = line.strip_prefix('$') {
            let rest = rest.trim_start();
            if let Some(p) = rest
                .strip_prefix("palpa:")
                .or_else(|| rest.strip_prefix("PALPA:"))
            {
                match current.as_mut() {
                    Some(b) => b.palpa.push((loc, p.trim().to_string())),
                    None if depth == 0 => out.header_palpa.push((loc, p.trim().to_string())),
                    None => {}
                }
            }
            continue;
        }
        if line.starts_with('*') {
            flush(&mut current, out);
            let (name, fmt, rest) = keyword_name(line);
            match name.as_str() {
                "KEYWORD" => {
                    let opts = rest.to_ascii_uppercase().replace(' ', "");
                    if opts.contains("LONG=Y") || opts.contains("LONG=S") {
                        deck_format = Format::Long;
                    } else if opts.contains("I10=Y") {
                        deck_format = Format::I10;
                    }
                    continue;
                }
                "END" => break,
                "INCLUDE" | "INCLUDE_PATH" | "INCLUDE_PATH_RELATIVE" => {
                    // The file name: the next non-comment line(s); a trailing ` +` continues it.
                    let mut fname = String::new();
                    let mut name_loc = loc.clone();
                    for (j, l) in lines.by_ref() {
                        let l = l.strip_suffix('\r').unwrap_or(l);
                        if l.starts_with('$') {
                            continue;
                        }
                        name_loc = Loc {
                            file: file.clone(),
                            line: j + 1,
                        };
                        let t = l.trim_end();
                        if let Some(t) = t.strip_suffix(" +") {
                            fname.push_str(t.trim());
                            continue;
                        }
                        fname.push_str(t.trim());
                        break;
                    }
                    if fname.len() > 1 && fname.starts_with('"') && fname.ends_with('"') {
                        fname = fname[1..fname.len() - 1].to_string();
                    }
                    if fname.is_empty() {
                        return Err(format!("{loc}: *{name} names no file or directory"));
                    }
                    let p = PathBuf::from(&fname);
                    if name != "INCLUDE" {
                        search.push(if p.is_relative() { dir.join(p) } else { p });
                        continue;
                    }
                    let candidates: Vec<PathBuf> = if p.is_absolute() {
                        vec![p.clone()]
                    } else {
                        std::iter::once(dir.join(&p))
                            .chain(search.iter().map(|d| d.join(&p)))
                            .chain(std::iter::once(p.clone()))
                            .collect()
                    };
                    let Some(found) = candidates.iter().find(|c| c.is_file()).cloned() else {
                        return Err(format!(
                            "{name_loc}: *INCLUDE: file `{fname}` not found (looked in {})",
                            candidates
                                .iter()
                                .map(|c| c.display().to_string())
                                .collect::<Vec<_>>()
                                .join(", ")
                        ));
                    };
                    read_file(
                        &found,
                        Some(&name_loc),
                        out,
                        search,
                        fmt.unwrap_or(deck_format),
                        depth + 1,
                    )?;
                    continue;
                }
                _ => {}
            }
            current = Some(Block {
                name,
                line: line.trim_end().to_string(),
                format: fmt.unwrap_or(deck_format),
                at: loc,
                cards: Vec::new(),
                palpa: Vec::new(),
                params: Default::default(),
            });
            continue;
        }
        match current.as_mut() {
            Some(b) => b.cards.push(Card {
                text: line.to_string(),
                at: loc,
            }),
            None => {
                if !line.trim().is_empty() {
                    return Err(format!(
                        "{loc}: data before the first keyword: `{}` (a keyword line starts with `*`, a comment with `$`)",
                        line.trim()
                    ));
                }
            }
        }
    }
    flush(&mut current, out);
    Ok(deck_format)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keywords_formats_comments_and_includes() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("mesh.k"),
            "*NODE\n       1             0.0             0.0             0.0\n*END\n*NODE\nignored\n",
        )
        .unwrap();
        std::fs::write(
            dir.path().join("main.k"),
            "$ a deck\n*KEYWORD LONG=Y\n*TITLE\nblock\n*INCLUDE\nmesh.k\n*PART\n$palpa: x = 1\nblock\n*NODE -\n\n*END\n*NODE\n",
        )
        .unwrap();
        let l = read(&dir.path().join("main.k")).unwrap();
        let names: Vec<&str> = l.blocks.iter().map(|b| b.name.as_str()).collect();
        assert_eq!(names, ["TITLE", "NODE", "PART", "NODE"]);
        assert_eq!(l.blocks[0].format, Format::Long);
        assert_eq!(l.blocks[1].format, Format::Long);
        assert_eq!(l.blocks[1].cards.len(), 1);
        assert_eq!(l.blocks[1].at.line, 1);
        assert!(l.blocks[1].at.file.ends_with("mesh.k"));
        assert_eq!(l.blocks[2].palpa[0].1, "x = 1");
        assert_eq!(l.blocks[3].format, Format::Standard);
        assert_eq!(l.blocks[3].cards.len(), 1);
        let e = {
            std::fs::write(dir.path().join("bad.k"), "*INCLUDE\nnope.k\n").unwrap();
            read(&dir.path().join("bad.k")).unwrap_err()
        };
        assert!(e.contains("bad.k:2") && e.contains("nope.k"), "{e}");
    }
}
