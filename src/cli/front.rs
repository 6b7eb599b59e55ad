//! `palpa front NAME=DIR[:N,..]... --runs 10,25,50,100 --out DIR`: the accuracy-per-run front of
//! surrogate designs. For each campaign directory (a design: the paper's raster, a Sobol
//! design, an adaptive one) and each run count n, the default GP (`palpa train --model gp`)
//! trains on the campaign's first n training locations (the campaign's order: the first n
//! points of a Sobol design, the initial design then the adaptive batches in the order they
//! were chosen) and is scored on every held-out location of that campaign. n counts
//! locations: in a campaign with several depths or durations every run of a location counts in
//! the cost.
//!
//! Reported per row: held-out Fit (paper eq. 5) pooled over all test locations, over A, B and
//! C, and over the other test locations (the seeded random ones); the Fit at the paper's time
//! stamps; the GP's 95 % interval coverage; the training runs' solver cost (their run wall
//! time times their threads, from each run's `done.json`, in core-hours) and the training
//! time. A campaign still running (no `dataset.npz` yet) is read from its finished runs
//! ([`campaign::assemble_finished`]). `--recover H` trains and scores on the recovered stress target
//! ([`surrogate::recovery`]) instead of the element stress. `--with FRONT.csv` adds an earlier
//! front's rows ([`super::front_row`]) to the table and the plot; each row records its settings
//! (target, training samples, likelihood rows, phase input), and rows of other settings are
//! refused. Written
//! as `front.csv`, `front.md` and `front.png` (Fit against runs, one line per design), each
//! atomically.

use super::front_row::{Row, CSV_HEADER};
use super::train::check_dataset_path;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use surrogate::{Dataset, ModelKind, Split, TrainOptions};

/// `palpa front`'s arguments.
#[derive(clap::Args)]
pub struct FrontArgs {
    /// Designs as NAME=DIR: campaign directories holding dataset.npz and runs/ (one still
    /// running, without dataset.npz, is read from its finished runs: its training locations
    /// up to the first unfinished one; its held-out runs, which a campaign runs last, must be
    /// finished); NAME=DIR:N,N gives that design
    /// its own run counts (e.g. grid=DIR:25, the paper's whole raster).
    #[arg(required = true, value_name = "NAME=DIR[:N,...]")]
    pub designs: Vec<String>,
    /// Training run counts (each at most a design's training locations; larger ones are
    /// skipped for that design).
    #[arg(long, value_delimiter = ',', default_value = "25,50,100")]
    pub runs: Vec<usize>,
    #[command(flatten)]
    pub target: super::selection::SampleTargetArgs,
    /// An earlier front's `front.csv` whose rows join the table and the plot, before the new
    /// designs' (a front measured in another sitting, drawn beside new designs without
    /// re-running its campaigns, or a design's front extended to more runs); repeatable. A
    /// point (design and run count) may not be given twice.
    #[arg(long, value_name = "FRONT.csv")]
    pub with: Vec<PathBuf>,
    /// Where to write front.csv, front.md and front.png.
    #[arg(long)]
    pub out: PathBuf,
}

/// Run `palpa front`.
pub fn run(a: &FrontArgs) -> Result<(), String> {
    let (interval, recovery_width) = (a.target.interval()?, a.target.recovery_width()?);
    let mut options = TrainOptions::default();
    a.target.set_likelihood_rows(&mut options.gp)?;
    if a.runs.contains(&0) {
        return Err("--runs: counts must be at least 1".into());
    }
    let settings = a.target.settings(&options.gp)?;
    let mut rows = Row::read_fronts(&a.with, &settings)?;
    let earlier = rows.len();
    // every design read before any is trained, so that a bad one stops the front at once
    let mut designs: Vec<(String, PathBuf, Vec<usize>, Dataset, bool)> = Vec::new();
    for d in &a.designs {
        let (name, dir, runs) = parse_design(d, &a.runs)?;
        if designs.iter().any(|x| x.0 == name) {
            return Err(format!("design `{name}` is named twice"));
        }
        if let Some(r) = rows
            .iter()
            .find(|r| r.design == name && runs.contains(&r.runs))
        {
            return Err(format!(
                "design `{name}` at {} runs is already a point of a --with front: leave that count out or give the design another name",
                r.runs
            ));
        }
        let (data, partial) = read_design(&name, &dir)?;
        designs.push((name, dir, runs, data, partial));
    }
    std::fs::create_dir_all(&a.out)
        .map_err(|e| format!("{}: cannot create: {e}", a.out.display()))?;
    println!(
        "  GP hyperparameters by the marginal likelihood of at most {} training rows; settings: {settings}",
        options.gp.max_likelihood_rows
    );
    for (name, dir, runs, data, partial) in &designs {
        let order = data.training_location_order();
        for &n in runs {
            if n > order.len() {
                let why = if *partial {
                    format!(
                        "only the first {} training locations are finished",
                        order.len()
                    )
                } else {
                    format!("the campaign has {} training locations", order.len())
                };
                eprintln!("  {name}: {n} runs skipped ({why})");
                continue;
            }
            let selection = surrogate::TrainingSelection {
                first_locations: Some(n),
                interval,
                recovery_width,
                ignore_phase: a.target.ignore_phase,
                leave_out: Vec::new(),
            };
            let row = point(
                name,
                dir,
                data,
                &order[..n],
                &selection,
                &options,
                &settings,
            )?;
            println!(
                "  {name:<10} {n:>4} runs, {:.3} core-h: held-out Fit {:.4} (A, B, C {}, others {}), at the paper's stamps {:.4}, 95 % coverage {}, trained in {:.1} s",
                row.core_hours,
                row.fit_all,
                opt(row.fit_abc),
                opt(row.fit_other),
                row.fit_paper_times,
                row.coverage.map_or("-".into(), |c| format!("{:.1} %", 100.0 * c)),
                row.train_seconds
            );
            rows.push(row);
        }
    }
    if rows.len() == earlier {
        return Err("no point of the front: every run count exceeds its design's training locations (the skipped counts are listed above)".to_string());
    }
    write_outputs(&a.out, &rows, &settings)
}

/// A design's dataset: its `dataset.npz`, or, for a campaign still running (its `campaign.json`
/// without a `dataset.npz`), the dataset of its
/// finished runs ([`campaign::assemble_finished`]), said on stderr, and whether that stops
/// short of the plan's training locations. A shard's directory is refused: its dataset lacks
/// the other shards' runs.
fn read_design(name: &str, dir: &Path) -> Result<(Dataset, bool), String> {
    let is_campaign = dir.join(campaign::CAMPAIGN_FILE).is_file();
    let running = is_campaign && !surrogate::dataset::dataset_paths(dir).0.is_file();
    if !running {
        check_dataset_path(dir)?;
        if is_campaign {
            let shard = campaign::read_campaign_dir(dir)?.shard;
            campaign::not_a_shard(dir, shard).map_err(|e| format!("{name}: {e}"))?;
        }
        let data = Dataset::read(dir).map_err(|e| format!("dataset {}: {e}", dir.display()))?;
        return Ok((data, false));
    }
    let f = campaign::assemble_finished(dir).map_err(|e| format!("{name}: {e}"))?;
    let p = &f.prefix;
    let cut = match &p.stopped_at {
        Some(run) => format!(
            "; it stops at {run}, not finished ({} finished training run(s) not read)",
            p.unread_finished
        ),
        None => String::new(),
    };
    eprintln!(
        "  {name}: {} has no dataset.npz yet: reading its finished runs, the first {} of {} training locations and every held-out one{cut}",
        dir.display(),
        p.training_locations,
        f.planned_training_locations
    );
    let partial = p.stopped_at.is_some();
    Ok((f.dataset, partial))
}

/// `NAME=DIR` or `NAME=DIR:N,N` (the design's own run counts; a DIR ending in `:digits` is
/// read as a count list).
fn parse_design(d: &str, runs: &[usize]) -> Result<(String, PathBuf, Vec<usize>), String> {
    let (name, rest) = d
        .split_once('=')
        .filter(|(n, r)| !n.is_empty() && !r.is_empty())
        .ok_or_else(|| format!("design `{d}`: give NAME=DIR or NAME=DIR:N,N"))?;
    if name.contains(',') || name.trim() != name {
        return Err(format!(
            "design `{name}`: a name without commas or surrounding spaces, as front.csv writes it unquoted"
        ));
    }
    let counts = rest
        .rsplit_once(':')
        .filter(|(_, l)| !l.is_empty() && l.chars().all(|c| c.is_ascii_digit() || c == ','));
    let (dir, runs) = match counts {
        Some((dir, list)) => {
            let n: Vec<usize> = list
                .split(',')
                .map(|n| n.parse::<usize>().ok().filter(|&n| n > 0))
                .collect::<Option<_>>()
                .ok_or_else(|| {
                    format!(
                        "design `{d}`: the run counts after `:` must be positive, comma-separated"
                    )
                })?;
            (dir, n)
        }
        None => (rest, runs.to_vec()),
    };
    Ok((name.to_string(), PathBuf::from(dir), runs))
}

fn opt(v: Option<f64>) -> String {
    v.map_or("-".into(), |f| format!("{f:.4}"))
}

/// Train on `locs` (and `interval`), score the test rows.
fn point(
    name: &str,
    dir: &Path,
    data: &Dataset,
    locs: &[i64],
    selection: &surrogate::TrainingSelection,
    options: &TrainOptions,
    settings: &str,
) -> Result<Row, String> {
    let sel = selection
        .apply(data)
        .map_err(|e| format!("{name} ({}): {e}", dir.display()))?;
    if sel.rows_with_split(Split::Test).is_empty() {
        return Err(format!(
            "{name} ({}): the campaign has no held-out (test) locations to score",
            dir.display()
        ));
    }
    let (_, report, yhat) = surrogate::train_and_predict(&sel, ModelKind::Gp, options)
        .map_err(|e| format!("{name}: {e}"))?;
    let (abc, other): (Vec<usize>, Vec<usize>) = sel
        .rows_with_split(Split::Test)
        .into_iter()
        .partition(|&i| {
            // a respiratory campaign's A at a phase is `A-ph0.5`
            let label = sel.location_label(sel.location[i]);
            let place = label.split("-ph").next().unwrap_or_default();
            ["A", "B", "C"].contains(&place)
        });
    let score = |rows: &[usize]| {
        (!rows.is_empty()).then(|| {
            let pick = |a: &ndarray::Array2<f64>| a.select(ndarray::Axis(0), rows);
            surrogate::compute_fit(pick(&sel.y).view(), pick(&yhat).view())
        })
    };
    let (fit_abc, fit_other) = (score(&abc), score(&other));
    let seconds = training_seconds(dir, &sel, locs)?;
    Ok(Row {
        design: name.to_string(),
        runs: locs.len(),
        core_hours: seconds / 3600.0,
        fit_all: report.test_fit.unwrap_or(f64::NAN),
        fit_abc,
        fit_other,
        fit_paper_times: report
            .test_fit_paper_times
            .or(report.test_fit)
            .unwrap_or(f64::NAN),
        coverage: report.test_coverage_95,
        train_seconds: report.train_seconds,
        settings: Some(settings.to_string()),
    })
}

/// Core-seconds of the runs at the training locations `locs` (every run of each location, from
/// the plan in `campaign.json`): run wall time times threads, from each `done.json`.
fn training_seconds(dir: &Path, data: &Dataset, locs: &[i64]) -> Result<f64, String> {
    let plan = campaign::read_campaign_dir(dir)?.plan()?;
    let labels: Vec<String> = locs.iter().map(|&l| data.location_label(l)).collect();
    let mut seconds = 0.0;
    for r in plan.runs.iter().filter(|r| labels.contains(&r.location)) {
        let path = campaign::run_dir(dir, &r.label);
        let m = campaign::read_done(&path)
            .ok_or_else(|| format!("{}: no readable done.json", path.display()))?;
        seconds += m.wall_seconds * m.threads as f64;
    }
    Ok(seconds)
}

fn write_outputs(out: &Path, rows: &[Row], settings: &str) -> Result<(), String> {
    let mut csv = format!("{CSV_HEADER}\n");
    let mut md = format!(
        "Settings: {settings}.\n\n| design | runs | solver core-h | held-out Fit | A, B, C | other held-out | at the paper's stamps | 95 % coverage | GP training (s) |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for r in rows {
        let _ = writeln!(csv, "{}", r.csv_cells().join(","));
        let _ = writeln!(md, "| {} |", r.cells(true).join(" | "));
    }
    let write = |name: &str, text: &str| {
        solver::output::atomic::write_atomic(&out.join(name), text.as_bytes())
    };
    write("front.csv", &csv)?;
    write("front.md", &md)?;
    let mut curves: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    for r in rows {
        match curves.iter_mut().find(|c| c.0 == r.design) {
            Some(c) => c.1.push((r.runs as f64, r.fit_all)),
            None => curves.push((r.design.clone(), vec![(r.runs as f64, r.fit_all)])),
        }
    }
    // a design extended with --with has its earlier points first, in their own order
    for c in &mut curves {
        c.1.sort_by(|p, q| p.0.total_cmp(&q.0));
    }
    let series = verification::Series {
        plot: "front".into(),
        title: "held-out Fit against training runs".into(),
        axes: ("training runs".into(), "held-out Fit (paper eq. 5)".into()),
        log: false,
        curves,
    };
    verification::plot::draw(&series, out)?;
    println!(
        "wrote {}, {} and {}",
        out.join("front.csv").display(),
        out.join("front.md").display(),
        out.join("front.png").display()
    );
    Ok(())
}
