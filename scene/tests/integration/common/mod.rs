//! Shared helpers for the solver's integration tests.
#![allow(dead_code)]

use scene::build::build_scene;
use scene::run::run_scene;
use scene::{Scene, SceneSpec};
use std::path::Path;
use std::sync::atomic::AtomicBool;

/// Parse a scene from text (relative paths resolve against the crate directory).
pub fn scene_from_str(src: &str) -> Scene {
    let spec: SceneSpec = toml::from_str(src).expect("scene parses");
    build_scene(
        spec,
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("test.toml")
            .as_path(),
        src,
    )
    .expect("scene builds")
}

/// A fresh temporary output directory, removed when the returned guard drops.
pub fn tmp_dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("palpa-test-{name}-"))
        .tempdir()
        .unwrap()
}

/// Run a scene to its end and return the history (columns, rows).
pub fn run_to_end(scene: &mut Scene, name: &str) -> (Vec<String>, Vec<Vec<f64>>) {
    let tmp = tmp_dir(name);
    let out = tmp.path();
    let (summary, err) = run_scene(scene, out, &AtomicBool::new(false), |_| {});
    assert!(err.is_none(), "run failed: {err:?} ({})", summary.status);
    let h = solver::output::history::read_history(&out.join("history.csv")).unwrap();
    h
}

/// Linear interpolation of `y` at `x = x0` on a monotone increasing `x`.
pub fn interpolate_at(x: &[f64], y: &[f64], x0: f64) -> f64 {
    let i = x.iter().position(|&v| v >= x0).expect("x0 reached");
    let (xa, xb, ya, yb) = (x[i - 1], x[i], y[i - 1], y[i]);
    ya + (yb - ya) * (x0 - xa) / (xb - xa)
}

/// Uniaxial compression of a 30 mm long block on rollers, 5 % in x over 20 ms (neo-Hookean,
/// every part the same material), from the mesh given by `mesh` (a `[mesh]` table body), with
/// the parts `parts` and the x = 0 node set given by `x0` (a `[node_sets.x0]` table body); the
/// final x0 support reaction (N).
pub fn roller_compression(mesh: &str, parts: &[&str], x0: &str, name: &str) -> f64 {
    let part_tables: String = parts
        .iter()
        .map(|p| format!("[[part]]\nname = \"{p}\"\nmaterial = \"m\"\n"))
        .collect();
    let src = format!(
        r#"
[run]
end_time = "25 ms"
[mesh]
{mesh}
[materials.m]
law = "neo_hookean"
density = "1000 kg/m^3"
youngs_modulus = "1 MPa"
poisson_ratio = 0.3
{part_tables}
[node_sets.x0]
{x0}
[node_sets.x1]
plane_axis = "x"
plane_value = "30 mm"
[node_sets.y0]
plane_axis = "y"
plane_value = "0 mm"
[node_sets.z0]
plane_axis = "z"
plane_value = "0 mm"
[[boundary]]
nodes = "x0"
symmetry = "x"
[[boundary]]
nodes = "y0"
symmetry = "y"
[[boundary]]
nodes = "z0"
symmetry = "z"
[[boundary]]
nodes = "x1"
displacement = {{ x = {{ kind = "smooth_step", value = "-1.5 mm", end = "20 ms" }} }}
[output]
history_interval = "1 ms"
reactions = ["x0"]
"#
    );
    let mut scene = scene_from_str(&src);
    let (cols, rows) = run_to_end(&mut scene, name);
    *solver::output::history::column(&cols, &rows, "x0_reaction_x")
        .unwrap()
        .last()
        .unwrap()
}

/// A distorted 30 x 20 x 20 mm block of a nu = 0.45 neo-Hookean solid on a fixed base, its top
/// pressed at 1 m/s and sheared at 0.3 m/s, ending at 2 ms: `FORM` is the formulation and
/// `EXTRA` more tables (the determinism and global-step tests).
pub const PRESSED_BLOCK: &str = r#"
[run]
end_time = "2 ms"
[mesh]
generator = "box"
size = ["30 mm", "20 mm", "20 mm"]
divisions = [30, 12, 10]
distortion = 0.2
part = "block"
[materials.m]
law = "neo_hookean"
density = "1000 kg/m^3"
youngs_modulus = "1 MPa"
poisson_ratio = 0.45
[[part]]
name = "block"
material = "m"
formulation = "FORM"
[[boundary]]
nodes = "zmin"
fix = ["all"]
[[boundary]]
nodes = "zmax"
velocity = { z = { kind = "constant", value = "-1 m/s" }, x = { kind = "constant", value = "0.3 m/s" } }
EXTRA
[output]
vtk = false
"#;

/// A free box of `divisions` elements with `mesh_extra` in `[mesh]`, of a nu = 0.49 linear
/// elastic solid (E = 300 kPa, 1000 kg/m^3), and `run_extra` in `[run]`: the regular block of
/// `verification/python/hex_stability_eigen.py` with 1 mm cubes. Shared with the command-line
/// tests (`tests/check_global_step.rs`).
pub fn free_box(
    run_extra: &str,
    size_mm: [f64; 3],
    divisions: [usize; 3],
    mesh_extra: &str,
) -> String {
    format!(
        r#"
[run]
end_time = "1 ms"
{run_extra}
[mesh]
generator = "box"
size = ["{} mm", "{} mm", "{} mm"]
divisions = [{}, {}, {}]
part = "block"
{mesh_extra}
[materials.m]
law = "linear_elastic"
density = "1000 kg/m^3"
youngs_modulus = "300 kPa"
poisson_ratio = 0.49
[[part]]
name = "block"
material = "m"
[output]
vtk = false
"#,
        size_mm[0], size_mm[1], size_mm[2], divisions[0], divisions[1], divisions[2]
    )
}
