//! The accuracy study at the paper's resolution: `palpa study --paper`.
//!
//! The quick study ([`crate::study`]) prices each knob on an 8 mm phantom, where the mesh error
//! swamps the rest. This one runs where the campaign and `palpate --paper` run: 3 mm voxels,
//! the campaign phantom (25 mm of subcutaneous fat), the paper's 15 mm in 25 ms, pressing at
//! A, B and C.
//!
//! **Design.** Every setting changes one knob of a *base* setting and is measured against one
//! *reference*:
//!
//! - base: one-point elements with physical hourglass stabilisation, K/G <= 5000, `f32`
//!   kernels, mass scaling to the initial step (palpate's default), time-step factor 0.9, 3 mm
//!   voxels (the `fast` preset when the study was made; the preset,
//!   [`scene::palpation::Fidelity::Fast`], is now this base with mass scaling to 1.3x the
//!   initial step, the cheapest row within the budget of [`crate::study_paper_report`]);
//! - knobs: mesh (4 and 2.5 mm), element (the viscous one-point form palpate runs by default,
//!   and F-bar), the K/G cap (the laws' own 5e4, 1e3, 5e2), mass scaling (off, 1.3x and 2x
//!   the initial step), time-step factor (0.5, 0.75), precision (`f64`) and the step
//!   estimate (the mesh's own critical step, [`solver::global_step`]);
//! - reference: the most faithful setting affordable on 2 cores: fully integrated F-bar
//!   elements, the laws' own bulk moduli, `f64`, 3 mm, time-step factor 0.9, and mass scaling
//!   to the initial step (no element gets mass at the start, crushed elements get enough to
//!   keep the initial step). Without that mass the crushed elements cut the step several
//!   times over and the F-bar reference would take hours per location; what the mass costs in
//!   accuracy is what the `mass scaling = off` setting measures against the base.
//!
//! **Errors**, each setting against the reference at the same location:
//!
//! - hand force at each ROI sample time t_k (5, 10, 15, 20 ms and the end), the hand force
//!   history filtered by a centred 1 ms moving average ([`FORCE_FILTER`]) and read at t_k (at
//!   the end, half a window before it, so that the window lies inside the run): the signed
//!   relative error `(F - F_ref) / F_ref`;
//! - ROI stress Fit per sample (the paper's eq. 5 on the maximum principal stress of the ROI
//!   elements), `Fit = 1 - sqrt(sum (s_ref - s)^2 / sum (s_ref - mean s_ref)^2)`, and pooled over
//!   the samples; on another mesh each reference ROI element is compared with the run's ROI
//!   element whose centroid is nearest;
//! - peak values: the filtered hand force's maximum and the ROI's largest maximum principal
//!   stress over the samples, as relative errors.
//!
//! **Costs**: the run's wall time on the machine's cores (the time loop and its output),
//! steps, element-cycles (elements x steps) and element-cycles per second.
//!
//! **Resuming.** Each run leaves a [`RunRecord`] (`records/<location>-<setting>.json`) with
//! its scene, cost and the data the errors need; a record whose scene is the one the plan asks
//! for is read instead of run again, so an interrupted study goes on where it stopped and the
//! report can be rebuilt from committed records alone.

use crate::study::run_one;
use crate::study_paper_record::{RunRecord, StudySetting};
use phantom::Phantom;
use scene::palpation::{ElementChoice, PalpationSetup, Place};
use scene::run::RunStatus;
use solver::element::precision::Precision;
use solver::model::StepTarget;
use solver::simulation::StepEstimate;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// The locations of the study.
pub const LOCATIONS: [&str; 3] = ["A", "B", "C"];

/// Knob name of the reference row.
pub const REFERENCE: &str = "reference";
/// Knob name of the base row.
pub const BASE: &str = "base";

/// The base setting at a location: 1pt-physical elements, K/G <= 5000, `f32` kernels, mass
/// scaling to the initial step, at 3 mm on the campaign phantom.
pub fn base_setup(location: &str) -> PalpationSetup {
    PalpationSetup {
        voxel: 0.003,
        fat_thickness: 0.025,
        place: Place::Named(location.into()),
        vtk: false,
        element: ElementChoice::OnePointPhysical,
        max_bulk_ratio: Some(5000.0),
        precision: Precision::F32,
        mass_scaling: Some(StepTarget::Initial(1.0)),
        title: format!("study at 3 mm, location {location}"),
        ..Default::default()
    }
}

/// The settings of the study at one location: the reference first, then the base, then one
/// change of one knob of the base per setting.
pub fn plan(location: &str) -> Vec<StudySetting> {
    let base = base_setup(location);
    let one = |f: &dyn Fn(&mut PalpationSetup)| {
        let mut s = base.clone();
        f(&mut s);
        s
    };
    let mut v = vec![
        StudySetting::new(
            REFERENCE,
            "F-bar, laws' K, f64, mass scaling to the initial step",
            one(&|s| {
                s.element = ElementChoice::FullFbar;
                s.max_bulk_ratio = None;
                s.precision = Precision::F64;
            }),
        ),
        StudySetting::new(BASE, "1pt-physical, K/G <= 5000, f32, 3 mm", base.clone()),
    ];
    for (mm, h) in [("4", 0.004), ("2.5", 0.0025)] {
        v.push(StudySetting::new(
            "mesh",
            &format!("voxel {mm} mm"),
            one(&|s| s.voxel = h),
        ));
    }
    for el in [ElementChoice::OnePointViscousShear, ElementChoice::FullFbar] {
        v.push(StudySetting::new(
            "element",
            el.label(),
            one(&|s| s.element = el),
        ));
    }
    v.push(StudySetting::new(
        "bulk ratio",
        "laws' own (K/G 5e4)",
        one(&|s| s.max_bulk_ratio = None),
    ));
    for r in [1e3, 5e2] {
        v.push(StudySetting::new(
            "bulk ratio",
            &format!("K/G <= {r}"),
            one(&|s| s.max_bulk_ratio = Some(r)),
        ));
    }
    v.push(StudySetting::new(
        "mass scaling",
        "off",
        one(&|s| s.mass_scaling = None),
    ));
    for k in [1.3, 2.0] {
        v.push(StudySetting::new(
            "mass scaling",
            &format!("{k} x initial step"),
            one(&|s| {
                s.mass_scaling = Some(StepTarget::Initial(k));
                s.mass_scaling_limit = 1e3;
            }),
        ));
    }
    for f in [0.5, 0.75] {
        v.push(StudySetting::new(
            "dt factor",
            &format!("{f}"),
            one(&|s| s.dt_factor = f),
        ));
    }
    v.push(StudySetting::new(
        "precision",
        "f64",
        one(&|s| s.precision = Precision::F64),
    ));
    v.push(StudySetting::new(
        "step estimate",
        "global",
        one(&|s| s.step_estimate = StepEstimate::Global),
    ));
    v
}

/// Where a setting's record lives.
pub fn record_path(out: &Path, location: &str, va: &StudySetting) -> PathBuf {
    out.join("records")
        .join(format!("{location}-{}.json", va.slug()))
}

/// Run one setting (or read its record) at one location.
fn run_or_read(
    out: &Path,
    location: &str,
    va: &StudySetting,
    phantoms: &mut HashMap<u64, Phantom>,
) -> Result<RunRecord, String> {
    let path = record_path(out, location, va);
    let scene = va.setup.scene_toml();
    if let Some(r) = RunRecord::read(&path)?.filter(|r| r.is_current(&scene)) {
        return Ok(r);
    }
    let dir = out.join("runs").join(location).join(va.slug());
    let d = run_one(&va.setup, &dir, phantoms)?;
    let mut rec = RunRecord::from_summary(location, va, scene, &d.summary);
    match &d.error {
        Some(e) => rec.status = RunStatus::Failed(e.clone()).to_string(),
        None => rec.take_samples(&d),
    }
    rec.write(&path)?;
    Ok(rec)
}

/// Run (or read) every setting at every location into `out`, in plan order (the reference,
/// the dearest run, first at each location, so that every setting recorded after it can be
/// compared at once); `progress` is told which setting starts. Returns the records.
pub fn run(
    out: &Path,
    locations: &[String],
    mut progress: impl FnMut(usize, usize, &str),
) -> Result<Vec<RunRecord>, String> {
    let mut phantoms = HashMap::new();
    let plans: Vec<(String, Vec<StudySetting>)> =
        locations.iter().map(|l| (l.clone(), plan(l))).collect();
    let n: usize = plans.iter().map(|p| p.1.len()).sum();
    let mut records = Vec::new();
    for (loc, va) in plans
        .iter()
        .flat_map(|(l, v)| v.iter().map(move |va| (l, va)))
    {
        progress(
            records.len(),
            n,
            &format!("{loc}: {} = {}", va.knob, va.setting),
        );
        records.push(run_or_read(out, loc, va, &mut phantoms)?);
    }
    Ok(records)
}

/// Read whatever records of the plan exist in `out` (for a report without runs).
pub fn read_records(out: &Path, locations: &[String]) -> Result<Vec<RunRecord>, String> {
    let mut records = Vec::new();
    for loc in locations {
        for va in plan(loc) {
            let path = record_path(out, loc, &va);
            if let Some(r) =
                RunRecord::read(&path)?.filter(|r| r.is_current(&va.setup.scene_toml()))
            {
                records.push(r);
            }
        }
    }
    Ok(records)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each setting differs from the base in its own knob's fields only (and in not being
    /// the preset); the reference in the element, the bulk modulus and the precision.
    #[test]
    fn each_setting_changes_one_knob() {
        let base = base_setup("B");
        let settings = plan("B");
        assert_eq!(settings[0].knob, REFERENCE);
        assert_eq!(settings[1].knob, BASE);
        assert_eq!(settings[1].setup, base);
        for st in &settings[2..] {
            let mut s = st.setup.clone();
            match st.knob.as_str() {
                "mesh" => s.voxel = base.voxel,
                "element" => s.element = base.element,
                "bulk ratio" => s.max_bulk_ratio = base.max_bulk_ratio,
                "mass scaling" => {
                    s.mass_scaling = base.mass_scaling;
                    s.mass_scaling_limit = base.mass_scaling_limit;
                }
                "dt factor" => s.dt_factor = base.dt_factor,
                "precision" => s.precision = base.precision,
                "step estimate" => s.step_estimate = base.step_estimate,
                k => panic!("unknown knob {k}"),
            }
            assert_ne!(st.setup, s, "{} = {} changes nothing", st.knob, st.setting);
            assert_eq!(
                s, base,
                "{} = {} changes more than its knob",
                st.knob, st.setting
            );
        }
        let mut r = settings[0].setup.clone();
        assert_eq!(r.element, ElementChoice::FullFbar);
        r.element = base.element;
        r.max_bulk_ratio = base.max_bulk_ratio;
        r.precision = base.precision;
        assert_eq!(r, base);
    }

    #[test]
    fn probe_centroids_follow_the_probe_order() {
        let roi = phantom::Roi {
            center: [0.0; 3],
            elements: vec![5, 2, 9],
            centroids: vec![[5.0, 0.0, 0.0], [2.0, 0.0, 0.0], [9.0, 0.0, 0.0]],
        };
        let probe = scene::palpation::ProbeSamples {
            elements: vec![2, 5, 9],
            ..Default::default()
        };
        let c = crate::study::probe_centroids(&roi, &probe).unwrap();
        assert_eq!(c, vec![[2.0, 0.0, 0.0], [5.0, 0.0, 0.0], [9.0, 0.0, 0.0]]);
        let stranger = scene::palpation::ProbeSamples {
            elements: vec![2, 7],
            ..Default::default()
        };
        let e = crate::study::probe_centroids(&roi, &stranger).unwrap_err();
        assert!(e.contains("probe element 7"), "{e}");
    }
}
