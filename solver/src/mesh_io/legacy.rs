//! VTK legacy unstructured grids (`.vtk`), ASCII or binary, file versions 2 to 5.1.
//!
//! Hand-written because vtkio 0.7.0-rc2's legacy parser refuses what VTK 9 and meshio 5 write:
//! field data between `DATASET` and `POINTS` (where VTK keeps a grid's field data, e.g. the
//! part names) and the `vtktypeint32`-style type names meshio gives field arrays. The format
//! (<https://docs.vtk.org/en/latest/vtk_file_formats/vtk_legacy_file_format.html>):
//!
//! ```text
//! # vtk DataFile Version 5.1
//! title
//! ASCII | BINARY                  (binary numbers are big-endian)
//! DATASET UNSTRUCTURED_GRID
//! [FIELD FieldData n  then n arrays `name components tuples type` and their values]
//! POINTS n type
//! CELLS n size                    (versions < 5: per cell `k i1 ... ik`, 32-bit in binary)
//! CELLS n+1 m, OFFSETS type, CONNECTIVITY type   (version 5: two arrays)
//! CELL_TYPES n
//! CELL_DATA n   then SCALARS name type [components] / LOOKUP_TABLE / FIELD ... / VECTORS ...
//! POINT_DATA n  (skipped)
//! ```
//!
//! `METADATA` blocks (text up to an empty line) are skipped wherever they appear. Strings in
//! binary field arrays carry VTK's length prefix (first byte `11xxxxxx`: 6-bit length, `10`: 14
//! bits, `01`: 30 bits, `00`: 62 bits); in ASCII files they come one per line, `%XX`-escaped.

use super::{names_from, vtk_cells, RawMesh, PART_ARRAYS};
use std::path::Path;

/// Read a legacy `.vtk` file.
pub fn read(path: &Path) -> Result<RawMesh, String> {
    let p = path.display();
    let bytes = std::fs::read(path).map_err(|e| format!("{p}: cannot read: {e}"))?;
    let mut c = Cursor {
        b: &bytes,
        at: 0,
        binary: false,
        line: 0,
    };
    parse(&mut c)
        .map_err(|e| format!("{p}:{}: {e}", c.line.max(1)))
        .and_then(|(points, types, cells, arrays, strings)| {
            let mut raw = RawMesh {
                nodes: points,
                ..Default::default()
            };
            let part = PART_ARRAYS
                .iter()
                .find_map(|n| arrays.iter().find(|(a, _)| a == n))
                .map(|(_, v)| v.clone());
            if let Some(v) = &part {
                if v.len() != types.len() {
                    return Err(format!(
                        "{p}: the part array has {} values for {} cells",
                        v.len(),
                        types.len()
                    ));
                }
            }
            vtk_cells(
                &mut raw,
                &types,
                cells.iter().map(|c| c.as_slice()),
                part,
                path,
            )?;
            raw.part_names = names_from(strings);
            Ok(raw)
        })
}

type Parsed = (
    Vec<[f64; 3]>,
    Vec<u8>,
    Vec<Vec<u64>>,
    Vec<(String, Vec<i64>)>,
    Vec<String>,
);

fn parse(c: &mut Cursor) -> Result<Parsed, String> {
    let head = c.line_raw()?;
    if !head.starts_with("# vtk DataFile") {
        return Err("not a VTK legacy file (no `# vtk DataFile Version` header)".into());
    }
    let _title = c.line_raw()?;
    match c.keyword_line()?.to_ascii_uppercase().as_str() {
        "ASCII" => c.binary = false,
        "BINARY" => c.binary = true,
        o => return Err(format!("expected ASCII or BINARY, got `{o}`")),
    }
    let ds = c.keyword_line()?;
    let w: Vec<&str> = ds.split_whitespace().collect();
    if w.len() != 2 || !w[0].eq_ignore_ascii_case("DATASET") {
        return Err(format!("expected `DATASET UNSTRUCTURED_GRID`, got `{ds}`"));
    }
    if !w[1].eq_ignore_ascii_case("UNSTRUCTURED_GRID") {
        return Err(format!(
            "the dataset is {}; palpa reads an UNSTRUCTURED_GRID of hexahedra",
            w[1]
        ));
    }
    let mut points: Option<Vec<[f64; 3]>> = None;
    let mut cells: Option<Vec<Vec<u64>>> = None;
    let mut types: Option<Vec<u8>> = None;
    let mut arrays = Vec::new();
    let mut strings = Vec::new();
    while let Some(l) = c.next_keyword_line()? {
        let w: Vec<String> = l.split_whitespace().map(String::from).collect();
        let kw = w[0].to_ascii_uppercase();
        match kw.as_str() {
            "FIELD" => {
                let k = count(&w, 2, "FIELD name n")?;
                field(c, k, None, &mut arrays, &mut strings)?;
            }
            "POINTS" => {
                let n = count(&w, 1, "POINTS n type")?;
                let ty = w.get(2).ok_or("POINTS without a type")?;
                let v = c.numbers(times(3, n)?, ty)?;
                points = Some(v.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect());
            }
            "CELLS" => {
                let n = count(&w, 1, "CELLS n size")?;
                let size = count(&w, 2, "CELLS n size")?;
                cells = Some(read_cells(c, n, size)?);
            }
            "CELL_TYPES" => {
                let n = count(&w, 1, "CELL_TYPES n")?;
                let v = c.numbers(n, "int")?;
                types = Some(v.iter().map(|&t| t as u8).collect());
            }
            "CELL_DATA" => {
                let n = count(&w, 1, "CELL_DATA n")?;
                attributes(c, n, Some(&mut arrays), &mut strings)?;
            }
            "POINT_DATA" => {
                let n = count(&w, 1, "POINT_DATA n")?;
                attributes(c, n, None, &mut strings)?;
            }
            "METADATA" => c.skip_metadata()?,
            o => return Err(format!("unexpected `{o}` in an unstructured grid")),
        }
    }
    let points = points.ok_or("no POINTS")?;
    let cells = cells.ok_or("no CELLS")?;
    let types = types.ok_or("no CELL_TYPES")?;
    if types.len() != cells.len() {
        return Err(format!(
            "{} CELL_TYPES for {} CELLS",
            types.len(),
            cells.len()
        ));
    }
    Ok((points, types, cells, arrays, strings))
}

/// `a * b` for array sizes, an error instead of an overflow.
fn times(a: usize, b: usize) -> Result<usize, String> {
    a.checked_mul(b)
        .ok_or_else(|| format!("an array of {a} x {b} values is larger than any file"))
}

fn count(w: &[String], k: usize, form: &str) -> Result<usize, String> {
    w.get(k)
        .and_then(|s| s.parse().ok())
        .ok_or_else(|| format!("expected `{form}`, got `{}`", w.join(" ")))
}

fn read_cells(c: &mut Cursor, n: usize, size: usize) -> Result<Vec<Vec<u64>>, String> {
    // Version 5: the next keyword is OFFSETS.
    let save = (c.at, c.line);
    let next = c.keyword_line()?;
    if next.to_ascii_uppercase().starts_with("OFFSETS") {
        let ty = next
            .split_whitespace()
            .nth(1)
            .ok_or("OFFSETS without a type")?
            .to_string();
        let off = c.numbers(n, &ty)?;
        let conn_line = c.keyword_line()?;
        let mut cw = conn_line.split_whitespace();
        if !cw
            .next()
            .is_some_and(|k| k.eq_ignore_ascii_case("CONNECTIVITY"))
        {
            return Err(format!("expected CONNECTIVITY, got `{conn_line}`"));
        }
        let ty = cw.next().ok_or("CONNECTIVITY without a type")?.to_string();
        let conn = c.numbers(size, &ty)?;
        let mut out = Vec::with_capacity(n.saturating_sub(1).min(conn.len()));
        for k in 1..n {
            let (a, b) = (off[k - 1] as usize, off[k] as usize);
            if a > b || b > conn.len() {
                return Err("cell offsets out of order or past the connectivity".into());
            }
            out.push(node_ids(&conn[a..b])?);
        }
        return Ok(out);
    }
    (c.at, c.line) = save;
    let v = c.numbers(size, "int")?;
    let mut out = Vec::with_capacity(n.min(v.len()));
    let mut i = 0;
    for _ in 0..n {
        let k = *v.get(i).ok_or("CELLS shorter than its size")? as usize;
        let s = v
            .get(i + 1..i + 1 + k)
            .ok_or("CELLS shorter than its size")?;
        out.push(node_ids(s)?);
        i += k + 1;
    }
    Ok(out)
}

/// Attribute sections of CELL_DATA / POINT_DATA (n tuples); keeps 1-component numeric arrays
/// when `keep` is given.
fn attributes(
    c: &mut Cursor,
    n: usize,
    mut keep: Option<&mut Vec<(String, Vec<i64>)>>,
    strings: &mut Vec<String>,
) -> Result<(), String> {
    loop {
        let save = (c.at, c.line);
        let Some(l) = c.next_keyword_line()? else {
            return Ok(());
        };
        let w: Vec<String> = l.split_whitespace().map(String::from).collect();
        match w[0].to_ascii_uppercase().as_str() {
            "SCALARS" => {
                let name = w.get(1).ok_or("SCALARS without a name")?.clone();
                let ty = w.get(2).ok_or("SCALARS without a type")?.clone();
                let comps: usize = w.get(3).and_then(|s| s.parse().ok()).unwrap_or(1);
                let save2 = (c.at, c.line);
                let lt = c.keyword_line()?;
                if !lt.to_ascii_uppercase().starts_with("LOOKUP_TABLE") {
                    (c.at, c.line) = save2;
                }
                let v = c.numbers(n * comps, &ty)?;
                if let (Some(k), 1) = (keep.as_deref_mut(), comps) {
                    k.push((name, v.iter().map(|&x| x as i64).collect()));
                }
            }
            "LOOKUP_TABLE" => {
                let size = count(&w, 2, "LOOKUP_TABLE name size")?;
                if c.binary {
                    c.numbers(4 * size, "unsigned_char")?;
                } else {
                    c.numbers(4 * size, "float")?;
                }
            }
            "COLOR_SCALARS" => {
                let m = count(&w, 2, "COLOR_SCALARS name n")?;
                c.numbers(
                    times(n, m)?,
                    if c.binary { "unsigned_char" } else { "float" },
                )?;
            }
            "VECTORS" | "NORMALS" => {
                c.numbers(times(3, n)?, w.get(2).ok_or("no type")?)?;
            }
            "TENSORS" | "TENSORS6" => {
                let k = if w[0].eq_ignore_ascii_case("TENSORS6") {
                    6
                } else {
                    9
                };
                c.numbers(times(k, n)?, w.get(2).ok_or("no type")?)?;
            }
            "TEXTURE_COORDINATES" => {
                let d = count(&w, 2, "TEXTURE_COORDINATES name dim type")?;
                c.numbers(times(d, n)?, w.get(3).ok_or("no type")?)?;
            }
            "FIELD" => {
                let k = count(&w, 2, "FIELD name n")?;
                let mut dummy = Vec::new();
                let sink = match keep.as_deref_mut() {
                    Some(k) => k,
                    None => &mut dummy,
                };
                field(c, k, Some(n), sink, strings)?;
            }
            "METADATA" => c.skip_metadata()?,
            _ => {
                (c.at, c.line) = save;
                return Ok(());
            }
        }
    }
}

/// `k` field arrays; numeric 1-component arrays of `tuples` tuples go to `arrays` (for
/// dataset-level field data `tuples` is None and nothing numeric is kept); the string array
/// `part_names` goes to `strings`.
fn field(
    c: &mut Cursor,
    k: usize,
    tuples: Option<usize>,
    arrays: &mut Vec<(String, Vec<i64>)>,
    strings: &mut Vec<String>,
) -> Result<(), String> {
    for _ in 0..k {
        let mut l = c.keyword_line()?;
        while l.eq_ignore_ascii_case("METADATA") {
            c.skip_metadata()?;
            l = c.keyword_line()?;
        }
        let w: Vec<String> = l.split_whitespace().map(String::from).collect();
        if w.len() < 4 {
            return Err(format!(
                "expected a field array `name components tuples type`, got `{l}`"
            ));
        }
        let comps = count(&w, 1, "name components tuples type")?;
        let nt = count(&w, 2, "name components tuples type")?;
        let ty = w[3].to_ascii_lowercase();
        if ty == "string" || ty == "utf8_string" {
            let s = c.strings(comps * nt)?;
            if w[0] == "part_names" {
                *strings = s;
            }
        } else {
            let v = c.numbers(comps * nt, &ty)?;
            if comps == 1 && Some(nt) == tuples {
                arrays.push((w[0].clone(), v.iter().map(|&x| x as i64).collect()));
            }
        }
    }
    Ok(())
}

struct Cursor<'a> {
    b: &'a [u8],
    at: usize,
    binary: bool,
    line: usize,
}

impl<'a> Cursor<'a> {
    /// The next line as it is (header lines may be blank or hold anything).
    fn line_raw(&mut self) -> Result<String, String> {
        if self.at >= self.b.len() {
            return Err("unexpected end of file".into());
        }
        let end = self.b[self.at..]
            .iter()
            .position(|&x| x == b'\n')
            .map(|e| self.at + e)
            .unwrap_or(self.b.len());
        let s = String::from_utf8_lossy(&self.b[self.at..end])
            .trim_end()
            .to_string();
        self.at = (end + 1).min(self.b.len());
        self.line += 1;
        Ok(s)
    }

    /// The next non-blank line, or None at the end of the file.
    fn next_keyword_line(&mut self) -> Result<Option<String>, String> {
        while self.at < self.b.len() {
            let l = self.line_raw()?;
            let t = l.trim();
            if !t.is_empty() {
                return Ok(Some(t.to_string()));
            }
        }
        Ok(None)
    }

    fn keyword_line(&mut self) -> Result<String, String> {
        self.next_keyword_line()?
            .ok_or_else(|| "unexpected end of file".into())
    }

    fn skip_metadata(&mut self) -> Result<(), String> {
        while self.at < self.b.len() {
            if self.line_raw()?.trim().is_empty() {
                break;
            }
        }
        Ok(())
    }

    /// `n` numbers of VTK type `ty`.
    fn numbers(&mut self, n: usize, ty: &str) -> Result<Vec<f64>, String> {
        let (size, kind) = type_of(ty)?;
        if self.binary {
            let len = n.checked_mul(size).ok_or("array too large")?;
            let s = self
                .b
                .get(self.at..self.at.saturating_add(len))
                .ok_or_else(|| format!("file ends inside a binary array of {n} `{ty}`"))?;
            let v = s.chunks_exact(size).map(|w| decode(w, kind)).collect();
            self.at += len;
            // The newline VTK writes after binary data.
            if self.b.get(self.at) == Some(&b'\n') {
                self.at += 1;
            }
            self.line += 1;
            Ok(v)
        } else {
            // A count larger than the rest of the file is caught when the numbers run out; the
            // capacity never exceeds what the file can hold.
            let mut v = Vec::with_capacity(n.min(self.b.len().saturating_sub(self.at)));
            while v.len() < n {
                self.skip_space();
                if self.at >= self.b.len() {
                    return Err(format!("file ends after {} of {n} numbers", v.len()));
                }
                let end = self.b[self.at..]
                    .iter()
                    .position(|x| x.is_ascii_whitespace())
                    .map(|e| self.at + e)
                    .unwrap_or(self.b.len());
                let t = String::from_utf8_lossy(&self.b[self.at..end]);
                let x: f64 = t
                    .parse()
                    .map_err(|_| format!("`{t}` is not a number (expected {n} `{ty}`)"))?;
                v.push(x);
                self.at = end;
            }
            // Finish the line the last number is on.
            while self.at < self.b.len() && self.b[self.at] != b'\n' {
                self.at += 1;
            }
            if self.at < self.b.len() {
                self.at += 1;
                self.line += 1;
            }
            Ok(v)
        }
    }

    fn skip_space(&mut self) {
        while self.at < self.b.len() && self.b[self.at].is_ascii_whitespace() {
            if self.b[self.at] == b'\n' {
                self.line += 1;
            }
            self.at += 1;
        }
    }

    fn strings(&mut self, n: usize) -> Result<Vec<String>, String> {
        let mut out = Vec::with_capacity(n.min(self.b.len().saturating_sub(self.at)));
        if self.binary {
            for _ in 0..n {
                let b0 = *self
                    .b
                    .get(self.at)
                    .ok_or("file ends inside a string array")?;
                let (bytes, mask) = match b0 >> 6 {
                    3 => (1, 0x3f_u64),
                    2 => (2, 0x3fff),
                    1 => (4, 0x3fff_ffff),
                    _ => (8, 0x3fff_ffff_ffff_ffff),
                };
                let h = self
                    .b
                    .get(self.at..self.at + bytes)
                    .ok_or("file ends inside a string array")?;
                let len = (h.iter().fold(0u64, |a, &x| (a << 8) | x as u64) & mask) as usize;
                self.at += bytes;
                let s = self
                    .b
                    .get(self.at..self.at + len)
                    .ok_or("file ends inside a string array")?;
                out.push(String::from_utf8_lossy(s).into_owned());
                self.at += len;
            }
            if self.b.get(self.at) == Some(&b'\n') {
                self.at += 1;
            }
        } else {
            for _ in 0..n {
                out.push(unescape(&self.line_raw()?));
            }
        }
        Ok(out)
    }
}

#[derive(Clone, Copy)]
enum Kind {
    Int,
    Uint,
    Float,
}

fn type_of(ty: &str) -> Result<(usize, Kind), String> {
    Ok(match ty.to_ascii_lowercase().as_str() {
        "unsigned_char" | "vtktypeuint8" => (1, Kind::Uint),
        "char" | "signed_char" | "vtktypeint8" => (1, Kind::Int),
        "unsigned_short" | "vtktypeuint16" => (2, Kind::Uint),
        "short" | "vtktypeint16" => (2, Kind::Int),
        "unsigned_int" | "vtktypeuint32" => (4, Kind::Uint),
        "int" | "vtktypeint32" | "vtkidtype" => (4, Kind::Int),
        "unsigned_long" | "vtktypeuint64" | "unsigned_long_long" => (8, Kind::Uint),
        "long" | "vtktypeint64" | "long_long" => (8, Kind::Int),
        "float" | "vtktypefloat32" => (4, Kind::Float),
        "double" | "vtktypefloat64" => (8, Kind::Float),
        o => return Err(format!("unsupported data type `{o}`")),
    })
}

fn decode(w: &[u8], kind: Kind) -> f64 {
    let u = w.iter().fold(0u64, |a, &x| (a << 8) | x as u64);
    let bits = 8 * w.len() as u32;
    match kind {
        Kind::Uint => u as f64,
        Kind::Int => {
            let shift = 64 - bits;
            (((u << shift) as i64) >> shift) as f64
        }
        Kind::Float if w.len() == 4 => f32::from_bits(u as u32) as f64,
        Kind::Float => f64::from_bits(u),
    }
}

/// Node ids of one cell: whole, non-negative numbers (a negative or fractional id is an error,
/// not a node the cast would invent).
fn node_ids(v: &[f64]) -> Result<Vec<u64>, String> {
    v.iter()
        .map(|&x| {
            if x >= 0.0 && x.fract() == 0.0 && x < u64::MAX as f64 {
                Ok(x as u64)
            } else {
                Err(format!(
                    "a cell lists the node id {x}, not a whole non-negative number"
                ))
            }
        })
        .collect()
}

/// VTK escapes characters in ASCII strings as `%XX`.
fn unescape(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            let hex = |c: u8| (c as char).to_digit(16);
            if let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

#[cfg(test)]
mod tests {
    #[test]
    fn unescape_decodes_hex_and_leaves_anything_else() {
        assert_eq!(super::unescape("liver%20left"), "liver left");
        assert_eq!(super::unescape("end%41"), "endA");
        // A `%` before non-ASCII text or at the end is kept as it is (it used to panic).
        assert_eq!(super::unescape("%a\u{e9}x"), "%a\u{e9}x");
        assert_eq!(super::unescape("50%"), "50%");
    }
}
