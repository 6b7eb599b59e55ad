//! The live force filter. The training data's force went through a centred moving average of
//! width w (the dataset's `force_filter_s`, 1 ms: the solver's penalty contact chatters):
//! `f_w(t) = mean { f(t_i) : |t_i - t| <= w/2 }`. A live stream cannot look ahead, so it takes
//! the same window trailing,
//!
//! ```text
//! f_w(t) = mean { f(t_i) : t - w < t_i <= t },
//! ```
//!
//! which equals the centred average of the sample w/2 earlier: it filters alike and lags by w/2
//! (0.5 ms for 1 ms). A sensor sampled more slowly than 1/w (a 100 Hz plate, 10 ms apart) has
//! one sample per window, and the filter passes it unchanged, as the training filter would have.

use std::collections::VecDeque;

/// A trailing moving average over a time window.
#[derive(Clone, Debug)]
pub struct TrailingAverage {
    window_s: f64,
    samples: VecDeque<(f64, f64)>,
    sum: f64,
}

impl TrailingAverage {
    /// An average over `window_s` seconds (0 passes each sample through).
    pub fn new(window_s: f64) -> TrailingAverage {
        TrailingAverage {
            window_s: window_s.max(0.0),
            samples: VecDeque::new(),
            sum: 0.0,
        }
    }

    /// The window [s].
    pub fn window(&self) -> f64 {
        self.window_s
    }

    /// Adds the sample `v` at time `t` [s] and returns the mean of the window ending at `t`.
    /// A time before the last one (a restarted stream) starts the window afresh.
    pub fn push(&mut self, t: f64, v: f64) -> f64 {
        if self.samples.back().is_some_and(|&(tl, _)| t < tl) {
            self.clear();
        }
        self.samples.push_back((t, v));
        self.sum += v;
        while let Some(&(t0, v0)) = self.samples.front() {
            if t0 <= t - self.window_s && self.samples.len() > 1 {
                self.samples.pop_front();
                self.sum -= v0;
            } else {
                break;
            }
        }
        // recompute now and then so that rounding does not build up
        if self.samples.len() == 1 {
            self.sum = v;
        }
        self.sum / self.samples.len() as f64
    }

    /// Forgets every sample.
    pub fn clear(&mut self) {
        self.samples.clear();
        self.sum = 0.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a ramp f = 3 t sampled every 0.1 ms, a 0.95 ms trailing average holds the last 10
    /// samples, whose mean is the ramp 0.45 ms back; chatter of +-1 alternating is removed.
    #[test]
    fn ramp_lags_by_half_the_window_and_chatter_goes() {
        let mut f = TrailingAverage::new(0.95e-3);
        let mut last = 0.0;
        for k in 0..100 {
            let t = k as f64 * 1e-4;
            let chatter = if k % 2 == 0 { 1.0 } else { -1.0 };
            last = f.push(t, 3.0 * t + chatter);
        }
        let t = 99.0 * 1e-4;
        assert!((last - 3.0 * (t - 0.45e-3)).abs() < 1e-12, "{last}");
    }

    /// Samples further apart than the window pass unchanged; a restarted clock restarts it.
    #[test]
    fn slow_stream_passes_and_restart() {
        let mut f = TrailingAverage::new(1e-3);
        assert_eq!(f.push(0.00, 5.0), 5.0);
        assert_eq!(f.push(0.01, 7.0), 7.0);
        assert_eq!(f.push(0.0105, 9.0), 8.0);
        assert_eq!(f.push(0.0, 1.0), 1.0);
        let mut pass = TrailingAverage::new(0.0);
        pass.push(0.0, 2.0);
        assert_eq!(
            pass.push(0.0, 4.0),
            4.0,
            "a zero window keeps the newest sample only"
        );
        assert_eq!(pass.push(1e-6, 6.0), 6.0);
    }
}
