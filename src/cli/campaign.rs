//! `palpa campaign [CAMPAIGN.toml] --out DIR`: run a palpation campaign ([`campaign`])
//! and write the surrogate's training dataset; `palpa campaign merge DIR... --out DIR` joins
//! the shards of a campaign.
//!
//! Layout of DIR:
//! - `campaign.json`: the resolved plan (settings, phantom, locations with their skin points,
//!   ROI, runs) and the shard; a resumed campaign and the shards of a merge must agree on it;
//! - `runs/<label>/`: one palpation each (`scene.toml`, `probe.csv`, `probe_stress.csv`,
//!   `history.csv`, `summary.json`), finished when `done.json` exists (written last,
//!   atomically); `--resume` skips finished runs and redoes any other run directory from
//!   scratch;
//! - `view.json`: the phantom in plan view (outlines, ROI cells, the hand;
//!   [`surrogate::ViewGeometry`]), which `palpa train` puts beside the model;
//! - `dataset.npz` + `manifest.json` (also as `dataset.json`, so that both `palpa train DIR` and
//!   `palpa train DIR/dataset.npz` find it): [`surrogate::Dataset`], written once every run of
//!   the campaign (or of the shard) is finished. X holds x, y [m], force [N], time [s] and
//!   depth [m] (indentation since first contact) per sample; the force is the hand reaction
//!   after the 1 ms centred moving average of [`solver::output::filter`] (the raw probed value
//!   chatters with the penalty contact and stays in `probe.csv`), Y the ROI maximum principal stress
//!   [Pa], S the full Cauchy tensors; rows in run order, every sample time of every run.
//!
//! Runs execute side by side, `--jobs` at a time, each on its own rayon pool of `--threads`
//! workers. On 2 cores, two runs side by side with one thread each beat one run at a time
//! with two threads (the solver is deterministic across thread counts, so the results are
//! identical either way); the default is as many jobs as cores, one thread each, and the
//! cores split between the jobs when there are fewer runs left than cores.

use super::progress::{stop_flag, time_bar};
use campaign::{
    in_shard, parse_shard, read_done, read_run, run_dir, write_done, Campaign, CampaignSpec,
    DoneMarker, PlannedRun, CAMPAIGN_FILE, CAMPAIGN_FORMAT, DONE_FILE,
};
use ndarray::{Array1, Array2, Array3};
use phantom::Phantom;
use scene::run::run_scene;
use serde_json::{json, Value};
use solver::output::atomic::write_atomic;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Instant, SystemTime, UNIX_EPOCH};
use surrogate::{Dataset, Manifest};

/// Options of `palpa campaign`.
#[derive(clap::Args, Debug)]
#[command(args_conflicts_with_subcommands = true)]
pub struct CampaignArgs {
    #[command(subcommand)]
    command: Option<CampaignCommand>,
    /// The campaign file (TOML, see scenes/campaign-paper.toml); without it the paper's
    /// protocol: P01..P25 (train) and A, B, C (test), 15 mm in 25 ms, samples every 5 ms, on
    /// the reduced phantom with the paper's 3 mm voxels (about 4 h on 2 cores;
    /// scenes/campaign-5mm.toml takes about 36 min).
    file: Option<PathBuf>,
    /// Campaign directory: runs/<label>/, campaign.json, dataset.npz + manifest.json.
    #[arg(long, default_value = "results/campaign")]
    out: PathBuf,
    /// Continue a campaign in --out: skip finished runs, redo unfinished ones.
    #[arg(long)]
    resume: bool,
    /// Run only the runs k with k mod n == i (a deterministic subset, e.g. one Slurm array
    /// task each); join the shards' directories with `palpa campaign merge`. n is the
    /// campaign's number of shards, fixed when the shard's directory is made: `--shard i`
    /// alone takes it from --out's campaign.json (a resubmitted shard), and a count that
    /// disagrees with it is refused.
    #[arg(long, value_name = "i/n")]
    shard: Option<String>,
    /// Runs side by side [default: as many as cores].
    #[arg(long)]
    jobs: Option<usize>,
    /// Worker threads per run [default: cores / jobs, at least 1].
    #[arg(long)]
    threads: Option<usize>,
    /// No progress bar and no per-run lines.
    #[arg(long)]
    quiet: bool,
    /// Build the phantom, check the locations, print the plan; run nothing.
    #[arg(long)]
    dry_run: bool,
    /// Stop after starting this many runs (for tests of --resume).
    #[arg(long, hide = true)]
    max_runs: Option<usize>,
}

/// `palpa campaign merge`.
#[derive(clap::Subcommand, Debug)]
enum CampaignCommand {
    /// Join the directories of a campaign's shards (`--shard i/n`) into one campaign
    /// directory: copy their finished runs into --out and write the whole dataset, identical
    /// to an unsharded run's.
    Merge {
        /// Shard directories.
        #[arg(required = true)]
        dirs: Vec<PathBuf>,
        /// The merged campaign directory (may be one of the shards).
        #[arg(long)]
        out: PathBuf,
        /// Print only errors.
        #[arg(long)]
        quiet: bool,
    },
}

/// Run `palpa campaign`.
pub fn campaign(a: &CampaignArgs) -> Result<(), String> {
    match &a.command {
        Some(CampaignCommand::Merge { dirs, out, quiet }) => merge(dirs, out, *quiet),
        None => run_campaign(a),
    }
}

fn now_unix() -> f64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_secs_f64())
        .unwrap_or(0.0)
}

fn read_json(path: &Path) -> Result<Value, String> {
    let s = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    serde_json::from_str(&s).map_err(|e| format!("{}: {e}", path.display()))
}

/// Where two campaign plans first differ, for the message that refuses to mix them:
/// `plan.locations[26].surface_m[0]: -0.0705 there, -0.0725 here`. `None` when equal.
fn first_difference(there: &Value, here: &Value, path: &str) -> Option<String> {
    let short = |v: &Value| {
        let s = v.to_string();
        if s.chars().count() > 60 {
            format!("{}...", s.chars().take(57).collect::<String>())
        } else {
            s
        }
    };
    match (there, here) {
        (Value::Object(a), Value::Object(b)) => {
            let mut keys: Vec<&String> = a.keys().chain(b.keys()).collect();
            keys.sort();
            keys.dedup();
            keys.into_iter().find_map(|k| {
                let (x, y) = (a.get(k), b.get(k));
                match (x, y) {
                    (Some(x), Some(y)) => first_difference(x, y, &format!("{path}.{k}")),
                    _ => Some(format!(
                        "{path}.{k}: {} there, {} here",
                        x.map_or("absent".into(), short),
                        y.map_or("absent".into(), short)
                    )),
                }
            })
        }
        (Value::Array(a), Value::Array(b)) if a.len() == b.len() => a
            .iter()
            .zip(b)
            .enumerate()
            .find_map(|(i, (x, y))| first_difference(x, y, &format!("{path}[{i}]"))),
        (Value::Array(a), Value::Array(b)) => Some(format!(
            "{path}: {} entries there, {} here",
            a.len(),
            b.len()
        )),
        _ if there != here => Some(format!(
            "{path}: {} there, {} here",
            short(there),
            short(here)
        )),
        _ => None,
    }
}

fn write_json(path: &Path, v: &Value) -> Result<(), String> {
    let s = serde_json::to_string_pretty(v).map_err(|e| e.to_string())?;
    write_atomic(path, s.as_bytes())
}

/// The campaign description file of DIR: format, solver version, shard and plan.
fn campaign_file(plan: &Value, shard: Option<(usize, usize)>) -> Value {
    json!({
        "format": CAMPAIGN_FORMAT,
        "version": 1,
        "solver_version": env!("CARGO_PKG_VERSION"),
        "shard": shard.map(|(i, n)| format!("{i}/{n}")),
        "plan": plan,
    })
}

/// The shard `DIR/campaign.json` records: `None` without that file, `Some(None)` for an
/// unsharded campaign.
fn recorded_shard(out: &Path) -> Result<Option<Option<(usize, usize)>>, String> {
    let cfile = out.join(CAMPAIGN_FILE);
    if !cfile.exists() {
        return Ok(None);
    }
    shard_in(&read_json(&cfile)?, &cfile).map(Some)
}

/// The shard of the campaign description `v` (read from `cfile`), `None` when unsharded.
fn shard_in(v: &Value, cfile: &Path) -> Result<Option<(usize, usize)>, String> {
    match &v["shard"] {
        Value::Null => Ok(None),
        Value::String(s) => parse_shard(s)
            .map(Some)
            .map_err(|_| format!("{}: `shard` is `{s}`, not i/n", cfile.display())),
        other => Err(format!(
            "{}: `shard` is {other}, not \"i/n\"",
            cfile.display()
        )),
    }
}

/// The shard of `--shard` (`i/n`, or `i` with n from `out`'s campaign.json), checked against
/// the shard `out` already holds: a shard's count is fixed when its directory is made, so a
/// resubmitted task (a Slurm array resubmitted as `--array=i` has SLURM_ARRAY_TASK_COUNT=1)
/// can neither silently split the campaign differently nor fail on `i/1`.
fn resolve_shard(arg: Option<&str>, out: &Path) -> Result<Option<(usize, usize)>, String> {
    let recorded = recorded_shard(out)?;
    let there = || out.join(CAMPAIGN_FILE).display().to_string();
    let continue_with = |(i, n): (usize, usize)| {
        format!("continue it with --shard {i}/{n} or --shard {i}, or choose a new --out")
    };
    let Some(arg) = arg else {
        return match recorded {
            Some(Some(r)) => Err(format!(
                "{} holds shard {}/{} of a campaign (see {}), not the whole campaign: {}",
                out.display(),
                r.0,
                r.1,
                there(),
                continue_with(r)
            )),
            _ => Ok(None),
        };
    };
    let shard = if let Some((i, n)) = arg.split_once('/') {
        match parse_shard(arg) {
            Ok(s) => s,
            Err(e) => {
                let hint = match recorded {
                    Some(Some(r)) => format!("; {} records shard {}/{}: {}", there(), r.0, r.1, continue_with(r)),
                    _ if matches!((i.trim().parse::<usize>(), n.trim().parse::<usize>()), (Ok(i), Ok(n)) if i >= n) => "; n is the campaign's number of shards, the same for every task, not the size of the array that runs this one (an array resubmitted as --array=i has SLURM_ARRAY_TASK_COUNT=1)".into(),
                    _ => String::new(),
                };
                return Err(format!("{e}{hint}"));
            }
        }
    } else {
        let i: usize = arg.trim().parse().map_err(|_| {
            format!("--shard: expected i/n with 0 <= i < n (or i alone to continue a shard), got `{arg}`")
        })?;
        match recorded {
            Some(Some(r)) => (i, r.1),
            Some(None) => {
                return Err(format!(
                    "--shard {i}: {} holds an unsharded campaign, with no shard count to take",
                    out.display()
                ))
            }
            None => {
                return Err(format!(
                    "--shard {i}: no shard count: {} does not exist yet to take it from; give --shard {i}/n, n the campaign's number of shards",
                    there()
                ))
            }
        }
    };
    match recorded {
        Some(Some(r)) if r != shard => Err(format!(
            "--shard {}/{}: {} holds shard {}/{} of a campaign (see {}); a shard's count is fixed when its directory is made and is the same for every task: {}",
            shard.0,
            shard.1,
            out.display(),
            r.0,
            r.1,
            there(),
            continue_with(r)
        )),
        Some(None) => Err(format!(
            "--shard {}/{}: {} holds the whole (unsharded) campaign; choose a new --out for a shard",
            shard.0,
            shard.1,
            out.display()
        )),
        _ => Ok(Some(shard)),
    }
}

/// Number of cores.
fn cores() -> usize {
    std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1)
}

fn run_campaign(a: &CampaignArgs) -> Result<(), String> {
    let t_start = Instant::now();
    let spec = match &a.file {
        Some(f) => CampaignSpec::load(f)?,
        None => CampaignSpec::default(),
    };
    // errors of the file's values name the file
    let in_file = |e: String| match &a.file {
        Some(f) => format!("{}: {e}", f.display()),
        None => e,
    };
    let campaign = spec.resolve().map_err(in_file)?;
    let shard = resolve_shard(a.shard.as_deref(), &a.out)?;
    if a.jobs == Some(0) || a.threads == Some(0) {
        return Err("--jobs and --threads must be at least 1".into());
    }

    // The phantom, once for every run.
    let t0 = Instant::now();
    let params = campaign.phantom_params().map_err(in_file)?;
    let phantom = phantom::build(&params).map_err(|e| in_file(format!("[phantom]: {e}")))?;
    let build_s = t0.elapsed().as_secs_f64();
    let locs = campaign.resolve_locations(&phantom)?;
    let plan = campaign.plan_json(&phantom, &locs);
    let mine: Vec<&PlannedRun> = campaign
        .runs
        .iter()
        .filter(|r| match shard {
            Some(s) => in_shard(r.index, s),
            None => true,
        })
        .collect();
    let out = &a.out;
    let done: Vec<bool> = mine
        .iter()
        .map(|r| read_done(&run_dir(out, &r.label)).is_some())
        .collect();
    let n_done = done.iter().filter(|&&d| d).count();

    if !a.quiet || a.dry_run {
        println!(
            "campaign `{}`: {} runs ({} locations: {} train, {} test){}; phantom {} voxel {:.1} mm: {} hexahedra, ROI {} elements, built in {:.2} s",
            campaign.title,
            campaign.runs.len(),
            campaign.locations.len(),
            campaign.locations.iter().filter(|l| l.split.code() == 0).count(),
            campaign.locations.iter().filter(|l| l.split.code() == 1).count(),
            match shard {
                Some((i, n)) => format!(", shard {i}/{n}: {} runs", mine.len()),
                None => String::new(),
            },
            campaign.base.variant,
            campaign.base.voxel * 1e3,
            phantom.mesh.elements.len(),
            phantom.roi.elements.len(),
            build_s
        );
    }
    if a.dry_run {
        print_plan(&campaign, &locs, &mine, &done);
        return Ok(());
    }

    // campaign.json: a resumed campaign must be the same campaign.
    std::fs::create_dir_all(out)
        .map_err(|e| format!("{}: cannot create the output directory: {e}", out.display()))?;
    let cfile = out.join(CAMPAIGN_FILE);
    let desc = campaign_file(&plan, shard);
    if cfile.exists() {
        let old = read_json(&cfile)?;
        if let Some(d) = first_difference(old.get("plan").unwrap_or(&Value::Null), &plan, "plan") {
            return Err(format!(
                "{} holds a different campaign ({d}; there = {}, here = this campaign file and palpa); choose a new --out",
                out.display(),
                cfile.display()
            ));
        }
        if old.get("solver_version") != desc.get("solver_version") && !a.quiet {
            println!(
                "  note: the finished runs in {} were made by palpa {}, this is {}",
                out.display(),
                old.get("solver_version").unwrap_or(&Value::Null),
                env!("CARGO_PKG_VERSION")
            );
        }
    }
    if n_done > 0 && !a.resume {
        return Err(format!(
            "{} already holds {n_done} finished run(s) of this campaign: pass --resume to continue it, or choose a new --out",
            out.display()
        ));
    }
    write_json(&cfile, &desc)?;
    let view = super::view_geometry::from_phantom(
        &phantom,
        &phantom.mesh,
        super::view_geometry::fingers(campaign.base.finger_spacing, campaign.base.finger_diameter),
        format!(
            "campaign `{}` (palpa {})",
            campaign.title,
            env!("CARGO_PKG_VERSION")
        ),
    )?;
    let vpath = out.join("view.json");
    view.write(&vpath)
        .map_err(|e| format!("{}: {e}", vpath.display()))?;

    let todo: Vec<&PlannedRun> = mine
        .iter()
        .zip(&done)
        .filter(|(_, &d)| !d)
        .map(|(r, _)| *r)
        .take(a.max_runs.unwrap_or(usize::MAX))
        .collect();
    let jobs = a.jobs.unwrap_or_else(cores).min(todo.len()).max(1);
    let threads = a.threads.unwrap_or_else(|| (cores() / jobs).max(1));
    if !a.quiet {
        println!(
            "  {} finished, {} to run: {} side by side, {} thread(s) each; output {}",
            n_done,
            todo.len(),
            jobs,
            threads,
            out.display()
        );
    }

    let report = execute(&campaign, &todo, out, &phantom, jobs, threads, a.quiet)?;
    let wall = t_start.elapsed().as_secs_f64();
    if !a.quiet {
        println!(
            "  {} run(s) finished in this invocation, {} failed{}; wall time {:.1} s (run time {:.1} s)",
            report.finished,
            report.failed.len(),
            if report.stopped { ", stopped" } else { "" },
            wall,
            report.run_seconds
        );
    }
    if !report.failed.is_empty() {
        let list: Vec<String> = report
            .failed
            .iter()
            .map(|(l, e)| format!("  {l}: {e}"))
            .collect();
        return Err(format!(
            "{} run(s) failed (rerun with --resume to retry them):\n{}",
            report.failed.len(),
            list.join("\n")
        ));
    }
    let missing: Vec<&str> = mine
        .iter()
        .filter(|r| read_done(&run_dir(out, &r.label)).is_none())
        .map(|r| r.label.as_str())
        .collect();
    if !missing.is_empty() {
        println!(
            "  {} run(s) not finished ({}); continue with --resume",
            missing.len(),
            missing.join(", ")
        );
        return if report.stopped {
            Err("stopped".into())
        } else {
            Ok(())
        };
    }
    let labels: Vec<String> = mine.iter().map(|r| r.label.clone()).collect();
    let ds = assemble(&plan, &labels, |l| run_dir(out, l))?;
    write_dataset(&ds, out)?;
    if !a.quiet {
        print_dataset(&ds, out, shard.is_some());
    }
    Ok(())
}

fn print_plan(c: &Campaign, locs: &[phantom::Location], mine: &[&PlannedRun], done: &[bool]) {
    println!(
        "  {:<20} {:<8} {:<5} {:>8} {:>8} {:>8} {:>8} {:>9} {:>7}  state",
        "run", "location", "split", "x mm", "y mm", "liver mm", "depth mm", "time ms", "samples"
    );
    for (r, d) in mine.iter().zip(done) {
        let l = &c.locations[r.location];
        let s = &locs[r.location];
        println!(
            "  {:<20} {:<8} {:<5} {:>8.1} {:>8.1} {:>8} {:>8.2} {:>9.2} {:>7}  {}",
            r.label,
            l.label,
            l.split.name(),
            s.surface[0] * 1e3,
            s.surface[1] * 1e3,
            s.liver_depth
                .map(|d| format!("{:.1}", d * 1e3))
                .unwrap_or_else(|| "-".into()),
            r.depth * 1e3,
            r.duration * 1e3,
            c.samples_per_run(r),
            if *d { "done" } else { "to run" }
        );
    }
}

/// Per job the (label, simulated time, end time) of its current run; the simulated time of the
/// finished runs (s).
type Slots = (Vec<Option<(String, f64, f64)>>, f64);

/// What [`execute`] did.
struct Report {
    finished: usize,
    failed: Vec<(String, String)>,
    stopped: bool,
    run_seconds: f64,
}

/// Run `todo`, `jobs` at a time with `threads` each, with one progress bar over the
/// simulated time of all of them.
fn execute(
    c: &Campaign,
    todo: &[&PlannedRun],
    out: &Path,
    phantom: &Phantom,
    jobs: usize,
    threads: usize,
    quiet: bool,
) -> Result<Report, String> {
    let total_time: f64 = todo.iter().map(|r| r.duration).sum();
    let pb = time_bar(total_time, quiet);
    let stop = stop_flag();
    let next = AtomicUsize::new(0);
    let finished = AtomicUsize::new(0);
    // per job: (label, simulated time, end time) of its current run; the time of finished runs
    let slots: Mutex<Slots> = Mutex::new((vec![None; jobs], 0.0));
    let failed: Mutex<Vec<(String, String)>> = Mutex::new(Vec::new());
    let run_seconds = Mutex::new(0.0f64);
    let n = todo.len();
    // a line above the bar (indicatif drops lines of a hidden bar: not a terminal)
    let say = |line: String| {
        if pb.is_hidden() {
            println!("{line}");
        } else {
            pb.println(line);
        }
    };
    let update = |slots: &Slots| {
        let pos = slots.1 + slots.0.iter().flatten().map(|s| s.1).sum::<f64>();
        pb.set_position((pos * 1e6) as u64);
        let cur: Vec<String> = slots
            .0
            .iter()
            .flatten()
            .map(|(l, t, end)| format!("{l} {:.2}/{:.2} ms", t * 1e3, end * 1e3))
            .collect();
        pb.set_message(format!(
            "{}/{} runs; {}",
            finished.load(Ordering::Relaxed),
            n,
            cur.join(", ")
        ));
    };
    let worker = |slot: usize| -> Result<(), String> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| e.to_string())?;
        loop {
            if stop.load(Ordering::SeqCst) {
                break;
            }
            let k = next.fetch_add(1, Ordering::SeqCst);
            let Some(&r) = todo.get(k) else { break };
            {
                let mut s = slots.lock().unwrap();
                s.0[slot] = Some((r.label.clone(), 0.0, r.duration));
                update(&s);
            }
            let t0 = Instant::now();
            let res = pool.install(|| {
                run_one(c, r, out, phantom, &stop, &mut |t| {
                    let mut s = slots.lock().unwrap();
                    s.0[slot] = Some((r.label.clone(), t, r.duration));
                    update(&s);
                })
            });
            *run_seconds.lock().unwrap() += t0.elapsed().as_secs_f64();
            let mut s = slots.lock().unwrap();
            s.0[slot] = None;
            match res {
                Ok(m) => {
                    s.1 += r.duration;
                    let k = finished.fetch_add(1, Ordering::SeqCst) + 1;
                    if !quiet {
                        say(format!(
                            "  done {:<16} ({k}/{n}): {} steps, {} samples, {:.1} s on {} thread(s)",
                            r.label, m.steps, m.samples, m.wall_seconds, m.threads
                        ));
                    }
                }
                Err(e) => {
                    if !stop.load(Ordering::SeqCst) {
                        say(format!("  FAILED {}: {e}", r.label));
                        failed.lock().unwrap().push((r.label.clone(), e));
                    }
                }
            }
            update(&s);
        }
        Ok(())
    };
    let results: Vec<Result<(), String>> = std::thread::scope(|sc| {
        let handles: Vec<_> = (0..jobs)
            .map(|j| {
                let w = &worker;
                sc.spawn(move || w(j))
            })
            .collect();
        handles
            .into_iter()
            .map(|h| {
                h.join()
                    .unwrap_or_else(|_| Err("a campaign worker panicked".into()))
            })
            .collect()
    });
    pb.finish_and_clear();
    for r in results {
        r?;
    }
    let mut failed = failed.into_inner().unwrap();
    failed.sort();
    Ok(Report {
        finished: finished.into_inner(),
        failed,
        stopped: stop.load(Ordering::SeqCst),
        run_seconds: run_seconds.into_inner().unwrap(),
    })
}

/// One run, from scratch, into `runs/<label>/`, marked finished by `done.json` at the end.
fn run_one(
    c: &Campaign,
    r: &PlannedRun,
    out: &Path,
    phantom: &Phantom,
    stop: &AtomicBool,
    progress: &mut dyn FnMut(f64),
) -> Result<DoneMarker, String> {
    let dir = run_dir(out, &r.label);
    if dir.exists() {
        std::fs::remove_dir_all(&dir)
            .map_err(|e| format!("{}: cannot clear the unfinished run: {e}", dir.display()))?;
    }
    let mut scene = c.build_run_scene(r, &dir, phantom)?;
    let notes = scene.notes.clone();
    let (summary, err) = run_scene(&mut scene, &dir, stop, |p| progress(p.sim.time));
    if let Some(e) = err {
        return Err(e);
    }
    if summary.status != "completed" {
        return Err(format!("run {}", summary.status));
    }
    let samples = read_run(&dir)?;
    let m = DoneMarker {
        label: r.label.clone(),
        index: r.index,
        status: summary.status,
        steps: summary.steps,
        simulated_time: summary.time,
        wall_seconds: summary.wall_seconds,
        threads: summary.threads,
        samples: samples.time.len(),
        finished_unix: now_unix(),
        solver_version: env!("CARGO_PKG_VERSION").into(),
        notes,
    };
    write_done(&dir, &m)?;
    Ok(m)
}

fn bad_plan(what: &str) -> String {
    format!("campaign.json: the plan has no valid `{what}`")
}

/// The dataset of the runs `labels` (in plan order) of campaign `plan`, reading run `l` from
/// `dir_of(l)`. Used by both `palpa campaign` and `merge`, so the two write the same bytes.
fn assemble(
    plan: &Value,
    labels: &[String],
    dir_of: impl Fn(&str) -> PathBuf,
) -> Result<Dataset, String> {
    let arr = |v: &Value, what: &str| v.as_array().cloned().ok_or_else(|| bad_plan(what));
    let f = |v: &Value, what: &str| v.as_f64().ok_or_else(|| bad_plan(what));
    let s = |v: &Value, what: &str| v.as_str().map(str::to_string).ok_or_else(|| bad_plan(what));
    let roi_ids: Vec<i64> = arr(&plan["roi"]["elements"], "roi.elements")?
        .iter()
        .map(|v| v.as_i64().ok_or_else(|| bad_plan("roi.elements")))
        .collect::<Result<_, _>>()?;
    let cents = arr(&plan["roi"]["centroids_m"], "roi.centroids_m")?;
    let r = roi_ids.len();
    let mut roi_centroids = Array2::zeros((r, 3));
    for (i, c) in cents.iter().enumerate().take(r) {
        for j in 0..3 {
            roi_centroids[(i, j)] = f(&c[j], "roi.centroids_m")?;
        }
    }
    // locations: label, split, x, y
    let mut locs = Vec::new();
    for l in arr(&plan["locations"], "locations")? {
        locs.push((
            s(&l["label"], "locations.label")?,
            if s(&l["split"], "locations.split")? == "test" {
                1u8
            } else {
                0
            },
            f(&l["surface_m"][0], "locations.surface_m")?,
            f(&l["surface_m"][1], "locations.surface_m")?,
        ));
    }
    let runs = arr(&plan["runs"], "runs")?;
    let mut xs: Vec<[f64; 5]> = Vec::new();
    let mut ys: Vec<f64> = Vec::new();
    let mut ss: Vec<f64> = Vec::new();
    let mut location = Vec::new();
    let mut split = Vec::new();
    let mut run_rows = Vec::new();
    for label in labels {
        let run = runs
            .iter()
            .find(|v| v["label"].as_str() == Some(label))
            .ok_or_else(|| format!("campaign.json: no run `{label}`"))?;
        let loc_label = s(&run["location"], "runs.location")?;
        let li = locs
            .iter()
            .position(|l| l.0 == loc_label)
            .ok_or_else(|| bad_plan("runs.location"))?;
        let (_, sp, x, y) = locs[li];
        let dir = dir_of(label);
        let d = read_run(&dir)?;
        // the probe's columns in the ROI's order (nearest to the ROI centre first)
        let cols: Vec<usize> = roi_ids
            .iter()
            .map(|&id| d.elements.iter().position(|&e| e as i64 == id))
            .collect::<Option<_>>()
            .filter(|_| d.elements.len() == r)
            .ok_or_else(|| {
                format!(
                    "{}: the probe's elements are not the campaign's ROI",
                    dir.display()
                )
            })?;
        let start = xs.len();
        for k in 0..d.time.len() {
            xs.push([x, y, d.force_filtered[k], d.time[k], d.depth[k]]);
            ys.extend(cols.iter().map(|&c| d.max_principal[k][c]));
            for &c in &cols {
                ss.extend(&d.tensors[k][c]);
            }
            location.push(li as i64);
            split.push(sp);
        }
        run_rows.push(json!({
            "label": label,
            "location": loc_label,
            "split": if sp == 1 { "test" } else { "train" },
            "depth_m": run["depth_m"],
            "duration_s": run["duration_s"],
            "rows": [start, xs.len()],
        }));
    }
    let n = xs.len();
    let mut manifest = Manifest {
        x_columns: ["x", "y", "force", "time", "depth"]
            .map(String::from)
            .to_vec(),
        location_labels: locs.iter().map(|l| l.0.clone()).collect(),
        solver: json!({
            "name": "palpa",
            "version": env!("CARGO_PKG_VERSION"),
            "campaign": plan["title"],
            "settings": plan["settings"],
            "force": "hand reaction along the pressing direction (hand_reaction), centred moving average of history.csv at the sample time (contact chatter removed)",
            "force_filter_s": solver::output::filter::FORCE_FILTER,
            "depth": "indentation since first contact (hand_depth)",
            "x_y": "skin point of the location where the two-finger hand presses",
            "runs": run_rows,
        }),
        phantom: json!({
            "parameters": plan["phantom"],
            "roi_center_m": plan["roi"]["center_m"],
        }),
        ..Manifest::default()
    };
    manifest
        .units
        .insert("location".into(), "index into location_labels".into());
    manifest
        .units
        .insert("split".into(), "0 train, 1 test".into());
    let ds = Dataset {
        x: Array2::from_shape_vec((n, 5), xs.concat()).map_err(|e| e.to_string())?,
        y: Array2::from_shape_vec((n, r), ys).map_err(|e| e.to_string())?,
        stress: Some(Array3::from_shape_vec((n, r, 6), ss).map_err(|e| e.to_string())?),
        roi_ids: Array1::from(roi_ids),
        roi_centroids,
        location: Array1::from(location),
        split: Array1::from(split),
        manifest,
    };
    Ok(ds)
}

/// Write `dataset.npz` + `manifest.json`, and the manifest again as `dataset.json`.
fn write_dataset(ds: &Dataset, out: &Path) -> Result<(), String> {
    ds.write(out).map_err(|e| e.to_string())?;
    let m = std::fs::read(out.join("manifest.json")).map_err(|e| e.to_string())?;
    write_atomic(&out.join("dataset.json"), &m)
}

fn print_dataset(ds: &Dataset, out: &Path, partial: bool) {
    let train = ds.rows_with_split(0).len();
    let (lo, hi) =
        ds.y.iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |a, &v| {
                (a.0.min(v), a.1.max(v))
            });
    let fmax =
        ds.x.column(2)
            .iter()
            .fold(f64::NEG_INFINITY, |a, &v| a.max(v));
    println!(
        "  dataset{}: {} samples ({} train, {} test) x {} ROI elements; force up to {:.2} N, stress {:.3} .. {:.3} kPa -> {}",
        if partial { " of this shard" } else { "" },
        ds.n_samples(),
        train,
        ds.n_samples() - train,
        ds.n_roi(),
        fmax,
        lo / 1e3,
        hi / 1e3,
        out.join("dataset.npz").display()
    );
}

/// Copy the finished run in `src` to `dst` (a fresh directory), `done.json` last.
fn copy_run(src: &Path, dst: &Path) -> Result<(), String> {
    if dst.exists() {
        std::fs::remove_dir_all(dst).map_err(|e| format!("{}: {e}", dst.display()))?;
    }
    std::fs::create_dir_all(dst).map_err(|e| format!("{}: {e}", dst.display()))?;
    let entries = std::fs::read_dir(src).map_err(|e| format!("{}: {e}", src.display()))?;
    for e in entries {
        let e = e.map_err(|e| format!("{}: {e}", src.display()))?;
        let name = e.file_name();
        if name == DONE_FILE || !e.file_type().map(|t| t.is_file()).unwrap_or(false) {
            continue;
        }
        std::fs::copy(e.path(), dst.join(&name))
            .map_err(|err| format!("{}: cannot copy: {err}", e.path().display()))?;
    }
    let done = std::fs::read(src.join(DONE_FILE)).map_err(|e| format!("{}: {e}", src.display()))?;
    write_atomic(&dst.join(DONE_FILE), &done)
}

/// `palpa campaign merge DIRS --out OUT`.
fn merge(dirs: &[PathBuf], out: &Path, quiet: bool) -> Result<(), String> {
    let mut plan: Option<Value> = None;
    // the shard counts the directories record (an unsharded one counts as 1)
    let mut counts: Vec<usize> = Vec::new();
    for d in dirs {
        let v = read_json(&d.join(CAMPAIGN_FILE))?;
        if v["format"] != CAMPAIGN_FORMAT {
            return Err(format!(
                "{}: not a palpa campaign",
                d.join(CAMPAIGN_FILE).display()
            ));
        }
        counts.push(shard_in(&v, &d.join(CAMPAIGN_FILE))?.map_or(1, |(_, n)| n));
        match &plan {
            None => plan = Some(v["plan"].clone()),
            Some(p) if *p != v["plan"] => {
                let diff = first_difference(p, &v["plan"], "plan").unwrap_or_default();
                return Err(format!(
                    "{} is a different campaign from {} ({diff}; there = {}, here = {})",
                    d.display(),
                    dirs[0].display(),
                    dirs[0].display(),
                    d.display()
                ));
            }
            _ => {}
        }
    }
    let plan = plan.ok_or("merge: no directories")?;
    let labels: Vec<String> = plan["runs"]
        .as_array()
        .ok_or_else(|| bad_plan("runs"))?
        .iter()
        .map(|r| {
            r["label"]
                .as_str()
                .map(String::from)
                .ok_or_else(|| bad_plan("runs.label"))
        })
        .collect::<Result<_, _>>()?;
    refuse_stale_out(out, &plan, dirs)?;
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let same = |a: &Path, b: &Path| match (a.canonicalize(), b.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => false,
    };
    let mut missing = Vec::new();
    let mut copied = 0;
    for (k, l) in labels.iter().enumerate() {
        let dst = run_dir(out, l);
        if read_done(&dst).is_some() {
            continue;
        }
        match dirs.iter().find(|d| read_done(&run_dir(d, l)).is_some()) {
            Some(d) if !same(d, out) => {
                copy_run(&run_dir(d, l), &dst)?;
                copied += 1;
            }
            _ => missing.push((k, l.as_str())),
        }
    }
    if !missing.is_empty() {
        counts.sort_unstable();
        counts.dedup();
        // the shards the missing runs belong to, when the directories agree on the count
        let which = match counts[..] {
            [n] if n > 1 => {
                let mut shards: Vec<usize> = missing.iter().map(|(k, _)| k % n).collect();
                shards.sort_unstable();
                shards.dedup();
                let shards: Vec<String> = shards.iter().map(|i| format!("{i}/{n}")).collect();
                format!(
                    "the runs of shard{} {}: not given, or not finished (resubmit {} and merge again)",
                    if shards.len() > 1 { "s" } else { "" },
                    shards.join(", "),
                    if shards.len() > 1 { "them" } else { "it" }
                )
            }
            _ => "a shard not given or not finished?".into(),
        };
        let labels: Vec<&str> = missing.iter().map(|(_, l)| *l).collect();
        return Err(format!(
            "merge: {} run(s) are finished in none of the directories: {} ({which})",
            missing.len(),
            labels.join(", ")
        ));
    }
    write_json(&out.join(CAMPAIGN_FILE), &campaign_file(&plan, None))?;
    // the plan view of the campaign's phantom, from a shard that has it
    let view = out.join("view.json");
    if !view.is_file() {
        if let Some(src) = dirs
            .iter()
            .map(|d| d.join("view.json"))
            .find(|v| v.is_file())
        {
            let bytes = std::fs::read(&src).map_err(|e| format!("{}: {e}", src.display()))?;
            write_atomic(&view, &bytes)?;
        }
    }
    let ds = assemble(&plan, &labels, |l| run_dir(out, l))?;
    write_dataset(&ds, out)?;
    if !quiet {
        println!(
            "merged {} director{} into {}: {} runs ({} copied)",
            dirs.len(),
            if dirs.len() == 1 { "y" } else { "ies" },
            out.display(),
            labels.len(),
            copied
        );
        print_dataset(&ds, out, false);
    }
    Ok(())
}

/// A merge keeps the finished runs it finds in `out`, so `out` must hold this campaign or
/// nothing: finished runs of another campaign (or of unknown origin) would enter the dataset.
fn refuse_stale_out(out: &Path, plan: &Value, dirs: &[PathBuf]) -> Result<(), String> {
    let file = out.join(CAMPAIGN_FILE);
    if file.is_file() {
        let v = read_json(&file)?;
        if v["plan"] != *plan {
            let diff = first_difference(&v["plan"], plan, "plan").unwrap_or_default();
            return Err(format!(
                "merge: {} holds another campaign ({diff}; there = {}, here = {}); merge into an empty directory or one of this campaign's",
                out.display(),
                out.display(),
                dirs[0].display()
            ));
        }
    } else if std::fs::read_dir(run_dir(out, "")).is_ok_and(|mut d| d.next().is_some()) {
        return Err(format!(
            "merge: {} holds runs but no {CAMPAIGN_FILE}, so nothing says which campaign they belong to; merge into an empty directory",
            out.display()
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::first_difference;
    use serde_json::json;

    #[test]
    fn first_difference_names_the_path_and_both_values() {
        let there =
            json!({"runs": [1, 2], "locations": [{"label": "A", "surface_m": [-0.0705, 0.1785]}]});
        let mut here = there.clone();
        assert_eq!(first_difference(&there, &here, "plan"), None);
        here["locations"][0]["surface_m"][0] = json!(-0.0725);
        assert_eq!(
            first_difference(&there, &here, "plan").as_deref(),
            Some("plan.locations[0].surface_m[0]: -0.0705 there, -0.0725 here")
        );
        here["runs"] = json!([1, 2, 3]);
        here["title"] = json!("new");
        // keys in sorted order: locations, runs, title
        assert_eq!(
            first_difference(&there, &here, "plan").as_deref(),
            Some("plan.locations[0].surface_m[0]: -0.0705 there, -0.0725 here")
        );
        here["locations"] = there["locations"].clone();
        assert_eq!(
            first_difference(&there, &here, "plan").as_deref(),
            Some("plan.runs: 2 entries there, 3 here")
        );
        here["runs"] = json!([1, 2]);
        assert_eq!(
            first_difference(&there, &here, "plan").as_deref(),
            Some("plan.title: absent there, \"new\" here")
        );
    }
}
