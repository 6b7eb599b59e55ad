//! The recovered stress target: each ROI element's maximum principal stress averaged over its
//! neighbours within a stated physical width, as a smoother alternative to the element stress
//! (the paper's target, which stays the default).
//!
//! ```text
//! y'_i = sum_j w_ij y_j,    w_ij = exp(-|c_i - c_j|^2 / h^2) / sum_k exp(-|c_i - c_k|^2 / h^2)
//! ```
//!
//! over the ROI's elements j (centroids c, width h in m): Gaussian smoothing of the element
//! values (a kernel average, Nadaraya 1964 and Watson 1964; not a Zienkiewicz-Zhu patch
//! recovery), with standard deviation h / sqrt 2 and the kernel of
//! `surrogate/scripts/mesh_compare.py --smooth h`, so that script's mesh-convergence figures are
//! this target's (docs/surrogate.md). Element stresses are piecewise constant and jump from
//! element to element with the voxel steps of the liver surface; at h = 3-5 mm the field is an
//! average over a few elements, the scale of a finger's pad. The weights are normalised over
//! the ROI, so an element near its edge averages over the ROI side only.
//!
//! A dataset's recovered form ([`Dataset::recovered`]) replaces `Y` by `Y W^T` and drops the
//! stress tensors, so a model learns and is scored on the recovered principal stress.

use crate::dataset::Dataset;
use crate::error::{Error, Result};
use ndarray::{Array2, ArrayView2};

/// The R x R weights `w_ij` of the module doc for centroids `c` (R x 3, m) and width `h` (m).
pub fn gaussian_weights(c: ArrayView2<f64>, h: f64) -> Array2<f64> {
    let r = c.nrows();
    let mut w = Array2::from_shape_fn((r, r), |(i, j)| {
        let d2: f64 = (0..c.ncols())
            .map(|k| (c[(i, k)] - c[(j, k)]).powi(2))
            .sum();
        (-d2 / (h * h)).exp()
    });
    for mut row in w.rows_mut() {
        let s = row.sum();
        row.mapv_inplace(|v| v / s);
    }
    w
}

impl Dataset {
    /// The dataset with the recovered target of width `h` (m; module doc) in place of `Y`, and
    /// no stress tensors.
    pub fn recovered(&self, h: f64) -> Result<Dataset> {
        if !(h > 0.0 && h.is_finite()) {
            return Err(Error::invalid(
                "recovery width",
                format!("{h} m is not a positive length"),
            ));
        }
        let w = gaussian_weights(self.roi_centroids.view(), h);
        Ok(Dataset {
            y: self.y.dot(&w.t()),
            stress: None,
            ..self.clone()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::array;

    /// Rows sum to one; a width far below the spacing leaves the field as it is, one far above
    /// it gives every element the mean.
    #[test]
    fn weights_average() {
        let c = array![[0.0, 0.0, 0.0], [0.003, 0.0, 0.0], [0.006, 0.0, 0.0]];
        let w = gaussian_weights(c.view(), 0.003);
        for row in w.rows() {
            assert!((row.sum() - 1.0).abs() < 1e-14);
        }
        let y = array![1.0, 2.0, 6.0];
        let narrow = gaussian_weights(c.view(), 1e-5).dot(&y);
        assert!((&narrow - &y).iter().all(|d| d.abs() < 1e-12), "{narrow}");
        let wide = gaussian_weights(c.view(), 10.0).dot(&y);
        assert!(wide.iter().all(|v| (v - 3.0).abs() < 1e-6), "{wide}");
        // symmetric neighbours: the middle element gets (e^-1 (1 + 6) + 2) / (2 e^-1 + 1)
        let e = (-1.0f64).exp();
        let mid = (e * 7.0 + 2.0) / (2.0 * e + 1.0);
        assert!((w.dot(&y)[1] - mid).abs() < 1e-12);
    }
}
