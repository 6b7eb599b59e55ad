//! Patch test (issue 2): a distorted 3x3x3 mesh whose boundary nodes follow a linear
//! displacement field u = A X + b, solved by dynamic relaxation, reproduces the exact
//! (homogeneous) interior displacements to 1e-8 relative, for both element formulations.
//! A homogeneous deformation satisfies equilibrium for any homogeneous material, so the
//! exact answer is u = A X + b at every node, whatever the law.

use contact::Curve;
use material::neo_hookean::NeoHookean;
use material::Material;
use solver::bc::{Constraint, Kinematic};
use solver::element::{Formulation, Hourglass, HourglassForm};
use solver::generate::{box_mesh, BoxSpec};
use solver::model::{Model, Part};
use solver::simulation::{DynamicRelaxation, LoopSettings, Simulation};

const A: [[f64; 3]; 3] = [
    [2e-3, 1e-3, -0.5e-3],
    [0.7e-3, -1.5e-3, 0.4e-3],
    [-0.3e-3, 0.9e-3, 1.2e-3],
];
const B: [f64; 3] = [1e-5, -2e-5, 0.5e-5];

fn exact(x: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| A[i][0] * x[0] + A[i][1] * x[1] + A[i][2] * x[2] + B[i])
}

fn patch(form: Formulation) -> f64 {
    let mesh = box_mesh(
        &BoxSpec {
            size: [0.01, 0.012, 0.009],
            divisions: [3, 3, 3],
            distortion: 0.25,
            seed: 7,
            ..Default::default()
        },
        "patch",
    )
    .unwrap();
    let mut boundary: Vec<u32> = mesh.node_sets.values().flatten().copied().collect();
    boundary.sort_unstable();
    boundary.dedup();
    let mut constraints = Vec::new();
    for &n in &boundary {
        let u = exact(mesh.nodes[n as usize]);
        for d in 0..3 {
            constraints.push(Constraint {
                nodes: vec![n],
                dof: d,
                kind: Kinematic::Displacement(Curve::Constant { value: u[d] }),
            });
        }
    }
    let part = Part {
        name: "patch".into(),
        material: Material::NeoHookean(NeoHookean {
            rho: 1000.0,
            lambda: 1.5e6,
            mu: 1.0e6,
        }),
        formulation: form,
    };
    let model = Model::build(mesh, vec![part], None, 0.9).unwrap();
    let settings = LoopSettings {
        bulk: None,
        relaxation: Some(DynamicRelaxation { tolerance: 1e-13 }),
        ..Default::default()
    };
    let mut sim = Simulation::new(model, settings, constraints, Vec::new(), None, false).unwrap();
    for _ in 0..200_000 {
        sim.step(f64::INFINITY).unwrap();
        if sim.step > 10 && sim.residual < 1e-13 {
            break;
        }
    }
    assert!(
        sim.residual < 1e-13,
        "not converged: residual {:e} after {} steps",
        sim.residual,
        sim.step
    );
    let umax = sim
        .u
        .iter()
        .flat_map(|u| u.iter())
        .fold(0.0f64, |m, x| m.max(x.abs()));
    let mut err: f64 = 0.0;
    for (n, x) in sim.model.mesh.nodes.iter().enumerate() {
        let ue = exact(*x);
        for d in 0..3 {
            err = err.max((sim.u[n][d] - ue[d]).abs());
        }
    }
    println!(
        "{}: {} steps, max error / max |u| = {:.2e}",
        form.label(),
        sim.step,
        err / umax
    );
    err / umax
}

#[test]
fn patch_test_one_point_viscous() {
    assert!(patch(Formulation::OnePoint(Hourglass::default())) < 1e-8);
}

#[test]
fn patch_test_one_point_stiffness() {
    assert!(
        patch(Formulation::OnePoint(Hourglass {
            form: HourglassForm::Stiffness,
            coefficient: 0.1,
            modulus: solver::element::HourglassModulus::PWave,
        })) < 1e-8
    );
}

#[test]
fn patch_test_full_fbar() {
    assert!(patch(Formulation::Full { fbar: true }) < 1e-8);
}

#[test]
fn patch_test_full() {
    assert!(patch(Formulation::Full { fbar: false }) < 1e-8);
}
