//! Negative log marginal likelihood of R outputs sharing one kernel, and its gradient.
//!
//! With `K = K_se + (sn2 + jitter) I` (n x n) shared by the R columns of the normalised targets
//! `V` (n x R), and `A = K^-1 V`:
//!
//! ```text
//! -log p(V | theta) = 1/2 tr(V^T K^-1 V) + R/2 log|K| + nR/2 log(2 pi)
//! d(-log p)/d theta_j = 1/2 tr( (R K^-1 - A A^T) dK/d theta_j )
//! ```
//!
//! One Cholesky factorisation per evaluation gives `log|K|` (twice the sum of the log diagonal),
//! `A` and `K^-1`. The value and gradient are divided by `n R` so that the optimiser's tolerances
//! do not depend on the dataset's size.
//!
//! Source: Rasmussen and Williams 2006, eqs. (2.30) and (5.9), summed over independent outputs.

use super::kernel::{SeArd, JITTER};
use nalgebra::DMatrix;

/// Squared differences per input dimension, precomputed once per training set.
pub struct PairwiseSquares {
    /// `d2[d][(a, b)] = (u_a,d - u_b,d)^2`.
    pub d2: Vec<DMatrix<f64>>,
}

impl PairwiseSquares {
    /// From normalised inputs `u` (n x D).
    pub fn compute(u: &DMatrix<f64>) -> Self {
        let n = u.nrows();
        let d2 = (0..u.ncols())
            .map(|d| DMatrix::from_fn(n, n, |a, b| (u[(a, d)] - u[(b, d)]).powi(2)))
            .collect();
        PairwiseSquares { d2 }
    }
}

/// Everything one factorisation gives.
pub struct Factorised {
    /// `K^-1 V`, n x R.
    pub alpha: DMatrix<f64>,
    /// `K^-1`, n x n.
    pub k_inv: DMatrix<f64>,
    /// Negative log marginal likelihood (not divided by n R).
    pub nll: f64,
    /// Correlation matrix times signal variance, `K_se` (without noise).
    pub k_se: DMatrix<f64>,
}

/// Factorises K for `kernel` and computes `A`, `K^-1` and the negative log marginal likelihood.
/// Returns `None` when K is not numerically positive definite.
pub fn compute_factorised(
    kernel: &SeArd,
    pw: &PairwiseSquares,
    v: &DMatrix<f64>,
) -> Option<Factorised> {
    let n = v.nrows();
    let r = v.ncols() as f64;
    let mut k_se = DMatrix::<f64>::zeros(n, n);
    for (d, m) in pw.d2.iter().enumerate() {
        let inv_l2 = 1.0 / (kernel.length_scales[d] * kernel.length_scales[d]);
        k_se.zip_apply(m, |acc, x| *acc += x * inv_l2);
    }
    k_se.apply(|x: &mut f64| *x = kernel.signal_variance * (-0.5 * *x).exp());
    let mut k = k_se.clone();
    for i in 0..n {
        k[(i, i)] += kernel.noise_variance + JITTER;
    }
    let chol = k.cholesky()?;
    let log_det: f64 = 2.0
        * chol
            .l_dirty()
            .diagonal()
            .iter()
            .map(|x| x.ln())
            .sum::<f64>();
    let alpha = chol.solve(v);
    let k_inv = chol.inverse();
    let fit_term: f64 = v.iter().zip(alpha.iter()).map(|(a, b)| a * b).sum();
    let nll =
        0.5 * fit_term + 0.5 * r * log_det + 0.5 * n as f64 * r * (2.0 * std::f64::consts::PI).ln();
    if !nll.is_finite() {
        return None;
    }
    Some(Factorised {
        alpha,
        k_inv,
        nll,
        k_se,
    })
}

/// Negative log marginal likelihood per target (divided by n R) and its gradient with respect
/// to the log-parameters `theta = [ln l_1 .. ln l_D, ln s2, ln sn2]`.
pub fn compute_nll_and_gradient(
    theta: &[f64],
    pw: &PairwiseSquares,
    v: &DMatrix<f64>,
) -> Option<(f64, Vec<f64>)> {
    let kernel = SeArd::from_log_params(theta);
    let f = compute_factorised(&kernel, pw, v)?;
    let n = v.nrows();
    let r = v.ncols() as f64;
    let scale = 1.0 / (n as f64 * r);
    // W = R K^-1 - A A^T (symmetric)
    let mut w = &f.alpha * f.alpha.transpose();
    w.zip_apply(&f.k_inv, |a, ki| *a = r * ki - *a);
    let nd = pw.d2.len();
    let mut grad = vec![0.0; nd + 2];
    for (d, m) in pw.d2.iter().enumerate() {
        let inv_l2 = 1.0 / (kernel.length_scales[d] * kernel.length_scales[d]);
        let mut s = 0.0;
        for ((wi, ki), di) in w.iter().zip(f.k_se.iter()).zip(m.iter()) {
            s += wi * ki * di;
        }
        grad[d] = 0.5 * s * inv_l2 * scale;
    }
    grad[nd] = 0.5 * w.iter().zip(f.k_se.iter()).map(|(a, b)| a * b).sum::<f64>() * scale;
    grad[nd + 1] = 0.5 * kernel.noise_variance * w.trace() * scale;
    Some((f.nll * scale, grad))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gradient_matches_finite_differences() {
        let n = 12;
        let u = DMatrix::from_fn(n, 3, |i, j| ((i * 7 + j * 3) % 11) as f64 / 5.0 - 1.0);
        let v = DMatrix::from_fn(n, 4, |i, j| {
            (u[(i, 0)] * (j as f64 + 1.0)).sin() + u[(i, 2)]
        });
        let pw = PairwiseSquares::compute(&u);
        let theta = [0.1, -0.3, 0.4, 0.2, -3.0];
        let (_, g) = compute_nll_and_gradient(&theta, &pw, &v).unwrap();
        for j in 0..theta.len() {
            let h = 1e-5;
            let mut tp = theta;
            tp[j] += h;
            let mut tm = theta;
            tm[j] -= h;
            let fp = compute_nll_and_gradient(&tp, &pw, &v).unwrap().0;
            let fm = compute_nll_and_gradient(&tm, &pw, &v).unwrap().0;
            let fd = (fp - fm) / (2.0 * h);
            assert!(
                (fd - g[j]).abs() < 1e-6 * (1.0 + fd.abs()),
                "param {j}: fd {fd} vs {}",
                g[j]
            );
        }
    }
}
