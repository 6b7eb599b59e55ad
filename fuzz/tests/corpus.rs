//! The committed corpus, replayed through the harnesses without afl: every file of
//! `corpus/<target>/` must go through its harness without a panic. `.ci/fuzz.sh` runs this
//! before fuzzing, so the corpus (the seeds and every past finding) keeps guarding the parsers.

use std::path::Path;

#[test]
fn every_corpus_file_goes_through_its_harness_without_a_panic() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("corpus");
    let mut total = 0;
    for (name, harness) in palpa_fuzz::TARGETS {
        let dir = root.join(name);
        let mut files: Vec<_> = std::fs::read_dir(&dir)
            .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
            .map(|e| e.unwrap().path())
            .filter(|p| p.is_file())
            .collect();
        files.sort();
        assert!(!files.is_empty(), "{}: no seed", dir.display());
        for f in &files {
            let data = std::fs::read(f).unwrap();
            let t = std::time::Instant::now();
            harness(&data);
            let s = t.elapsed().as_secs_f64();
            // a corpus file that takes this long would be a hang for afl
            assert!(s < 5.0, "{}: {s:.1} s", f.display());
        }
        eprintln!("{name}: {} files", files.len());
        total += files.len();
    }
    palpa_fuzz::remove_work_dir();
    eprintln!("{total} corpus files replayed");
}

/// Each target has a binary of its name (the afl target) and a corpus directory.
#[test]
fn every_target_has_a_binary_and_a_corpus() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for (name, _) in palpa_fuzz::TARGETS {
        assert!(
            root.join("src/bin").join(format!("{name}.rs")).is_file(),
            "{name}"
        );
        assert!(root.join("corpus").join(name).is_dir(), "{name}");
    }
}
