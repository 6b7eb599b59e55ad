//! `scenes/compression-block.toml`: a neo-Hookean cube compressed 10 % on rollers is in
//! homogeneous uniaxial stress. Closed form: lateral stretch l_t from S_22 = 0,
//!   mu (1 - l_t^-2) + lambda ln J / l_t^2 = 0,  J = l_z l_t^2,
//! and the nominal stress P_33 = l_z [mu (1 - l_z^-2) + lambda ln J / l_z^2]; the support
//! reaction is -P_33 A0. Tolerances from issue 2: 0.5 % on the force, energy error < 1 %.

use crate::common;
use scene::build::build_scene;
use scene::{load_scene, SceneSpec};
use solver::output::history::column;
use std::path::Path;

fn closed_form(e: f64, nu: f64, lz: f64, area: f64) -> f64 {
    let mu = e / (2.0 * (1.0 + nu));
    let lam = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let s22 = |lt: f64| mu * (1.0 - 1.0 / (lt * lt)) + lam * (lz * lt * lt).ln() / (lt * lt);
    let mut lt = 1.0;
    for _ in 0..60 {
        let h = 1e-7;
        lt -= s22(lt) / ((s22(lt + h) - s22(lt - h)) / (2.0 * h));
    }
    let j = lz * lt * lt;
    let p33 = lz * (mu * (1.0 - 1.0 / (lz * lz)) + lam * j.ln() / (lz * lz));
    -p33 * area
}

fn check(formulation: &str) {
    // The variant is built on the parsed scene, not by editing its text: a text edit that
    // no longer matched would silently run the base case.
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/compression-block.toml");
    let src = std::fs::read_to_string(&path).unwrap();
    let mut spec: SceneSpec = toml::from_str(&src).unwrap();
    assert_eq!(spec.parts.len(), 1, "the block has one part");
    let part = &mut spec.parts[0];
    assert_eq!(part.formulation.as_deref(), Some("one_point"));
    assert_eq!(part.hourglass.as_deref(), Some("viscous"));
    assert_eq!(part.hourglass_coefficient.map(|c| c.0), Some(0.1));
    part.formulation = Some(formulation.to_string());
    if formulation != "one_point" {
        // a fully integrated element has no hourglass modes to control
        part.hourglass = None;
        part.hourglass_coefficient = None;
    }
    let mut scene = build_scene(spec, &path, &src).unwrap();
    let (cols, rows) = common::run_to_end(&mut scene, &format!("cb-run-{formulation}"));
    let rz = column(&cols, &rows, "zmin_reaction_z").unwrap();
    let err = column(&cols, &rows, "energy_error").unwrap();
    let exact = closed_form(1e6, 0.3, 0.9, 1e-4);
    let f = *rz.last().unwrap();
    let rel = (f - exact).abs() / exact.abs();
    println!("{formulation}: reaction {f:.6} N, closed form {exact:.6} N, rel error {rel:.2e}, energy error {:.2e}", err.last().unwrap());
    assert!(rel < 5e-3, "reaction {f} vs closed form {exact}: {rel:.3e}");
    assert!(
        *err.last().unwrap() < 0.01,
        "energy error {}",
        err.last().unwrap()
    );
}

#[test]
fn compression_block_one_point_matches_closed_form() {
    check("one_point");
}

#[test]
fn compression_block_full_fbar_matches_closed_form() {
    check("full_fbar");
}

/// Issue 29: the console's "max energy error 1.3 %" for this scene was the instantaneous ratio
/// at 1 % of the run, when the energies are 1e-11 of their final size, while the balance closes
/// to round-off. The headline is now the run's largest imbalance over its largest energy; the
/// instantaneous ratio stays in the summary under its own name.
#[test]
fn the_energy_headline_is_not_a_start_up_ratio() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/compression-block.toml");
    let mut scene = load_scene(&path).unwrap();
    let tmp = common::tmp_dir("cb-headline");
    let (s, err) = scene::run::run_scene(
        &mut scene,
        tmp.path(),
        &std::sync::atomic::AtomicBool::new(false),
        |_| {},
    );
    assert!(err.is_none(), "{err:?}");
    assert!(s.max_energy_error < 1e-6, "headline {}", s.max_energy_error);
    assert!(
        s.max_instant_energy_error > s.max_energy_error,
        "instantaneous {} vs headline {}",
        s.max_instant_energy_error,
        s.max_energy_error
    );
}
