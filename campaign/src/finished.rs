//! The dataset of a campaign's finished runs, read while the campaign is still running (for
//! `palpa front` on a design not yet complete). A front trains on a design's *first* n
//! training locations, so the dataset holds the training locations in plan order up to the
//! first one with an unfinished run, and every held-out run, which must all be finished.

use crate::assemble::assemble;
use crate::dir::read_campaign_dir;
use crate::run_files::{read_done, run_dir};
use std::collections::HashSet;
use std::path::Path;
use surrogate::{Dataset, Split};

/// What [`assemble_finished`] read.
pub struct FinishedPrefix {
    /// The dataset of the runs read (not written to the directory).
    pub dataset: Dataset,
    /// Training locations read: the finished prefix of the plan's training locations.
    pub training_locations: usize,
    /// Training locations in the plan.
    pub planned_training_locations: usize,
}

/// Assemble the dataset of `out`'s finished runs: the held-out runs and the training runs of
/// the plan's training locations before the first location with an unfinished run. An error
/// names the held-out runs not finished.
pub fn assemble_finished(out: &Path) -> Result<FinishedPrefix, String> {
    let plan = read_campaign_dir(out)?.plan()?;
    let finished = |label: &str| read_done(&run_dir(out, label)).is_some();
    let split_of = |loc: &str| {
        plan.locations
            .iter()
            .find(|l| l.label == loc)
            .map(|l| l.split)
    };
    let unfinished_test: Vec<&str> = plan
        .runs
        .iter()
        .filter(|r| split_of(&r.location) == Some(Split::Test) && !finished(&r.label))
        .map(|r| r.label.as_str())
        .collect();
    if !unfinished_test.is_empty() {
        return Err(format!(
            "{}: held-out run(s) not finished: {} (continue the campaign with --resume)",
            out.display(),
            unfinished_test.join(", ")
        ));
    }
    // the training locations in plan order, cut before the first with an unfinished run
    let training: Vec<&str> = plan
        .locations
        .iter()
        .filter(|l| l.split == Split::Train)
        .map(|l| l.label.as_str())
        .collect();
    let complete = |loc: &str| {
        plan.runs
            .iter()
            .filter(|r| r.location == loc)
            .all(|r| finished(&r.label))
    };
    let n = training.iter().take_while(|l| complete(l)).count();
    let keep: HashSet<&str> = training[..n].iter().copied().collect();
    let labels: Vec<String> = plan
        .runs
        .iter()
        .filter(|r| {
            keep.contains(r.location.as_str()) || split_of(&r.location) == Some(Split::Test)
        })
        .map(|r| r.label.clone())
        .collect();
    let dataset = assemble(&plan, &labels, |l| run_dir(out, l))?;
    Ok(FinishedPrefix {
        dataset,
        training_locations: n,
        planned_training_locations: training.len(),
    })
}
