//! A resolved campaign ([`Campaign`]: locations, runs, the settings they share) and its plan
//! ([`CampaignPlan`]): the campaign on its built phantom, in SI, as `campaign.json` records it.
//! Shards and resumed invocations of one campaign must have the same plan; `palpa campaign
//! merge` and the dataset read it back. Every field is typed; the file's keys are sorted (the
//! plan is written through [`serde_json::Value`]), so that a plan reads back to the same bytes.

use crate::phantom_record::PhantomRecord;
use phantom::{location_at, Location, Phantom, PhantomParams};
use scene::palpation::{PalpationSetup, Place};
use scene::Scene;
use serde::{Deserialize, Serialize};
use solver::element::precision::Precision;
use solver::simulation::StepEstimate;
use std::collections::BTreeMap;
use std::path::Path;
pub use surrogate::Split;

/// Where scene file `there` (TOML) parts from `here` as a palpation: the first key whose value
/// differs, whatever the files' layout, once `[run] title` is left out of both
/// ([`crate::first_difference`]); `None` when they give the same palpation.
fn palpation_difference(there: &str, here: &str) -> Option<String> {
    let untitled = |s: &str| -> Result<serde_json::Value, String> {
        let mut t: toml::Table = s.parse().map_err(|e: toml::de::Error| {
            format!("not a scene file: {}", e.message().replace('\n', " "))
        })?;
        if let Some(run) = t.get_mut("run").and_then(|r| r.as_table_mut()) {
            run.remove("title");
        }
        serde_json::to_value(t).map_err(|e| e.to_string())
    };
    match (untitled(there), untitled(here)) {
        (Ok(x), Ok(y)) => crate::difference::first_difference(&x, &y, "scene"),
        (Err(e), _) => Some(e),
        (_, Err(e)) => Some(format!("the planned scene: {e}")),
    }
}

/// A respiratory run's file of its ROI: the element ids of its own mesh that carry the
/// reference ROI's points, in the ROI's order (`{"roi_elements": [...]}`).
pub const ROI_MAP_FILE: &str = "roi_map.json";

/// One location of a campaign.
#[derive(Clone, Debug, PartialEq)]
pub struct CampaignLocation {
    /// Label (a phantom location's name, or the point's name).
    pub label: String,
    /// Train or test.
    pub split: Split,
    /// Where the fingers press.
    pub place: Place,
    /// The respiratory phase it is pressed at (0 exhalation .. 1 inspiration); `None`: the
    /// phantom's own (`[phantom] respiratory_phase`, the ROI's reference frame).
    pub phase: Option<f64>,
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

impl Campaign {
    /// The runs of `shard` (all runs when `None`), in order.
    pub fn runs_of(&self, shard: Option<(usize, usize)>) -> Vec<&PlannedRun> {
        self.runs
            .iter()
            .filter(|r| shard.is_none_or(|s| crate::shard::in_shard(r.index, s)))
            .collect()
    }

    /// Why the run directory of `r` in `out` does not hold the palpation this plan gives `r`;
    /// `None` when it does: its `scene.toml` equals the one [`Campaign::setup`] writes, key for
    /// key, but for the run's title (which names the campaign: a run copied from another
    /// campaign that plans the same palpation, e.g. a Sobol design's first points into an
    /// adaptive one, is the same run).
    pub fn unlike_plan(&self, out: &std::path::Path, r: &PlannedRun) -> Option<String> {
        let path = crate::run_files::run_dir(out, &r.label).join("scene.toml");
        match std::fs::read_to_string(path) {
            Ok(there) => palpation_difference(&there, &self.setup(r).scene_toml()),
            Err(e) => Some(format!("cannot read it: {e}")),
        }
    }

    /// The palpation of run `r`.
    pub fn setup(&self, r: &PlannedRun) -> PalpationSetup {
        let loc = &self.locations[r.location];
        PalpationSetup {
            title: format!("{}: {}", self.title, r.label),
            place: loc.place.clone(),
            depth: r.depth,
            duration: r.duration,
            respiratory_phase: loc.phase.unwrap_or(self.base.respiratory_phase),
            ..self.base.clone()
        }
    }

    /// Whether some location is pressed at a phase of its own (a respiratory campaign: its
    /// dataset has a `phase` input column).
    pub fn is_respiratory(&self) -> bool {
        self.locations.iter().any(|l| l.phase.is_some())
    }

    /// Samples each run records: at 0, sample_interval, ... up to the duration.
    pub fn samples_per_run(&self, r: &PlannedRun) -> usize {
        (r.duration / self.base.sample_interval * (1.0 + 1e-9)).floor() as usize + 1
    }

    /// The phantom parameters every run's scene asks for (so that a phantom built from them is
    /// reused by every run).
    pub fn phantom_params(&self) -> Result<PhantomParams, String> {
        self.base.phantom_params()
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

    /// Write run `r`'s `scene.toml` into `dir` and build it, reusing `phantom` (the campaign's
    /// phantom, at its reference phase).
    ///
    /// A run at a phase of its own builds that phase's phantom, carries the reference ROI onto
    /// it with the liver ([`Phantom::carry_roi_from`]) and writes the carried element ids, in
    /// the ROI's order, to [`ROI_MAP_FILE`]; a named location (A, B, ...) is pressed at the
    /// reference phantom's skin point, so that it stays one place of the body while the liver
    /// moves under it. The run's `scene.toml` names the phase, so `palpa run` on it rebuilds
    /// that phantom, but with the phase's own ROI, not the carried one.
    pub fn build_run_scene(
        &self,
        r: &PlannedRun,
        dir: &Path,
        phantom: &Phantom,
    ) -> Result<Scene, String> {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("{}: cannot create the run directory: {e}", dir.display()))?;
        let mut setup = self.setup(r);
        if self.locations[r.location].phase.is_none() {
            return setup.build_scene(dir, Some(phantom.clone()));
        }
        let mut ph = if setup.respiratory_phase == phantom.params.respiratory_phase {
            phantom.clone()
        } else {
            phantom::build(&PhantomParams {
                respiratory_phase: setup.respiratory_phase,
                ..phantom.params.clone()
            })
            .map_err(|e| {
                format!(
                    "run {}: the phantom at phase {}: {e}",
                    r.label, setup.respiratory_phase
                )
            })?
        };
        ph.carry_roi_from(&phantom.roi, phantom.params.liver_shift())
            .map_err(|e| format!("run {}: {e}", r.label))?;
        if let Place::Named(n) = &setup.place {
            let at = phantom
                .locations
                .get(n)
                .ok_or_else(|| format!("location {n}: the phantom has no such location"))?
                .surface;
            setup.place = Place::At(at[0], at[1]);
        }
        let map = serde_json::json!({ "roi_elements": ph.roi.elements });
        solver::output::atomic::write_atomic(&dir.join(ROI_MAP_FILE), map.to_string().as_bytes())?;
        setup.build_scene(dir, Some(ph))
    }

    /// The plan of this campaign on the built phantom `ph` with its resolved locations `locs`:
    /// what must agree between its shards and resumed invocations.
    pub fn plan(&self, ph: &Phantom, locs: &[Location]) -> CampaignPlan {
        let b = &self.base;
        CampaignPlan {
            title: self.title.clone(),
            settings: PlanSettings {
                sample_interval_s: b.sample_interval,
                finger_diameter_m: b.finger_diameter,
                finger_spacing_m: b.finger_spacing,
                element: b.element.label().into(),
                dt_factor: b.dt_factor,
                mass_scaling: b.mass_scaling.map(|t| t.to_string()),
                mass_scaling_limit: b.mass_scaling_limit,
                vtk: b.vtk,
                // only when given, so that the plans of earlier campaigns still match on --resume
                element_by_part: b
                    .part_elements
                    .iter()
                    .map(|(k, v)| (k.clone(), v.label().to_string()))
                    .collect(),
                // the incompressibility knob changes every run's physics: part of the identity
                max_bulk_ratio: b.max_bulk_ratio,
                // so does the kernels' precision (only when not the default, as above)
                precision: (b.precision != Precision::F64).then(|| b.precision.label().into()),
                // and subcycling's integration (only when on)
                subcycling: (b.subcycling > 1).then_some(b.subcycling),
                // and the step (only when not the default)
                step_estimate: (b.step_estimate != StepEstimate::Element)
                    .then(|| b.step_estimate.name().into()),
            },
            phantom: PhantomRecord::of(&ph.params),
            roi: PlanRoi {
                center_m: ph.roi.center,
                elements: ph.roi.elements.clone(),
                centroids_m: ph.roi.centroids.clone(),
            },
            locations: self
                .locations
                .iter()
                .zip(locs)
                .map(|(l, s)| PlanLocation {
                    label: l.label.clone(),
                    split: l.split,
                    kind: match l.place {
                        Place::Named(_) => PlaceKind::Phantom,
                        Place::At(..) => PlaceKind::Point,
                    },
                    surface_m: s.surface,
                    liver_depth_m: s.liver_depth,
                    under_ribs: s.under_ribs,
                    phase: l.phase,
                })
                .collect(),
            runs: self
                .runs
                .iter()
                .map(|r| PlanRun {
                    index: r.index,
                    label: r.label.clone(),
                    location: self.locations[r.location].label.clone(),
                    depth_m: r.depth,
                    duration_s: r.duration,
                    samples: self.samples_per_run(r),
                })
                .collect(),
        }
    }
}

/// The plan of a campaign: settings, phantom, ROI, resolved locations and runs (SI).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CampaignPlan {
    /// Title.
    pub title: String,
    /// The palpation settings every run shares.
    pub settings: PlanSettings,
    /// The phantom's parameters.
    pub phantom: PhantomRecord,
    /// The region of interest whose stress the dataset holds.
    pub roi: PlanRoi,
    /// Locations in order, with their skin points.
    pub locations: Vec<PlanLocation>,
    /// Runs in order.
    pub runs: Vec<PlanRun>,
}

/// The palpation settings of a plan.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlanSettings {
    /// Sample interval (s).
    pub sample_interval_s: f64,
    /// Finger diameter (m).
    pub finger_diameter_m: f64,
    /// Finger spacing (m).
    pub finger_spacing_m: f64,
    /// Element formulation (`one_point`, `stiffness`, `full_fbar`, ...).
    pub element: String,
    /// Time-step factor.
    pub dt_factor: f64,
    /// Mass-scaling target (`initial`, `2 x initial`, `4 us`), `None` when off.
    pub mass_scaling: Option<String>,
    /// Added mass (fraction of a part's mass) at which a run stops.
    pub mass_scaling_limit: f64,
    /// Whether runs write VTK frames.
    pub vtk: bool,
    /// Per-part formulations; absent from the file when empty.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub element_by_part: BTreeMap<String, String>,
    /// The K/G cap; absent when none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_bulk_ratio: Option<f64>,
    /// The element kernels' precision; absent when `f64` (the default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub precision: Option<String>,
    /// Subcycling's largest macro ratio; absent when off (the default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub subcycling: Option<u32>,
    /// How the stable step is estimated; absent when element by element (the default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step_estimate: Option<String>,
}

/// The ROI of a plan.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlanRoi {
    /// Its centre (m).
    pub center_m: [f64; 3],
    /// Element ids, nearest to the centre first.
    pub elements: Vec<u32>,
    /// Element centroids (m), in the same order.
    pub centroids_m: Vec<[f64; 3]>,
}

/// How a location was given.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PlaceKind {
    /// A location of the phantom (A, B, C, P01..P25).
    Phantom,
    /// A point (x, y) of the skin.
    Point,
}

/// One location of a plan.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlanLocation {
    /// Label.
    pub label: String,
    /// Train or test.
    pub split: Split,
    /// How it was given.
    pub kind: PlaceKind,
    /// Its skin point (m).
    pub surface_m: [f64; 3],
    /// Depth of the liver below it (m), `None` where no liver is below.
    pub liver_depth_m: Option<f64>,
    /// Whether ribs lie between skin and liver (at the reference phase).
    pub under_ribs: bool,
    /// The respiratory phase it is pressed at; absent when the phantom's own.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub phase: Option<f64>,
}

/// One run of a plan.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlanRun {
    /// Position in the campaign's order (0-based).
    pub index: usize,
    /// Directory name under `runs/`.
    pub label: String,
    /// Its location's label.
    pub location: String,
    /// Indentation depth (m).
    pub depth_m: f64,
    /// Time to reach it (s).
    pub duration_s: f64,
    /// Samples it records.
    pub samples: usize,
}

impl CampaignPlan {
    /// The plan as JSON, keys sorted.
    pub fn to_value(&self) -> serde_json::Value {
        serde_json::to_value(self).expect("a plan is plain data")
    }

    /// Read a plan from JSON; an error names the missing or malformed key.
    pub fn from_value(v: &serde_json::Value) -> Result<CampaignPlan, String> {
        serde_path_to_error::deserialize(v)
            .map_err(|e| format!("the plan: {}", crate::phantom_record::at_key(&e)))
    }

    /// Whether some location is pressed at a phase of its own ([`Campaign::is_respiratory`]).
    pub fn is_respiratory(&self) -> bool {
        self.locations.iter().any(|l| l.phase.is_some())
    }

    /// The run labelled `label`.
    pub fn run(&self, label: &str) -> Result<&PlanRun, String> {
        self.runs
            .iter()
            .find(|r| r.label == label)
            .ok_or_else(|| format!("campaign.json: no run `{label}`"))
    }
}

#[cfg(test)]
mod tests {
    use super::palpation_difference;

    #[test]
    fn a_palpation_is_the_same_whatever_its_title_and_layout() {
        let a = "[run]\ntitle = \"Sobol: S001\"\nend_time = \"0.025 s\"\n\n[[hand]]\nat = [\"0.1 m\", \"0.2 m\"]\n";
        let b = "[run]\nend_time = \"0.025 s\"\ntitle = \"adaptive: S001\"\n[[hand]]\nat = [ \"0.1 m\", \"0.2 m\" ]\n";
        assert_eq!(palpation_difference(a, b), None);
        // an integer and a float of the same value are one palpation; another value is not
        let c = |v: &str| format!("{a}[phantom]\nfat_scale = {v}\n");
        assert_eq!(palpation_difference(&c("1"), &c("1.0")), None);
        assert_eq!(
            palpation_difference(&c("1"), &c("1.5")).as_deref(),
            Some("scene.phantom.fat_scale: 1 there, 1.5 here")
        );
        assert_eq!(
            palpation_difference(a, &b.replace("0.2 m", "0.21 m")).as_deref(),
            Some("scene.hand[0].at[1]: \"0.2 m\" there, \"0.21 m\" here")
        );
        assert_eq!(
            palpation_difference(a, &b.replace("0.025 s", "0.03 s")).as_deref(),
            Some("scene.run.end_time: \"0.025 s\" there, \"0.03 s\" here")
        );
        let bad = palpation_difference("[run\n", b).unwrap();
        assert!(
            bad.starts_with("not a scene file") && !bad.contains('\n'),
            "{bad}"
        );
    }
}
