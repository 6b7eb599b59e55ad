//! Palpation campaigns: many palpations of one phantom, the raw material of a surrogate's
//! training dataset (`palpa campaign`).
//!
//! A campaign is a [`CampaignSpec`] (a TOML file, or the paper's protocol when none is given)
//! resolved into a [`Campaign`]: a list of locations, each labelled train or test, and a list of
//! [`PlannedRun`]s, the product of locations x depths x durations in a fixed order. On its built
//! phantom it has a [`CampaignPlan`], which `campaign.json` records. Every run is an ordinary
//! palpation ([`scene::palpation::PalpationSetup`]), built in memory, its `scene.toml` written
//! into its own directory `DIR/runs/<label>/` and run there ([`execute`]; a run at a respiratory
//! phase of its own reads the campaign's ROI through the points carried with the liver, which its
//! `scene.toml` alone does not reproduce, see [`Campaign::build_run_scene`]); a run is finished
//! when its `done.json` ([`DoneMarker`]) exists, written atomically after everything else. A
//! directory without it is an interrupted or failed run and is redone from scratch. The
//! finished runs make the dataset ([`assemble`]); the shards of a campaign join by [`merge`].
//! While a campaign runs, [`assemble_finished`] reads the dataset of its finished prefix (for
//! `palpa front`), and [`stray_runs`] names finished runs its plan does not name.
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
//! skin = "voxel"                   # or "fitted": the skin one node layer on the outline
//! tumours = [{ center = ["-60 mm", "180 mm", "150 mm"], radius = "10 mm", stiffness = 5.0 }]
//!
//! [locations]
//! train = ["grid"]                 # "grid" = P01..P25; names A, B, C, P01..P25;
//!                                  # points ["-50 mm", "190 mm"]; { name = "D", at = [x, y] }
//! test = ["A", "B", "C"]
//! # phases = [0.0, 0.5, 1.0]       # respiratory phases: each location (without a phase of its
//!                                  # own) at each, labelled A-ph0, A-ph0.5, ... (module `plan`)
//! [[locations.raster]]             # optional further rasters of points (x, y of the skin)
//! center = ["-50 mm", "195 mm"]
//! spacing = ["10 mm", "10 mm"]
//! n = [3, 3]
//! split = "train"                  # or "test"
//! prefix = "R"                     # names R01, R02, ... (cranial row first, then by x)
//! [[locations.design]]             # optional space-filling designs (module `design`)
//! kind = "sobol"                   # or "lhs" (Latin hypercube), "random" (uniform)
//! n = 50
//! seed = 1
//! split = "train"                  # or "test"
//! prefix = "S"                     # names S01, S02, ... (default S sobol, L lhs, U random)
//! # extent = [["-100 mm", "165 mm"], ["0 mm", "225 mm"]]   # the default: the ROI's plan extent
//! # polygon = [["-100 mm", "165 mm"], ["0 mm", "165 mm"], ["-50 mm", "225 mm"]]   # not lhs
//! # phase = [0.0, 1.0]             # a design over (x, y, phase): each point its own phase
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
//! # fidelity = "fast"             # 1pt-physical, K/G <= 5000, f32, 1.3x mass scaling (docs/palpate.md)
//! # precision = "f32"              # element kernels: f64 (default) | f32
//! # max_bulk_ratio = 5000           # or the K/G cap alone
//! # subcycling = 16                # the liver's interior on a 16x longer step (docs/palpate.md)
//! # step_estimate = "global"       # the mesh's own critical step (docs/performance.md)
//! vtk = false                      # VTK frames of every run (off: only the probe files)
//! ```
//!
//! # Order, labels and shards
//! Locations come in the order train entries, train rasters, test entries, test rasters; runs
//! loop over locations, then depths, then durations. A run's label is its location's label, or
//! `<location>_d<depth>mm_t<duration>ms` when the campaign has more than one depth or duration.
//! Run `k` (0-based, in this order) belongs to shard `k mod n` ([`in_shard`]).

mod adaptive;
mod assemble;
mod design;
mod difference;
mod dir;
mod execute;
mod finished;
mod json_file;
mod label;
mod merge;
mod outcome;
mod phantom_record;
mod phase;
mod plan;
mod run_files;
mod shard;
mod spec;

pub use adaptive::{
    batch_label, check_adaptive, extend, is_batch_label, next_batch, AdaptiveBatch, AdaptivePoint,
    AdaptiveRecord, ADAPTIVE_FILE, CANDIDATES, CANDIDATE_SEED, FORCE_POINTS, MIN_SEPARATION,
};
pub use assemble::{assemble, write_dataset};
pub use design::{default_extent, DesignKind, DesignSpec, Region, MAX_DESIGN_POINTS};
pub use difference::first_difference;
pub use dir::{campaign_file, prepare_dir, read_campaign_dir, write_campaign_file, CampaignDir};
pub use execute::{execute, run_one, Parallelism, Report, RunEvent};
pub use finished::{assemble_finished, finished_prefix, not_a_shard, FinishedPrefix, Prefix};
pub use json_file::{read_json, write_json};
pub use merge::{merge, MergeReport};
pub use outcome::{finish, Outcome};

pub use phantom_record::{GridRecord, PhantomRecord};
pub use plan::{
    Campaign, CampaignLocation, CampaignPlan, PlaceKind, PlanLocation, PlanRoi, PlanRun,
    PlanSettings, PlannedRun, Split,
};
pub use run_files::{
    discard_run, is_finished, read_done, read_run, run_dir, runs_dir, stray_runs, write_done,
    DoneMarker, RunSamples,
};
pub use shard::{in_shard, parse_shard, recorded_shard, resolve_shard, shard_in};
pub use spec::{
    CampaignSpec, HandSpec, IndentationSpec, LocationEntry, LocationsSpec, NamedPoint, OneOrMany,
    RasterSpec, SolverSpec, CAMPAIGN_FAT_THICKNESS, CAMPAIGN_VOXEL, DEFAULT_MAX_SAMPLES, MAX_RUNS,
};

/// Name of the marker file of a finished run.
pub const DONE_FILE: &str = "done.json";
/// Name of the campaign description in a campaign directory.
pub const CAMPAIGN_FILE: &str = "campaign.json";
/// Value of the `format` key of [`CAMPAIGN_FILE`].
pub const CAMPAIGN_FORMAT: &str = "palpa-campaign";

#[cfg(test)]
mod tests {
    use super::*;
    use phantom::PhantomParams;
    use scene::palpation::{ElementChoice, PalpationSetup, Place};
    use std::path::Path;

    /// The phantom parameters survive [`PhantomRecord::of`] and [`PhantomRecord::to_params`]
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
        let text = serde_json::to_string(&PhantomRecord::of(&p)).unwrap();
        let back = PhantomRecord::from_value(&serde_json::from_str(&text).unwrap())
            .unwrap()
            .to_params(None)
            .unwrap();
        assert_eq!(back, p);
        let mut bad: serde_json::Value = serde_json::from_str(&text).unwrap();
        bad["torso_m"] = serde_json::json!([0.3, 0.2]);
        let e = PhantomRecord::from_value(&bad).unwrap_err();
        assert!(e.contains("torso_m"), "{e}");
        // a voxel skin is not written (plans from before the fitted skin read the same), a
        // fitted one is, and comes back
        assert!(!text.contains("skin"), "{text}");
        p.skin = phantom::Skin::Fitted;
        let text = serde_json::to_string(&PhantomRecord::of(&p)).unwrap();
        assert!(text.contains("\"skin\":\"fitted\""), "{text}");
        let record = PhantomRecord::from_value(&serde_json::from_str(&text).unwrap()).unwrap();
        assert_eq!(record.to_params(None).unwrap(), p);
    }

    /// `[phantom] skin` reaches every run's scene, and a misspelt one is named.
    #[test]
    fn the_fitted_skin_reaches_the_runs_scenes() {
        let spec: CampaignSpec = toml::from_str("[phantom]\nskin = \"fitted\"\n").unwrap();
        let c = spec.resolve().unwrap();
        assert_eq!(c.base.skin, phantom::Skin::Fitted);
        let scene = c.setup(&c.runs[0]).scene_toml();
        assert!(scene.contains("skin = \"fitted\""), "{scene}");
        assert_eq!(c.phantom_params().unwrap().skin, phantom::Skin::Fitted);
        assert!(!Campaign::paper().base.scene_toml().contains("skin = "));
        let spec: CampaignSpec = toml::from_str("[phantom]\nskin = \"fited\"\n").unwrap();
        let e = spec.resolve().unwrap_err();
        assert!(e.contains("phantom.skin") && e.contains("fited"), "{e}");
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
        assert!(scene.contains("target_dt = \"1.3 x initial\""), "{scene}");
        let spec: CampaignSpec = toml::from_str("[solver]\nprecision = \"f32\"\n").unwrap();
        let c = spec.resolve().unwrap();
        assert!(c.base.scene_toml().contains("precision = \"f32\""));
        let spec: CampaignSpec = toml::from_str("[solver]\nprecision = \"f16\"\n").unwrap();
        assert!(spec.resolve().unwrap_err().contains("solver.precision"));
        for extra in [
            "element = \"full_fbar\"",
            "max_bulk_ratio = 100",
            "precision = \"f64\"",
            "mass_scaling = \"initial\"",
        ] {
            let spec: CampaignSpec =
                toml::from_str(&format!("[solver]\nfidelity = \"fast\"\n{extra}\n")).unwrap();
            let e = spec.resolve().unwrap_err();
            assert!(e.contains("solver.fidelity"), "{e}");
        }
    }

    /// `[solver] subcycling` reaches every run's scene and the plan's identity (so a resumed
    /// campaign cannot mix runs with and without it); a ratio that is not a power of two is
    /// refused naming the key.
    #[test]
    fn subcycling_reaches_the_scene_and_the_plan() {
        let spec: CampaignSpec = toml::from_str("[solver]\nsubcycling = 16\n").unwrap();
        let c = spec.resolve().unwrap();
        assert_eq!(c.base.subcycling, 16);
        assert!(c.base.scene_toml().contains("subcycling = 16"));
        let plain: CampaignSpec = toml::from_str("[solver]\n").unwrap();
        assert!(!plain
            .resolve()
            .unwrap()
            .base
            .scene_toml()
            .contains("subcycling"));
        let spec: CampaignSpec = toml::from_str("[solver]\nsubcycling = 12\n").unwrap();
        assert!(spec.resolve().unwrap_err().contains("solver.subcycling"));
    }

    /// `[solver] step_estimate` reaches every run's scene and the plan's identity; an unknown
    /// value, and "global" beside subcycling, are refused naming the key.
    #[test]
    fn step_estimate_reaches_the_scene_and_the_plan() {
        let spec: CampaignSpec = toml::from_str("[solver]\nstep_estimate = \"global\"\n").unwrap();
        let c = spec.resolve().unwrap();
        assert_eq!(
            c.base.step_estimate,
            solver::simulation::StepEstimate::Global
        );
        assert!(c.base.scene_toml().contains("step_estimate = \"global\""));
        let plain: CampaignSpec = toml::from_str("[solver]\n").unwrap();
        assert!(!plain
            .resolve()
            .unwrap()
            .base
            .scene_toml()
            .contains("step_estimate"));
        for bad in [
            "step_estimate = \"nodal\"",
            "step_estimate = \"global\"\nsubcycling = 4",
        ] {
            let spec: CampaignSpec = toml::from_str(&format!("[solver]\n{bad}\n")).unwrap();
            let e = spec.resolve().unwrap_err();
            assert!(e.contains("solver.step_estimate"), "{e}");
        }
    }

    /// `[locations] phases` presses every location without a phase of its own at each phase,
    /// labelled by it; a design's phase range gives its points their own; bad phases are named.
    #[test]
    fn phases_cross_the_locations() {
        let spec: CampaignSpec = toml::from_str(
            "[locations]\ntrain = [\"P07\"]\ntest = [\"A\"]\nphases = [0.0, 0.25]\n\
             [[locations.design]]\nkind = \"sobol\"\nn = 3\nseed = 1\nsplit = \"train\"\nphase = [0.0, 1.0]\n",
        )
        .unwrap();
        let c = spec.resolve().unwrap();
        let labels: Vec<(&str, Option<f64>)> = c
            .locations
            .iter()
            .map(|l| (l.label.as_str(), l.phase))
            .collect();
        assert_eq!(labels.len(), 7);
        assert_eq!(
            &labels[..2],
            [("P07-ph0", Some(0.0)), ("P07-ph0.25", Some(0.25))]
        );
        assert!(labels[2..5]
            .iter()
            .all(|(l, p)| l.starts_with('S') && p.is_some()));
        assert_eq!(
            &labels[5..],
            [("A-ph0", Some(0.0)), ("A-ph0.25", Some(0.25))]
        );
        assert!(c.is_respiratory());
        assert_eq!(c.setup(&c.runs[1]).respiratory_phase, 0.25);
        assert!(!Campaign::paper().is_respiratory());
        for (bad, key) in [("[]", "empty"), ("[0.5, 1.2]", "outside 0")] {
            let spec: CampaignSpec =
                toml::from_str(&format!("[locations]\nphases = {bad}\n")).unwrap();
            let e = spec.resolve().unwrap_err();
            assert!(e.contains("locations.phases") && e.contains(key), "{e}");
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
        let plan = c.plan(&ph, &[]).to_value();
        assert_eq!(plan["settings"]["element_by_part"]["liver"], "full-fbar");
        let plain = Campaign::paper().plan(&ph, &[]).to_value();
        assert!(plain["settings"].get("element_by_part").is_none());
        assert!(plain["settings"].get("max_bulk_ratio").is_none());
        let fast: CampaignSpec = toml::from_str("[solver]\nfidelity = \"fast\"\n").unwrap();
        let fast = fast.resolve().unwrap().plan(&ph, &[]).to_value();
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
        let e = toml::from_str::<CampaignSpec>(
            "[[locations.raster]]\ncenter = [\"0 m\", \"0.2 m\"]\nspacing = [\"1 cm\", \"1 cm\"]\nn = [2, 2]\nsplit = \"tran\"\n",
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("tran") && e.contains("train") && e.contains("line 5"),
            "{e}"
        );
        // a scene's [mesh.phantom] keys that a campaign's runs leave at their defaults
        let spec: CampaignSpec = toml::from_str("[phantom]\ncoarsen = 2\n").unwrap();
        let e = spec.resolve().unwrap_err();
        assert!(
            e.contains("phantom.coarsen") && e.contains("not a campaign key"),
            "{e}"
        );
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
