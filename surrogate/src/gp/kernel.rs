//! The one kernel of the Gaussian process: squared exponential with automatic relevance
//! determination (one length scale per input), signal variance and white noise.
//!
//! ```text
//! k(a, b) = s2 * exp( -1/2 * sum_d (a_d - b_d)^2 / l_d^2 )   (+ sn2 if a is b)
//! ```
//!
//! Hyperparameters are handled as logarithms, `theta = [ln l_1 .. ln l_D, ln s2, ln sn2]`, so
//! that an unconstrained optimiser keeps them positive. Derivatives of the Gram matrix K:
//!
//! ```text
//! dK/d ln l_d = K_se .* (a_d - b_d)^2 / l_d^2
//! dK/d ln s2  = K_se
//! dK/d ln sn2 = sn2 * I
//! ```
//!
//! Source: C. E. Rasmussen and C. K. I. Williams, *Gaussian Processes for Machine Learning*,
//! MIT Press 2006, eqs. (5.1) and (5.9).

use serde::{Deserialize, Serialize};

/// Jitter added to the diagonal of every Gram matrix for numerical safety (normalised units).
pub const JITTER: f64 = 1e-8;

/// Hyperparameters of the squared-exponential ARD kernel, in normalised units.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SeArd {
    /// Length scale per input dimension.
    pub length_scales: Vec<f64>,
    /// Signal variance s2.
    pub signal_variance: f64,
    /// Noise variance sn2.
    pub noise_variance: f64,
}

impl SeArd {
    /// From log-parameters `[ln l_1 .. ln l_D, ln s2, ln sn2]`.
    pub fn from_log_params(theta: &[f64]) -> SeArd {
        let d = theta.len() - 2;
        SeArd {
            length_scales: theta[..d].iter().map(|t| t.exp()).collect(),
            signal_variance: theta[d].exp(),
            noise_variance: theta[d + 1].exp(),
        }
    }

    /// Correlation part `exp(-1/2 sum_d ((a_d - b_d)/l_d)^2)` for points already divided by the
    /// length scales (`a_s = a / l`), times the signal variance.
    #[inline]
    pub fn compute_scaled(&self, a_scaled: &[f64], b_scaled: &[f64]) -> f64 {
        let mut r2 = 0.0;
        for (p, q) in a_scaled.iter().zip(b_scaled) {
            r2 += (p - q) * (p - q);
        }
        self.signal_variance * (-0.5 * r2).exp()
    }

    /// Divides each point (row of `points`, `d` columns, row-major) by the length scales.
    pub fn compute_scaled_points(&self, points: &[f64]) -> Vec<f64> {
        let d = self.length_scales.len();
        points
            .chunks_exact(d)
            .flat_map(|p| p.iter().zip(&self.length_scales).map(|(v, l)| v / l))
            .collect()
    }
}
