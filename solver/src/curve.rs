//! Load curves: piecewise linear tables, smooth steps and constants.
//!
//! Smooth step (LS-DYNA / Abaqus "smooth step" amplitude): between (t0, a0) and (t1, a1),
//!   a(t) = a0 + (a1 - a0) xi^3 (10 - 15 xi + 6 xi^2),  xi = (t - t0)/(t1 - t0),
//! which has zero first and second derivatives at both ends, so a prescribed displacement
//! starts and stops without a velocity jump. Its time derivative is
//!   a'(t) = (a1 - a0) 30 xi^2 (1 - xi)^2 / (t1 - t0).

/// A scalar function of time.
#[derive(Clone, Debug, PartialEq)]
pub enum Curve {
    /// A constant.
    Constant(f64),
    /// Linear interpolation in a table of (time s, value); held constant outside.
    Table(Vec<(f64, f64)>),
    /// From `from` at `t0` to `to` at `t1` with the quintic smooth step; constant outside.
    SmoothStep {
        /// Start time (s).
        t0: f64,
        /// End time (s).
        t1: f64,
        /// Value before t0.
        from: f64,
        /// Value after t1.
        to: f64,
    },
}

impl Curve {
    /// Value at time t.
    pub fn value(&self, t: f64) -> f64 {
        match self {
            Curve::Constant(c) => *c,
            Curve::Table(pts) => {
                if pts.is_empty() {
                    return 0.0;
                }
                if t <= pts[0].0 {
                    return pts[0].1;
                }
                for w in pts.windows(2) {
                    let (t0, v0) = w[0];
                    let (t1, v1) = w[1];
                    if t <= t1 {
                        return if t1 > t0 {
                            v0 + (v1 - v0) * (t - t0) / (t1 - t0)
                        } else {
                            v1
                        };
                    }
                }
                pts[pts.len() - 1].1
            }
            Curve::SmoothStep { t0, t1, from, to } => {
                if t <= *t0 {
                    *from
                } else if t >= *t1 {
                    *to
                } else {
                    let xi = (t - t0) / (t1 - t0);
                    from + (to - from) * xi * xi * xi * (10.0 - 15.0 * xi + 6.0 * xi * xi)
                }
            }
        }
    }

    /// Time derivative at time t.
    pub fn rate(&self, t: f64) -> f64 {
        match self {
            Curve::Constant(_) => 0.0,
            Curve::Table(pts) => {
                for w in pts.windows(2) {
                    let (t0, v0) = w[0];
                    let (t1, v1) = w[1];
                    if t >= t0 && t < t1 && t1 > t0 {
                        return (v1 - v0) / (t1 - t0);
                    }
                }
                0.0
            }
            Curve::SmoothStep { t0, t1, from, to } => {
                if t <= *t0 || t >= *t1 {
                    0.0
                } else {
                    let xi = (t - t0) / (t1 - t0);
                    (to - from) * 30.0 * xi * xi * (1.0 - xi) * (1.0 - xi) / (t1 - t0)
                }
            }
        }
    }

    /// Check a table is sorted in time.
    pub fn validate(&self) -> Result<(), String> {
        if let Curve::Table(p) = self {
            if p.is_empty() {
                return Err("a curve table needs at least one point".into());
            }
            if p.windows(2).any(|w| w[1].0 < w[0].0) {
                return Err("curve times must be non-decreasing".into());
            }
        }
        if let Curve::SmoothStep { t0, t1, .. } = self {
            if !(t1 > t0) {
                return Err("smooth step needs t1 > t0".into());
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smooth_step_ends_and_rate() {
        let c = Curve::SmoothStep {
            t0: 0.0,
            t1: 2.0,
            from: 0.0,
            to: 3.0,
        };
        assert_eq!(c.value(-1.0), 0.0);
        assert_eq!(c.value(2.5), 3.0);
        assert!((c.value(1.0) - 1.5).abs() < 1e-15);
        let h = 1e-6;
        let fd = (c.value(0.7 + h) - c.value(0.7 - h)) / (2.0 * h);
        assert!((fd - c.rate(0.7)).abs() < 1e-8);
    }

    #[test]
    fn table_interpolates() {
        let c = Curve::Table(vec![(0.0, 0.0), (1.0, 2.0), (2.0, 2.0)]);
        assert_eq!(c.value(0.5), 1.0);
        assert_eq!(c.value(5.0), 2.0);
        assert_eq!(c.rate(0.5), 2.0);
    }
}
