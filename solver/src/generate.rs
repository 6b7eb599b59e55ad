//! Structured box meshes: graded spacing, optional random interior-node distortion (for patch
//! tests), and the six face node sets `xmin`, `xmax`, `ymin`, `ymax`, `zmin`, `zmax`.
//!
//! Grading: along an axis with n divisions and ratio r (last element length / first), the
//! element lengths form a geometric series h_k = h_0 q^k with q = r^(1/(n-1)).

use crate::mesh::Mesh;

/// Parameters of a structured box.
#[derive(Clone, Debug)]
pub struct BoxSpec {
    /// Lower corner (m).
    pub origin: [f64; 3],
    /// Edge lengths (m).
    pub size: [f64; 3],
    /// Divisions per axis.
    pub divisions: [usize; 3],
    /// Grading ratio per axis (last element / first element length); 1 is uniform.
    pub grading: [f64; 3],
    /// Random perturbation of interior nodes, as a fraction of the local spacing (0..0.3).
    pub distortion: f64,
    /// Seed for the distortion.
    pub seed: u64,
}

impl Default for BoxSpec {
    fn default() -> Self {
        BoxSpec {
            origin: [0.0; 3],
            size: [1.0; 3],
            divisions: [1; 3],
            grading: [1.0; 3],
            distortion: 0.0,
            seed: 1,
        }
    }
}

/// Node coordinates along one axis.
pub fn graded_axis(x0: f64, len: f64, n: usize, ratio: f64) -> Vec<f64> {
    if n == 1 || (ratio - 1.0).abs() < 1e-14 {
        return (0..=n).map(|i| x0 + len * i as f64 / n as f64).collect();
    }
    let q = ratio.powf(1.0 / (n as f64 - 1.0));
    let h0 = len * (q - 1.0) / (q.powi(n as i32) - 1.0);
    let mut out = Vec::with_capacity(n + 1);
    let mut x = x0;
    out.push(x);
    for k in 0..n {
        x += h0 * q.powi(k as i32);
        out.push(x);
    }
    out[n] = x0 + len;
    out
}

/// A small deterministic generator (SplitMix64) for mesh distortion.
pub struct SplitMix(u64);
impl SplitMix {
    /// New generator.
    pub fn new(seed: u64) -> Self {
        SplitMix(seed)
    }
    /// Uniform in [-1, 1).
    pub fn symmetric(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E3779B97F4A7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58476D1CE4E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D049BB133111EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}

/// The most elements a scene's box may have unless its `[mesh] max_elements` raises the limit.
pub const DEFAULT_MAX_ELEMENTS: f64 = 50e6;
/// A rough memory cost of one hexahedron through a run (mesh, model, state and output), for the
/// estimate in the message that refuses a box above the limit.
pub const BYTES_PER_ELEMENT: f64 = 2048.0;

/// Build the box mesh, with a single part named `part`. Node ids are `u32`: a box with more
/// nodes than that is refused before anything is allocated.
pub fn box_mesh(spec: &BoxSpec, part: &str) -> Result<Mesh, String> {
    let [nx, ny, nz] = spec.divisions;
    if nx == 0 || ny == 0 || nz == 0 {
        return Err("mesh divisions must be at least 1 along each axis".into());
    }
    let nodes = spec
        .divisions
        .iter()
        .map(|&d| d as u128 + 1)
        .product::<u128>();
    if nodes > u32::MAX as u128 {
        return Err(format!(
            "mesh divisions {:?} give {nodes} nodes, more than node ids can number ({})",
            spec.divisions,
            u32::MAX
        ));
    }
    for k in 0..3 {
        if !(spec.size[k] > 0.0) {
            return Err(format!("mesh size along axis {k} must be positive"));
        }
        if !(spec.grading[k] > 0.0) {
            return Err(format!("mesh grading along axis {k} must be positive"));
        }
    }
    if !(0.0..0.4).contains(&spec.distortion) {
        return Err("mesh distortion must lie in [0, 0.4)".into());
    }
    let ax: Vec<Vec<f64>> = (0..3)
        .map(|k| {
            graded_axis(
                spec.origin[k],
                spec.size[k],
                spec.divisions[k],
                spec.grading[k],
            )
        })
        .collect();
    let id = |i: usize, j: usize, k: usize| (i + (nx + 1) * (j + (ny + 1) * k)) as u32;
    let mut mesh = Mesh::default();
    let mut rng = SplitMix::new(spec.seed);
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                let mut p = [ax[0][i], ax[1][j], ax[2][k]];
                let interior = i > 0 && i < nx && j > 0 && j < ny && k > 0 && k < nz;
                if interior && spec.distortion > 0.0 {
                    let idx = [i, j, k];
                    for d in 0..3 {
                        let h = (ax[d][idx[d] + 1] - ax[d][idx[d]])
                            .min(ax[d][idx[d]] - ax[d][idx[d] - 1]);
                        p[d] += spec.distortion * h * rng.symmetric();
                    }
                }
                mesh.nodes.push(p);
            }
        }
    }
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                mesh.elements.push([
                    id(i, j, k),
                    id(i + 1, j, k),
                    id(i + 1, j + 1, k),
                    id(i, j + 1, k),
                    id(i, j, k + 1),
                    id(i + 1, j, k + 1),
                    id(i + 1, j + 1, k + 1),
                    id(i, j + 1, k + 1),
                ]);
            }
        }
    }
    mesh.element_part = vec![0; mesh.elements.len()];
    mesh.part_names = vec![part.to_string()];
    let n = [nx, ny, nz];
    for (axis, name) in ["x", "y", "z"].iter().enumerate() {
        for (side, idx) in [("min", 0usize), ("max", n[axis])] {
            let mut set = Vec::new();
            for k in 0..=nz {
                for j in 0..=ny {
                    for i in 0..=nx {
                        if [i, j, k][axis] == idx {
                            set.push(id(i, j, k));
                        }
                    }
                }
            }
            set.sort_unstable();
            mesh.node_sets.insert(format!("{name}{side}"), set);
        }
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grading_sums_to_length_with_ratio() {
        let x = graded_axis(0.0, 2.0, 5, 4.0);
        assert!((x[5] - 2.0).abs() < 1e-15);
        let r = (x[5] - x[4]) / (x[1] - x[0]);
        assert!((r - 4.0).abs() < 1e-12);
    }

    #[test]
    fn box_counts_and_sets() {
        let m = box_mesh(
            &BoxSpec {
                divisions: [2, 3, 4],
                ..Default::default()
            },
            "b",
        )
        .unwrap();
        assert_eq!(m.n_nodes(), 3 * 4 * 5);
        assert_eq!(m.n_elements(), 24);
        assert_eq!(m.node_sets["zmax"].len(), 12);
        assert_eq!(m.boundary_faces().len(), 2 * (6 + 8 + 12));
    }
}
