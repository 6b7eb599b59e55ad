//! Allocation-free GP prediction over a fitted model.
//!
//! ```text
//! k*_i  = s2 exp(-1/2 sum_d ((u_d - u_i,d) / l_d)^2)        i = 1..n
//! mean  = mu_y + s_y * (A^T k*)                              A = K^-1 V, n x M
//!       = mu_y + s_y * (B^T (C^T k*))                        with an output basis (`train`):
//!                                                            C = A W_r, n x r; B = W_r^T, r x M
//! ```
//!
//! The basis product `B^T z` is the largest (r M multiply-adds: 36 x 2262 for the default
//! campaign's tensor target) and runs in f32, like the MLP's layers: half the memory traffic,
//! twice the lanes, and a relative error of about 1e-7 of the field, far below the model's.
//!
//! ```text
//! var   = s_y^2 * (s2 - k*^T K^-1 k*)                        latent (noise-free) variance
//! ```
//!
//! The variance is the same for every ROI element: the kernel and the output scale `s_y` are
//! shared by all outputs (see `normalise`). Units: mean in Pa, variance in Pa^2.
//! Source: Rasmussen and Williams 2006, eqs. (2.25)-(2.26).

use super::kernel::SeArd;
use crate::kernels::accumulate_rows;
use crate::normalise::Scaling;

/// Reusable GP evaluator: owns its buffers, so [`GpPredictor::predict`] never allocates.
#[derive(Clone, Debug)]
pub struct GpPredictor {
    kernel: SeArd,
    input_scaling: Scaling,
    output_scaling: Scaling,
    /// Training inputs divided by the length scales, n x D row-major.
    scaled_train: Vec<f64>,
    /// `K^-1 V` (n x M) or, with a basis, `K^-1 V W_r` (n x r), row-major.
    coef: Vec<f64>,
    /// Output basis `W_r^T`, r x M row-major, in f32; empty without one.
    basis: Vec<f32>,
    /// `K^-1`, n x n row-major.
    k_inv: Vec<f64>,
    u: Vec<f64>,
    k: Vec<f64>,
    t: Vec<f64>,
    z: Vec<f64>,
    z32: Vec<f32>,
    out32: Vec<f32>,
    out: Vec<f64>,
}

impl GpPredictor {
    /// Builds an evaluator. `train_inputs` is n x D normalised, `coef` n x M (no basis) or
    /// n x r (with `basis` r x M), `k_inv` n x n, all row-major; `basis` empty for none.
    pub fn new(
        kernel: SeArd,
        input_scaling: Scaling,
        output_scaling: Scaling,
        train_inputs: &[f64],
        coef: Vec<f64>,
        basis: Vec<f64>,
        k_inv: Vec<f64>,
    ) -> Self {
        let d = kernel.length_scales.len();
        let n = train_inputs.len() / d.max(1);
        let r = output_scaling.len();
        let rank = if basis.is_empty() {
            0
        } else {
            basis.len() / r.max(1)
        };
        let scaled_train = kernel.compute_scaled_points(train_inputs);
        GpPredictor {
            kernel,
            input_scaling,
            output_scaling,
            scaled_train,
            coef,
            basis: basis.iter().map(|&b| b as f32).collect(),
            k_inv,
            u: vec![0.0; d],
            k: vec![0.0; n],
            t: vec![0.0; n],
            z: vec![0.0; rank],
            z32: vec![0.0; rank],
            out32: vec![0.0; if rank > 0 { r } else { 0 }],
            out: vec![0.0; r],
        }
    }

    /// Number of raw outputs M (R, or 6R on the tensor target).
    pub fn n_outputs(&self) -> usize {
        self.out.len()
    }

    /// Number of inputs D.
    pub fn n_inputs(&self) -> usize {
        self.u.len()
    }

    /// Predictive mean [Pa] at physical inputs `inputs` (length D: x [m], y [m], force [N]).
    pub fn predict_inputs(&mut self, inputs: &[f64]) -> &[f64] {
        let d = self.u.len();
        self.u.copy_from_slice(&inputs[..d]);
        self.input_scaling.forward_in_place(&mut self.u);
        for (u, l) in self.u.iter_mut().zip(&self.kernel.length_scales) {
            *u /= l;
        }
        for (ki, xi) in self.k.iter_mut().zip(self.scaled_train.chunks_exact(d)) {
            *ki = self.kernel.compute_scaled(&self.u, xi);
        }
        self.out.iter_mut().for_each(|o| *o = 0.0);
        if self.basis.is_empty() {
            accumulate_rows(&self.k, &self.coef, &mut self.out);
        } else {
            self.z.iter_mut().for_each(|z| *z = 0.0);
            accumulate_rows(&self.k, &self.coef, &mut self.z);
            for (a, &b) in self.z32.iter_mut().zip(&self.z) {
                *a = b as f32;
            }
            self.out32.iter_mut().for_each(|o| *o = 0.0);
            accumulate_rows(&self.z32, &self.basis, &mut self.out32);
            for (o, &v) in self.out.iter_mut().zip(&self.out32) {
                *o = f64::from(v);
            }
        }
        self.output_scaling.inverse_in_place(&mut self.out);
        &self.out
    }

    /// The kernel's length scales in physical input units (m, m, N): the normalised length
    /// scale times the input's standard deviation.
    pub fn physical_length_scales(&self) -> Vec<f64> {
        self.kernel
            .length_scales
            .iter()
            .zip(&self.input_scaling.std)
            .map(|(l, s)| l * s)
            .collect()
    }

    /// The noise variance [Pa^2] of an observed output (`sn2 s_y^2`): add it to the latent
    /// variance for the predictive variance of a value the solver would give.
    pub fn noise_variance(&self) -> f64 {
        let s_y = self.output_scaling.std.first().copied().unwrap_or(1.0);
        self.kernel.noise_variance * s_y * s_y
    }

    /// Predictive mean [Pa] and latent variance [Pa^2] (shared by all outputs) at `inputs`.
    pub fn predict_with_variance(&mut self, inputs: &[f64]) -> (&[f64], f64) {
        self.predict_inputs(inputs);
        // t = K^-1 k* as a sum of rows (K^-1 is symmetric): contiguous, vectorisable updates
        self.t.iter_mut().for_each(|t| *t = 0.0);
        accumulate_rows(&self.k, &self.k_inv, &mut self.t);
        let quad: f64 = self.k.iter().zip(&self.t).map(|(a, b)| a * b).sum();
        let s_y = self.output_scaling.std.first().copied().unwrap_or(1.0);
        let var = (self.kernel.signal_variance - quad).max(0.0) * s_y * s_y;
        (&self.out, var)
    }
}
