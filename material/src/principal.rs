//! Principal stretches and directions: the one eigen-kernel shared by every principal-stretch law
//! (Ogden, simplified rubber/foam, Hencky plasticity).
//!
//! **Method.** [`SymEigen`]: the isolated eigenvalue from the trigonometric (Cardano/Smith)
//! solution, evaluated without trigonometric calls (a polynomial and one Newton step on the
//! Chebyshev cubic), its eigenvector from the adjugate (cross products), and the remaining pair
//! from the Frobenius norm of the deviatoric part of the tensor restricted to the orthogonal plane
//! (see its doc). The laws only need isotropic functions `sum_i c_i N_i (x) N_i`, so the pair is
//! kept as a projector difference and its eigenvectors are never formed; [`sym_eigen`] builds
//! explicit eigenvectors (2x2 projection) for callers that need them. Plain Cardano for all three
//! eigenvalues loses about half the digits of two eigenvalues that are 1e-8 apart; this hybrid
//! does not, because the nearly equal pair comes from the projection on the plane. It is
//! non-iterative and calls no library function. A cyclic Jacobi solver ([`sym_eigen_jacobi`],
//! Golub & Van Loan sec. 8.5, Numerical Recipes sec. 11.1) is kept as the reference it is tested
//! against (and as the fallback for non-finite input).
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
//! divides a difference of coefficients by a difference of stretches ([`SymEigen::spectral6`]
//! multiplies `c_1 - c_2` by a bounded tensor).
//!
//! Symmetric tensors are stored as `[xx, yy, zz, xy, yz, zx]` (the "Sym6" order used for
//! history values and output columns).

use crate::real::{Mask, Real};
use crate::tensor::{Mat3, M3};

/// Symmetric tensor in the order `[xx, yy, zz, xy, yz, zx]`.
pub type Sym6<R = f64> = [R; 6];

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
pub fn ddot6<R: Real>(a: &Sym6<R>, b: &Sym6<R>) -> R {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + (a[3] * b[3] + a[4] * b[4] + a[5] * b[5]) * 2.0
}

/// `C - I = H + H^T + H^T H` with `H = F - I`, as Sym6 (twice the Green-Lagrange strain),
/// accurate at small strain.
#[inline(always)]
pub fn c_minus_identity<R: Real>(f: &M3<R>) -> Sym6<R> {
    let mut h = *f;
    for i in 0..3 {
        h[i][i] -= R::splat(1.0);
    }
    // (H^T H)_ij = sum_k H_ki H_kj.
    macro_rules! hth {
        ($i:expr, $j:expr) => {
            h[0][$i] * h[0][$j] + h[1][$i] * h[1][$j] + h[2][$i] * h[2][$j]
        };
    }
    [
        h[0][0] * 2.0 + hth!(0, 0),
        h[1][1] * 2.0 + hth!(1, 1),
        h[2][2] * 2.0 + hth!(2, 2),
        h[0][1] + h[1][0] + hth!(0, 1),
        h[1][2] + h[2][1] + hth!(1, 2),
        h[2][0] + h[0][2] + hth!(2, 0),
    ]
}

/// `b - I = H + H^T + H H^T` with `H = F - I` (left Cauchy-Green tensor minus identity).
#[inline(always)]
pub fn b_minus_identity<R: Real>(f: &M3<R>) -> Sym6<R> {
    let t = [
        [f[0][0], f[1][0], f[2][0]],
        [f[0][1], f[1][1], f[2][1]],
        [f[0][2], f[1][2], f[2][2]],
    ];
    c_minus_identity(&t)
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
fn cross<R: Real>(a: [R; 3], b: [R; 3]) -> [R; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[inline(always)]
fn dot<R: Real>(a: [R; 3], b: [R; 3]) -> R {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `cos(acos(r) / 3)` for `0 <= r <= 1`: the root `c` in `[sqrt(3)/2, 1]` of the Chebyshev
/// cubic `T_3(c) = 4c^3 - 3c = r` (`cos 3x = T_3(cos x)`).
///
/// A degree-10 Chebyshev interpolant of `c(r)` on [0, 1] (largest error 4.0e-11; `c(r)` is
/// analytic there, its nearest singularity is the double root at `r = -1`), evaluated by Estrin's
/// scheme, refined by one Newton step on `g(c) = 4c^3 - 3c - r`, `c <- c - g q(r)`, where
/// `q(r)` is a degree-7 Chebyshev interpolant of `1 / g'(c(r)) = 1 / (12 c^2 - 3)` (relative
/// error 4.2e-7) evaluated alongside `c`, so the step needs no division. The step's error is
/// `e (1 - g' q) + 1.5 e^2 < 4e-11 * 4.2e-7 + 3e-21`, below round-off: the result is within
/// 0.9 ulp of the true root over [0, 1] (checked with exact rational residuals at 3e5 points),
/// as accurate as `(r.acos() / 3.0).cos()` and without its two library calls.
/// `g' = 12c^2 - 3 >= 6` on the interval, so the step is well conditioned.
#[inline(always)]
fn cos_third_acos<R: Real>(r: R) -> R {
    const P: [f64; 11] = [
        0.866_025_403_824_073_7,
        0.166_666_657_041_595_22,
        -0.048_112_130_678_772_26,
        0.024_685_043_685_333_34,
        -0.015_538_831_970_539_362,
        0.010_705_742_346_317_493,
        -0.007_382_038_615_162_401_5,
        0.004_549_326_227_871_378,
        -0.002_180_841_184_698_775_6,
        0.000_682_820_153_253_322_2,
        -0.000_101_150_850_902_988_84,
    ];
    // 1 / g'(c(r)) = 1 / (12 c^2 - 3), to 4.2e-7 relative.
    const Q: [f64; 8] = [
        0.166_666_597_300_638_74,
        -0.096_216_101_535_776_91,
        0.073_879_304_580_797_33,
        -0.060_695_323_449_479_144,
        0.047_453_183_702_718_34,
        -0.030_138_396_738_139_228,
        0.012_636_372_717_629_74,
        -0.002_474_561_501_443_872_7,
    ];
    let r2 = r * r;
    let r4 = r2 * r2;
    let r8 = r4 * r4;
    let a = (r * P[1] + P[0]) + (r * P[3] + P[2]) * r2;
    let b = (r * P[5] + P[4]) + (r * P[7] + P[6]) * r2;
    let d = (r * P[9] + P[8]) + r2 * P[10];
    let c = (a + b * r4) + d * r8;
    let qa = (r * Q[1] + Q[0]) + (r * Q[3] + Q[2]) * r2;
    let qb = (r * Q[5] + Q[4]) + (r * Q[7] + Q[6]) * r2;
    let inv_g1 = qa + qb * r4;
    c - (c * (c * c * 4.0 - 3.0) - r) * inv_g1
}

/// First stage shared by [`SymEigen::decompose`] and [`sym_eigen`]: the isolated eigenvalue and
/// its eigenvector (see [`SymEigen`] for the method), for every lane at once.
///
/// `A = mean I + p Bn`; `mu0` is the isolated eigenvalue of `Bn`, `v` (with `nv = |v|^2`,
/// `12 <= nv <= 81`) an unnormalised eigenvector of it. Lanes with `tr(B^2)/6 <= 1e-280`
/// (isotropic to round-off, or below underflow, or NaN) are marked `iso` and computed with
/// `p = 1` so that nothing else divides by zero; lanes whose eigenvector bound fails (only a
/// non-finite input gets there) are marked `bad`.
struct Isolated<R: Real> {
    mean: R,
    p: R,
    bn: Sym6<R>,
    mu0: R,
    v: [R; 3],
    nv: R,
    iso: R::Mask,
    bad: R::Mask,
}

#[inline(always)]
fn isolated<R: Real>(m: &Sym6<R>) -> Isolated<R> {
    let mean = (m[0] + m[1] + m[2]) * (1.0 / 3.0);
    let b = [m[0] - mean, m[1] - mean, m[2] - mean, m[3], m[4], m[5]];
    let p2 =
        (b[0] * b[0] + b[1] * b[1] + b[2] * b[2] + (b[3] * b[3] + b[4] * b[4] + b[5] * b[5]) * 2.0)
            * (1.0 / 6.0);
    let iso = !p2.gt(R::splat(1e-280));
    let p2 = R::select(iso, R::splat(1.0), p2);
    let p = p2.sqrt();
    let ip2 = R::splat(1.0) / p2;
    let ip = p * ip2;
    let det = b[0] * (b[1] * b[2] - b[4] * b[4]) - b[3] * (b[3] * b[2] - b[4] * b[5])
        + b[5] * (b[3] * b[4] - b[1] * b[5]);
    let r = (det.abs() * 0.5 * (ip2 * ip)).min(R::splat(1.0));
    let c2 = cos_third_acos(r) * 2.0;
    let mu0 = R::select(det.ge(R::zero()), c2, -c2);
    let bn = [
        b[0] * ip,
        b[1] * ip,
        b[2] * ip,
        b[3] * ip,
        b[4] * ip,
        b[5] * ip,
    ];
    // N = Bn - mu0 I; adj(N) = (mu1 - mu0)(mu2 - mu0) v v^T, a non-negative multiple of the
    // projector. Its largest diagonal entry (a 2x2 principal minor of N) marks the largest
    // column, which is the cross product of the other two rows.
    let (n0, n1, n2) = (bn[0] - mu0, bn[1] - mu0, bn[2] - mu0);
    let r0 = [n0, bn[3], bn[5]];
    let r1 = [bn[3], n1, bn[4]];
    let r2 = [bn[5], bn[4], n2];
    let m0 = n1 * n2 - bn[4] * bn[4];
    let m1 = n0 * n2 - bn[5] * bn[5];
    let m2 = n0 * n1 - bn[3] * bn[3];
    let first = m0.ge(m1) & m0.ge(m2);
    let second = m1.ge(m2);
    let (c12, c20, c01) = (cross(r1, r2), cross(r2, r0), cross(r0, r1));
    let v: [R; 3] = crate::arr![3, |k| R::select(
        first,
        c12[k],
        R::select(second, c20[k], c01[k])
    )];
    let nv = dot(v, v);
    // 12 <= nv <= 81 in exact arithmetic: only a non-finite input fails this.
    let bad = !(nv.gt(R::splat(1.0)) & nv.lt(R::splat(1e3))) & !iso;
    Isolated {
        mean,
        p,
        bn,
        mu0,
        v,
        nv,
        iso,
        bad,
    }
}

/// Spectral decomposition of a symmetric 3x3 tensor `A`, in the form an isotropic tensor function
/// `sum_i c_i N_i (x) N_i` needs: the eigenvalues, the projector `V = N_0 (x) N_0` on the isolated
/// eigenvector and the half-difference `D = (N_1 (x) N_1 - N_2 (x) N_2) / 2` of the projectors
/// of the other two, so that (with `I = V + N_1 (x) N_1 + N_2 (x) N_2`)
///
/// ```text
/// sum_i c_i N_i (x) N_i = cm I + (c_0 - cm) V + (c_1 - c_2) D,      cm = (c_1 + c_2)/2
/// ```
///
/// ([`SymEigen::spectral6`]). The eigenvectors of the pair are never formed.
///
/// **Method.** Non-iterative, no library call. With the deviator `B = A - tr(A)/3 I`,
/// `p = sqrt(tr(B^2)/6)` and the scaled deviator `Bn = B / p` (eigenvalues in [-2, 2]):
///
/// 1. The trigonometric solution of the characteristic cubic (Smith 1961) gives the *isolated*
///    eigenvalue of `Bn`, the one farthest from the other two: with `r = det(B) / (2 p^3)` in
///    [-1, 1] it is `mu_0 = 2 sign(r) cos(acos(|r|)/3)` (the largest if det B >= 0, else the
///    smallest). The formula is flat (`dc/dr = 1/9` at `|r| = 1`), hence accurate, exactly where
///    the other two merge; `cos(acos(|r|)/3)` is evaluated without trigonometric calls
///    (`cos_third_acos`, a polynomial and one Newton step).
/// 2. Its eigenvector: `adj(Bn - mu_0 I) = (mu_1 - mu_0)(mu_2 - mu_0) N_0 (x) N_0` and
///    `|mu_i - mu_0| >= sqrt 3` for the isolated root, so the column of the adjugate with the
///    largest diagonal entry (a 2x2 principal minor), i.e. the cross product of the other two
///    rows (as in Kopp 2008, Int. J. Mod. Phys. C 19:523), is `v` with `12 <= |v|^2 <= 81`:
///    accurate to `eps / spread`, and
///    `V = v v^T / |v|^2` needs no square root.
/// 3. The pair: `Q = Bn - m I - (mu_0 - m) V` with `m = (tr Bn - mu_0)/2` the mean of the pair
///    (formed as `|v|^2 Q`, so that the division by `|v|^2` runs beside it) is
///    `Bn` restricted to the plane orthogonal to `N_0`, minus its mean there:
///    `Q = h (N_1 (x) N_1 - N_2 (x) N_2)` with `h = (mu_1 - mu_2)/2 = |Q|_F / sqrt 2`. So the pair
///    is `m +- h` and `D = Q / (2h)`. `Q` is formed from entries of size 1, so `h` carries an
///    absolute error of a few `eps` however close the pair is, and nothing subtracts two nearly
///    equal squares (the invariant form `(mu_1 - mu_2)^2 = 12 - 3 mu_0^2` loses half the
///    digits). When the pair is (nearly) equal, `D` is dominated by rounding, but its norm is
///    `1/sqrt 2` by construction (`h` comes from the same `Q`) and it only enters the function
///    multiplied by `c_1 - c_2 ~ c'(m) 2h`, so the result keeps an absolute error
///    `~ eps (|c| + |c'|)`: isotropic functions are continuous through degeneracy and no formula
///    divides a difference of `c` by a difference of eigenvalues. `Q = 0` exactly gives `D = 0`.
///
/// Eigenvalues of `A` are `tr(A)/3 + p mu`. Tested against [`sym_eigen_jacobi`] over 2000
/// random, degenerate and nearly degenerate matrices, and for reconstruction
/// (`sum lambda_i N_i (x) N_i = A`) and the projector identities.
#[derive(Clone, Copy, Debug)]
pub struct SymEigen<R: Real = f64> {
    /// Eigenvalues: the isolated one, then the larger and the smaller of the pair.
    pub values: [R; 3],
    /// `V = N_0 (x) N_0`, as Sym6.
    pub proj: Sym6<R>,
    /// `D = (N_1 (x) N_1 - N_2 (x) N_2) / 2`, as Sym6.
    pub half_diff: Sym6<R>,
}

impl SymEigen<f64> {
    /// Decompose a symmetric tensor given as Sym6.
    #[inline(always)]
    pub fn of(m: &Sym6) -> SymEigen {
        SymEigen::decompose(m).0
    }
}

impl<R: Real> SymEigen<R> {
    /// Decompose a symmetric tensor in every lane; the mask marks lanes with a non-finite input,
    /// whose result is meaningless. Lanes where the adjugate step cannot certify its eigenvector
    /// (a non-finite input, or a deviator so small against the mean that its scaled form is
    /// rounding noise, e.g. a uniform dilatation) are redone by [`sym_eigen_jacobi`], one lane at
    /// a time: a rare path.
    #[inline(always)]
    pub fn decompose(m: &Sym6<R>) -> (SymEigen<R>, R::Mask) {
        let Isolated {
            mean,
            p,
            bn,
            mu0,
            v,
            nv,
            iso,
            bad,
        } = isolated(m);
        // nv Q, so that no division by nv precedes the norm: h = |nv Q|_F / (sqrt 2 nv).
        let inv_nv = R::splat(1.0) / nv;
        let mid = ((bn[0] + bn[1] + bn[2]) - mu0) * 0.5;
        let k = mu0 - mid;
        let q = [
            nv * (bn[0] - mid) - k * (v[0] * v[0]),
            nv * (bn[1] - mid) - k * (v[1] * v[1]),
            nv * (bn[2] - mid) - k * (v[2] * v[2]),
            nv * bn[3] - k * (v[0] * v[1]),
            nv * bn[4] - k * (v[1] * v[2]),
            nv * bn[5] - k * (v[2] * v[0]),
        ];
        let h2 = ddot6(&q, &q) * 0.5;
        let hs = h2.sqrt();
        let h = hs * inv_nv;
        // D = Q / (2h) = (nv Q) / (2 |nv Q|_F / sqrt 2).
        let pos = h2.gt(R::zero());
        let g = R::select(
            pos,
            R::splat(0.5) / R::select(pos, hs, R::splat(1.0)),
            R::zero(),
        );
        let (z, one, half) = (R::zero(), R::splat(1.0), R::splat(0.5));
        // Isotropic lanes: any basis, the coordinate axes.
        macro_rules! sel {
            ($a:expr, $b:expr) => {
                R::select(iso, $b, $a)
            };
        }
        let e = SymEigen {
            values: [
                sel!(mean + p * mu0, m[0]),
                sel!(mean + p * (mid + h), m[1]),
                sel!(mean + p * (mid - h), m[2]),
            ],
            proj: [
                sel!(v[0] * v[0] * inv_nv, one),
                sel!(v[1] * v[1] * inv_nv, z),
                sel!(v[2] * v[2] * inv_nv, z),
                sel!(v[0] * v[1] * inv_nv, z),
                sel!(v[1] * v[2] * inv_nv, z),
                sel!(v[2] * v[0] * inv_nv, z),
            ],
            half_diff: [
                sel!(q[0] * g, z),
                sel!(q[1] * g, half),
                sel!(q[2] * g, -half),
                sel!(q[3] * g, z),
                sel!(q[4] * g, z),
                sel!(q[5] * g, z),
            ],
        };
        let mut e = e;
        if bad.any() {
            for l in 0..R::LANES {
                if bad.lane(l) {
                    let ml: Sym6 = crate::arr![6, |k| m[k].lane(l)];
                    let (vals, n) = sym_eigen_jacobi(&ml);
                    let el = SymEigen::from_vectors(vals, &n);
                    for k in 0..3 {
                        e.values[k].set_lane(l, el.values[k]);
                    }
                    for k in 0..6 {
                        e.proj[k].set_lane(l, el.proj[k]);
                        e.half_diff[k].set_lane(l, el.half_diff[k]);
                    }
                }
            }
        }
        let finite = all_finite6(m);
        (e, !finite)
    }

    /// `sum_i c_i N_i (x) N_i = cm I + (c_0 - cm) V + (c_1 - c_2) D`, as Sym6.
    #[inline(always)]
    pub fn spectral6(&self, c: &[R; 3]) -> Sym6<R> {
        let cm = (c[1] + c[2]) * 0.5;
        let a = c[0] - cm;
        let g = c[1] - c[2];
        let (v, d) = (&self.proj, &self.half_diff);
        [
            cm + a * v[0] + g * d[0],
            cm + a * v[1] + g * d[1],
            cm + a * v[2] + g * d[2],
            a * v[3] + g * d[3],
            a * v[4] + g * d[4],
            a * v[5] + g * d[5],
        ]
    }
}

impl SymEigen<f64> {
    /// From eigenvalues and orthonormal eigenvectors (the columns of `n`).
    pub fn from_vectors(values: [f64; 3], n: &Mat3) -> SymEigen {
        let outer = |k: usize| {
            spectral6(
                &[
                    (k == 0) as u8 as f64,
                    (k == 1) as u8 as f64,
                    (k == 2) as u8 as f64,
                ],
                n,
            )
        };
        let (v, x, y) = (outer(0), outer(1), outer(2));
        let mut d = [0.0; 6];
        for k in 0..6 {
            d[k] = 0.5 * (x[k] - y[k]);
        }
        SymEigen {
            values,
            proj: v,
            half_diff: d,
        }
    }
}

/// Eigenvalues and orthonormal eigenvectors (the columns of the returned matrix) of a symmetric
/// tensor given as Sym6. Eigenvalues are not sorted. The laws use [`SymEigen`], which does not
/// form the eigenvectors of the pair; this is for callers that need the vectors themselves.
///
/// Steps 1 and 2 are those of [`SymEigen`]. The pair comes from the exact eigen-solution of the
/// 2x2 projection of `Bn` on the plane orthogonal to `v`, spanned by `u = v x e` (`e` the
/// coordinate axis least aligned with `v`, so `u` is a permutation of two components of `v`,
/// exactly orthogonal to it) and `w = v x u`. Neither is normalised first: with `n_v = |v|^2`,
/// `n_u = |u|^2` and `|w| = sqrt(n_v n_u)`, the projection times `n_v n_u` is
/// `K = [[n_v u.Bn u, sqrt(n_v) u.Bn w], [sqrt(n_v) u.Bn w, w.Bn w]]`, whose eigenvalues, with
/// `d = (K11 - K22)/2` and `h = sqrt(d^2 + K12^2)`, are `(K11 + K22)/2 +- h`; the eigenvector of
/// the larger one is `(h + d, K12)` if `d >= 0`, else `(K12, h - d)`, in the orthonormal
/// coordinates `(u/|u|, w/|w|)` (the two rows of `K - l I`, whichever has no cancellation).
/// Neither form subtracts nearly equal numbers, so the pair is stable for equal and nearly equal
/// eigenvalues (an exactly degenerate pair keeps `(u, w)`). The isolated eigenvalue is the
/// Rayleigh quotient `v.Bn v / n_v`. An error in the directions only enters a principal-stretch
/// stress multiplied by a difference of principal stresses, itself proportional to the spread, so
/// stresses stay accurate to round-off of `|A|` (tested against [`sym_eigen_jacobi`]).
#[inline]
pub fn sym_eigen(m: &Sym6) -> ([f64; 3], Mat3) {
    let Isolated {
        mean,
        p,
        bn,
        v,
        nv,
        iso,
        bad,
        ..
    } = isolated(m);
    if iso {
        return ([m[0], m[1], m[2]], Mat3::identity());
    }
    if bad {
        return sym_eigen_jacobi(m);
    }
    let (ax, ay, az) = (v[0].abs(), v[1].abs(), v[2].abs());
    let u = if ax <= ay && ax <= az {
        [0.0, v[2], -v[1]]
    } else if ay <= az {
        [-v[2], 0.0, v[0]]
    } else {
        [v[1], -v[0], 0.0]
    };
    let nu = dot(u, u);
    let w = cross(v, u);
    let bw = mul6(&bn, w);
    let (q_vv, q_uu, q_ww, q_uw) = (
        dot(v, mul6(&bn, v)),
        dot(u, mul6(&bn, u)),
        dot(w, bw),
        dot(u, bw),
    );
    let sv = nv.sqrt();
    let su = nu.sqrt();
    // 1 / (nv nu sv) gives 1/(nv nu), 1/nv and 1/sv by multiplications.
    let dd = 1.0 / (nv * nu * sv);
    let k11 = q_uu * nv;
    let k12 = q_uw * sv;
    let d = 0.5 * (k11 - q_ww);
    let mid = 0.5 * (k11 + q_ww);
    let h = (d * d + k12 * k12).sqrt();
    let pk = p * dd * sv;
    let l0 = mean + p * q_vv * (dd * sv * nu);
    let (l1, l2) = (mean + (mid + h) * pk, mean + (mid - h) * pk);
    let iv = dd * nv * nu;
    let v = [v[0] * iv, v[1] * iv, v[2] * iv];
    // Eigenvector (s, t) of mid + h in (u/su, w/(su sv)) coordinates; (-t, s) is that of mid - h.
    let (s, t) = if d >= 0.0 { (h + d, k12) } else { (k12, h - d) };
    let n2 = s * s + t * t;
    let (x, y) = if n2 > 1e-200 {
        let g = 1.0 / (n2.sqrt() * su * sv);
        let (xu, xw) = (s * sv * g, t * g);
        let (yu, yw) = (-t * sv * g, s * g);
        (
            [
                xu * u[0] + xw * w[0],
                xu * u[1] + xw * w[1],
                xu * u[2] + xw * w[2],
            ],
            [
                yu * u[0] + yw * w[0],
                yu * u[1] + yw * w[1],
                yu * u[2] + yw * w[2],
            ],
        )
    } else {
        // Degenerate pair (split below 1e-100 p): any basis of the plane.
        let iu = 1.0 / su;
        let iw = iu * iv;
        (
            [u[0] * iu, u[1] * iu, u[2] * iu],
            [w[0] * iw, w[1] * iw, w[2] * iw],
        )
    };
    (
        [l0, l1, l2],
        Mat3::new(v[0], x[0], y[0], v[1], x[1], y[1], v[2], x[2], y[2]),
    )
}

/// `M a` for a symmetric `M` given as Sym6.
#[inline(always)]
fn mul6<R: Real>(m: &Sym6<R>, a: [R; 3]) -> [R; 3] {
    [
        m[0] * a[0] + m[3] * a[1] + m[5] * a[2],
        m[3] * a[0] + m[1] * a[1] + m[4] * a[2],
        m[5] * a[0] + m[4] * a[1] + m[2] * a[2],
    ]
}

/// Principal logarithmic stretches of `F` and the reference principal directions.
#[derive(Clone, Copy, Debug)]
pub struct Principal<R: Real = f64> {
    /// `ln l_i`, the principal logarithmic (Hencky) strains.
    pub ln_stretch: [R; 3],
    /// `ln J = sum_i ln l_i`.
    pub ln_j: R,
    /// Spectral decomposition of `C - I` (eigenvalues `l_i^2 - 1`): the reference (Lagrangian)
    /// principal directions `N_i`, as the projectors that stresses `sum_i c_i N_i (x) N_i` need.
    pub eigen: SymEigen<R>,
    /// `l_i^2`, the eigenvalues of `C`.
    pub stretch_sq: [R; 3],
    /// `1 / l_i^2`, the eigenvalues of `C^-1`.
    pub inv_stretch_sq: [R; 3],
    /// `C - I` (twice the Green-Lagrange strain), as Sym6: the tensor that was decomposed.
    pub c_minus_i: Sym6<R>,
}

impl<R: Real> Principal<R> {
    /// Decompose `F` (which must have a positive determinant: check it first). The mask marks
    /// lanes whose input was not finite or whose stretch collapsed to zero (`l_i^2 - 1 <= -1`,
    /// only possible through round-off at det F near 0): their result is meaningless.
    #[inline(always)]
    pub fn of(f: &M3<R>) -> (Principal<R>, R::Mask) {
        let c1 = c_minus_identity(f);
        let (eigen, mut bad) = SymEigen::decompose(&c1);
        let a = eigen.values;
        for x in a {
            bad = bad | !x.gt(R::splat(-1.0));
        }
        let ln = [a[0].ln_1p() * 0.5, a[1].ln_1p() * 0.5, a[2].ln_1p() * 0.5];
        let sq = [a[0] + 1.0, a[1] + 1.0, a[2] + 1.0];
        let one = R::splat(1.0);
        let p = Principal {
            ln_stretch: ln,
            ln_j: ln[0] + ln[1] + ln[2],
            eigen,
            stretch_sq: sq,
            inv_stretch_sq: [one / sq[0], one / sq[1], one / sq[2]],
            c_minus_i: c1,
        };
        (p, bad)
    }

    /// Isochoric logarithmic stretches `ln lbar_i = ln l_i - ln J / 3`.
    #[inline(always)]
    pub fn ln_isochoric(&self) -> [R; 3] {
        let s = self.ln_j * (1.0 / 3.0);
        [
            self.ln_stretch[0] - s,
            self.ln_stretch[1] - s,
            self.ln_stretch[2] - s,
        ]
    }

    /// PK2 stress from principal Kirchhoff stresses, as Sym6:
    /// `S = sum_i tau_i / l_i^2 N_i (x) N_i`.
    #[inline(always)]
    pub fn pk2_from_kirchhoff(&self, tau: &[R; 3]) -> Sym6<R> {
        let c = [
            tau[0] * self.inv_stretch_sq[0],
            tau[1] * self.inv_stretch_sq[1],
            tau[2] * self.inv_stretch_sq[2],
        ];
        self.eigen.spectral6(&c)
    }
}

/// `M S M^T` for a symmetric `S` given as Sym6, as Sym6.
#[inline(always)]
pub fn sandwich6<R: Real>(m: &M3<R>, s: &Sym6<R>) -> Sym6<R> {
    // T = M S (row i of M times S), then (T M^T)_ij = T_i . M_j.
    let t = [mul6(s, m[0]), mul6(s, m[1]), mul6(s, m[2])];
    macro_rules! e {
        ($i:expr, $j:expr) => {
            t[$i][0] * m[$j][0] + t[$i][1] * m[$j][1] + t[$i][2] * m[$j][2]
        };
    }
    [e!(0, 0), e!(1, 1), e!(2, 2), e!(0, 1), e!(1, 2), e!(2, 0)]
}

/// Whether every component of a Sym6 is finite.
#[inline(always)]
pub fn all_finite6<R: Real>(s: &Sym6<R>) -> R::Mask {
    (s[0].is_finite() & s[1].is_finite() & s[2].is_finite())
        & (s[3].is_finite() & s[4].is_finite() & s[5].is_finite())
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
        check_projectors(m);
    }

    /// `SymEigen`: reconstruction, partition of unity, and (for a separated pair) the projector
    /// identities `V^2 = V`, `tr V = 1`, `V D = 0`, `(2D)^2 = I - V`.
    fn check_projectors(m: Sym6) {
        let e = SymEigen::of(&m);
        let a = mat_from_sym6(&m);
        let scale = a.norm().max(1e-300);
        let recon = mat_from_sym6(&e.spectral6(&e.values));
        assert!(
            (recon - a).norm() <= 4e-16 * scale * 16.0,
            "{:e}",
            (recon - a).norm() / scale
        );
        assert_eq!(mat_from_sym6(&e.spectral6(&[1.0; 3])), Mat3::identity());
        let (v, d) = (mat_from_sym6(&e.proj), mat_from_sym6(&e.half_diff));
        assert!((v * v - v).norm() < 1e-14 && (v.trace() - 1.0).abs() < 1e-14);
        let spread = (e.values[1] - e.values[2]).abs();
        if spread > 1e-6 * scale {
            assert!(
                (v * d).norm() < 1e-14 * scale / spread,
                "{:e}",
                (v * d).norm()
            );
            let d2 = 4.0 * d * d;
            assert!(
                (d2 - (Mat3::identity() - v)).norm() < 1e-14 * scale / spread,
                "{:e}",
                (d2 - (Mat3::identity() - v)).norm()
            );
        }
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
            let e = SymEigen::of(&a);
            let f3 = mat_from_sym6(&e.spectral6(&e.values.map(g)));
            assert!(
                (f3 - f2).norm() < 1e-13 * f2.norm(),
                "k={k} d={d:?}: {:e}",
                (f3 - f2).norm()
            );
            check_projectors(a);
        }
    }

    #[test]
    fn cos_third_acos_matches_the_trigonometric_form() {
        // Both are within 0.8 ulp of the true root: they differ by at most 2 ulp.
        for k in 0..=100_000 {
            let r = k as f64 / 100_000.0;
            let c = cos_third_acos(r);
            let t = (r.acos() / 3.0).cos();
            assert!((c - t).abs() <= 2.0 * f64::EPSILON * t, "r={r}: {c} vs {t}");
        }
        assert!((cos_third_acos(1.0) - 1.0).abs() <= f64::EPSILON);
        assert!((cos_third_acos(0.0) - 0.75f64.sqrt()).abs() <= f64::EPSILON);
    }

    #[test]
    fn small_strain_logs_are_accurate() {
        let eps = 1e-9;
        let f = Mat3::new(1.0 + eps, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
        let p = Principal::of(&crate::tensor::from_mat3(&f)).0;
        let m = p.ln_stretch.iter().fold(0.0f64, |m, x| m.max(*x));
        assert!((m - (1.0 + eps).ln()).abs() < 1e-22, "{m:e}");
    }
}
