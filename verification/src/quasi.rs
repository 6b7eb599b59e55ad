//! Quasi-static solutions by palpa's dynamic relaxation (Underwood's adaptive viscous damping):
//! step the explicit loop with `LoopSettings::relaxation` until the out-of-balance force norm
//! falls below a tolerance times the internal force norm. Prescribed displacements given as
//! constant curves are applied in the first step.

use contact::Curve;
use material::Material;
use solver::bc::{Constraint, Kinematic, NodalLoad};
use solver::element::Formulation;
use solver::mesh::Mesh;
use solver::model::{Model, Part};
use solver::simulation::{DynamicRelaxation, LoopSettings, Simulation};
use std::time::Instant;

/// A converged (or not) relaxation.
pub struct Relaxed {
    /// The simulation at the end.
    pub sim: Simulation,
    /// Steps taken.
    pub steps: u64,
    /// Final residual.
    pub residual: f64,
    /// Whether the residual reached the tolerance.
    pub converged: bool,
    /// Wall time (s).
    pub seconds: f64,
}

/// A one-part model.
pub fn model(mesh: Mesh, material: Material, formulation: Formulation) -> Result<Model, String> {
    let part = Part {
        name: mesh
            .part_names
            .first()
            .cloned()
            .unwrap_or_else(|| "body".into()),
        material,
        formulation,
    };
    Model::build(mesh, vec![part], None, 0.9).map_err(|e| e.to_string())
}

/// Prescribed displacement `u` on every dof of one node (fixed where the value is exactly 0).
pub fn prescribe_node(out: &mut Vec<Constraint>, node: u32, u: [f64; 3]) {
    for (d, &x) in u.iter().enumerate() {
        out.push(Constraint {
            nodes: vec![node],
            dof: d,
            kind: if x == 0.0 {
                Kinematic::Fixed
            } else {
                Kinematic::Displacement(Curve::Constant { value: x })
            },
        });
    }
}

/// A constraint on a set.
pub fn on(nodes: &[u32], dof: usize, value: Option<f64>) -> Constraint {
    Constraint {
        nodes: nodes.to_vec(),
        dof,
        kind: match value {
            None => Kinematic::Fixed,
            Some(x) => Kinematic::Displacement(Curve::Constant { value: x }),
        },
    }
}

impl Relaxed {
    /// The relaxation if its residual reached the tolerance, else an error saying how far it got.
    pub fn converged(self) -> Result<Relaxed, String> {
        if self.converged {
            Ok(self)
        } else {
            Err(format!(
                "relaxation: residual {:.2e} after {} steps",
                self.residual, self.steps
            ))
        }
    }
}

/// Relax to equilibrium: at most `max_steps`, residual below `tolerance`.
pub fn relax(
    model: Model,
    constraints: Vec<Constraint>,
    loads: Vec<NodalLoad>,
    tolerance: f64,
    max_steps: u64,
) -> Result<Relaxed, String> {
    let settings = LoopSettings {
        bulk: None,
        relaxation: Some(DynamicRelaxation { tolerance }),
        ..Default::default()
    };
    let t0 = Instant::now();
    let mut sim = Simulation::new(model, settings, constraints, loads, None, false)
        .map_err(|e| e.to_string())?;
    let mut converged = false;
    while sim.step < max_steps {
        sim.step(f64::INFINITY).map_err(|e| e.to_string())?;
        if sim.step > 10 && sim.residual < tolerance {
            converged = true;
            break;
        }
    }
    let (steps, residual) = (sim.step, sim.residual);
    Ok(Relaxed {
        sim,
        steps,
        residual,
        converged,
        seconds: t0.elapsed().as_secs_f64(),
    })
}

/// Largest |component| of a field.
pub fn max_abs(u: &[[f64; 3]]) -> f64 {
    u.iter()
        .flat_map(|u| u.iter())
        .fold(0.0f64, |m, x| m.max(x.abs()))
}
