//! `palpa campaign --adaptive N --batch B` through the real binary, on the tiny campaign's
//! phantom (8 mm, 2 mm in 1 ms) with a 4-point Sobol design for training and A held out:
//! - 3 adaptive runs in batches of 2 and 1, recorded in adaptive.json and in the plan as
//!   training locations ad01-01, ad01-02, ad02-01, and in the dataset after the design's;
//! - a campaign stopped inside a batch, and one stopped between recording a batch and writing
//!   the plan, resumed with the same flags choose the same batches and write the same dataset,
//!   byte for byte, as one that ran straight through;
//! - resuming a finished adaptive campaign adds nothing; the directory refuses to be resumed
//!   without `--adaptive`;
//! - `palpa front` and `palpa train --train-locations/--train-interval/--recover` on it.

use std::path::Path;
use surrogate::Dataset;

#[path = "support/cli.rs"]
mod cli;
use cli::{ok, palpa, s};

const FILE: &str = r#"
title = "tiny adaptive"
[phantom]
voxel = "8 mm"
[locations]
train = []
test = ["A"]
[[locations.design]]
kind = "sobol"
n = 4
seed = 5
split = "train"
[indentation]
depth = "2 mm"
duration = "1 ms"
sample_interval = "0.5 ms"
"#;

/// `straight`'s runs copied into `name` beside it, without its plan or record.
fn copy_runs(straight: &Path, name: &str) -> std::path::PathBuf {
    let copied = straight.with_file_name(name);
    let runs = copied.join("runs");
    for e in std::fs::read_dir(straight.join("runs")).unwrap() {
        let e = e.unwrap();
        let to = runs.join(e.file_name());
        std::fs::create_dir_all(&to).unwrap();
        for f in std::fs::read_dir(e.path()).unwrap() {
            let f = f.unwrap();
            std::fs::copy(f.path(), to.join(f.file_name())).unwrap();
        }
    }
    copied
}

/// The finished campaign's runs, copied into a new directory without its plan or record and
/// titled as another campaign's (a Sobol design's runs copied into an adaptive one): the same
/// batches are chosen and the copied runs reused (nothing is solved), with no note that they
/// are not reused, and the dataset is the same, byte for byte. A copied run that is not the
/// palpation its batch, or the initial design, plans is solved again.
fn batch_runs_copied_in_are_reused(file: &Path, straight: &Path, flags: &[&str]) {
    let copied = copy_runs(straight, "copied");
    for e in std::fs::read_dir(copied.join("runs")).unwrap() {
        let path = e.unwrap().path().join("scene.toml");
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains("title = \"tiny adaptive: "), "{text}");
        let text = text.replace("title = \"tiny adaptive: ", "title = \"tiny Sobol: ");
        std::fs::write(&path, text).unwrap();
    }
    let mut args = vec!["campaign", s(file), "--out", s(&copied), "--resume"];
    args.extend(flags);
    let o = palpa(&args);
    let (out, err) = (
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr),
    );
    assert!(o.status.success(), "{err}");
    assert!(
        out.contains("7 finished, 0 to run") && out.contains("8 finished, 0 to run"),
        "{out}"
    );
    assert!(
        out.lines()
            .filter(|l| l.contains(" to run:"))
            .all(|l| l.contains(" 0 to run:")),
        "{out}"
    );
    assert!(
        !err.contains("not reused") && !err.contains("solved again"),
        "{err}"
    );
    let bytes = |dir: &Path| std::fs::read(dir.join("dataset.npz")).unwrap();
    assert_eq!(bytes(&copied), bytes(straight));
    // a copied run at another place than its batch plans (ad01-01 holding ad01-02's
    // palpation), or than the initial design plans (S01 holding S02's), is solved again, with
    // a note, and the dataset is the same
    let wrong = copy_runs(straight, "wrong");
    let scene = |l: &str| wrong.join("runs").join(l).join("scene.toml");
    for (at, from) in [("ad01-01", "ad01-02"), ("S01", "S02")] {
        let other = std::fs::read_to_string(scene(from)).unwrap();
        std::fs::write(scene(at), other.replace(from, at)).unwrap();
    }
    let run = |more: &[&str]| {
        let mut args = vec!["campaign", s(file), "--out", s(&wrong)];
        args.extend(flags);
        args.extend(more);
        let o = palpa(&args);
        let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
        (o.status.success(), text(&o.stdout), text(&o.stderr))
    };
    let s01_done = wrong.join("runs/S01/done.json");
    // without --resume the directory of finished runs is refused, and nothing is removed
    let (ok, _, err) = run(&[]);
    assert!(
        !ok && err.contains("finished run(s) of this campaign: pass --resume"),
        "{err}"
    );
    assert!(s01_done.is_file());
    // a resume that runs nothing removes the wrong S01 at once, naming where it parts from the
    // plan, so that no dataset or later resume takes it for finished
    let (ok, _, err) = run(&["--resume", "--max-runs", "0"]);
    assert!(
        ok && err.contains(
            "S01/scene.toml is not the palpation this campaign plans for S01 (scene.hand[0].at["
        ),
        "{err}"
    );
    assert!(!s01_done.exists() && !wrong.join("dataset.npz").exists());
    let (ok, out, err) = run(&["--resume"]);
    assert!(
        ok && err.contains("ad01-01/scene.toml is not the palpation adaptive batch 1 plans")
            && out.contains("4 finished, 1 to run")
            && out.contains("6 finished, 1 to run"),
        "{out}{err}"
    );
    assert_eq!(bytes(&wrong), bytes(straight));
}

#[test]
fn adaptive_batches_are_recorded_and_resume_to_the_same_bytes() {
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("adaptive.toml");
    std::fs::write(&file, FILE).unwrap();
    let straight = tmp.path().join("straight");
    let flags = ["--adaptive", "3", "--batch", "2", "--jobs", "1"];
    let mut args = vec!["campaign", s(&file), "--out", s(&straight)];
    args.extend(flags);
    let stdout = ok(&args);
    assert!(
        stdout.contains("adaptive batch 1: 2 location(s)"),
        "{stdout}"
    );
    assert!(
        stdout.contains("adaptive batch 2: 1 location(s)"),
        "{stdout}"
    );

    let rec = campaign::AdaptiveRecord::read(&straight).unwrap();
    let labels: Vec<&str> = rec
        .batches
        .iter()
        .flat_map(|b| b.points.iter().map(|p| p.label.as_str()))
        .collect();
    assert_eq!(labels, ["ad01-01", "ad01-02", "ad02-01"]);
    assert_eq!(rec.batches[0].trained_on_locations, 4);
    assert_eq!(rec.batches[1].trained_on_locations, 6);
    // the chosen points lie in the design's region (the ROI's plan extent) and apart
    let [lo, hi] = campaign::default_extent();
    for p in rec.batches.iter().flat_map(|b| &b.points) {
        assert!((lo[0]..=hi[0]).contains(&p.at[0]) && (lo[1]..=hi[1]).contains(&p.at[1]));
        assert!(p.variance > 0.0);
    }
    let d = Dataset::read(straight.join("dataset.npz")).unwrap();
    assert_eq!(
        d.manifest.location_labels,
        ["S01", "S02", "S03", "S04", "A", "ad01-01", "ad01-02", "ad02-01"]
    );
    assert_eq!(d.rows_with_split(surrogate::Split::Train).len(), 7 * 3);
    let plan = campaign::read_campaign_dir(&straight)
        .unwrap()
        .plan()
        .unwrap();
    assert_eq!(plan.runs.len(), 8);

    // stopped after 6 runs, inside the first batch (5 runs of the file, then 1 of batch 1's
    // 2), then resumed: the same batches and the same dataset bytes
    let stopped = tmp.path().join("stopped");
    let mut args = vec![
        "campaign",
        s(&file),
        "--out",
        s(&stopped),
        "--max-runs",
        "6",
    ];
    args.extend(flags);
    let first = ok(&args);
    assert!(first.contains("not finished"), "{first}");
    let part = campaign::AdaptiveRecord::read(&stopped).unwrap();
    assert_eq!(part.batches.len(), 1);
    assert_eq!(part.batches[0], rec.batches[0]);
    // as if it had stopped between recording the batch and writing the plan: campaign.json
    // without batch 1's two locations and runs
    let cfile = stopped.join("campaign.json");
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&cfile).unwrap()).unwrap();
    for key in ["locations", "runs"] {
        let a = v["plan"][key].as_array_mut().unwrap();
        let n = a.len();
        a.truncate(n - 2);
    }
    std::fs::write(&cfile, serde_json::to_string_pretty(&v).unwrap()).unwrap();
    let mut args = vec!["campaign", s(&file), "--out", s(&stopped), "--resume"];
    args.extend(flags);
    ok(&args);
    assert_eq!(campaign::AdaptiveRecord::read(&stopped).unwrap(), rec);
    let bytes = |dir: &Path| std::fs::read(dir.join("dataset.npz")).unwrap();
    assert_eq!(bytes(&stopped), bytes(&straight));

    // a finished adaptive campaign resumes to nothing new
    let mut args = vec!["campaign", s(&file), "--out", s(&straight), "--resume"];
    args.extend(flags);
    let again = ok(&args);
    assert!(
        again.contains("8 finished, 0 to run") && !again.contains("adaptive batch"),
        "{again}"
    );
    assert_eq!(campaign::AdaptiveRecord::read(&straight).unwrap(), rec);
    batch_runs_copied_in_are_reused(&file, &straight, &flags);

    // the front: the GP on the first 4 and 7 training runs, scored on A; 9 runs are skipped
    let front = tmp.path().join("front");
    let o = ok(&[
        "front",
        &format!("adaptive={}", s(&straight)),
        "--runs",
        "4,7,9",
        "--out",
        s(&front),
    ]);
    assert!(o.contains("adaptive") && o.contains("7 runs"), "{o}");
    let csv = std::fs::read_to_string(front.join("front.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), 2, "{csv}");
    for (r, n) in rows.iter().zip(["4", "7"]) {
        assert_eq!((r[0], r[1]), ("adaptive", n), "{csv}");
        let fit: f64 = r[3].parse().unwrap();
        assert!(fit.is_finite() && fit <= 1.0, "{csv}");
        let core_h: f64 = r[2].parse().unwrap();
        assert!(core_h > 0.0, "{csv}");
    }
    assert!(front.join("front.png").is_file() && front.join("front.md").is_file());
    // train on the first 2 training locations at the 1 ms stamps: 2 x 2 samples
    let model = tmp.path().join("gp");
    let o = ok(&[
        "train",
        s(&straight),
        "--model",
        "gp",
        "--train-locations",
        "2",
        "--train-interval",
        "1 ms",
        "--out",
        s(&model),
    ]);
    assert!(o.contains("4 training samples from 2 locations"), "{o}");
    assert!(o.contains("95 % predictive intervals cover"), "{o}");
    let o = palpa(&[
        "train",
        s(&straight),
        "--model",
        "gp",
        "--train-locations",
        "99",
        "--out",
        s(&model),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("7 training locations"),
        "{err}"
    );
    // the recovered target: learned and scored as such, and not with the tensor target
    let o = ok(&[
        "train",
        s(&straight),
        "--model",
        "gp",
        "--recover",
        "5 mm",
        "--out",
        s(&model),
    ]);
    assert!(
        o.contains("the recovered stress") && o.contains("principal target"),
        "{o}"
    );
    let meta = std::fs::read_to_string(model.join("model.json")).unwrap();
    assert!(meta.contains("\"recovery_width\": 0.005"), "{meta}");
    for bad in [["5 mm", "tensor"], ["5 s", "principal"]] {
        let o = palpa(&[
            "train",
            s(&straight),
            "--model",
            "gp",
            "--recover",
            bad[0],
            "--target",
            bad[1],
            "--out",
            s(&model),
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.contains("--recover"), "{err}");
    }

    // without --adaptive the directory is refused, naming the flag
    let o = palpa(&["campaign", s(&file), "--out", s(&straight), "--resume"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("--adaptive"), "{err}");
}
