//! The scene's node sets (`[node_sets.NAME]`: a box, a plane or a list of nodes), added to the
//! mesh, and the lookup by name that boundary conditions, loads and outputs use.

use super::locate::{axis, Locate};
use super::spec::NodeSetSpec;
use solver::mesh::Mesh;
use std::collections::BTreeMap;

/// Add the scene's node sets to the mesh; an error names the set and what is wrong with it.
pub(crate) fn add_node_sets(
    sets: &BTreeMap<String, NodeSetSpec>,
    mesh: &mut Mesh,
    at: Locate,
) -> Result<(), String> {
    for (name, ns) in sets {
        let key = format!("node_sets.{name}");
        let mut nodes: Vec<u32> = Vec::new();
        let mut given = 0;
        if let (Some(lo), Some(hi)) = (ns.box_min, ns.box_max) {
            nodes.extend(
                mesh.nodes_in_box([lo[0].0, lo[1].0, lo[2].0], [hi[0].0, hi[1].0, hi[2].0]),
            );
            given += 1;
        }
        if let (Some(ax), Some(val)) = (&ns.plane_axis, ns.plane_value) {
            let a = axis(ax)
                .ok_or_else(|| at.err(&key, Some("plane_axis"), &"plane_axis must be x, y or z"))?;
            nodes.extend(mesh.nodes_on_plane(a, val.0, ns.tolerance.map(|t| t.0).unwrap_or(1e-9)));
            given += 1;
        }
        if let Some(ids) = &ns.nodes {
            if let Some(bad) = ids.iter().find(|&&n| n as usize >= mesh.nodes.len()) {
                return Err(at.err(
                    &key,
                    Some(&format!("[node_sets.{name}]")),
                    &format!("node {bad} does not exist"),
                ));
            }
            nodes.extend(ids);
            given += 1;
        }
        if given != 1 {
            return Err(at.err(
                &key,
                Some(&format!("[node_sets.{name}]")),
                &"give exactly one of box_min+box_max, plane_axis+plane_value, nodes",
            ));
        }
        nodes.sort_unstable();
        nodes.dedup();
        if nodes.is_empty() {
            return Err(at.err(
                &key,
                Some(&format!("[node_sets.{name}]")),
                &"selects no node",
            ));
        }
        mesh.node_sets.insert(name.clone(), nodes);
    }
    Ok(())
}

/// The nodes of set `name` (`all`: every node), or an error at `key` naming the known sets.
pub(crate) fn node_set(mesh: &Mesh, at: Locate, name: &str, key: &str) -> Result<Vec<u32>, String> {
    if name == "all" {
        return Ok((0..mesh.nodes.len() as u32).collect());
    }
    mesh.node_sets.get(name).cloned().ok_or_else(|| {
        let known: Vec<&String> = mesh.node_sets.keys().collect();
        at.err(
            key,
            Some(&format!("\"{name}\"")),
            &format!("no node set `{name}`; known: all, {known:?}"),
        )
    })
}
