//! Running the real `palpa` binary from a test: its output, success, and no panic.
#![allow(dead_code)]

use std::path::Path;
use std::process::{Command, Output};

/// Run `palpa ARGS`; a panic in its stderr fails the test.
pub fn palpa(args: &[&str]) -> Output {
    let out = Command::new(env!("CARGO_BIN_EXE_palpa"))
        .args(args)
        .output()
        .unwrap();
    assert!(
        !String::from_utf8_lossy(&out.stderr).contains("panicked"),
        "panic: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Run `palpa ARGS` and return its stdout; failure fails the test.
pub fn ok(args: &[&str]) -> String {
    let o = palpa(args);
    let stdout = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(
        o.status.success(),
        "palpa {args:?} failed: {}\n{stdout}",
        String::from_utf8_lossy(&o.stderr)
    );
    stdout
}

/// Asserts that a run of `palpa` failed with `text` in its stderr.
pub fn fails_with(o: &Output, text: &str) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains(text),
        "expected `{text}`:\n{err}"
    );
}

/// Run `palpa predict MODEL --stdin` with `lines` on its stdin; its output.
pub fn predict_stdin(model: &Path, lines: &[u8]) -> Output {
    use std::io::Write as _;
    use std::process::Stdio;
    let mut child = Command::new(env!("CARGO_BIN_EXE_palpa"))
        .args(["predict", s(model), "--stdin"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child.stdin.take().unwrap().write_all(lines).unwrap();
    child.wait_with_output().unwrap()
}

/// A path as a command-line argument.
pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `palpa palpate` as a quick coarse press into `out`: 8 mm voxels, `depth_mm` in a time of the
/// same number of ms, samples every 1 ms, no VTK, and the `extra` options (not yet run, so
/// that a test may set its environment).
pub fn coarse_press(out: &Path, depth_mm: u32, extra: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_palpa"));
    c.arg("palpate")
        .args(extra)
        .args([
            "--voxel",
            "8mm",
            "--sample-interval",
            "1ms",
            "--no-vtk",
            "--quiet",
        ])
        .args(["--duration", &format!("{depth_mm}ms")])
        .args(["--depth", &format!("{depth_mm}mm")])
        .arg("--out")
        .arg(out);
    c
}
