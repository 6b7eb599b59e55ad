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
