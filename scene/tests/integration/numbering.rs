//! `[mesh] numbering`: reverse Cuthill-McKee and a shuffled numbering change where nodes sit in
//! memory, not the physics. A block (3 x 2 x 4 elements) compressed 5 % on rollers gives the same
//! support reaction whatever the numbering, to round-off (the order of the nodal sums changes),
//! with the fixed face given both as a plane and as explicit node ids of the mesh as generated
//! (which the renumbering must carry along). The phantom refuses a numbering.

use crate::common;

use scene::build::build_scene;
use scene::SceneSpec;
use solver::generate::{box_mesh, BoxSpec};
use std::path::Path;

/// The error building the scene `src` gives.
fn scene_err(src: &str) -> String {
    let spec: SceneSpec = toml::from_str(src).expect("scene parses");
    match build_scene(spec, Path::new("test.toml"), src) {
        Err(e) => e,
        Ok(_) => panic!("the scene built"),
    }
}

/// The block's final x = 0 reaction (N), its nodes numbered `numbering`, the face x = 0 given
/// by explicit node ids when `explicit`.
fn reaction(numbering: &str, explicit: bool) -> f64 {
    let block = box_mesh(
        &BoxSpec {
            size: [0.03, 0.02, 0.04],
            divisions: [3, 2, 4],
            ..BoxSpec::default()
        },
        "body",
    )
    .unwrap();
    let x0 = if explicit {
        let ids: Vec<String> = (0..block.nodes.len())
            .filter(|&a| block.nodes[a][0] == 0.0)
            .map(|a| a.to_string())
            .collect();
        format!("nodes = [{}]", ids.join(", "))
    } else {
        "plane_axis = \"x\"\nplane_value = \"0 mm\"".to_string()
    };
    common::roller_compression(
        &format!(
            "generator = \"box\"\nsize = [\"30 mm\", \"20 mm\", \"40 mm\"]\n\
             divisions = [3, 2, 4]\nnumbering = \"{numbering}\""
        ),
        &["body"],
        &x0,
        &format!("numbering-{numbering}"),
    )
}

#[test]
fn every_numbering_gives_the_same_reaction() {
    let r0 = reaction("as_given", false);
    assert!(r0 > 1.0, "the block pushes back: {r0} N");
    for (n, explicit) in [
        ("as_given", true),
        ("rcm", false),
        ("rcm", true),
        ("shuffled", false),
        ("shuffled", true),
    ] {
        let r = reaction(n, explicit);
        assert!(
            (r - r0).abs() <= 1e-9 * r0.abs(),
            "{n} (explicit ids: {explicit}): {r} N against {r0} N"
        );
    }
}

#[test]
fn the_phantom_and_unknown_numberings_are_refused() {
    let e = scene_err(
        "[run]\nend_time = \"1 ms\"\n[mesh]\ngenerator = \"box\"\nsize = [\"1 mm\", \"1 mm\", \"1 mm\"]\ndivisions = [1, 1, 1]\nnumbering = \"metis\"\n",
    );
    assert!(
        e.contains("mesh.numbering") && e.contains("metis") && e.contains("rcm"),
        "{e}"
    );
    let e = scene_err(
        "[run]\nend_time = \"1 ms\"\n[mesh]\ngenerator = \"phantom\"\nnumbering = \"rcm\"\n",
    );
    assert!(e.contains("mesh.numbering") && e.contains("phantom"), "{e}");
}
