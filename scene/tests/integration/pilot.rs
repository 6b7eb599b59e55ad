//! `palpa check`'s pilot (scene/src/pilot.rs): on a two-finger press whose elements are
//! crushed under the fingers, the starting step under-estimates the run's steps by a third;
//! the pilot (K/G capped at 5000) brings the estimate within 20 % of the steps the run takes.

use scene::pilot::{self, PilotPlan};
use scene::{load_scene, Scene};

/// scenes/finger-press.toml on a mesh of 8 mm elements (10 x 8 x 5).
const COARSE_PRESS: &str = r#"
[run]
title = "two-finger press, coarse"
end_time = "30 ms"

[mesh]
generator = "box"
origin = ["-40 mm", "-30 mm", "-40 mm"]
size = ["80 mm", "60 mm", "40 mm"]
divisions = [10, 8, 5]
part = "flesh"

[[part]]
name = "flesh"
material = "paper:flesh"

[[boundary]]
nodes = "zmin"
fix = ["all"]

[[hand]]
name = "hand"
point = ["0 mm", "0 mm", "0 mm"]
direction = [0, 0, -1]
spacing_axis = [1, 0, 0]
diameter = "15 mm"
spacing = "20 mm"
length = "60 mm"
motion = { kind = "displacement", curve = { kind = "smooth_step", value = "15 mm", end = "25 ms" } }

[contact]
surface = "zmax"

[output]
history_interval = "1 ms"
"#;

fn run_steps(mut scene: Scene) -> u64 {
    while scene.sim.time < scene.end_time {
        scene
            .sim
            .step(f64::INFINITY)
            .expect("the coarse press runs");
    }
    scene.sim.step
}

#[test]
fn the_pilot_follows_the_step_of_elements_crushed_under_the_fingers() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("coarse-press.toml");
    std::fs::write(&path, COARSE_PRESS).unwrap();
    let real = load_scene(&path).unwrap();
    let start = scene::def::estimated_steps(
        &real.sim.model,
        real.sim.settings.dt_factor,
        None,
        real.end_time,
    );
    let PilotPlan::Ready { scene, capped, .. } = pilot::plan(&path, &real).unwrap() else {
        panic!("the paper's flesh (K/G 5e4) gets a pilot");
    };
    assert_eq!(capped, ["flesh"]);
    let est = pilot::run(*scene, &real);
    assert!(est.stopped.is_none(), "{:?}", est.stopped);
    let actual = run_steps(load_scene(&path).unwrap()) as f64;
    let (e_start, e_pilot) = (start / actual - 1.0, est.steps / actual - 1.0);
    eprintln!(
        "run {actual} steps; starting step {start:.0} ({:+.1} %), pilot {:.0} ({:+.1} %) after {} pilot steps",
        100.0 * e_start,
        est.steps,
        100.0 * e_pilot,
        est.pilot_steps
    );
    // the case the pilot is for: the starting step is off by more than the 20 % the pilot meets
    assert!(e_start < -0.2, "starting step {e_start}");
    assert!(e_pilot.abs() < 0.2, "pilot {e_pilot}");
    // and it is cheaper than the run
    assert!((est.pilot_steps as f64) < 0.5 * actual);
}

#[test]
fn a_scene_that_is_not_nearly_incompressible_needs_no_pilot() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("soft.toml");
    let src = COARSE_PRESS.replace(
        "material = \"paper:flesh\"",
        "material = \"paper:flesh\"\nmax_bulk_ratio = 100",
    );
    assert_ne!(src, COARSE_PRESS);
    std::fs::write(&path, src).unwrap();
    let real = load_scene(&path).unwrap();
    match pilot::plan(&path, &real).unwrap() {
        PilotPlan::NotNeeded(why) => assert!(why.contains("K/G"), "{why}"),
        PilotPlan::Ready { .. } => panic!("a part with its own K/G cap gets no pilot"),
    }
}
