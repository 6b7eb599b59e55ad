//! A campaign's shards and the count they were made with (docs/campaigns.md). What broke:
//! resubmitting one failed task of a Slurm array (`sbatch --array=1`) set
//! SLURM_ARRAY_TASK_COUNT=1 and the task failed with `--shard ... got 1/1`. palpa now says
//! that n is the campaign's count, refuses a count that disagrees with the shard directory's
//! campaign.json, and `--shard i` alone takes the count from there.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const TINY: &str = r#"
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

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

fn palpa(dir: &Path, args: &[&str]) -> Output {
    let o = Command::new(env!("CARGO_BIN_EXE_palpa"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap();
    assert!(!text(&o).contains("panicked"), "panic: {}", text(&o));
    o
}

/// A campaign directory beside the tiny campaign file, in a fresh temporary directory.
struct Lab {
    tmp: tempfile::TempDir,
    file: PathBuf,
    out: PathBuf,
}

impl Lab {
    fn new() -> Lab {
        let tmp = tempfile::tempdir().unwrap();
        let file = tmp.path().join("tiny.toml");
        std::fs::write(&file, TINY).unwrap();
        let out = tmp.path().join("campaign");
        Lab { tmp, file, out }
    }
}

#[test]
fn a_shard_count_that_disagrees_with_the_directory_is_refused_naming_both() {
    let lab = Lab::new();
    let dir = lab.tmp.path();
    let run = |args: &[&str]| {
        palpa(
            dir,
            &[&["campaign", s(&lab.file), "--out", s(&lab.out)], args].concat(),
        )
    };
    // `--shard i/n` with i >= n, on a fresh directory: n is the campaign's count, not the array's
    let o = run(&["--shard", "1/1", "--dry-run"]);
    assert!(
        !o.status.success() && text(&o).contains("not the size of the array"),
        "{}",
        text(&o)
    );
    // `--shard i` alone needs a directory that records the count
    let o = run(&["--shard", "1", "--dry-run"]);
    assert!(
        !o.status.success() && text(&o).contains("--shard 1/n"),
        "{}",
        text(&o)
    );

    // shard 1/2's directory, started (campaign.json written) with no run finished
    let o = run(&["--shard", "1/2", "--max-runs", "0", "--quiet"]);
    assert!(o.status.success(), "{}", text(&o));
    // the resubmit of the old script: `--shard 1/1`
    let o = run(&["--shard", "1/1", "--resume"]);
    let t = text(&o);
    assert!(
        !o.status.success() && t.contains("records shard 1/2") && t.contains("--shard 1/2"),
        "{t}"
    );
    // another count, another index, no shard at all: each names what the directory holds
    for args in [&["--shard", "1/3"][..], &["--shard", "0/2"], &[]] {
        let o = run(&[args, &["--resume"]].concat());
        let t = text(&o);
        assert!(
            !o.status.success() && t.contains("holds shard 1/2"),
            "{args:?}: {t}"
        );
    }
    assert!(
        !lab.out.join("runs").exists()
            || std::fs::read_dir(lab.out.join("runs"))
                .unwrap()
                .next()
                .is_none()
    );
    // `--shard 1` takes the count from the directory
    let o = run(&["--shard", "1", "--dry-run"]);
    assert!(
        o.status.success() && text(&o).contains("shard 1/2: 1 runs"),
        "{}",
        text(&o)
    );

    // an unsharded campaign's directory is not a shard
    let whole = dir.join("whole");
    let o = palpa(
        dir,
        &[
            "campaign",
            s(&lab.file),
            "--out",
            s(&whole),
            "--max-runs",
            "0",
            "--quiet",
        ],
    );
    assert!(o.status.success(), "{}", text(&o));
    for shard in ["0/2", "0"] {
        let o = palpa(
            dir,
            &[
                "campaign",
                s(&lab.file),
                "--out",
                s(&whole),
                "--shard",
                shard,
                "--dry-run",
            ],
        );
        assert!(
            !o.status.success() && text(&o).contains("unsharded"),
            "{shard}: {}",
            text(&o)
        );
    }
}
