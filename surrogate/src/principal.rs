//! The largest eigenvalue of a symmetric 3 x 3 stress tensor, fast enough for serving.
//!
//! A tensor-target surrogate (see `target`) predicts the six Cauchy components of each ROI
//! element and reports their maximum principal stress, so every prediction needs R of these
//! (377 on the paper's ROI). nalgebra's iterative `symmetric_eigenvalues` takes about 175 us for
//! 377 tensors on the development machine, and the textbook trigonometric formula with `acos`,
//! `cos` and `powf` about 17 us: both too slow for the GP's 20 us latency floor.
//!
//! **Method** (the trigonometric solution of the characteristic cubic; Smith, "Eigenvalues of a
//! symmetric 3 x 3 matrix", Comm. ACM 4(4), 1961). With `m = tr(S) / 3`, the deviator
//! `B = S - m I`, `J2 = tr(B^2) / 2`, `J3 = det B` and `p = sqrt(J2 / 3)`, the eigenvalues are
//! `m + 2 p cos(theta + 2 pi k / 3)` with `cos(3 theta) = r = J3 / (2 p^3)`, `theta` in
//! `[0, pi / 3]`, and the largest is `m + 2 p c` with `c = cos(acos(r) / 3)` in `[1/2, 1]`.
//! Writing `h = sqrt((1 + r) / 2) = cos(3 theta / 2)` gives `c = cos(2/3 acos h)`, which is
//! analytic in `h` on `[0, 1]` (the square-root singularities of `acos` at `r = +-1` cancel), so
//! a degree-12 polynomial in `h` (Chebyshev interpolant, largest error 1.9e-12, Horner form)
//! replaces both library calls. No branch depends on the data except the isotropic guard, so
//! the loop over elements could vectorise (it does not yet: the components are interleaved).
//! The deviator is divided by its largest entry first, so any finite tensor, in any units,
//! gives a finite result.
//!
//! **Accuracy.** The polynomial adds at most `4e-12 p`. The rounding of `r` itself
//! (about `1e-15`) is amplified near `r = -1`, where the two largest eigenvalues meet and
//! `dc/dr` grows like `1 / sqrt(1 + r)`: there the error is about `p sqrt(1e-15)`, i.e. `1e-7`
//! of the deviatoric stress. The tests allow `1e-6 |B| + 1e-12 |S|` (Frobenius norms) against
//! nalgebra; for a surrogate whose error is a few percent this is round-off.

/// Degree-12 monomial coefficients of `c(h) = cos(2/3 acos h)` on `[0, 1]` (lowest first).
const C_OF_H: [f64; 13] = [
    0.5000000000018545,
    0.5773502685612654,
    -0.11111107547193218,
    0.05345755543879388,
    -0.03291229541294255,
    0.022800102183530662,
    -0.01675000054648387,
    0.012328409662911998,
    -0.008408648047377596,
    0.004814109735422088,
    -0.0020619415958669346,
    0.0005671066134395074,
    -7.359112361478683e-05,
];

/// Largest eigenvalue of the symmetric tensor `s = [xx, yy, zz, xy, yz, zx]` (module doc).
/// A non-finite component gives a non-finite result.
#[inline(always)]
pub fn max_principal(s: &[f64]) -> f64 {
    let m = (s[0] + s[1] + s[2]) * (1.0 / 3.0);
    // the deviator divided by its largest entry q, so that p^3 neither underflows nor
    // overflows whatever the units; q = 0 is the isotropic tensor
    let (a, b, c) = (s[0] - m, s[1] - m, s[2] - m);
    let q = a
        .abs()
        .max(b.abs())
        .max(c.abs())
        .max(s[3].abs())
        .max(s[4].abs())
        .max(s[5].abs());
    let iq = if q > 0.0 { 1.0 / q } else { 0.0 };
    let (a, b, c) = (a * iq, b * iq, c * iq);
    let (xy, yz, zx) = (s[3] * iq, s[4] * iq, s[5] * iq);
    // p^2 = J2 / 3
    let p2 = (0.5 * (a * a + b * b + c * c) + xy * xy + yz * yz + zx * zx) * (1.0 / 3.0);
    let det = a * (b * c - yz * yz) - xy * (xy * c - yz * zx) + zx * (xy * yz - b * zx);
    let p = p2.sqrt();
    // r = J3 / (2 p^3); an isotropic tensor (p = 0) has every eigenvalue equal to m
    let r = if p2 > 0.0 {
        (0.5 * det / (p2 * p)).clamp(-1.0, 1.0)
    } else {
        0.0
    };
    let h = (0.5 * (1.0 + r)).sqrt();
    let mut cth = C_OF_H[12];
    for k in (0..12).rev() {
        cth = cth * h + C_OF_H[k];
    }
    m + 2.0 * q * p * cth
}

/// `out[e] = max_principal(raw[6 e .. 6 e + 6])` for every element `e`. On x86-64 the loop is
/// also compiled with AVX2 and picked at run time, like `kernels::accumulate_rows` (the same
/// arithmetic: Rust does not fuse multiply-adds on its own).
pub fn max_principal_rows(raw: &[f64], out: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the processor supports AVX2, checked just above.
            unsafe { max_principal_rows_avx2(raw, out) };
            return;
        }
    }
    max_principal_rows_plain(raw, out)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn max_principal_rows_avx2(raw: &[f64], out: &mut [f64]) {
    max_principal_rows_plain(raw, out)
}

#[inline(always)]
fn max_principal_rows_plain(raw: &[f64], out: &mut [f64]) {
    for (o, s) in out.iter_mut().zip(raw.chunks_exact(6)) {
        *o = max_principal(s);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Matrix3;

    fn reference(s: &[f64; 6]) -> f64 {
        Matrix3::new(s[0], s[3], s[5], s[3], s[1], s[4], s[5], s[4], s[2])
            .symmetric_eigenvalues()
            .max()
    }

    fn check(s: [f64; 6]) {
        let m = (s[0] + s[1] + s[2]) / 3.0;
        let dev = ((s[0] - m).powi(2)
            + (s[1] - m).powi(2)
            + (s[2] - m).powi(2)
            + 2.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]))
            .sqrt();
        let norm = s.iter().map(|v| v * v).sum::<f64>().sqrt();
        let (got, want) = (max_principal(&s), reference(&s));
        assert!(
            (got - want).abs() <= 1e-6 * dev + 1e-12 * norm,
            "{s:?}: {got} against {want}"
        );
    }

    #[test]
    fn the_polynomial_matches_cos_of_two_thirds_acos() {
        for i in 0..=10_000 {
            let h = i as f64 / 10_000.0;
            let mut c = C_OF_H[12];
            for k in (0..12).rev() {
                c = c * h + C_OF_H[k];
            }
            assert!((c - (2.0 / 3.0 * h.acos()).cos()).abs() < 3e-12, "h = {h}");
        }
    }

    #[test]
    fn matches_nalgebra_on_random_and_degenerate_tensors() {
        let mut x = 0.318_309_886_f64;
        let mut rnd = move || {
            x = (x * 3.999 * (1.0 - x)).clamp(1e-9, 1.0 - 1e-9);
            2.0 * x - 1.0
        };
        for _ in 0..20_000 {
            let s = [rnd(), rnd(), rnd(), rnd(), rnd(), rnd()].map(|v| 3e3 * v);
            check(s);
        }
        // uniaxial tension and compression (two equal eigenvalues), pure shear, isotropic
        check([5.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        check([-5.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        check([0.0, 0.0, 0.0, 7.0, 0.0, 0.0]);
        check([2.0, 2.0, 2.0, 0.0, 0.0, 0.0]);
        check([0.0; 6]);
        // nearly equal largest pair, rotated
        check([1.0, 1.0 + 1e-9, -3.0, 1e-10, 0.0, 0.0]);
        check([1e4, 1e4, 1e4, 1e-3, 2e-3, -1e-3]);
        assert_eq!(max_principal(&[2.0, 2.0, 2.0, 0.0, 0.0, 0.0]), 2.0);
        // tiny and huge magnitudes: finite and scale with the tensor
        for scale in [1e-200, 1e-120, 1e120, 1e200] {
            let s = [3.0, -1.0, 0.5, 2.0, -0.25, 1.0].map(|v| v * scale);
            let want = reference(&[3.0, -1.0, 0.5, 2.0, -0.25, 1.0]) * scale;
            let got = max_principal(&s);
            assert!(
                (got - want).abs() <= 1e-12 * want.abs(),
                "{scale}: {got} against {want}"
            );
        }
        assert!(max_principal(&[f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0]).is_nan());
    }
}
