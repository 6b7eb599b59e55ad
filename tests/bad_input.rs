//! Bad input gets a clear message naming the file, the field or the element, a non-zero exit
//! and no panic (issue 2): malformed TOML, unknown key, unknown unit, negative modulus,
//! inverted element, missing file.

use std::path::Path;
use std::process::Command;

const GOOD: &str = r#"
[run]
end_time = "1 ms"
[mesh]
generator = "box"
size = ["10 mm", "10 mm", "10 mm"]
divisions = [2, 2, 2]
part = "block"
[materials.rubber]
law = "neo_hookean"
density = "1000 kg/m^3"
youngs_modulus = "1 MPa"
poisson_ratio = 0.3
[[part]]
name = "block"
material = "rubber"
[[boundary]]
nodes = "zmin"
fix = ["all"]
"#;

/// A fresh temporary directory, removed when the returned guard drops.
fn dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("palpa-bad-{name}-"))
        .tempdir()
        .unwrap()
}

/// Run `palpa check FILE` and return (exit ok?, stderr).
fn check(path: &Path) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_palpa"))
        .arg("check")
        .arg(path)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!err.contains("panicked"), "panic: {err}");
    (out.status.success(), err)
}

fn bad(name: &str, scene: &str, expect: &[&str]) {
    let tmp = dir(name);
    let d = tmp.path();
    let p = d.join(format!("{name}.toml"));
    std::fs::write(&p, scene).unwrap();
    let (ok, err) = check(&p);
    assert!(!ok, "{name}: should fail");
    assert!(
        err.contains(&format!("{name}.toml")),
        "{name}: message must name the file: {err}"
    );
    for e in expect {
        assert!(err.contains(e), "{name}: message must contain `{e}`: {err}");
    }
}

#[test]
fn good_scene_passes() {
    let tmp = dir("good");
    let d = tmp.path();
    let p = d.join("good.toml");
    std::fs::write(&p, GOOD).unwrap();
    let (ok, err) = check(&p);
    assert!(ok, "{err}");
}

#[test]
fn malformed_toml() {
    bad(
        "malformed",
        &GOOD.replace("end_time = \"1 ms\"", "end_time = \"1 ms"),
        &["line 3"],
    );
}

#[test]
fn unknown_key() {
    bad(
        "unknown_key",
        &GOOD.replace("poisson_ratio = 0.3", "poisson_ratio = 0.3\nposson = 0.3"),
        &["posson"],
    );
    bad(
        "unknown_key_run",
        &GOOD.replace("end_time = \"1 ms\"", "end_time = \"1 ms\"\nendtime = 3"),
        &["endtime", "line 4"],
    );
}

#[test]
fn unknown_unit() {
    bad(
        "unknown_unit",
        &GOOD.replace("\"1 MPa\"", "\"1 Mpascal\""),
        &["unknown unit `Mpascal`"],
    );
    bad(
        "wrong_dimension",
        &GOOD.replace("end_time = \"1 ms\"", "end_time = \"1 mm\""),
        &["expected a time", "line 3"],
    );
}

#[test]
fn negative_modulus() {
    bad(
        "negative_modulus",
        &GOOD.replace("\"1 MPa\"", "\"-1 MPa\""),
        &["rubber", "youngs_modulus", "positive"],
    );
}

#[test]
fn unknown_node_set_and_material() {
    bad(
        "unknown_set",
        &GOOD.replace("nodes = \"zmin\"", "nodes = \"bottom\""),
        &["no node set `bottom`", "boundary[0].nodes"],
    );
    bad(
        "unknown_material",
        &GOOD.replace("material = \"rubber\"", "material = \"rubbr\""),
        &["no material `rubbr`"],
    );
}

#[test]
fn missing_files() {
    let tmp = dir("missing");
    let d = tmp.path();
    let (ok, err) = check(&d.join("nope.toml"));
    assert!(
        !ok && err.contains("nope.toml") && err.contains("cannot read"),
        "{err}"
    );
    let scene = GOOD.replace(
        "generator = \"box\"\nsize = [\"10 mm\", \"10 mm\", \"10 mm\"]\ndivisions = [2, 2, 2]\npart = \"block\"",
        "file = \"absent.vtu\"",
    );
    bad("missing_mesh", &scene, &["absent.vtu", "does not exist"]);
}

#[test]
fn inverted_element_is_named() {
    let tmp = dir("inverted");
    let d = tmp.path();
    let mut mesh = solver::generate::box_mesh(
        &solver::generate::BoxSpec {
            size: [0.01; 3],
            divisions: [2, 2, 2],
            ..Default::default()
        },
        "body",
    )
    .unwrap();
    // Mirror element 5: swap its bottom and top faces.
    let c = mesh.elements[5];
    mesh.elements[5] = [c[4], c[5], c[6], c[7], c[0], c[1], c[2], c[3]];
    let frame = solver::output::vtk::Frame {
        part: true,
        ..Default::default()
    };
    solver::output::vtk::write_vtu(&d.join("inv.vtu"), &mesh, &frame, "inverted").unwrap();
    let scene = GOOD
        .replace(
            "generator = \"box\"\nsize = [\"10 mm\", \"10 mm\", \"10 mm\"]\ndivisions = [2, 2, 2]\npart = \"block\"",
            "file = \"inv.vtu\"",
        )
        .replace("name = \"block\"", "name = \"body\"")
        .replace("nodes = \"zmin\"", "nodes = \"all\"");
    let p = d.join("inverted.toml");
    std::fs::write(&p, scene).unwrap();
    let (ok, err) = check(&p);
    assert!(!ok);
    assert!(
        err.contains("inv.vtu") && err.contains("cell 5") && err.contains("non-positive Jacobian"),
        "{err}"
    );
}
