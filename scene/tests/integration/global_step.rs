//! The global step estimate ([`solver::global_step`]): the Lanczos estimate of the mesh's
//! critical step against dense eigenvalues (the regular block of
//! `verification/python/hex_stability_eigen.py`, and a graded, distorted block assembled here
//! independently), and runs on it: a block with thin layers keeps its energy balance and its
//! answer on fewer steps, and a fast, crushing press gives the same bits on one and two
//! threads.

use crate::common;
use nalgebra::{DMatrix, Vector3};
use scene::Scene;
use solver::hex::element_geometry;
use solver::output::history::column;

/// The shared free box ([`common::free_box`]) on the global estimate.
fn free_box(size_mm: [f64; 3], divisions: [usize; 3], mesh_extra: &str) -> String {
    common::free_box("step_estimate = \"global\"", size_mm, divisions, mesh_extra)
}

/// The mesh's critical step by the estimator, after the first force evaluation (s).
fn estimated(scene: &mut Scene) -> f64 {
    scene.sim.initialise().unwrap();
    let g = scene
        .sim
        .global_step
        .as_ref()
        .expect("the global estimate is on");
    assert_eq!(g.report.estimates, 1);
    g.critical_step()
}

/// P-wave speed of the nu = 0.49 solid above (m/s).
fn wave_speed() -> f64 {
    let (e, nu, rho): (f64, f64, f64) = (300e3, 0.49, 1000.0);
    let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let mu = e / (2.0 * (1.0 + nu));
    ((lambda + 2.0 * mu) / rho).sqrt()
}

#[test]
fn a_regular_block_matches_the_eigenvalue_study() {
    // hex_stability_eigen.py, one-point, free 5 x 4 x 4 cubes, nu = 0.49: dt_crit = 0.855 h / c
    let mut scene = common::scene_from_str(&free_box([5.0, 4.0, 4.0], [5, 4, 4], ""));
    let ratio = estimated(&mut scene) / (1e-3 / wave_speed());
    println!("regular block: dt_crit = {ratio:.4} h / c (study: 0.855)");
    assert!((ratio - 0.855).abs() < 0.0015, "{ratio}");
}

/// `2 / sqrt(max eig(M^-1 K))` with `K` assembled densely from each element's mean gradients
/// and volume (`hex::element_geometry`: the one-point element's) and the model's lumped masses
/// (s).
fn dense_critical_step(scene: &Scene) -> f64 {
    let model = &scene.sim.model;
    let mesh = &model.mesh;
    let n = 3 * mesh.nodes.len();
    let (e, nu) = (300e3, 0.49);
    let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let mu = e / (2.0 * (1.0 + nu));
    let mut k = DMatrix::<f64>::zeros(n, n);
    for conn in &mesh.elements {
        let x: [[f64; 3]; 8] = std::array::from_fn(|a| mesh.nodes[conn[a] as usize]);
        let g = element_geometry(&x).unwrap();
        let b = |a: usize| Vector3::new(g.mean_grad[0][a], g.mean_grad[1][a], g.mean_grad[2][a]);
        for a in 0..8 {
            for c in 0..8 {
                let (ba, bc) = (b(a), b(c));
                // K_ac = V (lambda b_a b_c^T + mu (b_c b_a^T + (b_a . b_c) I))
                for i in 0..3 {
                    for j in 0..3 {
                        let mut v = lambda * ba[i] * bc[j] + mu * bc[i] * ba[j];
                        if i == j {
                            v += mu * ba.dot(&bc);
                        }
                        k[(3 * conn[a] as usize + i, 3 * conn[c] as usize + j)] += g.volume * v;
                    }
                }
            }
        }
    }
    let w: Vec<f64> = (0..n).map(|d| 1.0 / model.mass[d / 3].sqrt()).collect();
    let a = DMatrix::from_fn(n, n, |i, j| w[i] * k[(i, j)] * w[j]);
    let top = a.symmetric_eigenvalues().max();
    2.0 / top.sqrt()
}

#[test]
fn a_graded_distorted_block_matches_its_dense_eigenvalue() {
    let src = free_box(
        [6.0, 5.0, 5.0],
        [4, 3, 5],
        "grading = [1.0, 1.0, 5.0]\ndistortion = 0.2\nseed = 3",
    );
    let mut scene = common::scene_from_str(&src);
    let lanczos = estimated(&mut scene);
    let dense = dense_critical_step(&scene);
    let element = scene.sim.model.initial_dt.0;
    println!(
        "graded block: Lanczos {lanczos:.6e} s, dense {dense:.6e} s, smallest element estimate {element:.4e} s"
    );
    // the estimate adds its residual bound to the largest Ritz value: never above the true
    // step, and within the iteration's tolerance (1e-3 on the eigenvalue) below it
    assert!(lanczos <= dense * (1.0 + 1e-9), "{lanczos} above {dense}");
    assert!(
        lanczos > dense * (1.0 - 1e-3),
        "{lanczos} far below {dense}"
    );
    assert!(
        dense > 1.2 * element,
        "the grading should leave room: {dense} vs {element}"
    );
}

/// A block of the paper's flesh (K/G = 5e4) graded to thin layers at the top, loaded there,
/// with the step estimate `how`: (steps, largest energy error, mean top displacement (m)).
fn thin_layers(how: &str) -> (u64, f64, f64) {
    let src = format!(
        r#"
[run]
end_time = "0.3 ms"
step_estimate = "{how}"
[mesh]
generator = "box"
size = ["10 mm", "8 mm", "6 mm"]
divisions = [10, 8, 6]
grading = [1.0, 1.0, 0.2]
part = "block"
[materials.m]
library = "paper:flesh"
[[part]]
name = "block"
material = "m"
[[boundary]]
nodes = "zmin"
fix = ["all"]
[[load]]
nodes = "zmax"
force = {{ z = {{ kind = "ramp", value = "-0.05 N", end = "0.3 ms" }} }}
total = true
[output]
vtk = false
history_interval = "0.01 ms"
"#
    );
    let mut scene = common::scene_from_str(&src);
    let (cols, rows) = common::run_to_end(&mut scene, "global-step");
    let err = column(&cols, &rows, "energy_error").unwrap();
    let worst = err.iter().cloned().fold(0.0, f64::max);
    let top = &scene.sim.model.mesh.node_sets["zmax"];
    let uz: f64 = top.iter().map(|&n| scene.sim.u[n as usize][2]).sum::<f64>() / top.len() as f64;
    (scene.sim.step, worst, uz)
}

#[test]
fn thin_layers_run_on_the_mesh_step_with_the_same_answer() {
    let (n_el, err_el, u_el) = thin_layers("element");
    let (n_gl, err_gl, u_gl) = thin_layers("global");
    println!(
        "thin layers: element {n_el} steps (energy error {:.4} %), global {n_gl} steps ({:.4} %); top displacement {u_el:.6e} / {u_gl:.6e} m",
        100.0 * err_el,
        100.0 * err_gl
    );
    assert!(
        (n_gl as f64) < (n_el as f64) / 1.3,
        "{n_gl} vs {n_el} steps"
    );
    assert!(err_gl < 0.01, "energy error {err_gl}");
    assert!(u_el < 0.0);
    assert!(
        ((u_gl - u_el) / u_el).abs() < 0.01,
        "top displacement {u_gl} vs {u_el}"
    );
}

/// A distorted block crushed at 1 m/s (40 % in 8 ms) and sheared, with the step estimate
/// `how`, on `threads` threads: (displacements, internal energy, estimates, largest energy
/// error over the last 4 ms).
fn crushing_press(threads: usize, how: &str) -> (Vec<[f64; 3]>, f64, u64, f64) {
    let src = common::PRESSED_BLOCK
        .replace(
            "end_time = \"2 ms\"",
            &format!("end_time = \"8 ms\"\nstep_estimate = \"{how}\""),
        )
        .replace("FORM", "one_point")
        .replace("EXTRA", "");
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut scene: Scene = common::scene_from_str(&src);
        let mut worst = 0.0f64;
        while scene.sim.time < 8e-3 {
            scene.sim.step(f64::INFINITY).unwrap();
            // the abrupt start's imbalance decays as 1 / steps; the second half shows the scheme
            if scene.sim.time >= 4e-3 {
                worst = worst.max(scene.sim.energy.error());
            }
        }
        let estimates = scene
            .sim
            .global_step
            .as_ref()
            .map_or(0, |g| g.report.estimates);
        println!("{how}: 8 ms in {} steps", scene.sim.step);
        (
            scene.sim.u.clone(),
            scene.sim.energy.internal,
            estimates,
            worst,
        )
    })
}

#[test]
fn a_crushing_press_gives_the_same_bits_on_one_and_two_threads() {
    let (u1, e1, n1, err) = crushing_press(1, "global");
    let (u2, e2, n2, _) = crushing_press(2, "global");
    let (u_el, _, _, err_el) = crushing_press(2, "element");
    let norm = |u: &[f64; 3]| (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
    let scale = u_el.iter().map(norm).fold(0.0, f64::max);
    let diff = u1
        .iter()
        .zip(&u_el)
        .map(|(a, b)| norm(&[a[0] - b[0], a[1] - b[1], a[2] - b[2]]))
        .fold(0.0, f64::max);
    println!(
        "crushing press: {n1} estimates, largest energy error {:.4} % (element estimate {:.4} %), displacements within {:.2e} of the largest",
        100.0 * err,
        100.0 * err_el,
        diff / scale
    );
    // the two runs end at slightly different times (8 ms passed by less than a step)
    assert!(
        diff < 0.01 * scale,
        "displacements differ by {diff} of {scale}"
    );
    assert!(n1 >= 2, "the estimate should have been renewed: {n1}");
    assert_eq!(n1, n2);
    assert!(
        u1.iter()
            .zip(&u2)
            .all(|(a, b)| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())),
        "displacements differ"
    );
    assert_eq!(e1.to_bits(), e2.to_bits());
    assert!(
        err < 2.0 * err_el.max(1e-4),
        "energy error {err} against {err_el}"
    );
}

#[test]
fn what_the_estimate_does_not_hold_is_refused_by_name() {
    // fully integrated elements without F-bar: locking stiffness the operator does not hold
    let src = free_box([5.0, 4.0, 4.0], [5, 4, 4], "").replace(
        "material = \"m\"",
        "material = \"m\"\nformulation = \"full\"",
    );
    let mut scene = common::scene_from_str(&src);
    let e = scene.sim.initialise().unwrap_err().to_string();
    assert!(e.contains("full_fbar") && e.contains("`block`"), "{e}");
    // a factor above 0.9: the contact bound assumes the body at most 0.9 of its critical step
    let src = free_box([5.0, 4.0, 4.0], [5, 4, 4], "").replace(
        "step_estimate = \"global\"",
        "step_estimate = \"global\"\ndt_factor = 0.95",
    );
    let mut scene = common::scene_from_str(&src);
    let e = scene.sim.initialise().unwrap_err().to_string();
    assert!(e.contains("run.dt_factor"), "{e}");
}
