//! The `palpa material` and `palpa mesh` commands, through the real binary: the material-point
//! driver's CSV, its error for a missing file, a coarse reduced phantom, and a NIfTI round
//! trip (phantom labels out, `mesh image` back in, same mesh).

use std::path::Path;
use std::process::{Command, Output};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A fresh temporary directory, removed when the returned guard drops.
fn dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("palpa-cli-mm-{name}-"))
        .tempdir()
        .unwrap()
}

fn palpa(args: &[&str]) -> Output {
    let out = Command::new(env!("CARGO_BIN_EXE_palpa"))
        .args(args)
        .current_dir(root())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked"), "panic: {err}");
    out
}

fn ok(args: &[&str]) -> String {
    let out = palpa(args);
    assert!(
        out.status.success(),
        "palpa {args:?} failed:\n{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn material_driver_writes_finite_csv() {
    let csv = ok(&["material", "scenes/materials/liver-uniaxial.toml"]);
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header[0], "time", "{header:?}");
    assert!(header.contains(&"stretch"), "{header:?}");
    assert!(header.contains(&"nominal_stress"), "{header:?}");
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse::<f64>().unwrap()).collect())
        .collect();
    // three ramps of 200 steps each, plus the undeformed first row
    assert_eq!(rows.len(), 601);
    for r in &rows {
        assert_eq!(r.len(), header.len());
        assert!(r.iter().all(|v| v.is_finite()), "{r:?}");
    }
    // the path goes to stretch 1.3 and ends at 1.0
    let s = header.iter().position(|h| *h == "stretch").unwrap();
    let max = rows.iter().map(|r| r[s]).fold(f64::MIN, f64::max);
    assert!((max - 1.3).abs() < 1e-9 && (rows.last().unwrap()[s] - 1.0).abs() < 1e-9);

    // --out writes the same table to a file
    let tmp = dir("material-out");
    let d = tmp.path();
    let f = d.join("liver.csv");
    ok(&[
        "material",
        "scenes/materials/liver-uniaxial.toml",
        "--out",
        f.to_str().unwrap(),
    ]);
    assert_eq!(std::fs::read_to_string(&f).unwrap(), csv);
}

#[test]
fn material_errors_name_the_file() {
    let out = palpa(&["material", "no/such/driver.toml"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("no/such/driver.toml"), "{err}");

    let tmp = dir("material-bad");
    let d = tmp.path();
    let f = d.join("typo.toml");
    std::fs::write(
        &f,
        "material = \"paper:ribs\"\nmode = \"uniaxial_stress\"\n[[segment]]\nramp_to = 1.01\nduraton = \"1 s\"\n",
    )
    .unwrap();
    let out = palpa(&["material", f.to_str().unwrap()]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("typo.toml") && err.contains("duraton"),
        "{err}"
    );
}

/// "N nodes, M hexahedra" and the per-part lines of the report.
fn counts(report: &str, parts: &[&str]) -> (usize, usize, Vec<usize>) {
    let l = report
        .lines()
        .find(|l| l.ends_with(" hexahedra"))
        .expect("no `N nodes, M hexahedra` line");
    let w: Vec<&str> = l.split_whitespace().collect();
    let nodes = w[0].parse().unwrap();
    let hexes = w[2].parse().unwrap();
    let per = parts
        .iter()
        .map(|p| {
            let l = report
                .lines()
                .find(|l| l.split_whitespace().next() == Some(p))
                .unwrap_or_else(|| panic!("no count for part {p}:\n{report}"));
            l.split_whitespace().nth(1).unwrap().parse().unwrap()
        })
        .collect();
    (nodes, hexes, per)
}

fn min_scaled_jacobian(report: &str) -> f64 {
    let l = report
        .lines()
        .find(|l| l.starts_with("scaled Jacobian: min "))
        .expect("no scaled Jacobian line");
    l["scaled Jacobian: min ".len()..]
        .split(',')
        .next()
        .unwrap()
        .parse()
        .unwrap()
}

#[test]
fn coarse_reduced_phantom_mesh() {
    let tmp = dir("phantom");
    let d = tmp.path();
    let vtu = d.join("phantom.vtu");
    let r = ok(&[
        "mesh",
        "phantom",
        "--variant",
        "reduced",
        "--voxel",
        "8mm",
        "--out",
        vtu.to_str().unwrap(),
    ]);
    let (_, hexes, per) = counts(&r, &["flesh", "liver", "ribs", "viscera"]);
    assert!(hexes > 1000, "{r}");
    assert!(per.iter().all(|&c| c > 0), "{r}");
    assert_eq!(per.iter().sum::<usize>(), hexes, "{r}"); // the reduced model has no spine
    let j = min_scaled_jacobian(&r);
    assert!(j > 0.0 && j <= 1.0, "{r}");
    assert!(r.contains("meshing + smoothing wall time"), "{r}");
    let mesh = solver::mesh_io::read_mesh(&vtu, 1.0).unwrap().mesh;
    assert_eq!(mesh.elements.len(), hexes);
    for f in ["roi.json", "roi.csv", "locations.json"] {
        assert!(d.join(f).is_file(), "{f} missing");
    }
}

#[test]
fn nifti_round_trip_gives_the_same_mesh() {
    let tmp = dir("nifti");
    let d = tmp.path();
    let (direct, nii, again) = (d.join("direct.vtu"), d.join("x.nii.gz"), d.join("y.vtu"));
    let map = d.join("map.toml");
    std::fs::write(
        &map,
        "1 = \"flesh\"\n2 = \"liver\"\n3 = \"ribs\"\n4 = \"viscera\"\n5 = \"spine\"\n",
    )
    .unwrap();
    let parts = ["flesh", "liver", "ribs", "viscera"];
    let r1 = ok(&[
        "mesh",
        "phantom",
        "--voxel",
        "8mm",
        "--out",
        direct.to_str().unwrap(),
        "--out",
        nii.to_str().unwrap(),
    ]);
    let r2 = ok(&[
        "mesh",
        "image",
        nii.to_str().unwrap(),
        "--labels",
        map.to_str().unwrap(),
        "--out",
        again.to_str().unwrap(),
    ]);
    // The .nii.gz holds the volume the phantom meshed: cropped to the reduced box already (so
    // the crop is not redone) and *before* clean-up, which `mesh image` then repeats with the
    // same options. Clean-up and hexahedron generation depend only on the labels, which the
    // uint8 NIfTI stores exactly, so node and element counts, connectivity and parts must be
    // identical. Only the affine goes through f32 millimetres, so node positions may differ
    // by rounding (~1e-5 mm), which smoothing cannot turn into a different topology.
    let (n1, e1, p1) = counts(&r1, &parts);
    let (n2, e2, p2) = counts(&r2, &parts);
    assert_eq!((n1, e1, p1), (n2, e2, p2), "direct:\n{r1}\nimage:\n{r2}");
    let a = solver::mesh_io::read_mesh(&direct, 1.0).unwrap().mesh;
    let b = solver::mesh_io::read_mesh(&again, 1.0).unwrap().mesh;
    assert_eq!(a.elements, b.elements);
    assert_eq!(a.element_part, b.element_part);
    let dmax = a
        .nodes
        .iter()
        .zip(&b.nodes)
        .map(|(p, q)| (0..3).map(|k| (p[k] - q[k]).abs()).fold(0.0, f64::max))
        .fold(0.0, f64::max);
    // 1 um against an 8 mm voxel
    assert!(dmax < 1e-6, "node positions differ by {dmax} m");
}

/// Regression: at a 10 mm voxel the palpation raster point P11 (x = -100 mm, y = 195 mm) falls
/// on a staircase riser of the skin that smoothing only tilts to n_z = 0.2; the skin used to
/// keep only faces with n_z > 0.3, so the vertical ray cast met a gap and the phantom failed
/// with "location P11 (-0.100, 0.195) m is not over the skin". The skin now keeps every
/// upward-facing outer face.
#[test]
fn reduced_phantom_at_10mm() {
    let tmp = dir("phantom10");
    let d = tmp.path();
    ok(&[
        "mesh",
        "phantom",
        "--variant",
        "reduced",
        "--voxel",
        "10mm",
        "--out",
        d.join("phantom.vtu").to_str().unwrap(),
    ]);
}

/// `palpa mesh import`: a Gmsh file needs its unit; with it, the report lists the parts and
/// sets, and the written .vtu reads back with the part names.
#[test]
fn mesh_import_reports_and_converts() {
    let tmp = dir("import");
    let out = tmp.path().join("block.vtu");
    let r = palpa(&["mesh", "import", "tests/meshes/gmsh.msh"]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        !r.status.success() && err.contains("gmsh.msh") && err.contains("--units"),
        "{err}"
    );
    let r = ok(&[
        "mesh",
        "import",
        "tests/meshes/gmsh.msh",
        "--units",
        "mm",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(r.contains("36 nodes, 12 hexahedra, 2 part(s)"), "{r}");
    assert!(r.contains("extent 0.030 x 0.020 x 0.020 mm"), "{r}");
    assert!(
        r.contains("part_id 0 left") && r.contains("part_id 1 right"),
        "{r}"
    );
    assert!(r.contains("node set    xmin"), "{r}");
    let m = solver::mesh_io::read_mesh(&out, 1.0).unwrap().mesh;
    assert_eq!(m.part_names, ["left", "right"]);
    assert!((m.bounds().1[0] - 3e-5).abs() < 1e-18);
    let r = palpa(&["mesh", "import", "tests/meshes/mixed.vtu"]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        !r.status.success() && err.contains("11 hexahedra and 1 wedge"),
        "{err}"
    );
}

/// Issue 29: a `.nii.gz` whose gzip checksum is wrong was meshed into different anatomy with
/// exit 0, and a truncated one printed the reader's Rust error (`Io(Kind(UnexpectedEof))`);
/// both are errors naming the file in words.
#[test]
fn corrupted_nii_gz_is_refused() {
    let tmp = dir("nifti-bad");
    let d = tmp.path();
    let nii = d.join("x.nii.gz");
    let map = d.join("map.toml");
    std::fs::write(&map, "1 = \"flesh\"\n2 = \"liver\"\n").unwrap();
    ok(&[
        "mesh",
        "phantom",
        "--voxel",
        "8mm",
        "--out",
        nii.to_str().unwrap(),
    ]);
    let bytes = std::fs::read(&nii).unwrap();
    let bad = d.join("bad.nii.gz");
    let image = |label: &str| {
        let out = palpa(&[
            "mesh",
            "image",
            bad.to_str().unwrap(),
            "--labels",
            map.to_str().unwrap(),
            "--out",
            d.join("y.vtu").to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&out.stderr).into_owned();
        assert!(!out.status.success(), "{label}: accepted");
        assert!(
            err.contains("bad.nii.gz") && err.contains("gzip stream is damaged"),
            "{label}: {err}"
        );
        assert!(!err.contains("Kind("), "{label}: {err}");
    };
    // The CRC-32 of the trailer, one bit flipped.
    let mut crc = bytes.clone();
    let n = crc.len();
    crc[n - 8] ^= 1;
    std::fs::write(&bad, &crc).unwrap();
    image("checksum");
    // Cut in the middle of the stream.
    std::fs::write(&bad, &bytes[..bytes.len() / 2]).unwrap();
    image("truncated");
}
