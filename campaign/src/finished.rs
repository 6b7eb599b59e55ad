//! The dataset of a campaign's finished runs, read while the campaign is still running (for
//! `palpa front` on a design not yet complete). A front trains on a design's *first* n
//! training locations, so the dataset holds the training locations in plan order up to the
//! first one with an unfinished run, and every held-out run, which must all be finished (a
//! campaign runs its held-out locations after its training ones, so they are finished when it
//! was extended from a finished one, or at its end).

use crate::assemble::assemble;
use crate::dir::read_campaign_dir;
use crate::run_files::is_finished;
use std::collections::HashMap;
use std::path::Path;
use surrogate::{Dataset, Split};

/// The runs of a campaign to read while it runs ([`finished_prefix`]).
#[derive(Debug, PartialEq)]
pub struct Prefix {
    /// Labels of the runs to read, in plan order.
    pub labels: Vec<String>,
    /// Training locations read: the finished prefix of the plan's training locations.
    pub training_locations: usize,
    /// The first unfinished training run, where the prefix stops (`None` when all finished).
    pub stopped_at: Option<String>,
    /// Finished training runs not read (of the stopping location and the ones after it).
    pub unread_finished: usize,
}

/// What [`assemble_finished`] read.
pub struct FinishedPrefix {
    /// The dataset of the runs read (not written to the directory).
    pub dataset: Dataset,
    /// The runs read.
    pub prefix: Prefix,
    /// Training locations in the plan.
    pub planned_training_locations: usize,
}

/// The runs to read, given each run's (label, location), each location's split and which runs
/// are finished: the runs of the training locations (in the order of their first run) before
/// the first location with an unfinished run, and every held-out run; or the unfinished
/// held-out runs.
pub fn finished_prefix(
    runs: &[(&str, &str)],
    split: &HashMap<&str, Split>,
    finished: impl Fn(&str) -> bool,
) -> Result<Prefix, Vec<String>> {
    let is_test = |loc: &str| split.get(loc) == Some(&Split::Test);
    let unfinished_test: Vec<String> = runs
        .iter()
        .filter(|(l, loc)| is_test(loc) && !finished(l))
        .map(|(l, _)| l.to_string())
        .collect();
    if !unfinished_test.is_empty() {
        return Err(unfinished_test);
    }
    let stop = runs
        .iter()
        .find(|(l, loc)| !is_test(loc) && !finished(l))
        .map(|&(l, loc)| (l, loc));
    // the training locations in the order of their first run, up to the stopping one
    let mut kept: Vec<&str> = Vec::new();
    for (_, loc) in runs.iter().filter(|(_, loc)| !is_test(loc)) {
        if stop.is_some_and(|(_, s)| s == *loc) {
            break;
        }
        if !kept.contains(loc) {
            kept.push(loc);
        }
    }
    let labels = runs
        .iter()
        .filter(|(_, loc)| is_test(loc) || kept.contains(loc))
        .map(|(l, _)| l.to_string())
        .collect();
    let unread_finished = runs
        .iter()
        .filter(|(l, loc)| !is_test(loc) && !kept.contains(loc) && finished(l))
        .count();
    Ok(Prefix {
        labels,
        training_locations: kept.len(),
        stopped_at: stop.map(|(l, _)| l.to_string()),
        unread_finished,
    })
}

/// Refuse the directory `out` of shard `shard` (`Some((i, n))`) where a whole campaign's
/// dataset is wanted: the other shards' runs are elsewhere.
pub fn not_a_shard(out: &Path, shard: Option<(usize, usize)>) -> Result<(), String> {
    match shard {
        Some((i, n)) => Err(format!(
            "{}: holds shard {i}/{n} of a campaign; join the shards with `palpa campaign merge` and give the merged directory",
            out.display()
        )),
        None => Ok(()),
    }
}

/// Assemble the dataset of `out`'s finished runs ([`finished_prefix`]). An error names the
/// held-out runs not finished, or refuses a shard's directory (the other shards' runs are
/// elsewhere: merge them first).
pub fn assemble_finished(out: &Path) -> Result<FinishedPrefix, String> {
    let cd = read_campaign_dir(out)?;
    not_a_shard(out, cd.shard)?;
    let plan = cd.plan()?;
    let split: HashMap<&str, Split> = plan
        .locations
        .iter()
        .map(|l| (l.label.as_str(), l.split))
        .collect();
    let runs: Vec<(&str, &str)> = plan
        .runs
        .iter()
        .map(|r| (r.label.as_str(), r.location.as_str()))
        .collect();
    let prefix =
        finished_prefix(&runs, &split, |l| is_finished(out, l)).map_err(|missing| {
            format!(
                "{}: held-out run(s) not finished: {} (a campaign runs its held-out locations last; continue it with --resume)",
                out.display(),
                missing.join(", ")
            )
        })?;
    let dataset = assemble(&plan, &prefix.labels, |l| crate::run_dir(out, l))?;
    Ok(FinishedPrefix {
        dataset,
        prefix,
        planned_training_locations: split.values().filter(|&&s| s == Split::Train).count(),
    })
}

#[cfg(test)]
mod tests {
    use super::finished_prefix;
    use std::collections::HashMap;
    use surrogate::Split;

    /// Two depths a location; a held-out location between training ones (an adaptive plan's
    /// layout). S2's second run is unfinished, so the prefix is S1 alone although S3 is
    /// finished; every held-out run is read; an unfinished held-out run is named.
    #[test]
    fn the_prefix_stops_at_the_first_location_with_an_unfinished_run() {
        let runs = [
            ("S1-d1", "S1"),
            ("S1-d2", "S1"),
            ("A-d1", "A"),
            ("S2-d1", "S2"),
            ("S2-d2", "S2"),
            ("S3-d1", "S3"),
            ("S3-d2", "S3"),
        ];
        let split = HashMap::from([
            ("S1", Split::Train),
            ("S2", Split::Train),
            ("S3", Split::Train),
            ("A", Split::Test),
        ]);
        let p = finished_prefix(&runs, &split, |l| l != "S2-d2").unwrap();
        assert_eq!(p.labels, ["S1-d1", "S1-d2", "A-d1"]);
        assert_eq!(
            (
                p.training_locations,
                p.stopped_at.as_deref(),
                p.unread_finished
            ),
            (1, Some("S2-d2"), 3)
        );
        let p = finished_prefix(&runs, &split, |_| true).unwrap();
        assert_eq!(
            (
                p.labels.len(),
                p.training_locations,
                p.stopped_at,
                p.unread_finished
            ),
            (7, 3, None, 0)
        );
        let missing = finished_prefix(&runs, &split, |l| l != "A-d1").unwrap_err();
        assert_eq!(missing, ["A-d1"]);
    }
}
