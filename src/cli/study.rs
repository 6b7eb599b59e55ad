//! `palpa study [--quick] [--out DIR]`: accuracy against cost of every speed knob (mesh size,
//! element formulation, mass scaling, bulk-modulus cap, time-step factor, step estimate) on the
//! phantom palpation; see
//! [`verification::study`]. Writes `study.csv`, `study.md` and the Pareto plots.
//!
//! `palpa study --paper [--locations A,B,C] [--report-only | --dry-run] [--out DIR]`: the same
//! at the paper's resolution against one reference ([`verification::study_paper`]); writes
//! `records/`, `study-3mm.csv`, `study-3mm.md` and `pareto_3mm_*.png`.

use indicatif::{ProgressBar, ProgressStyle};
use scene::run::RunStatus;
use solver::output::atomic::write_atomic;
use std::path::Path;
use verification::study_paper_record::RunRecord;
use verification::{study_paper, study_paper_report};

/// A progress bar, hidden when `quiet`.
fn progress_bar(quiet: bool) -> Result<ProgressBar, String> {
    Ok(if quiet {
        ProgressBar::hidden()
    } else {
        let pb = ProgressBar::new(1);
        pb.set_style(
            ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} {msg} (ETA {eta})",
            )
            .map_err(|e| e.to_string())?,
        );
        pb.enable_steady_tick(std::time::Duration::from_millis(200));
        pb
    })
}

/// Run the study.
pub fn study(quick: bool, out: &Path, quiet: bool) -> Result<(), String> {
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let pb = progress_bar(quiet)?;
    let rows = verification::study::run_study(quick, out, |i, n, what| {
        pb.set_length(n as u64);
        pb.set_position(i as u64);
        pb.set_message(what.to_string());
    })?;
    pb.finish_and_clear();
    let md = verification::study::to_markdown(&rows);
    write_atomic(
        &out.join("study.csv"),
        verification::study::to_csv(&rows).as_bytes(),
    )?;
    write_atomic(&out.join("study.md"), md.as_bytes())?;
    let files = verification::study::plots(&rows, out)?;
    println!("{md}");
    for r in rows.iter().filter(|r| r.status != RunStatus::Completed) {
        println!("  {} = {}: {}", r.knob, r.setting, r.status);
    }
    println!(
        "wrote study.csv, study.md, {} into {}",
        files.join(", "),
        out.display()
    );
    Ok(())
}

/// What `study --paper` does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PaperMode {
    /// Run what has no record, then report.
    Run,
    /// Report from the records there are.
    ReportOnly,
    /// Print the plan.
    DryRun,
}

impl PaperMode {
    /// From the two flags (clap keeps them exclusive).
    pub fn new(report_only: bool, dry_run: bool) -> PaperMode {
        match (report_only, dry_run) {
            (true, _) => PaperMode::ReportOnly,
            (_, true) => PaperMode::DryRun,
            _ => PaperMode::Run,
        }
    }
}

/// The study at the paper's resolution.
pub fn study_paper(
    out: &Path,
    locations: &[String],
    mode: PaperMode,
    quiet: bool,
) -> Result<(), String> {
    let mut locs: Vec<String> = Vec::new();
    for l in locations {
        if !study_paper::LOCATIONS.contains(&l.as_str()) {
            return Err(format!(
                "--locations: unknown location `{l}` (the study presses at {})",
                study_paper::LOCATIONS.join(", ")
            ));
        }
        if !locs.contains(l) {
            locs.push(l.clone());
        }
    }
    let locations = &locs[..];
    if mode == PaperMode::DryRun {
        for l in locations {
            for va in study_paper::plan(l) {
                let path = study_paper::record_path(out, l, &va);
                let state = match RunRecord::read(&path)? {
                    None => "to run".to_string(),
                    Some(r) if !r.is_current(&va.setup.scene_toml()) => {
                        "stale: another scene or record format; runs again".into()
                    }
                    Some(r) if r.completed() => "recorded".into(),
                    Some(r) => format!(
                        "recorded ({}; delete {} to run it again)",
                        r.status,
                        path.display()
                    ),
                };
                println!("{l}  {} = {}  ({state})", va.knob, va.setting);
            }
        }
        return Ok(());
    }
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let records = if mode == PaperMode::ReportOnly {
        study_paper::read_records(out, locations)?
    } else {
        let pb = progress_bar(quiet)?;
        let r = study_paper::run(out, locations, |i, n, what| {
            pb.set_length(n as u64);
            pb.set_position(i as u64);
            pb.set_message(what.to_string());
        })?;
        pb.finish_and_clear();
        r
    };
    if records.is_empty() {
        return Err(format!(
            "{}: no current study records to report (none, or all of another scene or record \
             format: `palpa study --paper --dry-run` lists them; run `palpa study --paper`)",
            out.join("records").display()
        ));
    }
    let md = study_paper_report::to_markdown(&records);
    write_atomic(
        &out.join("study-3mm.csv"),
        study_paper_report::to_csv(&records).as_bytes(),
    )?;
    write_atomic(&out.join("study-3mm.md"), md.as_bytes())?;
    let files = study_paper_report::plots(&records, out)?;
    println!("{md}");
    println!(
        "wrote study-3mm.csv, study-3mm.md{}{} into {}",
        if files.is_empty() { "" } else { ", " },
        files.join(", "),
        out.display()
    );
    Ok(())
}
