//! Flat cylindrical punch: `scenes/flat-punch.toml`, a rigid flat-ended cylinder (a = 2 mm)
//! pressed slowly into a large nearly incompressible neo-Hookean block (quarter model).
//! Reference: F = 2 a E* d, E* = E/(1 - nu^2) (rigid flat punch on an elastic half-space).
//! Tolerance (issue 4): 5 % at d = 0.05, 0.075 and 0.1 mm (d/a <= 0.05, small strain).

use crate::common;
use scene::load_scene;
use solver::output::history::column;
use std::path::Path;

#[test]
fn flat_punch_force_matches_closed_form() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/flat-punch.toml");
    let mut scene = load_scene(&path).unwrap();
    let t0 = std::time::Instant::now();
    let (cols, rows) = common::run_to_end(&mut scene, "punch");
    let wall = t0.elapsed().as_secs_f64();
    let travel = column(&cols, &rows, "punch_travel").unwrap();
    let fz = column(&cols, &rows, "punch_force_z").unwrap();
    let pen = column(&cols, &rows, "punch_max_penetration").unwrap();
    let err = column(&cols, &rows, "energy_error").unwrap();
    let (e, nu, a) = (30e3, 0.49, 2e-3);
    let es = e / (1.0 - nu * nu);
    let n = travel.iter().position(|&s| s >= 0.1e-3 - 1e-12).unwrap() + 1;
    let mut worst: f64 = 0.0;
    for d in [0.05e-3, 0.075e-3, 0.1e-3] {
        let f = if d < 0.1e-3 {
            4.0 * common::interpolate_at(&travel[..n], &fz[..n], d)
        } else {
            // Full depth: the end of the hold.
            4.0 * fz.last().unwrap()
        };
        let g = if d < 0.1e-3 {
            common::interpolate_at(&travel[..n], &pen[..n], d)
        } else {
            *pen.last().unwrap()
        };
        let f_ref = 2.0 * a * es * d;
        let rel = (f - f_ref) / f_ref;
        worst = worst.max(rel.abs());
        println!(
            "d = {:.3} mm: F = {:.5e} N, closed form {:.5e} N, error {:+.2} %, penetration {:.2} % of d",
            1e3 * d,
            f,
            f_ref,
            100.0 * rel,
            100.0 * g / d
        );
    }
    let emax = err[rows.len() / 10..].iter().cloned().fold(0.0, f64::max);
    println!(
        "worst {:.2} %, max energy error {:.3} %, steps {}, wall {wall:.1} s",
        100.0 * worst,
        100.0 * emax,
        scene.sim.step
    );
    assert!(worst < 0.05, "punch force error {:.2} %", 100.0 * worst);
    assert!(emax < 0.02, "energy error {emax}");
}
