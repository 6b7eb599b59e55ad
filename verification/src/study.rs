//! Accuracy against cost: `palpa study`.
//!
//! Every knob that trades accuracy for speed is measured both ways on the palpation of the
//! abdomen phantom ([`scene::palpation`]): the mesh size (voxel edge), the element formulation,
//! selective mass scaling (targets of 1, 2, 4 and 10 times the initial stable step; 1 is
//! palpate's default, which adds mass only to elements that shrink during the run), the bulk
//! modulus cap (K/G 5e3, 1e3, 5e2 against the laws' own 5e4), the time-step factor and the
//! step estimate (element by element, or the mesh's own critical step of
//! [`solver::global_step`]). Each setting changes one knob of a base setting (one-point
//! elements with shear-scaled viscous hourglass control, no mass scaling, time-step factor 0.9,
//! the element estimate, the coarsest mesh) and is run to the end; the study records its wall
//! time, its element-cycles (elements x steps) and two errors against the most accurate
//! setting of the same knob (the finest mesh, the fully integrated F-bar element, no mass
//! scaling, time-step factor 0.5, the element estimate), so that each
//! knob's price in accuracy is measured on its own:
//!
//! - force: the relative RMS difference of the hand force history (both histories filtered
//!   by a centred 1 ms moving average, [`FORCE_FILTER`]: the coarse skin's contact chatters),
//!   `sqrt(sum_t (F(t) - F_ref(t))^2 / sum_t F_ref(t)^2)` over the reference's history times
//!   (the run's force interpolated linearly in time);
//! - ROI stress: the relative RMS difference of the ROI's maximum principal stress over every
//!   sample time, `sqrt(sum (s - s_ref)^2 / sum s_ref^2)`, each reference ROI element compared
//!   with the run's ROI element whose centroid is nearest (meshes of different voxel size have
//!   different ROIs).
//!
//! The same knobs then run on the Hertz block ([`crate::study_hertz`]), whose error is measured
//! against Hertz's closed form (knobs `hertz mesh`, `hertz element`, ...).
//!
//! The study writes `study.csv`, `study.md` and the Pareto plots `pareto_force.png`,
//! `pareto_stress.png` and `pareto_hertz.png` (error against wall time, one line per knob).
//! `--quick` uses a coarse phantom and a short indentation (6 mm in 6 ms) so that it finishes
//! in a few minutes on two cores; the full study runs the paper's 15 mm in 25 ms.

use phantom::Phantom;
use scene::palpation::{read_probe, ElementChoice, PalpationSetup, ProbeSamples};
use scene::run::{run_scene, RunSummary};
use solver::model::StepTarget;
use solver::output::filter::{moving_average, moving_average_at, FORCE_FILTER};
use solver::output::history::{column, read_history};
use solver::simulation::StepEstimate;
use std::collections::HashMap;
use std::fmt::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use crate::study_row::StudyRow;

/// What one run left behind, for the error computation.
pub(crate) struct RunData {
    /// The run's summary.
    pub summary: RunSummary,
    /// Why the run failed (its other fields are then empty).
    pub error: Option<String>,
    /// History times (s).
    pub time: Vec<f64>,
    /// Hand force history (N).
    pub force: Vec<f64>,
    /// The ROI samples.
    pub probe: ProbeSamples,
    /// The centroid of each probe ROI element, in the probe's order.
    pub centroids: Vec<[f64; 3]>,
}

/// One setting of the study.
struct Variant {
    knob: String,
    setting: String,
    setup: PalpationSetup,
    /// The most accurate setting of its knob: the others are measured against it.
    reference: bool,
}

/// The variants of a study, each a change of one knob of the base setting.
fn plan(quick: bool) -> Vec<Variant> {
    // The base runs without mass scaling (the study's "none"); the mass-scaling knob adds it.
    let mut base = PalpationSetup {
        vtk: false,
        mass_scaling: None,
        ..Default::default()
    };
    let voxels: &[f64] = if quick {
        base.voxel = 0.008;
        base.depth = 0.006;
        base.duration = 0.006;
        base.sample_interval = 0.001;
        &[0.008, 0.007, 0.006]
    } else {
        base.voxel = 0.006;
        &[0.008, 0.006, 0.005, 0.004]
    };
    let finest = voxels.iter().cloned().fold(f64::INFINITY, f64::min);
    let mut v = Vec::new();
    let mut push = |knob: &str, setting: String, setup: PalpationSetup, reference: bool| {
        v.push(Variant {
            knob: knob.into(),
            setting,
            setup,
            reference,
        })
    };
    for &h in voxels {
        push(
            "mesh",
            format!("voxel {} mm", h * 1e3),
            PalpationSetup {
                voxel: h,
                ..base.clone()
            },
            h == finest,
        );
    }
    for el in ElementChoice::ALL {
        push(
            "element",
            el.label().into(),
            PalpationSetup {
                element: el,
                ..base.clone()
            },
            el == ElementChoice::FullFbar,
        );
    }
    push("mass scaling", "none".into(), base.clone(), true);
    for k in [1.0, 2.0, 4.0, 10.0] {
        push(
            "mass scaling",
            if k == 1.0 {
                "target = initial step (palpate's default)".to_string()
            } else {
                format!("target {k}x initial step")
            },
            PalpationSetup {
                mass_scaling: Some(StepTarget::Initial(k)),
                mass_scaling_limit: 1e3,
                ..base.clone()
            },
            false,
        );
    }
    // The incompressibility knob: every part's K capped at ratio x G (the flesh's is 5e4).
    push(
        "bulk ratio",
        "laws' own (K/G 5e4)".into(),
        base.clone(),
        true,
    );
    for r in [5e3, 1e3, 5e2] {
        push(
            "bulk ratio",
            format!("K/G <= {r}"),
            PalpationSetup {
                max_bulk_ratio: Some(r),
                ..base.clone()
            },
            false,
        );
    }
    for f in [0.5, 0.75, 0.9] {
        push(
            "dt factor",
            format!("{f}"),
            PalpationSetup {
                dt_factor: f,
                ..base.clone()
            },
            f == 0.5,
        );
    }
    // The step estimate at factor 0.9: the mesh's own critical step (a global Lanczos
    // estimate) against the element estimate, the shorter step and so the reference (the
    // contact penalty, designed on the initial step, is the same in both).
    for est in [StepEstimate::Element, StepEstimate::Global] {
        push(
            "step estimate",
            est.name().into(),
            PalpationSetup {
                step_estimate: est,
                ..base.clone()
            },
            est == StepEstimate::Element,
        );
    }
    v
}

/// Run one setting into `dir`, sharing phantoms by voxel size. A run that fails returns its
/// summary and error; only an unreadable output is an `Err`.
pub(crate) fn run_one(
    setup: &PalpationSetup,
    dir: &Path,
    phantoms: &mut HashMap<u64, Phantom>,
) -> Result<RunData, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let key = setup.voxel.to_bits();
    if !phantoms.contains_key(&key) {
        let p = phantom::build(&setup.phantom_params()?)?;
        phantoms.insert(key, p);
    }
    let mut scene = setup.build_scene(dir, phantoms.get(&key).cloned())?;
    let roi = scene.phantom.as_ref().map(|p| p.roi.clone());
    let stop = AtomicBool::new(false);
    let (summary, err) = run_scene(&mut scene, dir, &stop, |_| {});
    if let Some(e) = err {
        return Ok(RunData {
            summary,
            error: Some(e),
            time: Vec::new(),
            force: Vec::new(),
            probe: ProbeSamples::default(),
            centroids: Vec::new(),
        });
    }
    let (cols, rows) = read_history(&dir.join("history.csv"))?;
    let time = column(&cols, &rows, "time").ok_or("history without time")?;
    let force = column(&cols, &rows, "hand_reaction").ok_or("history without hand_reaction")?;
    let probe = read_probe(dir, "hand")?;
    let centroids = match &roi {
        Some(roi) => probe_centroids(roi, &probe)?,
        None => Vec::new(),
    };
    Ok(RunData {
        summary,
        error: None,
        time,
        force,
        probe,
        centroids,
    })
}

/// The centroid of each of the probe's ROI elements, in the probe's column order (the probe
/// reads the ROI element set, sorted by element id; the phantom's [`phantom::Roi`] lists them
/// nearest to its centre first).
pub fn probe_centroids(roi: &phantom::Roi, probe: &ProbeSamples) -> Result<Vec<[f64; 3]>, String> {
    let by_id: HashMap<u32, [f64; 3]> = roi
        .elements
        .iter()
        .copied()
        .zip(roi.centroids.iter().copied())
        .collect();
    probe
        .elements
        .iter()
        .map(|e| {
            by_id
                .get(e)
                .copied()
                .ok_or_else(|| format!("probe element {e} is not in the phantom's ROI"))
        })
        .collect()
}

/// The index of the point of `xs` nearest to `c` and its distance (0 and infinity for none).
pub fn nearest(xs: &[[f64; 3]], c: &[f64; 3]) -> (usize, f64) {
    let d2 = |q: &[f64; 3]| (0..3).map(|k| (q[k] - c[k]).powi(2)).sum::<f64>();
    xs.iter()
        .enumerate()
        .map(|(i, q)| (i, d2(q)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(i, d)| (i, d.sqrt()))
        .unwrap_or((0, f64::INFINITY))
}

/// Relative RMS force error of `r` against `reference`, both filtered ([`FORCE_FILTER`]).
fn force_error(r: &RunData, reference: &RunData) -> f64 {
    let fr_s = moving_average(&reference.time, &reference.force, FORCE_FILTER);
    // the run's filtered force at the reference's history times (linear, clamped)
    let f_s = moving_average_at(&r.time, &r.force, FORCE_FILTER, &reference.time);
    let (mut num, mut den) = (0.0, 0.0);
    for (f, fr) in f_s.iter().zip(&fr_s) {
        num += (f - fr).powi(2);
        den += fr * fr;
    }
    (num / den.max(1e-300)).sqrt()
}

/// Relative RMS ROI stress error of `r` against `reference` (nearest-centroid matching).
fn stress_error(r: &RunData, reference: &RunData) -> f64 {
    let map: Vec<usize> = reference
        .centroids
        .iter()
        .map(|c| nearest(&r.centroids, c).0)
        .collect();
    let (mut num, mut den) = (0.0, 0.0);
    for (k, sref) in reference.probe.stress.iter().enumerate() {
        let Some(s) = r.probe.stress.get(k) else {
            continue;
        };
        for (i, &m) in map.iter().enumerate() {
            if let (Some(a), Some(b)) = (s.get(m), sref.get(i)) {
                num += (a - b).powi(2);
                den += b * b;
            }
        }
    }
    (num / den.max(1e-300)).sqrt()
}

/// Run the study into `out`; `progress` is told which setting starts.
pub fn run_study(
    quick: bool,
    out: &Path,
    mut progress: impl FnMut(usize, usize, &str),
) -> Result<Vec<StudyRow>, String> {
    let variants = plan(quick);
    let mut phantoms = HashMap::new();
    let n = variants.len() + crate::study_hertz::count(quick);
    let mut data: Vec<Result<RunData, String>> = Vec::new();
    for (i, va) in variants.iter().enumerate() {
        progress(i, n, &format!("{}: {}", va.knob, va.setting));
        let dir: PathBuf = out.join("runs").join(format!(
            "{:02}-{}",
            i,
            format!("{}-{}", va.knob, va.setting).replace([' ', '/', '.'], "_")
        ));
        data.push(
            run_one(&va.setup, &dir, &mut phantoms).and_then(|d| match d.error {
                Some(e) => Err(e),
                None => Ok(d),
            }),
        );
    }
    let mut rows = variants
        .iter()
        .zip(&data)
        .map(|(va, d)| {
            let (knob, setting) = (va.knob.clone(), va.setting.clone());
            let k = variants
                .iter()
                .position(|w| w.knob == va.knob && w.reference)
                .expect("every knob has a reference setting");
            match (d, &data[k]) {
                (Ok(r), Ok(reference)) => StudyRow {
                    knob,
                    setting,
                    against: variants[k].setting.clone(),
                    elements: r.summary.elements,
                    steps: r.summary.steps,
                    element_cycles: r.summary.elements as f64 * r.summary.steps as f64,
                    wall: r.summary.wall_seconds,
                    added_mass_percent: r.summary.added_mass_percent(),
                    peak_force: r.force.iter().cloned().fold(0.0, f64::max),
                    force_error: force_error(r, reference),
                    stress_error: stress_error(r, reference),
                    status: r.summary.status.clone(),
                },
                (Err(e), _) => StudyRow::failed(knob, setting, e.clone()),
                (Ok(_), Err(e)) => StudyRow::failed(
                    knob,
                    setting,
                    format!("its knob's reference `{}` failed: {e}", variants[k].setting),
                ),
            }
        })
        .collect::<Vec<_>>();
    let first = variants.len();
    rows.extend(crate::study_hertz::run(quick, |i, what| {
        progress(first + i, n, what)
    }));
    Ok(rows)
}

/// CSV text of the rows.
pub fn to_csv(rows: &[StudyRow]) -> String {
    let mut s = String::from(
        "knob,setting,against,elements,steps,element_cycles,wall_s,added_mass_percent,peak_force_N,force_error,stress_error,status\n",
    );
    for r in rows {
        let _ = writeln!(
            s,
            "{},{},{},{},{},{:.6e},{:.3},{:.3},{:.4},{:.6e},{:.6e},{}",
            r.knob,
            r.setting,
            r.against,
            r.elements,
            r.steps,
            r.element_cycles,
            r.wall,
            r.added_mass_percent,
            r.peak_force,
            r.force_error,
            r.stress_error,
            r.status.to_string().replace(',', ";")
        );
    }
    s
}

/// Markdown table of the rows, with the recommendation.
pub fn to_markdown(rows: &[StudyRow]) -> String {
    let mut s = String::from(
        "| knob | setting | against | elements | steps | element-cycles | wall (s) | added mass | peak force (N) | force error | ROI stress error |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let pct = |x: f64| {
        if x.is_finite() {
            format!("{:.2} %", 100.0 * x)
        } else {
            "-".to_string()
        }
    };
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {:.3e} | {:.2} | {:.1} % | {:.3} | {} | {} |",
            r.knob,
            r.setting,
            if r.against == r.setting {
                "(itself)"
            } else {
                &r.against
            },
            r.elements,
            r.steps,
            r.element_cycles,
            r.wall,
            r.added_mass_percent,
            r.peak_force,
            pct(r.force_error),
            pct(r.stress_error)
        );
    }
    s.push_str(
        "\nPalpation rows: force and ROI-stress errors are relative RMS differences over the whole \
         history from the most accurate setting of the same knob (column `against`). Hertz rows: the force error is the final indenter \
         force against Hertz's closed form; peak force is that final force (quarter model).\n\n",
    );
    s.push_str(&recommendation(rows));
    s
}

/// The cheapest settings within 1 %, 5 % and 10 % force error of their knob's most accurate
/// setting, with their wall time as a share of that setting's.
pub fn recommendation(rows: &[StudyRow]) -> String {
    let wall_of = |knob: &str, setting: &str| {
        rows.iter()
            .find(|r| r.knob == knob && r.setting == setting)
            .map(|r| r.wall)
            .unwrap_or(f64::NAN)
    };
    let mut s = String::from("Palpation (each setting against its knob's most accurate one):\n");
    for tol in [0.01, 0.05, 0.10] {
        let best = rows
            .iter()
            .filter(|r| {
                !r.is_hertz()
                    && r.against != r.setting
                    && r.force_error.max(r.stress_error) <= tol
                    && r.wall > 0.0
            })
            .min_by(|a, b| {
                (a.wall / wall_of(&a.knob, &a.against))
                    .total_cmp(&(b.wall / wall_of(&b.knob, &b.against)))
            });
        match best {
            Some(b) => {
                let w = wall_of(&b.knob, &b.against);
                let _ = writeln!(
                    s,
                    "- force and ROI-stress error <= {:.0} %: {} = {} gives {:.2} % force and {:.2} % ROI-stress error against {} at {:.0} % of its wall time ({:.2} s of {:.2} s).",
                    100.0 * tol,
                    b.knob,
                    b.setting,
                    100.0 * b.force_error,
                    100.0 * b.stress_error,
                    b.against,
                    100.0 * b.wall / w,
                    b.wall,
                    w
                );
            }
            None => {
                let _ = writeln!(
                    s,
                    "- no setting is within {:.0} % force and ROI-stress error of its knob's most accurate one.",
                    100.0 * tol
                );
            }
        }
    }
    let hertz: Vec<&StudyRow> = rows
        .iter()
        .filter(|r| r.is_hertz() && r.wall > 0.0)
        .collect();
    if let Some(dearest) = hertz.iter().max_by(|a, b| a.wall.total_cmp(&b.wall)) {
        s.push_str("\nHertz block (against the closed form):\n");
        for tol in [0.02, 0.05, 0.10] {
            match hertz
                .iter()
                .filter(|r| r.force_error <= tol)
                .min_by(|a, b| a.wall.total_cmp(&b.wall))
            {
                Some(b) => {
                    let _ = writeln!(
                        s,
                        "- force error <= {:.0} %: {} = {} gives {:.2} % at {:.0} % of the dearest Hertz run's wall time ({:.2} s of {:.2} s, {}).",
                        100.0 * tol,
                        b.knob,
                        b.setting,
                        100.0 * b.force_error,
                        100.0 * b.wall / dearest.wall,
                        b.wall,
                        dearest.wall,
                        dearest.setting
                    );
                }
                None => {
                    let _ = writeln!(
                        s,
                        "- no Hertz setting reaches a force error of {:.0} %.",
                        100.0 * tol
                    );
                }
            }
        }
    }
    s
}

/// Draw the two Pareto plots into `out`; returns the file names.
pub fn plots(rows: &[StudyRow], out: &Path) -> Result<Vec<String>, String> {
    let mut files = Vec::new();
    for (which, title) in [
        ("force", "force error"),
        ("stress", "ROI stress error"),
        ("hertz", "Hertz force error"),
    ] {
        let mut curves: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
        for r in rows
            .iter()
            .filter(|r| r.wall > 0.0 && r.is_hertz() == (which == "hertz"))
        {
            let e = if which == "stress" {
                r.stress_error
            } else {
                r.force_error
            };
            let e = e.max(1e-4);
            match curves.iter_mut().find(|c| c.0 == r.knob) {
                Some(c) => c.1.push((r.wall, e)),
                None => curves.push((r.knob.clone(), vec![(r.wall, e)])),
            }
        }
        for c in curves.iter_mut() {
            c.1.sort_by(|a, b| a.0.total_cmp(&b.0));
        }
        let series = crate::Series {
            plot: format!("pareto_{which}"),
            title: if which == "hertz" {
                format!("{title} against wall time (relative, vs the closed form)")
            } else {
                format!(
                    "{title} against wall time (relative RMS vs the knob's most accurate setting)"
                )
            },
            axes: ("wall time (s)".into(), format!("{title} (relative)")),
            log: true,
            curves,
        };
        files.push(crate::plot::draw(&series, out)?);
    }
    Ok(files)
}
