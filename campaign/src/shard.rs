//! Shards: run `k` (0-based, in the campaign's order) belongs to shard `k mod n`. A shard's
//! count is fixed when its directory is made (`campaign.json` records it).

use crate::json_file::read_json;
use crate::CAMPAIGN_FILE;
use serde_json::Value;
use std::path::Path;

/// Parse `i/n` (0 <= i < n).
pub fn parse_shard(s: &str) -> Result<(usize, usize), String> {
    let bad = || format!("--shard: expected i/n with 0 <= i < n, e.g. 0/4, got `{s}`");
    let (i, n) = s.split_once('/').ok_or_else(bad)?;
    let (i, n): (usize, usize) = (
        i.trim().parse().map_err(|_| bad())?,
        n.trim().parse().map_err(|_| bad())?,
    );
    if n == 0 || i >= n {
        return Err(bad());
    }
    Ok((i, n))
}

/// Whether run `index` belongs to shard `(i, n)`: `index mod n == i`.
pub fn in_shard(index: usize, shard: (usize, usize)) -> bool {
    index % shard.1 == shard.0
}

/// The shard `DIR/campaign.json` records: `None` without that file, `Some(None)` for an
/// unsharded campaign.
pub fn recorded_shard(out: &Path) -> Result<Option<Option<(usize, usize)>>, String> {
    let cfile = out.join(CAMPAIGN_FILE);
    if !cfile.exists() {
        return Ok(None);
    }
    shard_in(&read_json(&cfile)?, &cfile).map(Some)
}

/// The shard of the campaign description `v` (read from `cfile`), `None` when unsharded.
pub fn shard_in(v: &Value, cfile: &Path) -> Result<Option<(usize, usize)>, String> {
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
pub fn resolve_shard(arg: Option<&str>, out: &Path) -> Result<Option<(usize, usize)>, String> {
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
