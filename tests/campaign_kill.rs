//! A campaign killed with SIGKILL at seeded random moments (during a run, between runs, while
//! the dataset is assembled, and at random times) and resumed after each kill ends with the
//! same bytes as one uninterrupted campaign: nothing lost, duplicated or half-written. After
//! every kill, each file under its final name is whole: every `done.json` parses, a finished
//! run's outputs and every campaign-level file that exists equal the uninterrupted campaign's.
//! The seed is `PALPA_KILL_SEED` (default below); a failure prints it.
#![cfg(unix)]

#[path = "support/tiny_campaign.rs"]
mod tiny_campaign;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};
use tiny_campaign::{done_count, tiny, RUNS};

/// Files whose bytes legitimately differ between two runs (wall times, finish times).
const TIMED: [&str; 2] = ["done.json", "summary.json"];

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn spawn(file: &Path, out: &Path, resume: bool) -> Child {
    let mut args = vec![
        "campaign",
        s(file),
        "--out",
        s(out),
        "--jobs",
        "1",
        "--threads",
        "1",
        "--quiet",
    ];
    if resume {
        args.push("--resume");
    }
    Command::new(env!("CARGO_BIN_EXE_palpa"))
        .args(&args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Every file under `dir`, by path relative to it.
fn files(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    fn walk(root: &Path, dir: &Path, out: &mut BTreeMap<PathBuf, Vec<u8>>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(root, &p, out);
            } else {
                // a file may vanish between listing and reading (a temporary renamed)
                if let Ok(b) = std::fs::read(&p) {
                    out.insert(p.strip_prefix(root).unwrap().to_path_buf(), b);
                }
            }
        }
    }
    let mut m = BTreeMap::new();
    if dir.is_dir() {
        walk(dir, dir, &mut m);
    }
    m
}

fn is_timed(p: &Path) -> bool {
    TIMED.iter().any(|t| p.file_name().unwrap() == *t)
}

fn is_temporary(p: &Path) -> bool {
    p.extension().is_some_and(|e| e == "tmp")
}

/// xorshift64*: the kill moments, reproducible from the seed.
struct Rng(u64);
impl Rng {
    fn unit(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Moment {
    /// Some time into a run that has started and not finished.
    DuringRun,
    /// As soon as a run has finished (its `done.json` written).
    BetweenRuns,
    /// Once every run has finished: while the dataset is assembled.
    DuringAssembly,
    /// This many seconds after the start.
    At(f64),
}

fn running_run(out: &Path) -> bool {
    std::fs::read_dir(out.join("runs"))
        .map(|d| {
            d.flatten()
                .any(|e| e.path().is_dir() && !e.path().join("done.json").exists())
        })
        .unwrap_or(false)
}

/// Waits for `moment` (or for the campaign to end); kills it there. Whether it was killed.
fn kill_at(child: &mut Child, out: &Path, moment: Moment, rng: &mut Rng) -> bool {
    let t0 = Instant::now();
    let done0 = done_count(out);
    let mut seen_running = None;
    loop {
        if child.try_wait().unwrap().is_some() {
            return false;
        }
        assert!(t0.elapsed() < Duration::from_secs(300), "campaign stalled");
        let fire = match moment {
            Moment::DuringRun => {
                if running_run(out) {
                    let since = *seen_running.get_or_insert_with(|| {
                        Instant::now() + Duration::from_secs_f64(0.05 + 0.4 * rng.unit())
                    });
                    Instant::now() >= since
                } else {
                    false
                }
            }
            Moment::BetweenRuns => done_count(out) > done0,
            Moment::DuringAssembly => done_count(out) == RUNS,
            Moment::At(t) => t0.elapsed().as_secs_f64() >= t,
        };
        if fire {
            if moment == Moment::DuringAssembly {
                std::thread::sleep(Duration::from_secs_f64(0.03 * rng.unit()));
            }
            child.kill().unwrap(); // SIGKILL
            child.wait().unwrap();
            return true;
        }
        std::thread::sleep(Duration::from_millis(2));
    }
}

/// No file under its final name is half-written: finished runs and campaign-level files equal
/// the uninterrupted campaign's, every `done.json` parses.
fn check_whole(out: &Path, reference: &BTreeMap<PathBuf, Vec<u8>>, ctx: &str) {
    let now = files(out);
    for (p, bytes) in &now {
        if is_temporary(p) {
            continue;
        }
        let in_run = p.starts_with("runs");
        let run_done = in_run && out.join(p.parent().unwrap()).join("done.json").exists();
        if p.file_name().unwrap() == "done.json" {
            let v: serde_json::Value = serde_json::from_slice(bytes)
                .unwrap_or_else(|e| panic!("{ctx}: {} is not whole: {e}", p.display()));
            assert_eq!(v["status"], "completed", "{ctx}: {}", p.display());
        } else if is_timed(p) || (in_run && !run_done) {
            continue;
        } else {
            let want = reference
                .get(p)
                .unwrap_or_else(|| panic!("{ctx}: unexpected file {}", p.display()));
            assert!(
                bytes == want,
                "{ctx}: {} differs from the uninterrupted campaign's",
                p.display()
            );
        }
    }
}

#[test]
fn a_campaign_killed_at_random_moments_resumes_to_the_same_bytes() {
    let seed: u64 = std::env::var("PALPA_KILL_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(20_261_125);
    let mut rng = Rng(seed.max(1));
    let tmp = tempfile::tempdir().unwrap();
    let file = tiny(tmp.path());

    let reference_dir = tmp.path().join("reference");
    let t0 = Instant::now();
    let mut child = spawn(&file, &reference_dir, false);
    assert!(
        child.wait().unwrap().success(),
        "the reference campaign failed"
    );
    let whole = t0.elapsed().as_secs_f64();
    let reference = files(&reference_dir);
    assert!(reference.contains_key(Path::new("dataset.npz")));

    let out = tmp.path().join("killed");
    let mut moments = vec![
        Moment::At(0.3 * whole * rng.unit()),
        Moment::DuringRun,
        Moment::BetweenRuns,
        Moment::DuringRun,
        Moment::At(whole * rng.unit()),
        Moment::BetweenRuns,
        Moment::DuringAssembly,
        Moment::DuringAssembly,
    ];
    moments.push(Moment::At(whole * rng.unit()));
    let mut hit = Vec::new();
    for (k, &m) in moments.iter().enumerate() {
        let ctx = format!("seed {seed}, kill {k} ({m:?})");
        let mut child = spawn(&file, &out, out.join("campaign.json").exists());
        if kill_at(&mut child, &out, m, &mut rng) {
            hit.push(m);
        } else {
            let o = child.wait_with_output().unwrap();
            assert!(
                o.status.success(),
                "{ctx}: the resumed campaign failed: {}",
                String::from_utf8_lossy(&o.stderr)
            );
        }
        check_whole(&out, &reference, &ctx);
    }
    for phase in [
        Moment::DuringRun,
        Moment::BetweenRuns,
        Moment::DuringAssembly,
    ] {
        assert!(
            hit.contains(&phase),
            "seed {seed}: no kill landed {phase:?} (kills: {hit:?})"
        );
    }

    // resumed to the end: the same bytes as the uninterrupted campaign
    let child = spawn(&file, &out, true);
    let o = child.wait_with_output().unwrap();
    assert!(
        o.status.success(),
        "seed {seed}: the final resume failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let now = files(&out);
    let names = |m: &BTreeMap<PathBuf, Vec<u8>>| -> Vec<PathBuf> {
        m.keys().filter(|p| !is_temporary(p)).cloned().collect()
    };
    assert_eq!(names(&now), names(&reference), "seed {seed}: file lists");
    for (p, want) in &reference {
        if !is_timed(p) {
            assert!(&now[p] == want, "seed {seed}: {} differs", p.display());
        }
    }
    let stale: Vec<&PathBuf> = now.keys().filter(|p| is_temporary(p)).collect();
    assert!(stale.is_empty(), "seed {seed}: temporaries left: {stale:?}");
}
