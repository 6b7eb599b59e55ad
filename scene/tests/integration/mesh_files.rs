//! Meshes written by other tools (tests/meshes/, made by tests/meshes/make_meshes.py with VTK
//! 9.7, meshio 5.3 and Gmsh 4.15): every encoding reads to the same block, 30 x 20 x 20 mm in
//! 12 hexahedra and two parts of equal volume, with the part names, node sets and element sets
//! each format carries; cells palpa does not mesh are refused with their counts.

use crate::common;

use solver::mesh_io::read_mesh;
use solver::Mesh;
use std::path::PathBuf;

fn file(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/meshes")
        .join(name)
}

/// Volume of a hexahedron (m^3) by its exact trilinear volume (sum over 2x2x2 Gauss points).
fn volume(m: &Mesh, e: usize) -> f64 {
    let x: [[f64; 3]; 8] = std::array::from_fn(|a| m.nodes[m.elements[e][a] as usize]);
    solver::hex::element_geometry(&x).unwrap().volume
}

/// The block: its bounds, 12 hexahedra, total volume 1.2e-5 m^3, and per part (by name) the
/// volume 6e-6 m^3.
fn check_block(m: &Mesh, names: [&str; 2]) {
    assert_eq!(m.elements.len(), 12);
    assert_eq!(m.nodes.len(), 36);
    let (lo, hi) = m.bounds();
    for k in 0..3 {
        assert!(lo[k].abs() < 1e-12, "{lo:?}");
    }
    assert!(
        (hi[0] - 0.030).abs() < 1e-12
            && (hi[1] - 0.020).abs() < 1e-12
            && (hi[2] - 0.020).abs() < 1e-12,
        "{hi:?}"
    );
    let total: f64 = (0..12).map(|e| volume(m, e)).sum();
    assert!((total - 1.2e-5).abs() < 1e-15, "total volume {total}");
    assert_eq!(m.part_names, names, "part names");
    for p in 0..2 {
        let v: f64 = (0..12)
            .filter(|&e| m.element_part[e] == p as u32)
            .map(|e| volume(m, e))
            .sum();
        assert!(
            (v - 6e-6).abs() < 1e-15,
            "part {} volume {v}",
            m.part_names[p]
        );
    }
}

#[test]
fn vtk_xml_in_every_encoding() {
    for f in [
        "vtk-appended-zlib.vtu",
        "vtk-binary-base64.vtu",
        "vtk-ascii.vtu",
        "vtk-appended-lz4.vtu",
        "vtk-appended-plain.vtu",
    ] {
        let m = read_mesh(&file(f), 1.0).unwrap_or_else(|e| panic!("{f}: {e}"));
        check_block(&m.mesh, ["left", "right"]);
        assert!(m.notes.is_empty(), "{f}: {:?}", m.notes);
    }
}

#[test]
fn vtk_legacy_ascii_and_binary() {
    for f in ["vtk-legacy-ascii.vtk", "vtk-legacy-binary.vtk"] {
        let m = read_mesh(&file(f), 1.0).unwrap_or_else(|e| panic!("{f}: {e}"));
        check_block(&m.mesh, ["left", "right"]);
    }
}

#[test]
fn meshio_default_ascii_and_legacy() {
    // meshio keeps no part names: the parts are named by their id.
    for f in [
        "meshio-default.vtu",
        "meshio-ascii.vtu",
        "meshio-legacy.vtk",
    ] {
        let m = read_mesh(&file(f), 1.0).unwrap_or_else(|e| panic!("{f}: {e}"));
        check_block(&m.mesh, ["part_1", "part_2"]);
    }
}

#[test]
fn gmsh_ascii_and_binary_with_physical_groups() {
    for f in ["gmsh.msh", "gmsh-binary.msh"] {
        let m = read_mesh(&file(f), 1.0).unwrap_or_else(|e| panic!("{f}: {e}"));
        let mesh = &m.mesh;
        assert_eq!(mesh.elements.len(), 12, "{f}");
        assert_eq!(mesh.part_names, ["left", "right"], "{f}");
        let total: f64 = (0..12).map(|e| volume(mesh, e)).sum();
        assert!((total - 1.2e-5).abs() < 1e-15, "{f}: {total}");
        // Gmsh's "left" volume is the 10 mm slab (4 hexahedra), "right" the 20 mm one (8).
        let left = mesh.element_part.iter().filter(|&&p| p == 0).count();
        assert_eq!(left, 4, "{f}");
        // The physical surface x = 0: a 3 x 3 grid of nodes, all on x = 0.
        let xmin = &mesh.node_sets["xmin"];
        assert_eq!(xmin.len(), 9, "{f}");
        assert!(
            xmin.iter().all(|&n| mesh.nodes[n as usize][0] == 0.0),
            "{f}"
        );
        // The file's quadrilaterals (of the surface) are reported, not meshed.
        assert!(
            m.notes.iter().any(|n| n.contains("quadrilaterals")),
            "{f}: {:?}",
            m.notes
        );
    }
    let e = read_mesh(&file("gmsh.msh"), 1e-3)
        .map(|m| m.mesh.bounds().1[0])
        .unwrap();
    assert!((e - 3e-5).abs() < 1e-18, "units scale coordinates: {e}");
}

#[test]
fn abaqus_part_sections_and_sets_in_mm() {
    let m = read_mesh(&file("abaqus.inp"), 1e-3).unwrap_or_else(|e| panic!("{e}"));
    check_block(&m.mesh, ["FAT", "MUSCLE"]);
    let xmin = &m.mesh.node_sets["XMIN"];
    assert_eq!(xmin.len(), 9);
    assert!(xmin.iter().all(|&n| m.mesh.nodes[n as usize][0] == 0.0));
    assert_eq!(m.mesh.element_sets["ALL"].len(), 12);
    assert_eq!(m.mesh.element_sets["FAT"].len(), 6);
}

fn refusal(name: &str) -> String {
    match read_mesh(&file(name), 1.0) {
        Ok(_) => panic!("{name} was accepted"),
        Err(e) => {
            assert!(e.contains(name), "the message names the file: {e}");
            e
        }
    }
}

#[test]
fn refusals_name_what_is_wrong() {
    let e = refusal("tetra.vtu");
    assert!(e.contains("no hexahedra but 12 tetrahedra"), "{e}");
    let e = refusal("mixed.vtu");
    assert!(e.contains("11 hexahedra and 1 wedge"), "{e}");
    let e = refusal("inverted.vtu");
    assert!(
        e.contains("1 of 12 hexahedra are inverted") && e.contains("cell 0"),
        "{e}"
    );
    let e = refusal("does-not-exist.vtu");
    assert!(e.contains("does not exist"), "{e}");
    // A file of another kind, and a Gmsh file of the old format.
    let dir = tempfile::tempdir().unwrap();
    let stl = dir.path().join("part.stl");
    std::fs::write(&stl, "solid x\nendsolid x\n").unwrap();
    let e = read_mesh(&stl, 1.0).err().unwrap();
    assert!(e.contains(".stl") && e.contains(".msh"), "{e}");
    let old = dir.path().join("old.msh");
    std::fs::write(&old, "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n").unwrap();
    let e = read_mesh(&old, 1.0).err().unwrap();
    assert!(e.contains("format 2.2") && e.contains("4.1"), "{e}");
    let inp = dir.path().join("tet.inp");
    std::fs::write(
        &inp,
        "*Node\n1, 0, 0, 0\n2, 1, 0, 0\n3, 0, 1, 0\n4, 0, 0, 1\n*Element, type=C3D4\n1, 1, 2, 3, 4\n",
    )
    .unwrap();
    let e = read_mesh(&inp, 1.0).err().unwrap();
    assert!(e.contains("1 C3D4 elements"), "{e}");
    let bad = dir.path().join("bad.inp");
    std::fs::write(&bad, "*Node\n1, 0, 0, zero\n").unwrap();
    let e = read_mesh(&bad, 1.0).err().unwrap();
    assert!(
        e.contains("bad.inp:2") && e.contains("`zero` is not a number"),
        "{e}"
    );
}

/// Uniaxial compression of the block on rollers ([`common::roller_compression`]); the final x0
/// support reaction (N).
fn compression(mesh: &str, parts: [&str; 2]) -> f64 {
    common::roller_compression(
        mesh,
        &parts,
        "plane_axis = \"x\"\nplane_value = \"0 mm\"",
        "mesh-file",
    )
}

/// Closed form of the neo-Hookean bar in uniaxial stress (as in compression_block.rs).
fn closed_form(e: f64, nu: f64, lx: f64, area: f64) -> f64 {
    let mu = e / (2.0 * (1.0 + nu));
    let lam = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let s22 = |lt: f64| mu * (1.0 - 1.0 / (lt * lt)) + lam * (lx * lt * lt).ln() / (lt * lt);
    let mut lt = 1.0;
    for _ in 0..60 {
        let h = 1e-7;
        lt -= s22(lt) / ((s22(lt + h) - s22(lt - h)) / (2.0 * h));
    }
    let j = lx * lt * lt;
    -lx * (mu * (1.0 - 1.0 / (lx * lx)) + lam * j.ln() / (lx * lx)) * area
}

#[test]
fn every_file_runs_to_the_box_twin_and_the_closed_form() {
    let twin = compression(
        "generator = \"box\"\nsize = [\"30 mm\", \"20 mm\", \"20 mm\"]\ndivisions = [3, 2, 2]\npart = \"a\"",
        ["a", "a"],
    );
    let exact = closed_form(1e6, 0.3, 0.95, 4e-4);
    let rel = (twin - exact) / exact;
    println!(
        "box twin {twin:.9} N, closed form {exact:.9} N ({:+.3e})",
        rel
    );
    assert!(rel.abs() < 5e-3, "twin {twin} vs closed form {exact}");
    let cases: [(&str, &str, [&str; 2]); 7] = [
        ("vtk-appended-zlib.vtu", "", ["left", "right"]),
        ("vtk-legacy-binary.vtk", "", ["left", "right"]),
        ("meshio-default.vtu", "", ["part_1", "part_2"]),
        ("meshio-ascii.vtu", "", ["part_1", "part_2"]),
        ("gmsh.msh", "units = \"m\"", ["left", "right"]),
        ("gmsh-binary.msh", "units = \"m\"", ["left", "right"]),
        ("abaqus.inp", "units = \"mm\"", ["FAT", "MUSCLE"]),
    ];
    for (f, units, parts) in cases {
        let r = compression(&format!("file = \"../tests/meshes/{f}\"\n{units}"), parts);
        let d = (r - twin) / twin;
        println!("{f}: {r:.9} N, {d:+.2e} against the box twin");
        assert!(d.abs() < 1e-9, "{f}: {r} against the twin's {twin}");
    }
}

/// palpa's own frames: zlib-compressed, the part names in the field data; read back, the mesh
/// is the same bit for bit, names included. The indenter file holds the surfaces and names.
#[test]
fn palpa_frames_keep_part_names_and_draw_indenters() {
    use solver::output::vtk::{write_surfaces, write_vtu, Frame, RigidSurface};
    let mut mesh = solver::generate::box_mesh(
        &solver::generate::BoxSpec {
            size: [0.03, 0.02, 0.01],
            divisions: [3, 2, 1],
            grading: [1.3, 1.0, 1.0],
            ..Default::default()
        },
        "fat",
    )
    .unwrap();
    mesh.part_names = vec!["fat".into(), "liver tissue".into()];
    mesh.element_part = (0..6).map(|e| (e % 2) as u32).collect();
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("frame.vtu");
    let frame = Frame {
        part: true,
        ..Default::default()
    };
    write_vtu(&p, &mesh, &frame, "t").unwrap();
    let text = std::fs::read(&p).unwrap();
    assert!(
        String::from_utf8_lossy(&text[..300]).contains("compressor=\"vtkZLibDataCompressor\""),
        "frames are compressed"
    );
    let back = read_mesh(&p, 1.0).unwrap().mesh;
    assert_eq!(back.nodes, mesh.nodes);
    assert_eq!(back.elements, mesh.elements);
    assert_eq!(back.element_part, mesh.element_part);
    assert_eq!(back.part_names, mesh.part_names);

    let sq = RigidSurface {
        name: "finger".into(),
        vertices: vec![[0.0; 3], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
        polygons: vec![vec![0, 1, 2, 3], vec![0, 2, 3]],
        displacement: [0.0, 0.0, -1e-3],
    };
    let s = dir.path().join("indenters.vtu");
    write_surfaces(
        &s,
        &[
            sq.clone(),
            RigidSurface {
                name: "thumb".into(),
                ..sq
            },
        ],
        "t",
    )
    .unwrap();
    let names = solver::mesh_io::xml::field_strings(&std::fs::read(&s).unwrap(), "indenter_names");
    assert_eq!(names.unwrap(), ["finger", "thumb"]);
    let e = read_mesh(&s, 1.0).err().unwrap();
    assert!(
        e.contains("no hexahedra") && e.contains("2 quadrilaterals, 2 triangles"),
        "{e}"
    );
}

/// Read a legacy .vtk written from `text` (a temporary file); the error or the mesh.
fn read_legacy_text(text: &str) -> Result<solver::mesh_io::Imported, String> {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("bad.vtk");
    std::fs::write(&p, text).unwrap();
    read_mesh(&p, 1.0)
}

const LEGACY_HEAD: &str = "# vtk DataFile Version 3.0\nbad\nASCII\nDATASET UNSTRUCTURED_GRID\n";

#[test]
fn legacy_vtk_with_a_huge_point_count_is_an_error_not_an_abort() {
    for n in ["10000000000000000000", "6148914691236517206", "4294967297"] {
        let e = read_legacy_text(&format!("{LEGACY_HEAD}POINTS {n} float\n0 0 0\n"))
            .err()
            .expect("an error");
        assert!(e.contains("bad.vtk"), "{e}");
    }
}

#[test]
fn legacy_vtk_cell_with_a_negative_or_fractional_node_is_refused() {
    let pts = "POINTS 8 float\n0 0 0 1 0 0 1 1 0 0 1 0 0 0 1 1 0 1 1 1 1 0 1 1\n";
    for conn in ["8 -1 1 2 3 4 5 6 7", "8 0 1 2 3.5 4 5 6 7"] {
        let text = format!("{LEGACY_HEAD}{pts}CELLS 1 9\n{conn}\nCELL_TYPES 1\n12\n");
        let e = read_legacy_text(&text).err().expect("an error");
        assert!(e.contains("not a whole non-negative number"), "{e}");
    }
    // The same cell with valid ids reads.
    let text = format!("{LEGACY_HEAD}{pts}CELLS 1 9\n8 0 1 2 3 4 5 6 7\nCELL_TYPES 1\n12\n");
    assert_eq!(read_legacy_text(&text).unwrap().mesh.elements.len(), 1);
}

#[test]
fn abaqus_reference_point_at_the_assembly_level_is_skipped_with_a_note() {
    // Abaqus/CAE writes a reference point as an assembly-level *Node whose label (1) is also a
    // node of the part.
    let text = std::fs::read_to_string(file("abaqus.inp")).unwrap();
    let text = text.replacen(
        "*End Assembly",
        "*Node\n      1,           0.,           0.,          50.\n*Nset, nset=RP-1\n 1,\n*End Assembly",
        1,
    );
    assert!(text.contains("RP-1"));
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("cae.inp");
    std::fs::write(&p, text).unwrap();
    let m = read_mesh(&p, 1e-3).unwrap_or_else(|e| panic!("{e}"));
    check_block(&m.mesh, ["FAT", "MUSCLE"]);
    assert!(!m.mesh.node_sets.contains_key("RP-1"));
    assert!(
        m.notes
            .iter()
            .any(|n| n.contains("1 node(s) at the assembly level") && n.contains("RP-1")),
        "{:?}",
        m.notes
    );
}

/// Two unit-cell hexahedra side by side in an ASCII `.vtu`, with `parts` as the text of its
/// `part_id` cell array.
fn two_cells_vtu(parts: &str) -> String {
    let mut pts = Vec::new();
    for z in 0..2 {
        for y in 0..2 {
            for x in 0..3 {
                pts.push(format!(
                    "{} {} {}",
                    x as f64 * 0.01,
                    y as f64 * 0.01,
                    z as f64 * 0.01
                ));
            }
        }
    }
    let id = |x: usize, y: usize, z: usize| x + 3 * y + 6 * z;
    let hex = |x0: usize| {
        [
            id(x0, 0, 0),
            id(x0 + 1, 0, 0),
            id(x0 + 1, 1, 0),
            id(x0, 1, 0),
            id(x0, 0, 1),
            id(x0 + 1, 0, 1),
            id(x0 + 1, 1, 1),
            id(x0, 1, 1),
        ]
        .map(|n| n.to_string())
        .join(" ")
    };
    format!(
        r#"<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian">
<UnstructuredGrid><Piece NumberOfPoints="12" NumberOfCells="2">
<CellData><DataArray type="Int32" Name="part_id" format="ascii">{parts}</DataArray></CellData>
<Points><DataArray type="Float64" NumberOfComponents="3" format="ascii">{}</DataArray></Points>
<Cells><DataArray type="Int64" Name="connectivity" format="ascii">{} {}</DataArray>
<DataArray type="Int64" Name="offsets" format="ascii">8 16</DataArray>
<DataArray type="UInt8" Name="types" format="ascii">12 12</DataArray></Cells>
</Piece></UnstructuredGrid></VTKFile>
"#,
        pts.join(" "),
        hex(0),
        hex(1)
    )
}

/// Issue 29: a `part_id` array one entry short was silently dropped (one part "body"); it is
/// an error naming the array and the cell count. A huge part id is only a key: the parts stay
/// dense (no allocation by the id's size).
#[test]
fn vtu_part_id_array_one_short_is_an_error() {
    let tmp = common::tmp_dir("vtu-parts");
    let p = tmp.path().join("short.vtu");
    for parts in ["1", ""] {
        std::fs::write(&p, two_cells_vtu(parts)).unwrap();
        let e = match read_mesh(&p, 1.0) {
            Ok(_) => panic!("part_id `{parts}` for 2 cells must be refused"),
            Err(e) => e,
        };
        assert!(
            e.contains("short.vtu") && e.contains("`part_id`") && e.contains("2 values"),
            "{e}"
        );
    }
    std::fs::write(&p, two_cells_vtu("2147483647 0")).unwrap();
    let m = read_mesh(&p, 1.0).unwrap().mesh;
    assert_eq!(m.part_names, vec!["part_0", "part_2147483647"]);
    assert_eq!(m.element_part, vec![1, 0]);
}

/// Issue 29: a cut or foreign `.vtu` was refused with vtkio's error printed as Rust
/// (`InvalidXml(IllFormed(MissingEndTag("DataArray")))`); the message now says what is wrong in
/// words and names the file.
#[test]
fn a_cut_or_foreign_vtu_is_refused_in_words() {
    let tmp = common::tmp_dir("vtu-words");
    let whole = two_cells_vtu("0 1");
    let p = tmp.path().join("cut.vtu");
    let cut_at = whole.find("<DataArray").unwrap() + 40;
    for (text, want) in [
        (&whole[..cut_at], "ends early or is cut off"),
        ("garbage\0\u{1}", "not VTK XML"),
        (
            "<VTKFile type=\"UnstructuredGrid\"><a></a></VTKFile>",
            "malformed VTK XML: unknown variant `a`",
        ),
    ] {
        std::fs::write(&p, text).unwrap();
        let e = match read_mesh(&p, 1.0) {
            Ok(_) => panic!("{text:?} must be refused"),
            Err(e) => e,
        };
        assert!(e.contains("cut.vtu") && e.contains(want), "{e}");
        assert!(
            !e.contains("InvalidXml")
                && !e.contains("IllFormed")
                && !e.contains("Deserialization")
                && !e.contains("Custom("),
            "{e}"
        );
    }
}

/// Found by the vtu fuzz target (docs/fuzzing.md): a zlib-compressed array whose block header
/// is damaged (here the `offsets` array's) made vtkio slice past its data and panic; it is an
/// error naming the file.
#[test]
fn a_vtu_with_a_damaged_compressed_header_is_an_error_not_a_panic() {
    let e = read_mesh(&file("damaged-zlib-header.vtu"), 1.0)
        .map(|_| ())
        .unwrap_err();
    assert!(
        e.contains("damaged-zlib-header.vtu: the file's data is damaged: the VTK XML reader (vtkio) failed on it"),
        "{e}"
    );
}

/// Read `bytes` as a mesh file named `name` (a temporary file); the error or the mesh.
fn read_bytes(name: &str, bytes: &[u8]) -> Result<solver::mesh_io::Imported, String> {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join(name);
    std::fs::write(&p, bytes).unwrap();
    read_mesh(&p, 1.0)
}

/// One hexahedron in Gmsh 4.1 ASCII, its `$Nodes` and `$Elements` headers given.
fn one_hex_msh(nodes_header: &str, elements_header: &str) -> String {
    format!(
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n{nodes_header}\n3 1 0 8\n1\n2\n3\n4\n5\n6\n7\n8\n\
         0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n$EndNodes\n\
         $Elements\n{elements_header}\n3 1 5 1\n1 1 2 3 4 5 6 7 8\n$EndElements\n"
    )
}

/// Found by the gmsh fuzz target (docs/fuzzing.md): a `$MeshFormat` data size mshio has no
/// reader for (9 in a binary file) or one too large for its integer (8000000000) made it panic;
/// both are errors naming the field.
#[test]
fn gmsh_with_an_unreadable_data_size_is_an_error_not_a_panic() {
    for (text, bad) in [
        (
            &b"$MeshFormat\n4.1 1 9\n\x01\0\0\0\n$EndMeshFormat\n"[..],
            "`9`",
        ),
        (
            b"$MeshFormat\n4.1 0 8000000000\n$EndMeshFormat\n",
            "`8000000000`",
        ),
        (b"$MeshFormat\n4.1 2 8\n$EndMeshFormat\n", "file type `2`"),
    ] {
        let e = read_bytes("bad.msh", text).err().expect("an error");
        assert!(e.contains("bad.msh: $MeshFormat") && e.contains(bad), "{e}");
    }
    assert_eq!(
        read_bytes("good.msh", one_hex_msh("1 8 1 8", "1 1 1 1").as_bytes())
            .unwrap()
            .mesh
            .elements
            .len(),
        1
    );
}

/// Found by the gmsh fuzz target: a `$Nodes` or `$Elements` header stating 0 entries made
/// mshio subtract 1 from 0 (a panic in debug and test builds); ASCII and binary.
#[test]
fn gmsh_section_of_zero_nodes_or_elements_is_an_error_not_a_panic() {
    let e = read_bytes("bad.msh", one_hex_msh("1 0 1 8", "1 1 1 1").as_bytes())
        .err()
        .expect("an error");
    assert!(
        e.contains("bad.msh: line 5: the $Nodes section's header states 0 nodes"),
        "{e}"
    );
    let e = read_bytes("bad.msh", one_hex_msh("1 8 1 8", "1 0 1 1").as_bytes())
        .err()
        .expect("an error");
    assert!(
        e.contains("line 25: the $Elements section's header states 0 elements"),
        "{e}"
    );
    // the binary file with its node count (the second size_t of the header) set to 0
    let mut b = std::fs::read(file("gmsh-binary.msh")).unwrap();
    let at = b.windows(8).position(|w| w == b"\n$Nodes\n").unwrap() + 8;
    b[at + 8..at + 16].copy_from_slice(&0u64.to_le_bytes());
    let e = read_bytes("bad.msh", &b).err().expect("an error");
    assert!(
        e.contains("the $Nodes section's header states 0 nodes"),
        "{e}"
    );
}

/// Found by the gmsh fuzz target: a physical tag of -2^31 in `$Entities` overflowed its
/// absolute value (a panic in debug and test builds).
#[test]
fn gmsh_physical_tag_of_i32_min_is_an_error_not_a_panic() {
    let text = one_hex_msh("1 8 1 8", "1 1 1 1").replace(
        "$Nodes",
        "$Entities\n0 0 0 1\n1 0 0 0 1 1 1 1 -2147483648 0\n$EndEntities\n$Nodes",
    );
    let e = read_bytes("bad.msh", text.as_bytes())
        .err()
        .expect("an error");
    assert!(
        e.contains("$Entities: the volume 1 has the physical tag -2147483648, out of range"),
        "{e}"
    );
}

/// Found while fuzzing gmsh (by reading the reader, not by afl): contiguous node tags that run
/// past 2^64 overflowed, and a node block giving a tag twice silently lost a node.
#[test]
fn gmsh_node_tags_past_2_64_or_given_twice_are_errors() {
    // contiguous tags from 2^64 - 1: mshio reads the tags (any) and numbers the nodes from the
    // header's minimum
    let max = u64::MAX;
    let text = one_hex_msh(&format!("1 8 {max} {max}"), "1 1 1 1");
    let e = read_bytes("bad.msh", text.as_bytes())
        .err()
        .expect("an error");
    assert!(
        e.contains("node tags from 18446744073709551615 run past 2^64"),
        "{e}"
    );
    // sparse tags (1, 1, 3, ...): the block gives tag 1 twice
    let text = one_hex_msh("1 8 1 20", "1 1 1 1").replace("3 1 0 8\n1\n2\n", "3 1 0 8\n1\n1\n");
    let e = read_bytes("bad.msh", text.as_bytes())
        .err()
        .expect("an error");
    assert!(e.contains("node block 1 gives a node tag twice"), "{e}");
}

/// Found while fuzzing abaqus (by reading the reader; afl did not reach it in 5 minutes): a
/// `generate` line over the whole i64 range overflowed `last - first` (a panic in debug
/// builds; in release the wrapped count passed the 1e8 limit and the range was listed id by
/// id, a hang; 40 ranges of 1e8 ids were 4e9), and a set that lists itself doubled at each
/// `*Nset` (60 lines of 15 bytes, 2^60 ids). Ranges are now kept as ranges and sets hold each
/// label once.
#[test]
fn abaqus_huge_generate_range_or_self_doubling_set_is_an_error_or_cheap_not_a_hang() {
    let hex = "*Node\n1, 0, 0, 0\n2, 1, 0, 0\n3, 1, 1, 0\n4, 0, 1, 0\n\
               5, 0, 0, 1\n6, 1, 0, 1\n7, 1, 1, 1\n8, 0, 1, 1\n\
               *Element, type=C3D8, elset=E\n1, 1, 2, 3, 4, 5, 6, 7, 8\n";
    let t = std::time::Instant::now();
    let text =
        format!("{hex}*Nset, nset=A, generate\n-9223372036854775808, 9223372036854775807, 1\n");
    let e = read_bytes("bad.inp", text.as_bytes())
        .err()
        .expect("an error");
    assert!(
        e.contains(
            "bad.inp:12: node set `A` lists node -9223372036854775808, which no *Node defines"
        ),
        "{e}"
    );
    // an element set over the whole range keeps the hexahedra it spans
    let text =
        format!("{hex}*Elset, elset=ALL, generate\n-9223372036854775808, 9223372036854775807, 1\n");
    let m = read_bytes("big.inp", text.as_bytes()).unwrap();
    assert_eq!(m.mesh.element_sets["ALL"], [0]);
    // 40 ranges of 1e8 labels each (4e9 ids listed one by one before)
    let text = format!(
        "{hex}{}",
        "*Elset, elset=MANY, generate\n1, 99999999, 1\n".repeat(40)
    );
    let m = read_bytes("many.inp", text.as_bytes()).unwrap();
    assert_eq!(m.mesh.element_sets["MANY"], [0]);
    // a set that lists itself twice, 60 times over
    let text = format!(
        "{hex}*Nset, nset=A\n1, 2\n{}",
        "*Nset, nset=A\nA, A\n".repeat(60)
    );
    let m = read_bytes("twice.inp", text.as_bytes()).unwrap();
    assert_eq!(m.mesh.node_sets["A"].len(), 2);
    // a generate range with a step, and the nodes of a range that a *Node does not define
    let text = format!("{hex}*Nset, nset=ODD, generate\n1, 8, 2\n");
    let m = read_bytes("odd.inp", text.as_bytes()).unwrap();
    assert_eq!(m.mesh.node_sets["ODD"].len(), 4);
    let text = format!("{hex}*Nset, nset=B, generate\n1, 9, 2\n");
    let e = read_bytes("bad.inp", text.as_bytes())
        .err()
        .expect("an error");
    assert!(e.contains("lists node 9"), "{e}");
    assert!(t.elapsed().as_secs_f64() < 5.0, "{:?}", t.elapsed());
}
