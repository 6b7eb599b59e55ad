//! Input and output scaling shared by every model.
//!
//! Inputs are z-scored per column: `u_d = (x_d - mean_d) / std_d`.
//! Outputs are centred per ROI element and divided by ONE pooled standard deviation:
//! `v_r = (y_r - mean_r) / s`, with `s^2` the mean over all elements of their variances.
//! A single scale keeps the training loss (mean squared error in normalised units) proportional
//! to the numerator of the Fit score (paper eq. 5), which pools all ROI elements in pascals;
//! a per-element scale would give quiet elements, whose stress hardly changes, the weight of the
//! loud ones. A column whose spread is zero (or not finite) keeps a scale of 1.

use ndarray::ArrayView2;
use serde::{Deserialize, Serialize};

/// Affine map between physical units and the normalised units a model works in.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Scaling {
    /// Per-column offset (physical units).
    pub mean: Vec<f64>,
    /// Per-column scale (physical units); for outputs every entry is the same pooled value.
    pub std: Vec<f64>,
}

impl Scaling {
    /// Per-column z-score of the rows of `a` (inputs).
    pub fn compute_zscore(a: ArrayView2<f64>) -> Scaling {
        let (n, c) = a.dim();
        let mut mean = vec![0.0; c];
        let mut std = vec![1.0; c];
        for j in 0..c {
            let col = a.column(j);
            let m = col.sum() / n.max(1) as f64;
            let v = col.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / n.max(1) as f64;
            mean[j] = m;
            std[j] = guard(v.sqrt());
        }
        Scaling { mean, std }
    }

    /// Per-column centring with one pooled scale (outputs); see the module doc.
    pub fn compute_pooled(a: ArrayView2<f64>) -> Scaling {
        let z = Scaling::compute_zscore(a);
        let c = z.mean.len();
        let (n, _) = a.dim();
        let mut var = 0.0;
        for j in 0..c {
            let m = z.mean[j];
            var += a.column(j).iter().map(|x| (x - m) * (x - m)).sum::<f64>() / n.max(1) as f64;
        }
        let s = guard((var / c.max(1) as f64).sqrt());
        Scaling {
            mean: z.mean,
            std: vec![s; c],
        }
    }

    /// Number of columns.
    pub fn len(&self) -> usize {
        self.mean.len()
    }

    /// True when there are no columns.
    pub fn is_empty(&self) -> bool {
        self.mean.is_empty()
    }

    /// Physical -> normalised, in place on one row.
    #[inline]
    pub fn forward_in_place(&self, row: &mut [f64]) {
        for ((v, m), s) in row.iter_mut().zip(&self.mean).zip(&self.std) {
            *v = (*v - m) / s;
        }
    }

    /// Normalised -> physical, in place on one row.
    #[inline]
    pub fn inverse_in_place(&self, row: &mut [f64]) {
        for ((v, m), s) in row.iter_mut().zip(&self.mean).zip(&self.std) {
            *v = *v * s + m;
        }
    }

    /// Physical -> normalised for every row of `a`.
    pub fn compute_forward(&self, a: ArrayView2<f64>) -> ndarray::Array2<f64> {
        let mut out = a.to_owned();
        for mut row in out.rows_mut() {
            if let Some(r) = row.as_slice_mut() {
                self.forward_in_place(r);
            }
        }
        out
    }
}

fn guard(s: f64) -> f64 {
    if s.is_finite() && s > 1e-12 {
        s
    } else {
        1.0
    }
}
