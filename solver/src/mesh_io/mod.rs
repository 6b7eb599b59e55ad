//! Hexahedral meshes from the files other tools write, chosen by the file's extension:
//!
//! | extension | format | reader | parts from | sets from |
//! |---|---|---|---|---|
//! | `.vtu` | VTK XML unstructured grid (ASCII, inline base64, appended raw or base64; zlib, LZ4 or LZMA compressed) | vtkio 0.7 ([`xml`]) | an integer cell array (see [`PART_ARRAYS`]), named by the field data `part_names` | - |
//! | `.vtk` | VTK legacy unstructured grid, versions 2 to 5.1, ASCII or binary | hand-written ([`legacy`]) | as `.vtu` | - |
//! | `.msh` | Gmsh MSH 4.1, ASCII or binary | mshio 0.4 ([`gmsh`]) | physical volumes (named by `$PhysicalNames`), else geometric volumes | physical surfaces, curves and points become node sets |
//! | `.inp` | Abaqus input file (flat or one `*Part`) | hand-written ([`abaqus`]) | `*Solid Section` element sets, else the `ELSET` of `*Element` | `*Nset` and `*Elset` |
//!
//! Every reader produces a [`RawMesh`] (the file's numbering, coordinates in the file's unit);
//! [`finish`] then checks it the same way for every format: the file must hold hexahedra
//! (VTK_HEXAHEDRON node order, which is also that of Gmsh's 8-node hexahedron, Abaqus C3D8 and
//! LS-DYNA's solids), no other volume cell (a mixed mesh is refused with its cell counts), no
//! inverted or degenerate hexahedron (non-positive Jacobian at a corner); nodes that no
//! hexahedron uses are dropped, parts with no hexahedron omitted, coordinates scaled to m.
//! Lower-dimensional cells (points, lines, faces) are not meshed: they only carry sets.

pub mod abaqus;
pub mod gmsh;
pub mod legacy;
pub mod xml;

use crate::mesh::Mesh;
use std::collections::BTreeMap;
use std::path::Path;

/// Cell arrays read as part ids, in this order of preference: palpa's own, meshio's for Gmsh
/// physical groups, VTK's and Salome's `CellEntityIds`, deal.II's and others' `MaterialIds`,
/// Medit's reference.
pub const PART_ARRAYS: [&str; 5] = [
    "part_id",
    "gmsh:physical",
    "CellEntityIds",
    "MaterialIds",
    "medit:ref",
];

/// A mesh as a file states it.
#[derive(Debug, Default)]
pub struct RawMesh {
    /// Node coordinates in the file's unit.
    pub nodes: Vec<[f64; 3]>,
    /// How the file numbers each node (for messages and sets): its id or 0-based index.
    pub node_ids: Vec<i64>,
    /// Hexahedra as node indices (into `nodes`).
    pub hexes: Vec<[u32; 8]>,
    /// How the file names each hexahedron in messages, e.g. `element 12` or `cell 3`.
    pub hex_labels: Vec<String>,
    /// Part key of each hexahedron (the file's part number); None if the file has no parts.
    pub hex_part: Option<Vec<i64>>,
    /// Names of part keys, where the file gives them.
    pub part_names: BTreeMap<i64, String>,
    /// Volume cells that are not 8-node hexahedra, counted by kind (e.g. `tetrahedron`).
    pub other_volume: BTreeMap<String, usize>,
    /// Lower-dimensional cells counted by kind (kept only for the report).
    pub other_lower: BTreeMap<String, usize>,
    /// Named node sets (indices into `nodes`).
    pub node_sets: BTreeMap<String, Vec<u32>>,
    /// Named element sets (indices into `hexes`).
    pub element_sets: BTreeMap<String, Vec<u32>>,
    /// What the reader skipped that the user should know (passed on to [`Imported::notes`]).
    pub notes: Vec<String>,
}

/// A mesh read from a file, and what the reader did that the user should know.
pub struct Imported {
    /// The mesh (m).
    pub mesh: Mesh,
    /// Notes (dropped nodes, ignored lower-dimensional cells, ...).
    pub notes: Vec<String>,
}

/// The file kinds this module reads, for messages.
pub const KNOWN: &str = ".vtu, .vtk, .msh (Gmsh 4.1) or .inp (Abaqus)";

/// Whether a path names a file kind that [`read_mesh`] reads.
pub fn is_mesh_file(path: &Path) -> bool {
    matches!(extension(path).as_str(), "vtu" | "vtk" | "msh" | "inp")
}

fn extension(path: &Path) -> String {
    path.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}

/// Read a mesh file; `scale` converts its coordinates to m (1 for metres, 1e-3 for mm).
pub fn read_mesh(path: &Path, scale: f64) -> Result<Imported, String> {
    let p = path.display();
    if !path.exists() {
        return Err(format!("mesh file {p} does not exist"));
    }
    if !(scale.is_finite() && scale > 0.0) {
        return Err(format!(
            "{p}: the length unit must be positive, got {scale} m"
        ));
    }
    let raw = match extension(path).as_str() {
        "vtu" => xml::read(path)?,
        "vtk" => legacy::read(path)?,
        "msh" => gmsh::read(path)?,
        "inp" => abaqus::read(path)?,
        e => {
            return Err(format!(
                "{p}: cannot read a mesh from a `.{e}` file; palpa reads {KNOWN}"
            ))
        }
    };
    finish(path, raw, scale)
}

/// Check a raw mesh and turn it into a [`Mesh`] in m (see the module doc).
pub fn finish(path: &Path, raw: RawMesh, scale: f64) -> Result<Imported, String> {
    let p = path.display();
    let counts = |m: &BTreeMap<String, usize>| {
        m.iter()
            .map(|(k, n)| format!("{n} {k}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    if !raw.other_volume.is_empty() {
        let what = if raw.hexes.is_empty() {
            "no hexahedra but".to_string()
        } else {
            format!("{} hexahedra and", raw.hexes.len())
        };
        return Err(format!(
            "{p}: the mesh holds {what} {}; palpa meshes 8-node hexahedra only \
             (remesh with hexahedra, e.g. Gmsh's transfinite and recombine options, \
             or split the other cells into hexahedra)",
            counts(&raw.other_volume)
        ));
    }
    if raw.hexes.is_empty() {
        let got = if raw.other_lower.is_empty() {
            "nothing".to_string()
        } else {
            counts(&raw.other_lower)
        };
        return Err(format!(
            "{p}: no hexahedra in the file (it holds {got}); palpa needs a volume mesh of 8-node hexahedra"
        ));
    }
    for (k, c) in raw.hexes.iter().enumerate() {
        let mut s = *c;
        s.sort_unstable();
        if s.windows(2).any(|w| w[0] == w[1]) {
            return Err(format!(
                "{p}: {} repeats a node (a collapsed hexahedron, e.g. a wedge written as a hexahedron); palpa needs eight distinct nodes",
                raw.hex_labels[k]
            ));
        }
    }
    check_orientation(path, &raw)?;
    let mut notes = raw.notes.clone();
    // Keep only the nodes hexahedra use, in their file order.
    let mut used = vec![false; raw.nodes.len()];
    for c in &raw.hexes {
        for &n in c {
            used[n as usize] = true;
        }
    }
    let mut new_id = vec![u32::MAX; raw.nodes.len()];
    let mut nodes = Vec::new();
    for (i, x) in raw.nodes.iter().enumerate() {
        if used[i] {
            new_id[i] = nodes.len() as u32;
            nodes.push([x[0] * scale, x[1] * scale, x[2] * scale]);
        }
    }
    let dropped = raw.nodes.len() - nodes.len();
    if dropped > 0 {
        notes.push(format!(
            "{p}: {dropped} of {} nodes belong to no hexahedron and are left out",
            raw.nodes.len()
        ));
    }
    if !raw.other_lower.is_empty() {
        notes.push(format!(
            "{p}: {} are not meshed (only hexahedra are; faces, lines and points serve as sets)",
            counts(&raw.other_lower)
        ));
    }
    let elements: Vec<[u32; 8]> = raw
        .hexes
        .iter()
        .map(|c| c.map(|n| new_id[n as usize]))
        .collect();
    let (element_part, part_names) = parts(&raw);
    let mut node_sets = BTreeMap::new();
    for (name, set) in &raw.node_sets {
        let mut s: Vec<u32> = set
            .iter()
            .map(|&n| new_id[n as usize])
            .filter(|&n| n != u32::MAX)
            .collect();
        s.sort_unstable();
        s.dedup();
        if s.len() < set.len() {
            notes.push(format!(
                "{p}: node set `{name}`: {} of its {} nodes belong to no hexahedron and are left out",
                set.len() - s.len(),
                set.len()
            ));
        }
        if !s.is_empty() {
            node_sets.insert(name.clone(), s);
        }
    }
    let mut element_sets = BTreeMap::new();
    for (name, set) in &raw.element_sets {
        let mut s = set.clone();
        s.sort_unstable();
        s.dedup();
        element_sets.insert(name.clone(), s);
    }
    Ok(Imported {
        mesh: Mesh {
            nodes,
            elements,
            element_part,
            part_names,
            node_sets,
            element_sets,
        },
        notes,
    })
}

/// Parts: the file's part keys in ascending order, only those with hexahedra, named by the
/// file where it names them, else `part_<key>`; a file without parts is one part `body`.
fn parts(raw: &RawMesh) -> (Vec<u32>, Vec<String>) {
    let Some(keys) = &raw.hex_part else {
        return (vec![0; raw.hexes.len()], vec!["body".into()]);
    };
    let mut present: Vec<i64> = keys.clone();
    present.sort_unstable();
    present.dedup();
    let index: BTreeMap<i64, u32> = present
        .iter()
        .enumerate()
        .map(|(i, &k)| (k, i as u32))
        .collect();
    let names = present
        .iter()
        .map(|k| match raw.part_names.get(k) {
            Some(n) if !n.trim().is_empty() => n.trim().to_string(),
            _ if present.len() == 1 && *k == 0 => "body".to_string(),
            _ => format!("part_{k}"),
        })
        .collect();
    (keys.iter().map(|k| index[k]).collect(), names)
}

/// Refuse inverted or degenerate hexahedra, naming them; a mesh whose hexahedra are all
/// inverted has the mirrored node order, which the message says.
fn check_orientation(path: &Path, raw: &RawMesh) -> Result<(), String> {
    let mut bad = Vec::new();
    for (k, c) in raw.hexes.iter().enumerate() {
        let x: [[f64; 3]; 8] = std::array::from_fn(|a| raw.nodes[c[a] as usize]);
        let (det, _) = crate::hex::corner_jacobians(&x);
        let (corner, worst) =
            det.iter().enumerate().fold(
                (0, f64::INFINITY),
                |b, (i, &d)| if d < b.1 { (i, d) } else { b },
            );
        if !(worst > 0.0) {
            bad.push((k, corner, worst));
        }
    }
    if bad.is_empty() {
        return Ok(());
    }
    let p = path.display();
    if bad.len() == raw.hexes.len() {
        return Err(format!(
            "{p}: all {} hexahedra are inverted (non-positive Jacobian): the file numbers their \
             nodes in the mirrored order; palpa expects VTK_HEXAHEDRON order (nodes 0-3 one face \
             counter-clockwise seen from the opposite face 4-7)",
            raw.hexes.len()
        ));
    }
    let list: Vec<String> = bad
        .iter()
        .take(5)
        .map(|&(k, c, d)| format!("{} (corner {c}, det J = {d:.3e})", raw.hex_labels[k]))
        .collect();
    Err(format!(
        "{p}: {} of {} hexahedra are inverted or degenerate (non-positive Jacobian at a corner): {}{}",
        bad.len(),
        raw.hexes.len(),
        list.join(", "),
        if bad.len() > 5 { ", ..." } else { "" }
    ))
}

/// VTK cell type numbers: (name, is a volume cell), for the counts in messages.
pub fn vtk_cell_kind(t: u8) -> (&'static str, bool) {
    match t {
        1 => ("vertex", false),
        2 => ("poly-vertex", false),
        3 => ("line", false),
        4 => ("poly-line", false),
        5 => ("triangle", false),
        6 => ("triangle strip", false),
        7 => ("polygon", false),
        8 => ("pixel", false),
        9 => ("quadrilateral", false),
        21 => ("quadratic edge", false),
        22 => ("quadratic triangle", false),
        23 => ("quadratic quadrilateral", false),
        10 => ("tetrahedron", true),
        11 => ("voxel", true),
        12 => ("hexahedron", true),
        13 => ("wedge", true),
        14 => ("pyramid", true),
        15 => ("pentagonal prism", true),
        16 => ("hexagonal prism", true),
        24 => ("quadratic tetrahedron", true),
        25 => ("quadratic hexahedron", true),
        26 => ("quadratic wedge", true),
        27 => ("quadratic pyramid", true),
        29 => ("triquadratic hexahedron", true),
        42 => ("polyhedron", true),
        _ => ("unknown cell", true),
    }
}

/// Turn VTK cells (types and node lists) into a raw mesh's hexahedra and counts; shared by the
/// XML and legacy readers. `cells` yields each cell's node list.
pub(crate) fn vtk_cells<'a>(
    raw: &mut RawMesh,
    types: &[u8],
    cells: impl Iterator<Item = &'a [u64]>,
    part: Option<Vec<i64>>,
    path: &Path,
) -> Result<(), String> {
    let n = raw.nodes.len() as u64;
    let mut keep = Vec::new();
    for (k, (c, &t)) in cells.zip(types).enumerate() {
        if let Some(&bad) = c.iter().find(|&&v| v >= n) {
            return Err(format!(
                "{}: cell {k} refers to point {bad}, but the file has {n} points",
                path.display()
            ));
        }
        let (name, volume) = vtk_cell_kind(t);
        if t == 12 && c.len() == 8 {
            raw.hexes.push(std::array::from_fn(|a| c[a] as u32));
            raw.hex_labels.push(format!("cell {k}"));
            keep.push(k);
        } else if t == 11 && c.len() == 8 {
            // VTK_VOXEL: the axis-aligned hexahedron with nodes in x-fastest lattice order.
            let h = [c[0], c[1], c[3], c[2], c[4], c[5], c[7], c[6]];
            raw.hexes.push(h.map(|v| v as u32));
            raw.hex_labels.push(format!("cell {k} (voxel)"));
            keep.push(k);
        } else {
            let m = if volume {
                &mut raw.other_volume
            } else {
                &mut raw.other_lower
            };
            *m.entry(plural(name)).or_default() += 1;
        }
    }
    raw.node_ids = (0..n as i64).collect();
    raw.hex_part = part.map(|p| keep.iter().map(|&k| p[k]).collect());
    Ok(())
}

fn plural(name: &str) -> String {
    if name.ends_with("ron") {
        format!("{}a", &name[..name.len() - 2])
    } else if name.ends_with('x') {
        format!("{}ices", &name[..name.len() - 2])
    } else {
        format!("{name}s")
    }
}

/// Parse the part-names field data: strings indexed by part id.
pub(crate) fn names_from(strings: Vec<String>) -> BTreeMap<i64, String> {
    strings
        .into_iter()
        .enumerate()
        .filter(|(_, s)| !s.is_empty())
        .map(|(i, s)| (i as i64, s))
        .collect()
}
