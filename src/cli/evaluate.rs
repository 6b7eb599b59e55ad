//! `palpa evaluate DATASET [--out DIR] [--epochs N] [--models a,b]`: leave-one-location-out
//! cross-validation of each surrogate configuration over every location of a dataset, and the
//! accuracy-versus-cost table (model type and size against Fit, training time per fold and
//! prediction latency).
//!
//! The configurations are [`surrogate::default_evaluation_configs`] (the GP, the paper's MLP and
//! two smaller MLPs) and the cross-validation is [`surrogate::evaluate`], called one
//! configuration at a time so that progress shows. With `--out DIR` the table is written as
//! `evaluation.md` (Markdown), `evaluation.csv` (one row per configuration),
//! `evaluation-by-location.csv` (one row per configuration and held-out location) and
//! `evaluation.json` (the whole [`surrogate::EvaluationReport`]), each written atomically.

use super::train::check_dataset_path;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;
use surrogate::{Dataset, EvaluationReport};

/// `palpa evaluate`'s arguments.
#[derive(clap::Args)]
pub struct EvaluateArgs {
    /// The dataset: a directory holding dataset.npz + manifest.json, or NAME.npz beside
    /// NAME.json. Every location (both splits) is held out once.
    pub dataset: PathBuf,
    /// Also write the table into this directory (evaluation.md, evaluation.csv,
    /// evaluation-by-location.csv, evaluation.json).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// MLP epochs per fold (Adam), by default those of `palpa train`. Every configuration is
    /// trained once per location: with 28 locations the default table takes about 8 minutes on
    /// 2 cores, `--epochs 500` about 4 (and under-trains the MLPs).
    #[arg(long, default_value_t = surrogate::mlp::MlpOptions::default().epochs)]
    pub epochs: usize,
    /// Only these configurations, comma-separated (gp, gp-principal, mlp-paper, mlp-medium,
    /// mlp-small) [default: all].
    #[arg(long, value_delimiter = ',')]
    pub models: Option<Vec<String>>,
}

/// Run `palpa evaluate`.
pub fn run(a: &EvaluateArgs) -> Result<(), String> {
    evaluate(&a.dataset, a.out.as_deref(), a.epochs, a.models.as_deref())
}

/// Cross-validate, print the table, write the files.
pub fn evaluate(
    dataset: &Path,
    out: Option<&Path>,
    epochs: usize,
    models: Option<&[String]>,
) -> Result<(), String> {
    if epochs == 0 {
        return Err("--epochs must be at least 1".into());
    }
    check_dataset_path(dataset)?;
    let data = Dataset::read(dataset).map_err(|e| format!("dataset {}: {e}", dataset.display()))?;
    let mut configs = surrogate::default_evaluation_configs(epochs);
    if let Some(names) = models {
        let known: Vec<String> = configs.iter().map(|c| c.name.clone()).collect();
        if let Some(bad) = names.iter().find(|n| !known.contains(n)) {
            return Err(format!(
                "--models: unknown configuration {bad:?}; known: {}",
                known.join(", ")
            ));
        }
        configs.retain(|c| names.contains(&c.name));
    }
    let mut locations = data.location.to_vec();
    locations.sort_unstable();
    locations.dedup();
    eprintln!(
        "palpa evaluate: {} configuration(s) x {} locations ({} samples, {} ROI elements), MLPs \
         {epochs} epochs ...",
        configs.len(),
        locations.len(),
        data.n_samples(),
        data.n_roi()
    );
    let wall = Instant::now();
    let mut report = EvaluationReport {
        n_folds: locations.len(),
        rows: Vec::new(),
    };
    for cfg in &configs {
        let t = Instant::now();
        let one = surrogate::evaluate(&data, std::slice::from_ref(cfg))
            .map_err(|e| format!("evaluate {} on {}: {e}", cfg.name, dataset.display()))?;
        report.n_folds = one.n_folds;
        for row in one.rows {
            eprintln!(
                "  {}: Fit pooled {:.4}, {:.1} s",
                row.name,
                row.fit_pooled,
                t.elapsed().as_secs_f64()
            );
            report.rows.push(row);
        }
    }
    println!("{report}");
    println!(
        "Fit: paper eq. 5 on each held-out location's samples (pooled over all, mean and worst of \
         the per-location figures); train s/fold: mean training time of one fold; latency: mean \
         single prediction, one thread. Wall time {:.1} s.",
        wall.elapsed().as_secs_f64()
    );
    if let Some(dir) = out {
        let files = write_report(&report, dir)?;
        println!("wrote {} into {}", files.join(", "), dir.display());
    }
    Ok(())
}

/// CSV field: quoted when it holds a comma, a quote or a newline.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// Writes the four report files into `dir`; returns their names.
fn write_report(report: &EvaluationReport, dir: &Path) -> Result<Vec<String>, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("--out {}: {e}", dir.display()))?;
    let mut table = String::from(
        "name,kind,target,size,n_params,fit_pooled,fit_mean,fit_min,train_seconds_per_fold,latency_us\n",
    );
    let mut by_location = String::from("name,kind,location,label,n_samples,fit\n");
    for r in &report.rows {
        let _ = writeln!(
            table,
            "{},{},{},{},{},{},{},{},{},{}",
            csv_field(&r.name),
            r.kind,
            r.target,
            csv_field(&r.size),
            r.n_params,
            r.fit_pooled,
            r.fit_mean,
            r.fit_min,
            r.train_seconds,
            r.latency_us
        );
        for l in &r.by_location {
            let _ = writeln!(
                by_location,
                "{},{},{},{},{},{}",
                csv_field(&r.name),
                r.kind,
                l.location,
                csv_field(&l.label),
                l.n_samples,
                l.fit
            );
        }
    }
    let json = serde_json::to_string_pretty(report).map_err(|e| e.to_string())?;
    let files = [
        ("evaluation.md", report.to_string()),
        ("evaluation.csv", table),
        ("evaluation-by-location.csv", by_location),
        ("evaluation.json", json),
    ];
    for (name, text) in &files {
        solver::output::atomic::write_atomic(&dir.join(name), text.as_bytes())?;
    }
    Ok(files.iter().map(|(n, _)| n.to_string()).collect())
}
