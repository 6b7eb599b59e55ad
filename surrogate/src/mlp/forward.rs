//! The hand-written MLP forward pass used for serving: no training framework at run time.
//!
//! ```text
//! h_0 = (input - mu_x) / s_x
//! h_l = relu(W_l^T h_{l-1} + b_l)      l = 1 .. L-1
//! out = mu_y + s_y * (W_L^T h_{L-1} + b_L)
//! ```
//!
//! Each `W_l` is stored input-major (`n_in x n_out`, row-major, f32), so a layer is a sum of
//! contiguous rows scaled by the previous activations: the inner loop is a vectorisable
//! `axpy`, and the rows of inputs that ReLU zeroed are skipped. A prediction touches only the
//! buffers the predictor owns: no allocation.

use crate::kernels::accumulate_rows;
use crate::normalise::Scaling;

/// One dense layer, input-major.
#[derive(Clone, Debug, PartialEq)]
pub struct DenseLayer {
    /// Number of inputs.
    pub n_in: usize,
    /// Number of outputs.
    pub n_out: usize,
    /// Weights, `n_in x n_out` row-major.
    pub weight: Vec<f32>,
    /// Biases, `n_out`.
    pub bias: Vec<f32>,
}

/// Reusable MLP evaluator.
#[derive(Clone, Debug)]
pub struct MlpPredictor {
    layers: Vec<DenseLayer>,
    input_scaling: Scaling,
    output_scaling: Scaling,
    a: Vec<f32>,
    b: Vec<f32>,
    out: Vec<f64>,
}

impl MlpPredictor {
    /// Builds an evaluator over `layers` (ReLU after each but the last).
    pub fn new(layers: Vec<DenseLayer>, input_scaling: Scaling, output_scaling: Scaling) -> Self {
        let width = layers
            .iter()
            .map(|l| l.n_in.max(l.n_out))
            .max()
            .unwrap_or(0);
        let r = layers.last().map_or(0, |l| l.n_out);
        MlpPredictor {
            layers,
            input_scaling,
            output_scaling,
            a: vec![0.0; width],
            b: vec![0.0; width],
            out: vec![0.0; r],
        }
    }

    /// The layers.
    pub fn layers(&self) -> &[DenseLayer] {
        &self.layers
    }

    /// Number of inputs.
    pub fn n_inputs(&self) -> usize {
        self.layers.first().map_or(0, |l| l.n_in)
    }

    /// Number of outputs R.
    pub fn n_outputs(&self) -> usize {
        self.out.len()
    }

    /// ROI stress [Pa] at physical inputs (x [m], y [m], force [N], ...).
    pub fn predict_inputs(&mut self, inputs: &[f64]) -> &[f64] {
        let n0 = self.n_inputs();
        for j in 0..n0 {
            let m = self.input_scaling.mean[j];
            let s = self.input_scaling.std[j];
            self.a[j] = ((inputs[j] - m) / s) as f32;
        }
        let last = self.layers.len().saturating_sub(1);
        for (li, layer) in self.layers.iter().enumerate() {
            let out = &mut self.b[..layer.n_out];
            out.copy_from_slice(&layer.bias);
            accumulate_rows(&self.a[..layer.n_in], &layer.weight, out);
            if li != last {
                out.iter_mut().for_each(|v| *v = v.max(0.0));
            }
            std::mem::swap(&mut self.a, &mut self.b);
        }
        for (j, o) in self.out.iter_mut().enumerate() {
            *o = self.a[j] as f64 * self.output_scaling.std[j] + self.output_scaling.mean[j];
        }
        &self.out
    }
}
