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
//!   scratch. Runs copied into a directory without `campaign.json`, and with `--adaptive` a new
//!   batch's runs already finished there, are reused when their `scene.toml` is the palpation
//!   the plan gives them ([`Campaign::unlike_plan`]: copied from a campaign that plans the
//!   same runs or chose the same batches), and removed and solved again otherwise;
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
    resolve_shard, AdaptiveRecord, Campaign, CampaignSpec, Outcome, Parallelism, PlannedRun,
    Report, RunEvent, Split,
};
use phantom::Phantom;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;
use surrogate::Dataset;

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
    /// After the campaign's own runs, add N training runs in batches where the current GP is
    /// least sure (its variance averaged over forces), retraining between batches; the
    /// batches are recorded in adaptive.json and the plan (docs/campaigns.md, adaptive
    /// sampling). Resume a stopped one with the same flags and --resume.
    #[arg(long, value_name = "N")]
    adaptive: Option<usize>,
    /// Runs per adaptive batch.
    #[arg(long, value_name = "B", default_value_t = 10, requires = "adaptive")]
    batch: usize,
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
    let mut campaign = spec.resolve().map_err(in_file)?;
    let shard = resolve_shard(a.shard.as_deref(), &a.out)?;
    if a.jobs == Some(0) || a.threads == Some(0) {
        return Err("--jobs and --threads must be at least 1".into());
    }
    let record = AdaptiveRecord::read(&a.out)?;
    let candidates = adaptive_setup(a, &spec, &campaign, &record, shard, &in_file)?;
    campaign::extend(&mut campaign, &record.batches)
        .map_err(|e| format!("{}: {e}", a.out.display()))?;

    // The phantom, once for every run.
    let t0 = Instant::now();
    let params = campaign.phantom_params().map_err(in_file)?;
    let phantom = phantom::build(&params).map_err(|e| in_file(format!("[phantom]: {e}")))?;
    let build_s = t0.elapsed().as_secs_f64();
    let locs = campaign.resolve_locations(&phantom)?;
    let plan = campaign.plan(&phantom, &locs);
    let mine = campaign.runs_of(shard);
    let out = &a.out;
    let finished: Vec<bool> = mine
        .iter()
        .map(|r| campaign::is_finished(out, &r.label))
        .collect();
    let unlike = copied_runs_unlike_plan(&campaign, out, &mine, &finished);
    let done: Vec<bool> = mine
        .iter()
        .zip(&finished)
        .map(|(r, &f)| f && !unlike.iter().any(|u| u.0 == r.label))
        .collect();
    let n_done = done.iter().filter(|&&d| d).count();

    if !a.quiet || a.dry_run {
        print_header(&campaign, &phantom, shard, mine.len(), build_s);
    }
    print_stray(out, &campaign, a.adaptive.is_some());
    if a.dry_run {
        print_plan(&campaign, &locs, &mine, &done);
        return Ok(());
    }

    // an adaptive campaign stopped between writing a batch to adaptive.json and to
    // campaign.json: the plan there lacks the last batch
    if let (Some(_), Some(last)) = (a.adaptive, record.batches.last()) {
        let mut before = campaign.clone();
        let keep = before.runs.len() - last.points.len();
        before.runs.truncate(keep);
        before
            .locations
            .truncate(before.locations.len() - last.points.len());
        let there = campaign::read_campaign_dir(out).ok();
        let before_plan = before.plan(&phantom, &locs[..before.locations.len()]);
        let before_plan = before_plan.to_value();
        if there.is_some_and(|d| {
            campaign::first_difference(&d.plan_value, &before_plan, "plan").is_none()
        }) {
            campaign::write_campaign_file(out, &plan, None)?;
        }
    }
    // copied runs that are not this plan's palpations go before campaign.json claims the
    // directory's runs and before anything reads them (without --resume, prepare_dir refuses
    // a directory with finished runs, and nothing is removed)
    if a.resume {
        for (label, why) in &unlike {
            discard_unlike(out, label, "this campaign", why)?;
        }
    }
    // campaign.json: a resumed campaign must be the same campaign.
    let n_finished = finished.iter().filter(|&&f| f).count();
    campaign::prepare_dir(out, &plan, shard, n_finished, a.resume, &mut |v| {
        if !a.quiet {
            println!(
                "  note: the finished runs in {} were made by palpa {v}, this is {}",
                out.display(),
                env!("CARGO_PKG_VERSION")
            );
        }
    })?;
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

    let todo: Vec<PlannedRun> = mine
        .iter()
        .zip(&done)
        .filter(|(_, &d)| !d)
        .map(|(r, _)| (*r).clone())
        .collect();
    let mut state = Invocation {
        plan,
        record,
        candidates,
        n_done,
        budget: a.max_runs.unwrap_or(usize::MAX),
    };
    run_and_grow(a, &mut campaign, &phantom, &mut state, todo, shard, t_start)
}

/// With `--adaptive`: checks that the campaign can grow and builds the batches' candidate
/// locations. Without it: refuses a directory that holds adaptive batches.
fn adaptive_setup(
    a: &CampaignArgs,
    spec: &CampaignSpec,
    campaign: &Campaign,
    record: &AdaptiveRecord,
    shard: Option<(usize, usize)>,
    in_file: &dyn Fn(String) -> String,
) -> Result<Option<Vec<[f64; 2]>>, String> {
    match a.adaptive {
        Some(n) => {
            if shard.is_some() {
                return Err(
                    "--adaptive chooses each batch from all the runs before it: it does not shard"
                        .into(),
                );
            }
            if a.batch == 0 {
                return Err("--batch must be at least 1".into());
            }
            campaign::check_adaptive(campaign, n).map_err(in_file)?;
            Ok(Some(adaptive_candidates(spec).map_err(in_file)?))
        }
        None if !record.batches.is_empty() => Err(format!(
                "{} holds an adaptive campaign ({} batches in {}): continue it with --adaptive N --resume",
                a.out.display(),
                record.batches.len(),
            a.out.join(campaign::ADAPTIVE_FILE).display()
        )),
        None => Ok(None),
    }
}

/// What changes as an adaptive campaign grows.
struct Invocation {
    plan: campaign::CampaignPlan,
    record: AdaptiveRecord,
    /// Candidate locations of adaptive batches (`None` without `--adaptive`).
    candidates: Option<Vec<[f64; 2]>>,
    n_done: usize,
    /// Runs this invocation may still start (`--max-runs`).
    budget: usize,
}

/// Candidate locations of adaptive batches: Sobol points in the region of the campaign's first
/// training design, or the ROI's plan extent.
fn adaptive_candidates(spec: &CampaignSpec) -> Result<Vec<[f64; 2]>, String> {
    let region = match spec
        .locations
        .design
        .iter()
        .find(|d| d.split == Split::Train)
    {
        Some(d) => d.region()?,
        None => campaign::Region::Rect(campaign::default_extent()),
    };
    region.sobol(campaign::CANDIDATES, campaign::CANDIDATE_SEED)
}

/// Run `todo`, write the dataset when every run is finished, and with `--adaptive` choose the
/// next batch, record it, and go on until the adaptive runs are in.
fn run_and_grow(
    a: &CampaignArgs,
    campaign: &mut Campaign,
    phantom: &Phantom,
    st: &mut Invocation,
    mut todo: Vec<PlannedRun>,
    shard: Option<(usize, usize)>,
    t_start: Instant,
) -> Result<(), String> {
    let out = &a.out;
    loop {
        let ran = run_todo(a, campaign, phantom, st, &todo, shard, t_start)?;
        let Some(ds) = ran else {
            return Ok(());
        };
        let (Some(n_adaptive), Some(candidates)) = (a.adaptive, &st.candidates) else {
            return Ok(());
        };
        let have = st.record.n_points();
        if have >= n_adaptive {
            return Ok(());
        }
        let size = a.batch.min(n_adaptive - have);
        let number = st.record.batches.len() + 1;
        let t0 = Instant::now();
        let over_skin = |x: f64, y: f64| {
            phantom::location_at(
                &phantom.mesh,
                &phantom.skin_faces,
                &phantom.volume,
                "c",
                x,
                y,
            )
            .is_ok()
        };
        let batch = campaign::next_batch(&ds, candidates, number, size, &over_skin)?;
        if !a.quiet {
            println!(
                "  adaptive batch {number}: {size} location(s) chosen in {:.1} s by the GP on {} training locations (held-out Fit {}, 95 % coverage {}); largest force-averaged variance {:.3e} Pa^2",
                t0.elapsed().as_secs_f64(),
                batch.trained_on_locations,
                batch.test_fit.map_or("-".into(), |f| format!("{f:.4}")),
                batch.test_coverage_95.map_or("-".into(), |c| format!("{:.1} %", 100.0 * c)),
                batch.max_variance
            );
            for p in &batch.points {
                println!(
                    "    {} at x = {:.1} mm, y = {:.1} mm (variance {:.3e} Pa^2)",
                    p.label,
                    p.at[0] * 1e3,
                    p.at[1] * 1e3,
                    p.variance
                );
            }
        }
        st.record.batches.push(batch.clone());
        st.record.write(out)?;
        let first_new = campaign.runs.len();
        campaign::extend(campaign, std::slice::from_ref(&batch))?;
        let locs = campaign.resolve_locations(phantom)?;
        st.plan = campaign.plan(phantom, &locs);
        campaign::write_campaign_file(out, &st.plan, None)?;
        // a batch's runs already finished in --out (copied from a campaign that chose the
        // same batch) are reused when their scene is the palpation the batch plans; any other
        // is solved again
        todo = Vec::new();
        for r in &campaign.runs[first_new..] {
            if !campaign::is_finished(out, &r.label) {
                todo.push(r.clone());
            } else if let Some(why) = campaign.unlike_plan(out, r) {
                discard_unlike(out, &r.label, &format!("adaptive batch {number}"), &why)?;
                todo.push(r.clone());
            } else {
                st.n_done += 1;
            }
        }
    }
}

/// The finished runs of `mine` (flagged in `finished`) copied into `out` before it held a
/// `campaign.json` that are not the palpation the plan gives them, with the reason
/// ([`Campaign::unlike_plan`]); none in a directory this campaign made (its `campaign.json`
/// already says its runs are its own).
fn copied_runs_unlike_plan(
    campaign: &Campaign,
    out: &Path,
    mine: &[&PlannedRun],
    finished: &[bool],
) -> Vec<(String, String)> {
    if out.join(campaign::CAMPAIGN_FILE).exists() {
        return Vec::new();
    }
    mine.iter()
        .zip(finished)
        .filter(|(_, &f)| f)
        .filter_map(|(r, _)| Some((r.label.clone(), campaign.unlike_plan(out, r)?)))
        .collect()
}

/// Remove the finished run `label` from `out` and say why on stderr: its `scene.toml` is not
/// the palpation `planner` plans for it (`why`), so it is solved again.
fn discard_unlike(out: &Path, label: &str, planner: &str, why: &str) -> Result<(), String> {
    eprintln!(
        "note: {} is not the palpation {planner} plans for {label} ({why}): it is removed and solved again",
        campaign::run_dir(out, label).join("scene.toml").display(),
    );
    campaign::discard_run(out, label)
}

/// Run `todo` (a share of the campaign's runs) and write the dataset when every run of the
/// campaign or shard is finished; `None` when some are not.
fn run_todo(
    a: &CampaignArgs,
    campaign: &Campaign,
    phantom: &Phantom,
    st: &mut Invocation,
    todo: &[PlannedRun],
    shard: Option<(usize, usize)>,
    t_start: Instant,
) -> Result<Option<Dataset>, String> {
    let out = &a.out;
    let todo: Vec<&PlannedRun> = todo.iter().take(st.budget).collect();
    st.budget -= todo.len();
    let mine = campaign.runs_of(shard);
    let n_done = st.n_done;
    let Parallelism { jobs, threads } = Parallelism::choose(a.jobs, a.threads, todo.len(), cores());
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

    let report = execute_with_progress(campaign, &todo, out, phantom, jobs, threads, a.quiet)?;
    st.n_done += report.finished;
    if !a.quiet {
        println!(
            "  {} run(s) finished in this invocation, {} failed{}; wall time {:.1} s (run time {:.1} s)",
            report.finished,
            report.failed.len(),
            if report.stopped { ", stopped" } else { "" },
            t_start.elapsed().as_secs_f64(),
            report.run_seconds
        );
    }
    match campaign::finish(&a.out, &report, &st.plan, &mine)? {
        Outcome::Unfinished(missing) => {
            println!(
                "  {} run(s) not finished ({}); continue with --resume",
                missing.len(),
                missing.join(", ")
            );
            if report.stopped {
                return Err("stopped".into());
            }
            Ok(None)
        }
        Outcome::Dataset(ds) => {
            if !a.quiet {
                print_dataset(&ds, &a.out, shard.is_some());
            }
            Ok(Some(ds))
        }
    }
}

/// Name on stderr, `--quiet` or not, the finished runs in `out` that the plan does not name and
/// so does not reuse (e.g. runs of a 75-point design copied to extend it to 200 points: S01..
/// there, S001.. here). The whole campaign's labels, not the shard's: a shard's directory may
/// hold the other shards' runs. With `--adaptive`, runs labelled as batches are left out: a
/// batch chosen later may name them and reuse them.
fn print_stray(out: &Path, campaign: &campaign::Campaign, adaptive: bool) {
    let mut stray = campaign::stray_runs(out, campaign.runs.iter().map(|r| r.label.as_str()));
    // with --adaptive, a later batch may name them (copied runs of the same batches)
    stray.retain(|l| !(adaptive && campaign::is_batch_label(l)));
    if stray.is_empty() {
        return;
    }
    let mut names = stray.iter().take(3).cloned().collect::<Vec<_>>().join(", ");
    if stray.len() > 3 {
        names.push_str(", ...");
    }
    eprintln!(
        "note: {} holds {} finished run(s) this campaign does not name ({names}): they are not reused; a design's labels have as many digits as its n, so to reuse runs of a smaller design rename them to this plan's labels (docs/campaigns.md, \"Designs and adaptive sampling\")",
        campaign::runs_dir(out).display(),
        stray.len()
    );
}

/// The campaign's first line: runs, locations, shard, phantom and its build time.
fn print_header(
    campaign: &Campaign,
    phantom: &Phantom,
    shard: Option<(usize, usize)>,
    n_mine: usize,
    build_s: f64,
) {
    println!(
        "campaign `{}`: {} runs ({} locations: {} train, {} test){}; phantom {} voxel {:.1} mm: {} hexahedra, ROI {} elements, built in {:.2} s",
        campaign.title,
        campaign.runs.len(),
        campaign.locations.len(),
        campaign.locations.iter().filter(|l| l.split == Split::Train).count(),
        campaign.locations.iter().filter(|l| l.split == Split::Test).count(),
        match shard {
            Some((i, n)) => format!(", shard {i}/{n}: {n_mine} runs"),
            None => String::new(),
        },
        campaign.base.variant,
        campaign.base.voxel * 1e3,
        phantom.mesh.elements.len(),
        phantom.roi.elements.len(),
        build_s
    );
}

fn print_plan(c: &Campaign, locs: &[phantom::Location], mine: &[&PlannedRun], done: &[bool]) {
    // a respiratory campaign's phases; the liver depth is the reference phase's
    let phase = |l: &campaign::CampaignLocation| match (c.is_respiratory(), l.phase) {
        (false, _) => String::new(),
        (true, p) => format!(" {:>5.3}", p.unwrap_or(c.base.respiratory_phase)),
    };
    let head = if c.is_respiratory() { " phase" } else { "" };
    println!(
        "  {:<20} {:<8} {:<5} {:>8} {:>8} {:>8} {:>8} {:>9} {:>7}{head}  state",
        "run", "location", "split", "x mm", "y mm", "liver mm", "depth mm", "time ms", "samples"
    );
    for (r, d) in mine.iter().zip(done) {
        let l = &c.locations[r.location];
        let s = &locs[r.location];
        println!(
            "  {:<20} {:<8} {:<5} {:>8.1} {:>8.1} {:>8} {:>8.2} {:>9.2} {:>7}{}  {}",
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
            phase(l),
            if *d { "done" } else { "to run" }
        );
    }
}

/// Per job the (label, simulated time, end time) of its current run; the simulated time of the
/// finished runs (s).
type Slots = (Vec<Option<(String, f64, f64)>>, f64);

/// Run `todo` ([`campaign::execute`]) with one progress bar over the simulated time of all of
/// them, and a line per finished or failed run.
fn execute_with_progress(
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
    let n = todo.len();
    let finished = AtomicUsize::new(0);
    let slots: Mutex<Slots> = Mutex::new((vec![None; jobs], 0.0));
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
    let on = |e: RunEvent| {
        let mut s = slots.lock().unwrap();
        match e {
            RunEvent::Started { slot, run } => {
                s.0[slot] = Some((run.label.clone(), 0.0, run.duration))
            }
            RunEvent::Progress { slot, run, time } => {
                s.0[slot] = Some((run.label.clone(), time, run.duration))
            }
            RunEvent::Finished {
                slot,
                run,
                marker: m,
            } => {
                s.0[slot] = None;
                s.1 += run.duration;
                // counted under the lock, so the lines come out in order
                let count = finished.fetch_add(1, Ordering::Relaxed) + 1;
                if !quiet {
                    say(format!(
                        "  done {:<16} ({count}/{n}): {} steps, {} samples, {:.1} s on {} thread(s)",
                        run.label, m.steps, m.samples, m.wall_seconds, m.threads
                    ));
                }
            }
            RunEvent::Stopped { slot, .. } => s.0[slot] = None,
            RunEvent::Failed { slot, run, error } => {
                s.0[slot] = None;
                say(format!("  FAILED {}: {error}", run.label));
            }
        }
        update(&s);
    };
    let report = campaign::execute(c, todo, out, phantom, jobs, threads, &stop, &on);
    pb.finish_and_clear();
    report
}

fn print_dataset(ds: &Dataset, out: &Path, partial: bool) {
    let train = ds.rows_with_split(Split::Train).len();
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

/// `palpa campaign merge DIRS --out OUT`.
fn merge(dirs: &[PathBuf], out: &Path, quiet: bool) -> Result<(), String> {
    let r = campaign::merge(dirs, out)?;
    if !quiet {
        println!(
            "merged {} director{} into {}: {} runs ({} copied)",
            dirs.len(),
            if dirs.len() == 1 { "y" } else { "ies" },
            out.display(),
            r.runs,
            r.copied
        );
        print_dataset(&r.dataset, out, false);
    }
    Ok(())
}
