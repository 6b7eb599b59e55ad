//! `palpa campaign merge`: the directories of a campaign's shards joined into one campaign
//! directory. The shards must hold the same plan; the target holds this campaign or nothing
//! (finished runs of another campaign would enter the dataset); every run must be finished in
//! one of them, else the error names the missing runs and their shards.

use crate::assemble::{assemble, write_dataset};
use crate::difference::first_difference;
use crate::dir::{campaign_file, read_campaign_dir, CampaignDir};
use crate::json_file::{read_json, write_json};
use crate::run_files::{is_finished, run_dir};
use crate::{CAMPAIGN_FILE, DONE_FILE};
use serde_json::Value;
use solver::output::atomic::write_atomic;
use std::path::{Path, PathBuf};
use surrogate::Dataset;

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

/// What [`merge`] did.
pub struct MergeReport {
    /// Runs of the campaign.
    pub runs: usize,
    /// Runs copied from the shards.
    pub copied: usize,
    /// The whole dataset, written to the target.
    pub dataset: Dataset,
}

/// `palpa campaign merge DIRS --out OUT`: copy the shards' finished runs into `out` and write
/// the whole dataset, identical to an unsharded run's.
pub fn merge(dirs: &[PathBuf], out: &Path) -> Result<MergeReport, String> {
    // the first directory's campaign, which every other must equal
    let mut first: Option<CampaignDir> = None;
    // the shard counts the directories record (an unsharded one counts as 1)
    let mut counts: Vec<usize> = Vec::new();
    for d in dirs {
        let cd = read_campaign_dir(d)?;
        counts.push(cd.shard.map_or(1, |(_, n)| n));
        match &first {
            None => first = Some(cd),
            Some(f) => {
                let Some(diff) = first_difference(&f.plan_value, &cd.plan_value, "plan") else {
                    continue;
                };
                return Err(format!(
                    "{} is a different campaign from {} ({diff}; there = {}, here = {})",
                    d.display(),
                    dirs[0].display(),
                    dirs[0].display(),
                    d.display()
                ));
            }
        }
    }
    let first = first.ok_or("merge: no directories")?;
    let typed = first.plan()?;
    let plan = first.plan_value;
    let labels: Vec<String> = typed.runs.iter().map(|r| r.label.clone()).collect();
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
        if is_finished(out, l) {
            continue;
        }
        match dirs.iter().find(|d| is_finished(d, l)) {
            Some(d) if !same(d, out) => {
                copy_run(&run_dir(d, l), &dst)?;
                copied += 1;
            }
            _ => missing.push((k, l.as_str())),
        }
    }
    if !missing.is_empty() {
        return Err(missing_runs(&missing, counts));
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
    let dataset = assemble(&typed, &labels, |l| run_dir(out, l))?;
    write_dataset(&dataset, out)?;
    Ok(MergeReport {
        runs: labels.len(),
        copied,
        dataset,
    })
}

/// The error of a merge that lacks the finished runs `missing` (index, label); `counts` are the
/// shard counts the directories record.
fn missing_runs(missing: &[(usize, &str)], mut counts: Vec<usize>) -> String {
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
    format!(
        "merge: {} run(s) are finished in none of the directories: {} ({which})",
        missing.len(),
        labels.join(", ")
    )
}

/// A merge keeps the finished runs it finds in `out`, so `out` must hold this campaign or
/// nothing: finished runs of another campaign (or of unknown origin) would enter the dataset.
fn refuse_stale_out(out: &Path, plan: &Value, dirs: &[PathBuf]) -> Result<(), String> {
    let file = out.join(CAMPAIGN_FILE);
    if file.is_file() {
        let v = read_json(&file)?;
        if let Some(diff) = first_difference(&v["plan"], plan, "plan") {
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
