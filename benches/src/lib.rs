//! Shared set-up for palpa's benchmarks: the standard 100k-element neo-Hookean block.
#![warn(missing_docs)]

use contact::Curve;
use material::neo_hookean::NeoHookean;
use material::Material;
use solver::bc::{Constraint, Kinematic};
use solver::element::{Formulation, Hourglass};
use solver::generate::{box_mesh, BoxSpec};
use solver::model::{Model, Part};
use solver::simulation::{LoopSettings, Simulation};

/// A block of `n.0 x n.1 x n.2` one-point neo-Hookean elements (soft tissue scale), bottom
/// fixed, top pressed down, ready to step.
pub fn block_simulation(n: [usize; 3], formulation: Formulation) -> Simulation {
    let mesh = box_mesh(
        &BoxSpec {
            size: [0.1, 0.1, 0.1 * n[2] as f64 / n[0] as f64],
            divisions: n,
            ..Default::default()
        },
        "block",
    )
    .unwrap();
    let bottom = mesh.node_sets["zmin"].clone();
    let top = mesh.node_sets["zmax"].clone();
    let part = Part {
        name: "block".into(),
        material: Material::NeoHookean(NeoHookean {
            rho: 1060.0,
            lambda: 1.0e6,
            mu: 4.0e4,
        }),
        formulation,
    };
    let model = Model::build(mesh, vec![part], None, 0.9).unwrap();
    let constraints = vec![
        Constraint {
            nodes: bottom,
            dof: 2,
            kind: Kinematic::Fixed,
        },
        Constraint {
            nodes: top,
            dof: 2,
            kind: Kinematic::Velocity(Curve::Constant { value: -0.5 }),
        },
    ];
    Simulation::new(
        model,
        LoopSettings::default(),
        constraints,
        Vec::new(),
        None,
        false,
    )
    .unwrap()
}

/// The default one-point formulation with viscous hourglass control.
pub fn one_point() -> Formulation {
    Formulation::OnePoint(Hourglass::default())
}
