//! Default contact settings on the paper's palpation (`scenes/finger-press.toml`: two 15 mm
//! fingers press 15 mm in 25 ms into abdominal flesh, K = 2 GPa, G = 40 kPa). Issue 4:
//! penetration at most 5 % of the indentation depth (checked once the depth exceeds 1 mm, i.e.
//! once the contact is established), and the energy error, contact energy included, within 2 %
//! (after the first 10 % of the run).

use crate::common;
use scene::load_scene;
use solver::output::history::column;
use std::path::Path;

#[test]
fn finger_press_default_penetration_and_energy() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/finger-press.toml");
    let mut scene = load_scene(&path).unwrap();
    let t0 = std::time::Instant::now();
    let (cols, rows) = common::run_to_end(&mut scene, "finger-press");
    let wall = t0.elapsed().as_secs_f64();
    let depth = column(&cols, &rows, "hand_depth").unwrap();
    let pen = column(&cols, &rows, "hand_max_penetration").unwrap();
    let fz = column(&cols, &rows, "hand_force_z").unwrap();
    let err = column(&cols, &rows, "energy_error").unwrap();
    let ec = column(&cols, &rows, "contact_energy").unwrap();
    let wx = column(&cols, &rows, "external_work").unwrap();
    let mut worst: f64 = 0.0;
    for (d, g) in depth.iter().zip(&pen) {
        if *d > 1e-3 {
            worst = worst.max(g / d);
        }
    }
    let emax = err[rows.len() / 10..].iter().cloned().fold(0.0, f64::max);
    println!(
        "final depth {:.3} mm, force {:.3} N, worst penetration {:.3} % of depth, max energy error {:.3} %, \
         contact energy {:.3e} J of external work {:.3e} J, steps {}, wall {wall:.1} s",
        1e3 * depth.last().unwrap(),
        fz.last().unwrap(),
        100.0 * worst,
        100.0 * emax,
        ec.last().unwrap(),
        wx.last().unwrap(),
        scene.sim.step
    );
    assert!(worst <= 0.05, "penetration {:.2} % of depth", 100.0 * worst);
    assert!(emax <= 0.02, "energy error {:.2} %", 100.0 * emax);
}
