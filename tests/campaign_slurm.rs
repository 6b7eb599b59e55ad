//! A campaign on a Slurm array (scenes/campaign-slurm.sbatch, docs/cluster.md), without Slurm:
//! the script's array tasks and merge run under bash with the variables Slurm would set, on the
//! tiny campaign of tests/support/tiny_campaign.rs (three runs of about a second). What broke:
//! - resubmitting one failed task (`sbatch --array=1`) set SLURM_ARRAY_TASK_COUNT=1 and the task
//!   failed with `--shard ... got 1/1`: the shard count now comes from the record the first
//!   submission left ($OUT/shard-count), and palpa refuses a count that disagrees with the
//!   shard directory's campaign.json (`--shard i` alone takes it from there);
//! - the `#SBATCH` defaults asked for 4 CPUs and 8 GB per task, so on a small node the array
//!   stayed pending.
//!
//! .ci/slurm.sh runs the same script on a real one-node Slurm.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

#[path = "support/tiny_campaign.rs"]
mod tiny_campaign;
use tiny_campaign::tiny;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

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
        let file = tiny(tmp.path());
        let out = tmp.path().join("campaign");
        Lab { tmp, file, out }
    }

    /// `bash campaign-slurm.sbatch [mode]` with the array variables of task `id` of an array
    /// `min..=max`; `shards`: the SHARDS variable.
    fn script(
        &self,
        mode: Option<&str>,
        task: Option<(usize, usize, usize)>,
        shards: Option<&str>,
    ) -> Output {
        let mut c = Command::new("bash");
        c.current_dir(self.tmp.path())
            .arg(root().join("scenes/campaign-slurm.sbatch"))
            .args(mode)
            .env("CAMPAIGN", &self.file)
            .env("OUT", &self.out)
            .env("PALPA", env!("CARGO_BIN_EXE_palpa"))
            .env("SLURM_CPUS_PER_TASK", "1")
            .env_remove("SHARDS");
        for v in [
            "SLURM_ARRAY_TASK_ID",
            "SLURM_ARRAY_TASK_COUNT",
            "SLURM_ARRAY_TASK_MIN",
            "SLURM_ARRAY_TASK_MAX",
        ] {
            c.env_remove(v);
        }
        if let Some((id, min, max)) = task {
            c.env("SLURM_ARRAY_TASK_ID", id.to_string())
                .env("SLURM_ARRAY_TASK_MIN", min.to_string())
                .env("SLURM_ARRAY_TASK_MAX", max.to_string())
                .env("SLURM_ARRAY_TASK_COUNT", (max - min + 1).to_string());
        }
        if let Some(n) = shards {
            c.env("SHARDS", n);
        }
        let o = c.output().unwrap();
        assert!(!text(&o).contains("panicked"), "panic: {}", text(&o));
        o
    }

    fn ok(
        &self,
        mode: Option<&str>,
        task: Option<(usize, usize, usize)>,
        shards: Option<&str>,
    ) -> String {
        self.expect(true, mode, task, shards)
    }

    fn fails(
        &self,
        mode: Option<&str>,
        task: Option<(usize, usize, usize)>,
        shards: Option<&str>,
    ) -> String {
        self.expect(false, mode, task, shards)
    }

    /// The script's output, after asserting that it succeeded (or failed) as `success` says.
    fn expect(
        &self,
        success: bool,
        mode: Option<&str>,
        task: Option<(usize, usize, usize)>,
        shards: Option<&str>,
    ) -> String {
        let o = self.script(mode, task, shards);
        assert_eq!(
            o.status.success(),
            success,
            "{mode:?} {task:?}: {}",
            text(&o)
        );
        text(&o)
    }
}

fn same_dataset(a: &Path, b: &Path) {
    for f in ["dataset.npz", "manifest.json", "dataset.json", "view.json"] {
        assert!(
            std::fs::read(a.join(f)).unwrap() == std::fs::read(b.join(f)).unwrap(),
            "{f}: {} and {} differ",
            a.display(),
            b.display()
        );
    }
}

#[test]
fn a_single_task_resubmit_takes_the_shard_count_from_the_plan() {
    let lab = Lab::new();
    let full = lab.tmp.path().join("full");
    let o = palpa(
        lab.tmp.path(),
        &["campaign", s(&lab.file), "--out", s(&full), "--quiet"],
    );
    assert!(o.status.success(), "{}", text(&o));

    // the first submission: an array 0-1, its tasks, then the merge
    for id in 0..2 {
        lab.ok(None, Some((id, 0, 1)), None);
    }
    assert_eq!(
        std::fs::read_to_string(lab.out.join("shard-count")).unwrap(),
        "2\n"
    );
    lab.ok(Some("merge"), None, None);
    same_dataset(&full, &lab.out.join("merged"));
    // a merge that misses a shard names it
    let partial = lab.tmp.path().join("partial");
    let o = palpa(
        lab.tmp.path(),
        &[
            "campaign",
            "merge",
            s(&lab.out.join("shard-0")),
            "--out",
            s(&partial),
        ],
    );
    assert!(
        !o.status.success() && text(&o).contains("P12 (the runs of shard 1/2"),
        "{}",
        text(&o)
    );

    // task 1's output is lost (its node died with the disk): the merge names the task to resubmit
    std::fs::remove_dir_all(lab.out.join("shard-1")).unwrap();
    let err = lab.fails(Some("merge"), None, None);
    assert!(err.contains("submit --array=1"), "{err}");

    // `sbatch --array=1`: SLURM_ARRAY_TASK_COUNT=1, and the task used to run `--shard 1/1`
    let log = lab.ok(None, Some((1, 1, 1)), None);
    assert!(log.contains("shard 1/2"), "{log}");
    let c = std::fs::read_to_string(lab.out.join("shard-1/campaign.json")).unwrap();
    assert!(c.contains("\"shard\": \"1/2\""), "{c}");
    assert!(lab.out.join("shard-1/runs/P12/done.json").is_file());
    // the merge starts afresh, so the redone runs are the ones merged
    lab.ok(Some("merge"), None, None);
    same_dataset(&full, &lab.out.join("merged"));
    let merged_done = std::fs::read(lab.out.join("merged/runs/P12/done.json")).unwrap();
    assert_eq!(
        merged_done,
        std::fs::read(lab.out.join("shard-1/runs/P12/done.json")).unwrap()
    );

    // a requeued task of the original array continues its shard: nothing left to run
    let log = lab.ok(None, Some((0, 0, 1)), None);
    assert!(log.contains("shard 0/2 finished"), "{log}");
}

#[test]
fn a_shard_count_other_than_the_recorded_one_is_refused_before_running() {
    let lab = Lab::new();
    std::fs::create_dir_all(&lab.out).unwrap();
    // the first submission was not 0..n-1 and gave no SHARDS: no count to record
    let err = lab.fails(None, Some((1, 1, 1)), None);
    assert!(err.contains("SHARDS=n"), "{err}");
    assert!(!lab.out.join("shard-count").exists());
    std::fs::write(lab.out.join("shard-count"), "2\n").unwrap();
    // SHARDS disagreeing with the record, at submission or in a task
    let err = lab.fails(None, Some((1, 1, 1)), Some("3"));
    assert!(
        err.contains("SHARDS=3") && err.contains("split into 2 shards"),
        "{err}"
    );
    let err = lab.fails(Some("submit"), None, Some("3"));
    assert!(err.contains("split into 2 shards"), "{err}");
    // a task beyond the recorded count
    let err = lab.fails(None, Some((2, 0, 2)), None);
    assert!(
        err.contains("array task 2") && err.contains("2 shards"),
        "{err}"
    );
    // nothing ran
    assert!(!lab.out.join("shard-1").exists() && !lab.out.join("shard-2").exists());
    // a record that is not a count
    std::fs::write(lab.out.join("shard-count"), "two\n").unwrap();
    let err = lab.fails(None, Some((0, 0, 1)), None);
    assert!(err.contains("not a shard count"), "{err}");
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

/// The resources each array task asks for by default fit a small node (the CI's has 2 CPUs).
#[test]
fn the_sbatch_defaults_fit_a_small_node() {
    let script = std::fs::read_to_string(root().join("scenes/campaign-slurm.sbatch")).unwrap();
    let option = |name: &str| -> String {
        script
            .lines()
            .filter_map(|l| l.strip_prefix("#SBATCH "))
            .find_map(|l| {
                l.trim()
                    .strip_prefix(&format!("--{name}="))
                    .map(str::to_string)
            })
            .unwrap_or_else(|| panic!("no #SBATCH --{name}"))
    };
    let cpus: usize = option("cpus-per-task").parse().unwrap();
    assert!((1..=2).contains(&cpus), "--cpus-per-task={cpus}");
    let mem = option("mem");
    let gb: f64 = match mem.strip_suffix('G') {
        Some(g) => g.parse().unwrap(),
        None => mem.trim_end_matches('M').parse::<f64>().unwrap() / 1024.0,
    };
    assert!(gb <= 4.0, "--mem={mem}");
}
