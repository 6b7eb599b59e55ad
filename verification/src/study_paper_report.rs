//! The report of the paper-resolution study ([`crate::study_paper`]): each setting's errors
//! against the reference and its cost, per location (`study-3mm.csv`) and over the locations
//! (`study-3mm.md`: the table, the Pareto front and the cheapest setting within each error
//! budget), and the Pareto plots (`pareto_3mm_force.png`, `pareto_3mm_fit.png`).
//!
//! Over the locations a setting's cost is its mean wall time and its error the worst one: the
//! largest |hand force error| over every sample and location, the smallest per-sample Fit.

use crate::study_paper::{BASE, REFERENCE};
use crate::study_paper_record::{compare, Comparison, RunRecord};
use std::fmt::Write;
use std::path::Path;

/// One setting over the locations that ran it.
#[derive(Clone, Debug)]
pub struct SettingSummary {
    /// Knob.
    pub knob: String,
    /// Setting.
    pub setting: String,
    /// Locations with a completed run and a completed reference.
    pub locations: Vec<String>,
    /// Mean wall time (s).
    pub wall: f64,
    /// Mean element-cycles.
    pub element_cycles: f64,
    /// Largest added mass (percent).
    pub added_mass_percent: f64,
    /// Largest |hand force error| over samples and locations.
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
    /// Failures, `location: status`.
    pub failures: Vec<String>,
}

/// The error budgets the report checks: (|hand force error| at most, per-sample Fit at least).
pub const BUDGETS: [(f64, f64); 4] = [(0.02, 0.98), (0.05, 0.95), (0.10, 0.90), (0.15, 0.80)];

/// Each record with its comparison against the reference at its location (`None` when it
/// or its reference did not complete).
pub fn comparisons(records: &[RunRecord]) -> Vec<(&RunRecord, Option<Comparison>)> {
    records
        .iter()
        .map(|r| {
            let reference = records
                .iter()
                .find(|q| q.location == r.location && q.knob == REFERENCE && q.completed());
            let c = match reference {
                Some(q) if r.completed() => Some(compare(r, q)),
                _ => None,
            };
            (r, c)
        })
        .collect()
}

/// The settings in plan order, each summarised over its locations.
pub fn summarise(records: &[RunRecord]) -> Vec<SettingSummary> {
    let cmp = comparisons(records);
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
            let mine: Vec<&(&RunRecord, Option<Comparison>)> = cmp
                .iter()
                .filter(|(r, _)| r.knob == knob && r.setting == setting)
                .collect();
            let ok: Vec<(&RunRecord, &Comparison)> = mine
                .iter()
                .filter_map(|(r, c)| c.as_ref().map(|c| (*r, c)))
                .collect();
            let n = ok.len().max(1) as f64;
            let max_abs = |f: &dyn Fn(&Comparison) -> f64| {
                ok.iter().map(|(_, c)| f(c).abs()).fold(0.0, f64::max)
            };
            let min_of = |f: &dyn Fn(&Comparison) -> f64| {
                ok.iter().map(|(_, c)| f(c)).fold(f64::INFINITY, f64::min)
            };
            SettingSummary {
                locations: ok.iter().map(|(r, _)| r.location.clone()).collect(),
                wall: ok.iter().map(|(r, _)| r.wall_seconds).sum::<f64>() / n,
                element_cycles: ok
                    .iter()
                    .map(|(r, _)| r.elements as f64 * r.steps as f64)
                    .sum::<f64>()
                    / n,
                added_mass_percent: ok
                    .iter()
                    .map(|(r, _)| r.added_mass_percent)
                    .fold(0.0, f64::max),
                worst_force_error: max_abs(&Comparison::worst_force_error),
                worst_fit: min_of(&Comparison::worst_fit),
                pooled_fit: min_of(&|c| c.pooled_fit),
                worst_recovered_fit: min_of(&Comparison::worst_recovered_fit),
                peak_force_error: max_abs(&|c| c.peak_force_error),
                peak_stress_error: max_abs(&|c| c.peak_stress_error),
                failures: mine
                    .iter()
                    .filter(|(r, _)| !r.completed())
                    .map(|(r, _)| format!("{}: {}", r.location, r.status))
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
    let num = |x: Option<f64>| x.map(|v| format!("{v:.6}")).unwrap_or_default();
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
                num(c.as_ref().and_then(|c| c.force_errors.get(k).copied()))
            );
        }
        for k in 0..times.len() {
            let _ = write!(
                s,
                ",{}",
                num(c.as_ref().and_then(|c| c.fits.get(k).copied()))
            );
        }
        for k in 0..times.len() {
            let _ = write!(
                s,
                ",{}",
                num(c.as_ref().and_then(|c| c.recovered_fits.get(k).copied()))
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
            num(c.as_ref().map(|c| c.pooled_fit)),
            num(c.as_ref().map(|c| c.pooled_recovered_fit)),
            c.as_ref()
                .map(|c| c.compared_elements.to_string())
                .unwrap_or_default(),
            r.peak_force,
            num(c.as_ref().map(|c| c.peak_force_error)),
            peak_stress,
            num(c.as_ref().map(|c| c.peak_stress_error))
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
        .filter(|r| !r.locations.is_empty() && err(r).is_finite())
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

/// The cheapest setting within a budget of |hand force error| and per-sample Fit.
pub fn cheapest_within(rows: &[SettingSummary], force: f64, fit: f64) -> Option<&SettingSummary> {
    rows.iter()
        .filter(|r| !r.locations.is_empty() && r.worst_force_error <= force && r.worst_fit >= fit)
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
    let mut v: Vec<String> = Vec::new();
    for r in records {
        let has = records
            .iter()
            .any(|q| q.location == r.location && q.knob == REFERENCE && q.completed());
        if !has && !v.contains(&r.location) {
            v.push(r.location.clone());
        }
    }
    v
}

/// The markdown report: the table over the locations, the fronts and the budgets, then the
/// per-location errors.
pub fn to_markdown(records: &[RunRecord]) -> String {
    let rows = summarise(records);
    let mut s = String::new();
    for loc in pending_references(records) {
        let _ = writeln!(
            s,
            "Location {loc}: {} settings recorded, its reference not yet (they are listed per location below, and left out of the table and the fronts).\n",
            records.iter().filter(|r| r.location == loc).count()
        );
    }
    s.push_str(
        "| knob | setting | locations | wall (s, mean) | element-cycles | M el-cyc/s | added mass | hand force error (worst) | peak force error | ROI Fit per sample (worst) | ROI Fit pooled (worst) | recovered Fit per sample (worst) | peak ROI stress error |\n|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for r in rows
        .iter()
        .filter(|r| !r.locations.is_empty() || !r.failures.is_empty())
    {
        let _ =
            writeln!(
            s,
            "| {} | {} | {} | {:.1} | {:.3e} | {:.2} | {:.2} % | {} | {} | {:.3} | {:.3} | {:.3} | {} |",
            r.knob,
            r.setting,
            if r.failures.is_empty() {
                r.locations.join(" ")
            } else {
                format!("{} (failed: {})", r.locations.join(" "), r.failures.join("; "))
            },
            r.wall,
            r.element_cycles,
            r.element_cycles / r.wall.max(1e-12) / 1e6,
            r.added_mass_percent,
            pct(r.worst_force_error),
            pct(r.peak_force_error),
            r.worst_fit,
            r.pooled_fit,
            r.worst_recovered_fit,
            pct(r.peak_stress_error),
        );
    }
    s.push_str("\nErrors against the reference at the same location; over the locations the worst one, the wall time the mean. The hand force error counts the samples where the reference's force is at least a fifth of its peak (from 10 ms on; the per-location table shows the others in parentheses).\n");
    for (what, f) in [
        (
            "hand force error",
            Box::new(|r: &SettingSummary| r.worst_force_error)
                as Box<dyn Fn(&SettingSummary) -> f64>,
        ),
        (
            "1 - ROI Fit per sample",
            Box::new(|r: &SettingSummary| 1.0 - r.worst_fit),
        ),
    ] {
        let _ = writeln!(s, "\nPareto front, wall time against {what}:");
        for r in front(&rows, f) {
            let _ = writeln!(
                s,
                "- {} = {}: {:.1} s, force {}, Fit {:.3}",
                r.knob,
                r.setting,
                r.wall,
                pct(r.worst_force_error),
                r.worst_fit
            );
        }
    }
    s.push_str("\nThe cheapest setting within each error budget (hand force at every sample, ROI Fit at every sample):\n");
    for (force, fit) in BUDGETS {
        match cheapest_within(&rows, force, fit) {
            Some(r) => {
                let _ = writeln!(
                    s,
                    "- force within {:.0} %, Fit >= {fit}: {} = {} ({:.1} s; force {}, Fit {:.3})",
                    100.0 * force,
                    r.knob,
                    r.setting,
                    r.wall,
                    pct(r.worst_force_error),
                    r.worst_fit
                );
            }
            None => {
                let _ = writeln!(
                    s,
                    "- force within {:.0} %, Fit >= {fit}: none but the reference",
                    100.0 * force
                );
            }
        }
    }
    s.push_str("\nPer location (hand force error and ROI Fit at each sample time):\n\n| location | knob | setting | wall (s) | steps | hand force error | ROI Fit | recovered Fit | energy error |\n|---|---|---|---:|---:|---|---|---|---:|\n");
    for (r, c) in comparisons(records) {
        let (fe, fi, fr) = match &c {
            Some(c) => (
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
                c.fits
                    .iter()
                    .map(|f| format!("{f:.3}"))
                    .collect::<Vec<_>>()
                    .join(" / "),
                c.recovered_fits
                    .iter()
                    .map(|f| format!("{f:.3}"))
                    .collect::<Vec<_>>()
                    .join(" / "),
            ),
            None if r.completed() => (
                "awaiting its location's reference".into(),
                "-".into(),
                "-".into(),
            ),
            None => (r.status.clone(), "-".into(), "-".into()),
        };
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.1} | {} | {fe} | {fi} | {fr} | {:.1e} |",
            r.location, r.knob, r.setting, r.wall_seconds, r.steps, r.max_energy_error
        );
    }
    s
}

/// Draw the two Pareto plots (one curve per knob through the base) into `out`.
pub fn plots(records: &[RunRecord], out: &Path) -> Result<Vec<String>, String> {
    let rows = summarise(records);
    let base = rows
        .iter()
        .find(|r| r.knob == BASE && !r.locations.is_empty());
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
            .filter(|r| !r.locations.is_empty() && r.knob != BASE && r.knob != REFERENCE)
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
            title: format!("3 mm study: {label} against wall time, each knob from the fast preset"),
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
