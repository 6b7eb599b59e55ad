//! The training dataset of a campaign ([`surrogate::Dataset`]): every sample of every run, in
//! plan order. X holds x, y [m], force [N], time [s] and depth [m] (indentation since first
//! contact) per sample, and for a respiratory campaign the phase (0 exhalation .. 1
//! inspiration) as a sixth column; the force is the hand reaction after the 1 ms centred moving average of
//! [`solver::output::filter`] (the raw probed value chatters with the penalty contact and stays
//! in `probe.csv`), Y the ROI maximum principal stress [Pa], S the full Cauchy tensors. A run at
//! a phase of its own reads its ROI columns through its `roi_map.json` (the reference ROI's
//! points carried with the liver, [`crate::plan::ROI_MAP_FILE`]), so column i is one point of the
//! liver at every phase. Both
//! `palpa campaign` and `palpa campaign merge` assemble through here, so the two write the same
//! bytes.

use crate::plan::{CampaignPlan, PlanLocation};
use crate::run_files::read_run;
use ndarray::{Array1, Array2, Array3};
use serde_json::json;
use solver::output::atomic::write_atomic;
use std::path::{Path, PathBuf};
use surrogate::{Dataset, Manifest};

/// The rows of one run's samples.
struct Rows {
    xs: Vec<f64>,
    ys: Vec<f64>,
    ss: Vec<f64>,
    location: Vec<i64>,
    split: Vec<u8>,
}

/// The dataset of the runs `labels` (in plan order) of `plan`, reading run `l` from
/// `dir_of(l)`.
pub fn assemble(
    plan: &CampaignPlan,
    labels: &[String],
    dir_of: impl Fn(&str) -> PathBuf,
) -> Result<Dataset, String> {
    let roi_ids: Vec<i64> = plan.roi.elements.iter().map(|&e| e as i64).collect();
    let r = roi_ids.len();
    let mut roi_centroids = Array2::zeros((r, 3));
    for (i, c) in plan.roi.centroids_m.iter().enumerate().take(r) {
        for j in 0..3 {
            roi_centroids[(i, j)] = c[j];
        }
    }
    let mut rows = Rows {
        xs: Vec::new(),
        ys: Vec::new(),
        ss: Vec::new(),
        location: Vec::new(),
        split: Vec::new(),
    };
    let respiratory = plan.is_respiratory();
    let cols = if respiratory { 6 } else { 5 };
    let mut run_rows = Vec::new();
    for label in labels {
        let run = plan.run(label)?;
        let li = plan
            .locations
            .iter()
            .position(|l| l.label == run.location)
            .ok_or_else(|| {
                format!(
                    "campaign.json: run `{label}`: no location `{}`",
                    run.location
                )
            })?;
        let loc = &plan.locations[li];
        let start = rows.location.len();
        let dir = dir_of(label);
        let ids = match loc.phase {
            Some(_) => carried_roi(&dir, r)?,
            None => roi_ids.clone(),
        };
        let phase = respiratory.then(|| loc.phase.unwrap_or(plan.phantom.respiratory_phase));
        append_run(&mut rows, &dir, &ids, li, loc, phase)?;
        run_rows.push(json!({
            "label": label,
            "location": run.location,
            "split": loc.split.name(),
            "depth_m": run.depth_m,
            "duration_s": run.duration_s,
            "rows": [start, rows.location.len()],
        }));
    }
    let n = rows.location.len();
    Ok(Dataset {
        x: Array2::from_shape_vec((n, cols), rows.xs).map_err(|e| e.to_string())?,
        y: Array2::from_shape_vec((n, r), rows.ys).map_err(|e| e.to_string())?,
        stress: Some(Array3::from_shape_vec((n, r, 6), rows.ss).map_err(|e| e.to_string())?),
        roi_ids: Array1::from(roi_ids),
        roi_centroids,
        location: Array1::from(rows.location),
        split: Array1::from(rows.split),
        manifest: manifest(plan, run_rows, respiratory),
    })
}

/// The element ids of a respiratory run's carried ROI, in the ROI's order (`r` of them).
fn carried_roi(dir: &Path, r: usize) -> Result<Vec<i64>, String> {
    let path = dir.join(crate::plan::ROI_MAP_FILE);
    let text = std::fs::read_to_string(&path)
        .map_err(|e| format!("{}: cannot read the run's ROI map: {e}", path.display()))?;
    #[derive(serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    struct RoiMap {
        roi_elements: Vec<i64>,
    }
    let m: RoiMap = serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
    if m.roi_elements.len() != r {
        return Err(format!(
            "{}: {} ROI elements, the campaign's ROI has {r}: remove {} and continue with --resume to redo the run",
            path.display(),
            m.roi_elements.len(),
            dir.display()
        ));
    }
    Ok(m.roi_elements)
}

/// Append the samples of the run in `dir` (location `li`, whose ROI columns are the probe's
/// elements `roi_ids`, in order), with `phase` as a sixth input column when given.
fn append_run(
    rows: &mut Rows,
    dir: &Path,
    roi_ids: &[i64],
    li: usize,
    loc: &PlanLocation,
    phase: Option<f64>,
) -> Result<(), String> {
    let d = read_run(dir)?;
    // the probe's columns in the ROI's order (nearest to the ROI centre first); a carried ROI
    // may read one element twice, and its probe lists each element once
    let mut distinct = roi_ids.to_vec();
    distinct.sort_unstable();
    distinct.dedup();
    let cols: Vec<usize> = roi_ids
        .iter()
        .map(|&id| d.elements.iter().position(|&e| e as i64 == id))
        .collect::<Option<_>>()
        .filter(|_| d.elements.len() == distinct.len())
        .ok_or_else(|| {
            format!(
                "{}: the probe's elements are not the campaign's ROI (for a run at a phase of its own: not those of its {})",
                dir.display(),
                crate::plan::ROI_MAP_FILE
            )
        })?;
    let at = loc.surface_m;
    for k in 0..d.time.len() {
        rows.xs
            .extend([at[0], at[1], d.force_filtered[k], d.time[k], d.depth[k]]);
        rows.xs.extend(phase);
        rows.ys.extend(cols.iter().map(|&c| d.max_principal[k][c]));
        for &c in &cols {
            rows.ss.extend(&d.tensors[k][c]);
        }
        rows.location.push(li as i64);
        rows.split.push(loc.split.code());
    }
    Ok(())
}

/// The dataset's manifest: columns, locations, the solver's settings and runs, the phantom.
fn manifest(plan: &CampaignPlan, run_rows: Vec<serde_json::Value>, respiratory: bool) -> Manifest {
    let mut x_columns: Vec<String> = ["x", "y", "force", "time", "depth"]
        .map(String::from)
        .to_vec();
    if respiratory {
        x_columns.push("phase".into());
    }
    let mut manifest = Manifest {
        x_columns,
        location_labels: plan.locations.iter().map(|l| l.label.clone()).collect(),
        solver: json!({
            "name": "palpa",
            "version": env!("CARGO_PKG_VERSION"),
            "campaign": plan.title,
            "settings": serde_json::to_value(&plan.settings).expect("plain data"),
            "force": "hand reaction along the pressing direction (hand_reaction), centred moving average of history.csv at the sample time (contact chatter removed)",
            "force_filter_s": solver::output::filter::FORCE_FILTER,
            "depth": "indentation since first contact (hand_depth)",
            "x_y": "skin point of the location where the two-finger hand presses",
            "runs": run_rows,
        }),
        phantom: json!({
            "parameters": serde_json::to_value(&plan.phantom).expect("plain data"),
            "roi_center_m": plan.roi.center_m,
        }),
        ..Manifest::default()
    };
    manifest
        .units
        .insert("location".into(), "index into location_labels".into());
    manifest
        .units
        .insert("split".into(), "0 train, 1 test".into());
    if respiratory {
        manifest.units.insert(
            "phase".into(),
            "respiratory phase, 0 exhalation .. 1 inspiration (the liver moves caudally by phase x max_liver_shift)".into(),
        );
    }
    manifest
}

/// Write `dataset.npz` + `manifest.json`, and the manifest again as `dataset.json`.
pub fn write_dataset(ds: &Dataset, out: &Path) -> Result<(), String> {
    ds.write(out).map_err(|e| e.to_string())?;
    let m = std::fs::read(out.join("manifest.json")).map_err(|e| e.to_string())?;
    write_atomic(&out.join("dataset.json"), &m)
}
