//! The goodness-of-fit score of the reference study (paper eq. 5).
//!
//! ```text
//! Fit = 1 - sqrt( sum_k (y_k - yhat_k)^2 / sum_k (y_k - ybar)^2 )
//! ```
//!
//! The sums run over every scored target: every sample of the scored set and every ROI element.
//! `ybar` is the mean over all those targets (one scalar over all samples and all ROI elements of
//! the scored set), so predicting `ybar` everywhere scores 0 and a perfect prediction scores 1.
//! For the per-location figures the scored set is that location's samples, and `ybar` is that
//! location's own mean; the overall figure pools all test samples (the paper's 92.64 % is such an
//! overall figure over its three test locations A, B, C).
//!
//! Source: the 2022 abdomen-palpation article summarised in `docs/paper.md`.

use ndarray::ArrayView2;

/// Fit of predictions `yhat` against targets `y` (same shape, any number of rows), paper eq. 5.
///
/// Returns NaN when the shapes differ, the set is empty, or every target equals the mean (the
/// score is undefined then).
pub fn compute_fit(y: ArrayView2<f64>, yhat: ArrayView2<f64>) -> f64 {
    if y.dim() != yhat.dim() || y.is_empty() {
        return f64::NAN;
    }
    let ybar = y.iter().sum::<f64>() / y.len() as f64;
    let mut sse = 0.0;
    let mut sst = 0.0;
    for (a, b) in y.iter().zip(yhat.iter()) {
        sse += (a - b) * (a - b);
        sst += (a - ybar) * (a - ybar);
    }
    if sst <= 0.0 {
        return f64::NAN;
    }
    1.0 - (sse / sst).sqrt()
}

/// Fit per location: one `(location, Fit)` pair per distinct value of `location` (ascending),
/// each scored on that location's rows only, with that location's own mean as `ybar`.
pub fn compute_fit_by_location(
    y: ArrayView2<f64>,
    yhat: ArrayView2<f64>,
    location: &[i64],
) -> Vec<(i64, f64)> {
    let mut ids: Vec<i64> = location.to_vec();
    ids.sort_unstable();
    ids.dedup();
    ids.into_iter()
        .map(|id| {
            let rows: Vec<usize> = (0..location.len()).filter(|&i| location[i] == id).collect();
            let ys = y.select(ndarray::Axis(0), &rows);
            let yh = yhat.select(ndarray::Axis(0), &rows);
            (id, compute_fit(ys.view(), yh.view()))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::{array, Array2};

    #[test]
    fn perfect_prediction_scores_one() {
        let y = array![[1.0, -2.0], [3.0, 0.5]];
        assert_eq!(compute_fit(y.view(), y.view()), 1.0);
    }

    #[test]
    fn mean_prediction_scores_zero() {
        let y = array![[1.0, -2.0], [3.0, 0.5]];
        let m = y.mean().unwrap();
        let yhat = Array2::from_elem(y.dim(), m);
        assert!(compute_fit(y.view(), yhat.view()).abs() < 1e-15);
    }

    #[test]
    fn known_value() {
        let y = array![[1.0, 3.0]];
        let yhat = array![[1.5, 2.5]];
        // sse = 0.5, sst = 2 -> 1 - sqrt(0.25) = 0.5
        assert!((compute_fit(y.view(), yhat.view()) - 0.5).abs() < 1e-15);
    }

    #[test]
    fn undefined_cases_are_nan() {
        let y = array![[2.0, 2.0]];
        assert!(compute_fit(y.view(), y.view()).is_nan());
        let z = array![[2.0]];
        assert!(compute_fit(y.view(), z.view()).is_nan());
    }

    #[test]
    fn per_location_uses_each_locations_rows() {
        let y = array![[1.0, 3.0], [0.0, 10.0]];
        let yhat = array![[1.5, 2.5], [0.0, 10.0]];
        let f = compute_fit_by_location(y.view(), yhat.view(), &[7, 2]);
        assert_eq!(f[0].0, 2);
        assert_eq!(f[0].1, 1.0);
        assert_eq!(f[1].0, 7);
        assert!((f[1].1 - 0.5).abs() < 1e-15);
    }
}
