//! `palpa check` prints the mesh's element bandwidth, and suggests `[mesh] numbering = "rcm"`
//! where the numbering has no locality: a 10 x 10 x 10 block shuffled gets the hint, the same
//! block as generated (a raster) and renumbered by RCM do not.

#[path = "support/block.rs"]
mod block;
#[path = "support/cli.rs"]
mod cli;

/// `palpa check`'s node-numbering line for the shared block at 10 x 10 x 10, numbered
/// `numbering`.
fn numbering_line(numbering: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("block.toml");
    let src = block::BLOCK.replace(
        "divisions = [2, 2, 2]",
        &format!("divisions = [10, 10, 10]\nnumbering = \"{numbering}\""),
    );
    std::fs::write(&scene, src).unwrap();
    let stdout = cli::ok(&["check", cli::s(&scene)]);
    stdout
        .lines()
        .find(|l| l.contains("node numbering"))
        .unwrap_or_else(|| panic!("no node-numbering line:\n{stdout}"))
        .to_string()
}

#[test]
fn check_suggests_rcm_for_a_numbering_without_locality() {
    // 1331 nodes; the raster's bandwidth is one layer of 11 x 11 nodes and a row and a node more
    let raster = numbering_line("as_given");
    assert!(
        raster.contains("bandwidth 133 of 1331 nodes") && !raster.contains("rcm"),
        "{raster}"
    );
    let shuffled = numbering_line("shuffled");
    assert!(shuffled.contains("numbering = \"rcm\""), "{shuffled}");
    let rcm = numbering_line("rcm");
    assert!(!rcm.contains("numbering = \"rcm\""), "{rcm}");
}
