//! Mesh quality report: counts per part, corner Jacobians, what clean-up and smoothing did,
//! timings and memory.

use rayon::prelude::*;

use super::cleanup::CleanupReport;
use super::jacobian::{
    characteristic_length, corner_jacobians, element_coords, min_scaled_jacobian,
};
use super::smooth::SmoothReport;
use solver::mesh::Mesh;

/// Quality figures of a hexahedral mesh.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshQuality {
    /// Number of nodes.
    pub n_nodes: usize,
    /// Number of elements.
    pub n_elements: usize,
    /// (part name, element count), in part-id order.
    pub part_counts: Vec<(String, usize)>,
    /// Smallest scaled corner Jacobian over all elements (1 = cube).
    pub min_scaled_jacobian: f64,
    /// Mean over elements of the element's smallest scaled corner Jacobian.
    pub mean_scaled_jacobian: f64,
    /// Smallest corner Jacobian (m^3).
    pub min_corner_jacobian: f64,
    /// Elements with a non-positive corner Jacobian (must be 0).
    pub n_nonpositive: usize,
    /// Shortest element edge (m).
    pub min_edge: f64,
    /// Smallest characteristic length V / A_max (m), which sets the explicit time step.
    pub min_char_length: f64,
    /// What the clean-up changed.
    pub cleanup: CleanupReport,
    /// What smoothing did.
    pub smoothing: SmoothReport,
    /// Wall time of clean-up and hexahedron generation (s).
    pub seconds_mesh: f64,
    /// Wall time of smoothing (s).
    pub seconds_smooth: f64,
    /// Approximate memory held by the mesh (bytes).
    pub mesh_bytes: usize,
}

impl MeshQuality {
    /// Measure a mesh (Jacobians, counts, memory); clean-up, smoothing and timings are left
    /// at their defaults for the caller to fill.
    pub fn measure(mesh: &Mesh) -> Self {
        let per: Vec<(f64, f64, f64, f64)> = mesh
            .elements
            .par_iter()
            .map(|c| {
                let x = element_coords(&mesh.nodes, c);
                let j = corner_jacobians(&x)
                    .iter()
                    .copied()
                    .fold(f64::INFINITY, f64::min);
                let mut e = f64::INFINITY;
                for (a, b) in [
                    (0, 1),
                    (1, 2),
                    (2, 3),
                    (3, 0),
                    (4, 5),
                    (5, 6),
                    (6, 7),
                    (7, 4),
                    (0, 4),
                    (1, 5),
                    (2, 6),
                    (3, 7),
                ] {
                    let d = ((x[a][0] - x[b][0]).powi(2)
                        + (x[a][1] - x[b][1]).powi(2)
                        + (x[a][2] - x[b][2]).powi(2))
                    .sqrt();
                    e = e.min(d);
                }
                (min_scaled_jacobian(&x), j, e, characteristic_length(&x))
            })
            .collect();
        let mut q = MeshQuality {
            n_nodes: mesh.nodes.len(),
            n_elements: mesh.elements.len(),
            min_scaled_jacobian: f64::INFINITY,
            min_corner_jacobian: f64::INFINITY,
            min_edge: f64::INFINITY,
            min_char_length: f64::INFINITY,
            ..Default::default()
        };
        let mut sum = 0.0;
        for &(s, j, e, l) in &per {
            q.min_char_length = q.min_char_length.min(l);
            q.min_scaled_jacobian = q.min_scaled_jacobian.min(s);
            q.min_corner_jacobian = q.min_corner_jacobian.min(j);
            q.min_edge = q.min_edge.min(e);
            sum += s;
            if j <= 0.0 {
                q.n_nonpositive += 1;
            }
        }
        if !per.is_empty() {
            q.mean_scaled_jacobian = sum / per.len() as f64;
        }
        let mut counts = vec![0usize; mesh.part_names.len()];
        for &p in &mesh.element_part {
            if let Some(c) = counts.get_mut(p as usize) {
                *c += 1;
            }
        }
        q.part_counts = mesh.part_names.iter().cloned().zip(counts).collect();
        let sets: usize = mesh.node_sets.values().map(|s| s.len() * 4).sum::<usize>()
            + mesh
                .element_sets
                .values()
                .map(|s| s.len() * 4)
                .sum::<usize>();
        q.mesh_bytes = mesh.nodes.len() * 24 + mesh.elements.len() * (32 + 4) + sets;
        q
    }

    /// A multi-line human-readable summary.
    pub fn summary(&self) -> String {
        let mut s = format!("{} nodes, {} hexahedra\n", self.n_nodes, self.n_elements);
        for (name, c) in &self.part_counts {
            s += &format!("  {name:<10} {c:>9}\n");
        }
        s += &format!(
            "scaled Jacobian: min {:.3}, mean {:.3}; non-positive corners: {}; shortest edge {:.2} mm, smallest V/A_max {:.2} mm\n",
            self.min_scaled_jacobian,
            self.mean_scaled_jacobian,
            self.n_nonpositive,
            self.min_edge * 1e3,
            self.min_char_length * 1e3
        );
        s += &format!(
            "clean-up: {} island voxels relabelled, {} detached removed, non-manifold: {} removed, {} filled, {} left\n",
            self.cleanup.island_voxels_relabelled,
            self.cleanup.detached_voxels_removed,
            self.cleanup.nonmanifold_removed,
            self.cleanup.nonmanifold_filled,
            self.cleanup.nonmanifold_left
        );
        s += &format!(
            "smoothing: {} movable nodes, {} half steps, {} back-offs, {} reverted, displacement mean {:.2} mm max {:.2} mm\n",
            self.smoothing.movable_nodes,
            self.smoothing.half_steps,
            self.smoothing.backoffs,
            self.smoothing.reverted,
            self.smoothing.mean_displacement * 1e3,
            self.smoothing.max_displacement * 1e3
        );
        s += &format!(
            "time: mesh {:.2} s, smooth {:.2} s; mesh memory {:.1} MB",
            self.seconds_mesh,
            self.seconds_smooth,
            self.mesh_bytes as f64 / 1e6
        );
        s
    }
}
