//! The round trip of the main job: the two-finger palpation of the phantom
//! (`scenes/decks/palpation-8mm.toml`, 8 mm voxels, 6 mm in 6 ms), exported with
//! `palpa export --lsdyna` (`scenes/decks/palpation-8mm.k`) and run from the deck, writes the
//! very same `history.csv`, `probe.csv` and `probe_stress.csv` (the ROI stresses) as the scene:
//! byte for byte. The committed deck is what the exporter writes today.

use lsdyna::export::{export, ExportOptions};
use lsdyna::{load_deck, ReadOptions};
use scene::run::run_scene;
use scene::{load_scene, Scene};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

fn decks() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/decks")
}

fn run(mut scene: Scene, out: &Path) {
    let (summary, err) = run_scene(&mut scene, out, &AtomicBool::new(false), |_| {});
    assert!(err.is_none(), "run failed: {err:?} ({})", summary.status);
}

#[test]
fn exported_palpation_runs_to_the_same_bytes() {
    let twin = load_scene(&decks().join("palpation-8mm.toml")).unwrap();
    // The committed deck is today's export of the twin.
    let e = export(
        &twin,
        &ExportOptions {
            source: "scenes/decks/palpation-8mm.toml".into(),
            ..Default::default()
        },
    )
    .unwrap();
    let committed = std::fs::read_to_string(decks().join("palpation-8mm.k")).unwrap();
    assert!(
        e.text == committed,
        "scenes/decks/palpation-8mm.k is not what `palpa export --lsdyna scenes/decks/palpation-8mm.toml` writes; regenerate it"
    );
    let (deck, report) =
        load_deck(&decks().join("palpation-8mm.k"), &ReadOptions::default()).unwrap();
    assert!(report.warnings.is_empty(), "{:#?}", report.warnings);
    let a = tempfile::tempdir().unwrap();
    let b = tempfile::tempdir().unwrap();
    run(twin, a.path());
    run(deck, b.path());
    for f in ["history.csv", "probe.csv", "probe_stress.csv"] {
        let x = std::fs::read(a.path().join(f)).unwrap();
        let y = std::fs::read(b.path().join(f)).unwrap();
        assert!(
            x == y,
            "{f} differs between the scene and its exported deck"
        );
    }
}
