//! Element erosion (issue 3, item 4): a bar of piecewise-linear plasticity with a failure
//! strain is pulled quasi-statically. In uniaxial stress with linear hardening the effective
//! plastic strain is eps_p = (sigma - sigma_y) / H with H = E E_t / (E - E_t), and the log strain
//! is eps = sigma / E + eps_p; with E = 10 MPa, sigma_y = 0.2 MPa, E_t = 1 MPa the failure
//! strain 0.03 is reached at sigma = 0.2 MPa + 0.03 H = 0.2333 MPa, eps = sigma / E + 0.03 =
//! 5.33 % (stretch 1.055), well before the 10 % stretch applied. Once an element erodes the bar is cut: the reaction at the
//! pulled end must fall to (almost) zero, the summary must report the eroded element, and the
//! energy balance must still close (the eroded element's stored energy stays in the internal
//! work it received).

use crate::common;
use scene::run::run_scene;
use solver::output::history::{column, read_history};
use std::sync::atomic::AtomicBool;

const SCENE: &str = r#"
[run]
title = "erosion bar"
end_time = "30 ms"
[mesh]
generator = "box"
size = ["10 mm", "10 mm", "40 mm"]
divisions = [1, 1, 4]
part = "bar"
[materials.rib]
law = "piecewise_linear_plasticity"
density = "1000 kg/m^3"
youngs_modulus = "10 MPa"
poisson_ratio = 0.3
yield_stress = "0.2 MPa"
tangent_modulus = "1 MPa"
failure_strain = 0.03
[[part]]
name = "bar"
material = "rib"
formulation = "full_fbar"
[[boundary]]
nodes = "xmin"
symmetry = "x"
[[boundary]]
nodes = "ymin"
symmetry = "y"
[[boundary]]
nodes = "zmin"
symmetry = "z"
[[boundary]]
nodes = "zmax"
displacement = { z = { kind = "smooth_step", value = "4 mm", end = "20 ms" } }
[output]
history_interval = "0.1 ms"
reactions = ["zmax"]
"#;

#[test]
fn failed_element_is_eroded_and_the_bar_lets_go() {
    let mut scene = common::scene_from_str(SCENE);
    let out = common::tmp_dir("erosion");
    let (summary, err) = run_scene(&mut scene, out.path(), &AtomicBool::new(false), |_| {});
    assert!(err.is_none(), "run failed: {err:?}");
    let (cols, rows) = read_history(&out.path().join("history.csv")).unwrap();
    let t = column(&cols, &rows, "time").unwrap();
    let rz = column(&cols, &rows, "zmax_reaction_z").unwrap();
    let err = column(&cols, &rows, "energy_error").unwrap();
    let peak = rz.iter().fold(0.0f64, |m, r| m.max(r.abs()));
    let last = rz.last().unwrap().abs();
    println!(
        "eroded {} (first {:?}), peak reaction {peak:.4} N, final {last:.3e} N, energy error {:.3e}",
        summary.eroded_elements,
        summary.first_eroded,
        err.last().unwrap()
    );
    assert!(summary.eroded_elements >= 1);
    let first = summary.first_eroded.clone().unwrap();
    let t_fail = first.time;
    assert_eq!(first.part, "bar");
    // Failure at stretch 1.055 of the smooth step 1 + 0.1 s(t / 20 ms): s = 0.55 near 10.5 ms.
    assert!(
        (8e-3..12e-3).contains(&t_fail),
        "eroded at {t_fail} s, expected near 10 ms"
    );
    // Peak reaction: the true stress at failure, 0.2333 MPa, times the current area. The
    // lateral stretch is exp(-nu eps_e - eps_p / 2) = 0.978 (elastic nu = 0.3, plastic flow
    // isochoric), so A = 100 mm^2 * 0.978^2 = 95.6 mm^2 and F = 22.3 N; 3 % tolerance for the
    // step at which the failure is detected and the residual dynamics.
    assert!((21.6..23.0).contains(&peak), "peak reaction {peak} N");
    // After erosion the pulled end holds almost nothing (a free part rides on the support).
    let after: Vec<f64> = t
        .iter()
        .zip(&rz)
        .filter(|(&ti, _)| ti > t_fail + 5e-3)
        .map(|(_, r)| r.abs())
        .collect();
    assert!(!after.is_empty());
    let worst = after.iter().cloned().fold(0.0, f64::max);
    assert!(
        worst < 0.05 * peak,
        "reaction after erosion {worst} N (peak {peak} N)"
    );
    assert!(err.iter().all(|e| e.is_finite()));
    assert!(
        *err.last().unwrap() < 0.02,
        "energy error {}",
        err.last().unwrap()
    );
}
