//! The tiny campaign of the campaign tests: 8 mm phantom, three locations, 2 mm in 1 ms, a
//! sample every 0.5 ms (three runs of about a second each).
#![allow(dead_code)]

use std::path::{Path, PathBuf};

/// The campaign file.
pub const TINY: &str = r#"
title = "tiny"
[phantom]
voxel = "8 mm"
[locations]
train = ["P07", "P12"]
test = ["A"]
[indentation]
depth = "2 mm"
duration = "1 ms"
sample_interval = "0.5 ms"
"#;
/// Its runs.
pub const RUNS: usize = 3;
/// Samples per run.
pub const SAMPLES: usize = 3;

/// Writes the campaign file into `dir`.
pub fn tiny(dir: &Path) -> PathBuf {
    let p = dir.join("tiny.toml");
    std::fs::write(&p, TINY).unwrap();
    p
}

/// Finished runs (a `done.json` in their directory) of the campaign in `out`.
pub fn done_count(out: &Path) -> usize {
    std::fs::read_dir(out.join("runs"))
        .map(|d| {
            d.filter(|e| e.as_ref().unwrap().path().join("done.json").is_file())
                .count()
        })
        .unwrap_or(0)
}
