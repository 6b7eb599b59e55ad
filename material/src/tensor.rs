//! 3x3 matrices over a [`Real`] (one point, or one lane per point of a batch), row-major:
//! `m[i][j]`. The kernels need only these few operations, each written out so that the scalar
//! and the batched instantiation perform the same arithmetic in the same order.

use crate::real::Real;
use nalgebra::Matrix3;

/// 3x3 matrix of f64 (deformation gradient, stresses).
pub type Mat3 = Matrix3<f64>;

/// A 3x3 matrix over `R`, row-major.
pub type M3<R> = [[R; 3]; 3];

/// From a nalgebra matrix.
#[inline(always)]
pub fn from_mat3(m: &Mat3) -> M3<f64> {
    [
        [m[(0, 0)], m[(0, 1)], m[(0, 2)]],
        [m[(1, 0)], m[(1, 1)], m[(1, 2)]],
        [m[(2, 0)], m[(2, 1)], m[(2, 2)]],
    ]
}

/// To a nalgebra matrix.
#[inline(always)]
pub fn to_mat3(m: &M3<f64>) -> Mat3 {
    Mat3::new(
        m[0][0], m[0][1], m[0][2], m[1][0], m[1][1], m[1][2], m[2][0], m[2][1], m[2][2],
    )
}

/// Lane `l` of a batched matrix.
#[inline(always)]
pub fn lane<R: Real>(m: &M3<R>, l: usize) -> Mat3 {
    Mat3::from_fn(|i, j| m[i][j].lane(l))
}

/// The identity.
#[inline(always)]
pub fn identity<R: Real>() -> M3<R> {
    let (o, z) = (R::splat(1.0), R::zero());
    [[o, z, z], [z, o, z], [z, z, o]]
}

/// det M by the rule of Sarrus, grouped as the first-row cofactor expansion.
#[inline(always)]
pub fn det<R: Real>(m: &M3<R>) -> R {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

/// Cofactor matrix `cof M = det(M) M^-T`, without a division.
#[inline(always)]
pub fn cofactor<R: Real>(f: &M3<R>) -> M3<R> {
    let [[a, b, c], [d, e, g], [h, i, k]] = *f;
    [
        [e * k - g * i, g * h - d * k, d * i - e * h],
        [c * i - b * k, a * k - c * h, b * h - a * i],
        [b * g - c * e, c * d - a * g, a * e - b * d],
    ]
}

/// `A B`.
#[inline(always)]
pub fn mul<R: Real>(a: &M3<R>, b: &M3<R>) -> M3<R> {
    let mut c = [[R::zero(); 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            c[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
        }
    }
    c
}

/// `A B^T`.
#[inline(always)]
pub fn mul_bt<R: Real>(a: &M3<R>, b: &M3<R>) -> M3<R> {
    let mut c = [[R::zero(); 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            c[i][j] = a[i][0] * b[j][0] + a[i][1] * b[j][1] + a[i][2] * b[j][2];
        }
    }
    c
}

/// `A : B = sum_ij A_ij B_ij`.
#[inline(always)]
pub fn ddot<R: Real>(a: &M3<R>, b: &M3<R>) -> R {
    let mut s = R::zero();
    for i in 0..3 {
        s += a[i][0] * b[i][0] + a[i][1] * b[i][1] + a[i][2] * b[i][2];
    }
    s
}

/// `s M`.
#[inline(always)]
pub fn scale<R: Real>(m: &M3<R>, s: R) -> M3<R> {
    let mut c = *m;
    for row in c.iter_mut() {
        for x in row.iter_mut() {
            *x *= s;
        }
    }
    c
}

/// `M S` for a symmetric `S` given as Sym6 (`[xx, yy, zz, xy, yz, zx]`).
#[inline(always)]
pub fn mul_sym<R: Real>(m: &M3<R>, s: &[R; 6]) -> M3<R> {
    let sm = [[s[0], s[3], s[5]], [s[3], s[1], s[4]], [s[5], s[4], s[2]]];
    mul(m, &sm)
}

/// 64 deformation gradients typical of an indentation step: a mix of stretch (up to 15 %),
/// shear and rotation, varied so that a law's branches and table lookups see varied input.
/// The input of the law benchmarks and the `law_loop` example.
pub fn sample_gradients() -> Vec<Mat3> {
    (0..64)
        .map(|k| {
            let s = k as f64 / 63.0;
            let (a, b, c) = (
                0.3 * s - 0.15,
                0.1 * (s * 7.0).sin(),
                0.05 * (s * 3.0).cos(),
            );
            let stretch = Mat3::new(
                1.0 + a,
                b,
                0.0,
                b * 0.5,
                1.0 - 0.5 * a,
                c,
                0.0,
                c * 0.3,
                1.0 - 0.4 * a,
            );
            let rot =
                nalgebra::Rotation3::from_euler_angles(0.2 * s, -0.4 * s, 0.7 * s).into_inner();
            rot * stretch
        })
        .collect()
}
