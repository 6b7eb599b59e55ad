//! The committed campaigns (data/): their `campaign.json` reads as a typed plan and writes back
//! to the same bytes, their manifests' phantom parameters read as a `PhantomRecord`, and their
//! dataset reassembles from the committed runs byte for byte (the dataset's code, the npz writer
//! and its zip library are all on the path).

use campaign::{assemble, campaign_file, read_campaign_dir, run_dir, CampaignPlan, PhantomRecord};
use std::path::{Path, PathBuf};

fn committed() -> Vec<PathBuf> {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data");
    [
        "default-campaign-3mm",
        "campaign-paper-fast-3mm",
        "convergence-2.5mm",
    ]
    .iter()
    .map(|d| data.join(d))
    .collect()
}

#[test]
fn committed_plans_read_typed_and_write_back_to_the_same_bytes() {
    for dir in committed() {
        let file = std::fs::read_to_string(dir.join("campaign.json")).unwrap();
        let cd = read_campaign_dir(&dir).unwrap();
        let plan = cd.plan().unwrap();
        let back = serde_json::to_string_pretty(&campaign_file(&plan.to_value(), cd.shard))
            .unwrap()
            .replace(
                &format!("\"solver_version\": \"{}\"", env!("CARGO_PKG_VERSION")),
                &format!("\"solver_version\": {}", cd.solver_version),
            );
        assert!(
            back == file,
            "{}: the typed plan writes other bytes",
            dir.display()
        );
        let manifest: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("manifest.json")).unwrap())
                .unwrap();
        let rec = PhantomRecord::from_value(&manifest["phantom"]["parameters"]).unwrap();
        assert_eq!(rec, plan.phantom, "{}", dir.display());
    }
}

#[test]
fn a_plan_with_an_unknown_or_missing_key_is_an_error_naming_it() {
    let dir = &committed()[0];
    let mut v = read_campaign_dir(dir).unwrap().plan_value;
    v["settings"]["colour"] = serde_json::json!(1);
    let e = CampaignPlan::from_value(&v).unwrap_err();
    assert!(e.contains("colour"), "{e}");
    let mut v = read_campaign_dir(dir).unwrap().plan_value;
    v["phantom"].as_object_mut().unwrap().remove("variant");
    let e = CampaignPlan::from_value(&v).unwrap_err();
    assert!(e.contains("phantom") && e.contains("variant"), "{e}");
}

#[test]
fn committed_datasets_reassemble_to_the_same_bytes() {
    // the two whole 28-run campaigns: the default and the same with the fast preset
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data");
    for name in ["default-campaign-3mm", "campaign-paper-fast-3mm"] {
        let dir = &data.join(name);
        let plan = read_campaign_dir(dir).unwrap().plan().unwrap();
        let labels: Vec<String> = plan.runs.iter().map(|r| r.label.clone()).collect();
        let ds = assemble(&plan, &labels, |l| run_dir(dir, l)).unwrap();
        let tmp = tempfile::tempdir().unwrap();
        campaign::write_dataset(&ds, tmp.path()).unwrap();
        for f in ["dataset.npz", "manifest.json", "dataset.json"] {
            let a = std::fs::read(dir.join(f)).unwrap();
            let b = std::fs::read(tmp.path().join(f)).unwrap();
            assert!(
                a == b,
                "{}/{f}: reassembled bytes differ from the committed file",
                dir.display()
            );
        }
    }
}
