//! The trainer's batched MLP: parameters, forward pass and back-propagation over a whole batch
//! with single-precision GEMMs (`matrixmultiply::sgemm`, single-threaded).
//!
//! For a batch `H_0` (N x n_0) and layers `l = 0 .. L-1` with `W_l` (n_l x n_{l+1}):
//!
//! ```text
//! Z_{l+1} = H_l W_l + 1 b_l^T,   H_{l+1} = relu(Z_{l+1})  (identity for the last layer)
//! loss    = 1/(N R) sum (H_L - V)^2                       (mean squared error, normalised units)
//! D_L     = 2/(N R) (H_L - V)
//! dW_l    = H_l^T D_{l+1},   db_l = 1^T D_{l+1}
//! D_l     = (D_{l+1} W_l^T) .* [H_l > 0]
//! ```
//!
//! Why hand-written rather than candle: measured on the project's 2-core machine for the paper's
//! 3-64-126-256-512-377 network and 150 samples, one full-batch epoch (forward, backward, update)
//! took 28 ms with candle 0.9 (2 threads; 52 ms on 1 thread) against 13.5 ms for these GEMMs
//! on 1 thread, and candle-core + candle-nn took 4 min 17 s to compile (release) against 32 s
//! for matrixmultiply. Two single-threaded GEMM loops run side by side each slowed to 27 ms,
//! so the machine's two cores give one core's worth of floating-point throughput here, and the
//! trainer stays single-threaded.

use crate::rng::Rng;
use matrixmultiply::sgemm;

/// Parameters of a dense ReLU network, layers input-major (`W_l` is `n_l x n_{l+1}` row-major).
#[derive(Clone, Debug, PartialEq)]
pub struct MlpParams {
    /// Layer widths `n_0 .. n_L` (inputs, hidden sizes, outputs).
    pub sizes: Vec<usize>,
    /// Weights per layer.
    pub weights: Vec<Vec<f32>>,
    /// Biases per layer.
    pub biases: Vec<Vec<f32>>,
}

impl MlpParams {
    /// He-normal initialisation (`N(0, 2/n_in)`) for the ReLU layers, `N(0, 1/n_in)` for the
    /// linear output layer, zero biases, from `seed`.
    pub fn new_random(sizes: &[usize], seed: u64) -> Self {
        let mut rng = Rng::new(seed);
        let nl = sizes.len() - 1;
        let weights = (0..nl)
            .map(|l| {
                let gain = if l + 1 == nl { 1.0 } else { 2.0 };
                let s = (gain / sizes[l] as f64).sqrt();
                (0..sizes[l] * sizes[l + 1])
                    .map(|_| (rng.normal() * s) as f32)
                    .collect()
            })
            .collect();
        let biases = (0..nl).map(|l| vec![0.0; sizes[l + 1]]).collect();
        MlpParams {
            sizes: sizes.to_vec(),
            weights,
            biases,
        }
    }

    /// Parameters with every value zero (gradient or optimiser-state storage).
    pub fn zeros_like(&self) -> Self {
        MlpParams {
            sizes: self.sizes.clone(),
            weights: self.weights.iter().map(|w| vec![0.0; w.len()]).collect(),
            biases: self.biases.iter().map(|b| vec![0.0; b.len()]).collect(),
        }
    }

    /// Number of layers L.
    pub fn n_layers(&self) -> usize {
        self.weights.len()
    }

    /// Total number of parameters.
    pub fn n_params(&self) -> usize {
        self.weights.iter().map(Vec::len).sum::<usize>()
            + self.biases.iter().map(Vec::len).sum::<usize>()
    }

    /// Every parameter slice, weights then bias of each layer, for element-wise updates.
    pub fn slices_mut(&mut self) -> impl Iterator<Item = &mut [f32]> {
        self.weights
            .iter_mut()
            .zip(self.biases.iter_mut())
            .flat_map(|(w, b)| [w.as_mut_slice(), b.as_mut_slice()])
    }

    /// Every parameter slice, read-only, in the order of [`MlpParams::slices_mut`].
    pub fn slices(&self) -> impl Iterator<Item = &[f32]> {
        self.weights
            .iter()
            .zip(self.biases.iter())
            .flat_map(|(w, b)| [w.as_slice(), b.as_slice()])
    }
}

/// Activation and gradient buffers for one batch size, reused across epochs.
#[derive(Clone, Debug)]
pub struct BatchWorkspace {
    n: usize,
    /// `H_l`, N x n_l, row-major, for l = 0 .. L.
    pub h: Vec<Vec<f32>>,
    d: Vec<Vec<f32>>,
}

impl BatchWorkspace {
    /// Buffers for batches of `n` rows of the network `sizes`.
    pub fn new(sizes: &[usize], n: usize) -> Self {
        BatchWorkspace {
            n,
            h: sizes.iter().map(|&s| vec![0.0; n * s]).collect(),
            d: sizes.iter().map(|&s| vec![0.0; n * s]).collect(),
        }
    }

    /// Batch size.
    pub fn batch_size(&self) -> usize {
        self.n
    }
}

/// `C (m x n) = alpha A (m x k) B (k x n) + beta C` with explicit row/column strides of A and B.
#[allow(clippy::too_many_arguments)]
fn gemm(
    m: usize,
    k: usize,
    n: usize,
    a: &[f32],
    (rsa, csa): (usize, usize),
    b: &[f32],
    (rsb, csb): (usize, usize),
    beta: f32,
    c: &mut [f32],
) {
    // Bounds: the largest index read from A is (m-1)*rsa + (k-1)*csa, and so on.
    if m == 0 || n == 0 {
        return;
    }
    if k > 0 {
        assert!((m - 1) * rsa + (k - 1) * csa < a.len());
        assert!((k - 1) * rsb + (n - 1) * csb < b.len());
    }
    assert!(m * n <= c.len());
    // SAFETY: the asserts above keep every access of sgemm inside the three slices; C is
    // written with row stride n and column stride 1 within its first m*n entries.
    unsafe {
        sgemm(
            m,
            k,
            n,
            1.0,
            a.as_ptr(),
            rsa as isize,
            csa as isize,
            b.as_ptr(),
            rsb as isize,
            csb as isize,
            beta,
            c.as_mut_ptr(),
            n as isize,
            1,
        );
    }
}

/// Forward pass of the batch already copied into `ws.h[0]`; the output lands in `ws.h[L]`.
pub fn forward_batch(p: &MlpParams, ws: &mut BatchWorkspace) {
    let n = ws.n;
    let nl = p.n_layers();
    for l in 0..nl {
        let (n_in, n_out) = (p.sizes[l], p.sizes[l + 1]);
        let (lo, hi) = ws.h.split_at_mut(l + 1);
        let (hin, hout) = (&lo[l], &mut hi[0]);
        for row in hout.chunks_exact_mut(n_out) {
            row.copy_from_slice(&p.biases[l]);
        }
        gemm(
            n,
            n_in,
            n_out,
            hin,
            (n_in, 1),
            &p.weights[l],
            (n_out, 1),
            1.0,
            hout,
        );
        if l + 1 != nl {
            hout.iter_mut().for_each(|v| *v = v.max(0.0));
        }
    }
}

/// Mean squared error of `ws.h[L]` against `target` (N x R row-major, normalised units).
pub fn compute_loss(p: &MlpParams, ws: &BatchWorkspace, target: &[f32]) -> f64 {
    let out = &ws.h[p.n_layers()];
    let s: f64 = out
        .iter()
        .zip(target)
        .map(|(a, b)| {
            let e = (a - b) as f64;
            e * e
        })
        .sum();
    s / out.len() as f64
}

/// Back-propagates the mean squared error against `target` after [`forward_batch`], writing the
/// gradient into `grad`.
pub fn backward_batch(
    p: &MlpParams,
    ws: &mut BatchWorkspace,
    target: &[f32],
    grad: &mut MlpParams,
) {
    let n = ws.n;
    let nl = p.n_layers();
    let scale = 2.0 / (ws.h[nl].len() as f32);
    for ((d, o), t) in ws.d[nl].iter_mut().zip(&ws.h[nl]).zip(target) {
        *d = scale * (o - t);
    }
    for l in (0..nl).rev() {
        let (n_in, n_out) = (p.sizes[l], p.sizes[l + 1]);
        // dW_l = H_l^T D_{l+1}: H_l^T has rows of stride 1 and columns of stride n_in
        gemm(
            n_in,
            n,
            n_out,
            &ws.h[l],
            (1, n_in),
            &ws.d[l + 1],
            (n_out, 1),
            0.0,
            &mut grad.weights[l],
        );
        let gb = &mut grad.biases[l];
        gb.iter_mut().for_each(|v| *v = 0.0);
        for row in ws.d[l + 1].chunks_exact(n_out) {
            for (g, v) in gb.iter_mut().zip(row) {
                *g += v;
            }
        }
        if l > 0 {
            let (lo, hi) = ws.d.split_at_mut(l + 1);
            // D_l = D_{l+1} W_l^T: W_l^T has rows of stride 1 and columns of stride n_out
            gemm(
                n,
                n_out,
                n_in,
                &hi[0],
                (n_out, 1),
                &p.weights[l],
                (1, n_out),
                0.0,
                &mut lo[l],
            );
            for (d, h) in lo[l].iter_mut().zip(&ws.h[l]) {
                if *h <= 0.0 {
                    *d = 0.0;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gradient_matches_finite_differences() {
        let sizes = [3, 5, 4, 2];
        let mut p = MlpParams::new_random(&sizes, 3);
        p.biases[0].iter_mut().for_each(|b| *b = 0.3);
        let n = 4;
        let mut ws = BatchWorkspace::new(&sizes, n);
        let mut rng = Rng::new(1);
        ws.h[0].iter_mut().for_each(|v| *v = rng.normal() as f32);
        let target: Vec<f32> = (0..n * 2).map(|_| rng.normal() as f32).collect();
        let mut g = p.zeros_like();
        forward_batch(&p, &mut ws);
        backward_batch(&p, &mut ws, &target, &mut g);
        for (l, i) in [(0, 2), (1, 7), (2, 3)] {
            let h = 1e-2f32;
            let mut pp = p.clone();
            pp.weights[l][i] += h;
            forward_batch(&pp, &mut ws);
            let fp = compute_loss(&pp, &ws, &target);
            pp.weights[l][i] -= 2.0 * h;
            forward_batch(&pp, &mut ws);
            let fm = compute_loss(&pp, &ws, &target);
            let fd = (fp - fm) / (2.0 * h as f64);
            let an = g.weights[l][i] as f64;
            assert!(
                (fd - an).abs() < 1e-3 * (1.0 + an.abs()),
                "layer {l} w{i}: {fd} vs {an}"
            );
        }
    }
}
