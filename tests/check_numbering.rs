//! `palpa check` prints the mesh's element bandwidth, and suggests `[mesh] numbering = "rcm"`
//! where the numbering has no locality: a 10 x 10 x 10 block shuffled gets the hint, the same
//! block as generated (a raster) and renumbered by RCM do not.

use std::process::Command;

/// `palpa check`'s node-numbering line for the block numbered `numbering`.
fn numbering_line(numbering: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("block.toml");
    std::fs::write(
        &scene,
        format!(
            r#"[run]
end_time = "1 ms"
[mesh]
generator = "box"
size = ["10 mm", "10 mm", "10 mm"]
divisions = [10, 10, 10]
numbering = "{numbering}"
[materials.m]
law = "neo_hookean"
density = "1000 kg/m^3"
youngs_modulus = "1 MPa"
poisson_ratio = 0.3
[[part]]
name = "body"
material = "m"
"#
        ),
    )
    .unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_palpa"))
        .arg("check")
        .arg(&scene)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
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
