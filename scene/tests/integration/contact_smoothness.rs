//! Smoothness: a finger (capsule) whose radius equals one element (1 mm) presses 1 mm into a
//! block of 1 mm elements, off the node grid. Metric: once the force exceeds 5 % of its
//! largest value, every step-to-step change |F_(n+1) - F_n| stays below 5 % of |F_n| (F the
//! reaction along the pressing direction, every step).

use crate::common;

fn scene(motion: &str, center: &str) -> String {
    format!(
        r#"
[run]
end_time = "45 ms"

[mesh]
generator = "box"
origin = ["-8 mm", "-8 mm", "-8 mm"]
size = ["16 mm", "16 mm", "8 mm"]
divisions = [16, 16, 8]

[materials.gel]
law = "neo_hookean"
density = "1000 kg/m^3"
youngs_modulus = "30 kPa"
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
motion = {motion}
part = [{{ shape = "capsule", center = {center}, axis = [0, 0, 1], radius = "1 mm", length = "10 mm" }}]

[contact]
surface = "zmax"

[output]
vtk = false
"#
    )
}

/// Step the scene to its end; returns the reaction at every step.
fn reaction_history(src: &str) -> Vec<f64> {
    let mut scene = common::scene_from_str(src);
    let sim = &mut scene.sim;
    let mut out = Vec::new();
    let mut vals = Vec::new();
    while sim.time < scene.end_time {
        sim.step(f64::INFINITY).unwrap();
        vals.clear();
        sim.stages[0].history_values(&mut vals);
        out.push(vals[3]);
    }
    out
}

fn worst_jump(f: &[f64]) -> (f64, usize) {
    let fmax = f.iter().cloned().fold(0.0, f64::max);
    let start = f.iter().position(|&x| x > 0.05 * fmax).unwrap();
    let mut worst: (f64, usize) = (0.0, 0);
    for n in start..f.len() - 1 {
        let j = (f[n + 1] - f[n]).abs() / f[n].abs();
        if j > worst.0 {
            worst = (j, n);
        }
    }
    worst
}

#[test]
fn one_element_finger_press_is_smooth() {
    let src = scene(
        r#"{ kind = "displacement", curve = { kind = "smooth_step", value = "1 mm", end = "40 ms" } }"#,
        r#"["0.37 mm", "0.21 mm", "1 mm"]"#,
    );
    let f = reaction_history(&src);
    let (j, n) = worst_jump(&f);
    println!(
        "press: {} steps, max force {:.4e} N, worst step-to-step jump {:.3} % at step {n}",
        f.len(),
        f.iter().cloned().fold(0.0, f64::max),
        100.0 * j
    );
    assert!(j < 0.05, "force jumps {:.2} % in one step", 100.0 * j);
}
