//! Gmsh meshes (`.msh`, format 4.1, ASCII or binary) through the mshio crate.
//!
//! - 8-node hexahedra (Gmsh type 5, the node order of VTK_HEXAHEDRON) are the elements; other
//!   volume elements (tetrahedra, prisms, pyramids, second-order cells) are refused by the
//!   common check.
//! - A hexahedron's part is the physical volume of its geometric volume, named from
//!   `$PhysicalNames` (or `physical_<tag>`); a volume in no physical group (a file saved with
//!   `Mesh.SaveAll`) is the part `volume_<tag>`. A volume in two physical volumes is refused.
//! - Elements on physical surfaces, curves and points make node sets of the same names
//!   (`physical_<dim>_<tag>` when unnamed), e.g. a `bottom` surface to fix.
//!
//! mshio reads the `$Entities`, `$Nodes` and `$Elements` sections; `$PhysicalNames`, which it
//! skips, is read here (a count, then lines `dimension tag "name"`, ASCII in binary files too).
//! Files of format 2.2 are refused with the Gmsh option that writes 4.1. Where node tags are
//! contiguous mshio gives them in file order, which is how Gmsh numbers them.
//!
//! Checked here before mshio sees the file, since mshio 0.4 panics on them: the `$MeshFormat`
//! line's file type (0 or 1) and data size (4 or 8; it reads no other), and the counts of the
//! `$Nodes` and `$Elements` section headers (it subtracts 1 from them unchecked).

use super::RawMesh;
use mshio::ElementType;
use std::collections::BTreeMap;
use std::path::Path;

/// A file as mshio reads it: node tags `u64`, entity tags `i32`, coordinates `f64`.
type Msh = mshio::MshFile<u64, i32, f64>;

/// Read a `.msh` file.
pub fn read(path: &Path) -> Result<RawMesh, String> {
    let p = path.display();
    let bytes = std::fs::read(path).map_err(|e| format!("{p}: cannot read: {e}"))?;
    check_header(path, &bytes)?;
    let msh = mshio::parse_msh_bytes(&bytes).map_err(|e| {
        let text = e.to_string();
        let short: Vec<&str> = text
            .lines()
            .take_while(|l| !l.starts_with("Hex dump"))
            .map(str::trim)
            .collect();
        format!("{p}: cannot parse the Gmsh file: {}", short.join(" "))
    })?;
    let names = physical_names(&bytes).map_err(|e| format!("{p}: $PhysicalNames: {e}"))?;
    let groups = entity_groups(path, &msh)?;
    let mut raw = RawMesh::default();
    let index = read_nodes(path, &msh, &mut raw)?;
    let Some(elements) = &msh.data.elements else {
        return Ok(raw);
    };
    let blocks = Blocks {
        path,
        names,
        groups,
        index,
    };
    let mut part = Vec::new();
    for b in &elements.element_blocks {
        blocks.read(b, &mut raw, &mut part)?;
    }
    raw.hex_part = Some(part);
    Ok(raw)
}

/// What is checked before mshio sees the file: a `$MeshFormat` section of version 4.1 with an
/// encoding mshio reads, and `$Nodes` and `$Elements` headers that do not state 0 entries.
fn check_header(path: &Path, bytes: &[u8]) -> Result<(), String> {
    let p = path.display();
    let version = format_version(bytes)
        .ok_or_else(|| format!("{p}: not a Gmsh file (no `$MeshFormat` section)"))?;
    if version != "4.1" {
        return Err(format!(
            "{p}: Gmsh format {version}; palpa reads format 4.1 (Gmsh's default; in Gmsh set \
             `Mesh.MshFileVersion = 4.1` or use File > Export > Version 4 ASCII)"
        ));
    }
    let format = mesh_format(bytes).map_err(|e| format!("{p}: $MeshFormat: {e}"))?;
    check_section_counts(bytes, &format).map_err(|e| format!("{p}: {e}"))
}

/// `$Entities`: the physical tags of each geometric entity, by (dimension, tag); a tag whose
/// absolute value does not fit is an error.
fn entity_groups(path: &Path, msh: &Msh) -> Result<BTreeMap<(i32, i32), Vec<i32>>, String> {
    let p = path.display();
    let mut groups: BTreeMap<(i32, i32), Vec<i32>> = BTreeMap::new();
    if let Some(ent) = &msh.data.entities {
        let points = ent.points.iter().map(|e| (0, e.tag, &e.physical_tags));
        let curves = ent.curves.iter().map(|e| (1, e.tag, &e.physical_tags));
        let surfaces = ent.surfaces.iter().map(|e| (2, e.tag, &e.physical_tags));
        let volumes = ent.volumes.iter().map(|e| (3, e.tag, &e.physical_tags));
        for (dim, tag, phys) in points.chain(curves).chain(surfaces).chain(volumes) {
            let tags = phys
                .iter()
                .map(|t| {
                    t.checked_abs().ok_or_else(|| {
                        format!(
                            "{p}: $Entities: the {} {tag} has the physical tag {t}, out of range",
                            ["point", "curve", "surface", "volume"][dim]
                        )
                    })
                })
                .collect::<Result<_, _>>()?;
            groups.insert((dim as i32, tag), tags);
        }
    }
    Ok(groups)
}

/// `$Nodes`: the nodes and their tags into `raw`; returns each tag's node index. A tag given
/// twice is an error.
fn read_nodes(path: &Path, msh: &Msh, raw: &mut RawMesh) -> Result<BTreeMap<u64, u32>, String> {
    let p = path.display();
    let mut index: BTreeMap<u64, u32> = BTreeMap::new();
    if let Some(nodes) = &msh.data.nodes {
        let mut next_tag = nodes.min_node_tag;
        for (k, b) in nodes.node_blocks.iter().enumerate() {
            let tags = block_tags(path, b, k, nodes.min_node_tag, &mut next_tag)?;
            for (n, tag) in b.nodes.iter().zip(tags) {
                if index.insert(tag, raw.nodes.len() as u32).is_some() {
                    return Err(format!("{p}: node {tag} is given twice"));
                }
                raw.nodes.push([n.x, n.y, n.z]);
                raw.node_ids.push(tag as i64);
            }
        }
    }
    Ok(index)
}

/// The node tags of node block `k` (0-based): the block's own, or contiguous from `next_tag`
/// (which moves past them), counted from `min_tag` in the message when they overflow.
fn block_tags(
    path: &Path,
    b: &mshio::NodeBlock<u64, i32, f64>,
    k: usize,
    min_tag: u64,
    next_tag: &mut u64,
) -> Result<Vec<u64>, String> {
    let p = path.display();
    Ok(match &b.node_tags {
        Some(map) => {
            // mshio maps tag -> index: a tag given twice in the block keeps one index
            if map.len() != b.nodes.len() {
                return Err(format!(
                    "{p}: $Nodes: node block {} gives a node tag twice",
                    k + 1
                ));
            }
            let mut t = vec![0u64; b.nodes.len()];
            for (&tag, &i) in map {
                t[i] = tag;
            }
            t
        }
        None => {
            let end = next_tag
                .checked_add(b.nodes.len() as u64)
                .ok_or_else(|| format!("{p}: $Nodes: node tags from {min_tag} run past 2^64"))?;
            let t = (*next_tag..end).collect();
            *next_tag = end;
            t
        }
    })
}

/// What the element blocks are read against: the file (for messages), the physical names,
/// the physical tags of each geometric entity, and the node index of each node tag.
struct Blocks<'a> {
    path: &'a Path,
    names: BTreeMap<(i32, i32), String>,
    groups: BTreeMap<(i32, i32), Vec<i32>>,
    index: BTreeMap<u64, u32>,
}

impl Blocks<'_> {
    /// The name of physical group `tag` of dimension `dim`: from `$PhysicalNames`, else
    /// `physical_<tag>` (volumes) or `physical_<dim>_<tag>`.
    fn physical(&self, dim: i32, tag: i32) -> String {
        self.names
            .get(&(dim, tag))
            .cloned()
            .unwrap_or_else(|| match dim {
                3 => format!("physical_{tag}"),
                _ => format!("physical_{dim}_{tag}"),
            })
    }

    /// The index of node `k` of element `e`; an error if the file does not define it.
    fn node(&self, e: &mshio::Element<u64>, k: usize) -> Result<u32, String> {
        self.index.get(&e.nodes[k]).copied().ok_or_else(|| {
            format!(
                "{}: element {} refers to node {}, which the file does not define",
                self.path.display(),
                e.element_tag,
                e.nodes[k]
            )
        })
    }

    /// One element block: hexahedra of a volume (with their part keys into `part`), other
    /// volume cells counted, lower-dimensional cells counted and their nodes put in the node
    /// sets of their entity's physical groups.
    fn read(
        &self,
        b: &mshio::ElementBlock<u64, i32>,
        raw: &mut RawMesh,
        part: &mut Vec<i64>,
    ) -> Result<(), String> {
        let (dim, etag) = (b.entity_dim, b.entity_tag);
        let phys = self.groups.get(&(dim, etag)).cloned().unwrap_or_default();
        if dim == 3 {
            if b.element_type != ElementType::Hex8 {
                *raw.other_volume.entry(kind(b.element_type)).or_default() += b.elements.len();
                return Ok(());
            }
            let key = self.part_key(etag, &phys, raw)?;
            for e in &b.elements {
                let mut h = [0u32; 8];
                for (k, slot) in h.iter_mut().enumerate() {
                    *slot = self.node(e, k)?;
                }
                raw.hexes.push(h);
                raw.hex_labels.push(format!("element {}", e.element_tag));
                part.push(key);
            }
        } else {
            *raw.other_lower.entry(kind(b.element_type)).or_default() += b.elements.len();
            for &t in &phys {
                let set = raw.node_sets.entry(self.physical(dim, t)).or_default();
                for e in &b.elements {
                    for k in 0..e.nodes.len() {
                        set.push(self.node(e, k)?);
                    }
                }
            }
        }
        Ok(())
    }

    /// The part key of the hexahedra of geometric volume `etag` in the physical volumes
    /// `phys`, its name put in `raw`: the physical volume, or `-etag` (`volume_<etag>`) for a
    /// volume in none; an error for a volume in several.
    fn part_key(&self, etag: i32, phys: &[i32], raw: &mut RawMesh) -> Result<i64, String> {
        Ok(match phys {
            [] => {
                raw.part_names
                    .insert(-(etag as i64), format!("volume_{etag}"));
                -(etag as i64)
            }
            [t] => {
                raw.part_names.insert(*t as i64, self.physical(3, *t));
                *t as i64
            }
            many => {
                return Err(format!(
                    "{}: geometric volume {etag} belongs to {} physical volumes ({}); \
                     palpa needs one part per hexahedron",
                    self.path.display(),
                    many.len(),
                    many.iter()
                        .map(|&t| self.physical(3, t))
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
            }
        })
    }
}

/// Gmsh element kinds in the words of the messages.
fn kind(t: ElementType) -> String {
    use ElementType::*;
    match t {
        Pnt => "points",
        Lin2 | Lin3 => "line elements",
        Tri3 | Tri6 | Tri9 | Tri10 | Tri12 => "triangles",
        Qua4 | Qua8 | Qua9 => "quadrilaterals",
        Tet4 => "tetrahedra",
        Tet10 => "quadratic tetrahedra",
        Hex8 => "hexahedra",
        Hex20 | Hex27 => "quadratic hexahedra",
        Pri6 => "prisms",
        Pri15 | Pri18 => "quadratic prisms",
        Pyr5 => "pyramids",
        Pyr13 | Pyr14 => "quadratic pyramids",
        _ => "higher-order elements",
    }
    .to_string()
}

/// The version in `$MeshFormat`.
fn format_version(bytes: &[u8]) -> Option<String> {
    let at = find(bytes, b"$MeshFormat")?;
    let rest = &bytes[at + 11..];
    let text = String::from_utf8_lossy(&rest[..rest.len().min(64)]);
    text.split_whitespace().next().map(String::from)
}

/// What the `$MeshFormat` section says of the encoding.
struct Format {
    binary: bool,
    /// Bytes of a `size_t` (counts and tags) in a binary file.
    size: usize,
    big_endian: bool,
}

/// The `$MeshFormat` line `version file-type data-size`, and in a binary file the byte order
/// (the int 1 on the next line). mshio panics on a data size it has no reader for (other than
/// 1, 2, 4, 8 or 16 bytes, or too large a number); Gmsh writes 8, and 4 is `size_t` on 32-bit
/// machines.
fn mesh_format(bytes: &[u8]) -> Result<Format, String> {
    let at = find(bytes, b"$MeshFormat").ok_or("missing")? + 11;
    let rest = &bytes[at..];
    let start = rest
        .iter()
        .position(|&b| b == b'\n')
        .ok_or("no line break")?
        + 1;
    let len = rest[start..]
        .iter()
        .position(|&b| b == b'\n')
        .ok_or("no line break after the format line")?;
    let line = String::from_utf8_lossy(&rest[start..start + len]);
    let w: Vec<&str> = line.split_whitespace().collect();
    let [_, file_type, data_size] = w[..] else {
        return Err(format!(
            "the format line `{}` is not `version file-type data-size`",
            line.trim()
        ));
    };
    let binary = match file_type.parse::<u64>() {
        Ok(0) => false,
        Ok(1) => true,
        _ => return Err(format!("file type `{file_type}`: 0 (ASCII) or 1 (binary)")),
    };
    let size = match data_size.parse::<u64>() {
        Ok(n @ (4 | 8)) => n as usize,
        _ => {
            return Err(format!(
                "data size `{data_size}`: palpa reads 8 (what Gmsh writes) or 4"
            ))
        }
    };
    let after = &rest[start + len + 1..];
    let big_endian = binary && after.len() >= 4 && after[..4] == 1i32.to_be_bytes();
    Ok(Format {
        binary,
        size,
        big_endian,
    })
}

/// Refuse a `$Nodes` or `$Elements` section whose header states 0 nodes or elements: mshio
/// subtracts 1 from the count unchecked (a panic in debug builds, a wrapped count otherwise).
/// Every line that starts the section is checked (mshio refuses a second one, but only after
/// reading it).
fn check_section_counts(bytes: &[u8], f: &Format) -> Result<(), String> {
    for (tag, what) in [(&b"$Nodes"[..], "nodes"), (b"$Elements", "elements")] {
        let mut from = 0;
        while let Some(i) = find(&bytes[from..], tag) {
            let at = from + i;
            from = at + tag.len();
            // mshio's section start: whitespace, the tag, a line break
            if at > 0 && !bytes[at - 1].is_ascii_whitespace() {
                continue;
            }
            let body = match &bytes[from..] {
                [b'\n', r @ ..] | [b'\r', b'\n', r @ ..] => r,
                _ => continue,
            };
            let name = String::from_utf8_lossy(tag);
            let count = if f.binary {
                let Some(b) = body.get(f.size..2 * f.size) else {
                    continue;
                };
                let v = b.iter().fold(0u128, |v, &x| v << 8 | x as u128);
                let v_le = b.iter().rev().fold(0u128, |v, &x| v << 8 | x as u128);
                if f.big_endian {
                    v
                } else {
                    v_le
                }
            } else {
                let text = String::from_utf8_lossy(&body[..body.len().min(256)]);
                match text.split_whitespace().nth(1).map(str::parse::<u128>) {
                    Some(Ok(n)) => n,
                    _ => continue,
                }
            };
            if count == 0 {
                let line = bytes[..at].iter().filter(|&&b| b == b'\n').count() + 2;
                let place = if f.binary {
                    String::new()
                } else {
                    format!("line {line}: ")
                };
                return Err(format!(
                    "{place}the {name} section's header states 0 {what}; palpa needs a mesh with {what}"
                ));
            }
        }
    }
    Ok(())
}

/// `$PhysicalNames`: (dimension, tag) -> name.
fn physical_names(bytes: &[u8]) -> Result<BTreeMap<(i32, i32), String>, String> {
    let mut out = BTreeMap::new();
    let Some(at) = find(bytes, b"$PhysicalNames") else {
        return Ok(out);
    };
    let end = find(&bytes[at..], b"$EndPhysicalNames")
        .map(|e| at + e)
        .ok_or("no $EndPhysicalNames")?;
    let text = String::from_utf8_lossy(&bytes[at + 14..end]);
    let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
    let n: usize = lines
        .next()
        .and_then(|l| l.parse().ok())
        .ok_or("no count")?;
    for _ in 0..n {
        let l = lines.next().ok_or("fewer names than its count")?;
        let mut w = l.splitn(3, char::is_whitespace);
        let dim: i32 = w
            .next()
            .and_then(|s| s.parse().ok())
            .ok_or(format!("bad line `{l}`"))?;
        let tag: i32 = w
            .next()
            .and_then(|s| s.trim().parse().ok())
            .ok_or(format!("bad line `{l}`"))?;
        let name = w.next().unwrap_or("").trim().trim_matches('"').to_string();
        out.insert((dim, tag), name);
    }
    Ok(out)
}

fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}
