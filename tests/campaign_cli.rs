//! `palpa campaign` end to end through the real binary (issue 7), on a tiny campaign (8 mm
//! phantom, three locations, 2 mm in 1 ms, a sample every 0.5 ms: three runs of a few seconds):
//! - the chain writes `dataset.npz` whose X / Y / S shapes are runs x samples, with the
//!   locations, splits and sample times in run order;
//! - two shards (`--shard 0/2`, `--shard 1/2`) merged give byte-identical dataset files to the
//!   unsharded campaign;
//! - a campaign killed after its first finished run and continued with `--resume` loses and
//!   duplicates no run, does not recompute the finished one (its `done.json` is unchanged) and
//!   redoes an unfinished run directory from scratch; without `--resume` it refuses to touch
//!   the finished runs;
//! - the campaign writes its phantom's plan view (`view.json`) with the dataset's ROI; `palpa
//!   train` puts it beside the model, or, for a dataset without one, rebuilds the phantom from
//!   the manifest and derives the same geometry; a merge carries it over;
//! - the shipped profiles (scenes/campaign-quick.toml, scenes/campaign-paper.toml,
//!   scenes/campaign-paper-fast.toml,
//!   scenes/campaign-5mm.toml, scenes/campaign-fbar-8mm.toml, scenes/campaign-wide-grid.toml,
//!   scenes/campaign-convergence-2.5mm.toml)
//!   resolve on their phantoms (`--dry-run`), the default raster covers the ROI's plan extent,
//!   and a bad key is an error naming it;
//! - a respiratory campaign (`[locations] phases`) has the phase as its sixth input column,
//!   reads each run's ROI through the points carried with the liver, and at the reference
//!   phase gives the plain campaign's numbers bit for bit; its model takes the phase (in
//!   `palpa predict --phase` and in `palpa serve`'s phase message);
//! - finished runs the plan does not name are named and not reused; `palpa front` reads a
//!   campaign still running from its finished runs, as the finished campaign at that count.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};
use surrogate::{Dataset, ViewGeometry};

#[path = "support/cli.rs"]
mod cli;
use cli::{fails_with, ok, palpa, s};
#[path = "support/mod.rs"]
mod serve_support;
#[path = "support/tiny_campaign.rs"]
mod tiny_campaign;
use tiny_campaign::{done_count, tiny, RUNS, SAMPLES, TINY};

/// The dataset has RUNS x SAMPLES rows in run order: locations 0, 1, 2, splits train, train,
/// test, times 0, 0.5, 1 ms within each run; no row lost or duplicated.
fn check_dataset(out: &Path) -> Dataset {
    let d = Dataset::read(out.join("dataset.npz")).unwrap();
    let n = RUNS * SAMPLES;
    let r = d.n_roi();
    assert!(r > 10, "ROI of {r} elements");
    assert_eq!(d.x.dim(), (n, 5));
    assert_eq!(d.y.dim(), (n, r));
    assert_eq!(d.stress.as_ref().unwrap().dim(), (n, r, 6));
    assert_eq!(d.roi_ids.len(), r);
    assert_eq!(d.roi_centroids.dim(), (r, 3));
    assert_eq!(d.manifest.x_columns, ["x", "y", "force", "time", "depth"]);
    assert_eq!(d.manifest.location_labels, ["P07", "P12", "A"]);
    for i in 0..n {
        let run = i / SAMPLES;
        assert_eq!(d.location[i], run as i64, "row {i}");
        assert_eq!(d.split[i], u8::from(run == 2), "row {i}");
        let t = d.x[(i, 3)];
        let want = (i % SAMPLES) as f64 * 0.5e-3;
        assert!(
            (t - want).abs() < 0.05e-3,
            "row {i}: time {t}, expected {want}"
        );
    }
    // the fingers push in each run, and the ROI feels it
    for run in 0..RUNS {
        let rows = run * SAMPLES..(run + 1) * SAMPLES;
        assert!(
            rows.clone().any(|i| d.x[(i, 2)] > 0.0),
            "run {run}: no force"
        );
        assert!(
            d.y.row(rows.end - 1).iter().any(|v| v.abs() > 0.0),
            "run {run}: no stress"
        );
    }
    assert!(out.join("manifest.json").is_file() && out.join("dataset.json").is_file());
    d
}

#[test]
fn chain_and_two_shards_merged_equal_one_unsharded_run() {
    let tmp = tempfile::tempdir().unwrap();
    let file = tiny(tmp.path());
    let full = tmp.path().join("full");
    ok(&["campaign", s(&file), "--out", s(&full), "--quiet"]);
    assert_eq!(done_count(&full), RUNS);
    let d = check_dataset(&full);
    assert_eq!(d.manifest.solver["version"], env!("CARGO_PKG_VERSION"));

    // the plan view: the dataset's ROI, outlines, and the same geometry when train rebuilds it
    let view = ViewGeometry::read(&full.join("view.json")).unwrap();
    assert_eq!(view.roi_ids, d.roi_ids.to_vec());
    assert!(!view.liver.is_empty() && !view.ribs.is_empty());
    let model = tmp.path().join("gp");
    ok(&["train", s(&full), "--model", "gp", "--out", s(&model)]);
    assert_eq!(ViewGeometry::read(&model.join("view.json")).unwrap(), view);
    let bare = tmp.path().join("bare");
    std::fs::create_dir_all(&bare).unwrap();
    for f in ["dataset.npz", "manifest.json"] {
        std::fs::copy(full.join(f), bare.join(f)).unwrap();
    }
    let derived_model = tmp.path().join("gp-derived");
    ok(&[
        "train",
        s(&bare),
        "--model",
        "gp",
        "--out",
        s(&derived_model),
    ]);
    let derived = ViewGeometry::read(&derived_model.join("view.json")).unwrap();
    assert!(derived.source.contains("rebuilt"), "{}", derived.source);
    assert_eq!(
        ViewGeometry {
            source: view.source.clone(),
            ..derived
        },
        view,
        "the phantom rebuilt from the manifest gives the campaign's geometry"
    );
    let png = tmp.path().join("map.png");
    let out = ok(&[
        "predict",
        s(&model),
        "--x=-0.05",
        "--y=0.2",
        "--force=1",
        "--png",
        s(&png),
    ]);
    assert!(png.is_file(), "{out}");

    let (s0, s1) = (tmp.path().join("s0"), tmp.path().join("s1"));
    ok(&[
        "campaign",
        s(&file),
        "--out",
        s(&s0),
        "--shard",
        "0/2",
        "--jobs",
        "1",
        "--quiet",
    ]);
    ok(&[
        "campaign",
        s(&file),
        "--out",
        s(&s1),
        "--shard",
        "1/2",
        "--jobs",
        "1",
        "--quiet",
    ]);
    assert_eq!((done_count(&s0), done_count(&s1)), (2, 1));
    // a merge that misses a shard names the missing runs
    let o = palpa(&[
        "campaign",
        "merge",
        s(&s0),
        "--out",
        s(&tmp.path().join("bad")),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("P12"), "{err}");

    let merged = tmp.path().join("merged");
    ok(&[
        "campaign",
        "merge",
        s(&s0),
        s(&s1),
        "--out",
        s(&merged),
        "--quiet",
    ]);
    assert_eq!(done_count(&merged), RUNS);
    for f in ["dataset.npz", "manifest.json", "dataset.json", "view.json"] {
        let a = std::fs::read(full.join(f)).unwrap();
        let b = std::fs::read(merged.join(f)).unwrap();
        assert!(
            a == b,
            "{f}: merged shards differ from the unsharded campaign"
        );
    }
    merge_into_a_stale_directory_is_refused(tmp.path(), &merged, &s0, &s1);
}

/// A merge keeps the finished runs it finds in `--out`: into a directory that holds another
/// campaign, or runs of unknown origin, it is refused before anything is copied.
fn merge_into_a_stale_directory_is_refused(tmp: &Path, merged: &Path, s0: &Path, s1: &Path) {
    let other = tmp.join("other");
    std::fs::create_dir_all(&other).unwrap();
    let mut v: serde_json::Value =
        serde_json::from_slice(&std::fs::read(merged.join("campaign.json")).unwrap()).unwrap();
    let runs = v["plan"]["runs"].as_array_mut().unwrap();
    runs.pop();
    std::fs::write(other.join("campaign.json"), v.to_string()).unwrap();
    let o = palpa(&["campaign", "merge", s(s0), s(s1), "--out", s(&other)]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("holds another campaign") && err.contains("plan.runs"),
        "{err}"
    );
    assert!(!other.join("runs").exists(), "nothing copied");

    // the same plan with `26` written `26.0` (a hand-edited campaign.json) is this campaign
    let refloat = tmp.join("refloat");
    std::fs::create_dir_all(&refloat).unwrap();
    let mut v: serde_json::Value =
        serde_json::from_slice(&std::fs::read(merged.join("campaign.json")).unwrap()).unwrap();
    let samples = &mut v["plan"]["runs"][0]["samples"];
    let n = samples.as_u64().expect("samples is an integer");
    *samples = serde_json::json!(n as f64);
    std::fs::write(refloat.join("campaign.json"), v.to_string()).unwrap();
    ok(&[
        "campaign",
        "merge",
        s(s0),
        s(s1),
        "--out",
        s(&refloat),
        "--quiet",
    ]);
    assert_eq!(done_count(&refloat), RUNS);

    let unknown = tmp.join("unknown");
    std::fs::create_dir_all(unknown.join("runs").join("P01")).unwrap();
    let o = palpa(&["campaign", "merge", s(s0), s(s1), "--out", s(&unknown)]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("holds runs but no campaign.json"),
        "{err}"
    );
}

#[test]
fn killed_campaign_resumes_without_losing_or_repeating_runs() {
    let tmp = tempfile::tempdir().unwrap();
    let file = tiny(tmp.path());
    let out = tmp.path().join("c");
    let mut child = Command::new(env!("CARGO_BIN_EXE_palpa"))
        .args([
            "campaign",
            s(&file),
            "--out",
            s(&out),
            "--jobs",
            "1",
            "--threads",
            "1",
            "--quiet",
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    while done_count(&out) == 0 {
        assert!(t0.elapsed() < Duration::from_secs(120), "no run finished");
        assert!(
            child.try_wait().unwrap().is_none(),
            "the campaign ended early"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let done = done_count(&out);
    assert!(
        (1..RUNS).contains(&done),
        "{done} runs finished before the kill"
    );
    let first = out.join("runs/P07/done.json");
    let marker = std::fs::read(&first).unwrap();
    assert!(!out.join("dataset.npz").exists());
    // an unfinished run directory (as a kill mid-run leaves it) is redone from scratch
    let partial = out.join("runs/A");
    std::fs::create_dir_all(&partial).unwrap();
    std::fs::write(partial.join("probe.csv"), "time\n0\n").unwrap();

    // without --resume the finished runs are not touched
    let o = palpa(&["campaign", s(&file), "--out", s(&out), "--quiet"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("--resume"), "{err}");

    let stdout = ok(&["campaign", s(&file), "--out", s(&out), "--resume"]);
    assert!(
        stdout.contains(&format!("{done} finished, {} to run", RUNS - done)),
        "{stdout}"
    );
    assert_eq!(stdout.matches("  done ").count(), RUNS - done, "{stdout}");
    assert!(!stdout.contains("done P07"), "{stdout}");
    assert_eq!(
        std::fs::read(&first).unwrap(),
        marker,
        "a finished run was recomputed"
    );
    assert_eq!(done_count(&out), RUNS);
    check_dataset(&out);
    // resuming a finished campaign runs nothing and rewrites the same dataset
    let before = std::fs::read(out.join("dataset.npz")).unwrap();
    let stdout = ok(&["campaign", s(&file), "--out", s(&out), "--resume"]);
    assert!(
        stdout.contains(&format!("{RUNS} finished, 0 to run")),
        "{stdout}"
    );
    assert_eq!(std::fs::read(out.join("dataset.npz")).unwrap(), before);
    // a finished run the plan does not name (as runs copied from a design with fewer digits
    // are) is named on stderr, even with --quiet, and not reused
    let stray = out.join("runs/P7");
    std::fs::create_dir_all(&stray).unwrap();
    for e in std::fs::read_dir(out.join("runs/P07")).unwrap() {
        let e = e.unwrap();
        std::fs::copy(e.path(), stray.join(e.file_name())).unwrap();
    }
    let o = palpa(&[
        "campaign",
        s(&file),
        "--out",
        s(&out),
        "--resume",
        "--quiet",
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        o.status.success()
            && err.contains("holds 1 finished run(s) this campaign does not name (P7)"),
        "{err}"
    );
    assert_eq!(std::fs::read(out.join("dataset.npz")).unwrap(), before);
}

#[test]
fn shipped_profiles_resolve_and_bad_keys_are_named() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    // `palpa campaign scenes/NAME --dry-run`: the plan's table
    let dry_run = |name: &str| ok(&["campaign", s(&root.join("scenes").join(name)), "--dry-run"]);
    let quick = dry_run("campaign-quick.toml");
    assert!(
        quick.contains("5 runs (5 locations: 4 train, 1 test)"),
        "{quick}"
    );
    assert_eq!(quick.matches("to run").count(), 5, "{quick}");
    let paper = dry_run("campaign-paper.toml");
    assert!(
        paper.contains("28 runs (28 locations: 25 train, 3 test)"),
        "{paper}"
    );
    assert!(paper.contains("voxel 3.0 mm"), "{paper}");
    // the same campaign on 5 mm voxels: the same runs at the same places (label, location,
    // split, x, y); what lies under them (the liver depth column) is read from each mesh
    let five = dry_run("campaign-5mm.toml");
    assert!(five.contains("voxel 5.0 mm"), "{five}");
    let places = |t: &str| -> Vec<String> {
        t.lines()
            .skip(2)
            .map(|l| l.split_whitespace().take(5).collect::<Vec<_>>().join(" "))
            .collect()
    };
    assert_eq!(places(&five).len(), 28, "{five}");
    assert_eq!(places(&five), places(&paper));
    // the default with the fast preset (data/campaign-paper-fast-3mm): the same runs
    let fast = dry_run("campaign-paper-fast.toml");
    assert!(fast.contains("voxel 3.0 mm"), "{fast}");
    assert_eq!(places(&fast), places(&paper));
    let fbar = dry_run("campaign-fbar-8mm.toml");
    assert!(
        fbar.contains("28 runs (28 locations: 25 train, 3 test)") && fbar.contains("voxel 8.0 mm"),
        "{fbar}"
    );
    // the y of each raster row in a plan table, from the rows whose label starts with `prefix`
    let ys = |table: &str, prefix: char| -> Vec<f64> {
        table
            .lines()
            .filter(|l| l.trim_start().starts_with(prefix))
            .filter_map(|l| l.split_whitespace().nth(4)?.parse().ok())
            .collect()
    };
    // the default raster (P01..P25) covers the ROI's plan extent: rows 15 mm apart, y = 225..165 mm
    let p = ys(&paper, 'P');
    assert_eq!(p.len(), 25, "{paper}");
    assert!(
        (p[0] - 225.0).abs() < 1e-9 && (p[24] - 165.0).abs() < 1e-9,
        "{p:?}"
    );
    // the earlier raster: rows 25 mm apart, y = 245..145 mm, with the default A, B, C
    let wide = dry_run("campaign-wide-grid.toml");
    assert!(
        wide.contains("28 runs (28 locations: 25 train, 3 test)"),
        "{wide}"
    );
    let w = ys(&wide, 'W');
    assert_eq!(w.len(), 25, "{wide}");
    assert!(
        (w[0] - 245.0).abs() < 1e-9 && (w[24] - 145.0).abs() < 1e-9,
        "{w:?}"
    );
    // the test locations' rows of a plan table (label, location, split, x, y)
    let abc = |t: &str| -> Vec<String> {
        places(t)
            .into_iter()
            .filter(|l| ["A ", "B ", "C "].iter().any(|k| l.starts_with(k)))
            .collect()
    };
    assert_eq!(abc(&paper).len(), 3, "{paper}");
    assert_eq!(abc(&paper), abc(&wide));
    // the mesh-convergence row: the default's P01..P04 at the same places on 2.5 mm voxels
    let fine = dry_run("campaign-convergence-2.5mm.toml");
    assert!(
        fine.contains("4 runs (4 locations: 4 train, 0 test)") && fine.contains("voxel 2.5 mm"),
        "{fine}"
    );
    assert_eq!(places(&fine), places(&paper)[..4].to_vec(), "{fine}");

    let tmp = tempfile::tempdir().unwrap();
    let bad = tmp.path().join("bad.toml");
    // a campaign file that must fail with an error naming the file and `key`
    let fails_naming = |text: &str, key: &str| {
        std::fs::write(&bad, text).unwrap();
        let o = palpa(&["campaign", s(&bad), "--dry-run"]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            !o.status.success() && err.contains(key) && err.contains("bad.toml"),
            "{err}"
        );
    };
    // the Sobol front's profile: 100 design points S001..S100 in the ROI's plan extent,
    // A, B, C and 12 random held-out points T01..T12
    let sobol = dry_run("campaign-sobol-5mm.toml");
    assert!(
        sobol.contains("115 runs (115 locations: 100 train, 15 test)"),
        "{sobol}"
    );
    let sx = ys(&sobol, 'S');
    assert_eq!(sx.len(), 100, "{sobol}");
    assert!(sx.iter().all(|y| (165.0..=225.0).contains(y)), "{sx:?}");
    // the 3 mm front's profile: the same sequence, 200 points, its first 100 the 5 mm front's,
    // and the same held-out points
    let sobol3 = dry_run("campaign-sobol-3mm.toml");
    assert!(
        sobol3.contains("215 runs (215 locations: 200 train, 15 test)")
            && sobol3.contains("voxel 3.0 mm"),
        "{sobol3}"
    );
    let (s5, s3) = (profile_points(&sobol, 'S'), profile_points(&sobol3, 'S'));
    assert_eq!((s5.len(), s3.len()), (100, 200), "{sobol3}");
    assert_eq!(s3[..100], s5[..]);
    assert_eq!(profile_points(&sobol3, 'T'), profile_points(&sobol, 'T'));
    assert_eq!(profile_points(&sobol3, 'T').len(), 12);
    // the raster and the adaptive start of the 3 mm front share those held-out points, and the
    // adaptive start is the Sobol design's first 10
    let grid3 = dry_run("campaign-grid-3mm-fast.toml");
    assert!(
        grid3.contains("40 runs (40 locations: 25 train, 15 test)"),
        "{grid3}"
    );
    let adaptive3 = dry_run("campaign-adaptive-3mm.toml");
    assert!(
        adaptive3.contains("25 runs (25 locations: 10 train, 15 test)"),
        "{adaptive3}"
    );
    for table in [&grid3, &adaptive3] {
        assert!(table.contains("voxel 3.0 mm"), "{table}");
        assert_eq!(profile_points(table, 'T'), profile_points(&sobol3, 'T'));
    }
    assert_eq!(profile_points(&adaptive3, 'S'), s3[..10]);
    fitted_profiles_match_the_3mm_front(&dry_run, &sobol3, &s3);
    // the respiratory design: Sobol over (x, y, phase), whose (x, y) are the plain design's
    let breath = dry_run("campaign-respiration-5mm.toml");
    assert!(
        breath.contains("221 runs (221 locations: 200 train, 21 test)")
            && breath.contains(" phase "),
        "{breath}"
    );
    assert_eq!(profile_points(&breath, 'S')[..100], s5[..]);
    fails_naming("[indentation]\ndepht = \"5 mm\"\n", "depht");
    fails_naming(
        "[[locations.design]]\nkind = \"halton\"\nn = 4\nseed = 1\nsplit = \"train\"\n",
        "halton",
    );
    fails_naming(
        "[[locations.design]]\nkind = \"lhs\"\nn = 4\nseed = 1\nsplit = \"train\"\npolygon = [[\"0 mm\", \"0 mm\"], [\"1 mm\", \"0 mm\"], [\"0 mm\", \"1 mm\"]]\n",
        "polygon",
    );
    // a value out of range names the file and the key
    fails_naming("[phantom]\nfat_thickness = \"-5 mm\"\n", "fat_thickness");
    let o = palpa(&["campaign", "--shard", "2/2", "--dry-run"]);
    assert!(!o.status.success());
}

/// The (x, y) cells of a dry run's rows whose label starts with `prefix`.
fn profile_points(table: &str, prefix: char) -> Vec<(String, String)> {
    table
        .lines()
        .filter(|l| l.trim_start().starts_with(prefix))
        .filter_map(|l| {
            let w: Vec<&str> = l.split_whitespace().collect();
            Some((w.get(3)?.to_string(), w.get(4)?.to_string()))
        })
        .collect()
}

/// The fitted-skin profiles: the Sobol one holds the 3 mm front's 200 points (`s3`) and its
/// held-out points; the adaptive one starts from the first 10, on the same fitted mesh.
fn fitted_profiles_match_the_3mm_front(
    dry_run: &dyn Fn(&str) -> String,
    sobol3: &str,
    s3: &[(String, String)],
) {
    // the fitted-skin front: the 3 mm front's 200 points and its held-out points
    let fitted3 = dry_run("campaign-sobol-3mm-fitted.toml");
    assert!(
        fitted3.contains("215 runs (215 locations: 200 train, 15 test)"),
        "{fitted3}"
    );
    assert_eq!(profile_points(&fitted3, 'S'), s3);
    assert_eq!(profile_points(&fitted3, 'T'), profile_points(sobol3, 'T'));
    // and its adaptive design starts from the same first 10 points, with the fitted skin
    let fitted_adaptive3 = dry_run("campaign-adaptive-3mm-fitted.toml");
    assert!(
        fitted_adaptive3.contains("25 runs (25 locations: 10 train, 15 test)"),
        "{fitted_adaptive3}"
    );
    assert_eq!(profile_points(&fitted_adaptive3, 'S'), s3[..10]);
    assert_eq!(
        profile_points(&fitted_adaptive3, 'T'),
        profile_points(sobol3, 'T')
    );
    // the fitted skin's mesh, not the voxel skin's: the header's hexahedra
    let hexes = |t: &str| {
        t.lines()
            .next()
            .and_then(|l| l.split(" hexahedra").next()?.rsplit(' ').next())
            .map(String::from)
    };
    assert_eq!(hexes(&fitted_adaptive3), hexes(&fitted3));
    assert_ne!(hexes(&fitted3), hexes(&sobol3));
}

/// Issue 29: `sample_interval = "1e-320 s"` was accepted and the campaign never ended; a run
/// with more samples than the limit is refused, naming the key, unless the limit is raised.
#[test]
fn tiny_sample_interval_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let p = tmp.path().join("tiny-interval.toml");
    for (interval, expect) in [
        ("1e-320 s", "more than the limit of 1000000"),
        ("-1 ms", "must be a positive finite time"),
    ] {
        std::fs::write(
            &p,
            TINY.replace(
                "sample_interval = \"0.5 ms\"",
                &format!("sample_interval = \"{interval}\""),
            ),
        )
        .unwrap();
        let o = palpa(&["campaign", s(&p), "--dry-run"]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            !o.status.success()
                && err.contains("tiny-interval.toml")
                && err.contains("indentation.sample_interval")
                && err.contains(expect),
            "{interval}: {err}"
        );
    }
    // 1 ns over 1 ms is 1e6 + 1 samples: refused by default, accepted when raised.
    let text = TINY.replace("sample_interval = \"0.5 ms\"", "sample_interval = \"1 ns\"");
    std::fs::write(&p, &text).unwrap();
    assert!(!palpa(&["campaign", s(&p), "--dry-run"]).status.success());
    std::fs::write(
        &p,
        text.replace("[indentation]", "[indentation]\nmax_samples = 2e6"),
    )
    .unwrap();
    ok(&["campaign", s(&p), "--dry-run"]);
}

/// A respiratory campaign (`[locations] phases`): every location at each phase, labelled
/// `<label>-ph<phase>`; the dataset's sixth input column is the phase; each run reads the
/// reference ROI's points through its `roi_map.json`; a run at the reference phase is the plain
/// run bit for bit (the same phantom, ROI and press); `palpa train` fits on (x, y, force,
/// phase), and `palpa predict --phase` takes it (refused for a model without one).
#[test]
fn respiratory_campaign_adds_the_phase_as_an_input() {
    let tmp = tempfile::tempdir().unwrap();
    let plain_file = tmp.path().join("plain.toml");
    let base = TINY.replace("train = [\"P07\", \"P12\"]", "train = [\"P07\"]");
    std::fs::write(&plain_file, &base).unwrap();
    let resp_file = tmp.path().join("resp.toml");
    let resp = base.replace("test = [\"A\"]", "test = [\"A\"]\nphases = [0.0, 1.0]");
    std::fs::write(&resp_file, &resp).unwrap();
    let (plain, breath) = (tmp.path().join("plain"), tmp.path().join("breath"));
    for (file, out) in [(&plain_file, &plain), (&resp_file, &breath)] {
        ok(&["campaign", s(file), "--out", s(out), "--quiet"]);
    }
    let p = Dataset::read(plain.join("dataset.npz")).unwrap();
    let d = Dataset::read(breath.join("dataset.npz")).unwrap();
    assert_eq!(
        d.manifest.x_columns,
        ["x", "y", "force", "time", "depth", "phase"]
    );
    assert_eq!(
        d.manifest.location_labels,
        ["P07-ph0", "P07-ph1", "A-ph0", "A-ph1"]
    );
    assert_eq!(d.n_roi(), p.n_roi());
    assert_eq!(d.roi_ids, p.roi_ids);
    for i in 0..d.n_samples() {
        let want = [0.0, 1.0][d.location[i] as usize % 2];
        assert_eq!(d.x[(i, 5)], want, "row {i}");
    }
    // the reference phase: the plain campaign's rows, bit for bit (P07 and A)
    for (pl, dl) in [(0i64, 0i64), (1, 2)] {
        let rows = |ds: &Dataset, l: i64| -> Vec<usize> {
            (0..ds.n_samples())
                .filter(|&i| ds.location[i] == l)
                .collect()
        };
        let (a, b) = (rows(&p, pl), rows(&d, dl));
        assert_eq!(a.len(), b.len());
        for (&i, &j) in a.iter().zip(&b) {
            assert_eq!(p.y.row(i), d.y.row(j), "location {dl}, row {j}");
            for c in 0..5 {
                assert_eq!(
                    p.x[(i, c)],
                    d.x[(j, c)],
                    "location {dl}, row {j}, column {c}"
                );
            }
        }
    }
    // each run's ROI map: the plan's ROI at phase 0, the liver's points carried at phase 1
    let map = |label: &str| -> Vec<i64> {
        let t =
            std::fs::read_to_string(breath.join("runs").join(label).join("roi_map.json")).unwrap();
        let v: serde_json::Value = serde_json::from_str(&t).unwrap();
        v["roi_elements"]
            .as_array()
            .unwrap()
            .iter()
            .map(|e| e.as_i64().unwrap())
            .collect()
    };
    assert_eq!(map("A-ph0"), p.roi_ids.to_vec());
    assert_eq!(map("A-ph1").len(), p.n_roi());
    assert_ne!(map("A-ph1"), p.roi_ids.to_vec());
    phase_model_takes_the_phase(tmp.path(), &breath, &plain, &d);
}

/// The respiratory campaign's model takes the phase (`palpa predict --phase`, `--stdin` lines
/// with and without `"phase"`, `palpa serve`'s phase message); `--ignore-phase` and the plain
/// campaign's model take x, y and force only, and refuse a phase.
fn phase_model_takes_the_phase(tmp: &Path, breath: &Path, plain: &Path, d: &Dataset) {
    let model = tmp.join("gp");
    ok(&["train", s(breath), "--model", "gp", "--out", s(&model)]);
    let meta = std::fs::read_to_string(model.join("model.json")).unwrap();
    assert!(
        meta.contains(
            "\"input_columns\": [\n    \"x\",\n    \"y\",\n    \"force\",\n    \"phase\"\n  ]"
        ),
        "{meta}"
    );
    let xy = [format!("{}", d.x[(0, 0)]), format!("{}", d.x[(0, 1)])];
    let at = |m: &Path, phase: &str| {
        palpa(&[
            "predict",
            s(m),
            "--x",
            &xy[0],
            "--y",
            &xy[1],
            "--force",
            "1",
            "--phase",
            phase,
        ])
    };
    let o = at(&model, "0.5");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("respiratory phase 0.5"));
    let o = at(&model, "1.5");
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("phase = 1.5 is outside 0"));
    // --stdin: a line without "phase" is at phase 0, not the line before's
    let stream = |m: &Path, lines: &str| -> Vec<serde_json::Value> {
        let out = cli::predict_stdin(m, lines.as_bytes());
        String::from_utf8_lossy(&out.stdout)
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect()
    };
    let line = |phase: &str| {
        format!(
            "{{\"x\": {}, \"y\": {}, \"force\": 20{phase}}}\n",
            xy[0], xy[1]
        )
    };
    let lines = [line(", \"phase\": 1"), line(""), line(", \"phase\": 0")].concat();
    let r = stream(&model, &lines);
    assert_eq!(r.len(), 3, "{r:?}");
    assert_eq!(r[1]["stress"], r[2]["stress"]);
    assert_ne!(r[0]["stress"], r[1]["stress"]);
    // served: the phase message reaches the model, and the liver is drawn where it moves
    let server = serve_support::Server::start(&model, &[]);
    let mut screen = server.connect();
    screen.next_of("frame");
    let fmax = d.x.column(2).fold(0.0f64, |a, &b| a.max(b));
    let press = format!(
        r#"{{"type":"pointer","x":{},"y":{},"force":{fmax}}}"#,
        xy[0], xy[1]
    );
    screen.send(&press);
    let at0 = screen.next_of("frame");
    screen.send(r#"{"type":"phase","value":0.5}"#);
    let at5 = screen.next_of("frame");
    assert_eq!(at0["liver_shift"], 0.0);
    assert!(
        (at5["liver_shift"].as_f64().unwrap() - 0.01).abs() < 1e-12,
        "{at5}"
    );
    assert_ne!(
        at0["stress"], at5["stress"],
        "the phase does not reach the model"
    );
    drop(server);
    let blind = tmp.join("blind");
    ok(&[
        "train",
        s(breath),
        "--model",
        "gp",
        "--ignore-phase",
        "--out",
        s(&blind),
    ]);
    let meta = std::fs::read_to_string(blind.join("model.json")).unwrap();
    assert!(!meta.contains("\"phase\""), "{meta}");
    let flat = tmp.join("flat");
    ok(&["train", s(plain), "--model", "gp", "--out", s(&flat)]);
    let o = at(&flat, "0.5");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("takes x, y and force only"),
        "{err}"
    );
    let r = stream(&flat, &line(", \"phase\": 0.5"));
    let e = r[0]["error"].as_str().unwrap_or_default();
    assert!(e.contains("takes x, y and force only"), "{r:?}");
}

/// `palpa train --leave-out P07` learns from P12 alone (3 samples); a label that is not a
/// training location (the held-out A, or one not among the first --train-locations) is named.
fn left_out_locations_are_not_learned(tmp: &Path, campaign: &Path) {
    let model = tmp.join("gp-left-out");
    let train = |more: &[&str]| {
        let mut args = vec!["train", s(campaign), "--model", "gp", "--out", s(&model)];
        args.extend(more);
        palpa(&args)
    };
    let o = train(&["--leave-out", "P07"]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success() && text.contains("3 training samples from 1 locations"),
        "{text}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    for (more, label) in [
        (&["--leave-out", "A"][..], "A"),
        (&["--train-locations", "1", "--leave-out", "P12"][..], "P12"),
    ] {
        fails_with(
            &train(more),
            &format!("`{label}` is not a training location of the selection"),
        );
    }
}

/// `--likelihood-rows N` caps the rows of the GP's hyperparameter search at N (the trained
/// model says how many it took), and fewer than 2 rows are refused naming the flag.
fn likelihood_rows_reach_the_gp(tmp: &Path, campaign: &Path) {
    let model = tmp.join("gp-rows");
    let train = |rows: &str| {
        palpa(&[
            "train",
            s(campaign),
            "--model",
            "gp",
            "--likelihood-rows",
            rows,
            "--out",
            s(&model),
        ])
    };
    let o = train("3");
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success() && text.contains("(3 in the likelihood)"),
        "{text}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let mlp = palpa(&[
        "train",
        s(campaign),
        "--model",
        "mlp",
        "--likelihood-rows",
        "3",
        "--out",
        s(&model),
    ]);
    fails_with(&mlp, "--likelihood-rows sets the GP's");
    for bad in [
        train("1"),
        palpa(&["front", "d=x", "--likelihood-rows", "0", "--out", s(&model)]),
    ] {
        let err = String::from_utf8_lossy(&bad.stderr);
        assert!(
            !bad.status.success()
                && err.contains("--likelihood-rows")
                && err.contains("at least 2"),
            "{err}"
        );
    }
}

/// `--with FRONT.csv` puts an earlier front's rows, as written, before the new design's; a point
/// (design, runs) may not be given twice, by a new design or by two fronts, and a front of other
/// settings (target, likelihood rows) is refused.
fn earlier_front_joins_a_new_one(tmp: &Path, campaign: &Path) {
    let earlier = tmp.join("whole/front.csv");
    let joined = tmp.join("joined");
    let front = |name: &str| {
        palpa(&[
            "front",
            &format!("{name}={}", s(campaign)),
            "--runs",
            "1",
            "--with",
            s(&earlier),
            "--out",
            s(&joined),
        ])
    };
    let o = front("again");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let old: Vec<String> = std::fs::read_to_string(&earlier)
        .unwrap()
        .lines()
        .map(String::from)
        .collect();
    let new: Vec<String> = std::fs::read_to_string(joined.join("front.csv"))
        .unwrap()
        .lines()
        .map(String::from)
        .collect();
    assert_eq!(new.len(), old.len() + 1, "{new:?}");
    assert_eq!(new[..old.len()], old[..]);
    assert!(new[old.len()].starts_with("again,1,"), "{new:?}");
    let o = front("d");
    fails_with(
        &o,
        "design `d` at 1 runs is already a point of a --with front",
    );
    let o = palpa(&[
        "front",
        "e=x",
        "--with",
        s(&earlier),
        "--with",
        s(&earlier),
        "--out",
        s(&joined),
    ]);
    fails_with(&o, "design `d` at 1 runs is given twice");
    // the earlier front learned the element stress from every sample: a recovered front, or
    // one with another likelihood cap, refuses it, naming both settings
    for (flag, value, here) in [
        (
            "--recover",
            "5 mm",
            "recovered H = 5 mm; every sample; 600 likelihood rows",
        ),
        (
            "--likelihood-rows",
            "300",
            "element stress; every sample; 300 likelihood rows",
        ),
    ] {
        let o = palpa(&[
            "front",
            "e=x",
            flag,
            value,
            "--with",
            s(&earlier),
            "--out",
            s(&joined),
        ]);
        fails_with(
            &o,
            &format!("d at 1 runs was measured with element stress; every sample; 600 likelihood rows, this front with {here}"),
        );
    }
}

/// `palpa front` on a campaign still running (no dataset.npz) reads its finished runs: the
/// training locations before the first unfinished one, and every held-out one; its row at
/// that count equals the finished campaign's. An unfinished held-out run is named.
#[test]
fn front_reads_the_finished_runs_of_a_running_campaign() {
    let tmp = tempfile::tempdir().unwrap();
    let file = tiny(tmp.path());
    let out = tmp.path().join("c");
    ok(&["campaign", s(&file), "--out", s(&out), "--quiet"]);
    likelihood_rows_reach_the_gp(tmp.path(), &out);
    left_out_locations_are_not_learned(tmp.path(), &out);
    let front = |name: &str| {
        let dir = tmp.path().join(name);
        let o = palpa(&[
            "front",
            &format!("d={}", s(&out)),
            "--runs",
            "1,2",
            "--out",
            s(&dir),
        ]);
        let csv = std::fs::read_to_string(dir.join("front.csv")).unwrap_or_default();
        // the rows without the GP's training time (the 9th cell)
        let rows: Vec<String> = csv
            .lines()
            .skip(1)
            .map(|l| {
                let mut cells: Vec<&str> = l.split(',').collect();
                cells.remove(8);
                cells.join(",")
            })
            .collect();
        (o, rows)
    };
    let (o, whole) = front("whole");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(whole.len(), 2, "{whole:?}");
    earlier_front_joins_a_new_one(tmp.path(), &out);
    // the campaign stopped with P12, its second training location, unfinished
    for f in [
        "dataset.npz",
        "manifest.json",
        "dataset.json",
        "runs/P12/done.json",
    ] {
        let _ = std::fs::remove_file(out.join(f));
    }
    let (o, running) = front("running");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        o.status.success()
            && err.contains("the first 1 of 2 training locations")
            && err.contains("it stops at P12")
            && err.contains("2 runs skipped (only the first 1 training locations are finished)"),
        "{err}"
    );
    assert_eq!(running, whole[..1], "{err}");
    // without its held-out run there is nothing to score: the error names it
    std::fs::remove_file(out.join("runs/A/done.json")).unwrap();
    let (o, _) = front("no-test");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("held-out run(s) not finished: A"),
        "{err}"
    );
}
