//! The campaign file ([`CampaignSpec`]; the format is in the crate doc) and its resolution into
//! a [`Campaign`]: locations in order, each train or test, and the runs.

use crate::design::DesignSpec;
use crate::label::check_label;
use crate::phase::check_phase;
use crate::plan::{Campaign, CampaignLocation, PlannedRun, Split};
use material::quantity::{Length, Number, Time, Velocity};
use phantom::PAPER_VOXEL;
use scene::palpation::{ElementChoice, PalpationSetup, Place};
use scene::phantom_spec::PhantomScene;
use serde::{Deserialize, Deserializer};
use std::path::Path;

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
    pub phantom: PhantomScene,
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
    pub split: Split,
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
    /// Space-filling designs (Sobol, Latin hypercube or seeded uniform random).
    #[serde(default)]
    pub design: Vec<DesignSpec>,
    /// Respiratory phases (0 exhalation .. 1 inspiration): every location without a phase of
    /// its own (a design's `phase` range gives one) is pressed at each, labelled
    /// `<label>-ph<phase>` (a respiratory campaign).
    pub phases: Option<Vec<Number>>,
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
    /// initial"`, a time step, or `"off"`; not beside `fidelity = "fast"`, which sets it.
    pub mass_scaling: Option<String>,
    /// Largest added mass fraction (default 0.05).
    pub mass_scaling_limit: Option<Number>,
    /// Write VTK frames of every run (default false).
    pub vtk: Option<bool>,
    /// Preset of the accuracy knobs: `standard` (default) or `fast` (1pt-physical elements,
    /// K/G capped at 5000, f32 kernels, mass scaling to 1.3x the initial step; not with
    /// `element`, `element_by_part`, `max_bulk_ratio`, `precision` or `mass_scaling`).
    pub fidelity: Option<String>,
    /// Element-kernel precision, `"f64"` or `"f32"` (default: the preset's).
    pub precision: Option<String>,
    /// The incompressibility knob: cap every part's bulk modulus at this multiple of its
    /// shear modulus (as `palpate --max-bulk-ratio`).
    pub max_bulk_ratio: Option<Number>,
    /// Subcycling's largest macro ratio, a power of two (as `palpate --subcycle`; 1, the
    /// default, is off).
    pub subcycling: Option<u32>,
    /// How the stable step is estimated, `"element"` (default) or `"global"` (as
    /// `palpate --step-estimate`).
    pub step_estimate: Option<String>,
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

fn entry_locations(e: &LocationEntry, split: Split) -> Result<Vec<CampaignLocation>, String> {
    let named = |n: &str| CampaignLocation {
        label: n.to_string(),
        split,
        place: Place::Named(n.to_string()),
        phase: None,
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
                phase: None,
            }]
        }
        LocationEntry::Named(p) => {
            check_label(&p.name)?;
            vec![CampaignLocation {
                label: p.name.clone(),
                split,
                place: Place::At(p.at[0].0, p.at[1].0),
                phase: None,
            }]
        }
    })
}

fn raster_locations(r: &RasterSpec) -> Result<(Split, Vec<CampaignLocation>), String> {
    let split = r.split;
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
            phase: None,
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
        toml::from_str(&src).map_err(|e| material::toml_error::describe(path, &src, &e))
    }

    /// Resolve into a campaign (checks values; the phantom is not built here).
    pub fn resolve(&self) -> Result<Campaign, String> {
        let mut base = PalpationSetup {
            vtk: false,
            ..Default::default()
        };
        self.apply_phantom_and_hand(&mut base)?;
        apply_solver(&self.solver, &mut base)?;
        let (depths, timing, max_samples) = indentation(&self.indentation, &mut base)?;
        let locations = resolve_locations(&self.locations)?;
        let runs = plan_runs(&locations, &depths, &timing, &base, max_samples)?;
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

    /// `[phantom]` and `[hand]` into the palpation settings.
    fn apply_phantom_and_hand(&self, base: &mut PalpationSetup) -> Result<(), String> {
        let p = &self.phantom;
        // a scene's [mesh.phantom] table, less what every run of a campaign shares by default
        for (given, key) in [
            (p.coarsen.is_some(), "coarsen"),
            (p.roi_radius.is_some(), "roi_radius"),
            (p.roi_count.is_some(), "roi_count"),
        ] {
            if given {
                return Err(format!(
                    "phantom.{key}: not a campaign key (a campaign's runs mesh the phantom and pick its ROI with the defaults)"
                ));
            }
        }
        if let Some(v) = &p.variant {
            v.parse::<phantom::Variant>()?;
            base.variant = v.clone();
        }
        base.voxel = p.voxel.map_or(CAMPAIGN_VOXEL, |v| v.0);
        base.fat_thickness = p.fat_thickness.map_or(CAMPAIGN_FAT_THICKNESS, |v| v.0);
        if let Some(v) = p.respiratory_phase {
            base.respiratory_phase = v.0;
        }
        if let Some(s) = &p.skin {
            base.skin = s
                .parse::<phantom::Skin>()
                .map_err(|e| format!("phantom.skin: {e}"))?;
        }
        base.tumours = p
            .tumours
            .iter()
            .map(|t| phantom::Tumour {
                center: [t.center[0].0, t.center[1].0, t.center[2].0],
                radius: t.radius.0,
                stiffness_factor: t.stiffness.0,
            })
            .collect();
        if let Some(d) = self.hand.diameter {
            base.finger_diameter = d.0;
        }
        if let Some(s) = self.hand.spacing {
            base.finger_spacing = s.0;
        }
        Ok(())
    }
}

/// `[solver]` into the palpation settings: element (per part), the fidelity preset, precision,
/// step factor, mass scaling and VTK output.
fn apply_solver(sv: &SolverSpec, base: &mut PalpationSetup) -> Result<(), String> {
    if let Some(e) = &sv.element {
        base.element = e.parse::<ElementChoice>()?;
    }
    for (part, e) in sv.element_by_part.iter().flatten() {
        let known = phantom::PART_NAMES.contains(&part.as_str()) || phantom::is_tumour_part(part);
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
                || sv.precision.is_some()
                || sv.mass_scaling.is_some())
        {
            return Err(scene::palpation::Fidelity::fast_conflict(
                "solver.fidelity = \"fast\"",
                false,
            ));
        }
        fid.apply(base);
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
    if let Some(k) = sv.subcycling {
        if !(1..=1024).contains(&k) || !k.is_power_of_two() {
            return Err(format!(
                "solver.subcycling: must be a power of two from 1 (off) to 1024, got {k}"
            ));
        }
        base.subcycling = k;
    }
    if let Some(s) = &sv.step_estimate {
        base.step_estimate = solver::simulation::StepEstimate::parse(s)
            .map_err(|e| format!("solver.step_estimate: {e}"))?;
        if base.subcycling > 1 && base.step_estimate != solver::simulation::StepEstimate::Element {
            return Err(
                "solver.step_estimate: \"global\" cannot be combined with solver.subcycling".into(),
            );
        }
    }
    base.vtk = sv.vtk.unwrap_or(false);
    Ok(())
}

/// The time of an indentation to a depth (s).
type Timing = Box<dyn Fn(f64) -> f64>;

/// `[indentation]`: the sample interval (into `base`), the depths, the timings (a duration or a
/// speed each) and the most samples a run may record.
fn indentation(
    ind: &IndentationSpec,
    base: &mut PalpationSetup,
) -> Result<(Vec<f64>, Vec<Timing>, f64), String> {
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
    let mut timing: Vec<Timing> = Vec::new();
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

    Ok((depths, timing, max_samples))
}

/// `[locations]`: train entries, train rasters, train designs, then the same for test, each
/// label once.
fn resolve_locations(l: &LocationsSpec) -> Result<Vec<CampaignLocation>, String> {
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
    let designs: Vec<Vec<CampaignLocation>> = l
        .design
        .iter()
        .enumerate()
        .map(|(k, d)| {
            d.locations()
                .map_err(|e| format!("[[locations.design]] number {}: {e}", k + 1))
        })
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
        for (d, pts) in l.design.iter().zip(&designs) {
            if d.split == split {
                locations.extend(pts.iter().cloned());
            }
        }
    }
    if locations.is_empty() {
        return Err("locations: the campaign has no locations".into());
    }
    if let Some(phases) = &l.phases {
        locations = cross_phases(locations, phases)?;
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
    Ok(locations)
}

/// Every location without a phase of its own at each of `phases` (in that order, labelled
/// `<label>-ph<phase>`), the others as they are.
fn cross_phases(
    locations: Vec<CampaignLocation>,
    phases: &[Number],
) -> Result<Vec<CampaignLocation>, String> {
    if phases.is_empty() {
        return Err("locations.phases: the list is empty".into());
    }
    for p in phases {
        check_phase(p.0, "locations.phases")?;
    }
    let mut out = Vec::new();
    for l in locations {
        if l.phase.is_some() {
            out.push(l);
            continue;
        }
        for p in phases {
            out.push(CampaignLocation {
                label: format!("{}-ph{}", l.label, short(p.0, 3)),
                phase: Some(p.0),
                ..l.clone()
            });
        }
    }
    Ok(out)
}

/// The runs: locations x depths x timings, in that order, within [`MAX_RUNS`] and the sample
/// limit, each label once.
fn plan_runs(
    locations: &[CampaignLocation],
    depths: &[f64],
    timing: &[Timing],
    base: &PalpationSetup,
    max_samples: f64,
) -> Result<Vec<PlannedRun>, String> {
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
        for &depth in depths {
            for tf in timing {
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
    Ok(runs)
}

impl Campaign {
    /// The paper's protocol (the defaults of every key).
    pub fn paper() -> Campaign {
        CampaignSpec::default()
            .resolve()
            .expect("the default campaign is valid")
    }
}
