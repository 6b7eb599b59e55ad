//! What one setting of the paper-resolution study ([`crate::study_paper`]) is and what its run
//! left behind ([`RunRecord`]), and its errors against the reference ([`Comparison`]).
//!
//! Fit is the paper's eq. 5 (`docs/paper.md`): `Fit = 1 - sqrt(sum (y - yhat)^2 / sum (y -
//! ybar)^2)` with y the reference's values and yhat the setting's.

use crate::study::{nearest, RunData};
use ndarray::ArrayView2;
use scene::palpation::PalpationSetup;
use scene::run::RunSummary;
use serde::{Deserialize, Serialize};
use solver::output::atomic::write_atomic;
use solver::output::filter::{moving_average, moving_average_at, FORCE_FILTER};
use std::path::Path;

/// One setting: a knob, its value and the palpation it runs.
#[derive(Clone, Debug)]
pub struct StudySetting {
    /// The knob changed from the base (`reference` and `base` for those two rows).
    pub knob: String,
    /// Its value, e.g. `voxel 2.5 mm`.
    pub setting: String,
    /// The palpation.
    pub setup: PalpationSetup,
}

impl StudySetting {
    /// A setting.
    pub fn new(knob: &str, setting: &str, setup: PalpationSetup) -> StudySetting {
        StudySetting {
            knob: knob.into(),
            setting: setting.into(),
            setup,
        }
    }

    /// A file-name form of knob and setting.
    pub fn slug(&self) -> String {
        let s: String = format!("{}-{}", self.knob, self.setting)
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
            .collect();
        s.split('_')
            .filter(|p| !p.is_empty())
            .collect::<Vec<_>>()
            .join("_")
    }
}

/// The record format: a record of another one (or none, written before the field existed) is
/// stale and runs again. 2: ROI centroids paired with the probe's element order.
pub const FORMAT: u32 = 2;

/// What one run of the study left: its scene, its cost and the data its errors need.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RunRecord {
    /// Record format ([`FORMAT`]).
    #[serde(default)]
    pub format: u32,
    /// Location pressed.
    pub location: String,
    /// Knob.
    pub knob: String,
    /// Setting.
    pub setting: String,
    /// How the run ended (`completed` or `failed: ...`).
    pub status: String,
    /// Elements.
    pub elements: usize,
    /// Steps.
    pub steps: u64,
    /// Wall time of the time loop and output (s).
    pub wall_seconds: f64,
    /// Element-cycles per second.
    pub element_cycles_per_second: f64,
    /// Worker threads.
    pub threads: usize,
    /// Mass added by mass scaling, percent of the physical mass.
    pub added_mass_percent: f64,
    /// Largest energy imbalance over the largest energy.
    pub max_energy_error: f64,
    /// ROI sample times after the start (s).
    pub sample_times: Vec<f64>,
    /// Hand force, 1 ms centred average, at each sample time (N).
    pub force_at_samples: Vec<f64>,
    /// Largest 1 ms averaged hand force (N).
    pub peak_force: f64,
    /// ROI element ids, in the probe's order (sorted).
    #[serde(default)]
    pub roi_elements: Vec<u32>,
    /// ROI element centroids (m), same order.
    pub roi_centroids: Vec<[f64; 3]>,
    /// ROI maximum principal stress (Pa), one row per sample time.
    pub roi_stress: Vec<Vec<f64>>,
    /// The scene that ran (`palpa run` repeats it).
    pub scene: String,
}

impl RunRecord {
    /// A record of a run's summary, without its samples yet.
    pub fn from_summary(
        location: &str,
        va: &StudySetting,
        scene: String,
        s: &RunSummary,
    ) -> RunRecord {
        RunRecord {
            format: FORMAT,
            location: location.into(),
            knob: va.knob.clone(),
            setting: va.setting.clone(),
            status: s.status.to_string(),
            elements: s.elements,
            steps: s.steps,
            wall_seconds: s.wall_seconds,
            element_cycles_per_second: s.element_cycles_per_second,
            threads: s.threads,
            added_mass_percent: s.added_mass_percent(),
            max_energy_error: s.max_energy_error,
            sample_times: Vec::new(),
            force_at_samples: Vec::new(),
            peak_force: f64::NAN,
            roi_elements: Vec::new(),
            roi_centroids: Vec::new(),
            roi_stress: Vec::new(),
            scene,
        }
    }

    /// Whether the run completed.
    pub fn completed(&self) -> bool {
        self.status == "completed"
    }

    /// Write the record (atomically: a record is never half-written).
    pub fn write(&self, path: &Path) -> Result<(), String> {
        if let Some(d) = path.parent() {
            std::fs::create_dir_all(d).map_err(|e| format!("{}: {e}", d.display()))?;
        }
        let text = serde_json::to_string(self).map_err(|e| format!("{}: {e}", path.display()))?;
        write_atomic(path, text.as_bytes())
    }

    /// The record at `path`, `None` if there is none.
    pub fn read(path: &Path) -> Result<Option<RunRecord>, String> {
        let text = match std::fs::read_to_string(path) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(format!("{}: {e}", path.display())),
        };
        serde_json::from_str(&text)
            .map(Some)
            .map_err(|e| format!("{}: not a study record: {e}", path.display()))
    }

    /// Whether the record is of this format and ran `scene` (else the plan or the format
    /// changed: run it again).
    pub fn is_current(&self, scene: &str) -> bool {
        self.format == FORMAT && self.scene == scene
    }

    /// Take a completed run's samples: the ROI samples after the start, the 1 ms averaged hand
    /// force at their times (at the end, half a window before it) and its peak (over the
    /// times whose window lies inside the run), the ROI's elements and centroids.
    pub(crate) fn take_samples(&mut self, d: &RunData) {
        let p = &d.probe;
        let keep: Vec<usize> = (0..p.time.len()).filter(|&k| p.time[k] > 0.0).collect();
        self.sample_times = keep.iter().map(|&k| p.time[k]).collect();
        let end = d.time.last().copied().unwrap_or(0.0);
        let half = 0.5 * FORCE_FILTER;
        let at: Vec<f64> = self
            .sample_times
            .iter()
            .map(|&t| t.min(end - half))
            .collect();
        self.force_at_samples = moving_average_at(&d.time, &d.force, FORCE_FILTER, &at);
        let peak = moving_average(&d.time, &d.force, FORCE_FILTER)
            .into_iter()
            .zip(&d.time)
            .filter(|(_, &t)| t >= half && t <= end - half)
            .map(|(f, _)| f);
        self.peak_force = fold_nan(peak, f64::NEG_INFINITY, f64::max);
        self.roi_elements = p.elements.clone();
        self.roi_centroids = d.centroids.clone();
        self.roi_stress = keep.iter().map(|&k| p.stress[k].clone()).collect();
    }

    /// Whether each sample's force error counts ([`Comparison::force_counted`]): the force there
    /// is at least [`FORCE_COUNTED`] of the peak.
    pub fn counted_samples(&self) -> Vec<bool> {
        self.force_at_samples
            .iter()
            .map(|&f| f >= FORCE_COUNTED * self.peak_force)
            .collect()
    }

    /// Why the record's samples cannot be compared (inconsistent shapes), if they cannot.
    pub fn shape_error(&self) -> Option<String> {
        let r = self.roi_centroids.len();
        if r == 0 || self.roi_elements.len() != r {
            return Some(format!(
                "{} ROI elements with {} centroids",
                self.roi_elements.len(),
                r
            ));
        }
        if self.roi_stress.len() != self.sample_times.len()
            || self.force_at_samples.len() != self.sample_times.len()
        {
            return Some(format!(
                "{} sample times, {} force samples, {} stress rows",
                self.sample_times.len(),
                self.force_at_samples.len(),
                self.roi_stress.len()
            ));
        }
        self.roi_stress
            .iter()
            .any(|row| row.len() != r)
            .then(|| format!("a stress row without {r} values"))
    }
}

/// Fold that keeps a NaN (unlike `f64::max` and `f64::min` alone).
pub fn fold_nan(xs: impl Iterator<Item = f64>, start: f64, pick: fn(f64, f64) -> f64) -> f64 {
    xs.fold(start, |m, x| {
        if m.is_nan() || x.is_nan() {
            f64::NAN
        } else {
            pick(m, x)
        }
    })
}

/// Paper eq. 5: the Fit of `yhat` to the reference values `y` ([`surrogate::compute_fit`]:
/// NaN when the lengths differ, the set is empty or `y` is constant).
pub fn fit(y: &[f64], yhat: &[f64]) -> f64 {
    match (
        ArrayView2::from_shape((1, y.len()), y),
        ArrayView2::from_shape((1, yhat.len()), yhat),
    ) {
        (Ok(a), Ok(b)) => surrogate::compute_fit(a, b),
        _ => f64::NAN,
    }
}

/// The share of the reference's peak hand force below which a sample's force error is shown
/// but not counted in the worst one.
pub const FORCE_COUNTED: f64 = 0.2;

/// A setting's errors against the reference at the same location.
#[derive(Clone, Debug)]
pub struct Comparison {
    /// Signed relative hand force error at each sample time.
    pub force_errors: Vec<f64>,
    /// Whether each sample's force error counts towards the worst one: the reference's force
    /// there is at least [`FORCE_COUNTED`] of its peak (at 5 ms it is about 1 N of 50, and a
    /// relative error of a force that small says little about the run).
    pub force_counted: Vec<bool>,
    /// ROI stress Fit at each sample time.
    pub fits: Vec<f64>,
    /// ROI stress Fit pooled over the samples.
    pub pooled_fit: f64,
    /// Fit of the recovered ROI stress ([`RECOVERY_WIDTH`]) at each sample time.
    pub recovered_fits: Vec<f64>,
    /// Fit of the recovered ROI stress pooled over the samples.
    pub pooled_recovered_fit: f64,
    /// Reference ROI elements compared (those inside the run's ROI patch).
    pub compared_elements: usize,
    /// Signed relative error of the peak (1 ms averaged) hand force.
    pub peak_force_error: f64,
    /// Signed relative error of the largest maximum principal stress over the compared ROI
    /// elements.
    pub peak_stress_error: f64,
}

impl Comparison {
    /// The largest |force error| over the samples that count ([`Comparison::force_counted`]).
    pub fn worst_force_error(&self) -> f64 {
        self.force_errors
            .iter()
            .zip(&self.force_counted)
            .filter(|(_, &c)| c)
            .fold(
                0.0,
                |m: f64, (e, _)| {
                    if e.is_nan() {
                        f64::NAN
                    } else {
                        m.max(e.abs())
                    }
                },
            )
    }

    /// The smallest per-sample Fit.
    pub fn worst_fit(&self) -> f64 {
        self.fits.iter().copied().fold(f64::INFINITY, f64::min)
    }

    /// The smallest per-sample Fit of the recovered stress.
    pub fn worst_recovered_fit(&self) -> f64 {
        self.recovered_fits
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min)
    }
}

/// Width H of the recovered stress (m): the Gaussian average `sum_j w_j s_j / sum_j w_j`, `w_j =
/// exp(-|x - x_j|^2 / H^2)` over the ROI elements j, the surrogate's `--recover` target
/// (`surrogate::recovery`, whose weights are those of a field on its own centroids; here one
/// mesh's field is read at another's centroids), with which 2.5 and 3 mm meshes agree to Fit 0.82-0.87 where the
/// element stresses agree to 0.63-0.69 (docs/campaigns.md).
pub const RECOVERY_WIDTH: f64 = 5e-3;

/// The Gaussian average of one sample's ROI stresses `s` (at `xs`) at `c`.
fn recovered(xs: &[[f64; 3]], s: &[f64], c: &[f64; 3]) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    for (x, v) in xs.iter().zip(s) {
        let d2 = (0..3).map(|k| (x[k] - c[k]).powi(2)).sum::<f64>();
        let w = (-d2 / (RECOVERY_WIDTH * RECOVERY_WIDTH)).exp();
        num += w * v;
        den += w;
    }
    num / den.max(1e-300)
}

/// The reference ROI elements inside the run's ROI patch: those whose nearest run ROI
/// centroid lies within the run's own spacing (the median distance from a run ROI element to
/// its nearest neighbour, about a voxel). A finer mesh's 377 ROI elements cover less of the
/// liver's surface, and a reference element beyond them has no counterpart.
fn covered(run: &RunRecord, reference: &RunRecord) -> Vec<usize> {
    let xs = &run.roi_centroids;
    let dist = |a: &[f64; 3], b: &[f64; 3]| (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>();
    let mut nn: Vec<f64> = (0..xs.len())
        .map(|i| {
            let d2 = (0..xs.len())
                .filter(|&j| j != i)
                .map(|j| dist(&xs[i], &xs[j]))
                .fold(f64::INFINITY, f64::min);
            d2.sqrt()
        })
        .collect();
    nn.sort_by(f64::total_cmp);
    let spacing = nn.get(nn.len() / 2).copied().unwrap_or(0.0);
    (0..reference.roi_centroids.len())
        .filter(|&i| nearest(xs, &reference.roi_centroids[i]).1 <= spacing * (1.0 + 1e-9))
        .collect()
}

/// Compare `run` with `reference` (both completed at the same location); an error says why
/// they cannot be compared (shapes, sample times).
pub fn compare(run: &RunRecord, reference: &RunRecord) -> Result<Comparison, String> {
    for (who, r) in [("run", run), ("reference", reference)] {
        if let Some(e) = r.shape_error() {
            return Err(format!("the {who}'s record: {e}"));
        }
    }
    let same_times = run.sample_times.len() == reference.sample_times.len()
        && run
            .sample_times
            .iter()
            .zip(&reference.sample_times)
            .all(|(a, b)| (a - b).abs() < 1e-4);
    if !same_times {
        return Err("its sample times are not the reference's".into());
    }
    let rel = |a: f64, b: f64| (a - b) / b;
    let inside = covered(run, reference);
    if inside.is_empty() {
        return Err("its ROI covers none of the reference's".into());
    }
    // Each covered reference ROI element's nearest ROI element of the run (the same one on
    // one mesh).
    let map: Vec<usize> = inside
        .iter()
        .map(|&i| nearest(&run.roi_centroids, &reference.roi_centroids[i]).0)
        .collect();
    let n = run.roi_stress.len();
    let at = |row: &[f64], idx: &[usize]| -> Vec<f64> { idx.iter().map(|&m| row[m]).collect() };
    let ref_raw: Vec<Vec<f64>> = (0..n)
        .map(|k| at(&reference.roi_stress[k], &inside))
        .collect();
    let run_raw: Vec<Vec<f64>> = (0..n).map(|k| at(&run.roi_stress[k], &map)).collect();
    let rec = |r: &RunRecord, k: usize| -> Vec<f64> {
        inside
            .iter()
            .map(|&i| {
                recovered(
                    &r.roi_centroids,
                    &r.roi_stress[k],
                    &reference.roi_centroids[i],
                )
            })
            .collect()
    };
    let ref_rec: Vec<Vec<f64>> = (0..n).map(|k| rec(reference, k)).collect();
    let run_rec: Vec<Vec<f64>> = (0..n).map(|k| rec(run, k)).collect();
    let fits = (0..n).map(|k| fit(&ref_raw[k], &run_raw[k])).collect();
    let recovered_fits = (0..n).map(|k| fit(&ref_rec[k], &run_rec[k])).collect();
    let flat = |s: &[Vec<f64>]| s.iter().flatten().copied().collect::<Vec<f64>>();
    let peak = |s: &[Vec<f64>]| {
        s.iter()
            .flatten()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max)
    };
    Ok(Comparison {
        force_errors: run
            .force_at_samples
            .iter()
            .zip(&reference.force_at_samples)
            .map(|(&a, &b)| rel(a, b))
            .collect(),
        force_counted: reference.counted_samples(),
        fits,
        pooled_fit: fit(&flat(&ref_raw), &flat(&run_raw)),
        recovered_fits,
        pooled_recovered_fit: fit(&flat(&ref_rec), &flat(&run_rec)),
        compared_elements: inside.len(),
        peak_force_error: rel(run.peak_force, reference.peak_force),
        peak_stress_error: rel(peak(&run_raw), peak(&ref_raw)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(force: Vec<f64>, centroids: Vec<[f64; 3]>, stress: Vec<Vec<f64>>) -> RunRecord {
        RunRecord {
            format: FORMAT,
            location: "A".into(),
            knob: "k".into(),
            setting: "s".into(),
            status: "completed".into(),
            elements: 1,
            steps: 1,
            wall_seconds: 1.0,
            element_cycles_per_second: 1.0,
            threads: 1,
            added_mass_percent: 0.0,
            max_energy_error: 0.0,
            sample_times: (0..force.len()).map(|k| 0.01 * (k + 1) as f64).collect(),
            peak_force: force.iter().copied().fold(0.0, f64::max),
            force_at_samples: force,
            roi_elements: (0..centroids.len() as u32).collect(),
            roi_centroids: centroids,
            roi_stress: stress,
            scene: String::new(),
        }
    }

    #[test]
    fn itself_is_exact_and_a_shifted_field_loses_what_eq5_says() {
        let c = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
        let s = vec![vec![1.0, 2.0, 3.0], vec![2.0, 4.0, 6.0]];
        let r = record(vec![10.0, 20.0], c.clone(), s.clone());
        let same = compare(&r, &r).unwrap();
        assert_eq!(same.pooled_fit, 1.0);
        assert_eq!(same.worst_force_error(), 0.0);
        // +1 on every element at the first sample: sse = 3, sst = 2, Fit = 1 - sqrt(3/2).
        let shifted = record(
            vec![11.0, 18.0],
            c,
            vec![vec![2.0, 3.0, 4.0], vec![2.0, 4.0, 6.0]],
        );
        let d = compare(&shifted, &r).unwrap();
        assert!((d.fits[0] - (1.0 - 1.5f64.sqrt())).abs() < 1e-12);
        assert_eq!(d.fits[1], 1.0);
        assert!((d.force_errors[0] - 0.1).abs() < 1e-12);
        assert!((d.force_errors[1] + 0.1).abs() < 1e-12);
        assert!((d.worst_force_error() - 0.1).abs() < 1e-12);
        assert!((d.peak_force_error + 0.1).abs() < 1e-12);
        assert_eq!(d.peak_stress_error, 0.0);
    }

    #[test]
    fn another_mesh_is_read_at_the_nearest_centroid() {
        let r = record(
            vec![1.0],
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]],
            vec![vec![1.0, 3.0]],
        );
        // A finer run: four elements, two of them nearest to the reference's two.
        let fine = record(
            vec![1.0],
            vec![
                [-0.1, 0.0, 0.0],
                [0.45, 0.0, 0.0],
                [0.55, 0.0, 0.0],
                [1.1, 0.0, 0.0],
            ],
            vec![vec![1.0, 7.0, 7.0, 3.0]],
        );
        let d = compare(&fine, &r).unwrap();
        assert_eq!(d.compared_elements, 2);
        assert_eq!(d.fits[0], 1.0);
        // peaks over the compared elements: the finer mesh's 7s lie between them
        assert_eq!(d.peak_stress_error, 0.0);
    }

    #[test]
    fn a_smaller_patch_compares_what_it_covers() {
        let r = record(
            vec![1.0],
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]],
            vec![vec![1.0, 3.0]],
        );
        let small = record(
            vec![1.0],
            vec![[-0.1, 0.0, 0.0], [0.1, 0.0, 0.0]],
            vec![vec![1.0, 1.0]],
        );
        assert_eq!(compare(&small, &r).unwrap().compared_elements, 1);
    }

    #[test]
    fn the_recovered_stress_is_the_gaussian_average() {
        let h = RECOVERY_WIDTH;
        let xs = [[0.0, 0.0, 0.0], [h, 0.0, 0.0]];
        // at x = 0: weights 1 and e^-1
        let w = (-1.0f64).exp();
        let v = recovered(&xs, &[1.0, 3.0], &[0.0, 0.0, 0.0]);
        assert!((v - (1.0 + 3.0 * w) / (1.0 + w)).abs() < 1e-12);
    }

    #[test]
    fn what_cannot_be_compared_says_why() {
        let c = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]];
        let r = record(
            vec![1.0, 2.0],
            c.clone(),
            vec![vec![1.0, 2.0], vec![2.0, 4.0]],
        );
        let mut late = r.clone();
        late.sample_times[1] += 1e-3;
        assert!(compare(&late, &r).unwrap_err().contains("sample times"));
        let mut short = r.clone();
        short.roi_stress[1].pop();
        assert!(compare(&short, &r).unwrap_err().contains("stress row"));
        let far = record(
            vec![1.0, 2.0],
            vec![[5.0, 0.0, 0.0], [6.0, 0.0, 0.0]],
            r.roi_stress.clone(),
        );
        assert!(compare(&far, &r).unwrap_err().contains("covers none"));
        // a constant reference field has no Fit
        assert!(fit(&[2.0, 2.0], &[2.0, 2.0]).is_nan());
    }

    #[test]
    fn slugs_are_file_names() {
        let v = StudySetting::new("bulk ratio", "K/G <= 1000", PalpationSetup::default());
        assert_eq!(v.slug(), "bulk_ratio_K_G_1000");
    }
}
