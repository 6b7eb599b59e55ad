//! VTK XML unstructured-grid frames (`.vtu`, written with vtkio) and the `.pvd` collection
//! that ParaView opens as a time series.
//!
//! Point data: `displacement` (m), `velocity` (m/s). Cell data: `part_id`, `cauchy_stress`
//! (Pa, full 3x3 tensor, which ParaView shows with its components), `von_mises` (Pa),
//! `max_principal_stress` (Pa), and the laws' history variables, each only when requested.

use super::atomic::write_atomic;
use crate::mesh::Mesh;
use std::path::{Path, PathBuf};
use vtkio::model::{
    Attribute, Attributes, ByteOrder, CellType, Cells, DataArray, DataSet, IOBuffer,
    UnstructuredGridPiece, Version, VertexNumbers, Vtk,
};

/// One frame's fields.
#[derive(Default)]
pub struct Frame<'a> {
    /// Nodal displacement.
    pub displacement: Option<&'a [[f64; 3]]>,
    /// Nodal velocity.
    pub velocity: Option<&'a [[f64; 3]]>,
    /// Part id per element.
    pub part: bool,
    /// Cauchy stress per element (xx yy zz xy yz zx).
    pub stress: Option<&'a [[f64; 6]]>,
    /// Extra named cell scalars.
    pub cell_scalars: Vec<(String, Vec<f64>)>,
    /// Extra named point scalars.
    pub point_scalars: Vec<(String, Vec<f64>)>,
    /// Write the full stress tensor (not only derived scalars).
    pub tensor: bool,
}

/// Build the vtkio model of a mesh with fields.
pub fn vtk_model(mesh: &Mesh, frame: &Frame, title: &str) -> Vtk {
    let points: Vec<f64> = mesh.nodes.iter().flat_map(|p| p.iter().copied()).collect();
    let connectivity: Vec<u64> = mesh
        .elements
        .iter()
        .flat_map(|c| c.iter().map(|&n| n as u64))
        .collect();
    let offsets: Vec<u64> = (1..=mesh.elements.len() as u64).map(|k| 8 * k).collect();
    let mut attrs = Attributes::new();
    let flat3 = |v: &[[f64; 3]]| -> Vec<f64> { v.iter().flat_map(|p| p.iter().copied()).collect() };
    if let Some(u) = frame.displacement {
        attrs.point.push(Attribute::DataArray(
            DataArray::vectors("displacement").with_data(flat3(u)),
        ));
    }
    if let Some(v) = frame.velocity {
        attrs.point.push(Attribute::DataArray(
            DataArray::vectors("velocity").with_data(flat3(v)),
        ));
    }
    for (name, vals) in &frame.point_scalars {
        attrs.point.push(Attribute::DataArray(
            DataArray::scalars(name.as_str(), 1).with_data(vals.clone()),
        ));
    }
    if frame.part {
        let p: Vec<i32> = mesh.element_part.iter().map(|&p| p as i32).collect();
        attrs.cell.push(Attribute::DataArray(
            DataArray::scalars("part_id", 1).with_data(p),
        ));
    }
    if let (Some(s), true) = (frame.stress, frame.tensor) {
        let t: Vec<f64> = s
            .iter()
            .flat_map(|s| [s[0], s[3], s[5], s[3], s[1], s[4], s[5], s[4], s[2]])
            .collect();
        attrs.cell.push(Attribute::DataArray(
            DataArray::tensors("cauchy_stress").with_data(t),
        ));
    }
    for (name, vals) in &frame.cell_scalars {
        attrs.cell.push(Attribute::DataArray(
            DataArray::scalars(name.as_str(), 1).with_data(vals.clone()),
        ));
    }
    Vtk {
        version: Version::new_xml(1, 0),
        title: title.to_string(),
        byte_order: ByteOrder::LittleEndian,
        file_path: None,
        data: DataSet::inline(UnstructuredGridPiece {
            points: IOBuffer::F64(points),
            cells: Cells {
                cell_verts: VertexNumbers::XML {
                    connectivity,
                    offsets,
                },
                types: vec![CellType::Hexahedron; mesh.elements.len()],
            },
            data: attrs,
        }),
    }
}

/// Write one `.vtu` file atomically.
pub fn write_vtu(path: &Path, mesh: &Mesh, frame: &Frame, title: &str) -> Result<(), String> {
    let mut buf = Vec::new();
    vtk_model(mesh, frame, title)
        .write_xml(&mut buf)
        .map_err(|e| format!("{}: cannot encode VTK: {e}", path.display()))?;
    write_atomic(path, &buf)
}

/// A `.pvd` time series.
pub struct Series {
    dir: PathBuf,
    stem: String,
    frames: Vec<(f64, String)>,
}

impl Series {
    /// A series of files `DIR/STEM_NNNN.vtu` listed in `DIR/STEM.pvd`.
    pub fn new(dir: &Path, stem: &str) -> Series {
        Series {
            dir: dir.to_path_buf(),
            stem: stem.to_string(),
            frames: Vec::new(),
        }
    }
    /// Write a frame and update the collection.
    pub fn write(
        &mut self,
        time: f64,
        mesh: &Mesh,
        frame: &Frame,
        title: &str,
    ) -> Result<PathBuf, String> {
        let name = format!("{}_{:04}.vtu", self.stem, self.frames.len());
        let path = self.dir.join(&name);
        write_vtu(&path, mesh, frame, title)?;
        self.frames.push((time, name));
        self.flush()?;
        Ok(path)
    }
    /// Frames written.
    pub fn len(&self) -> usize {
        self.frames.len()
    }
    /// No frame yet.
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }
    fn flush(&self) -> Result<(), String> {
        let mut s = String::from(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n",
        );
        for (t, f) in &self.frames {
            s.push_str(&format!(
                "    <DataSet timestep=\"{t:.9e}\" group=\"\" part=\"0\" file=\"{f}\"/>\n"
            ));
        }
        s.push_str("  </Collection>\n</VTKFile>\n");
        write_atomic(&self.dir.join(format!("{}.pvd", self.stem)), s.as_bytes())
    }
}
