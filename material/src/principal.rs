//! Principal stretches and directions: the one eigen-kernel shared by every principal-stretch law
//! (Ogden, simplified rubber/foam, Hencky plasticity).
//!
//! **Method.** [`sym_eigen`]: the isolated eigenvalue from the trigonometric (Cardano/Smith)
//! solution, its eigenvector by cross products, and the remaining pair by one exact Jacobi
//! rotation in the orthogonal plane (see its doc). Plain Cardano for all three eigenvalues loses
//! about half the digits of two eigenvalues that are 1e-8 apart; this hybrid does not, because
//! the nearly equal pair comes from a 2x2 Jacobi rotation. A cyclic Jacobi solver
//! ([`sym_eigen_jacobi`], Golub & Van Loan sec. 8.5, Numerical Recipes sec. 11.1) is kept as the
//! reference it is tested against; it is about twice as slow.
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

/// One Jacobi rotation zeroing `a[p][q]`; `r` is the third index. Off-diagonal terms at or
/// below `tol` are dropped: their effect on the eigenvalues is below round-off of `|A|`.
#[inline(always)]
fn rotate(a: &mut [[f64; 3]; 3], v: &mut [[f64; 3]; 3], p: usize, q: usize, r: usize, tol: f64) {
    let apq = a[p][q];
    if apq.abs() <= tol {
        a[p][q] = 0.0;
        a[q][p] = 0.0;
        return;
    }
    let (app, aqq) = (a[p][p], a[q][q]);
    let (c, s, t) = givens(app, aqq, apq);
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

/// Jacobi rotation (c, s, t = s/c) that diagonalises `[[app, apq], [apq, aqq]]`
/// (Numerical Recipes, eqs. 11.1.8-11.1.11; the smaller of the two angles).
#[inline(always)]
fn givens(app: f64, aqq: f64, apq: f64) -> (f64, f64, f64) {
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
    (c, t * c, t)
}

/// Eigenvalues and orthonormal eigenvectors of a symmetric tensor by cyclic Jacobi: the slow,
/// simple reference that the tests hold [`sym_eigen`] against. Off-diagonal terms are driven
/// below `1e-17 |A|` (max row sum). Eigenvalues are not sorted.
pub fn sym_eigen_jacobi(m: &Sym6) -> ([f64; 3], Mat3) {
    let mut a = [[m[0], m[3], m[5]], [m[3], m[1], m[4]], [m[5], m[4], m[2]]];
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let (o0, o1, o2) = (m[3].abs(), m[4].abs(), m[5].abs());
    let norm = (m[0].abs() + o0 + o2)
        .max(m[1].abs() + o0 + o1)
        .max(m[2].abs() + o1 + o2);
    let tol = 1e-17 * norm;
    for _sweep in 0..16 {
        if a[0][1] == 0.0 && a[1][2] == 0.0 && a[0][2] == 0.0 {
            break;
        }
        rotate(&mut a, &mut v, 0, 1, 2, tol);
        rotate(&mut a, &mut v, 0, 2, 1, tol);
        rotate(&mut a, &mut v, 1, 2, 0, tol);
    }
    (
        [a[0][0], a[1][1], a[2][2]],
        Mat3::new(
            v[0][0], v[0][1], v[0][2], v[1][0], v[1][1], v[1][2], v[2][0], v[2][1], v[2][2],
        ),
    )
}

#[inline(always)]
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[inline(always)]
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a . M b` for a symmetric `M`.
#[inline(always)]
fn quad(m: &Sym6, a: [f64; 3], b: [f64; 3]) -> f64 {
    let ma = [
        m[0] * a[0] + m[3] * a[1] + m[5] * a[2],
        m[3] * a[0] + m[1] * a[1] + m[4] * a[2],
        m[5] * a[0] + m[4] * a[1] + m[2] * a[2],
    ];
    dot(ma, b)
}

/// Eigenvalues and orthonormal eigenvectors (the columns of the returned matrix) of a symmetric
/// tensor given as Sym6. Eigenvalues are not sorted.
///
/// Hybrid and non-iterative: (1) the trigonometric solution of the characteristic cubic of the
/// deviator `B = A - tr(A)/3 I` (Smith 1961) gives the *isolated* eigenvalue, the one farthest
/// from the other two (the largest if det B >= 0, else the smallest); the formula is flat, hence
/// accurate, exactly where the other two merge; (2) its eigenvector is the largest cross product
/// of two rows of `B - l I`, accurate to `eps |A| / spread`; (3) the other two come from one exact
/// Jacobi rotation of the 2x2 projection of `A` on the orthogonal plane, which is stable for equal
/// and nearly equal eigenvalues. Eigenvalues are Rayleigh quotients. An error in the directions
/// only enters a principal-stretch stress multiplied by a difference of principal stresses,
/// itself proportional to the spread, so stresses stay accurate to round-off of `|A|` (tested
/// against [`sym_eigen_jacobi`] over 2000 random, degenerate and nearly degenerate matrices).
#[inline]
pub fn sym_eigen(m: &Sym6) -> ([f64; 3], Mat3) {
    let mean = (m[0] + m[1] + m[2]) * (1.0 / 3.0);
    let b = [m[0] - mean, m[1] - mean, m[2] - mean, m[3], m[4], m[5]];
    let p2 =
        (b[0] * b[0] + b[1] * b[1] + b[2] * b[2] + 2.0 * (b[3] * b[3] + b[4] * b[4] + b[5] * b[5]))
            * (1.0 / 6.0);
    if !(p2 > 1e-280) {
        // Isotropic to round-off (or below underflow): any basis.
        return ([m[0], m[1], m[2]], Mat3::identity());
    }
    let p = p2.sqrt();
    let det = b[0] * (b[1] * b[2] - b[4] * b[4]) - b[3] * (b[3] * b[2] - b[4] * b[5])
        + b[5] * (b[3] * b[4] - b[1] * b[5]);
    let r = (0.5 * det / (p2 * p)).clamp(-1.0, 1.0);
    let phi = r.acos() * (1.0 / 3.0);
    let l_iso = if det >= 0.0 {
        2.0 * p * phi.cos()
    } else {
        2.0 * p * (phi + 2.0 * std::f64::consts::FRAC_PI_3).cos()
    };
    let r0 = [b[0] - l_iso, b[3], b[5]];
    let r1 = [b[3], b[1] - l_iso, b[4]];
    let r2 = [b[5], b[4], b[2] - l_iso];
    let (c01, c02, c12) = (cross(r0, r1), cross(r0, r2), cross(r1, r2));
    let (n01, n02, n12) = (dot(c01, c01), dot(c02, c02), dot(c12, c12));
    let (v, nv) = if n01 >= n02 && n01 >= n12 {
        (c01, n01)
    } else if n02 >= n12 {
        (c02, n02)
    } else {
        (c12, n12)
    };
    if !(nv > 1e-300) || !nv.is_finite() {
        return sym_eigen_jacobi(m);
    }
    let inv = 1.0 / nv.sqrt();
    let v = [v[0] * inv, v[1] * inv, v[2] * inv];
    // Orthonormal basis (u, w) of the plane orthogonal to v.
    let (ax, ay, az) = (v[0].abs(), v[1].abs(), v[2].abs());
    let e = if ax <= ay && ax <= az {
        [1.0, 0.0, 0.0]
    } else if ay <= az {
        [0.0, 1.0, 0.0]
    } else {
        [0.0, 0.0, 1.0]
    };
    let u = cross(v, e);
    let inv = 1.0 / dot(u, u).sqrt();
    let u = [u[0] * inv, u[1] * inv, u[2] * inv];
    let w = cross(v, u);
    let l0 = quad(m, v, v);
    let (a11, a22, a12) = (quad(m, u, u), quad(m, w, w), quad(m, u, w));
    let (l1, l2, x, y) = if a12 == 0.0 {
        (a11, a22, u, w)
    } else {
        let (c, s, t) = givens(a11, a22, a12);
        (
            a11 - t * a12,
            a22 + t * a12,
            [
                c * u[0] - s * w[0],
                c * u[1] - s * w[1],
                c * u[2] - s * w[2],
            ],
            [
                s * u[0] + c * w[0],
                s * u[1] + c * w[1],
                s * u[2] + c * w[2],
            ],
        )
    };
    (
        [l0, l1, l2],
        Mat3::new(v[0], x[0], y[0], v[1], x[1], y[1], v[2], x[2], y[2]),
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
    /// `1 / l_i^2`, the eigenvalues of `C^-1`.
    pub inv_stretch_sq: [f64; 3],
}

impl Principal {
    /// Decompose `F` (which must have a positive determinant: check it first).
    #[inline]
    pub fn of(f: &Mat3) -> Result<Principal, LawError> {
        let (a, n) = sym_eigen(&c_minus_identity(f));
        let mut ln = [0.0; 3];
        let mut inv = [0.0; 3];
        for i in 0..3 {
            // a_i > -1 for det F > 0 up to round-off; refuse a collapsed direction.
            if !(a[i] > -1.0) {
                return Err(LawError::NotFinite("principal stretch collapsed to zero"));
            }
            ln[i] = 0.5 * a[i].ln_1p();
            inv[i] = 1.0 / (1.0 + a[i]);
        }
        Ok(Principal {
            ln_stretch: ln,
            ln_j: ln[0] + ln[1] + ln[2],
            directions: n,
            inv_stretch_sq: inv,
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
            tau[0] * self.inv_stretch_sq[0],
            tau[1] * self.inv_stretch_sq[1],
            tau[2] * self.inv_stretch_sq[2],
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
        check_with(m, sym_eigen);
        check_with(m, sym_eigen_jacobi);
    }

    fn check_with(m: Sym6, eig: fn(&Sym6) -> ([f64; 3], Mat3)) {
        let (l, v) = eig(&m);
        let a = mat_from_sym6(&m);
        let scale = a.norm().max(1e-300);
        let recon = spectral(&l, &v);
        assert!(
            (recon - a).norm() <= 4e-16 * scale * 16.0,
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
            [2.0, 2.0 + 1e-8, 2.0 - 1e-8],
            [-0.5, 0.3, 0.3 + 1e-12],
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
    fn spectral_functions_agree_with_jacobi_near_degeneracy() {
        // A smooth isotropic function g(A) = sum g(l_i) n_i n_i must not depend on how a
        // (nearly) degenerate eigenspace is split.
        let g = |x: f64| x * x * x + 2.0 * x + x.exp();
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for k in 0..2000 {
            let r =
                Rotation3::from_euler_angles(6.0 * rnd(), 6.0 * rnd(), 6.0 * rnd()).into_inner();
            let base = rnd() - 0.5;
            let gap = [1.0, 1e-4, 1e-8, 1e-12, 0.0][k % 5];
            let d = [base, base + gap * rnd(), base + (rnd() - 0.5)];
            let a = sym6(&(r * Mat3::from_diagonal(&d.into()) * r.transpose()));
            let (l1, v1) = sym_eigen(&a);
            let (l2, v2) = sym_eigen_jacobi(&a);
            let f1 = spectral(&l1.map(g), &v1);
            let f2 = spectral(&l2.map(g), &v2);
            assert!(
                (f1 - f2).norm() < 1e-13 * f2.norm(),
                "k={k} d={d:?}: {:e}",
                (f1 - f2).norm()
            );
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
