//! The report of the paper-resolution study ([`crate::study_paper`]): each setting's errors
//! against the reference and its cost, per location (`study-3mm.csv`) and over the locations
//! (`study-3mm.md`: the table, the Pareto front and the cheapest setting within each error
//! budget), and the Pareto plots (`pareto_3mm_force.png`, `pareto_3mm_fit.png`).
//!
//! Over the locations a setting's cost is its mean wall time and its error the worst one: the
//! largest |hand force error| over the counted samples ([`Comparison::force_counted`]) and
//! locations, the smallest per-sample Fit. A value that cannot be computed (NaN) stays NaN,
//! prints as `-` and keeps its setting out of the fronts and the budgets, as does a setting
//! not yet measured at every location that has a reference.

use crate::study_paper::{BASE, REFERENCE};
use crate::study_paper_record::{compare, fold_nan, Comparison, RunRecord};
use std::fmt::Write;
use std::path::Path;

/// One setting over the locations that ran it.
#[derive(Clone, Debug)]
pub struct SettingSummary {
    /// Knob.
    pub knob: String,
    /// Setting.
    pub setting: String,
    /// Locations with a completed run compared with a completed reference.
    pub locations: Vec<String>,
    /// Whether those are all the locations with a reference.
    pub complete: bool,
    /// Mean wall time (s).
    pub wall: f64,
    /// Mean element-cycles.
    pub element_cycles: f64,
    /// Largest added mass (percent).
    pub added_mass_percent: f64,
    /// Largest |hand force error| over the counted samples and locations.
    pub worst_force_error: f64,
    /// Smallest per-sample Fit over the locations.
    pub worst_fit: f64,
    /// Smallest pooled Fit over the locations.
    pub pooled_fit: f64,
    /// Smallest per-sample Fit of the recovered stress over the locations.
    pub worst_recovered_fit: f64,
    /// Largest |peak force error|.
    pub peak_force_error: f64,
    /// Largest |peak ROI stress error|.
    pub peak_stress_error: f64,
    /// Locations without a comparison, `location: why`.
    pub missing: Vec<String>,
}

impl SettingSummary {
    /// Whether the setting enters the fronts and the budgets: measured at every location with
    /// a reference, with finite errors.
    pub fn comparable(&self) -> bool {
        self.complete
            && !self.locations.is_empty()
            && self.worst_force_error.is_finite()
            && self.worst_fit.is_finite()
    }
}

/// The `fast` preset's budget ([`scene::palpation::Fidelity::Fast`] is its answer): a force
/// error below the spread between the 4, 3 and 2.5 mm meshes (8-11 %), and a per-sample Fit
/// well above the agreement of the ROI field between 3 and 2.5 mm voxels (0.28-0.67). It was
/// set with the study's records in hand.
pub const FAST_PRESET_BUDGET: (f64, f64) = (0.10, 0.75);

/// The error budgets the report checks: (|hand force error| at most, per-sample Fit at least).
pub const BUDGETS: [(f64, f64); 5] = [
    (0.02, 0.98),
    (0.05, 0.95),
    (0.10, 0.90),
    FAST_PRESET_BUDGET,
    (0.15, 0.80),
];

/// The completed reference at `location`, if any.
fn reference_at<'a>(records: &'a [RunRecord], location: &str) -> Option<&'a RunRecord> {
    records
        .iter()
        .find(|q| q.location == location && q.knob == REFERENCE && q.completed())
}

/// Each record with its comparison against the reference at its location, or why there is
/// none.
pub fn comparisons(records: &[RunRecord]) -> Vec<(&RunRecord, Result<Comparison, String>)> {
    records
        .iter()
        .map(|r| {
            let c = if !r.completed() {
                Err(r.status.clone())
            } else {
                match reference_at(records, &r.location) {
                    Some(q) => compare(r, q),
                    None => Err("awaiting its location's reference".into()),
                }
            };
            (r, c)
        })
        .collect()
}

/// Locations with a completed reference, in record order.
fn referenced_locations(records: &[RunRecord]) -> Vec<String> {
    locations_where(records, true)
}

/// The locations of the records, in record order, whose reference has (`true`) or has not
/// completed.
fn locations_where(records: &[RunRecord], referenced: bool) -> Vec<String> {
    let mut v: Vec<String> = Vec::new();
    for r in records {
        if reference_at(records, &r.location).is_some() == referenced && !v.contains(&r.location) {
            v.push(r.location.clone());
        }
    }
    v
}

/// The settings in plan order, each summarised over its locations.
pub fn summarise(records: &[RunRecord]) -> Vec<SettingSummary> {
    let cmp = comparisons(records);
    let referenced = referenced_locations(records);
    let mut order: Vec<(String, String)> = Vec::new();
    for r in records {
        let key = (r.knob.clone(), r.setting.clone());
        if !order.contains(&key) {
            order.push(key);
        }
    }
    order
        .into_iter()
        .map(|(knob, setting)| {
            let mine: Vec<&(&RunRecord, Result<Comparison, String>)> = cmp
                .iter()
                .filter(|(r, _)| r.knob == knob && r.setting == setting)
                .collect();
            let ok: Vec<(&RunRecord, &Comparison)> = mine
                .iter()
                .filter_map(|(r, c)| c.as_ref().ok().map(|c| (*r, c)))
                .collect();
            let n = ok.len().max(1) as f64;
            let max_abs = |f: &dyn Fn(&Comparison) -> f64| {
                fold_nan(ok.iter().map(|(_, c)| f(c).abs()), 0.0, f64::max)
            };
            let min_of = |f: &dyn Fn(&Comparison) -> f64| {
                let v = fold_nan(ok.iter().map(|(_, c)| f(c)), f64::INFINITY, f64::min);
                if ok.is_empty() {
                    f64::NAN
                } else {
                    v
                }
            };
            let locations: Vec<String> = ok.iter().map(|(r, _)| r.location.clone()).collect();
            SettingSummary {
                complete: referenced.iter().all(|l| locations.contains(l)),
                locations,
                wall: ok.iter().map(|(r, _)| r.wall_seconds).sum::<f64>() / n,
                element_cycles: ok
                    .iter()
                    .map(|(r, _)| r.elements as f64 * r.steps as f64)
                    .sum::<f64>()
                    / n,
                added_mass_percent: fold_nan(
                    ok.iter().map(|(r, _)| r.added_mass_percent),
                    0.0,
                    f64::max,
                ),
                worst_force_error: max_abs(&Comparison::worst_force_error),
                worst_fit: min_of(&Comparison::worst_fit),
                pooled_fit: min_of(&|c| c.pooled_fit),
                worst_recovered_fit: min_of(&Comparison::worst_recovered_fit),
                peak_force_error: max_abs(&|c| c.peak_force_error),
                peak_stress_error: max_abs(&|c| c.peak_stress_error),
                missing: mine
                    .iter()
                    .filter_map(|(r, c)| c.as_ref().err().map(|e| format!("{}: {e}", r.location)))
                    .collect(),
                knob,
                setting,
            }
        })
        .collect()
}

/// The per-location CSV.
pub fn to_csv(records: &[RunRecord]) -> String {
    let times = records
        .iter()
        .map(|r| r.sample_times.len())
        .max()
        .and_then(|n| records.iter().find(|r| r.sample_times.len() == n))
        .map(|r| r.sample_times.clone())
        .unwrap_or_default();
    let mut s = String::from("location,knob,setting,status,elements,steps,element_cycles,wall_s,element_cycles_per_s,threads,added_mass_percent,max_energy_error");
    for t in &times {
        let _ = write!(s, ",force_error_{:.1}ms", t * 1e3);
    }
    for t in &times {
        let _ = write!(s, ",fit_{:.1}ms", t * 1e3);
    }
    for t in &times {
        let _ = write!(s, ",recovered_fit_{:.1}ms", t * 1e3);
    }
    s.push_str(",pooled_fit,pooled_recovered_fit,compared_elements,peak_force_N,peak_force_error,peak_stress_Pa,peak_stress_error\n");
    let num = |x: Option<f64>| {
        x.filter(|v| v.is_finite())
            .map(|v| format!("{v:.6}"))
            .unwrap_or_default()
    };
    for (r, c) in comparisons(records) {
        let _ = write!(
            s,
            "{},{},{},{},{},{},{:.6e},{:.3},{:.6e},{},{:.4},{:.3e}",
            r.location,
            r.knob,
            r.setting.replace(',', ";"),
            r.status.replace(',', ";"),
            r.elements,
            r.steps,
            r.elements as f64 * r.steps as f64,
            r.wall_seconds,
            r.element_cycles_per_second,
            r.threads,
            r.added_mass_percent,
            r.max_energy_error
        );
        for k in 0..times.len() {
            let _ = write!(
                s,
                ",{}",
                num(c.as_ref().ok().and_then(|c| c.force_errors.get(k).copied()))
            );
        }
        for k in 0..times.len() {
            let _ = write!(
                s,
                ",{}",
                num(c.as_ref().ok().and_then(|c| c.fits.get(k).copied()))
            );
        }
        for k in 0..times.len() {
            let _ = write!(
                s,
                ",{}",
                num(c
                    .as_ref()
                    .ok()
                    .and_then(|c| c.recovered_fits.get(k).copied()))
            );
        }
        let peak_stress = r
            .roi_stress
            .iter()
            .flatten()
            .copied()
            .fold(f64::NAN, f64::max);
        let _ = writeln!(
            s,
            ",{},{},{},{:.4},{},{:.1},{}",
            num(c.as_ref().ok().map(|c| c.pooled_fit)),
            num(c.as_ref().ok().map(|c| c.pooled_recovered_fit)),
            c.as_ref()
                .ok()
                .map(|c| c.compared_elements.to_string())
                .unwrap_or_default(),
            r.peak_force,
            num(c.as_ref().ok().map(|c| c.peak_force_error)),
            peak_stress,
            num(c.as_ref().ok().map(|c| c.peak_stress_error))
        );
    }
    s
}

/// Settings no other setting beats in both wall time and error (`err`: smaller is better).
pub fn front<'a>(
    rows: &'a [SettingSummary],
    err: impl Fn(&SettingSummary) -> f64,
) -> Vec<&'a SettingSummary> {
    let ok: Vec<&SettingSummary> = rows
        .iter()
        .filter(|r| r.comparable() && err(r).is_finite())
        .collect();
    let mut f: Vec<&SettingSummary> = ok
        .iter()
        .copied()
        .filter(|a| {
            !ok.iter().any(|b| {
                b.wall <= a.wall && err(b) <= err(a) && (b.wall < a.wall || err(b) < err(a))
            })
        })
        .collect();
    f.sort_by(|a, b| a.wall.total_cmp(&b.wall));
    f
}

/// The cheapest setting but the reference within a budget of |hand force error| and
/// per-sample Fit.
pub fn cheapest_within(rows: &[SettingSummary], force: f64, fit: f64) -> Option<&SettingSummary> {
    rows.iter()
        .filter(|r| {
            r.comparable()
                && r.knob != REFERENCE
                && r.worst_force_error <= force
                && r.worst_fit >= fit
        })
        .min_by(|a, b| a.wall.total_cmp(&b.wall))
}

fn pct(x: f64) -> String {
    if x.is_finite() {
        format!("{:.1} %", 100.0 * x)
    } else {
        "-".into()
    }
}

/// Locations with records but no completed reference.
pub fn pending_references(records: &[RunRecord]) -> Vec<String> {
    locations_where(records, false)
}

/// From when on the force errors count: the earliest and latest first counted sample time
/// over the references (ms), for the report's wording.
fn counted_from(records: &[RunRecord]) -> Option<(f64, f64)> {
    let firsts: Vec<f64> = referenced_locations(records)
        .iter()
        .filter_map(|l| {
            let q = reference_at(records, l)?;
            let k = q.counted_samples().iter().position(|&x| x)?;
            Some(1e3 * q.sample_times.get(k)?)
        })
        .collect();
    (!firsts.is_empty()).then(|| {
        (
            firsts.iter().copied().fold(f64::INFINITY, f64::min),
            firsts.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        )
    })
}

fn fixed3(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.3}")
    } else {
        "-".into()
    }
}

/// The table over the locations.
fn table(rows: &[SettingSummary]) -> String {
    let mut s = String::from(
        "| knob | setting | locations | wall (s, mean) | element-cycles | M el-cyc/s | added mass | hand force error (worst) | peak force error | ROI Fit per sample (worst) | ROI Fit pooled (worst) | recovered Fit per sample (worst) | peak ROI stress error |\n|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for r in rows.iter().filter(|r| !r.locations.is_empty()) {
        let mut locs = r.locations.join(" ");
        if !r.missing.is_empty() {
            let _ = write!(locs, " (not compared: {})", r.missing.join("; "));
        }
        let _ = writeln!(
            s,
            "| {} | {} | {locs} | {:.1} | {:.3e} | {:.2} | {:.2} % | {} | {} | {} | {} | {} | {} |",
            r.knob,
            r.setting,
            r.wall,
            r.element_cycles,
            r.element_cycles / r.wall.max(1e-12) / 1e6,
            r.added_mass_percent,
            pct(r.worst_force_error),
            pct(r.peak_force_error),
            fixed3(r.worst_fit),
            fixed3(r.pooled_fit),
            fixed3(r.worst_recovered_fit),
            pct(r.peak_stress_error),
        );
    }
    s
}

/// The two Pareto fronts and the cheapest setting within each budget.
fn fronts_and_budgets(rows: &[SettingSummary]) -> String {
    let mut s = String::new();
    let force: &dyn Fn(&SettingSummary) -> f64 = &|r| r.worst_force_error;
    let fit: &dyn Fn(&SettingSummary) -> f64 = &|r| 1.0 - r.worst_fit;
    for (what, f) in [("hand force error", force), ("1 - ROI Fit per sample", fit)] {
        let _ = writeln!(s, "\nPareto front, wall time against {what}:");
        for r in front(rows, f) {
            let _ = writeln!(
                s,
                "- {} = {}: {:.1} s, force {}, Fit {}",
                r.knob,
                r.setting,
                r.wall,
                pct(r.worst_force_error),
                fixed3(r.worst_fit)
            );
        }
    }
    s.push_str("\nThe cheapest setting but the reference within each error budget (hand force at every counted sample, ROI Fit at every sample):\n");
    for (force, fit) in BUDGETS {
        let _ = match cheapest_within(rows, force, fit) {
            Some(r) => writeln!(
                s,
                "- force within {:.0} %, Fit >= {fit}: {} = {} ({:.1} s; force {}, Fit {})",
                100.0 * force,
                r.knob,
                r.setting,
                r.wall,
                pct(r.worst_force_error),
                fixed3(r.worst_fit)
            ),
            None => writeln!(
                s,
                "- force within {:.0} %, Fit >= {fit}: none but the reference",
                100.0 * force
            ),
        };
    }
    s
}

/// The per-location table.
fn per_location(records: &[RunRecord]) -> String {
    let mut s = String::from("\nPer location (hand force error and ROI Fit at each sample time; a force error in parentheses does not count):\n\n| location | knob | setting | wall (s) | steps | hand force error | ROI Fit | recovered Fit | energy error |\n|---|---|---|---:|---:|---|---|---|---:|\n");
    let join = |v: &[f64]| v.iter().map(|&f| fixed3(f)).collect::<Vec<_>>().join(" / ");
    for (r, c) in comparisons(records) {
        let (fe, fi, fr) = match &c {
            Ok(c) => (
                c.force_errors
                    .iter()
                    .zip(&c.force_counted)
                    .map(|(e, &counted)| {
                        if counted {
                            format!("{:+.1}", 100.0 * e)
                        } else {
                            format!("({:+.1})", 100.0 * e)
                        }
                    })
                    .collect::<Vec<_>>()
                    .join(" / ")
                    + " %",
                join(&c.fits),
                join(&c.recovered_fits),
            ),
            Err(e) => (e.clone(), "-".into(), "-".into()),
        };
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.1} | {} | {fe} | {fi} | {fr} | {:.1e} |",
            r.location, r.knob, r.setting, r.wall_seconds, r.steps, r.max_energy_error
        );
    }
    s
}

/// The markdown report: the table over the locations, the fronts and the budgets, then the
/// per-location errors.
pub fn to_markdown(records: &[RunRecord]) -> String {
    let rows = summarise(records);
    let mut s = String::new();
    for loc in pending_references(records) {
        let _ = writeln!(
            s,
            "Location {loc}: {} settings recorded, its reference not yet (listed per location below, left out of the table and the fronts).\n",
            records.iter().filter(|r| r.location == loc).count()
        );
    }
    s.push_str(&table(&rows));
    let from = match counted_from(records) {
        Some((a, b)) if (a - b).abs() < 0.05 => format!("from {a:.0} ms on"),
        Some((a, b)) => format!("from {a:.0} to {b:.0} ms on, by location"),
        None => "none yet".into(),
    };
    let _ = writeln!(
        s,
        "\nErrors against the reference at the same location; over the locations the worst one, the wall time the mean. The hand force error counts the samples where the reference's force is at least a fifth of its peak ({from}). Settings not measured at every location with a reference stay out of the fronts and the budgets."
    );
    s.push_str(&fronts_and_budgets(&rows));
    s.push_str(&per_location(records));
    s
}

/// Draw the two Pareto plots (one curve per knob through the base) into `out`.
pub fn plots(records: &[RunRecord], out: &Path) -> Result<Vec<String>, String> {
    let rows = summarise(records);
    let base = rows.iter().find(|r| r.knob == BASE && r.comparable());
    let mut files = Vec::new();
    for (which, label) in [
        ("force", "hand force error (worst)"),
        ("fit", "1 - ROI Fit (worst sample)"),
    ] {
        let err = |r: &SettingSummary| {
            let e = if which == "force" {
                r.worst_force_error
            } else {
                1.0 - r.worst_fit
            };
            e.max(1e-4)
        };
        let mut curves: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
        for r in rows
            .iter()
            .filter(|r| r.comparable() && r.knob != BASE && r.knob != REFERENCE)
        {
            match curves.iter_mut().find(|c| c.0 == r.knob) {
                Some(c) => c.1.push((r.wall, err(r))),
                None => {
                    let mut pts = vec![(r.wall, err(r))];
                    if let Some(b) = base {
                        pts.push((b.wall, err(b)));
                    }
                    curves.push((r.knob.clone(), pts));
                }
            }
        }
        for c in curves.iter_mut() {
            c.1.sort_by(|a, b| a.0.total_cmp(&b.0));
        }
        if curves.is_empty() {
            continue;
        }
        let series = crate::Series {
            plot: format!("pareto_3mm_{which}"),
            title: format!("3 mm study: {label} against wall time, each knob from the base"),
            axes: (
                "wall time (s)".into(),
                format!("{label} against the reference"),
            ),
            log: true,
            curves,
        };
        files.push(crate::plot::draw(&series, out)?);
    }
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(location: &str, knob: &str, force: f64, stress: [f64; 3]) -> RunRecord {
        RunRecord {
            format: crate::study_paper_record::FORMAT,
            location: location.into(),
            knob: knob.into(),
            setting: knob.into(),
            status: "completed".into(),
            elements: 10,
            steps: 10,
            wall_seconds: if knob == REFERENCE { 100.0 } else { 10.0 },
            element_cycles_per_second: 10.0,
            threads: 1,
            added_mass_percent: 0.0,
            max_energy_error: 0.0,
            sample_times: vec![0.01],
            force_at_samples: vec![force],
            peak_force: force,
            roi_elements: vec![0, 1, 2],
            roi_centroids: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]],
            roi_stress: vec![stress.to_vec()],
            scene: String::new(),
        }
    }

    #[test]
    fn a_nan_error_is_no_setting_within_budget() {
        let records = vec![
            record("A", REFERENCE, 10.0, [1.0, 2.0, 3.0]),
            record("A", "good", 10.1, [1.0, 2.0, 3.1]),
            record("A", "nan", f64::NAN, [1.0, 2.0, 3.0]),
        ];
        let rows = summarise(&records);
        let good = &rows[1];
        assert!((good.worst_force_error - 0.01).abs() < 1e-12);
        assert!(good.comparable());
        let nan = &rows[2];
        assert!(nan.worst_force_error.is_nan());
        assert!(!nan.comparable());
        let best = cheapest_within(&rows, 0.02, 0.9).unwrap();
        assert_eq!(best.knob, "good");
        assert!(front(&rows, |r| r.worst_force_error)
            .iter()
            .all(|r| r.knob != "nan"));
        // the reference is never a budget's answer
        assert!(cheapest_within(&rows, 0.001, 0.999).is_none());
    }

    #[test]
    fn a_setting_missing_a_location_stays_out_of_the_fronts() {
        let records = vec![
            record("A", REFERENCE, 10.0, [1.0, 2.0, 3.0]),
            record("B", REFERENCE, 10.0, [1.0, 2.0, 3.0]),
            record("A", "half", 10.0, [1.0, 2.0, 3.0]),
        ];
        let rows = summarise(&records);
        assert!(!rows[1].complete);
        assert!(cheapest_within(&rows, 0.5, 0.0).is_none());
        // and a location without its reference is named
        let md = to_markdown(&[record("C", "early", 1.0, [1.0, 2.0, 3.0])]);
        assert!(md.contains("Location C: 1 settings recorded, its reference not yet"));
    }
}
