//! Trilinear 8-node hexahedron: shape functions, reference geometry, Jacobian checks,
//! the Flanagan-Belytschko mean gradient and hourglass base vectors.
//!
//! N_a(xi) = 1/8 (1 + xi xi_a)(1 + eta eta_a)(1 + zeta zeta_a) with the corner coordinates of
//! [`crate::mesh::CORNERS`]. The reference Jacobian is J_ij = dX_i/dxi_j = sum_a X_ai dN_a/dxi_j
//! and dN_a/dX = J^-T dN_a/dxi.
//!
//! Mean (uniform) gradient, Flanagan & Belytschko (1981), IJNME 17:679-706, eq. 14:
//!   b_a = 1/V int_V dN_a/dX dV, evaluated exactly by 2x2x2 Gauss quadrature,
//! which makes the one-point element pass the patch test on distorted meshes.
//! Hourglass vectors (FB eq. 30, unnormalised): gamma_alpha = h_alpha - (h_alpha . X_i) b_i with
//! h_alpha the four modes xi*eta, eta*zeta, zeta*xi, xi*eta*zeta sampled at the corners.

use crate::mesh::CORNERS;
use material::real::Real;
use nalgebra::{Matrix3, Vector3};

/// Gauss point coordinate of the 2-point rule.
pub const G: f64 = 0.577_350_269_189_625_8;

/// Derivatives dN_a/dxi_j at natural point `p`: out[a][j].
#[inline]
pub fn dn_dxi(p: [f64; 3]) -> [[f64; 3]; 8] {
    let mut d = [[0.0; 3]; 8];
    for (a, c) in CORNERS.iter().enumerate() {
        let fx = 1.0 + p[0] * c[0];
        let fy = 1.0 + p[1] * c[1];
        let fz = 1.0 + p[2] * c[2];
        d[a] = [
            0.125 * c[0] * fy * fz,
            0.125 * fx * c[1] * fz,
            0.125 * fx * fy * c[2],
        ];
    }
    d
}

/// Shape function values at natural point `p`.
#[inline]
pub fn shape(p: [f64; 3]) -> [f64; 8] {
    let mut n = [0.0; 8];
    for (a, c) in CORNERS.iter().enumerate() {
        n[a] = 0.125 * (1.0 + p[0] * c[0]) * (1.0 + p[1] * c[1]) * (1.0 + p[2] * c[2]);
    }
    n
}

/// The eight 2x2x2 Gauss points (weights are all 1), in corner order.
pub fn gauss_points() -> [[f64; 3]; 8] {
    let mut g = [[0.0; 3]; 8];
    for (k, c) in CORNERS.iter().enumerate() {
        g[k] = [c[0] * G, c[1] * G, c[2] * G];
    }
    g
}

/// Jacobian J_ij = dX_i/dxi_j at natural point `p` for element coordinates `x`.
#[inline]
pub fn jacobian(x: &[[f64; 3]; 8], p: [f64; 3]) -> Matrix3<f64> {
    let d = dn_dxi(p);
    let mut j = Matrix3::zeros();
    for a in 0..8 {
        for i in 0..3 {
            for k in 0..3 {
                j[(i, k)] += x[a][i] * d[a][k];
            }
        }
    }
    j
}

/// Corner Jacobian determinants (at the eight corners) and their scaled values
/// det J / (|e1||e2||e3|) with the edge-derivative columns of J.
pub fn corner_jacobians(x: &[[f64; 3]; 8]) -> ([f64; 8], [f64; 8]) {
    let mut det = [0.0; 8];
    let mut scaled = [0.0; 8];
    for (k, c) in CORNERS.iter().enumerate() {
        let j = jacobian(x, *c);
        det[k] = j.determinant();
        let n = j.column(0).norm() * j.column(1).norm() * j.column(2).norm();
        scaled[k] = if n > 0.0 { det[k] / n } else { 0.0 };
    }
    (det, scaled)
}

/// Reference geometry of one element.
#[derive(Clone, Debug)]
pub struct ElementGeometry {
    /// Exact volume (m^3).
    pub volume: f64,
    /// Mean gradient b_a (1/m), [component][node].
    pub mean_grad: [[f64; 8]; 3],
    /// dN/dX at each Gauss point, [gp][component][node].
    pub gp_grad: [[[f64; 8]; 3]; 8],
    /// det J * weight at each Gauss point (m^3).
    pub gp_weight: [f64; 8],
    /// Consistent-mass row sums per unit density: int N_a dV (m^3).
    pub lumped_volume: [f64; 8],
    /// Centre gradient dN/dX at xi = 0, [component][node].
    pub centre_grad: [[f64; 8]; 3],
}

/// Compute the reference geometry, or the corner index with a non-positive Jacobian.
pub fn element_geometry(x: &[[f64; 3]; 8]) -> Result<ElementGeometry, (usize, f64)> {
    let (det, _) = corner_jacobians(x);
    for (k, d) in det.iter().enumerate() {
        if !(*d > 0.0) {
            return Err((k, *d));
        }
    }
    let mut g = ElementGeometry {
        volume: 0.0,
        mean_grad: [[0.0; 8]; 3],
        gp_grad: [[[0.0; 8]; 3]; 8],
        gp_weight: [0.0; 8],
        lumped_volume: [0.0; 8],
        centre_grad: [[0.0; 8]; 3],
    };
    let grad_at = |p: [f64; 3]| -> Option<([[f64; 8]; 3], f64)> {
        let j = jacobian(x, p);
        let dj = j.determinant();
        let jit = j.try_inverse()?.transpose();
        let d = dn_dxi(p);
        let mut out = [[0.0; 8]; 3];
        for a in 0..8 {
            let v = jit * Vector3::new(d[a][0], d[a][1], d[a][2]);
            for i in 0..3 {
                out[i][a] = v[i];
            }
        }
        Some((out, dj))
    };
    for (k, p) in gauss_points().iter().enumerate() {
        let (gr, dj) = grad_at(*p).ok_or((k, 0.0))?;
        if !(dj > 0.0) {
            return Err((k, dj));
        }
        g.gp_grad[k] = gr;
        g.gp_weight[k] = dj;
        g.volume += dj;
        let n = shape(*p);
        for a in 0..8 {
            g.lumped_volume[a] += n[a] * dj;
            for i in 0..3 {
                g.mean_grad[i][a] += gr[i][a] * dj;
            }
        }
    }
    for i in 0..3 {
        for a in 0..8 {
            g.mean_grad[i][a] /= g.volume;
        }
    }
    g.centre_grad = grad_at([0.0; 3]).ok_or((0, 0.0))?.0;
    Ok(g)
}

/// Hourglass base vectors h_alpha sampled at the corners.
#[inline(always)]
pub fn hourglass_modes() -> [[f64; 8]; 4] {
    let mut h = [[0.0; 8]; 4];
    for (a, c) in CORNERS.iter().enumerate() {
        h[0][a] = c[0] * c[1];
        h[1][a] = c[1] * c[2];
        h[2][a] = c[2] * c[0];
        h[3][a] = c[0] * c[1] * c[2];
    }
    h
}

/// Flanagan-Belytschko hourglass shape vectors gamma_alpha = h_alpha - (h_alpha . X_i) b_i of
/// one element, from its reference coordinates `x[a]` and mean gradient `b`.
pub fn hourglass_gamma(x: &[[f64; 3]; 8], b: &[[f64; 8]; 3]) -> [[f64; 8]; 4] {
    let xt: [[f64; 8]; 3] = material::arr![3, |i| material::arr![8, |a| x[a][i]]];
    hourglass_vectors(&xt, b)
}

/// [`hourglass_gamma`] over lanes (one element per lane), from the reference coordinates
/// `x[i][a]` and mean gradients `b[i][a]` in component-major order. The one-point kernels form
/// their vectors here each step in `f64` (see `solver::forces`), the model builder once: the
/// same operations in the same order, so both give the same bits (`h` is +-1, so `h x` is
/// exact and each sum adds or subtracts the coordinates in node order).
#[inline(always)]
pub fn hourglass_vectors<R: Real>(x: &[[R; 8]; 3], b: &[[R; 8]; 3]) -> [[R; 8]; 4] {
    // Plain loops rather than closures (`std::array::from_fn`): a closure does not inherit the
    // AVX-512 kernels' target features, and its lane operations would not be inlined.
    let h = hourglass_modes();
    let mut gamma = [[R::zero(); 8]; 4];
    for al in 0..4 {
        let mut hx = [R::zero(); 3];
        for i in 0..3 {
            for a in 0..8 {
                hx[i] = if h[al][a] > 0.0 {
                    hx[i] + x[i][a]
                } else {
                    hx[i] - x[i][a]
                };
            }
        }
        for a in 0..8 {
            gamma[al][a] =
                R::splat(h[al][a]) - (hx[0] * b[0][a] + hx[1] * b[1][a] + hx[2] * b[2][a]);
        }
    }
    gamma
}

#[cfg(test)]
mod tests {
    use super::*;

    fn skewed() -> [[f64; 3]; 8] {
        let mut x = [[0.0; 3]; 8];
        for (a, c) in CORNERS.iter().enumerate() {
            x[a] = [0.5 + 0.5 * c[0], 0.5 + 0.5 * c[1], 0.5 + 0.5 * c[2]];
        }
        x[6] = [1.2, 1.1, 1.3];
        x[0] = [0.1, -0.05, 0.0];
        x
    }

    #[test]
    fn mean_gradient_reproduces_linear_fields() {
        let x = skewed();
        let g = element_geometry(&x).unwrap();
        // sum_a X_ai b_aj = delta_ij (consistency), sum_a b_a = 0.
        for i in 0..3 {
            for j in 0..3 {
                let s: f64 = (0..8).map(|a| x[a][i] * g.mean_grad[j][a]).sum();
                assert!((s - if i == j { 1.0 } else { 0.0 }).abs() < 1e-13);
            }
            let s: f64 = g.mean_grad[i].iter().sum();
            assert!(s.abs() < 1e-13);
        }
        let lv: f64 = g.lumped_volume.iter().sum();
        assert!((lv - g.volume).abs() < 1e-14);
    }

    #[test]
    fn hourglass_vectors_are_orthogonal_to_linear_fields() {
        let x = skewed();
        let g = element_geometry(&x).unwrap();
        let gam = hourglass_gamma(&x, &g.mean_grad);
        for al in 0..4 {
            for i in 0..3 {
                let s: f64 = (0..8).map(|a| gam[al][a] * x[a][i]).sum();
                assert!(s.abs() < 1e-13);
            }
            let s: f64 = gam[al].iter().sum();
            assert!(s.abs() < 1e-13);
        }
    }

    #[test]
    fn unit_cube_volume_and_area() {
        let mut x = [[0.0; 3]; 8];
        for (a, c) in CORNERS.iter().enumerate() {
            x[a] = [0.5 + 0.5 * c[0], 0.5 + 0.5 * c[1], 0.5 + 0.5 * c[2]];
        }
        let g = element_geometry(&x).unwrap();
        assert!((g.volume - 1.0).abs() < 1e-14);
    }

    #[test]
    fn inverted_corner_is_found() {
        let mut x = skewed();
        x[6] = [0.2, 0.2, 0.2];
        x[6] = [-0.5, -0.5, -0.5];
        assert!(element_geometry(&x).is_err());
    }

    #[test]
    fn hourglass_vectors_in_lanes_are_the_builders_bit_for_bit() {
        // Eight differently skewed elements, one per lane: the kernels' lane form must give the
        // very bits the model builder stored (the f64 kernels form them instead of reading).
        use material::real::{F64x8, LANES};
        let els: Vec<[[f64; 3]; 8]> = (0..LANES)
            .map(|q| {
                let mut x = skewed();
                x[q][q % 3] += 0.013 * (q as f64 + 1.0);
                x.iter_mut().for_each(|p| p[0] += 1234.5678 * q as f64);
                x
            })
            .collect();
        let geo: Vec<_> = els.iter().map(|x| element_geometry(x).unwrap()).collect();
        let lanes = |f: &dyn Fn(usize, usize, usize) -> f64| -> [[F64x8; 8]; 3] {
            material::arr![3, |i| material::arr![8, |a| F64x8::new(material::arr![
                LANES,
                |q| f(q, i, a)
            ])]]
        };
        let x = lanes(&|q, i, a| els[q][a][i]);
        let b = lanes(&|q, i, a| geo[q].mean_grad[i][a]);
        let g = hourglass_vectors(&x, &b);
        for q in 0..LANES {
            let want = hourglass_gamma(&els[q], &geo[q].mean_grad);
            for al in 0..4 {
                for a in 0..8 {
                    assert_eq!(g[al][a].to_array()[q].to_bits(), want[al][a].to_bits());
                }
            }
        }
    }
}
