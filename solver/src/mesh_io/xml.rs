//! VTK XML unstructured grids (`.vtu`) through vtkio 0.7: points, cells and cell arrays in
//! every encoding VTK, ParaView and meshio write (ASCII, inline base64, appended raw or base64;
//! uncompressed, zlib, LZ4 or LZMA).
//!
//! vtkio does not read `<FieldData>`, where palpa (and anyone who wants ParaView to show them)
//! keeps the part names as the string array `part_names` (entry `i` names part id `i`), so that
//! one array is decoded here by hand, following the VTK XML file-format reference
//! (<https://docs.vtk.org/en/latest/vtk_file_formats/vtkxml_file_format.html>):
//!
//! - `format="ascii"`: the bytes of the strings as decimal numbers, each string ended by a 0;
//! - `format="binary"`: base64 of a header and the bytes (the header and the data may be
//!   encoded separately, so the text is decoded piece by piece at its `=` padding);
//! - `format="appended"`: the same at `offset` after the `_` of `<AppendedData>`, raw or base64;
//! - the header is `[n bytes]` uncompressed, or `[n blocks, block size, last block size,
//!   compressed size of each block]` for `compressor="vtkZLibDataCompressor"`,
//!   `vtkLZ4DataCompressor` or `vtkLZMADataCompressor`, each of `header_type` (UInt32 unless the
//!   file says UInt64) in the file's `byte_order`.

use super::{names_from, vtk_cells, RawMesh, PART_ARRAYS};
use base64::Engine;
use std::io::Read;
use std::path::Path;
use vtkio::model::{Attribute, DataSet, VertexNumbers, Vtk};

/// vtkio's error in words: it prints its XML parser's errors as Rust values
/// (`Deserialization error: InvalidXml(IllFormed(MissingEndTag("DataArray")))`).
fn xml_message(e: &vtkio::Error) -> String {
    let raw = e.to_string();
    let quoted = |key: &str| {
        let i = raw.find(key)? + key.len();
        let rest = &raw[i..];
        let a = rest.find('"')? + 1;
        let b = rest[a..].find('"')? + a;
        Some(rest[a..b].to_string())
    };
    if let Some(tag) = quoted("MissingEndTag(") {
        return format!("the file ends early or is cut off: the element <{tag}> is never closed");
    }
    if let (Some(want), Some(found)) = (quoted("expected:"), quoted("found:")) {
        return format!("malformed XML: </{found}> closes <{want}>");
    }
    for (key, what) in [
        ("UnclosedTag", "a tag"),
        ("UnclosedComment", "a comment"),
        ("UnclosedCData", "a CDATA section"),
        ("UnclosedPIOrXmlDecl", "the XML declaration"),
        ("UnclosedDoctype", "the DOCTYPE"),
        ("UnexpectedEof", "the document"),
    ] {
        if raw.contains(key) {
            return format!("the file ends early or is cut off: {what} is never closed");
        }
    }
    if raw.contains("expected struct VTKFile") {
        return "it does not begin with a <VTKFile> element: not VTK XML".into();
    }
    if raw.contains("NonDecodable") || raw.contains("Utf8") {
        return "the file is not text (it holds bytes that are not UTF-8 outside <AppendedData>)"
            .into();
    }
    // serde's own messages are words already; drop the Rust wrappers around them
    if let Some(i) = raw.find("Custom(\"") {
        let msg = raw[i + 8..].trim_end_matches(')').trim_end_matches('"');
        return format!("malformed VTK XML: {}", msg.replace("\\\"", "\""));
    }
    format!("malformed VTK XML ({raw})")
}

/// Read a `.vtu` file.
pub fn read(path: &Path) -> Result<RawMesh, String> {
    let p = path.display();
    let bytes = std::fs::read(path).map_err(|e| format!("{p}: cannot read: {e}"))?;
    let piece = vtkio_guarded(&p.to_string(), || load_piece(path))?;
    let pts: Vec<f64> = piece
        .points
        .cast_into()
        .ok_or_else(|| format!("{p}: the points are not numbers"))?;
    let mut raw = RawMesh {
        nodes: pts.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        ..Default::default()
    };
    let types: Vec<u8> = piece.cells.types.iter().map(|&t| t as u8).collect();
    let mut part = None;
    for name in PART_ARRAYS {
        let found = piece.data.cell.iter().find_map(|a| match a {
            Attribute::DataArray(d) if d.name == name => Some(d),
            _ => None,
        });
        if let Some(d) = found {
            let v: Vec<i64> = d
                .data
                .cast_into()
                .ok_or_else(|| format!("{p}: cell array `{name}` is not numeric"))?;
            if v.len() != types.len() {
                return Err(format!(
                    "{p}: cell array `{name}` has {} values for {} cells",
                    v.len(),
                    types.len()
                ));
            }
            part = Some(v);
            break;
        }
    }
    if part.is_none() {
        // vtkio drops a cell array whose length does not match the cells: a part array the file
        // declares but that did not come through is damaged, not absent (else every cell would
        // silently fall into one part).
        if let Some(name) = declared_cell_array(&bytes, &PART_ARRAYS) {
            return Err(format!(
                "{p}: cell array `{name}` could not be read as {} values, one per cell (the array is short, long or damaged)",
                types.len()
            ));
        }
    }
    match piece.cells.cell_verts {
        VertexNumbers::XML {
            connectivity,
            offsets,
        } => {
            if offsets.len() != types.len() {
                return Err(format!(
                    "{p}: {} cell offsets for {} cell types",
                    offsets.len(),
                    types.len()
                ));
            }
            let mut start = 0usize;
            let mut cells = Vec::with_capacity(offsets.len());
            for &end in &offsets {
                let end = end as usize;
                if end < start || end > connectivity.len() {
                    return Err(format!(
                        "{p}: cell offsets out of order or past the connectivity"
                    ));
                }
                cells.push(&connectivity[start..end]);
                start = end;
            }
            vtk_cells(&mut raw, &types, cells.into_iter(), part, path)?;
        }
        VertexNumbers::Legacy { .. } => return Err(format!("{p}: unexpected legacy cell layout")),
    }
    let names = field_strings(&bytes, "part_names").map_err(|e| format!("{p}: {e}"))?;
    raw.part_names = names_from(names);
    Ok(raw)
}

/// The grid's single piece, with its data loaded, as vtkio reads it.
fn load_piece(path: &Path) -> Result<vtkio::model::UnstructuredGridPiece, String> {
    let p = path.display();
    let vtk = Vtk::import(path)
        .map_err(|e| format!("{p}: not a readable VTK XML file: {}", xml_message(&e)))?;
    match vtk.data {
        DataSet::UnstructuredGrid { pieces, .. } => {
            if pieces.len() != 1 {
                return Err(format!(
                    "{p}: the grid has {} pieces; palpa reads single-piece files (in ParaView: Merge Blocks, then save)",
                    pieces.len()
                ));
            }
            pieces
                .into_iter()
                .next()
                .unwrap()
                .into_loaded_piece_data(Some(path))
                .map_err(|e| format!("{p}: {e}"))
        }
        _ => Err(format!("{p}: not an unstructured grid")),
    }
}

/// Run vtkio on a file: vtkio 0.7 slices compressed data by the sizes its block header states,
/// unchecked, and panics on a damaged header; that panic is this file's error (the panic
/// message is printed first, by the panic hook).
fn vtkio_guarded<T>(p: &str, f: impl FnOnce() -> Result<T, String>) -> Result<T, String> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).unwrap_or_else(|e| {
        let why = e
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| e.downcast_ref::<&str>().copied())
            .unwrap_or("a panic");
        Err(format!(
            "{p}: the file's data is damaged: the VTK XML reader (vtkio) failed on it ({why})"
        ))
    })
}

/// The first of `names` that the file's `<CellData>` declares as a `DataArray`, if any.
fn declared_cell_array<'a>(bytes: &[u8], names: &[&'a str]) -> Option<&'a str> {
    let head_end = find(bytes, b"<AppendedData").unwrap_or(bytes.len());
    let head = String::from_utf8_lossy(&bytes[..head_end]);
    let start = head.find("<CellData")?;
    let end = head[start..]
        .find("</CellData>")
        .map(|e| start + e)
        .unwrap_or(head.len());
    let section = &head[start..end];
    names.iter().copied().find(|n| {
        section.contains(&format!("Name=\"{n}\"")) || section.contains(&format!("Name='{n}'"))
    })
}

/// The `<FieldData>` string array `name` of a VTK XML file's bytes, or nothing.
pub fn field_strings(bytes: &[u8], name: &str) -> Result<Vec<String>, String> {
    let head_end = find(bytes, b"<AppendedData").unwrap_or(bytes.len());
    let head = String::from_utf8_lossy(&bytes[..head_end]);
    let Some(fd) = head.find("<FieldData") else {
        return Ok(Vec::new());
    };
    let fd_end = head[fd..]
        .find("</FieldData>")
        .map(|e| fd + e)
        .unwrap_or(head.len());
    let section = &head[fd..fd_end];
    let mut at = 0;
    let (attrs, body) = loop {
        let Some(s) = section[at..].find("Array").map(|s| at + s) else {
            return Ok(Vec::new());
        };
        let tag_end = section[s..]
            .find('>')
            .map(|e| s + e)
            .ok_or("unterminated tag")?;
        let attrs = &section[s..tag_end];
        at = tag_end;
        if attr(attrs, "Name").as_deref() == Some(name) {
            let body = if attrs.ends_with('/') {
                ""
            } else {
                let close = section[tag_end..].find('<').map(|e| tag_end + e);
                &section[tag_end + 1..close.unwrap_or(section.len())]
            };
            break (attrs.to_string(), body.to_string());
        }
    };
    if attr(&attrs, "type").as_deref() != Some("String") {
        return Err(format!("field data `{name}` must be a String array").into());
    }
    let file_tag_start = head.find("<VTKFile").ok_or("no <VTKFile> element")?;
    let file_tag = &head[file_tag_start..][..head[file_tag_start..].find('>').unwrap_or(0)];
    let enc = Encoding {
        header64: attr(file_tag, "header_type").as_deref() == Some("UInt64"),
        big_endian: attr(file_tag, "byte_order").as_deref() == Some("BigEndian"),
        compressor: attr(file_tag, "compressor").unwrap_or_default(),
    };
    let data = match attr(&attrs, "format").as_deref().unwrap_or("ascii") {
        "ascii" => body
            .split_whitespace()
            .map(|t| t.parse::<u8>().map_err(|_| format!("`{t}` is not a byte")))
            .collect::<Result<Vec<u8>, String>>()?,
        "binary" => enc.unpack(&base64_pieces(body.trim())?)?,
        "appended" => {
            let off: usize = attr(&attrs, "offset")
                .and_then(|o| o.trim().parse().ok())
                .ok_or_else(|| format!("appended `{name}` without an offset"))?;
            let ad = find(bytes, b"<AppendedData").ok_or("no <AppendedData>")?;
            let ad_tag_end = ad + find(&bytes[ad..], b">").ok_or("unterminated <AppendedData>")?;
            let ad_tag = String::from_utf8_lossy(&bytes[ad..ad_tag_end]).into_owned();
            let underscore =
                ad_tag_end + find(&bytes[ad_tag_end..], b"_").ok_or("no `_` in <AppendedData>")?;
            let start = underscore + 1 + off;
            if start > bytes.len() {
                return Err(format!("`{name}` offset past the end of the file"));
            }
            if attr(&ad_tag, "encoding").as_deref() == Some("base64") {
                // Up to the next array's offset, or the end of the appended data.
                let next = offsets(&head).into_iter().filter(|&o| o > off).min();
                let end = match next {
                    Some(n) => underscore + 1 + n,
                    None => start + find(&bytes[start..], b"<").unwrap_or(bytes.len() - start),
                };
                let text = String::from_utf8_lossy(&bytes[start..end.min(bytes.len())]);
                enc.unpack(&base64_pieces(text.trim())?)?
            } else {
                enc.unpack(&bytes[start..])?
            }
        }
        f => return Err(format!("unknown data format `{f}` of `{name}`")),
    };
    let mut names: Vec<String> = data
        .split(|&b| b == 0)
        .map(|s| String::from_utf8_lossy(s).into_owned())
        .collect();
    if data.last() == Some(&0) {
        names.pop();
    }
    Ok(names)
}

struct Encoding {
    header64: bool,
    big_endian: bool,
    compressor: String,
}

impl Encoding {
    fn word(&self, b: &[u8], k: usize) -> Result<usize, String> {
        let w = if self.header64 { 8 } else { 4 };
        let s = b
            .get(k * w..(k + 1) * w)
            .ok_or("data block shorter than its header")?;
        let mut v: u64 = 0;
        for i in 0..w {
            let byte = if self.big_endian { s[i] } else { s[w - 1 - i] };
            v = (v << 8) | byte as u64;
        }
        Ok(v as usize)
    }

    /// Header + data (possibly with bytes after it) -> the data's bytes.
    fn unpack(&self, b: &[u8]) -> Result<Vec<u8>, String> {
        let w = if self.header64 { 8 } else { 4 };
        if self.compressor.is_empty() {
            let n = self.word(b, 0)?;
            return b
                .get(w..w + n)
                .map(|s| s.to_vec())
                .ok_or_else(|| "data block shorter than its header says".into());
        }
        let nb = self.word(b, 0)?;
        let block = self.word(b, 1)?;
        let last = self.word(b, 2)?;
        let mut at = (3 + nb) * w;
        let mut out = Vec::new();
        for k in 0..nb {
            let cs = self.word(b, 3 + k)?;
            let chunk = b.get(at..at + cs).ok_or("compressed block past the data")?;
            at += cs;
            let size = if k + 1 == nb && last != 0 {
                last
            } else {
                block
            };
            // The header's block size is only a hint for the capacity: the decompressor stops
            // at the data's end, and a block that disagrees with it is reported below.
            let mut part = Vec::with_capacity(size.min(1 << 24));
            match self.compressor.as_str() {
                "vtkZLibDataCompressor" => {
                    flate2::read::ZlibDecoder::new(chunk)
                        .read_to_end(&mut part)
                        .map_err(|e| format!("zlib: {e}"))?;
                }
                "vtkLZ4DataCompressor" => {
                    part = lz4_flex::block::decompress(chunk, size)
                        .map_err(|e| format!("LZ4: {e}"))?;
                }
                "vtkLZMADataCompressor" => {
                    xz2::read::XzDecoder::new(chunk)
                        .read_to_end(&mut part)
                        .map_err(|e| format!("LZMA: {e}"))?;
                }
                c => return Err(format!("unknown compressor `{c}`")),
            }
            out.extend_from_slice(&part);
        }
        Ok(out)
    }
}

/// Decode base64 text that may be several padded encodings one after the other.
fn base64_pieces(text: &str) -> Result<Vec<u8>, String> {
    let clean: String = text.chars().filter(|c| !c.is_whitespace()).collect();
    let mut out = Vec::new();
    let mut rest = clean.as_str();
    while !rest.is_empty() {
        // A piece ends after its padding, or at the end.
        let mut end = rest.len();
        if let Some(eq) = rest.find('=') {
            end = eq + rest[eq..].chars().take_while(|&c| c == '=').count();
        }
        let piece = &rest[..end];
        let decoded = base64::engine::general_purpose::STANDARD
            .decode(piece)
            .map_err(|e| format!("bad base64: {e}"))?;
        out.extend_from_slice(&decoded);
        rest = &rest[end..];
    }
    Ok(out)
}

fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

/// The value of `key="..."` in a tag's text.
fn attr(tag: &str, key: &str) -> Option<String> {
    let mut from = 0;
    while let Some(i) = tag[from..].find(key).map(|i| from + i) {
        let before_ok = i == 0 || tag.as_bytes()[i - 1].is_ascii_whitespace();
        let rest = tag[i + key.len()..].trim_start();
        if before_ok {
            if let Some(r) = rest.strip_prefix('=') {
                let r = r.trim_start();
                let q = r.chars().next()?;
                if q == '"' || q == '\'' {
                    let v = &r[1..];
                    return v.find(q).map(|e| v[..e].to_string());
                }
            }
        }
        from = i + key.len();
    }
    None
}

/// Every `offset="..."` in the header.
fn offsets(head: &str) -> Vec<usize> {
    let mut out = Vec::new();
    let mut from = 0;
    while let Some(i) = head[from..].find(" offset=").map(|i| from + i) {
        if let Some(v) = attr(&head[i..], "offset") {
            if let Ok(o) = v.trim().parse() {
                out.push(o);
            }
        }
        from = i + 8;
    }
    out
}
