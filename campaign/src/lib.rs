//! Palpation campaigns: many palpations of one phantom, the raw material of a surrogate's
//! training dataset (`palpa campaign`).
//!
//! A campaign is a [`CampaignSpec`] (a TOML file, or the paper's protocol when none is given)
//! resolved into a [`Campaign`]: a list of locations, each labelled train or test, and a list of
//! [`PlannedRun`]s, the product of locations x depths x durations in a fixed order. Every run is
//! an ordinary palpation ([`PalpationSetup`]) written as `scene.toml` into its own directory
//! `DIR/runs/<label>/` and run there; a run is finished when its `done.json` ([`DoneMarker`])
//! exists, written atomically after everything else. A directory without it is an interrupted or
//! failed run and is redone from scratch.
//!
//! # The file
//! Every key is optional; the defaults are the paper's protocol (`docs/paper.md`):
//! the 25 raster points P01..P25 for training, A, B, C for testing, 15 mm in 25 ms, a sample every
//! 5 ms, on the reduced phantom with the paper's 3 mm voxels ([`CAMPAIGN_VOXEL`]) and 25 mm of
//! subcutaneous fat ([`CAMPAIGN_FAT_THICKNESS`]). Quantities take units as in scene files,
//! and unknown keys are errors.
//!
//! ```toml
//! title = "paper protocol"
//!
//! [phantom]                        # as a scene's [mesh.phantom] (these keys only)
//! variant = "reduced"              # or "full"
//! voxel = "3 mm"                   # the campaign default (a single palpation's is 5 mm)
//! fat_thickness = "25 mm"          # the campaign default (a single palpation's is 15 mm)
//! respiratory_phase = 0.0
//! tumours = [{ center = ["-60 mm", "180 mm", "150 mm"], radius = "10 mm", stiffness = 5.0 }]
//!
//! [locations]
//! train = ["grid"]                 # "grid" = P01..P25; names A, B, C, P01..P25;
//!                                  # points ["-50 mm", "190 mm"]; { name = "D", at = [x, y] }
//! test = ["A", "B", "C"]
//! [[locations.raster]]             # optional further rasters of points (x, y of the skin)
//! center = ["-50 mm", "195 mm"]
//! spacing = ["10 mm", "10 mm"]
//! n = [3, 3]
//! split = "train"                  # or "test"
//! prefix = "R"                     # names R01, R02, ... (cranial row first, then by x)
//!
//! [indentation]
//! depth = "15 mm"                  # one value or a list: every depth is run
//! duration = "25 ms"               # one value or a list; or speed = "0.6 m/s" (depth / duration)
//! sample_interval = "5 ms"         # samples at 0, 5, ..., 25 ms
//!
//! [hand]
//! diameter = "15 mm"
//! spacing = "20 mm"
//!
//! [solver]
//! element = "one_point"            # one_point | stiffness | full_fbar
//! # element_by_part = { liver = "full_fbar" }   # per-part formulations replacing `element`
//! dt_factor = 0.9
//! mass_scaling = "initial"         # selective mass scaling: initial (default) | "2 x initial" | "4 us" | "off"
//! # mass_scaling_limit = 0.05
//! # fidelity = "fast"             # 1pt-physical elements, K/G <= 5000, f32 kernels (docs/palpate.md)
//! # precision = "f32"              # element kernels: f64 (default) | f32
//! # max_bulk_ratio = 5000           # or the K/G cap alone
//! vtk = false                      # VTK frames of every run (off: only the probe files)
//! ```
//!
//! # Order, labels and shards
//! Locations come in the order train entries, train rasters, test entries, test rasters; runs
//! loop over locations, then depths, then durations. A run's label is its location's label, or
//! `<location>_d<depth>mm_t<duration>ms` when the campaign has more than one depth or duration.
//! Run `k` (0-based, in this order) belongs to shard `k mod n` ([`in_shard`]).

use material::quantity::{Length, Number, Time, Velocity};
use phantom::{location_at, Location, Phantom, PhantomParams, PAPER_VOXEL};
use scene::build::build_scene_with;
use scene::palpation::{read_probe, ElementChoice, PalpationSetup, Place, TumourSetup};
use scene::phantom_spec::TumourScene;
use scene::{Scene, SceneSpec};
use serde::{Deserialize, Deserializer, Serialize};
use serde_json::json;
use solver::output::atomic::write_atomic;
use solver::output::filter::{moving_average_at, FORCE_FILTER};
use solver::output::history::{column, read_history};
use std::path::{Path, PathBuf};

/// Name of the marker file of a finished run.
pub const DONE_FILE: &str = "done.json";
/// Name of the campaign description in a campaign directory.
pub const CAMPAIGN_FILE: &str = "campaign.json";
/// Value of the `format` key of [`CAMPAIGN_FILE`].
pub const CAMPAIGN_FORMAT: &str = "palpa-campaign";

/// One value or a list of values (`depth = "15 mm"` or `depth = ["10 mm", "15 mm"]`).
#[derive(Clone, Debug, PartialEq)]
pub struct OneOrMany<T>(pub Vec<T>);

impl<'de, T: serde::de::DeserializeOwned> Deserialize<'de> for OneOrMany<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        let v = toml::Value::deserialize(d)?;
        let one = |x: toml::Value| T::deserialize(x).map_err(|e| D::Error::custom(e.message()));
        match v {
            toml::Value::Array(a) => {
                Ok(OneOrMany(a.into_iter().map(one).collect::<Result<_, _>>()?))
            }
            x => Ok(OneOrMany(vec![one(x)?])),
        }
    }
}

/// A campaign file (see the module doc).
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CampaignSpec {
    /// Title (default "palpation campaign").
    pub title: Option<String>,
    /// The phantom.
    #[serde(default)]
    pub phantom: PhantomSpec,
    /// Where to press.
    #[serde(default)]
    pub locations: LocationsSpec,
    /// How deep, how fast, how often to sample.
    #[serde(default)]
    pub indentation: IndentationSpec,
    /// The two fingers.
    #[serde(default)]
    pub hand: HandSpec,
    /// Element formulation and time step.
    #[serde(default)]
    pub solver: SolverSpec,
}

/// `[phantom]`.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PhantomSpec {
    /// `reduced` (default) or `full`.
    pub variant: Option<String>,
    /// Voxel edge (default [`CAMPAIGN_VOXEL`], 3 mm).
    pub voxel: Option<Length>,
    /// Subcutaneous fat thickness (default [`CAMPAIGN_FAT_THICKNESS`], 25 mm).
    pub fat_thickness: Option<Length>,
    /// Respiratory phase 0..1 (default 0).
    pub respiratory_phase: Option<Number>,
    /// Liver tumours.
    #[serde(default)]
    pub tumours: Vec<TumourScene>,
}

/// A location entry: a name, a point, or a named point.
#[derive(Clone, Debug, Deserialize)]
#[serde(untagged)]
pub enum LocationEntry {
    /// `"A"`, `"P07"`, or `"grid"` for P01..P25.
    Name(String),
    /// `["-50 mm", "190 mm"]`: a point (x, y) of the body surface.
    Point([Length; 2]),
    /// `{ name = "D", at = ["-50 mm", "190 mm"] }`.
    Named(NamedPoint),
}

/// A point with a name.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NamedPoint {
    /// Label.
    pub name: String,
    /// (x, y) of the body surface.
    pub at: [Length; 2],
}

/// A raster of points.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RasterSpec {
    /// Centre (x, y).
    pub center: [Length; 2],
    /// Distance between neighbours along x and y.
    pub spacing: [Length; 2],
    /// Points along x and y.
    pub n: [usize; 2],
    /// `train` or `test`.
    pub split: String,
    /// Label prefix (default "R"): R01, R02, ...
    pub prefix: Option<String>,
}

/// `[locations]`.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LocationsSpec {
    /// Training locations (default `["grid"]`).
    pub train: Option<Vec<LocationEntry>>,
    /// Test locations (default `["A", "B", "C"]`).
    pub test: Option<Vec<LocationEntry>>,
    /// Further rasters of points.
    #[serde(default)]
    pub raster: Vec<RasterSpec>,
}

/// `[indentation]`.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IndentationSpec {
    /// Depth(s) (default 15 mm).
    pub depth: Option<OneOrMany<Length>>,
    /// Time(s) to reach the depth (default 25 ms).
    pub duration: Option<OneOrMany<Time>>,
    /// Mean speed(s), instead of durations: duration = depth / speed.
    pub speed: Option<OneOrMany<Velocity>>,
    /// Interval between samples (default 5 ms).
    pub sample_interval: Option<Time>,
    /// The most samples a run may record (default [`DEFAULT_MAX_SAMPLES`]); a shorter
    /// sample interval is refused.
    pub max_samples: Option<f64>,
}

/// The most runs a campaign may have (locations x depths x durations; a raster's points count
/// as locations). A run takes minutes to hours: far more is a mistake in the file, refused
/// before the plan is built.
pub const MAX_RUNS: usize = 10_000;

/// The most samples one run may record unless `[indentation] max_samples` raises the limit.
pub const DEFAULT_MAX_SAMPLES: f64 = 1e6;

/// `[hand]`.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HandSpec {
    /// Finger diameter (default 15 mm).
    pub diameter: Option<Length>,
    /// Centre-to-centre finger spacing (default 20 mm).
    pub spacing: Option<Length>,
}

/// `[solver]`.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolverSpec {
    /// `one_point` (default), `stiffness` or `full_fbar`.
    pub element: Option<String>,
    /// Per-part formulations that replace `element`, e.g. `{ liver = "full_fbar" }` (parts
    /// flesh, liver, ribs, viscera, spine, tumour, tumour2, ...; tumours follow liver).
    pub element_by_part: Option<std::collections::BTreeMap<String, String>>,
    /// Time-step safety factor (default 0.75).
    pub dt_factor: Option<Number>,
    /// Selective mass scaling: `"initial"` (the default, as `palpa palpate`), `"<k> x
    /// initial"`, a time step, or `"off"`.
    pub mass_scaling: Option<String>,
    /// Largest added mass fraction (default 0.05).
    pub mass_scaling_limit: Option<Number>,
    /// Write VTK frames of every run (default false).
    pub vtk: Option<bool>,
    /// Preset of the accuracy knobs: `standard` (default) or `fast` (1pt-physical elements,
    /// K/G capped at 5000, f32 kernels; not with `element`, `element_by_part` or
    /// `max_bulk_ratio`).
    pub fidelity: Option<String>,
    /// Element-kernel precision, `"f64"` or `"f32"` (default: the preset's).
    pub precision: Option<String>,
    /// The incompressibility knob: cap every part's bulk modulus at this multiple of its
    /// shear modulus (as `palpate --max-bulk-ratio`).
    pub max_bulk_ratio: Option<Number>,
}

/// Training or test location.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Split {
    /// Used for training (dataset split 0).
    Train,
    /// Held out (dataset split 1).
    Test,
}

impl Split {
    /// 0 for train, 1 for test.
    pub fn code(self) -> u8 {
        match self {
            Split::Train => 0,
            Split::Test => 1,
        }
    }
    /// "train" or "test".
    pub fn name(self) -> &'static str {
        match self {
            Split::Train => "train",
            Split::Test => "test",
        }
    }
}

/// One location of a campaign.
#[derive(Clone, Debug, PartialEq)]
pub struct CampaignLocation {
    /// Label (a phantom location's name, or the point's name).
    pub label: String,
    /// Train or test.
    pub split: Split,
    /// Where the fingers press.
    pub place: Place,
}

/// One run of a campaign.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedRun {
    /// Position in the campaign's order (0-based).
    pub index: usize,
    /// Directory name under `runs/`.
    pub label: String,
    /// Index into [`Campaign::locations`].
    pub location: usize,
    /// Indentation depth (m).
    pub depth: f64,
    /// Time to reach it (s).
    pub duration: f64,
}

/// A resolved campaign: the common palpation settings, the locations and the runs.
#[derive(Clone, Debug, PartialEq)]
pub struct Campaign {
    /// Title.
    pub title: String,
    /// Settings shared by every run (its place, depth and duration are replaced per run).
    pub base: PalpationSetup,
    /// Locations in order.
    pub locations: Vec<CampaignLocation>,
    /// Runs in order.
    pub runs: Vec<PlannedRun>,
}

/// `v` with at most `d` decimals, trailing zeros removed.
fn short(v: f64, d: usize) -> String {
    let s = format!("{v:.d$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

fn check_label(l: &str) -> Result<(), String> {
    if l.is_empty()
        || !l
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.'))
        || l.starts_with('.')
    {
        return Err(format!(
            "location label `{l}`: use letters, digits, `-`, `_` and `.` (it names a directory)"
        ));
    }
    Ok(())
}

fn entry_locations(e: &LocationEntry, split: Split) -> Result<Vec<CampaignLocation>, String> {
    let named = |n: &str| CampaignLocation {
        label: n.to_string(),
        split,
        place: Place::Named(n.to_string()),
    };
    Ok(match e {
        LocationEntry::Name(n) if n.eq_ignore_ascii_case("grid") => {
            let g = phantom::GridParams::default();
            (1..=g.n[0] * g.n[1])
                .map(|k| named(&format!("P{k:02}")))
                .collect()
        }
        LocationEntry::Name(n) => {
            let n = n.to_ascii_uppercase();
            let ok = matches!(n.as_str(), "A" | "B" | "C")
                || (n.len() == 3
                    && n.starts_with('P')
                    && n[1..].parse::<usize>().is_ok_and(|k| (1..=25).contains(&k)));
            if !ok {
                return Err(format!(
                    "unknown location `{n}`: A, B, C, P01..P25, \"grid\", a point [x, y] or {{ name, at }}"
                ));
            }
            vec![named(&n)]
        }
        LocationEntry::Point(p) => {
            let (x, y) = (p[0].0, p[1].0);
            vec![CampaignLocation {
                label: format!("at_{}_{}", short(x * 1e3, 1), short(y * 1e3, 1)),
                split,
                place: Place::At(x, y),
            }]
        }
        LocationEntry::Named(p) => {
            check_label(&p.name)?;
            vec![CampaignLocation {
                label: p.name.clone(),
                split,
                place: Place::At(p.at[0].0, p.at[1].0),
            }]
        }
    })
}

fn raster_locations(r: &RasterSpec) -> Result<(Split, Vec<CampaignLocation>), String> {
    let split = match r.split.as_str() {
        "train" => Split::Train,
        "test" => Split::Test,
        o => {
            return Err(format!(
                "locations.raster: split `{o}` is not train or test"
            ))
        }
    };
    let prefix = r.prefix.clone().unwrap_or_else(|| "R".into());
    check_label(&prefix)?;
    let [nx, ny] = r.n;
    if nx == 0 || ny == 0 {
        return Err("locations.raster: n must be at least [1, 1]".into());
    }
    if nx.saturating_mul(ny) > MAX_RUNS {
        return Err(format!(
            "locations.raster: n = [{nx}, {ny}] gives {:.4e} points, more than a campaign's limit of {MAX_RUNS} runs",
            nx as f64 * ny as f64
        ));
    }
    let grid = phantom::GridParams {
        center: [r.center[0].0, r.center[1].0],
        spacing: [r.spacing[0].0, r.spacing[1].0],
        n: r.n,
    };
    let out = grid
        .points()
        .into_iter()
        .enumerate()
        .map(|(k, [x, y])| CampaignLocation {
            label: format!("{prefix}{:02}", k + 1),
            split,
            place: Place::At(x, y),
        })
        .collect();
    Ok((split, out))
}

/// A campaign's default voxel size (m): the paper's CT resolution ([`PAPER_VOXEL`]), finer than
/// a single palpation's 5 mm ([`phantom::DEFAULT_VOXEL`]).
///
/// The reduced phantom then has 104,455 hexahedra (the paper's reduced model: 112,955) and the
/// ROI the paper's 377 elements. At 5 mm the ROI stress is not converged in the mesh: the 5 mm
/// field predicts the 3 mm field at the same location with a Fit of -0.20 to 0.73, its peaks
/// 1.0-3.1 times the 3 mm ones. The held-out GP Fit of the paper's protocol is 0.897 at 3 mm
/// against 0.867 at 5 mm (docs/campaigns.md). A run takes 17-23 min on one thread
/// against 2-3 min at 5 mm.
pub const CAMPAIGN_VOXEL: f64 = PAPER_VOXEL;

/// A campaign's default subcutaneous fat thickness (m), thicker than a single palpation's
/// 15 mm ([`PalpationSetup`]'s default).
///
/// The paper's protocol presses 15 mm at every raster point, including the cranial and lateral
/// points over the ribs (P11, P12 and, on the earlier raster with rows 25 mm apart, P16). Over
/// 15 mm of flesh, a 15 mm indentation there crushes the flesh between finger and rib to
/// nothing. At 5 mm voxels, P12 then stopped at its
/// mass-scaling limit: 14.1 % of the flesh's mass had been added over 98 elements, and one
/// element needed a 619x density scale. With 25 mm, every run of the protocol finishes with at
/// most 2.2 % of the flesh's mass added. 25 mm is within the range of adult abdominal
/// subcutaneous fat.
pub const CAMPAIGN_FAT_THICKNESS: f64 = 0.025;

impl CampaignSpec {
    /// Read and parse a campaign file.
    pub fn load(path: &Path) -> Result<CampaignSpec, String> {
        let src = std::fs::read_to_string(path)
            .map_err(|e| format!("{}: cannot read the campaign file: {e}", path.display()))?;
        toml::from_str(&src)
            .map_err(|e| format!("{}: {}", path.display(), e.to_string().trim_end()))
    }

    /// Resolve into a campaign (checks values; the phantom is not built here).
    pub fn resolve(&self) -> Result<Campaign, String> {
        let mut base = PalpationSetup {
            vtk: false,
            ..Default::default()
        };
        let p = &self.phantom;
        if let Some(v) = &p.variant {
            v.parse::<phantom::Variant>()?;
            base.variant = v.clone();
        }
        base.voxel = p.voxel.map_or(CAMPAIGN_VOXEL, |v| v.0);
        base.fat_thickness = p.fat_thickness.map_or(CAMPAIGN_FAT_THICKNESS, |v| v.0);
        if let Some(v) = p.respiratory_phase {
            base.respiratory_phase = v.0;
        }
        base.tumours = p
            .tumours
            .iter()
            .map(|t| TumourSetup {
                center: [t.center[0].0, t.center[1].0, t.center[2].0],
                radius: t.radius.0,
                stiffness: t.stiffness.0,
            })
            .collect();
        if let Some(d) = self.hand.diameter {
            base.finger_diameter = d.0;
        }
        if let Some(s) = self.hand.spacing {
            base.finger_spacing = s.0;
        }
        let sv = &self.solver;
        if let Some(e) = &sv.element {
            base.element = e.parse::<ElementChoice>()?;
        }
        for (part, e) in sv.element_by_part.iter().flatten() {
            let known =
                phantom::PART_NAMES.contains(&part.as_str()) || phantom::is_tumour_part(part);
            if !known {
                return Err(format!(
                    "solver.element_by_part: unknown part `{part}` ({}, tumour, tumour2, ...)",
                    phantom::PART_NAMES.join(", ")
                ));
            }
            let choice = e
                .parse::<ElementChoice>()
                .map_err(|m| format!("solver.element_by_part.{part}: {m}"))?;
            base.part_elements.insert(part.clone(), choice);
        }
        base.max_bulk_ratio = sv.max_bulk_ratio.map(|r| r.0);
        if let Some(f) = &sv.fidelity {
            let fid = f
                .parse::<scene::palpation::Fidelity>()
                .map_err(|e| format!("solver.fidelity: {e}"))?;
            if fid == scene::palpation::Fidelity::Fast
                && (sv.element.is_some()
                    || sv.element_by_part.is_some()
                    || sv.max_bulk_ratio.is_some()
                    || sv.precision.is_some())
            {
                return Err("solver.fidelity = \"fast\" sets the element, max_bulk_ratio and precision: give the preset or those keys".into());
            }
            fid.apply(&mut base);
            base.fidelity = fid;
        }
        if let Some(p) = &sv.precision {
            base.precision = solver::element::precision::Precision::parse(p)
                .map_err(|e| format!("solver.precision: {e}"))?;
        }
        if let Some(f) = sv.dt_factor {
            base.dt_factor = f.0;
        }
        if let Some(m) = &sv.mass_scaling {
            base.mass_scaling = solver::model::StepTarget::parse_switch(m)
                .map_err(|e| format!("solver.mass_scaling: {e}"))?;
        }
        if let Some(l) = sv.mass_scaling_limit {
            base.mass_scaling_limit = l.0;
        }
        base.vtk = sv.vtk.unwrap_or(false);
        let ind = &self.indentation;
        if let Some(t) = ind.sample_interval {
            base.sample_interval = t.0;
            if !(t.0 > 0.0 && t.0.is_finite()) {
                return Err(format!(
                    "indentation.sample_interval must be a positive finite time, got {} s",
                    t.0
                ));
            }
        }
        let max_samples = ind.max_samples.unwrap_or(DEFAULT_MAX_SAMPLES);
        if !(max_samples >= 1.0 && max_samples.is_finite()) {
            return Err(format!(
                "indentation.max_samples must be a positive finite count, got {max_samples}"
            ));
        }
        let depths: Vec<f64> = match &ind.depth {
            Some(d) => d.0.iter().map(|x| x.0).collect(),
            None => vec![base.depth],
        };
        if depths.is_empty() {
            return Err("indentation.depth: the list is empty".into());
        }
        let mut timing: Vec<Box<dyn Fn(f64) -> f64>> = Vec::new();
        match (&ind.duration, &ind.speed) {
            (Some(_), Some(_)) => {
                return Err("indentation: give `duration` or `speed`, not both".into());
            }
            (Some(d), None) => {
                for t in &d.0 {
                    let t = t.0;
                    timing.push(Box::new(move |_| t));
                }
            }
            (None, Some(s)) => {
                for v in &s.0 {
                    let v = v.0;
                    if !(v > 0.0 && v.is_finite()) {
                        return Err(format!("indentation.speed must be positive, got {v} m/s"));
                    }
                    timing.push(Box::new(move |depth| depth / v));
                }
            }
            (None, None) => {
                let t = base.duration;
                timing.push(Box::new(move |_| t));
            }
        }
        if timing.is_empty() {
            return Err("indentation: the list of durations or speeds is empty".into());
        }

        let l = &self.locations;
        let default_train = vec![LocationEntry::Name("grid".into())];
        let default_test: Vec<LocationEntry> = ["A", "B", "C"]
            .iter()
            .map(|n| LocationEntry::Name(n.to_string()))
            .collect();
        let mut locations = Vec::new();
        let rasters: Vec<(Split, Vec<CampaignLocation>)> = l
            .raster
            .iter()
            .map(raster_locations)
            .collect::<Result<_, _>>()?;
        for (split, entries) in [
            (Split::Train, l.train.as_ref().unwrap_or(&default_train)),
            (Split::Test, l.test.as_ref().unwrap_or(&default_test)),
        ] {
            for e in entries {
                locations.extend(entry_locations(e, split)?);
            }
            for (s, r) in &rasters {
                if *s == split {
                    locations.extend(r.iter().cloned());
                }
            }
        }
        if locations.is_empty() {
            return Err("locations: the campaign has no locations".into());
        }
        let mut seen = std::collections::HashSet::new();
        for a in &locations {
            if !seen.insert(a.label.as_str()) {
                return Err(format!(
                    "locations: `{}` appears twice (a location is either train or test, once)",
                    a.label
                ));
            }
        }
        let n_runs = locations
            .len()
            .saturating_mul(depths.len())
            .saturating_mul(timing.len());
        if n_runs > MAX_RUNS {
            return Err(format!(
                "the campaign has {n_runs} runs ({} locations x {} depths x {} durations or speeds), more than the limit of {MAX_RUNS}",
                locations.len(),
                depths.len(),
                timing.len()
            ));
        }

        let several = depths.len() * timing.len() > 1;
        let mut runs = Vec::new();
        let mut labels = std::collections::HashSet::new();
        for (li, loc) in locations.iter().enumerate() {
            for &depth in &depths {
                for tf in &timing {
                    let duration = tf(depth);
                    let samples = duration / base.sample_interval + 1.0;
                    if samples.is_nan() || samples > max_samples {
                        return Err(format!(
                            "indentation.sample_interval: {:e} s over a duration of {:e} s gives {samples:.3e} samples a run, more than the limit of {max_samples:.0}; use a longer interval, or raise `indentation.max_samples` if you mean it",
                            base.sample_interval, duration
                        ));
                    }
                    let label = if several {
                        format!(
                            "{}_d{}mm_t{}ms",
                            loc.label,
                            short(depth * 1e3, 3),
                            short(duration * 1e3, 3)
                        )
                    } else {
                        loc.label.clone()
                    };
                    if !labels.insert(label.clone()) {
                        return Err(format!("two runs would be labelled `{label}`: make the depths and durations distinct"));
                    }
                    runs.push(PlannedRun {
                        index: runs.len(),
                        label,
                        location: li,
                        depth,
                        duration,
                    });
                }
            }
        }
        let c = Campaign {
            title: self
                .title
                .clone()
                .unwrap_or_else(|| "palpation campaign".into()),
            base,
            locations,
            runs,
        };
        for r in &c.runs {
            c.setup(r)
                .validate()
                .map_err(|e| format!("run {}: {e}", r.label))?;
        }
        Ok(c)
    }
}

impl Campaign {
    /// The paper's protocol (the defaults of every key).
    pub fn paper() -> Campaign {
        CampaignSpec::default()
            .resolve()
            .expect("the default campaign is valid")
    }

    /// The palpation of run `r`.
    pub fn setup(&self, r: &PlannedRun) -> PalpationSetup {
        PalpationSetup {
            title: format!("{}: {}", self.title, r.label),
            place: self.locations[r.location].place.clone(),
            depth: r.depth,
            duration: r.duration,
            ..self.base.clone()
        }
    }

    /// Samples each run records: at 0, sample_interval, ... up to the duration.
    pub fn samples_per_run(&self, r: &PlannedRun) -> usize {
        (r.duration / self.base.sample_interval * (1.0 + 1e-9)).floor() as usize + 1
    }

    /// The phantom parameters every run's scene asks for (read back from the scene text, so
    /// that a phantom built from them is reused by [`build_scene_with`]).
    pub fn phantom_params(&self) -> Result<PhantomParams, String> {
        let src = self.base.scene_toml();
        let spec: SceneSpec =
            toml::from_str(&src).map_err(|e| format!("internal: campaign scene: {e}"))?;
        spec.mesh.phantom.unwrap_or_default().to_params()
    }

    /// Resolve each location on the built phantom (its skin point); an error names a location
    /// that does not exist or is not over the skin.
    pub fn resolve_locations(&self, ph: &Phantom) -> Result<Vec<Location>, String> {
        self.locations
            .iter()
            .map(|l| match &l.place {
                Place::Named(n) => ph
                    .locations
                    .get(n)
                    .cloned()
                    .ok_or_else(|| format!("location {n}: the phantom has no such location")),
                Place::At(x, y) => {
                    location_at(&ph.mesh, &ph.skin_faces, &ph.volume, &l.label, *x, *y)
                        .map_err(|e| format!("location {}: {e}", l.label))
                }
            })
            .collect()
    }

    /// Write run `r`'s `scene.toml` into `dir` and build it, reusing `phantom`.
    pub fn build_run_scene(
        &self,
        r: &PlannedRun,
        dir: &Path,
        phantom: &Phantom,
    ) -> Result<Scene, String> {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("{}: cannot create the run directory: {e}", dir.display()))?;
        let path = dir.join("scene.toml");
        let src = self.setup(r).scene_toml();
        write_atomic(&path, src.as_bytes())?;
        let spec: SceneSpec = toml::from_str(&src)
            .map_err(|e| format!("{}: {}", path.display(), e.to_string().trim_end()))?;
        build_scene_with(spec, &path, &src, Some(phantom.clone()))
    }

    /// The description of the campaign that must agree between its shards and resumed
    /// invocations: settings, phantom, resolved locations, ROI and runs (JSON).
    pub fn plan_json(&self, ph: &Phantom, locs: &[Location]) -> serde_json::Value {
        let b = &self.base;
        let p = &ph.params;
        let mut plan = json!({
            "title": self.title,
            "settings": {
                "sample_interval_s": b.sample_interval,
                "finger_diameter_m": b.finger_diameter,
                "finger_spacing_m": b.finger_spacing,
                "element": b.element.label(),
                "dt_factor": b.dt_factor,
                "mass_scaling": b.mass_scaling.map(|t| t.to_string()),
                "mass_scaling_limit": b.mass_scaling_limit,
                "vtk": b.vtk,
            },
            "phantom": phantom_json(p),
            "roi": {
                "center_m": ph.roi.center,
                "elements": ph.roi.elements,
                "centroids_m": ph.roi.centroids,
            },
            "locations": self.locations.iter().zip(locs).map(|(l, s)| json!({
                "label": l.label,
                "split": l.split.name(),
                "kind": match l.place { Place::Named(_) => "phantom", Place::At(..) => "point" },
                "surface_m": s.surface,
                "liver_depth_m": s.liver_depth,
                "under_ribs": s.under_ribs,
            })).collect::<Vec<_>>(),
            "runs": self.runs.iter().map(|r| json!({
                "index": r.index,
                "label": r.label,
                "location": self.locations[r.location].label,
                "depth_m": r.depth,
                "duration_s": r.duration,
                "samples": self.samples_per_run(r),
            })).collect::<Vec<_>>(),
        });
        // only when given, so that the plans of earlier campaigns still match on --resume
        if !b.part_elements.is_empty() {
            plan["settings"]["element_by_part"] = b
                .part_elements
                .iter()
                .map(|(k, v)| (k.clone(), json!(v.label())))
                .collect::<serde_json::Map<_, _>>()
                .into();
        }
        // The incompressibility knob changes every run's physics: part of the identity.
        if let Some(r) = b.max_bulk_ratio {
            plan["settings"]["max_bulk_ratio"] = json!(r);
        }
        // So does the kernels' precision (only when not the default, as above).
        if b.precision != solver::element::precision::Precision::F64 {
            plan["settings"]["precision"] = json!(b.precision.label());
        }
        plan
    }
}

/// The phantom parameters as JSON (SI).
pub fn phantom_json(p: &PhantomParams) -> serde_json::Value {
    json!({
        "variant": format!("{:?}", p.variant).to_lowercase(),
        "voxel_m": p.voxel,
        "fat_thickness_m": p.fat_thickness,
        "respiratory_phase": p.respiratory_phase,
        "max_liver_shift_m": p.max_liver_shift,
        "torso_m": [p.torso_width, p.torso_depth, p.torso_length],
        "coarsen": p.mesh.coarsen,
        "tumours": p.tumours.iter().map(|t| json!({
            "center_m": t.center, "radius_m": t.radius, "stiffness_factor": t.stiffness_factor,
        })).collect::<Vec<_>>(),
        "roi_radius_m": p.roi.radius,
        "roi_max_count": p.roi.max_count,
        "grid": { "center_m": p.grid.center, "spacing_m": p.grid.spacing, "n": p.grid.n },
    })
}

/// The phantom parameters back from [`phantom_json`]'s JSON (a campaign's plan, a dataset
/// manifest's `phantom.parameters`), so that the phantom of a dataset can be rebuilt without its
/// campaign file. Meshing options other than `coarsen` take their defaults, as a campaign's do;
/// the ROI centre is the default one (the liver's edge below the raster's centre) unless
/// `roi_center` names another.
pub fn phantom_params_from_json(
    v: &serde_json::Value,
    roi_center: Option<[f64; 3]>,
) -> Result<PhantomParams, String> {
    let num = |key: &str| {
        v[key]
            .as_f64()
            .ok_or_else(|| format!("phantom parameters: `{key}` is missing or not a number"))
    };
    let arr = |val: &serde_json::Value, key: &str, n: usize| -> Result<Vec<f64>, String> {
        let a = val
            .as_array()
            .filter(|a| a.len() == n)
            .ok_or_else(|| format!("phantom parameters: `{key}` is not a list of {n} numbers"))?;
        a.iter()
            .map(|x| {
                x.as_f64()
                    .ok_or_else(|| format!("phantom parameters: `{key}` holds a non-number"))
            })
            .collect()
    };
    let mut p = PhantomParams {
        variant: v["variant"]
            .as_str()
            .ok_or("phantom parameters: `variant` is missing")?
            .parse()?,
        voxel: num("voxel_m")?,
        fat_thickness: num("fat_thickness_m")?,
        respiratory_phase: num("respiratory_phase")?,
        max_liver_shift: num("max_liver_shift_m")?,
        ..Default::default()
    };
    let t = arr(&v["torso_m"], "torso_m", 3)?;
    (p.torso_width, p.torso_depth, p.torso_length) = (t[0], t[1], t[2]);
    p.mesh.coarsen = v["coarsen"].as_u64().unwrap_or(1) as usize;
    if let Some(ts) = v["tumours"].as_array() {
        for tv in ts {
            let c = arr(&tv["center_m"], "tumours.center_m", 3)?;
            p.tumours.push(phantom::Tumour {
                center: [c[0], c[1], c[2]],
                radius: tv["radius_m"]
                    .as_f64()
                    .ok_or("phantom parameters: tumour radius")?,
                stiffness_factor: tv["stiffness_factor"]
                    .as_f64()
                    .ok_or("phantom parameters: tumour stiffness")?,
            });
        }
    }
    p.roi.radius = num("roi_radius_m")?;
    p.roi.max_count = v["roi_max_count"].as_u64().map(|n| n as usize);
    let g = &v["grid"];
    let c = arr(&g["center_m"], "grid.center_m", 2)?;
    let sp = arr(&g["spacing_m"], "grid.spacing_m", 2)?;
    let n = arr(&g["n"], "grid.n", 2)?;
    p.grid = phantom::GridParams {
        center: [c[0], c[1]],
        spacing: [sp[0], sp[1]],
        n: [n[0] as usize, n[1] as usize],
    };
    if let Some(rc) = roi_center {
        // the default centre, unless the given one is elsewhere (a JSON round trip may move
        // the last digit: 1 nm decides)
        let an = phantom::Anatomy::new(&p);
        let d = an.liver_edge_point(p.grid.center[0]);
        if (0..3).any(|k| (d[k] - rc[k]).abs() > 1e-9) {
            p.roi.center = Some(rc);
        }
    }
    p.validate()?;
    Ok(p)
}

/// Parse `i/n` (0 <= i < n).
pub fn parse_shard(s: &str) -> Result<(usize, usize), String> {
    let bad = || format!("--shard: expected i/n with 0 <= i < n, e.g. 0/4, got `{s}`");
    let (i, n) = s.split_once('/').ok_or_else(bad)?;
    let (i, n): (usize, usize) = (
        i.trim().parse().map_err(|_| bad())?,
        n.trim().parse().map_err(|_| bad())?,
    );
    if n == 0 || i >= n {
        return Err(bad());
    }
    Ok((i, n))
}

/// Whether run `index` belongs to shard `(i, n)`: `index mod n == i`.
pub fn in_shard(index: usize, shard: (usize, usize)) -> bool {
    index % shard.1 == shard.0
}

/// Directory of run `label` in campaign directory `out`.
pub fn run_dir(out: &Path, label: &str) -> PathBuf {
    out.join("runs").join(label)
}

/// The marker of a finished run (`done.json`), written last and atomically.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DoneMarker {
    /// Run label.
    pub label: String,
    /// Run index in the campaign.
    pub index: usize,
    /// Run status (`completed`).
    pub status: String,
    /// Steps.
    pub steps: u64,
    /// Simulated time (s).
    pub simulated_time: f64,
    /// Wall time of the run (s).
    pub wall_seconds: f64,
    /// Worker threads of the run.
    pub threads: usize,
    /// Samples in `probe.csv`.
    pub samples: usize,
    /// When it finished (seconds since the Unix epoch).
    pub finished_unix: f64,
    /// Solver version.
    pub solver_version: String,
    /// Notes of the scene builder (e.g. the fingers' initial back-off).
    pub notes: Vec<String>,
}

/// The marker of a finished run in `dir`, if there is a readable one.
pub fn read_done(dir: &Path) -> Option<DoneMarker> {
    let s = std::fs::read_to_string(dir.join(DONE_FILE)).ok()?;
    serde_json::from_str(&s).ok()
}

/// Mark the run in `dir` finished.
pub fn write_done(dir: &Path, m: &DoneMarker) -> Result<(), String> {
    let s = serde_json::to_string_pretty(m).map_err(|e| e.to_string())?;
    write_atomic(&dir.join(DONE_FILE), s.as_bytes())
}

/// The samples of a finished run: `probe.csv` and `probe_stress.csv` of its hand `hand`.
#[derive(Clone, Debug, Default)]
pub struct RunSamples {
    /// Sample times (s).
    pub time: Vec<f64>,
    /// Hand force along the pressing direction (N), as probed at the sample time.
    pub force: Vec<f64>,
    /// The same force filtered: the centred [`FORCE_FILTER`] moving average of the run's
    /// `history.csv`, at the sample times ([`solver::output::filter`]).
    pub force_filtered: Vec<f64>,
    /// Indentation since first contact (m): `hand_depth`.
    pub depth: Vec<f64>,
    /// ROI element ids.
    pub elements: Vec<u32>,
    /// Maximum principal stress (Pa), per sample per ROI element.
    pub max_principal: Vec<Vec<f64>>,
    /// Cauchy stress (Pa), per sample per ROI element, xx, yy, zz, xy, yz, zx.
    pub tensors: Vec<Vec<[f64; 6]>>,
}

/// Read the samples of the finished run in `dir` (hand `hand`): `probe.csv`, `probe_stress.csv`
/// and, for the filtered force, `history.csv`.
pub fn read_run(dir: &Path) -> Result<RunSamples, String> {
    read_run_files(dir).map_err(|e| {
        format!(
            "{e}; the run's files are damaged: remove {} and continue with --resume to redo the run",
            dir.display()
        )
    })
}

fn read_run_files(dir: &Path) -> Result<RunSamples, String> {
    let hand = "hand";
    let p = read_probe(dir, hand)?;
    let (cols, rows) = read_history(&dir.join("probe.csv"))?;
    let depth = column(&cols, &rows, &format!("{hand}_depth")).ok_or_else(|| {
        format!(
            "{}: no column `{hand}_depth`",
            dir.join("probe.csv").display()
        )
    })?;
    let path = dir.join("history.csv");
    let (hcols, hrows) = read_history(&path)?;
    let need = |name: &str| {
        column(&hcols, &hrows, name)
            .ok_or_else(|| format!("{}: no column `{name}`", path.display()))
    };
    let force_filtered = moving_average_at(
        &need("time")?,
        &need(&format!("{hand}_reaction"))?,
        FORCE_FILTER,
        &p.time,
    );
    let path = dir.join("probe_stress.csv");
    let (tcols, trows) = read_history(&path)?;
    if trows.len() != p.time.len() {
        return Err(format!(
            "{}: {} rows, probe.csv has {}",
            path.display(),
            trows.len(),
            p.time.len()
        ));
    }
    let mut idx = Vec::with_capacity(p.elements.len());
    for e in &p.elements {
        let mut k = [0usize; 6];
        for (c, comp) in ["xx", "yy", "zz", "xy", "yz", "zx"].iter().enumerate() {
            let name = format!("e{e}_{comp}");
            k[c] = tcols
                .iter()
                .position(|x| *x == name)
                .ok_or_else(|| format!("{}: no column `{name}`", path.display()))?;
        }
        idx.push(k);
    }
    let tensors = trows
        .iter()
        .map(|row| idx.iter().map(|k| k.map(|c| row[c])).collect())
        .collect();
    Ok(RunSamples {
        time: p.time,
        force: p.force,
        force_filtered,
        depth,
        elements: p.elements,
        max_principal: p.stress,
        tensors,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The phantom parameters survive [`phantom_json`] and [`phantom_params_from_json`],
    /// tumours, raster and ROI settings included.
    #[test]
    fn phantom_params_round_trip_through_json() {
        let mut p = Campaign::paper().phantom_params().unwrap();
        p.tumours.push(phantom::Tumour {
            center: [-0.06, 0.18, 0.15],
            radius: 0.01,
            stiffness_factor: 5.0,
        });
        p.respiratory_phase = 0.25;
        p.grid.n = [3, 4];
        let text = serde_json::to_string(&phantom_json(&p)).unwrap();
        let back = phantom_params_from_json(&serde_json::from_str(&text).unwrap(), None).unwrap();
        assert_eq!(back, p);
        let mut bad: serde_json::Value = serde_json::from_str(&text).unwrap();
        bad["torso_m"] = serde_json::json!([0.3, 0.2]);
        let e = phantom_params_from_json(&bad, None).unwrap_err();
        assert!(e.contains("torso_m"), "{e}");
    }

    #[test]
    fn the_fast_fidelity_sets_the_element_and_the_cap_and_refuses_either_beside_it() {
        let spec: CampaignSpec = toml::from_str("[solver]\nfidelity = \"fast\"\n").unwrap();
        let c = spec.resolve().unwrap();
        assert_eq!(c.base.element, ElementChoice::OnePointPhysical);
        assert_eq!(c.base.max_bulk_ratio, Some(5000.0));
        let scene = c.base.scene_toml();
        assert!(scene.contains("max_bulk_ratio = 5000.0"), "{scene}");
        assert!(scene.contains("precision = \"f32\""), "{scene}");
        let spec: CampaignSpec = toml::from_str("[solver]\nprecision = \"f32\"\n").unwrap();
        let c = spec.resolve().unwrap();
        assert!(c.base.scene_toml().contains("precision = \"f32\""));
        let spec: CampaignSpec = toml::from_str("[solver]\nprecision = \"f16\"\n").unwrap();
        assert!(spec.resolve().unwrap_err().contains("solver.precision"));
        for extra in [
            "element = \"full_fbar\"",
            "max_bulk_ratio = 100",
            "precision = \"f64\"",
        ] {
            let spec: CampaignSpec =
                toml::from_str(&format!("[solver]\nfidelity = \"fast\"\n{extra}\n")).unwrap();
            let e = spec.resolve().unwrap_err();
            assert!(e.contains("solver.fidelity"), "{e}");
        }
    }

    #[test]
    fn default_is_the_paper_protocol() {
        let c = Campaign::paper();
        assert_eq!(c.runs.len(), 28);
        assert_eq!(
            c.locations
                .iter()
                .filter(|l| l.split == Split::Train)
                .count(),
            25
        );
        assert_eq!(c.runs[0].label, "P01");
        assert_eq!(c.runs[27].label, "C");
        assert_eq!(c.samples_per_run(&c.runs[0]), 6);
        // finer than a single palpation's default (CAMPAIGN_VOXEL)
        assert_eq!(c.base.voxel, 0.003);
        assert_eq!(PalpationSetup::default().voxel, phantom::DEFAULT_VOXEL);
        // thicker than a single palpation's default (CAMPAIGN_FAT_THICKNESS)
        assert_eq!(c.base.fat_thickness, 0.025);
        assert_eq!(PalpationSetup::default().fat_thickness, 0.015);
        assert!(
            (c.runs[0].depth - 0.015).abs() < 1e-15 && (c.runs[0].duration - 0.025).abs() < 1e-15
        );
    }

    #[test]
    fn shipped_paper_file_equals_the_default() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/campaign-paper.toml");
        let mut c = CampaignSpec::load(&path).unwrap().resolve().unwrap();
        assert_eq!(c.title, "paper protocol");
        c.title = Campaign::paper().title;
        assert_eq!(c, Campaign::paper());
    }

    #[test]
    fn lists_points_rasters_and_speeds() {
        let spec: CampaignSpec = toml::from_str(
            r#"
            [locations]
            train = ["P07", ["-50 mm", "190 mm"], { name = "D", at = ["-40 mm", "0.2 m"] }]
            test = ["a"]
            [[locations.raster]]
            center = ["-50 mm", "195 mm"]
            spacing = ["10 mm", "10 mm"]
            n = [2, 2]
            split = "test"
            [indentation]
            depth = ["5 mm", "10 mm"]
            speed = "1 m/s"
            "#,
        )
        .unwrap();
        let c = spec.resolve().unwrap();
        let labels: Vec<&str> = c.locations.iter().map(|l| l.label.as_str()).collect();
        assert_eq!(
            labels,
            ["P07", "at_-50_190", "D", "A", "R01", "R02", "R03", "R04"]
        );
        match c.locations[4].place {
            Place::At(x, y) => assert!((x + 0.055).abs() < 1e-12 && (y - 0.2).abs() < 1e-12),
            ref p => panic!("{p:?}"),
        }
        assert_eq!(c.runs.len(), 16);
        assert_eq!(c.runs[1].label, "P07_d10mm_t10ms");
        assert!((c.runs[1].duration - 0.010).abs() < 1e-15);
    }

    /// `element_by_part` sets the liver (and its tumours) apart; the other parts keep
    /// `element`, and the plan records the override.
    #[test]
    fn per_part_elements_reach_the_scene_and_the_plan() {
        let spec: CampaignSpec = toml::from_str(
            r#"
            [phantom]
            tumours = [{ center = ["-60 mm", "180 mm", "150 mm"], radius = "10 mm", stiffness = 5.0 }]
            [solver]
            element = "one_point"
            element_by_part = { liver = "full_fbar" }
            "#,
        )
        .unwrap();
        let c = spec.resolve().unwrap();
        let scene = c.setup(&c.runs[0]).scene_toml();
        let formulation = |part: &str| {
            let i = scene.find(&format!("name = \"{part}\"")).unwrap();
            let rest = &scene[i..];
            let j = rest.find("formulation = ").unwrap();
            rest[j..].lines().next().unwrap().to_string()
        };
        assert_eq!(formulation("liver"), "formulation = \"full_fbar\"");
        assert_eq!(formulation("tumour"), "formulation = \"full_fbar\"");
        assert_eq!(formulation("flesh"), "formulation = \"one_point\"");
        assert_eq!(formulation("ribs"), "formulation = \"one_point\"");
        let ph = phantom::build(&PhantomParams {
            voxel: 0.012,
            ..c.phantom_params().unwrap()
        })
        .unwrap();
        let plan = c.plan_json(&ph, &[]);
        assert_eq!(plan["settings"]["element_by_part"]["liver"], "full-fbar");
        let plain = Campaign::paper().plan_json(&ph, &[]);
        assert!(plain["settings"].get("element_by_part").is_none());
        assert!(plain["settings"].get("max_bulk_ratio").is_none());
        let fast: CampaignSpec = toml::from_str("[solver]\nfidelity = \"fast\"\n").unwrap();
        let fast = fast.resolve().unwrap().plan_json(&ph, &[]);
        assert_eq!(fast["settings"]["max_bulk_ratio"], 5000.0);
        assert_eq!(fast["settings"]["element"], "1pt-physical");
    }

    #[test]
    fn errors_name_the_problem() {
        let e = toml::from_str::<CampaignSpec>("[indentation]\ndepth = \"5 ms\"\n").unwrap_err();
        assert!(e.to_string().contains("length"), "{e}");
        let e = toml::from_str::<CampaignSpec>("[phantom]\nvoxels = \"5 mm\"\n").unwrap_err();
        assert!(e.to_string().contains("voxels"), "{e}");
        let spec: CampaignSpec = toml::from_str("[locations]\ntrain = [\"A\"]\n").unwrap();
        assert!(spec.resolve().unwrap_err().contains("twice"));
        let spec: CampaignSpec = toml::from_str("[locations]\ntrain = [\"Q9\"]\n").unwrap();
        assert!(spec.resolve().unwrap_err().contains("unknown location"));
        let spec: CampaignSpec =
            toml::from_str("[solver]\nelement_by_part = { livers = \"full_fbar\" }\n").unwrap();
        assert!(spec
            .resolve()
            .unwrap_err()
            .contains("unknown part `livers`"));
        let spec: CampaignSpec =
            toml::from_str("[solver]\nelement_by_part = { liver = \"fbar2\" }\n").unwrap();
        let e = spec.resolve().unwrap_err();
        assert!(
            e.contains("element_by_part.liver") && e.contains("fbar2"),
            "{e}"
        );
        assert_eq!(parse_shard("1/3").unwrap(), (1, 3));
        assert!(parse_shard("3/3").is_err());
    }

    /// Found while writing the campaign fuzz harness (docs/fuzzing.md), confirmed through it: a
    /// raster of 1e5 x 1e5 points was built point by point (hundreds of GiB) before anything
    /// checked its size.
    #[test]
    fn a_campaign_with_a_huge_raster_is_an_error_not_a_hang() {
        let spec: CampaignSpec = toml::from_str(
            r#"
            [locations]
            raster = [{ center = [0, 0.2], spacing = ["1 mm", "1 mm"], n = [100000, 100000], split = "train" }]
            "#,
        )
        .unwrap();
        let t = std::time::Instant::now();
        let e = spec.resolve().unwrap_err();
        assert!(t.elapsed().as_secs_f64() < 1.0);
        assert!(
            e.contains("n = [100000, 100000]") && e.contains("limit of 10000 runs"),
            "{e}"
        );
    }

    /// Found with it too: hundreds of depths times hundreds of durations made millions of runs,
    /// each label compared with every earlier one (a hang).
    #[test]
    fn a_campaign_with_too_many_runs_is_an_error_not_a_hang() {
        let list = |unit: &str| {
            (1..=400)
                .map(|k| format!("\"{k} {unit}\""))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let src = format!(
            "[indentation]\ndepth = [{}]\nduration = [{}]\n",
            list("um"),
            list("ms")
        );
        let spec: CampaignSpec = toml::from_str(&src).unwrap();
        let t = std::time::Instant::now();
        let e = spec.resolve().unwrap_err();
        assert!(t.elapsed().as_secs_f64() < 1.0);
        assert!(
            e.contains("4480000 runs (28 locations x 400 depths x 400 durations or speeds)")
                && e.contains("limit of 10000"),
            "{e}"
        );
        // at the limit, the plan is built
        let list = |n: usize, unit: &str| {
            (1..=n)
                .map(|k| format!("\"{k} {unit}\""))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let src = format!(
            "[locations]\ntrain = [\"A\"]\ntest = [\"B\"]\n[indentation]\ndepth = [{}]\nduration = [{}]\n",
            list(100, "um"),
            list(50, "ms")
        );
        let spec: CampaignSpec = toml::from_str(&src).unwrap();
        assert_eq!(spec.resolve().unwrap().runs.len(), MAX_RUNS);
    }
}
