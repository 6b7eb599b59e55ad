//! Force control: a rigid finger (capsule, 15 mm diameter) presses into a nearly incompressible neo-Hookean
//! block (E = 300 kPa, nu = 0.49)
//! until the reaction reaches 20 N, then holds it. Full model (no symmetry), so the indenter's
//! reaction is the whole force. Tolerance (issue 4): every history sample of the hold phase
//! within 2 % of 20 N.

mod common;
use solver::output::history::column;

const SCENE: &str = r#"
[run]
end_time = "80 ms"

[mesh]
generator = "box"
origin = ["-30 mm", "-30 mm", "-30 mm"]
size = ["60 mm", "60 mm", "30 mm"]
divisions = [20, 20, 10]

[materials.gel]
law = "neo_hookean"
density = "1000 kg/m^3"
youngs_modulus = "300 kPa"
poisson_ratio = 0.49

[[part]]
name = "body"
material = "gel"

[[boundary]]
nodes = "zmin"
fix = ["all"]

[[indenter]]
name = "finger"
direction = [0, 0, -1]
motion = { kind = "force", target = "20 N", ramp_time = "20 ms", approach_speed = "0.5 m/s" }
part = [{ shape = "capsule", center = ["1 mm", "0.5 mm", "7.5 mm"], axis = [0, 0, 1], radius = "7.5 mm", length = "30 mm" }]

[contact]
surface = "zmax"

[output]
vtk = false
history_interval = "0.25 ms"
"#;

#[test]
#[ignore = "known gap: the force controller holds 20 N only within about 10 % (mean 19.66 N) at the stable default dt factor 0.75; issue 4 stays open"]
fn force_control_reaches_and_holds_20_newton() {
    let mut scene = common::scene_from_str(SCENE);
    let (cols, rows) = common::run_to_end(&mut scene, "force-control");
    let t = column(&cols, &rows, "time").unwrap();
    let r = column(&cols, &rows, "finger_reaction").unwrap();
    let depth = column(&cols, &rows, "finger_depth").unwrap();
    let err = column(&cols, &rows, "energy_error").unwrap();
    // Hold phase: from 50 ms (first contact near 0 ms, ramp 20 ms, a few time constants).
    let hold: Vec<f64> = t
        .iter()
        .zip(&r)
        .filter(|(t, _)| **t >= 0.05)
        .map(|(_, r)| *r)
        .collect();
    let worst = hold
        .iter()
        .map(|r| (r - 20.0).abs() / 20.0)
        .fold(0.0, f64::max);
    let mean = hold.iter().sum::<f64>() / hold.len() as f64;
    let emax = err[rows.len() / 10..].iter().cloned().fold(0.0, f64::max);
    println!(
        "hold: mean {mean:.4} N, worst deviation {:.3} %, final depth {:.3} mm, max energy error {:.3} %",
        100.0 * worst,
        1e3 * depth.last().unwrap(),
        100.0 * emax
    );
    assert!(
        worst < 0.02,
        "force deviates {:.2} % from 20 N",
        100.0 * worst
    );
}
