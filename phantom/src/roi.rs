//! Region of interest: liver elements on the liver's surface near its inferior edge.
//!
//! A liver element is on the surface when one of its six faces is shared with a non-liver
//! element or with nothing (tumours count as liver). The ROI keeps the surface elements whose
//! centroid lies within `radius` of the ROI centre, nearest first, at most `max_count`
//! (the paper's ROI had 377 elements on the liver's edge).
//!
//! Across respiratory phases the liver moves rigidly (caudally by `phase * max_liver_shift`),
//! and the voxel mesh of another phase has other elements. [`carry_roi`] keeps one ROI's
//! material points: each reference centroid `c_i`, moved with the liver to `c_i + d`, is read
//! from the organ-surface element of the new mesh whose centroid is nearest, so that column
//! `i` of every phase's ROI is the same point of the liver (within a voxel, half a voxel on
//! average on the 8 mm test phantom).

use std::collections::HashMap;

use serde::Serialize;

use super::params::RoiParams;
use solver::mesh::{Mesh, FACES};

/// The region of interest.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Roi {
    /// Centre used for the selection (m).
    pub center: [f64; 3],
    /// Element ids, nearest to the centre first.
    pub elements: Vec<u32>,
    /// Element centroids (m), same order.
    pub centroids: Vec<[f64; 3]>,
}

impl Roi {
    /// The ROI's element ids sorted, each once: the mesh's element set `roi`.
    pub fn element_set(&self) -> Vec<u32> {
        let mut s = self.elements.clone();
        s.sort_unstable();
        s.dedup();
        s
    }

    /// JSON text of the ROI.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_default()
    }

    /// CSV text: `element,x,y,z` (m).
    pub fn to_csv(&self) -> String {
        let mut s = String::from("element,x,y,z\n");
        for (e, c) in self.elements.iter().zip(&self.centroids) {
            s += &format!("{e},{:.6},{:.6},{:.6}\n", c[0], c[1], c[2]);
        }
        s
    }
}

/// Flags for elements of the `organ` parts with a face on the organ's boundary.
pub fn surface_elements(mesh: &Mesh, organ: &[bool]) -> Vec<bool> {
    let mut owner: HashMap<[u32; 4], (u32, u32)> = HashMap::new();
    for (e, c) in mesh.elements.iter().enumerate() {
        for f in FACES.iter() {
            let mut key = [c[f[0]], c[f[1]], c[f[2]], c[f[3]]];
            key.sort_unstable();
            owner
                .entry(key)
                .and_modify(|v| v.1 = e as u32)
                .or_insert((e as u32, u32::MAX));
        }
    }
    let in_organ = |e: u32| {
        organ
            .get(mesh.element_part[e as usize] as usize)
            .copied()
            .unwrap_or(false)
    };
    let mut out = vec![false; mesh.elements.len()];
    for &(a, b) in owner.values() {
        match (in_organ(a), b != u32::MAX && in_organ(b)) {
            (true, false) => out[a as usize] = true,
            (false, true) => out[b as usize] = true,
            _ => {}
        }
    }
    out
}

/// Flags for the parts of `part_names` that make up the organ of the ROI: the liver and its
/// tumours.
pub fn organ_parts(part_names: &[String]) -> Vec<bool> {
    part_names
        .iter()
        .map(|n| n == "liver" || n.starts_with("tumour"))
        .collect()
}

/// The ROI `reference` carried by the rigid displacement `d` (m) onto `mesh` (module doc): in
/// the reference's order, the organ-surface element nearest each moved centroid (two points
/// may share one element). `None` when the mesh has no organ-surface element.
pub fn carry_roi(mesh: &Mesh, organ: &[bool], reference: &Roi, d: [f64; 3]) -> Option<Roi> {
    let surf = surface_elements(mesh, organ);
    let cents = mesh.centroids();
    let cand: Vec<usize> = (0..mesh.elements.len()).filter(|&e| surf[e]).collect();
    if cand.is_empty() {
        return None;
    }
    let moved = |c: [f64; 3]| [c[0] + d[0], c[1] + d[1], c[2] + d[2]];
    let elements: Vec<u32> = reference
        .centroids
        .iter()
        .map(|&c| {
            let p = moved(c);
            let dist = |e: usize| {
                let q = cents[e];
                (q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2) + (q[2] - p[2]).powi(2)
            };
            // nearest, ties to the lower id (a deterministic choice)
            cand.iter()
                .copied()
                .min_by(|&a, &b| dist(a).total_cmp(&dist(b)).then(a.cmp(&b)))
                .expect("candidates are not empty") as u32
        })
        .collect();
    Some(Roi {
        center: moved(reference.center),
        centroids: elements.iter().map(|&e| cents[e as usize]).collect(),
        elements,
    })
}

/// Select the ROI around `center`.
pub fn select_roi(mesh: &Mesh, organ: &[bool], center: [f64; 3], p: &RoiParams) -> Roi {
    let surf = surface_elements(mesh, organ);
    let cents = mesh.centroids();
    let mut cand: Vec<(f64, u32)> = (0..mesh.elements.len())
        .filter(|&e| surf[e])
        .map(|e| {
            let c = cents[e];
            (
                ((c[0] - center[0]).powi(2)
                    + (c[1] - center[1]).powi(2)
                    + (c[2] - center[2]).powi(2))
                .sqrt(),
                e as u32,
            )
        })
        .filter(|&(d, _)| d <= p.radius)
        .collect();
    cand.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    if let Some(m) = p.max_count {
        cand.truncate(m);
    }
    Roi {
        center,
        elements: cand.iter().map(|c| c.1).collect(),
        centroids: cand.iter().map(|c| cents[c.1 as usize]).collect(),
    }
}
