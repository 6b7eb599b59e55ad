//! Force control: a rigid finger (capsule, 15 mm diameter) presses into a nearly incompressible
//! neo-Hookean block (E = 300 kPa, nu = 0.49) until the reaction reaches 20 N (reference ramped
//! over 20 ms from first contact), then holds it to 80 ms. Full model (no symmetry), so the
//! indenter's reaction is the whole force.
//!
//! **Tolerance (issue 4).** The quantity asserted is `finger_reaction` as written to
//! `history.csv`: the raw (unfiltered) penalty reaction of the body on the finger, sampled every
//! 0.05 ms (a few samples per step-level oscillation of the contact, so ringing cannot alias
//! away). Over the hold phase `t >= 50 ms`:
//! - every sample lies within 2 % of 20 N (the issue's figure; measured 0.41 %);
//! - the mean lies within 0.5 % of 20 N (no bias from the filter lag; measured 0.01 %);
//! - the raw ring, each sample minus the centred 1 ms moving average of the samples, stays
//!   within 0.5 % of 20 N (measured 0.09 %: the sampled penalty force does not ring);
//! - the body holds still: the finger depth varies by less than 1 % of its mean (measured
//!   0.08 %). A controller holding the force on a body that creeps would pass the force checks
//!   while the model is wrong; this check fails then.
//!
//! Besides, the energy balance closes (`energy_error` below 2 % after the first 10 % of the run)
//! and the hourglass energy stays below 10 % of the internal energy (the usual LS-DYNA rule).
//!
//! **Why stiffness hourglass control.** The block uses one-point elements with the stiffness form
//! of the hourglass control. The viscous form (the scene default) resists only hourglass *rates*,
//! so under a load held for tens of milliseconds the elements under the finger drift in their
//! zero-energy modes. With it the hourglass energy grows throughout the hold (0.8 mJ at 50 ms,
//! 2.5 mJ at 80 ms), the elements under the finger flatten (stable step 28 us at 2 ms, 10 us at
//! 50 ms, 4 us at 80 ms), and the reaction falls (to 17.99 N, -10 %; mean 19.66 N) while the
//! finger is driven 0.6 mm deeper (depth drift 9.8 %). That was the "holds only within about
//! 10 %" of issue 4: the controller was faithfully following a collapsing body (with
//! shear-scaled viscous control the finger punches through the surface at about 40 ms). LS-DYNA
//! practice is the same: stiffness hourglass forms for slow, sustained loading. With the F-bar
//! element (`full_fbar`, no hourglass modes) the same scene holds 20 N within 0.42 % (mean
//! 19.999 N), as here.

use crate::common;
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
hourglass = "stiffness"

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
history_interval = "0.05 ms"
"#;

const TARGET: f64 = 20.0;
const HOLD_FROM: f64 = 0.05;

#[test]
fn force_control_reaches_and_holds_20_newton() {
    let mut scene = common::scene_from_str(SCENE);
    let (cols, rows) = common::run_to_end(&mut scene, "force-control");
    let col = |name: &str| column(&cols, &rows, name).unwrap();
    let t = col("time");
    let r = col("finger_reaction");
    let depth = col("finger_depth");
    let err = col("energy_error");
    let hg = col("hourglass_energy");
    let ie = col("internal_energy");

    let hold: Vec<usize> = (0..t.len()).filter(|&i| t[i] >= HOLD_FROM).collect();
    assert!(
        hold.len() > 500,
        "only {} hold samples; history too sparse",
        hold.len()
    );
    let worst = hold
        .iter()
        .map(|&i| (r[i] - TARGET).abs() / TARGET)
        .fold(0.0, f64::max);
    let mean = hold.iter().map(|&i| r[i]).sum::<f64>() / hold.len() as f64;
    // Raw ring: sample minus the centred 1 ms moving average (over hold samples).
    let ring = hold
        .iter()
        .map(|&i| {
            let w: Vec<f64> = hold
                .iter()
                .filter(|&&j| (t[j] - t[i]).abs() <= 0.5e-3)
                .map(|&j| r[j])
                .collect();
            (r[i] - w.iter().sum::<f64>() / w.len() as f64).abs() / TARGET
        })
        .fold(0.0, f64::max);
    let (dmin, dmax, dsum) = hold
        .iter()
        .fold((f64::MAX, f64::MIN, 0.0), |(a, b, s), &i| {
            (a.min(depth[i]), b.max(depth[i]), s + depth[i])
        });
    let drift = (dmax - dmin) / (dsum / hold.len() as f64);
    let emax = err[rows.len() / 10..].iter().cloned().fold(0.0, f64::max);
    let hg_share = hg.last().unwrap() / ie.last().unwrap();
    println!(
        "hold (t >= 50 ms, {} samples): mean {mean:.4} N, worst deviation {:.3} %, ring {:.3} %, \
         depth drift {:.3} %, final depth {:.3} mm, max energy error {:.4} %, hourglass/internal {:.2} %",
        hold.len(),
        100.0 * worst,
        100.0 * ring,
        100.0 * drift,
        1e3 * depth.last().unwrap(),
        100.0 * emax,
        100.0 * hg_share
    );
    assert!(
        worst < 0.02,
        "force deviates {:.2} % from 20 N",
        100.0 * worst
    );
    assert!(
        (mean - TARGET).abs() / TARGET < 0.005,
        "mean hold force {mean:.4} N is biased by more than 0.5 %"
    );
    assert!(
        ring < 0.005,
        "raw force rings {:.3} % about its 1 ms average",
        100.0 * ring
    );
    assert!(
        drift < 0.01,
        "the finger depth drifts {:.2} % during the hold: the body creeps",
        100.0 * drift
    );
    assert!(emax < 0.02, "energy error {:.3} %", 100.0 * emax);
    assert!(
        hg_share < 0.1,
        "hourglass energy is {:.1} % of the internal energy",
        100.0 * hg_share
    );
}
