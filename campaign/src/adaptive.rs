//! Adaptive sampling (`palpa campaign ... --adaptive N --batch B`): after the campaign's own
//! runs, add training locations in batches where the current surrogate is least sure, retrain,
//! repeat until N runs have been added.
//!
//! **Acquisition.** The GP ([`surrogate::gp`], trained as `palpa train --model gp` would on the
//! campaign's dataset so far) has a latent variance `v(x, y, f)` shared by all ROI outputs. A
//! candidate location's score is that variance integrated over the forces a press reaches,
//! approximated by the mean over `FORCE_POINTS` forces evenly spaced from 1/FORCE_POINTS of the
//! largest training force up to it (the integrated-variance criterion of Sacks, Welch, Mitchell
//! and Wynn 1989, "Design and analysis of computer experiments", restricted to the force axis).
//! Candidates are the first `CANDIDATES` points of a fixed Sobol sequence in the design's
//! region (the first training `[[locations.design]]`'s, else the ROI's plan extent).
//!
//! **Batches.** A batch takes the best candidate, then multiplies every other score by the
//! penalty `1 - exp(-1/2 sum_d ((c_d - p_d) / l_d)^2)` over x and y (l: the GP's length scales
//! in physical units), so the next pick keeps a length scale away (local penalisation,
//! González, Dai, Hennig and Lawrence 2016, "Batch Bayesian optimization via local
//! penalization", AISTATS). A candidate that is not over the skin is passed over.
//!
//! **No location twice.** The solver is deterministic: a run at a location already run gives
//! the same samples again and teaches the GP nothing. The GP's latent variance there is not
//! zero, though (it models the data as noisy), and once the region is covered it can exceed
//! the variance of every untried candidate: the fixed candidate set then offered the same
//! points batch after batch. On the voxel-skin 3 mm campaign 36 of 90 adaptive runs repeated
//! a location; batches 6 to 9 repeated 30 of 40. So a candidate within [`MIN_SEPARATION`] of a
//! training location the dataset already has is passed over too.
//!
//! **Record.** Each batch is appended to `DIR/adaptive.json` (its locations, scores and the
//! model it was chosen by) before its runs start, and its locations join the campaign's plan
//! (`campaign.json`) as training locations labelled `ad<batch>-<k>`, so a stopped campaign
//! resumes with `--resume` like any other.

use crate::json_file::{read_json, write_json};
use crate::plan::{Campaign, CampaignLocation, PlannedRun, Split};
use scene::palpation::Place;
use serde::{Deserialize, Serialize};
use std::path::Path;
use surrogate::model::PredictorImpl;
use surrogate::{Dataset, ModelKind, TrainOptions};

/// File of a campaign directory that records the adaptive batches.
pub const ADAPTIVE_FILE: &str = "adaptive.json";
/// Candidate locations scored per batch.
pub const CANDIDATES: usize = 1024;
/// Seed of the candidates' Sobol sequence (independent of any design's).
pub const CANDIDATE_SEED: u32 = 0xADA9;
/// Forces the variance is averaged over.
pub const FORCE_POINTS: usize = 8;
/// A candidate closer than this to a training location already run is passed over (m; module
/// doc): a third of the 3 mm mesh's element, and under half the candidates' mean spacing.
pub const MIN_SEPARATION: f64 = 1e-3;

/// One chosen location of a batch.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AdaptivePoint {
    /// Label (`ad<batch>-<k>`).
    pub label: String,
    /// (x, y) of the body surface (m).
    pub at: [f64; 2],
    /// Its score: the force-averaged latent variance (Pa^2) before the batch's penalties.
    pub variance: f64,
}

/// One batch: where it pressed and what chose it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AdaptiveBatch {
    /// 1-based batch number.
    pub batch: usize,
    /// Training locations of the model that chose it.
    pub trained_on_locations: usize,
    /// That model's held-out Fit (paper eq. 5) on the campaign's test locations, if any.
    pub test_fit: Option<f64>,
    /// Its 95 % interval coverage on them.
    pub test_coverage_95: Option<f64>,
    /// The largest candidate score (Pa^2).
    pub max_variance: f64,
    /// The chosen locations.
    pub points: Vec<AdaptivePoint>,
}

/// `adaptive.json`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct AdaptiveRecord {
    /// The batches in order.
    pub batches: Vec<AdaptiveBatch>,
}

impl AdaptiveRecord {
    /// The record in `dir` (empty when there is none).
    pub fn read(dir: &Path) -> Result<AdaptiveRecord, String> {
        let path = dir.join(ADAPTIVE_FILE);
        if !path.exists() {
            return Ok(AdaptiveRecord::default());
        }
        serde_json::from_value(read_json(&path)?).map_err(|e| format!("{}: {e}", path.display()))
    }

    /// Write it to `dir`, atomically.
    pub fn write(&self, dir: &Path) -> Result<(), String> {
        let v = serde_json::to_value(self).map_err(|e| e.to_string())?;
        write_json(&dir.join(ADAPTIVE_FILE), &v)
    }

    /// Locations added so far.
    pub fn n_points(&self) -> usize {
        self.batches.iter().map(|b| b.points.len()).sum()
    }
}

/// Checks that a campaign can grow adaptively by `n` runs: one depth and one duration per
/// location (the added runs repeat the first run's), and at most [`crate::MAX_RUNS`] runs in
/// all.
pub fn check_adaptive(c: &Campaign, n: usize) -> Result<(), String> {
    if c.runs.len().saturating_add(n) > crate::MAX_RUNS {
        return Err(format!(
            "--adaptive {n}: the campaign would have {} runs, more than the limit of {}",
            c.runs.len().saturating_add(n),
            crate::MAX_RUNS
        ));
    }
    let per_location = c.runs.iter().filter(|r| r.location == 0).count();
    if per_location != 1 {
        return Err(format!(
            "--adaptive chooses locations: give the campaign one depth and one duration or speed (it has {per_location} runs a location)"
        ));
    }
    if !c.locations.iter().any(|l| l.split == Split::Train) {
        return Err("--adaptive needs training locations to start from".into());
    }
    if c.is_respiratory() {
        return Err(
            "--adaptive chooses (x, y) locations at one phase; this campaign presses at several respiratory phases (locations.phases or a design's phase range)"
                .into(),
        );
    }
    Ok(())
}

/// Add `batches`' locations to the campaign as training locations, each pressed as its first
/// run is. An error names a recorded label that could not name a directory or that the
/// campaign already has.
pub fn extend(c: &mut Campaign, batches: &[AdaptiveBatch]) -> Result<(), String> {
    let Some(first) = c.runs.first().cloned() else {
        return Ok(());
    };
    for p in batches.iter().flat_map(|b| &b.points) {
        crate::label::check_label(&p.label).map_err(|e| format!("{ADAPTIVE_FILE}: {e}"))?;
        if c.runs.iter().any(|r| r.label == p.label) {
            return Err(format!(
                "{ADAPTIVE_FILE}: `{}` is already a run of the campaign",
                p.label
            ));
        }
        c.locations.push(CampaignLocation {
            label: p.label.clone(),
            split: Split::Train,
            place: Place::At(p.at[0], p.at[1]),
            phase: None,
        });
        c.runs.push(PlannedRun {
            index: c.runs.len(),
            label: p.label.clone(),
            location: c.locations.len() - 1,
            depth: first.depth,
            duration: first.duration,
        });
    }
    Ok(())
}

/// The label of point `k` (from 1) of adaptive batch `batch`: `ad<batch>-<k>`, two digits each.
pub fn batch_label(batch: usize, k: usize) -> String {
    format!("ad{batch:02}-{k:02}")
}

/// Whether `label` has the form of an adaptive batch's label (`ad01-01`, `ad100-01`): a run a
/// later batch of an adaptive campaign may name.
pub fn is_batch_label(label: &str) -> bool {
    let digits = |s: &str| s.len() >= 2 && s.bytes().all(|c| c.is_ascii_digit());
    label
        .strip_prefix("ad")
        .and_then(|r| r.split_once('-'))
        .is_some_and(|(b, k)| digits(b) && digits(k))
}

/// Choose batch number `batch` of `size` locations from `candidates` (m) on the campaign's
/// dataset so far (see the module doc). `over_skin` says whether the phantom has skin at a
/// point.
pub fn next_batch(
    data: &Dataset,
    candidates: &[[f64; 2]],
    batch: usize,
    size: usize,
    over_skin: &dyn Fn(f64, f64) -> bool,
) -> Result<AdaptiveBatch, String> {
    let (model, report) = surrogate::train_model(data, ModelKind::Gp, &TrainOptions::default())
        .map_err(|e| format!("adaptive batch {batch}: training the GP: {e}"))?;
    let PredictorImpl::Gp(mut gp) = model.to_predictor() else {
        return Err("adaptive sampling needs a GP".into());
    };
    let fmax = data
        .rows_with_split(Split::Train)
        .iter()
        .map(|&i| data.x[(i, 2)])
        .fold(0.0f64, f64::max);
    let forces: Vec<f64> = (1..=FORCE_POINTS)
        .map(|k| fmax * k as f64 / FORCE_POINTS as f64)
        .collect();
    let trained: Vec<[f64; 2]> = data
        .rows_with_split(Split::Train)
        .iter()
        .map(|&i| [data.x[(i, 0)], data.x[(i, 1)]])
        .collect();
    let run_before = |c: [f64; 2]| {
        trained
            .iter()
            .any(|t| (t[0] - c[0]).hypot(t[1] - c[1]) < MIN_SEPARATION)
    };
    let mut score: Vec<f64> = candidates
        .iter()
        .map(|c| {
            forces
                .iter()
                .map(|&f| gp.predict_with_variance(&[c[0], c[1], f]).1)
                .sum::<f64>()
                / FORCE_POINTS as f64
        })
        .collect();
    let max_variance = score.iter().copied().fold(0.0, f64::max);
    let unpenalised = score.clone();
    let scales = gp.physical_length_scales();
    let mut points = Vec::new();
    let mut taken = vec![false; candidates.len()];
    while points.len() < size {
        let best = (0..candidates.len())
            .filter(|&j| !taken[j])
            .max_by(|&a, &b| score[a].total_cmp(&score[b]));
        let Some(j) = best else {
            break;
        };
        taken[j] = true;
        let c = candidates[j];
        if !over_skin(c[0], c[1]) || run_before(c) {
            continue;
        }
        points.push(AdaptivePoint {
            label: batch_label(batch, points.len() + 1),
            at: c,
            variance: unpenalised[j],
        });
        for (k, s) in score.iter_mut().enumerate() {
            let d2: f64 = (0..2)
                .map(|d| ((candidates[k][d] - c[d]) / scales[d]).powi(2))
                .sum();
            *s *= 1.0 - (-0.5 * d2).exp();
        }
    }
    if points.len() < size {
        return Err(format!(
            "adaptive batch {batch}: only {} of {} candidates lie over the skin and away from the locations already run, fewer than the batch of {size}",
            points.len(),
            candidates.len()
        ));
    }
    Ok(AdaptiveBatch {
        batch,
        trained_on_locations: report.n_train_locations,
        test_fit: report.test_fit,
        test_coverage_95: report.test_coverage_95,
        max_variance,
        points,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::Axis;

    /// The synthetic dataset (a 5 x 5 raster over 5..95 mm) without its training locations in
    /// the quadrant x, y > 55 mm: the first pick lies in that quadrant, and a batch's picks
    /// are distinct and labelled in order.
    #[test]
    fn picks_where_the_model_has_no_data() {
        let full = surrogate::synthetic::make_synthetic_dataset(12);
        let rows: Vec<usize> = (0..full.n_samples())
            .filter(|&i| full.split[i] == 1 || !(full.x[(i, 0)] > 0.055 && full.x[(i, 1)] > 0.055))
            .collect();
        let mut data = full.clone();
        data.x = full.x.select(Axis(0), &rows);
        data.y = full.y.select(Axis(0), &rows);
        data.stress = full.stress.as_ref().map(|s| s.select(Axis(0), &rows));
        data.location = full.location.select(Axis(0), &rows);
        data.split = full.split.select(Axis(0), &rows);
        let cands: Vec<[f64; 2]> = (0..19)
            .flat_map(|i| {
                (0..19).map(move |j| [0.005 * i as f64 + 0.005, 0.005 * j as f64 + 0.005])
            })
            .collect();
        let b = next_batch(&data, &cands, 1, 3, &|_, _| true).unwrap();
        let p = b.points[0].at;
        assert!(p[0] > 0.055 && p[1] > 0.055, "first pick {p:?}");
        for (i, a) in b.points.iter().enumerate() {
            for c in &b.points[i + 1..] {
                assert_ne!(a.at, c.at);
            }
        }
        assert_eq!(b.points[2].label, "ad01-03");
        assert!(is_batch_label("ad01-03") && is_batch_label(&batch_label(100, 2)));
        assert!(!is_batch_label("ad1-03") && !is_batch_label("S001") && !is_batch_label("ad01-"));
        assert_eq!(b.trained_on_locations, 21);
        // a candidate that is not over the skin is passed over
        let b2 = next_batch(&data, &cands, 2, 1, &|x, y| !(x > 0.055 && y > 0.055)).unwrap();
        assert!(!(b2.points[0].at[0] > 0.055 && b2.points[0].at[1] > 0.055));
        // a location already run is never offered again, whatever its variance
        let trained: Vec<[f64; 2]> = data
            .rows_with_split(Split::Train)
            .iter()
            .map(|&i| [data.x[(i, 0)], data.x[(i, 1)] + 0.4 * MIN_SEPARATION])
            .collect();
        let err = next_batch(&data, &trained, 3, 1, &|_, _| true).unwrap_err();
        assert!(err.contains("only 0 of"), "{err}");
        let mut with_new = trained.clone();
        with_new.push([0.08, 0.08]);
        let b3 = next_batch(&data, &with_new, 3, 1, &|_, _| true).unwrap();
        assert_eq!(b3.points[0].at, [0.08, 0.08]);
    }
}
