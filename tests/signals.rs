//! Signals and closed pipes through the real binary (issue 29):
//! - `palpa check SCENE | head -1`: stdout closed before palpa printed panicked in `println!`
//!   (exit 101, "failed printing to stdout"); it now ends quietly, as any Unix tool does,
//!   by SIGPIPE;
//! - Ctrl-C on `palpa run` exited 0 as if the run had finished; it now exits 130 after writing
//!   the output it has, complete.
#![cfg(unix)]

use std::os::unix::process::ExitStatusExt;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

#[path = "support/block.rs"]
mod block;

fn scene(dir: &std::path::Path, end: &str) -> std::path::PathBuf {
    let p = dir.join("s.toml");
    std::fs::write(&p, block::BLOCK.replace("\"1 ms\"", &format!("\"{end}\""))).unwrap();
    p
}

#[test]
fn broken_pipe_on_check_is_quiet() {
    let tmp = tempfile::tempdir().unwrap();
    let p = scene(tmp.path(), "1 ms");
    let mut child = Command::new(env!("CARGO_BIN_EXE_palpa"))
        .arg("check")
        .arg(&p)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Close the reading end before palpa prints its first line.
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked"), "panic: {err}");
    assert_ne!(out.status.code(), Some(101), "{err}");
    assert!(
        out.status.success() || out.status.signal() == Some(13),
        "status {:?}: {err}",
        out.status
    );
}

#[test]
fn ctrl_c_on_run_exits_130_with_complete_output() {
    let tmp = tempfile::tempdir().unwrap();
    let p = scene(tmp.path(), "1000 s");
    let out_dir = tmp.path().join("out");
    let mut child = Command::new(env!("CARGO_BIN_EXE_palpa"))
        .arg("run")
        .arg(&p)
        .arg("--out")
        .arg(&out_dir)
        .arg("--quiet")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Wait until it runs (its first frame is written), then interrupt it.
    let t0 = Instant::now();
    while !out_dir.join("history.csv").is_file() && t0.elapsed() < Duration::from_secs(60) {
        assert!(child.try_wait().unwrap().is_none(), "palpa run ended early");
        std::thread::sleep(Duration::from_millis(50));
    }
    std::thread::sleep(Duration::from_millis(300));
    let pid = child.id().to_string();
    assert!(Command::new("kill")
        .args(["-INT", &pid])
        .status()
        .unwrap()
        .success());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked"), "panic: {err}");
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert!(err.contains("Ctrl-C"), "{err}");
    // What it wrote reads back whole.
    let (_, rows) = solver::output::history::read_history(&out_dir.join("history.csv")).unwrap();
    assert!(!rows.is_empty());
}
