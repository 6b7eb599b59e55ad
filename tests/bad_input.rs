//! Bad input gets a clear message naming the file, the field or the element, a non-zero exit
//! and no panic (issue 2): malformed TOML, unknown key, unknown unit, negative modulus,
//! inverted element, missing file.

use std::path::Path;
use std::process::Command;

#[path = "support/block.rs"]
mod block;
use block::BLOCK as GOOD;

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
    // a material card's key: toml places it at the card's `[materials.NAME]` header; palpa
    // names its own line
    let scene = GOOD.replace("poisson_ratio = 0.3", "poisson_ratio = 0.3\nposson = 0.3");
    let line = 1 + scene.lines().position(|l| l.starts_with("posson")).unwrap();
    bad(
        "unknown_key",
        &scene,
        &["posson", &format!("line {line}, column 1")],
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

// Issue 29: values the mutation probe found accepted, aborting or hanging.

#[test]
fn infinite_end_time() {
    bad(
        "end_time_inf",
        &GOOD.replace("end_time = \"1 ms\"", "end_time = inf"),
        &["run.end_time", "finite", "end_time_inf.toml:3"],
    );
}

#[test]
fn negative_history_interval() {
    bad(
        "negative_history",
        &format!("{GOOD}[output]\nhistory_interval = \"-1 ms\"\n"),
        &["output.history_interval", "positive"],
    );
}

#[test]
fn negative_bulk_viscosity() {
    bad(
        "negative_bulk",
        &format!("{GOOD}[bulk_viscosity]\nquadratic = -1\n"),
        &["bulk_viscosity.quadratic", "got -1"],
    );
}

#[test]
fn absurd_divisions_refused_before_allocating() {
    bad(
        "divisions_u32",
        &GOOD.replace("[2, 2, 2]", "[4294967297, 1, 1]"),
        &["mesh.divisions", "4.2950e9 elements", "max_elements"],
    );
    bad(
        "divisions_1e9",
        &GOOD.replace("[2, 2, 2]", "[1000000000, 6, 6]"),
        &["mesh.divisions", "3.6000e10 elements", "limit of 50000000"],
    );
    // Raising the limit is possible (and then the node ids are the limit).
    bad(
        "divisions_raised",
        &GOOD.replace("[2, 2, 2]", "[4294967297, 1, 1]\nmax_elements = 1e12"),
        &["more than node ids can number"],
    );
}

#[test]
fn non_physical_moduli_and_densities() {
    // A huge stable step (0 estimated steps, then a run that never returned) ...
    bad(
        "tiny_modulus",
        &GOOD.replace("\"1 MPa\"", "\"1e-320 Pa\""),
        &["part `block`", "wave speed", "not physical"],
    );
    bad(
        "huge_density",
        &GOOD.replace("\"1000 kg/m^3\"", "\"1e308 kg/m^3\""),
        &["part `block`", "density 1e308"],
    );
    // ... and a tiny one (1.7e152 estimated steps).
    bad(
        "tiny_density",
        &GOOD.replace("\"1000 kg/m^3\"", "\"1e-300 kg/m^3\""),
        &["part `block`", "density 1e-300", "wave speed"],
    );
}

#[test]
fn too_many_steps_refused_unless_raised() {
    // 1e6 s of a 5 mm rubber block: about 8e9 steps.
    let long = GOOD.replace("end_time = \"1 ms\"", "end_time = \"1e6 s\"")
        + "[output]\nvtk = false\nhistory_interval = \"10 s\"\n";
    bad("too_many_steps", &long, &["time steps", "max_steps"]);
    let tmp = dir("raised_steps");
    let p = tmp.path().join("raised.toml");
    std::fs::write(
        &p,
        long.replace(
            "end_time = \"1e6 s\"",
            "end_time = \"1e6 s\"\nmax_steps = 1e11",
        ),
    )
    .unwrap();
    let (ok, err) = check(&p);
    assert!(ok, "{err}");
}

#[test]
fn tiny_output_intervals() {
    bad(
        "tiny_frames",
        &format!("{GOOD}[output]\ninterval = \"1e-9 ms\"\n"),
        &["output.interval", "1.000e9 frames", "max_outputs"],
    );
    bad(
        "tiny_history",
        &format!("{GOOD}[output]\nhistory_interval = \"1e-320 s\"\n"),
        &["output.history_interval", "history rows", "max_outputs"],
    );
}
