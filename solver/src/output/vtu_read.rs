//! Read a hexahedral mesh from a `.vtu` file (as written by palpa or ParaView): points,
//! VTK_HEXAHEDRON cells, and the optional cell array `part_id` for parts (named `part_N`).

use crate::mesh::Mesh;
use std::path::Path;
use vtkio::model::{Attribute, CellType, DataSet, VertexNumbers, Vtk};

/// Read the mesh.
pub fn read_vtu_mesh(path: &Path) -> Result<Mesh, String> {
    if !path.exists() {
        return Err(format!("mesh file {} does not exist", path.display()));
    }
    let vtk = Vtk::import(path).map_err(|e| format!("{}: cannot read VTK: {e}", path.display()))?;
    let piece = match vtk.data {
        DataSet::UnstructuredGrid { pieces, .. } => pieces
            .into_iter()
            .next()
            .ok_or_else(|| format!("{}: no piece", path.display()))?
            .into_loaded_piece_data(None)
            .map_err(|e| format!("{}: {e}", path.display()))?,
        _ => return Err(format!("{}: not an unstructured grid", path.display())),
    };
    let pts: Vec<f64> = piece
        .points
        .cast_into()
        .ok_or_else(|| format!("{}: bad points", path.display()))?;
    let mut mesh = Mesh {
        nodes: pts.chunks(3).map(|c| [c[0], c[1], c[2]]).collect(),
        ..Default::default()
    };
    let (conn, offs): (Vec<u64>, Vec<u64>) = match piece.cells.cell_verts {
        VertexNumbers::XML {
            connectivity,
            offsets,
        } => (connectivity, offsets),
        VertexNumbers::Legacy { vertices, .. } => {
            let mut c = Vec::new();
            let mut o = Vec::new();
            let mut i = 0;
            while i < vertices.len() {
                let n = vertices[i] as usize;
                c.extend(vertices[i + 1..i + 1 + n].iter().map(|&v| v as u64));
                o.push(c.len() as u64);
                i += n + 1;
            }
            (c, o)
        }
    };
    let mut start = 0usize;
    for (k, &end) in offs.iter().enumerate() {
        if piece.cells.types[k] != CellType::Hexahedron || end as usize - start != 8 {
            return Err(format!(
                "{}: cell {k} is not an 8-node hexahedron",
                path.display()
            ));
        }
        let c: [u32; 8] = std::array::from_fn(|a| conn[start + a] as u32);
        mesh.elements.push(c);
        start = end as usize;
    }
    let mut parts = vec![0u32; mesh.elements.len()];
    for a in &piece.data.cell {
        if let Attribute::DataArray(d) = a {
            if d.name == "part_id" {
                let v: Vec<i64> = d.data.clone().cast_into().ok_or("bad part_id")?;
                parts = v.iter().map(|&p| p.max(0) as u32).collect();
            }
        }
    }
    let np = parts.iter().copied().max().unwrap_or(0) as usize + 1;
    mesh.part_names = (0..np).map(|p| format!("part_{p}")).collect();
    if np == 1 {
        mesh.part_names = vec!["body".into()];
    }
    mesh.element_part = parts;
    Ok(mesh)
}
