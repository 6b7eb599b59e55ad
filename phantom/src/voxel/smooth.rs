//! Constrained Taubin smoothing of the outer surface and the part interfaces of a voxel mesh.
//!
//! A voxel mesh has staircase surfaces. Following the image-based hexahedral meshing of
//! Ghajari et al. ("The influence of the body on the response of the helmeted head during
//! impact", 2011, and Ghajari, Hellyer & Sharp, "Computational modelling of traumatic brain
//! injury predicts the location of chronic traumatic encephalopathy pathology", Brain 2017),
//! only the nodes on surfaces are moved, each towards the average of its surface neighbours,
//! and a move is cut back wherever it would spoil an element.
//!
//! - **Surfaces.** Every voxel face between two different parts (an interface) or between a
//!   part and background (the outer surface) is a surface face; its *patch* is the unordered
//!   pair of the two sides. Faces on the grid's bounding planes (cut planes) form patches of
//!   their own.
//! - **Features.** Node v carries the set P(v) of patches of its faces. A surface-edge
//!   neighbour u counts for v only if P(u) contains P(v): nodes inside a patch are smoothed
//!   over the patch, nodes on a curve where patches meet (a triple line, the rim of a cut
//!   plane) are smoothed along the curve, and corner nodes with no such neighbour stay put.
//! - **Taubin's lambda/mu filter** (Taubin, "A signal processing approach to fair surface
//!   design", SIGGRAPH 1995): with the umbrella Laplacian L(v) = mean(x_u) - x_v, each
//!   iteration applies x += lambda L(x) then x += mu L(x), mu < -lambda < 0, a low-pass
//!   filter that does not shrink the surface the way plain Laplacian smoothing does.
//!   Updates are Jacobi-style (all new positions from the old ones), so the result does not
//!   depend on the order of nodes or the number of threads.
//! - **Cut planes.** A node on a bounding plane keeps only the in-plane part of its move, so
//!   cut planes stay planar (rollers and fixed backs stay exact).
//! - **Element validity.** After each half step every element touching a moved node is
//!   checked; where the minimum scaled corner Jacobian falls below `min_scaled_jacobian`
//!   the moves of that element's nodes are halved, up to three times, then undone. Every
//!   element therefore keeps a positive Jacobian at all eight corners (the voxel mesh starts
//!   at 1). Likewise an element's characteristic length V / A_max (which sets the explicit
//!   time step) may not fall below `min_length_ratio` times its value before smoothing.

use rayon::prelude::*;

use super::jacobian::{characteristic_length, element_coords, min_scaled_jacobian};

/// Smoothing parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct SmoothOptions {
    /// Taubin iterations (each one lambda step and one mu step); 0 disables smoothing.
    pub iterations: usize,
    /// Positive Taubin factor.
    pub lambda: f64,
    /// Negative Taubin factor, |mu| slightly larger than lambda.
    pub mu: f64,
    /// Smallest scaled corner Jacobian a move may leave in any element (0 < value < 1).
    pub min_scaled_jacobian: f64,
    /// Smallest characteristic length (V / A_max) a move may leave in an element, as a
    /// fraction of the element's length before smoothing: bounds the loss of explicit time
    /// step to this factor.
    pub min_length_ratio: f64,
    /// Smooth part interfaces as well as the outer surface.
    pub interfaces: bool,
}

impl Default for SmoothOptions {
    fn default() -> Self {
        SmoothOptions {
            iterations: 12,
            lambda: 0.5,
            mu: -0.53,
            min_scaled_jacobian: 0.3,
            min_length_ratio: 0.6,
            interfaces: true,
        }
    }
}

/// A surface face: four nodes in cyclic order and its patch key.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SurfaceFace {
    /// Nodes in cyclic order.
    pub nodes: [u32; 4],
    /// Patch key (same key = same pair of sides).
    pub patch: u64,
}

/// What smoothing did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SmoothReport {
    /// Nodes free to move (on a surface, with at least one admissible neighbour).
    pub movable_nodes: usize,
    /// Half steps applied.
    pub half_steps: usize,
    /// Node moves halved to keep elements valid.
    pub backoffs: usize,
    /// Node moves undone entirely.
    pub reverted: usize,
    /// Largest total node displacement (m).
    pub max_displacement: f64,
    /// Mean total displacement of the movable nodes (m).
    pub mean_displacement: f64,
}

fn csr_from_pairs(n: usize, mut pairs: Vec<(u32, u64)>) -> (Vec<usize>, Vec<u64>) {
    pairs.par_sort_unstable();
    pairs.dedup();
    let mut start = vec![0usize; n + 1];
    for &(a, _) in &pairs {
        start[a as usize + 1] += 1;
    }
    for i in 0..n {
        start[i + 1] += start[i];
    }
    (start, pairs.into_iter().map(|p| p.1).collect())
}

/// Smooth the surface nodes in place. `plane_normals[v]` lists, as bits 0..3, the bounding
/// planes node v lies on, whose unit normals are `normals[bit]`.
pub fn smooth_surfaces(
    nodes: &mut [[f64; 3]],
    elements: &[[u32; 8]],
    faces: &[SurfaceFace],
    plane_bits: &[u8],
    normals: &[[f64; 3]; 3],
    opts: &SmoothOptions,
) -> SmoothReport {
    let n = nodes.len();
    let mut report = SmoothReport::default();
    if opts.iterations == 0 || faces.is_empty() {
        return report;
    }
    let adm = admissible_neighbours(n, faces);
    report.movable_nodes = adm.len();
    let mut movable = vec![false; n];
    for (v, _) in &adm {
        movable[*v as usize] = true;
    }
    let candidates: Vec<u32> = (0..elements.len() as u32)
        .into_par_iter()
        .filter(|&e| elements[e as usize].iter().any(|&v| movable[v as usize]))
        .collect();
    let start: Vec<[f64; 3]> = adm.iter().map(|(v, _)| nodes[*v as usize]).collect();
    let slot: Vec<u32> = {
        let mut s = vec![u32::MAX; n];
        for (q, (v, _)) in adm.iter().enumerate() {
            s[*v as usize] = q as u32;
        }
        s
    };
    // never ask more of an element than it had to begin with (sheared image grids)
    let init_min = candidates
        .par_iter()
        .map(|&e| min_scaled_jacobian(&element_coords(nodes, &elements[e as usize])))
        .reduce(|| f64::INFINITY, f64::min);
    let guard = Guard {
        elements,
        candidates: &candidates,
        lmin: candidates
            .par_iter()
            .map(|&e| {
                opts.min_length_ratio
                    * characteristic_length(&element_coords(nodes, &elements[e as usize]))
            })
            .collect(),
        thr: opts.min_scaled_jacobian.min(0.9 * init_min),
        slot: &slot,
    };
    for _ in 0..opts.iterations {
        for &f in &[opts.lambda, opts.mu] {
            let old: Vec<[f64; 3]> = adm.iter().map(|(v, _)| nodes[*v as usize]).collect();
            let target = half_step(nodes, &adm, f, plane_bits, normals);
            for (q, (v, _)) in adm.iter().enumerate() {
                nodes[*v as usize] = target[q];
            }
            guard.back_off(nodes, &adm, &old, &target, &mut report);
            report.half_steps += 1;
        }
    }
    let mut sum = 0.0;
    for (q, (v, _)) in adm.iter().enumerate() {
        let x = nodes[*v as usize];
        let d = ((x[0] - start[q][0]).powi(2)
            + (x[1] - start[q][1]).powi(2)
            + (x[2] - start[q][2]).powi(2))
        .sqrt();
        sum += d;
        report.max_displacement = report.max_displacement.max(d);
    }
    if !adm.is_empty() {
        report.mean_displacement = sum / adm.len() as f64;
    }
    report
}

/// The movable nodes with their admissible neighbours: edge neighbours `u` on the surface whose
/// patch set contains the node's (a node on a patch edge moves only along that edge).
fn admissible_neighbours(n: usize, faces: &[SurfaceFace]) -> Vec<(u32, Vec<u32>)> {
    // patch sets and edge neighbours
    let mut np = Vec::with_capacity(faces.len() * 4);
    let mut ne = Vec::with_capacity(faces.len() * 8);
    for f in faces {
        for a in 0..4 {
            let (v, u, w) = (f.nodes[a], f.nodes[(a + 1) % 4], f.nodes[(a + 3) % 4]);
            np.push((v, f.patch));
            ne.push((v, u as u64));
            ne.push((v, w as u64));
        }
    }
    let (ps, pv) = csr_from_pairs(n, np);
    let (es, ev) = csr_from_pairs(n, ne);
    let patches = |v: usize| &pv[ps[v]..ps[v + 1]];
    // admissible neighbours: P(u) contains P(v) (both sorted)
    let contains = |big: &[u64], small: &[u64]| small.iter().all(|s| big.binary_search(s).is_ok());
    (0..n)
        .into_par_iter()
        .filter(|&v| ps[v + 1] > ps[v])
        .filter_map(|v| {
            let pvv = patches(v);
            let list: Vec<u32> = ev[es[v]..es[v + 1]]
                .iter()
                .map(|&u| u as u32)
                .filter(|&u| contains(patches(u as usize), pvv))
                .collect();
            if list.is_empty() {
                None
            } else {
                Some((v as u32, list))
            }
        })
        .collect()
}

/// One Taubin half step with factor `f` (lambda or mu): each movable node moves `f` times the
/// way to its neighbours' mean, less the components along the normals of its bounding planes.
fn half_step(
    nodes: &[[f64; 3]],
    adm: &[(u32, Vec<u32>)],
    f: f64,
    plane_bits: &[u8],
    normals: &[[f64; 3]; 3],
) -> Vec<[f64; 3]> {
    adm.par_iter()
        .map(|(v, list)| {
            let x = nodes[*v as usize];
            let mut m = [0.0; 3];
            for &u in list {
                for k in 0..3 {
                    m[k] += nodes[u as usize][k];
                }
            }
            let inv = 1.0 / list.len() as f64;
            let mut d = [
                f * (m[0] * inv - x[0]),
                f * (m[1] * inv - x[1]),
                f * (m[2] * inv - x[2]),
            ];
            let bits = plane_bits[*v as usize];
            for (b, nrm) in normals.iter().enumerate() {
                if bits & (1 << b) != 0 {
                    let dn = d[0] * nrm[0] + d[1] * nrm[1] + d[2] * nrm[2];
                    for k in 0..3 {
                        d[k] -= dn * nrm[k];
                    }
                }
            }
            [x[0] + d[0], x[1] + d[1], x[2] + d[2]]
        })
        .collect()
}

/// The element-quality guard of a half step: the elements that touch a movable node, their
/// smallest admissible characteristic lengths and the scaled-Jacobian threshold.
struct Guard<'a> {
    elements: &'a [[u32; 8]],
    candidates: &'a [u32],
    lmin: Vec<f64>,
    thr: f64,
    /// Index of a node among the movable ones (`u32::MAX` if not movable).
    slot: &'a [u32],
}

impl Guard<'_> {
    /// Halve the moves of the nodes of poor elements (from `old` towards `target`) until none
    /// is poor; after three halvings a node's move is undone.
    fn back_off(
        &self,
        nodes: &mut [[f64; 3]],
        adm: &[(u32, Vec<u32>)],
        old: &[[f64; 3]],
        target: &[[f64; 3]],
        report: &mut SmoothReport,
    ) {
        let elements = self.elements;
        let mut scale = vec![1.0f64; adm.len()];
        for round in 0.. {
            let snap: &[[f64; 3]] = nodes;
            let bad: Vec<u32> = self
                .candidates
                .par_iter()
                .zip(self.lmin.par_iter())
                .filter(|&(&e, &lm)| {
                    let x = element_coords(snap, &elements[e as usize]);
                    min_scaled_jacobian(&x) < self.thr || characteristic_length(&x) < lm
                })
                .map(|(&e, _)| e)
                .collect();
            if bad.is_empty() {
                break;
            }
            let mut hit = vec![false; adm.len()];
            for &e in &bad {
                for &v in &elements[e as usize] {
                    let q = self.slot[v as usize];
                    if q != u32::MAX {
                        hit[q as usize] = true;
                    }
                }
            }
            for (q, (v, _)) in adm.iter().enumerate() {
                if !hit[q] || scale[q] == 0.0 {
                    continue;
                }
                if round >= 3 {
                    scale[q] = 0.0;
                    report.reverted += 1;
                } else {
                    scale[q] *= 0.5;
                    report.backoffs += 1;
                }
                let s = scale[q];
                let (o, t) = (old[q], target[q]);
                nodes[*v as usize] = [
                    o[0] + s * (t[0] - o[0]),
                    o[1] + s * (t[1] - o[1]),
                    o[2] + s * (t[2] - o[2]),
                ];
            }
        }
    }
}
