//! VTK XML unstructured-grid frames (`.vtu`, written with vtkio, zlib-compressed) and the
//! `.pvd` collection that ParaView opens as a time series.
//!
//! Point data: `displacement` (m), `velocity` (m/s). Cell data: `part_id`, `cauchy_stress`
//! (Pa, full 3x3 tensor, which ParaView shows with its components), `von_mises` (Pa),
//! `max_principal_stress` (Pa), and the laws' history variables, each only when requested.
//! Field data: `part_names` (string `i` names `part_id` `i`), which palpa reads back.
//!
//! The indenters of a frame go to a second file of the same time step ([`write_surfaces`]):
//! their surfaces as quadrilaterals and triangles at the start position, with the point data
//! `displacement` (the indenter's travel, m), cell data `indenter_id` and field data
//! `indenter_names`, so that ParaView's Warp By Vector moves tissue and fingers alike. The
//! `.pvd` lists both files of a time step (`part="0"` the tissue, `part="1"` the indenters),
//! which ParaView shows as two blocks of one dataset.
//!
//! vtkio writes no `<FieldData>`; [`with_field_strings`] adds it to the XML vtkio writes, as an
//! ASCII string array (the bytes of each string in decimal, each string ended by a 0, as VTK
//! writes ASCII string arrays).
//!
//! A [`Series`] copies a frame's fields and encodes and writes it on a background thread while
//! the solver goes on: compressing a frame of the 104k-hexahedron `--paper` model takes about
//! 0.6 s on one core, which the time loop would otherwise wait for at every frame while the
//! other core idles. One frame is in flight at a time; the `.pvd` lists a frame only once its
//! file is whole, and a write error surfaces at the next frame or at [`Series::finish`].

use super::atomic::write_atomic;
use crate::mesh::Mesh;
use std::path::{Path, PathBuf};
use vtkio::model::{
    Attribute, Attributes, ByteOrder, CellType, Cells, DataArray, DataSet, IOBuffer,
    UnstructuredGridPiece, Version, VertexNumbers, Vtk,
};
use vtkio::xml::Compressor;

/// zlib level of the frames: 1 (fastest) writes a frame of the 23k-hexahedron palpation model
/// about as small as the default 6 does, in a fraction of the time.
pub const ZLIB_LEVEL: u32 = 1;

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

/// Encode a model as zlib-compressed VTK XML.
fn encode(vtk: Vtk, path: &Path) -> Result<Vec<u8>, String> {
    let mut buf = Vec::new();
    vtk.try_into_xml_format(Compressor::ZLib, ZLIB_LEVEL)
        .and_then(|x| x.write(&mut buf))
        .map_err(|e| format!("{}: cannot encode VTK: {e}", path.display()))?;
    Ok(buf)
}

/// Add `<FieldData>` with one string array to the XML of an unstructured grid, right after
/// its `<UnstructuredGrid>` tag.
pub fn with_field_strings(xml: Vec<u8>, name: &str, strings: &[String]) -> Vec<u8> {
    let tag = b"<UnstructuredGrid";
    let Some(at) = xml.windows(tag.len()).position(|w| w == tag) else {
        return xml;
    };
    let Some(end) = xml[at..]
        .iter()
        .position(|&b| b == b'>')
        .map(|e| at + e + 1)
    else {
        return xml;
    };
    let bytes: Vec<String> = strings
        .iter()
        .flat_map(|s| {
            s.bytes()
                .filter(|&b| b != 0)
                .map(|b| b.to_string())
                .chain(std::iter::once("0".to_string()))
        })
        .collect();
    let name: String = name
        .chars()
        .filter(|c| c.is_ascii_alphanumeric() || *c == '_')
        .collect();
    let field = format!(
        "\n    <FieldData>\n      <Array type=\"String\" Name=\"{name}\" NumberOfTuples=\"{}\" format=\"ascii\">\n        {}\n      </Array>\n    </FieldData>",
        strings.len(),
        bytes.join(" ")
    );
    let mut out = Vec::with_capacity(xml.len() + field.len());
    out.extend_from_slice(&xml[..end]);
    out.extend_from_slice(field.as_bytes());
    out.extend_from_slice(&xml[end..]);
    out
}

/// Write one `.vtu` file atomically (zlib-compressed, with the part names).
pub fn write_vtu(path: &Path, mesh: &Mesh, frame: &Frame, title: &str) -> Result<(), String> {
    write_model(path, vtk_model(mesh, frame, title), &mesh.part_names)
}

/// Encode a model and write it atomically with the part names.
fn write_model(path: &Path, vtk: Vtk, part_names: &[String]) -> Result<(), String> {
    let buf = encode(vtk, path)?;
    write_atomic(path, &with_field_strings(buf, "part_names", part_names))
}

/// A rigid surface of one frame: polygons (quadrilaterals and triangles) at the start position
/// and the displacement that takes them to the frame's position.
#[derive(Clone, Debug)]
pub struct RigidSurface {
    /// Indenter name.
    pub name: String,
    /// Vertices at t = 0 (m).
    pub vertices: Vec<[f64; 3]>,
    /// Polygons: 3 or 4 vertex indices each.
    pub polygons: Vec<Vec<u32>>,
    /// Displacement of every vertex (m).
    pub displacement: [f64; 3],
}

/// Write the indenters of a frame as one `.vtu` of surface cells.
pub fn write_surfaces(path: &Path, surfaces: &[RigidSurface], title: &str) -> Result<(), String> {
    let mut points = Vec::new();
    let mut disp = Vec::new();
    let mut connectivity = Vec::new();
    let mut offsets = Vec::new();
    let mut types = Vec::new();
    let mut ids = Vec::new();
    for (k, s) in surfaces.iter().enumerate() {
        let base = (points.len() / 3) as u64;
        for v in &s.vertices {
            points.extend_from_slice(v);
            disp.extend_from_slice(&s.displacement);
        }
        for p in &s.polygons {
            connectivity.extend(p.iter().map(|&i| base + i as u64));
            offsets.push(connectivity.len() as u64);
            types.push(if p.len() == 3 {
                CellType::Triangle
            } else {
                CellType::Quad
            });
            ids.push(k as i32);
        }
    }
    let mut attrs = Attributes::new();
    attrs.point.push(Attribute::DataArray(
        DataArray::vectors("displacement").with_data(disp),
    ));
    attrs.cell.push(Attribute::DataArray(
        DataArray::scalars("indenter_id", 1).with_data(ids),
    ));
    let vtk = Vtk {
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
                types,
            },
            data: attrs,
        }),
    };
    let names: Vec<String> = surfaces.iter().map(|s| s.name.clone()).collect();
    let buf = encode(vtk, path)?;
    write_atomic(path, &with_field_strings(buf, "indenter_names", &names))
}

/// A frame whose tissue file is being written on a background thread: its time, its files
/// and the writer.
struct InFlight {
    time: f64,
    files: Vec<String>,
    writer: std::thread::JoinHandle<Result<(), String>>,
}

/// A `.pvd` time series.
pub struct Series {
    dir: PathBuf,
    stem: String,
    /// Per frame: its time and files (the tissue, then the indenters if any).
    frames: Vec<(f64, Vec<String>)>,
    /// The frame being written.
    in_flight: Option<InFlight>,
}

impl Series {
    /// A series of files `DIR/STEM_NNNN.vtu` (and `DIR/indenters_NNNN.vtu`) listed in
    /// `DIR/STEM.pvd`.
    pub fn new(dir: &Path, stem: &str) -> Series {
        Series {
            dir: dir.to_path_buf(),
            stem: stem.to_string(),
            frames: Vec::new(),
            in_flight: None,
        }
    }
    /// Write a frame (and its indenters, if any) and update the collection. The fields are
    /// copied and the tissue file is written on a background thread (after the previous
    /// frame's is whole); the error of a frame still being written comes with the next call
    /// or [`Series::finish`].
    pub fn write(
        &mut self,
        time: f64,
        mesh: &Mesh,
        frame: &Frame,
        surfaces: &[RigidSurface],
        title: &str,
    ) -> Result<PathBuf, String> {
        self.finish()?;
        let k = self.frames.len();
        let name = format!("{}_{k:04}.vtu", self.stem);
        let path = self.dir.join(&name);
        let mut files = vec![name];
        if !surfaces.is_empty() {
            let s = format!("indenters_{k:04}.vtu");
            write_surfaces(&self.dir.join(&s), surfaces, title)?;
            files.push(s);
        }
        let vtk = vtk_model(mesh, frame, title);
        let part_names = mesh.part_names.clone();
        let target = path.clone();
        let writer = std::thread::Builder::new()
            .name("vtk-writer".into())
            .spawn(move || write_model(&target, vtk, &part_names))
            .map_err(|e| format!("{}: cannot start the VTK writer: {e}", path.display()))?;
        self.in_flight = Some(InFlight {
            time,
            files,
            writer,
        });
        Ok(path)
    }
    /// Wait for the frame being written, then list it in the collection.
    pub fn finish(&mut self) -> Result<(), String> {
        let Some(f) = self.in_flight.take() else {
            return Ok(());
        };
        f.writer
            .join()
            .map_err(|_| format!("{}: the VTK writer panicked", f.files[0]))??;
        self.frames.push((f.time, f.files));
        self.flush()
    }
    /// Frames written or being written.
    pub fn len(&self) -> usize {
        self.frames.len() + usize::from(self.in_flight.is_some())
    }
    /// No frame yet.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    fn flush(&self) -> Result<(), String> {
        let mut s = String::from(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n",
        );
        for (t, files) in &self.frames {
            for (part, f) in files.iter().enumerate() {
                s.push_str(&format!(
                    "    <DataSet timestep=\"{t:.9e}\" group=\"\" part=\"{part}\" file=\"{f}\"/>\n"
                ));
            }
        }
        s.push_str("  </Collection>\n</VTKFile>\n");
        write_atomic(&self.dir.join(format!("{}.pvd", self.stem)), s.as_bytes())
    }
}

impl Drop for Series {
    /// A series dropped without [`Series::finish`] still waits for its last frame (its error
    /// is lost: call `finish` to see it).
    fn drop(&mut self) {
        let _ = self.finish();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::{box_mesh, BoxSpec};

    fn cube() -> Mesh {
        box_mesh(
            &BoxSpec {
                divisions: [2, 2, 2],
                ..Default::default()
            },
            "block",
        )
        .unwrap()
    }

    fn pvd_files(dir: &Path) -> usize {
        std::fs::read_to_string(dir.join("frame.pvd"))
            .map(|t| t.matches("<DataSet").count())
            .unwrap_or(0)
    }

    /// Frames written on the background thread are whole once listed: the `.pvd` lists a
    /// frame when its file is written (at the next frame or at `finish`), and the files read
    /// back as VTK.
    #[test]
    fn a_frame_is_listed_once_its_file_is_whole() {
        let dir = tempfile::tempdir().unwrap();
        let mesh = cube();
        let u = vec![[1e-3, 0.0, 0.0]; mesh.nodes.len()];
        let frame = Frame {
            displacement: Some(&u),
            part: true,
            ..Default::default()
        };
        let mut s = Series::new(dir.path(), "frame");
        s.write(0.0, &mesh, &frame, &[], "t").unwrap();
        assert_eq!((s.len(), pvd_files(dir.path())), (1, 0));
        s.write(1e-3, &mesh, &frame, &[], "t").unwrap();
        assert_eq!((s.len(), pvd_files(dir.path())), (2, 1));
        s.finish().unwrap();
        assert_eq!((s.len(), pvd_files(dir.path())), (2, 2));
        for k in 0..2 {
            let p = dir.path().join(format!("frame_{k:04}.vtu"));
            vtkio::Vtk::import(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        }
        // finishing twice, and dropping after, are no-ops
        s.finish().unwrap();
        drop(s);
        assert_eq!(pvd_files(dir.path()), 2);
    }

    /// A frame that cannot be written fails the next write (or `finish`), naming the file, and
    /// is never listed; dropping the series waits for its writer.
    #[test]
    fn a_failed_frame_is_an_error_at_the_next_call_naming_it() {
        let dir = tempfile::tempdir().unwrap();
        let mesh = cube();
        let frame = Frame::default();
        // the first frame's path is a directory: its atomic write fails
        std::fs::create_dir(dir.path().join("frame_0000.vtu")).unwrap();
        let mut s = Series::new(dir.path(), "frame");
        s.write(0.0, &mesh, &frame, &[], "t").unwrap();
        let e = s.write(1e-3, &mesh, &frame, &[], "t").unwrap_err();
        assert!(e.contains("frame_0000.vtu"), "{e}");
        assert_eq!(pvd_files(dir.path()), 0);
        let mut s = Series::new(dir.path(), "frame");
        s.write(0.0, &mesh, &frame, &[], "t").unwrap();
        let e = s.finish().unwrap_err();
        assert!(e.contains("frame_0000.vtu"), "{e}");
        assert_eq!(s.len(), 0);
        let s2 = {
            let mut s = Series::new(dir.path(), "frame");
            s.write(0.0, &mesh, &frame, &[], "t").unwrap();
            s
        };
        drop(s2);
    }
}
