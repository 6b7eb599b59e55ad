//! Unstructured hexahedral meshes: nodes, 8-node hexahedra, parts, node sets, element sets,
//! and boundary-face extraction.
//!
//! Node numbering of a hexahedron follows VTK_HEXAHEDRON (and LS-DYNA / Abaqus C3D8): nodes
//! 0-3 are the bottom face counter-clockwise seen from outside-below... i.e. with natural
//! coordinates (xi, eta, zeta) in {-1, 1}^3:
//! 0 (-,-,-) 1 (+,-,-) 2 (+,+,-) 3 (-,+,-) 4 (-,-,+) 5 (+,-,+) 6 (+,+,+) 7 (-,+,+).

use std::collections::{BTreeMap, HashMap};

/// Natural coordinates of the eight corners, in node order.
pub const CORNERS: [[f64; 3]; 8] = [
    [-1.0, -1.0, -1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, -1.0],
    [-1.0, 1.0, -1.0],
    [-1.0, -1.0, 1.0],
    [1.0, -1.0, 1.0],
    [1.0, 1.0, 1.0],
    [-1.0, 1.0, 1.0],
];

/// The six faces of a hexahedron as local node indices, ordered so that the normal
/// (by the right-hand rule) points out of the element.
pub const FACES: [[usize; 4]; 6] = [
    [0, 3, 2, 1], // zeta = -1
    [4, 5, 6, 7], // zeta = +1
    [0, 1, 5, 4], // eta = -1
    [2, 3, 7, 6], // eta = +1
    [0, 4, 7, 3], // xi = -1
    [1, 2, 6, 5], // xi = +1
];

/// A boundary face: the element it belongs to, which local face, and its four global nodes
/// (outward normal by the right-hand rule).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BoundaryFace {
    /// Element index.
    pub element: u32,
    /// Local face index into [`FACES`].
    pub local: u8,
    /// Global node ids.
    pub nodes: [u32; 4],
}

/// A hexahedral mesh with parts and named sets. Coordinates in m.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// Reference node coordinates (m).
    pub nodes: Vec<[f64; 3]>,
    /// Element connectivity (VTK_HEXAHEDRON order).
    pub elements: Vec<[u32; 8]>,
    /// Part index of each element, into `part_names`.
    pub element_part: Vec<u32>,
    /// Part names.
    pub part_names: Vec<String>,
    /// Named node sets (sorted, unique node ids).
    pub node_sets: BTreeMap<String, Vec<u32>>,
    /// Named element sets (sorted, unique element ids).
    pub element_sets: BTreeMap<String, Vec<u32>>,
}

impl Mesh {
    /// Number of nodes.
    pub fn n_nodes(&self) -> usize {
        self.nodes.len()
    }
    /// Number of elements.
    pub fn n_elements(&self) -> usize {
        self.elements.len()
    }

    /// Faces that belong to exactly one element, in element order.
    pub fn boundary_faces(&self) -> Vec<BoundaryFace> {
        let mut seen: HashMap<[u32; 4], (u32, u8, usize)> =
            HashMap::with_capacity(self.elements.len() * 3);
        for (e, conn) in self.elements.iter().enumerate() {
            for (lf, f) in FACES.iter().enumerate() {
                let mut key = [conn[f[0]], conn[f[1]], conn[f[2]], conn[f[3]]];
                key.sort_unstable();
                let ent = seen.entry(key).or_insert((e as u32, lf as u8, 0));
                ent.2 += 1;
            }
        }
        let mut out: Vec<BoundaryFace> = seen
            .into_values()
            .filter(|v| v.2 == 1)
            .map(|(e, lf, _)| {
                let c = self.elements[e as usize];
                let f = FACES[lf as usize];
                BoundaryFace {
                    element: e,
                    local: lf,
                    nodes: [c[f[0]], c[f[1]], c[f[2]], c[f[3]]],
                }
            })
            .collect();
        out.sort_by_key(|f| (f.element, f.local));
        out
    }

    /// Axis-aligned bounding box (min, max) of the nodes.
    pub fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in &self.nodes {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        (lo, hi)
    }

    /// Nodes whose coordinate `axis` is within `tol` of `value`.
    pub fn nodes_on_plane(&self, axis: usize, value: f64, tol: f64) -> Vec<u32> {
        (0..self.nodes.len() as u32)
            .filter(|&i| (self.nodes[i as usize][axis] - value).abs() <= tol)
            .collect()
    }

    /// Nodes inside the closed box [lo, hi].
    pub fn nodes_in_box(&self, lo: [f64; 3], hi: [f64; 3]) -> Vec<u32> {
        (0..self.nodes.len() as u32)
            .filter(|&i| {
                let p = self.nodes[i as usize];
                (0..3).all(|k| p[k] >= lo[k] && p[k] <= hi[k])
            })
            .collect()
    }

    /// Element centroids (m).
    pub fn centroids(&self) -> Vec<[f64; 3]> {
        self.elements
            .iter()
            .map(|c| {
                let mut s = [0.0; 3];
                for &n in c {
                    for k in 0..3 {
                        s[k] += self.nodes[n as usize][k] / 8.0;
                    }
                }
                s
            })
            .collect()
    }
}
