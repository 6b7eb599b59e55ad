//! Subcycling in a palpation (`[run] subcycling`, solver::subcycle) on the coarse 8 mm phantom:
//! the liver's interior (Ogden + Prony, wave speed about 13 m/s against the flesh's 1,374 m/s)
//! is the only slow part; no slow node carries a kinematic condition or is read by the
//! contact; the run closes its energy balance and follows the run without subcycling: the
//! hand force within 0.2 % of its peak, the laws' dissipation (the liver's Prony series,
//! integrated over the macro step) within 1 % (the 3 mm figures are in docs/performance.md,
//! "Subcycling"). A bad setting is refused naming the key.

use crate::common;

use scene::palpation::PalpationSetup;

fn setup(subcycling: u32) -> PalpationSetup {
    PalpationSetup {
        voxel: 0.008,
        depth: 0.006,
        duration: 0.006,
        sample_interval: 0.003,
        subcycling,
        vtk: false,
        ..Default::default()
    }
}

/// The hand force (N) over time, the ROI stress table's last row and the energy error of a
/// run, with the scene it ran.
fn run(s: &PalpationSetup, name: &str) -> (Vec<f64>, f64, scene::Scene) {
    let dir = common::tmp_dir(name);
    let mut sc = s.build_scene(dir.path(), None).unwrap();
    let (cols, rows) = common::run_to_end(&mut sc, name);
    let col = |n: &str| cols.iter().position(|c| c == n).unwrap();
    let force = rows.iter().map(|r| r[col("hand_reaction")]).collect();
    let err = rows.last().unwrap()[col("energy_error")];
    (force, err, sc)
}

#[test]
fn the_liver_interior_subcycles_and_the_palpation_follows_the_plain_run() {
    let (f_plain, err_plain, plain) = run(&setup(1), "sub-plain");
    let (f_sub, err_sub, sc) = run(&setup(16), "sub-16");
    let sim = &sc.sim;
    let sub = sim.subcycling.as_ref().expect("the liver is slow enough");
    assert_eq!(sub.k, 16);
    assert_eq!(sub.parts.len(), 1, "{:?}", sub.parts);
    let (part, slow, all) = &sub.parts[0];
    assert_eq!(part, "liver");
    assert!(*slow > 0 && slow < all, "{slow} of {all}");
    let mut read = vec![false; sim.u.len()];
    for st in &sim.stages {
        for &n in st.nodes_read().unwrap() {
            read[n as usize] = true;
        }
    }
    assert!(sub.slow_nodes.iter().all(|&n| !read[n as usize]));
    assert!(
        err_plain.abs() < 1e-3 && err_sub.abs() < 1e-3,
        "{err_plain} {err_sub}"
    );
    let peak = f_plain.iter().fold(0.0f64, |m, f| m.max(f.abs()));
    let worst = f_plain
        .iter()
        .zip(&f_sub)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(peak > 1.0, "the hand pressed: {peak} N");
    // measured 0.03 N
    assert!(
        worst < 0.002 * peak,
        "hand force differs by {worst} N of {peak} N"
    );
    // the liver's Prony series integrates over the macro step (measured 0.13 %; a law given
    // the small step instead dissipates 3 % less)
    let (d, d0) = (sim.energy.law_dissipation, plain.sim.energy.law_dissipation);
    assert!(
        d0 > 0.0 && (d - d0).abs() < 0.01 * d0,
        "law dissipation {d:e} J against {d0:e} J"
    );
}

#[test]
fn a_subcycling_ratio_that_is_not_a_power_of_two_is_refused() {
    let src = setup(16)
        .scene_toml()
        .replace("subcycling = 16", "subcycling = 3");
    let spec: scene::SceneSpec = toml::from_str(&src).unwrap();
    let err = match scene::build::build_scene(spec, std::path::Path::new("sub.toml"), &src) {
        Ok(_) => panic!("a ratio of 3 was accepted"),
        Err(e) => e,
    };
    assert!(err.contains("sub.toml"), "{err}");
    assert!(err.contains("run.subcycling"), "{err}");
    assert!(err.contains("power of two"), "{err}");
}
