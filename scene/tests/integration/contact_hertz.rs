//! Hertz: `scenes/hertz-sphere.toml`, a rigid sphere pressed slowly into a large nearly
//! incompressible neo-Hookean block (quarter model). Reference: F = 4/3 E* sqrt(R) d^(3/2),
//! E* = E/(1 - nu^2), for a rigid sphere on an elastic half-space. Tolerance (issue 4): 5 % at
//! every compared depth d/R = 0.02 ... 0.1; the energy error (contact energy included) below 2 %.

use crate::common;
use scene::load_scene;
use solver::output::history::column;
use std::path::Path;

#[test]
fn hertz_sphere_force_depth_matches_closed_form() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/hertz-sphere.toml");
    let mut scene = load_scene(&path).unwrap();
    let t0 = std::time::Instant::now();
    let (cols, rows) = common::run_to_end(&mut scene, "hertz");
    let wall = t0.elapsed().as_secs_f64();
    let travel = column(&cols, &rows, "sphere_travel").unwrap();
    let fz = column(&cols, &rows, "sphere_force_z").unwrap();
    let pen = column(&cols, &rows, "sphere_max_penetration").unwrap();
    let err = column(&cols, &rows, "energy_error").unwrap();
    let (e, nu, r) = (30e3, 0.49, 5e-3);
    let es = e / (1.0 - nu * nu);
    // Only the ramp (travel increasing): up to the first row at full depth.
    let n = travel.iter().position(|&s| s >= 0.5e-3 - 1e-9).unwrap() + 1;
    let mut worst: f64 = 0.0;
    for k in 1..=5 {
        let d = 0.02 * k as f64 * r;
        let f = 4.0 * common::interpolate_at(&travel[..n], &fz[..n], d);
        let g = common::interpolate_at(&travel[..n], &pen[..n], d);
        let f_h = 4.0 / 3.0 * es * r.sqrt() * d.powf(1.5);
        let rel = (f - f_h) / f_h;
        worst = worst.max(rel.abs());
        println!(
            "d/R = {:.2}: F = {:.5e} N, Hertz {:.5e} N, error {:+.2} %, penetration {:.2} % of d",
            d / r,
            f,
            f_h,
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
    assert!(worst < 0.05, "Hertz force error {:.2} %", 100.0 * worst);
    assert!(emax < 0.02, "energy error {emax}");
}
