//! Principal stretches and directions: the one eigen-kernel shared by every principal-stretch law
//! (Ogden, simplified rubber/foam, Hencky plasticity).
//!
//! **Method.** Cyclic Jacobi rotations on a symmetric 3x3 matrix (Golub & Van Loan, *Matrix
//! Computations*, 4th ed., sec. 8.5; the update formulas of Press et al., *Numerical Recipes*,
//! sec. 11.1). Jacobi is backward stable and keeps the eigenvector matrix orthogonal to round-off
//! even when eigenvalues coincide, which an analytic (Cardano) solution does not: Cardano loses
//! about half the digits of two eigenvalues that are 1e-8 apart.
//!
//! **Shift.** The laws never decompose `C = F^T F` itself but `A = C - I = H + H^T + H^T H`
//! (with `H = F - I`), and take `ln l_i = ln_1p(a_i) / 2`. The eigenvalues `a_i` then carry an
//! absolute error of about `1e-16 |A|` instead of `1e-16 |C|`, so the logarithmic strains stay
//! accurate to round-off relative to the strain itself at small strain (1e-7 and below).
//!
//! **Degenerate stretches.** With equal eigenvalues the eigenvectors are any orthonormal basis of
//! the eigenspace. Every law here builds its stress as `sum_i c_i N_i (x) N_i` with a coefficient
//! that is a function of the eigenvalue alone, so equal eigenvalues give equal coefficients and the
//! sum is the same for every basis: the result is well defined and continuous, and no formula
//! divides by a difference of stretches.
//!
//! Symmetric tensors are stored as `[xx, yy, zz, xy, yz, zx]` (the "Sym6" order used for
//! history values and output columns).

use crate::law::{LawError, Mat3};

/// Symmetric tensor in the order `[xx, yy, zz, xy, yz, zx]`.
pub type Sym6 = [f64; 6];

/// Symmetric part of a matrix as Sym6.
#[inline(always)]
pub fn sym6(m: &Mat3) -> Sym6 {
    [
        m[(0, 0)],
        m[(1, 1)],
        m[(2, 2)],
        0.5 * (m[(0, 1)] + m[(1, 0)]),
        0.5 * (m[(1, 2)] + m[(2, 1)]),
        0.5 * (m[(2, 0)] + m[(0, 2)]),
    ]
}

/// Full matrix from Sym6.
#[inline(always)]
pub fn mat_from_sym6(s: &Sym6) -> Mat3 {
    Mat3::new(s[0], s[3], s[5], s[3], s[1], s[4], s[5], s[4], s[2])
}

/// Double contraction `a : b` of two symmetric tensors.
#[inline(always)]
pub fn ddot6(a: &Sym6, b: &Sym6) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + 2.0 * (a[3] * b[3] + a[4] * b[4] + a[5] * b[5])
}

/// `C - I = H + H^T + H^T H` with `H = F - I`, as Sym6 (twice the Green-Lagrange strain),
/// accurate at small strain.
#[inline(always)]
pub fn c_minus_identity(f: &Mat3) -> Sym6 {
    let h = f - Mat3::identity();
    let hth = h.transpose() * h;
    [
        2.0 * h[(0, 0)] + hth[(0, 0)],
        2.0 * h[(1, 1)] + hth[(1, 1)],
        2.0 * h[(2, 2)] + hth[(2, 2)],
        h[(0, 1)] + h[(1, 0)] + hth[(0, 1)],
        h[(1, 2)] + h[(2, 1)] + hth[(1, 2)],
        h[(2, 0)] + h[(0, 2)] + hth[(2, 0)],
    ]
}

/// `b - I = H + H^T + H H^T` with `H = F - I` (left Cauchy-Green tensor minus identity).
#[inline(always)]
pub fn b_minus_identity(f: &Mat3) -> Sym6 {
    c_minus_identity(&f.transpose())
}

/// One Jacobi rotation zeroing `a[p][q]`; `r` is the third index.
#[inline(always)]
fn rotate(a: &mut [[f64; 3]; 3], v: &mut [[f64; 3]; 3], p: usize, q: usize, r: usize) {
    let apq = a[p][q];
    if apq == 0.0 {
        return;
    }
    let app = a[p][p];
    let aqq = a[q][q];
    // Negligible off-diagonal term: drop it (Numerical Recipes' test).
    let g = 100.0 * apq.abs();
    if app.abs() + g == app.abs() && aqq.abs() + g == aqq.abs() {
        a[p][q] = 0.0;
        a[q][p] = 0.0;
        return;
    }
    let theta = (aqq - app) / (2.0 * apq);
    let t = if theta.abs() > 1e150 {
        0.5 / theta
    } else {
        let t = 1.0 / (theta.abs() + (theta * theta + 1.0).sqrt());
        if theta < 0.0 {
            -t
        } else {
            t
        }
    };
    let c = 1.0 / (t * t + 1.0).sqrt();
    let s = t * c;
    let tau = s / (1.0 + c);
    a[p][p] = app - t * apq;
    a[q][q] = aqq + t * apq;
    a[p][q] = 0.0;
    a[q][p] = 0.0;
    let arp = a[r][p];
    let arq = a[r][q];
    a[r][p] = arp - s * (arq + tau * arp);
    a[p][r] = a[r][p];
    a[r][q] = arq + s * (arp - tau * arq);
    a[q][r] = a[r][q];
    for row in v.iter_mut() {
        let vp = row[p];
        let vq = row[q];
        row[p] = vp - s * (vq + tau * vp);
        row[q] = vq + s * (vp - tau * vq);
    }
}

/// Eigenvalues and orthonormal eigenvectors (the columns of the returned matrix) of a symmetric
/// tensor given as Sym6, by cyclic Jacobi. Eigenvalues are not sorted.
#[inline]
pub fn sym_eigen(m: &Sym6) -> ([f64; 3], Mat3) {
    let mut a = [[m[0], m[3], m[5]], [m[3], m[1], m[4]], [m[5], m[4], m[2]]];
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _sweep in 0..32 {
        if a[0][1] == 0.0 && a[1][2] == 0.0 && a[0][2] == 0.0 {
            break;
        }
        rotate(&mut a, &mut v, 0, 1, 2);
        rotate(&mut a, &mut v, 0, 2, 1);
        rotate(&mut a, &mut v, 1, 2, 0);
    }
    (
        [a[0][0], a[1][1], a[2][2]],
        Mat3::new(
            v[0][0], v[0][1], v[0][2], v[1][0], v[1][1], v[1][2], v[2][0], v[2][1], v[2][2],
        ),
    )
}

/// Principal logarithmic stretches of `F` and the reference principal directions.
#[derive(Clone, Copy, Debug)]
pub struct Principal {
    /// `ln l_i`, the principal logarithmic (Hencky) strains.
    pub ln_stretch: [f64; 3],
    /// `ln J = sum_i ln l_i`.
    pub ln_j: f64,
    /// Reference (Lagrangian) principal directions `N_i`, as columns: eigenvectors of `C`.
    pub directions: Mat3,
}

impl Principal {
    /// Decompose `F` (which must have a positive determinant: check it first).
    #[inline]
    pub fn of(f: &Mat3) -> Result<Principal, LawError> {
        let (a, n) = sym_eigen(&c_minus_identity(f));
        let mut ln = [0.0; 3];
        for i in 0..3 {
            // a_i > -1 for det F > 0 up to round-off; refuse a collapsed direction.
            if !(a[i] > -1.0) {
                return Err(LawError::NotFinite("principal stretch collapsed to zero"));
            }
            ln[i] = 0.5 * a[i].ln_1p();
        }
        Ok(Principal {
            ln_stretch: ln,
            ln_j: ln[0] + ln[1] + ln[2],
            directions: n,
        })
    }

    /// Isochoric logarithmic stretches `ln lbar_i = ln l_i - ln J / 3`.
    #[inline(always)]
    pub fn ln_isochoric(&self) -> [f64; 3] {
        let s = self.ln_j / 3.0;
        [
            self.ln_stretch[0] - s,
            self.ln_stretch[1] - s,
            self.ln_stretch[2] - s,
        ]
    }

    /// PK2 stress from principal Kirchhoff stresses: `S = sum_i tau_i / l_i^2 N_i (x) N_i`.
    #[inline(always)]
    pub fn pk2_from_kirchhoff(&self, tau: &[f64; 3]) -> Mat3 {
        let c = [
            tau[0] * (-2.0 * self.ln_stretch[0]).exp(),
            tau[1] * (-2.0 * self.ln_stretch[1]).exp(),
            tau[2] * (-2.0 * self.ln_stretch[2]).exp(),
        ];
        spectral(&c, &self.directions)
    }
}

/// `sum_i c_i n_i (x) n_i` for the columns `n_i` of `n`.
#[inline(always)]
pub fn spectral(c: &[f64; 3], n: &Mat3) -> Mat3 {
    let mut m = Mat3::zeros();
    for i in 0..3 {
        for j in i..3 {
            let v = c[0] * n[(i, 0)] * n[(j, 0)]
                + c[1] * n[(i, 1)] * n[(j, 1)]
                + c[2] * n[(i, 2)] * n[(j, 2)];
            m[(i, j)] = v;
            m[(j, i)] = v;
        }
    }
    m
}

/// `sum_i c_i n_i (x) n_i` as Sym6.
#[inline(always)]
pub fn spectral6(c: &[f64; 3], n: &Mat3) -> Sym6 {
    let e = |i: usize, j: usize| {
        c[0] * n[(i, 0)] * n[(j, 0)] + c[1] * n[(i, 1)] * n[(j, 1)] + c[2] * n[(i, 2)] * n[(j, 2)]
    };
    [e(0, 0), e(1, 1), e(2, 2), e(0, 1), e(1, 2), e(2, 0)]
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Rotation3;

    fn check(m: Sym6) {
        let (l, v) = sym_eigen(&m);
        let a = mat_from_sym6(&m);
        let scale = a.norm().max(1e-300);
        let recon = spectral(&l, &v);
        assert!(
            (recon - a).norm() <= 4e-16 * scale * 8.0,
            "{:e}",
            (recon - a).norm() / scale
        );
        assert!((v.transpose() * v - Mat3::identity()).norm() < 1e-14);
    }

    #[test]
    fn jacobi_reconstructs_random_and_degenerate_matrices() {
        let r = Rotation3::from_euler_angles(0.4, -1.2, 2.1).into_inner();
        for d in [
            [1.0, 2.0, 3.0],
            [1.0, 1.0, 1.0],
            [0.0, 0.0, 0.0],
            [1.0, 1.0 + 1e-8, 2.0],
            [1e-7, -3e-7, 1e-7 + 1e-15],
            [5.0, 5.0, -1e-3],
        ] {
            let a = r * Mat3::from_diagonal(&d.into()) * r.transpose();
            check(sym6(&a));
            let (l, _) = sym_eigen(&sym6(&a));
            let mut l = l;
            l.sort_by(|a, b| a.partial_cmp(b).unwrap());
            let mut d = d;
            d.sort_by(|a, b| a.partial_cmp(b).unwrap());
            for k in 0..3 {
                let s = d.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                assert!(
                    (l[k] - d[k]).abs() <= 1e-15 * s.max(1e-300) * 4.0,
                    "{l:?} vs {d:?}"
                );
            }
        }
    }

    #[test]
    fn small_strain_logs_are_accurate() {
        let eps = 1e-9;
        let f = Mat3::new(1.0 + eps, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
        let p = Principal::of(&f).unwrap();
        let m = p.ln_stretch.iter().fold(0.0f64, |m, x| m.max(*x));
        assert!((m - (1.0 + eps).ln()).abs() < 1e-22, "{m:e}");
    }
}
