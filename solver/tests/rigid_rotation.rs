//! A block rotated rigidly by 90 degrees carries no stress (objectivity of the total
//! Lagrangian formulation): |sigma| < 1e-8 of the modulus, for both formulations.

use material::neo_hookean::NeoHookean;
use material::Material;
use nalgebra::{Rotation3, Vector3};
use solver::element::{Formulation, Hourglass, StepInput};
use solver::forces::element_loop;
use solver::generate::{box_mesh, BoxSpec};
use solver::model::{Model, Part};

fn max_stress(form: Formulation) -> f64 {
    let mesh = box_mesh(
        &BoxSpec {
            size: [0.01, 0.02, 0.015],
            divisions: [3, 3, 3],
            distortion: 0.2,
            ..Default::default()
        },
        "b",
    )
    .unwrap();
    let e = 1e6;
    let part = Part {
        name: "b".into(),
        material: Material::NeoHookean(NeoHookean {
            rho: 1000.0,
            lambda: 0.6 * e,
            mu: 0.4 * e,
        }),
        formulation: form,
    };
    let mut model = Model::build(mesh, vec![part], None, 0.9).unwrap();
    let rot = Rotation3::from_axis_angle(
        &nalgebra::Unit::new_normalize(Vector3::new(1.0, 2.0, 0.5)),
        std::f64::consts::FRAC_PI_2,
    );
    let u: Vec<[f64; 3]> = model
        .mesh
        .nodes
        .iter()
        .map(|p| {
            let x = Vector3::new(p[0], p[1], p[2]);
            let y = rot * x - x;
            [y[0], y[1], y[2]]
        })
        .collect();
    let v = vec![[0.0; 3]; u.len()];
    let mut force = vec![[0.0; 3]; u.len()];
    let mut stress = vec![[0.0; 6]; model.mesh.elements.len()];
    let nodes = model.mesh.nodes.clone();
    let input = StepInput {
        dt: 1e-6,
        bulk: None,
        want_stress: true,
        precision: Default::default(),
    };
    let Model { parts, groups, .. } = &mut model;
    element_loop(
        parts,
        groups,
        &nodes,
        &u,
        &v,
        &input,
        &mut force,
        Some(&mut stress),
    )
    .unwrap();
    stress
        .iter()
        .flat_map(|s| s.iter())
        .fold(0.0f64, |m, x| m.max(x.abs()))
        / e
}

#[test]
fn rigid_rotation_one_point_is_stress_free() {
    let s = max_stress(Formulation::OnePoint(Hourglass::default()));
    assert!(s < 1e-8, "max |sigma|/E = {s:e}");
}

#[test]
fn rigid_rotation_full_fbar_is_stress_free() {
    let s = max_stress(Formulation::Full { fbar: true });
    assert!(s < 1e-8, "max |sigma|/E = {s:e}");
}
