//! Subcycling (solver::subcycle) against the same run without it: a bar of a stiff solid
//! (wave speed 1280 m/s) with a core of the paper's liver (Ogden + Prony, about 13 m/s, so the
//! core's interior steps 16 times longer), fixed at one end and compressed 0.4 mm at the
//! other by a smooth step, without bulk viscosity. The core's dynamics are resolved by both
//! steps, so the subcycled run must converge to the plain one at the scheme's second order:
//! doubling the macro ratio `k` (4, 8, 16) multiplies the largest nodal difference by about 4
//! (3 to 5.5 accepted), and at `k` = 16 it stays below 1e-3 of the largest displacement. The
//! Prony series integrates over the macro step: the law's dissipation stays within 1 % of the
//! plain run's (a law given the small step instead dissipates half as much, and the order
//! falls to about 1). Each run keeps its energy balance to 1e-4 and skips the slow elements'
//! evaluations. The output schedule does not change the motion, and the same run on one and
//! on two threads gives the same bits.

use contact::Curve;
use material::neo_hookean::NeoHookean;
use material::Material;
use solver::bc::{Constraint, Kinematic};
use solver::element::{Formulation, Hourglass, HourglassForm};
use solver::generate::{box_mesh, BoxSpec};
use solver::model::{Model, Part};
use solver::simulation::{LoopSettings, Simulation};

const END: f64 = 2e-3;

fn material(mu: f64) -> Material {
    Material::NeoHookean(NeoHookean {
        rho: 1000.0,
        lambda: 2.0 * mu,
        mu,
    })
}

/// The bar after `END`, run with subcycling ratio `k` (1: off).
fn run(k: u32) -> Simulation {
    run_with_output(k, 0)
}

/// As [`run`], with the stress written every `every` steps (0: never).
fn run_with_output(k: u32, every: u64) -> Simulation {
    run_bar(k, every, false)
}

/// The bar; with `layer`, the stiff layer just after the core (x from 8 to 9 mm) is a part of
/// its own, soft (wave speed 28 m/s) but too thin to have an element inside it.
fn run_bar(k: u32, every: u64, layer: bool) -> Simulation {
    let mut mesh = box_mesh(
        &BoxSpec {
            size: [0.012, 0.006, 0.006],
            divisions: [12, 6, 6],
            ..Default::default()
        },
        "stiff",
    )
    .unwrap();
    mesh.part_names.push("core".into());
    for (e, c) in mesh.elements.iter().enumerate() {
        let x = c.iter().map(|&n| mesh.nodes[n as usize][0]).sum::<f64>() / 8.0;
        if (0.004..0.008).contains(&x) {
            mesh.element_part[e] = 1;
        }
        if layer && (0.008..0.009).contains(&x) {
            mesh.element_part[e] = 2;
        }
    }
    if layer {
        mesh.part_names.push("layer".into());
    }
    let form = Formulation::OnePoint(Hourglass {
        form: HourglassForm::Stiffness,
        ..Default::default()
    });
    let parts = vec![
        Part {
            name: "stiff".into(),
            material: material(4.096e8),
            formulation: form,
        },
        Part {
            name: "core".into(),
            material: material::named("paper:liver")
                .unwrap()
                .build("core")
                .unwrap(),
            formulation: form,
        },
    ];
    let mut parts = parts;
    if layer {
        parts.push(Part {
            name: "layer".into(),
            material: material(2e5),
            formulation: form,
        });
    }
    let face = |x: f64| -> Vec<u32> {
        (0..mesh.nodes.len() as u32)
            .filter(|&n| (mesh.nodes[n as usize][0] - x).abs() < 1e-9)
            .collect()
    };
    let (fixed, moved) = (face(0.0), face(0.012));
    let mut constraints: Vec<Constraint> = (0..3)
        .map(|d| Constraint {
            nodes: fixed.clone(),
            dof: d,
            kind: Kinematic::Fixed,
        })
        .collect();
    constraints.push(Constraint {
        nodes: moved,
        dof: 0,
        kind: Kinematic::Displacement(Curve::SmoothStep {
            amplitude: -4e-4,
            duration: 1e-3,
            start: 0.0,
        }),
    });
    let model = Model::build(mesh, parts, None, 0.9).unwrap();
    let settings = LoopSettings {
        bulk: None,
        subcycling: k,
        ..Default::default()
    };
    let mut sim =
        Simulation::new(model, settings, constraints, Vec::new(), None, every > 0).unwrap();
    while sim.time < END {
        let out = every > 0 && (sim.step + 1).is_multiple_of(every);
        sim.step(if out { 0.0 } else { f64::INFINITY }).unwrap();
    }
    sim
}

/// Largest nodal distance between two runs' displacements (m).
fn max_difference(a: &Simulation, b: &Simulation) -> f64 {
    a.u.iter()
        .zip(&b.u)
        .map(|(a, b)| {
            let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
            (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
        })
        .fold(0.0, f64::max)
}

#[test]
fn subcycled_core_converges_at_second_order_to_the_core_stepped_every_step() {
    let plain = run(1);
    assert!(plain.subcycling.is_none());
    let umax = plain
        .u
        .iter()
        .map(|u| (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt())
        .fold(0.0, f64::max);
    assert!(umax > 3e-4, "the bar was compressed: {umax:e} m");
    let mut diffs = Vec::new();
    for k in [4, 8, 16] {
        let sub = run(k);
        let sc = sub.subcycling.as_ref().expect("the core is slow enough");
        assert_eq!(sc.k, k);
        // of the core's 4 x 6 x 6 elements, the two middle layers touch no stiff element's
        // node (the bar's sides are free, so their nodes count too)
        assert_eq!(sc.parts, vec![("core".to_string(), 72, 144)]);
        assert!(sc.saved > 0);
        let err = sub.energy.error();
        assert!(err.abs() < 1e-4, "k = {k}: energy balance {err:e}");
        assert!(sub.energy.internal > 0.0);
        let (d, d0) = (sub.energy.law_dissipation, plain.energy.law_dissipation);
        assert!(
            d0 > 0.0 && (d - d0).abs() < 0.01 * d0,
            "k = {k}: law dissipation {d:e} J against {d0:e} J"
        );
        diffs.push(max_difference(&plain, &sub));
    }
    // measured 5.3e-9, 2.2e-8, 9.1e-8 m: ratios 4.2 and 4.1
    for w in diffs.windows(2) {
        let order = w[1] / w[0];
        assert!(
            (3.0..5.5).contains(&order),
            "doubling k multiplied the difference by {order} (second order: 4); {diffs:?}"
        );
    }
    assert!(
        diffs[2] < 1e-3 * umax,
        "k = 16 differs by {:e} m of {umax:e} m",
        diffs[2]
    );
}

#[test]
fn subcycling_gives_the_same_bits_on_one_and_two_threads() {
    let on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| run(16))
    };
    let (a, b) = (on(1), on(2));
    assert_eq!(a.step, b.step);
    for (x, y) in a.u.iter().zip(&b.u) {
        for d in 0..3 {
            assert_eq!(x[d].to_bits(), y[d].to_bits());
        }
    }
    assert_eq!(a.energy.internal.to_bits(), b.energy.internal.to_bits());
}

#[test]
fn the_output_schedule_does_not_change_the_subcycled_motion() {
    let quiet = run(16);
    for every in [1, 37] {
        let loud = run_with_output(16, every);
        assert_eq!(quiet.step, loud.step);
        assert_eq!(
            max_difference(&quiet, &loud),
            0.0,
            "stress every {every} steps"
        );
        assert!(loud.stress.as_ref().unwrap().iter().any(|s| s[0] != 0.0));
    }
}

#[test]
fn a_slow_part_without_slow_elements_still_reports_its_step_over_k() {
    let sim = run_bar(16, 0, true);
    let sc = sim.subcycling.as_ref().unwrap();
    // the layer is slow (its step is many times the stiff part's), but every element of it
    // touches the stiff part: none is slow, yet its elements move the core's slow nodes
    assert_eq!(sc.parts.len(), 1, "{:?}", sc.parts);
    for g in &sim.model.groups {
        let want = if g.part == 0 { 1 } else { 16 };
        assert_eq!(g.step_ratio, want, "part {}", g.part);
    }
    assert!(sim.energy.error().abs() < 1e-4);
}
