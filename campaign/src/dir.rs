//! The description file of a campaign directory (`campaign.json`): format, solver version,
//! shard and the [`CampaignPlan`]. A resumed campaign, the shards of a merge and a merge's target
//! must agree on the plan; [`first_difference`] names where two plans part.

use crate::difference::first_difference;
use crate::json_file::{read_json, write_json};
use crate::plan::CampaignPlan;
use crate::shard::shard_in;
use crate::{CAMPAIGN_FILE, CAMPAIGN_FORMAT};
use serde_json::{json, Value};
use std::path::Path;

/// The campaign description file of a directory: format, solver version, shard and plan.
pub fn campaign_file(plan: &Value, shard: Option<(usize, usize)>) -> Value {
    json!({
        "format": CAMPAIGN_FORMAT,
        "version": 1,
        "solver_version": env!("CARGO_PKG_VERSION"),
        "shard": shard.map(|(i, n)| format!("{i}/{n}")),
        "plan": plan,
    })
}

/// A campaign directory's description as read back: its shard and its plan (as written, for
/// comparisons, and typed).
pub struct CampaignDir {
    /// The shard it holds, `None` when unsharded.
    pub shard: Option<(usize, usize)>,
    /// The plan as JSON.
    pub plan_value: Value,
    /// The solver version that wrote it.
    pub solver_version: Value,
    /// The file read (`DIR/campaign.json`).
    pub file: std::path::PathBuf,
}

/// Read `dir`'s `campaign.json`; an error names the file when it is not a palpa campaign.
pub fn read_campaign_dir(dir: &Path) -> Result<CampaignDir, String> {
    let file = dir.join(CAMPAIGN_FILE);
    let v = read_json(&file)?;
    if v["format"] != CAMPAIGN_FORMAT {
        return Err(format!("{}: not a palpa campaign", file.display()));
    }
    Ok(CampaignDir {
        shard: shard_in(&v, &file)?,
        plan_value: v.get("plan").cloned().unwrap_or(Value::Null),
        solver_version: v.get("solver_version").cloned().unwrap_or(Value::Null),
        file,
    })
}

impl CampaignDir {
    /// The typed plan; an error names the file and the key.
    pub fn plan(&self) -> Result<CampaignPlan, String> {
        CampaignPlan::from_value(&self.plan_value)
            .map_err(|e| format!("{}: {e}", self.file.display()))
    }
}

/// Make `out` the directory of this campaign (`plan`, `shard`): create it, refuse one that holds
/// another campaign (naming where the plans part) or finished runs without `resume`, and write
/// `campaign.json`. `note` hears the solver version of the finished runs when it is not this
/// one, before any refusal.
pub fn prepare_dir(
    out: &Path,
    plan: &CampaignPlan,
    shard: Option<(usize, usize)>,
    n_done: usize,
    resume: bool,
    note: &mut dyn FnMut(&Value),
) -> Result<(), String> {
    std::fs::create_dir_all(out)
        .map_err(|e| format!("{}: cannot create the output directory: {e}", out.display()))?;
    let cfile = out.join(CAMPAIGN_FILE);
    let plan = plan.to_value();
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
        if old.get("solver_version") != desc.get("solver_version") {
            note(old.get("solver_version").unwrap_or(&Value::Null));
        }
    }
    if n_done > 0 && !resume {
        return Err(format!(
            "{} already holds {n_done} finished run(s) of this campaign: pass --resume to continue it, or choose a new --out",
            out.display()
        ));
    }
    write_json(&cfile, &desc)
}

/// Write `out`'s `campaign.json` for `plan` and `shard` (atomically), as [`prepare_dir`] does
/// once it has checked the directory; an adaptive campaign writes it again after each batch.
pub fn write_campaign_file(
    out: &Path,
    plan: &CampaignPlan,
    shard: Option<(usize, usize)>,
) -> Result<(), String> {
    write_json(
        &out.join(CAMPAIGN_FILE),
        &campaign_file(&plan.to_value(), shard),
    )
}
