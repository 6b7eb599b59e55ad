//! The training dataset of a campaign ([`surrogate::Dataset`]): every sample of every run, in
//! plan order. X holds x, y [m], force [N], time [s] and depth [m] (indentation since first
//! contact) per sample; the force is the hand reaction after the 1 ms centred moving average of
//! [`solver::output::filter`] (the raw probed value chatters with the penalty contact and stays
//! in `probe.csv`), Y the ROI maximum principal stress [Pa], S the full Cauchy tensors. Both
//! `palpa campaign` and `palpa campaign merge` assemble through here, so the two write the same
//! bytes.

use crate::plan::{CampaignPlan, Split};
use crate::run_files::read_run;
use ndarray::{Array1, Array2, Array3};
use serde_json::json;
use solver::output::atomic::write_atomic;
use std::path::{Path, PathBuf};
use surrogate::{Dataset, Manifest};

/// The rows of one run's samples.
struct Rows {
    xs: Vec<[f64; 5]>,
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
        let start = rows.xs.len();
        append_run(
            &mut rows,
            &dir_of(label),
            &roi_ids,
            li,
            loc.split,
            loc.surface_m,
        )?;
        run_rows.push(json!({
            "label": label,
            "location": run.location,
            "split": loc.split.name(),
            "depth_m": run.depth_m,
            "duration_s": run.duration_s,
            "rows": [start, rows.xs.len()],
        }));
    }
    let n = rows.xs.len();
    Ok(Dataset {
        x: Array2::from_shape_vec((n, 5), rows.xs.concat()).map_err(|e| e.to_string())?,
        y: Array2::from_shape_vec((n, r), rows.ys).map_err(|e| e.to_string())?,
        stress: Some(Array3::from_shape_vec((n, r, 6), rows.ss).map_err(|e| e.to_string())?),
        roi_ids: Array1::from(roi_ids),
        roi_centroids,
        location: Array1::from(rows.location),
        split: Array1::from(rows.split),
        manifest: manifest(plan, run_rows),
    })
}

/// Append the samples of the run in `dir` (location `li` at skin point `at`).
fn append_run(
    rows: &mut Rows,
    dir: &Path,
    roi_ids: &[i64],
    li: usize,
    split: Split,
    at: [f64; 3],
) -> Result<(), String> {
    let d = read_run(dir)?;
    // the probe's columns in the ROI's order (nearest to the ROI centre first)
    let cols: Vec<usize> = roi_ids
        .iter()
        .map(|&id| d.elements.iter().position(|&e| e as i64 == id))
        .collect::<Option<_>>()
        .filter(|_| d.elements.len() == roi_ids.len())
        .ok_or_else(|| {
            format!(
                "{}: the probe's elements are not the campaign's ROI",
                dir.display()
            )
        })?;
    for k in 0..d.time.len() {
        rows.xs
            .push([at[0], at[1], d.force_filtered[k], d.time[k], d.depth[k]]);
        rows.ys.extend(cols.iter().map(|&c| d.max_principal[k][c]));
        for &c in &cols {
            rows.ss.extend(&d.tensors[k][c]);
        }
        rows.location.push(li as i64);
        rows.split.push(split.code());
    }
    Ok(())
}

/// The dataset's manifest: columns, locations, the solver's settings and runs, the phantom.
fn manifest(plan: &CampaignPlan, run_rows: Vec<serde_json::Value>) -> Manifest {
    let mut manifest = Manifest {
        x_columns: ["x", "y", "force", "time", "depth"]
            .map(String::from)
            .to_vec(),
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
    manifest
}

/// Write `dataset.npz` + `manifest.json`, and the manifest again as `dataset.json`.
pub fn write_dataset(ds: &Dataset, out: &Path) -> Result<(), String> {
    ds.write(out).map_err(|e| e.to_string())?;
    let m = std::fs::read(out.join("manifest.json")).map_err(|e| e.to_string())?;
    write_atomic(&out.join("dataset.json"), &m)
}
