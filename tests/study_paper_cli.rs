//! `palpa study --paper` through the real binary, on the committed records of the 3 mm study
//! (`data/study-3mm/records`; the runs themselves take hours, docs/study/README.md):
//! - `--dry-run` finds every committed record current: the plan and the scene writer still
//!   produce the scenes those runs ran (a change to either makes the committed study stale, and
//!   this test says so);
//! - `--report-only` rebuilds the report from the records alone: one CSV row per record, the
//!   reference exact against itself (force error 0, Fit 1), the base's errors as the committed
//!   report states them, the Pareto plots;
//! - bad flags and an empty directory get a clear error.

use std::path::{Path, PathBuf};

#[path = "support/cli.rs"]
mod cli;
use cli::{ok, palpa, s};

fn committed() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("data/study-3mm")
}

/// The committed records' file names.
fn records() -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(committed().join("records"))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.ends_with(".json"))
        .collect();
    v.sort();
    v
}

/// The locations with at least one committed record.
fn locations() -> Vec<String> {
    let mut l: Vec<String> = records()
        .iter()
        .map(|n| n.split('-').next().unwrap().to_string())
        .collect();
    l.dedup();
    l
}

#[test]
fn committed_records_are_current() {
    let locs = locations();
    assert!(!locs.is_empty(), "no committed study records");
    let out = ok(&[
        "study",
        "--paper",
        "--dry-run",
        "--locations",
        &locs.join(","),
        "--out",
        s(&committed()),
    ]);
    let recorded = out.lines().filter(|l| l.ends_with("(recorded)")).count();
    assert_eq!(
        recorded,
        records().len(),
        "every committed record must be the scene the plan runs now:\n{out}"
    );
    // one line per setting of the plan at each location
    let settings = verification::study_paper::plan("A").len();
    assert_eq!(out.lines().count(), settings * locs.len(), "{out}");
}

#[test]
fn committed_records_are_whole() {
    use verification::study_paper_record::{RunRecord, FORMAT};
    for n in records() {
        let r = RunRecord::read(&committed().join("records").join(&n))
            .unwrap()
            .unwrap();
        assert_eq!(r.format, FORMAT, "{n}");
        if r.completed() {
            assert_eq!(r.shape_error(), None, "{n}");
            // the probe's order: element ids strictly increasing
            assert!(r.roi_elements.windows(2).all(|w| w[0] < w[1]), "{n}");
            assert_eq!(r.roi_elements.len(), 377, "{n}: the ROI's 377 elements");
        }
    }
}

#[test]
fn the_report_is_rebuilt_from_records_alone() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("records")).unwrap();
    for n in records() {
        std::fs::copy(
            committed().join("records").join(&n),
            dir.path().join("records").join(&n),
        )
        .unwrap();
    }
    // the locations of the committed report (a location whose study is under way has records
    // but stays out of it until its settings are all there)
    let committed_csv = std::fs::read_to_string(committed().join("study-3mm.csv")).unwrap();
    let mut locs: Vec<String> = committed_csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap().to_string())
        .collect();
    locs.dedup();
    ok(&[
        "study",
        "--paper",
        "--report-only",
        "--locations",
        &locs.join(","),
        "--out",
        s(dir.path()),
    ]);
    let csv = std::fs::read_to_string(dir.path().join("study-3mm.csv")).unwrap();
    let n = records()
        .iter()
        .filter(|n| locs.iter().any(|l| n.starts_with(&format!("{l}-"))))
        .count();
    assert_eq!(csv.lines().count(), 1 + n);
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let references: Vec<&str> = csv
        .lines()
        .skip(1)
        .filter(|l| l.split(',').nth(1) == Some("reference"))
        .collect();
    assert_eq!(references.len(), locs.len(), "one reference per location");
    for line in references {
        let f: Vec<&str> = line.split(',').collect();
        assert_eq!(f[col("pooled_fit")].parse::<f64>().unwrap(), 1.0, "{line}");
        assert_eq!(f[col("peak_force_error")].parse::<f64>().unwrap(), 0.0);
    }
    // the rebuilt report is the committed one
    assert_eq!(csv, committed_csv);
    let md = std::fs::read_to_string(dir.path().join("study-3mm.md")).unwrap();
    assert_eq!(
        md,
        std::fs::read_to_string(committed().join("study-3mm.md")).unwrap()
    );
    assert!(dir.path().join("pareto_3mm_force.png").exists());
    assert!(dir.path().join("pareto_3mm_fit.png").exists());
}

#[test]
fn bad_flags_and_empty_directories_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let o = palpa(&[
        "study",
        "--paper",
        "--locations",
        "A,Q",
        "--dry-run",
        "--out",
        s(dir.path()),
    ]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("unknown location `Q`"), "{err}");
    // (--dry-run and a scratch --out: should the flag rules break, nothing long runs)
    let o = palpa(&[
        "study",
        "--quick",
        "--paper",
        "--dry-run",
        "--out",
        s(dir.path()),
    ]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("cannot be used with"));
    let o = palpa(&["study", "--report-only", "--out", s(dir.path())]);
    assert!(!o.status.success(), "--report-only needs --paper");
    assert!(String::from_utf8_lossy(&o.stderr).contains("--paper"));
    let o = palpa(&["study", "--paper", "--report-only", "--out", s(dir.path())]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("no current study records"), "{err}");
}

/// The `fast` preset is the committed study's answer to the preset's own budget: the cheapest
/// setting within hand force 10 % and per-sample ROI Fit 0.75 at A, B and C is the base with
/// mass scaling to 1.3x the initial step, and the preset applied to the base runs that
/// setting's scene (but for the added-mass limit, which only stops a run).
#[test]
fn the_fast_preset_is_the_studys_cheapest_setting_within_its_budget() {
    use scene::palpation::Fidelity;
    use verification::study_paper::{base_setup, plan};
    use verification::study_paper_record::RunRecord;
    use verification::study_paper_report::{cheapest_within, summarise, FAST_PRESET_BUDGET};
    let records: Vec<RunRecord> = records()
        .iter()
        .map(|n| {
            RunRecord::read(&committed().join("records").join(n))
                .unwrap()
                .unwrap()
        })
        .collect();
    let rows = summarise(&records);
    let (force, fit) = FAST_PRESET_BUDGET;
    let best = cheapest_within(&rows, force, fit).expect("a setting within the budget");
    assert_eq!(
        (best.knob.as_str(), best.setting.as_str()),
        ("mass scaling", "1.3 x initial step")
    );
    assert_eq!(best.locations, ["A", "B", "C"]);
    assert!(best.worst_force_error <= force && best.worst_fit >= fit);
    // the summary's budget line states the preset's measured errors
    let said = Fidelity::Fast.describe();
    for figure in [
        format!("within {:.1} %", 100.0 * best.worst_force_error),
        format!("Fit {:.2}-", best.worst_fit),
        format!("({:.2} pooled)", best.pooled_fit),
        format!("within {:.1} %,", 100.0 * best.peak_stress_error),
    ] {
        assert!(said.contains(&figure), "`{figure}` not in: {said}");
    }
    for loc in ["A", "B", "C"] {
        let row = plan(loc)
            .into_iter()
            .find(|s| s.knob == best.knob && s.setting == best.setting)
            .unwrap();
        let mut fast = base_setup(loc);
        Fidelity::Fast.apply(&mut fast);
        fast.mass_scaling_limit = row.setup.mass_scaling_limit;
        assert_eq!(fast.scene_toml(), row.setup.scene_toml(), "{loc}");
    }
}
