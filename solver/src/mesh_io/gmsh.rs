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

use super::RawMesh;
use mshio::ElementType;
use std::collections::BTreeMap;
use std::path::Path;

/// Read a `.msh` file.
pub fn read(path: &Path) -> Result<RawMesh, String> {
    let p = path.display();
    let bytes = std::fs::read(path).map_err(|e| format!("{p}: cannot read: {e}"))?;
    let version = format_version(&bytes)
        .ok_or_else(|| format!("{p}: not a Gmsh file (no `$MeshFormat` section)"))?;
    if version != "4.1" {
        return Err(format!(
            "{p}: Gmsh format {version}; palpa reads format 4.1 (Gmsh's default; in Gmsh set \
             `Mesh.MshFileVersion = 4.1` or use File > Export > Version 4 ASCII)"
        ));
    }
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
    let physical = |dim: i32, tag: i32| -> String {
        names
            .get(&(dim, tag))
            .cloned()
            .unwrap_or_else(|| match dim {
                3 => format!("physical_{tag}"),
                _ => format!("physical_{dim}_{tag}"),
            })
    };
    // Physical tags of each geometric entity, by (dimension, tag).
    let mut groups: BTreeMap<(i32, i32), Vec<i32>> = BTreeMap::new();
    if let Some(ent) = &msh.data.entities {
        for e in &ent.points {
            groups.insert(
                (0, e.tag),
                e.physical_tags.iter().map(|t| t.abs()).collect(),
            );
        }
        for e in &ent.curves {
            groups.insert(
                (1, e.tag),
                e.physical_tags.iter().map(|t| t.abs()).collect(),
            );
        }
        for e in &ent.surfaces {
            groups.insert(
                (2, e.tag),
                e.physical_tags.iter().map(|t| t.abs()).collect(),
            );
        }
        for e in &ent.volumes {
            groups.insert(
                (3, e.tag),
                e.physical_tags.iter().map(|t| t.abs()).collect(),
            );
        }
    }
    let mut raw = RawMesh::default();
    let mut index: BTreeMap<u64, u32> = BTreeMap::new();
    if let Some(nodes) = &msh.data.nodes {
        let mut next_tag = nodes.min_node_tag;
        for b in &nodes.node_blocks {
            let tags: Vec<u64> = match &b.node_tags {
                Some(map) => {
                    let mut t = vec![0u64; b.nodes.len()];
                    for (&tag, &i) in map {
                        t[i] = tag;
                    }
                    t
                }
                None => {
                    let t = (next_tag..next_tag + b.nodes.len() as u64).collect();
                    next_tag += b.nodes.len() as u64;
                    t
                }
            };
            for (n, tag) in b.nodes.iter().zip(tags) {
                if index.insert(tag, raw.nodes.len() as u32).is_some() {
                    return Err(format!("{p}: node {tag} is given twice"));
                }
                raw.nodes.push([n.x, n.y, n.z]);
                raw.node_ids.push(tag as i64);
            }
        }
    }
    let Some(elements) = &msh.data.elements else {
        return Ok(raw);
    };
    let mut part = Vec::new();
    for b in &elements.element_blocks {
        let (dim, etag) = (b.entity_dim, b.entity_tag);
        let phys = groups.get(&(dim, etag)).cloned().unwrap_or_default();
        let node = |e: &mshio::Element<u64>, k: usize| -> Result<u32, String> {
            index.get(&e.nodes[k]).copied().ok_or_else(|| {
                format!(
                    "{p}: element {} refers to node {}, which the file does not define",
                    e.element_tag, e.nodes[k]
                )
            })
        };
        if dim == 3 {
            if b.element_type != ElementType::Hex8 {
                *raw.other_volume.entry(kind(b.element_type)).or_default() += b.elements.len();
                continue;
            }
            let key = match phys.as_slice() {
                [] => {
                    raw.part_names
                        .insert(-(etag as i64), format!("volume_{etag}"));
                    -(etag as i64)
                }
                [t] => {
                    raw.part_names.insert(*t as i64, physical(3, *t));
                    *t as i64
                }
                many => {
                    return Err(format!(
                        "{p}: geometric volume {etag} belongs to {} physical volumes ({}); \
                         palpa needs one part per hexahedron",
                        many.len(),
                        many.iter()
                            .map(|&t| physical(3, t))
                            .collect::<Vec<_>>()
                            .join(", ")
                    ))
                }
            };
            for e in &b.elements {
                let mut h = [0u32; 8];
                for (k, slot) in h.iter_mut().enumerate() {
                    *slot = node(e, k)?;
                }
                raw.hexes.push(h);
                raw.hex_labels.push(format!("element {}", e.element_tag));
                part.push(key);
            }
        } else {
            *raw.other_lower.entry(kind(b.element_type)).or_default() += b.elements.len();
            for &t in &phys {
                let set = raw.node_sets.entry(physical(dim, t)).or_default();
                for e in &b.elements {
                    for k in 0..e.nodes.len() {
                        set.push(node(e, k)?);
                    }
                }
            }
        }
    }
    raw.hex_part = Some(part);
    Ok(raw)
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
