//! The scene's kinematic conditions (`[[boundary]]`: fixed, symmetric, prescribed displacement
//! or velocity), nodal loads (`[[load]]`) and initial velocities, on named node sets.

use super::locate::{axis, Locate};
use super::node_sets::node_set;
use super::spec::SceneSpec;
use solver::bc::{Constraint, Kinematic, NodalLoad};
use solver::mesh::Mesh;

/// The constraints of every `[[boundary]]`, in order.
pub(crate) fn constraints(
    spec: &SceneSpec,
    mesh: &Mesh,
    at: Locate,
) -> Result<Vec<Constraint>, String> {
    let mut constraints = Vec::new();
    for (i, b) in spec.boundaries.iter().enumerate() {
        let key = format!("boundary[{i}]");
        let nodes = node_set(mesh, at, &b.nodes, &format!("{key}.nodes"))?;
        let mut fixed = [false; 3];
        if let Some(f) = &b.fix {
            for d in f {
                if d == "all" {
                    fixed = [true; 3];
                } else {
                    let a = axis(d).ok_or_else(|| {
                        at.err(
                            &format!("{key}.fix"),
                            Some("fix"),
                            &format!("`{d}` is not x, y, z or all"),
                        )
                    })?;
                    fixed[a] = true;
                }
            }
        }
        if let Some(s) = &b.symmetry {
            let a = axis(s).ok_or_else(|| {
                at.err(
                    &format!("{key}.symmetry"),
                    Some("symmetry"),
                    &format!("`{s}` is not x, y or z"),
                )
            })?;
            fixed[a] = true;
        }
        for (a, f) in fixed.iter().enumerate() {
            if *f {
                constraints.push(Constraint {
                    nodes: nodes.clone(),
                    dof: a,
                    kind: Kinematic::Fixed,
                });
            }
        }
        if let Some(d) = &b.displacement {
            for (a, c) in [&d.x, &d.y, &d.z].into_iter().enumerate() {
                if let Some(c) = c {
                    let cv = c.boundary_curve().map_err(|m| {
                        at.err(&format!("{key}.displacement"), Some("displacement"), &m)
                    })?;
                    constraints.push(Constraint {
                        nodes: nodes.clone(),
                        dof: a,
                        kind: Kinematic::Displacement(cv),
                    });
                }
            }
        }
        if let Some(d) = &b.velocity {
            for (a, c) in [&d.x, &d.y, &d.z].into_iter().enumerate() {
                if let Some(c) = c {
                    let cv = c
                        .boundary_curve()
                        .map_err(|m| at.err(&format!("{key}.velocity"), Some("velocity"), &m))?;
                    constraints.push(Constraint {
                        nodes: nodes.clone(),
                        dof: a,
                        kind: Kinematic::Velocity(cv),
                    });
                }
            }
        }
    }
    Ok(constraints)
}

/// The nodal loads of every `[[load]]` (a `total` force shared equally by the set's nodes).
pub(crate) fn loads(spec: &SceneSpec, mesh: &Mesh, at: Locate) -> Result<Vec<NodalLoad>, String> {
    let mut loads = Vec::new();
    for (i, l) in spec.loads.iter().enumerate() {
        let key = format!("load[{i}]");
        let nodes = node_set(mesh, at, &l.nodes, &format!("{key}.nodes"))?;
        let share = if l.total.unwrap_or(false) {
            1.0 / nodes.len() as f64
        } else {
            1.0
        };
        for (a, c) in [&l.force.x, &l.force.y, &l.force.z].into_iter().enumerate() {
            if let Some(c) = c {
                let cv = c
                    .boundary_curve()
                    .map_err(|m| at.err(&format!("{key}.force"), Some("force"), &m))?
                    .scaled(share);
                loads.push(NodalLoad {
                    nodes: nodes.clone(),
                    dof: a,
                    curve: cv,
                });
            }
        }
    }
    Ok(loads)
}

/// The initial velocities, in order (a later one overrides an earlier one on a node).
pub(crate) fn initial_velocities(
    spec: &SceneSpec,
    mesh: &Mesh,
    at: Locate,
) -> Result<Vec<(Vec<u32>, [f64; 3])>, String> {
    let mut initial_velocity = Vec::new();
    for (i, iv) in spec.initial_velocities.iter().enumerate() {
        let nodes = node_set(mesh, at, &iv.nodes, &format!("initial_velocity[{i}].nodes"))?;
        initial_velocity.push((
            nodes,
            [iv.velocity[0].0, iv.velocity[1].0, iv.velocity[2].0],
        ));
    }
    Ok(initial_velocity)
}
