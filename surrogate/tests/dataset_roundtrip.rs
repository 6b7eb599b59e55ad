//! The dataset file format: round trip, numpy compatibility, clear errors.

use surrogate::synthetic::make_synthetic_dataset;
use surrogate::Dataset;

#[test]
fn npz_round_trip_is_exact() {
    let dir = tempfile::tempdir().unwrap();
    let mut d = make_synthetic_dataset(7);
    d.stress = Some(ndarray::Array3::from_shape_fn(
        (d.n_samples(), 7, 6),
        |(i, r, c)| (i * 100 + r * 10 + c) as f64 * 0.5 - 3.0,
    ));
    d.write(dir.path()).unwrap();
    let back = Dataset::read(dir.path()).unwrap();
    assert_eq!(back, d);
    // NAME.npz + NAME.json form
    let p = dir.path().join("campaign.npz");
    d.write(&p).unwrap();
    assert!(dir.path().join("campaign.json").exists());
    assert_eq!(Dataset::read(&p).unwrap(), d);
    // no temporary files left behind
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty());
}

#[test]
fn invalid_dataset_names_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let mut d = make_synthetic_dataset(5);
    d.split[3] = 2;
    let e = d.write(dir.path()).unwrap_err().to_string();
    assert!(e.contains("split"), "{e}");
    let mut d = make_synthetic_dataset(5);
    d.roi_centroids = ndarray::Array2::zeros((4, 3));
    let e = d.validate().unwrap_err().to_string();
    assert!(e.contains("roi_centroids"), "{e}");
}

#[test]
fn missing_or_corrupt_files_are_errors_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let e = Dataset::read(dir.path()).unwrap_err().to_string();
    assert!(e.contains("manifest.json"), "{e}");
    make_synthetic_dataset(5).write(dir.path()).unwrap();
    std::fs::write(dir.path().join("dataset.npz"), b"not a zip").unwrap();
    let e = Dataset::read(dir.path()).unwrap_err().to_string();
    assert!(e.contains("dataset.npz"), "{e}");
}

/// Python with numpy: `$PALPA_PYTHON`, else the repository's `.venv-surrogate`, else `python3`.
fn python_with_numpy() -> Option<std::path::PathBuf> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let candidates = [
        std::env::var_os("PALPA_PYTHON").map(Into::into),
        Some(root.join(".venv-surrogate/bin/python")),
        Some("python3".into()),
    ];
    candidates
        .into_iter()
        .flatten()
        .find(|p: &std::path::PathBuf| {
            std::process::Command::new(p)
                .args(["-c", "import numpy"])
                .output()
                .map(|o| o.status.success())
                .unwrap_or(false)
        })
}

#[test]
fn numpy_reads_the_npz_in_one_line() {
    let Some(py) = python_with_numpy() else {
        assert!(
            std::env::var_os("PALPA_REQUIRE_NUMPY").is_none(),
            "PALPA_REQUIRE_NUMPY is set but no python with numpy was found"
        );
        eprintln!("SKIPPED: no python with numpy (set PALPA_PYTHON, or create .venv-surrogate)");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let d = make_synthetic_dataset(9);
    d.write(dir.path()).unwrap();
    let npz = dir.path().join("dataset.npz");
    let script = "import sys, numpy as np; d = np.load(sys.argv[1]); \
        print(sorted(d.files), d['X'].shape, d['Y'].shape, d['roi_ids'].dtype, d['split'].dtype, \
        d['location'].dtype, repr(float(d['Y'][30, 4])), int(d['split'].sum()))";
    let out = std::process::Command::new(py)
        .args(["-c", script])
        .arg(&npz)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    let expected = format!(
        "['X', 'Y', 'location', 'roi_centroids', 'roi_ids', 'split'] (168, 4) (168, 9) int64 uint8 int64 {:?} 18",
        d.y[(30, 4)]
    );
    assert_eq!(text.trim(), expected);
}

/// The same dataset written twice, seconds apart, gives the same bytes: the npz holds no time
/// stamp (so a campaign's dataset is identical from run to run and across shards).
#[test]
fn npz_bytes_do_not_depend_on_when_it_was_written() {
    let a = tempfile::tempdir().unwrap();
    let b = tempfile::tempdir().unwrap();
    let d = make_synthetic_dataset(5);
    d.write(a.path()).unwrap();
    std::thread::sleep(std::time::Duration::from_millis(2100));
    d.write(b.path()).unwrap();
    for f in ["dataset.npz", "manifest.json"] {
        let x = std::fs::read(a.path().join(f)).unwrap();
        let y = std::fs::read(b.path().join(f)).unwrap();
        assert!(x == y, "{f} differs between two writes");
    }
}
