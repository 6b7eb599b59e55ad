//! The end of an invocation of a campaign: failed runs are an error that lists them;
//! unfinished runs (stopped, or left for another invocation) are named; when every run of the
//! campaign (or of the shard) is finished, the dataset is assembled and written.

use crate::assemble::{assemble, write_dataset};
use crate::execute::Report;
use crate::plan::{CampaignPlan, PlannedRun};
use crate::run_files::{is_finished, run_dir};
use std::path::Path;
use surrogate::Dataset;

/// How an invocation ended, when no run failed.
pub enum Outcome {
    /// These runs are not finished (continue with `--resume`).
    Unfinished(Vec<String>),
    /// Every run is finished: the dataset, written to the campaign directory.
    Dataset(Dataset),
}

/// The outcome of the invocation that ran `mine` (the runs of its shard) into `out`.
pub fn finish(
    out: &Path,
    report: &Report,
    plan: &CampaignPlan,
    mine: &[&PlannedRun],
) -> Result<Outcome, String> {
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
    let missing: Vec<String> = mine
        .iter()
        .filter(|r| !is_finished(out, &r.label))
        .map(|r| r.label.clone())
        .collect();
    if !missing.is_empty() {
        return Ok(Outcome::Unfinished(missing));
    }
    let labels: Vec<String> = mine.iter().map(|r| r.label.clone()).collect();
    let ds = assemble(plan, &labels, |l| run_dir(out, l))?;
    write_dataset(&ds, out)?;
    Ok(Outcome::Dataset(ds))
}
