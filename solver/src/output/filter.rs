//! Filtering of force histories.
//!
//! The penalty contact of a coarse phantom chatters. On the quick profile the hand force swings
//! between 1 and 65 N from one 12 us history sample to the next, while the ROI stress stays
//! smooth. Crash analysts filter contact forces the same way before they use them: SAE J211
//! channel filtering of LS-DYNA's RCFORC output. palpa uses a centred moving average of width
//! [`FORCE_FILTER`]:
//!
//! ```text
//! f_w(t) = mean { f(t_i) : |t_i - t| <= w/2 }
//! ```
//!
//! Near the ends of the history the window is cut to the samples that exist. The filter is
//! used in two places. The study compares force-indentation curves with it. The campaign's
//! dataset uses it for the force input of the surrogate, sampled at the sample times from the
//! run's full `history.csv`.

use contact::Curve;

/// Width of the centred moving average applied to hand-force histories (s).
pub const FORCE_FILTER: f64 = 1e-3;

/// Centred moving average of the samples (t, f) over `width`, at every sample time.
pub fn moving_average(t: &[f64], f: &[f64], width: f64) -> Vec<f64> {
    let (mut lo, mut hi, mut sum) = (0usize, 0usize, 0.0);
    t.iter()
        .map(|&x| {
            while hi < t.len() && t[hi] <= x + 0.5 * width {
                sum += f[hi];
                hi += 1;
            }
            while t[lo] < x - 0.5 * width {
                sum -= f[lo];
                lo += 1;
            }
            sum / (hi - lo) as f64
        })
        .collect()
}

/// The centred moving average of (t, f) over `width`, linearly interpolated at `at`.
pub fn moving_average_at(t: &[f64], f: &[f64], width: f64, at: &[f64]) -> Vec<f64> {
    let smooth = Curve::Polyline(t.iter().copied().zip(moving_average(t, f, width)).collect());
    at.iter().map(|&x| smooth.value(x)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn moving_average_keeps_a_ramp_and_removes_chatter() {
        let t: Vec<f64> = (0..1001).map(|i| i as f64 * 1e-5).collect();
        // A ramp is reproduced in the interior (a centred average of a linear function; the
        // width falls between samples so that 50 lie on each side).
        let ramp: Vec<f64> = t.iter().map(|&x| 3.0 * x).collect();
        let m = moving_average(&t, &ramp, 1.005e-3);
        for i in 60..940 {
            assert!((m[i] - ramp[i]).abs() < 1e-12, "{} vs {}", m[i], ramp[i]);
        }
        // Sample-to-sample chatter of +-1 around 2 averages out to within 1/101.
        let chat: Vec<f64> = (0..t.len())
            .map(|i| 2.0 + if i % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let m = moving_average(&t, &chat, 1.005e-3);
        for v in &m[60..940] {
            assert!((v - 2.0).abs() <= 1.0 / 101.0 + 1e-12, "{v}");
        }
    }

    #[test]
    fn sampled_between_history_rows_by_linear_interpolation() {
        let t: Vec<f64> = (0..1001).map(|i| i as f64 * 1e-5).collect();
        let ramp: Vec<f64> = t.iter().map(|&x| 3.0 * x).collect();
        let at = [2.345e-3, 5.0e-3];
        let m = moving_average_at(&t, &ramp, 1.005e-3, &at);
        for (v, x) in m.iter().zip(at) {
            assert!((v - 3.0 * x).abs() < 1e-12, "{v} vs {}", 3.0 * x);
        }
        // the window is cut at the ends: at t = 0 it holds the first 51 samples, mean 3 * 25e-5
        let m0 = moving_average_at(&t, &ramp, 1.005e-3, &[0.0]);
        assert!((m0[0] - 3.0 * 25e-5).abs() < 1e-12, "{}", m0[0]);
    }
}
