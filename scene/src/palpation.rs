//! One two-finger palpation of the abdomen phantom, as the reference study ran it
//! (`docs/paper.md`): the reduced phantom, the paper's three tissues
//! (`paper:liver`, `paper:flesh`, `paper:ribs`), two rigid capsule fingers pressed 15 mm along
//! the inward skin normal in 25 ms with a smooth ramp, penalty contact on the anterior skin,
//! the back fixed and rollers on the cut planes, and the ROI's stresses sampled every 5 ms.
//!
//! [`PalpationSetup::scene_spec`] builds it as a typed scene in memory, and
//! [`PalpationSetup::scene_toml`] writes the same scene as an ordinary scene file, so that a
//! palpation is a scene like any other: `palpa palpate` saves it as `scene.toml` in its output directory,
//! and `palpa run` on that file repeats the run exactly. Campaigns and the accuracy study
//! vary its fields. [`read_probe`] reads the ROI samples back.
//!
//! Materials of the other phantom parts: the lumped viscera are given the flesh law (the
//! paper's "lumped abdominal tissue"), the spine the rib law (its nodes are fixed anyway), and
//! a tumour the liver law with its shear and Prony moduli scaled by the tumour's stiffness
//! factor (so its Poisson ratio and relaxation times stay the liver's).

use phantom::{Tumour, DEFAULT_VOXEL};
use solver::element::{HourglassForm, HourglassModulus};
use solver::model::StepTarget;
use solver::output::history::{column, read_history};
use std::path::Path;

/// Where the fingers press.
#[derive(Clone, Debug, PartialEq)]
pub enum Place {
    /// A named phantom location: "A", "B", "C", "P01".."P25".
    Named(String),
    /// A point (x, y) of the body surface (m).
    At(f64, f64),
}

/// Element formulation of every part.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ElementChoice {
    /// One-point integration with viscous hourglass control scaled by the P-wave modulus
    /// (LS-DYNA's type 1).
    OnePointViscous,
    /// One-point integration with stiffness hourglass control scaled by the P-wave modulus
    /// (Flanagan-Belytschko, LS-DYNA type 4).
    OnePointStiffness,
    /// One-point integration with viscous hourglass control scaled by the shear modulus.
    OnePointViscousShear,
    /// One-point integration with stiffness hourglass control scaled by the shear modulus
    /// (in the spirit of LS-DYNA type 6).
    OnePointStiffnessShear,
    /// One-point integration with physical (assumed-strain) hourglass stabilisation, Q = 1
    /// (in the spirit of LS-DYNA type 6, see [`solver::element::physical`]).
    OnePointPhysical,
    /// Fully integrated 2x2x2 with F-bar.
    FullFbar,
}

impl ElementChoice {
    /// Every choice, in table order.
    pub const ALL: [ElementChoice; 6] = [
        ElementChoice::OnePointViscous,
        ElementChoice::OnePointStiffness,
        ElementChoice::OnePointViscousShear,
        ElementChoice::OnePointStiffnessShear,
        ElementChoice::OnePointPhysical,
        ElementChoice::FullFbar,
    ];
    /// The hourglass control of a one-point choice; `None` for F-bar.
    pub fn hourglass(&self) -> Option<(HourglassForm, HourglassModulus)> {
        use HourglassForm::{Physical, Stiffness, Viscous};
        use HourglassModulus::{PWave, Shear};
        match self {
            ElementChoice::OnePointViscous => Some((Viscous, PWave)),
            ElementChoice::OnePointStiffness => Some((Stiffness, PWave)),
            ElementChoice::OnePointViscousShear => Some((Viscous, Shear)),
            ElementChoice::OnePointStiffnessShear => Some((Stiffness, Shear)),
            ElementChoice::OnePointPhysical => Some((Physical, Shear)),
            ElementChoice::FullFbar => None,
        }
    }
    /// Short name for tables.
    pub fn label(&self) -> &'static str {
        match self {
            ElementChoice::OnePointViscous => "1pt-viscous",
            ElementChoice::OnePointStiffness => "1pt-stiffness",
            ElementChoice::OnePointViscousShear => "1pt-viscous-shear",
            ElementChoice::OnePointStiffnessShear => "1pt-stiffness-shear",
            ElementChoice::OnePointPhysical => "1pt-physical",
            ElementChoice::FullFbar => "full-fbar",
        }
    }
}

impl std::str::FromStr for ElementChoice {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "1pt-viscous" | "viscous" => Ok(ElementChoice::OnePointViscous),
            "one_point" => Ok(ElementChoice::OnePointViscousShear),
            "1pt-stiffness" | "stiffness" => Ok(ElementChoice::OnePointStiffness),
            "1pt-viscous-shear" | "viscous-shear" => Ok(ElementChoice::OnePointViscousShear),
            "1pt-stiffness-shear" | "stiffness-shear" => Ok(ElementChoice::OnePointStiffnessShear),
            "1pt-physical" | "physical" => Ok(ElementChoice::OnePointPhysical),
            "full_fbar" | "full-fbar" | "full" => Ok(ElementChoice::FullFbar),
            o => Err(format!(
                "unknown element formulation `{o}` (one_point, 1pt-viscous, 1pt-stiffness, \
                 1pt-viscous-shear, 1pt-stiffness-shear, 1pt-physical, full_fbar)"
            )),
        }
    }
}

/// A named setting of the knobs that trade accuracy for time (`--fidelity` of `palpate`,
/// `solver.fidelity` of a campaign). Measured against fully integrated F-bar elements at the
/// laws' own bulk modulus at 3 mm on the campaign phantom at A, B and C (docs/study/README.md,
/// `palpa study --paper`), and at location A on the 5 mm phantom (docs/palpate.md).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fidelity {
    /// The options as given (by default: one-point elements with shear-scaled viscous
    /// hourglass control, the laws' own bulk moduli).
    Standard,
    /// One-point elements with physical hourglass stabilisation, every part's bulk modulus
    /// capped at 5000 times its shear modulus, single-precision element kernels, and selective
    /// mass scaling to 1.3 times the initial stable step: the cheapest setting of the 3 mm
    /// study within its error budget (hand force within 10 % from 10 ms on, ROI Fit >= 0.75
    /// at every sample, at A, B and C).
    Fast,
}

impl Fidelity {
    /// The K/G cap of the fast preset.
    pub const FAST_BULK_RATIO: f64 = 5000.0;
    /// The fast preset's mass-scaling target, as a multiple of the initial stable step.
    pub const FAST_MASS_SCALING: f64 = 1.3;
    /// The knobs the fast preset sets (scene and campaign key names): an option or key for any
    /// of them beside the preset is refused, so that neither silently overrides the other.
    pub const FAST_KNOBS: [&'static str; 4] =
        ["element", "max_bulk_ratio", "precision", "mass_scaling"];
    /// The refusal of a knob given beside the fast preset; `as_flag` names them as
    /// command-line options (`--max-bulk-ratio`), else as keys (`max_bulk_ratio`).
    pub fn fast_conflict(preset: &str, as_flag: bool) -> String {
        let knobs: Vec<String> = Self::FAST_KNOBS
            .iter()
            .map(|k| {
                if as_flag {
                    format!("--{}", k.replace('_', "-"))
                } else {
                    k.to_string()
                }
            })
            .collect();
        format!(
            "{preset} sets {}: give the preset or those {}",
            knobs.join(", "),
            if as_flag { "options" } else { "keys" }
        )
    }
    /// Apply the preset to a setup (the element, the K/G cap, the precision and the mass
    /// scaling target; the added-mass limit stays the setup's).
    pub fn apply(&self, s: &mut PalpationSetup) {
        if *self == Fidelity::Fast {
            s.element = ElementChoice::OnePointPhysical;
            s.part_elements.clear();
            s.max_bulk_ratio = Some(Self::FAST_BULK_RATIO);
            s.precision = solver::element::precision::Precision::F32;
            s.mass_scaling = Some(StepTarget::Initial(Self::FAST_MASS_SCALING));
        }
    }
    /// The preset and its measured error budget, for the summary.
    pub fn describe(&self) -> &'static str {
        match self {
            Fidelity::Standard => "standard (the options as given)",
            Fidelity::Fast => {
                "fast (1pt-physical, K/G <= 5000, f32 kernels, mass scaling to 1.3x the initial step): \
                 measured at 3 mm on the campaign phantom at A, B and C (docs/study/README.md) against F-bar \
                 at the laws' K in f64: hand force within 7.3 % from 10 ms on, ROI stress Fit 0.79-0.95 per \
                 sample (0.93 pooled), peak ROI stress within 1.9 %, about 1/20 of the reference's wall time; \
                 its budget: force within 10 %, Fit >= 0.75 at every sample (the mesh is the larger error: \
                 on 2.5 mm voxels the ROI field meets the 3 mm reference only to Fit 0.28-0.67 from 10 ms on). \
                 The budget holds at 3 mm: at 5 mm (location A) the force is 6-12 % low from 10 ms on, \
                 Fit 0.78-0.89 per sample, and about 4 % of the model's mass is added (the limit is 5 %)"
            }
        }
    }
}

impl std::str::FromStr for Fidelity {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "standard" => Ok(Fidelity::Standard),
            "fast" => Ok(Fidelity::Fast),
            o => Err(format!("unknown fidelity `{o}` (standard, fast)")),
        }
    }
}

/// Everything that defines one palpation. Lengths in m, times in s.
#[derive(Clone, Debug, PartialEq)]
pub struct PalpationSetup {
    /// Title of the run.
    pub title: String,
    /// `reduced` or `full`.
    pub variant: String,
    /// Voxel edge (m).
    pub voxel: f64,
    /// Subcutaneous fat (m).
    pub fat_thickness: f64,
    /// Respiratory phase 0..1.
    pub respiratory_phase: f64,
    /// Voxel steps or a fitted skin.
    pub skin: phantom::Skin,
    /// Tumours.
    pub tumours: Vec<Tumour>,
    /// Where the fingers press.
    pub place: Place,
    /// Indentation depth (m).
    pub depth: f64,
    /// Time to reach the depth (s); the run ends then.
    pub duration: f64,
    /// Interval between stress samples and VTK frames (s).
    pub sample_interval: f64,
    /// Finger diameter (m).
    pub finger_diameter: f64,
    /// Centre-to-centre finger spacing (m).
    pub finger_spacing: f64,
    /// Element formulation.
    pub element: ElementChoice,
    /// Per-part formulations that replace `element` (part name to choice): e.g. F-bar in the
    /// liver, whose element stresses are the ROI's, and one-point elsewhere. Tumour parts
    /// follow the liver's entry unless they have their own.
    pub part_elements: std::collections::BTreeMap<String, ElementChoice>,
    /// Selective mass scaling, if any. Default: the initial stable step
    /// ([`StepTarget::Initial`]), so that elements crushed under the fingers do not pull
    /// the step down (about half the steps of an unscaled run, about 1.4 % mass added to the
    /// flesh at the default resolution); `None` runs without.
    pub mass_scaling: Option<StepTarget>,
    /// Largest mass that mass scaling may add, as a fraction of the physical mass.
    pub mass_scaling_limit: f64,
    /// Time-step safety factor.
    pub dt_factor: f64,
    /// The incompressibility knob: cap every part's bulk modulus at this multiple of its
    /// initial shear modulus (`max_bulk_ratio` of each `[[part]]`); `None` keeps the laws'.
    pub max_bulk_ratio: Option<f64>,
    /// The preset the knobs came from (stated in the summary).
    pub fidelity: Fidelity,
    /// The element kernels' number type (`[run] precision`).
    pub precision: solver::element::precision::Precision,
    /// Subcycling's largest macro ratio (`[run] subcycling`, [`solver::subcycle`]); 1 is off.
    pub subcycling: u32,
    /// How the stable step is estimated (`[run] step_estimate`, [`solver::global_step`]).
    pub step_estimate: solver::simulation::StepEstimate,
    /// Write VTK frames.
    pub vtk: bool,
}

impl Default for PalpationSetup {
    /// The paper's protocol on the default (coarse) reduced phantom at location A.
    fn default() -> Self {
        PalpationSetup {
            title: "palpation".into(),
            variant: "reduced".into(),
            voxel: DEFAULT_VOXEL,
            fat_thickness: 0.015,
            respiratory_phase: 0.0,
            skin: phantom::Skin::Voxel,
            tumours: Vec::new(),
            place: Place::Named("A".into()),
            depth: 0.015,
            duration: 0.025,
            sample_interval: 0.005,
            finger_diameter: 0.015,
            finger_spacing: 0.020,
            element: ElementChoice::OnePointViscousShear,
            part_elements: Default::default(),
            mass_scaling: Some(StepTarget::Initial(1.0)),
            mass_scaling_limit: 0.05,
            dt_factor: solver::simulation::DEFAULT_DT_FACTOR,
            max_bulk_ratio: None,
            fidelity: Fidelity::Standard,
            precision: Default::default(),
            subcycling: 1,
            step_estimate: Default::default(),
            vtk: true,
        }
    }
}

impl PalpationSetup {
    /// Check the values a user can set.
    pub fn validate(&self) -> Result<(), String> {
        let pos = |v: f64, what: &str| {
            if v > 0.0 && v.is_finite() {
                Ok(())
            } else {
                Err(format!("{what} must be positive, got {v}"))
            }
        };
        pos(self.depth, "depth")?;
        pos(self.duration, "duration")?;
        pos(self.sample_interval, "sample interval")?;
        pos(self.finger_diameter, "finger diameter")?;
        pos(self.finger_spacing, "finger spacing")?;
        pos(self.voxel, "voxel")?;
        if self.finger_spacing < self.finger_diameter {
            return Err(
                "the finger spacing (centre to centre) must be at least the diameter".into(),
            );
        }
        if !(self.dt_factor > 0.0 && self.dt_factor <= 1.0) {
            return Err(format!(
                "dt factor must lie in (0, 1], got {}",
                self.dt_factor
            ));
        }
        if let Some(r) = self.max_bulk_ratio {
            if r.is_nan() || r.is_infinite() || r <= 2.0 / 3.0 {
                return Err(format!(
                    "max bulk ratio must be a finite K/G above 2/3 (Poisson ratio above 0), got {r}"
                ));
            }
        }
        match self.mass_scaling {
            Some(StepTarget::Step(t)) => pos(t, "mass-scaling target step")?,
            Some(StepTarget::Initial(k)) => pos(k, "mass-scaling multiple of the initial step")?,
            None => {}
        }
        if !(self.mass_scaling_limit >= 0.0 && self.mass_scaling_limit.is_finite()) {
            return Err(format!(
                "mass-scaling limit must be a finite fraction of the mass, 0 or more, got {}",
                self.mass_scaling_limit
            ));
        }
        let finite = |v: f64, what: &str| {
            if v.is_finite() {
                Ok(())
            } else {
                Err(format!("{what} must be finite, got {v}"))
            }
        };
        finite(self.fat_thickness, "fat thickness")?;
        finite(self.respiratory_phase, "respiratory phase")?;
        for t in &self.tumours {
            for c in t.center {
                finite(c, "tumour centre")?;
            }
            pos(t.radius, "tumour radius")?;
            pos(t.stiffness_factor, "tumour stiffness")?;
        }
        if let Place::At(x, y) = self.place {
            finite(x, "x of the place")?;
            finite(y, "y of the place")?;
        }
        Ok(())
    }

    /// The phantom parameters its scene asks for (to build the phantom once and share it, see
    /// [`crate::build::build_scene_with`]).
    pub fn phantom_params(&self) -> Result<phantom::PhantomParams, String> {
        self.phantom_scene().to_params()
    }
}

/// The ROI samples of a finished run (`probe.csv`).
#[derive(Clone, Debug, Default)]
pub struct ProbeSamples {
    /// Sample times (s).
    pub time: Vec<f64>,
    /// Hand force along the pressing direction (N) at each sample (`hand_reaction`).
    pub force: Vec<f64>,
    /// Hand travel along the pressing direction (m) at each sample (`hand_travel`): the
    /// indentation, as the fingers start on the skin.
    pub depth: Vec<f64>,
    /// ROI element ids.
    pub elements: Vec<u32>,
    /// Maximum principal Cauchy stress (Pa), one row per sample, one column per ROI element.
    pub stress: Vec<Vec<f64>>,
}

/// Read `probe.csv` of a run directory whose hand is named `hand`.
pub fn read_probe(dir: &Path, hand: &str) -> Result<ProbeSamples, String> {
    let (cols, rows) = read_history(&dir.join("probe.csv"))?;
    let get = |name: &str| {
        column(&cols, &rows, name)
            .ok_or_else(|| format!("{}: no column `{name}`", dir.join("probe.csv").display()))
    };
    let time = get("time")?;
    let force = get(&format!("{hand}_reaction"))?;
    let depth = get(&format!("{hand}_travel"))?;
    let idx: Vec<(usize, u32)> = cols
        .iter()
        .enumerate()
        .filter_map(|(i, c)| {
            c.strip_prefix('e')
                .and_then(|n| n.parse().ok())
                .map(|e| (i, e))
        })
        .collect();
    Ok(ProbeSamples {
        time,
        force,
        depth,
        elements: idx.iter().map(|x| x.1).collect(),
        stress: rows
            .iter()
            .map(|r| idx.iter().map(|&(i, _)| r[i]).collect())
            .collect(),
    })
}
