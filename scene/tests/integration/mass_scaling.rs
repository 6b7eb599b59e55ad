//! Selective mass scaling (issue 2, item 5), at build time and during the run.
//!
//! - Build time: a block graded 4:1 in z has thin elements at its base; a target step between
//!   the thinnest and the thickest element's step scales only the elements below it, each to
//!   `s = (target / (factor kappa L/c))^2`, and the added mass equals `sum rho V (s - 1)`
//!   computed here from the mesh. A limit below that is refused with a message that names the
//!   part and the percentage.
//! - Run time (LS-DYNA's negative DT2MS): a block crushed 45 % in 4 ms shrinks its elements,
//!   so without mass scaling the step falls to about half its initial value; with a target of
//!   0.75 of the initial step, no step is taken below the target, mass is added during the run and
//!   reported, and the energy balance (which counts the kinetic energy of the added mass) stays
//!   within 1 %.

use crate::common;
use solver::output::history::column;

fn scene(grading: f64, end: &str, crush: &str, mass_scaling: &str) -> String {
    format!(
        r#"
[run]
end_time = "{end}"

[mesh]
generator = "box"
size = ["8 mm", "8 mm", "8 mm"]
divisions = [4, 4, 8]
grading = [1, 1, {grading}]
part = "block"

[materials.m]
law = "neo_hookean"
density = "1000 kg/m^3"
youngs_modulus = "1 MPa"
poisson_ratio = 0.3

[[part]]
name = "block"
material = "m"
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
displacement = {{ z = {{ kind = "smooth_step", value = "{crush}", end = "{end}" }} }}

{mass_scaling}

[output]
vtk = false
history_interval = "0.05 ms"
"#
    )
}

#[test]
fn build_time_scaling_adds_the_closed_form_mass_to_thin_elements_only() {
    let plain = common::scene_from_str(&scene(4.0, "1 ms", "-0.01 mm", ""));
    let m0 = &plain.sim.model;
    let factor = plain.sim.settings.dt_factor;
    let kappa = m0.groups[0].dt_kappa;
    // Element steps from the mesh: factor kappa L / c, L = V / A_max.
    let law = &m0.parts[0].material;
    let c = law.initial_wave_speed();
    let rho = law.density();
    let steps: Vec<(f64, f64)> = m0
        .mesh
        .elements
        .iter()
        .map(|conn| {
            let x: [[f64; 3]; 8] = std::array::from_fn(|a| m0.mesh.nodes[conn[a] as usize]);
            let geo = solver::hex::element_geometry(&x).unwrap();
            let dt = factor * kappa * solver::model::initial_element_dt(&x, geo.volume, c);
            (dt, geo.volume)
        })
        .collect();
    let dt_min = steps.iter().map(|s| s.0).fold(f64::INFINITY, f64::min);
    let dt_max = steps.iter().map(|s| s.0).fold(0.0, f64::max);
    let target = 0.5 * (dt_min + dt_max);
    let expect_added: f64 = steps
        .iter()
        .filter(|s| s.0 < target)
        .map(|s| rho * s.1 * ((target / s.0).powi(2) - 1.0))
        .sum();
    let expect_count = steps.iter().filter(|s| s.0 < target).count();
    assert!(expect_count > 0 && expect_count < steps.len());

    let ms = format!("[mass_scaling]\ntarget_dt = {target}\nmax_added = 10.0");
    let scaled = common::scene_from_str(&scene(4.0, "1 ms", "-0.01 mm", &ms));
    let pm = &scaled.sim.model.part_mass[0];
    println!(
        "target {target:.4e} s: {} of {} elements scaled, added {:.4e} kg (closed form {expect_added:.4e} kg), {:.2} % of {:.4e} kg",
        pm.scaled_elements,
        pm.elements,
        pm.added,
        100.0 * pm.added / pm.physical,
        pm.physical
    );
    assert_eq!(pm.scaled_elements, expect_count);
    assert!((pm.added - expect_added).abs() <= 1e-9 * expect_added);
    assert!((scaled.sim.model.scaled_dt * factor - target).abs() < 1e-9 * target);

    // A limit below the needed mass is refused, naming the part and the figures.
    let tight = expect_added / pm.physical * 0.5;
    let ms = format!("[mass_scaling]\ntarget_dt = {target}\nmax_added = {tight}");
    let spec: scene::SceneSpec = toml::from_str(&scene(4.0, "1 ms", "-0.01 mm", &ms)).unwrap();
    let err = scene::build::build_scene(spec, std::path::Path::new("ms.toml"), "")
        .err()
        .expect("the limit must be refused")
        .to_string();
    assert!(
        err.contains("mass scaling would add") && err.contains("block"),
        "{err}"
    );
}

#[test]
fn run_time_scaling_holds_the_target_step_of_a_crushed_block() {
    // Without mass scaling the crushed block's step falls.
    let mut plain = common::scene_from_str(&scene(1.0, "4 ms", "-3.6 mm", ""));
    let dt0 = plain.sim.settings.dt_factor * plain.sim.model.initial_dt.0;
    common::run_to_end(&mut plain, "ms-plain");
    let (lo, _) = plain.sim.dt_range;
    println!(
        "no mass scaling: dt {lo:.4e} .. initial {dt0:.4e} s ({:.1} %)",
        100.0 * lo / dt0
    );
    assert!(lo < 0.8 * dt0, "the crushed block's step should fall");

    let target = 0.75 * dt0;
    let ms = format!("[mass_scaling]\ntarget_dt = {target}\nmax_added = 2.0");
    let mut scaled = common::scene_from_str(&scene(1.0, "4 ms", "-3.6 mm", &ms));
    assert_eq!(
        scaled.sim.model.added_mass(),
        0.0,
        "nothing below the target at t = 0"
    );
    let (cols, rows) = common::run_to_end(&mut scaled, "ms-run");
    let (lo, _) = scaled.sim.dt_range;
    let pm = &scaled.sim.model.part_mass[0];
    let err = column(&cols, &rows, "energy_error").unwrap();
    let worst = err[rows.len() / 10..].iter().cloned().fold(0.0, f64::max);
    println!(
        "run-time mass scaling: dt >= {lo:.4e} s (target {target:.4e}), {} of {} elements scaled, added {:.3} %, max energy error {:.4} %",
        pm.scaled_elements,
        pm.elements,
        100.0 * pm.added / pm.physical,
        100.0 * worst
    );
    assert!(
        lo >= target * (1.0 - 1e-9),
        "a step {lo:e} below the target {target:e}"
    );
    assert!(pm.added > 0.0 && pm.scaled_elements > 0);
    let nodal: f64 = scaled.sim.model.mass.iter().sum();
    assert!(
        (nodal - pm.physical - pm.added).abs() < 1e-9 * nodal,
        "nodal masses {nodal} vs physical + added {}",
        pm.physical + pm.added
    );
    assert!(worst < 0.01, "energy error {:.3} %", 100.0 * worst);

    // A limit the run passes stops it with the element and the time named.
    let ms = format!("[mass_scaling]\ntarget_dt = {target}\nmax_added = 1e-4");
    let mut tight = common::scene_from_str(&scene(1.0, "4 ms", "-3.6 mm", &ms));
    let out = common::tmp_dir("ms-tight");
    let (_, err) = scene::run::run_scene(
        &mut tight,
        out.path(),
        &std::sync::atomic::AtomicBool::new(false),
        |_| {},
    );
    let msg = err.expect("the run must stop").to_string();
    println!("{msg}");
    assert!(
        msg.contains("element") && msg.contains("run-time mass scaling") && msg.contains("limit"),
        "{msg}"
    );
}

#[test]
fn target_initial_keeps_the_initial_step_and_parses_with_clear_errors() {
    use solver::model::StepTarget;
    assert_eq!(StepTarget::parse("initial"), Ok(StepTarget::Initial(1.0)));
    assert_eq!(
        StepTarget::parse("4 x initial"),
        Ok(StepTarget::Initial(4.0))
    );
    assert_eq!(StepTarget::parse("2 us"), Ok(StepTarget::Step(2e-6)));
    for bad in ["2 kg", "x initial", "-1 x initial", "0 s", "soon"] {
        let e = StepTarget::parse(bad).expect_err(bad);
        println!("{bad:?}: {e}");
        assert!(!e.is_empty());
    }
    // A bad target in a scene names the file and the key.
    let ms = "[mass_scaling]\ntarget_dt = \"2 kg\"";
    let spec: Result<scene::SceneSpec, _> = toml::from_str(&scene(1.0, "2 ms", "-1.5 mm", ms));
    let e = spec.expect_err("a mass as target step").to_string();
    assert!(e.contains("target_dt") && e.contains("time"), "{e}");

    // "initial": nothing is added at the start, and the crushed block never steps below its
    // initial step.
    let ms = "[mass_scaling]\ntarget_dt = \"initial\"\nmax_added = 2.0";
    let mut s = common::scene_from_str(&scene(1.0, "2 ms", "-1.5 mm", ms));
    let dt0 = s.sim.settings.dt_factor * s.sim.model.initial_dt.0;
    assert_eq!(s.sim.model.added_mass(), 0.0);
    common::run_to_end(&mut s, "ms-initial");
    let (lo, _) = s.sim.dt_range;
    let pm = &s.sim.model.part_mass[0];
    println!(
        "target initial: dt >= {lo:.4e} (initial {dt0:.4e}), added {:.3} %",
        100.0 * pm.added / pm.physical
    );
    assert!(lo >= dt0 * (1.0 - 1e-9));
    assert!(pm.added > 0.0);
}
