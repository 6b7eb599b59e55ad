//! Curves: a scalar of time, for an indenter's travel or speed ([`crate::motion`]) and for the
//! solver's boundary conditions and loads (one type for both).
//!
//! Smooth step: the quintic `S(r) = 10 r^3 - 15 r^4 + 6 r^5` (`S(0) = 0`, `S(1) = 1`, zero
//! first and second derivatives at both ends, so a prescribed motion starts and stops without
//! a velocity jump), `S'(r) = 30 r^2 (1 - r)^2`.
//!
//! The variants come in two families, written the way each user states its curve, and each
//! evaluates with its own arithmetic (kept from the two curve types this one replaced, so
//! that results are bitwise what they were; the two agree to round-off):
//! - a motion's curves, which a motion file or a `$palpa: motion` comment writes
//!   (`curve = "smooth_step"`, `"ramp"`, `"table"`, `"constant"`): [`Curve::SmoothStep`] and
//!   [`Curve::Ramp`] from 0 to an amplitude, [`Curve::Table`] with strictly increasing times,
//!   [`Curve::Constant`];
//! - the boundary conditions' curves, built from a scene's curves by the solver:
//!   [`Curve::SmoothStepBetween`] from one value to another, [`Curve::Polyline`] whose times
//!   may repeat (a jump), and [`Curve::Constant`].

use serde::Deserialize;

/// A scalar function of time (value unit set by its use: m, m/s, N).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(tag = "curve", rename_all = "snake_case", deny_unknown_fields)]
pub enum Curve {
    /// Quintic smooth step from 0 to `amplitude` over `[start, start + duration]`, then held.
    SmoothStep {
        /// Final value.
        amplitude: f64,
        /// Duration of the transition (s).
        duration: f64,
        /// Start time (s). Default 0.
        #[serde(default)]
        start: f64,
    },
    /// Linear ramp from 0 to `amplitude` over `[start, start + duration]`, then held.
    Ramp {
        /// Final value.
        amplitude: f64,
        /// Duration of the ramp (s).
        duration: f64,
        /// Start time (s). Default 0.
        #[serde(default)]
        start: f64,
    },
    /// Piecewise linear through `[t (s), value]` points (sorted by time), held outside.
    Table {
        /// `[time (s), value]` pairs, increasing in time.
        points: Vec<[f64; 2]>,
    },
    /// A constant value.
    Constant {
        /// The value.
        value: f64,
    },
    /// From `from` at `t0` to `to` at `t1` with the quintic smooth step; constant outside.
    #[serde(skip)]
    SmoothStepBetween {
        /// Start time (s).
        t0: f64,
        /// End time (s).
        t1: f64,
        /// Value before t0.
        from: f64,
        /// Value after t1.
        to: f64,
    },
    /// Linear interpolation in a table of (time s, value), times non-decreasing (a repeated
    /// time is a jump); held constant outside.
    #[serde(skip)]
    Polyline(Vec<(f64, f64)>),
}

impl Curve {
    /// Value at time `t` (s).
    pub fn value(&self, t: f64) -> f64 {
        match self {
            Curve::SmoothStep {
                amplitude,
                duration,
                start,
            } => {
                let r = ((t - start) / duration).clamp(0.0, 1.0);
                amplitude * r * r * r * (10.0 + r * (-15.0 + 6.0 * r))
            }
            Curve::Ramp {
                amplitude,
                duration,
                start,
            } => amplitude * ((t - start) / duration).clamp(0.0, 1.0),
            Curve::Table { points } => table(points, t).0,
            Curve::Constant { value } => *value,
            Curve::SmoothStepBetween { t0, t1, from, to } => {
                if t <= *t0 {
                    *from
                } else if t >= *t1 {
                    *to
                } else {
                    let xi = (t - t0) / (t1 - t0);
                    from + (to - from) * xi * xi * xi * (10.0 - 15.0 * xi + 6.0 * xi * xi)
                }
            }
            Curve::Polyline(pts) => {
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
        }
    }

    /// Time derivative at `t` (unit of the value per s).
    pub fn rate(&self, t: f64) -> f64 {
        match self {
            Curve::SmoothStep {
                amplitude,
                duration,
                start,
            } => {
                let r = (t - start) / duration;
                if !(0.0..=1.0).contains(&r) {
                    return 0.0;
                }
                amplitude / duration * 30.0 * r * r * (1.0 - r) * (1.0 - r)
            }
            Curve::Ramp {
                amplitude,
                duration,
                start,
            } => {
                if t >= *start && t <= start + duration {
                    amplitude / duration
                } else {
                    0.0
                }
            }
            Curve::Table { points } => table(points, t).1,
            Curve::Constant { .. } => 0.0,
            Curve::SmoothStepBetween { t0, t1, from, to } => {
                if t <= *t0 || t >= *t1 {
                    0.0
                } else {
                    let xi = (t - t0) / (t1 - t0);
                    (to - from) * 30.0 * xi * xi * (1.0 - xi) * (1.0 - xi) / (t1 - t0)
                }
            }
            Curve::Polyline(pts) => {
                for w in pts.windows(2) {
                    let (t0, v0) = w[0];
                    let (t1, v1) = w[1];
                    if t >= t0 && t < t1 && t1 > t0 {
                        return (v1 - v0) / (t1 - t0);
                    }
                }
                0.0
            }
        }
    }

    /// Check the curve's shape: a positive duration and a finite amplitude and start, tables
    /// with at least one point, their times increasing (strictly for [`Curve::Table`]), and
    /// `t1 > t0` for [`Curve::SmoothStepBetween`]. A constant is not checked here (a motion
    /// checks that its constant is finite, [`crate::MotionSpec`]).
    pub fn validate(&self) -> Result<(), String> {
        match self {
            Curve::SmoothStep {
                duration,
                amplitude,
                start,
            }
            | Curve::Ramp {
                duration,
                amplitude,
                start,
            } => {
                if !(*duration > 0.0) || !amplitude.is_finite() || !start.is_finite() {
                    return Err("curve needs a positive duration and finite amplitude".into());
                }
            }
            Curve::Table { points } => {
                if points.is_empty() {
                    return Err("table curve has no points".into());
                }
                if points.windows(2).any(|w| !(w[1][0] > w[0][0])) {
                    return Err("table curve times must increase strictly".into());
                }
            }
            Curve::Constant { .. } => {}
            Curve::SmoothStepBetween { t0, t1, .. } => {
                if !(t1 > t0) {
                    return Err("smooth step needs t1 > t0".into());
                }
            }
            Curve::Polyline(p) => {
                if p.is_empty() {
                    return Err("a curve table needs at least one point".into());
                }
                if p.windows(2).any(|w| w[1].0 < w[0].0) {
                    return Err("curve times must be non-decreasing".into());
                }
            }
        }
        Ok(())
    }

    /// The curve times `s`: the values scaled, the times kept.
    pub fn scaled(&self, s: f64) -> Curve {
        match self {
            Curve::SmoothStep {
                amplitude,
                duration,
                start,
            } => Curve::SmoothStep {
                amplitude: amplitude * s,
                duration: *duration,
                start: *start,
            },
            Curve::Ramp {
                amplitude,
                duration,
                start,
            } => Curve::Ramp {
                amplitude: amplitude * s,
                duration: *duration,
                start: *start,
            },
            Curve::Table { points } => Curve::Table {
                points: points.iter().map(|&[t, v]| [t, v * s]).collect(),
            },
            Curve::Constant { value } => Curve::Constant { value: value * s },
            Curve::SmoothStepBetween { t0, t1, from, to } => Curve::SmoothStepBetween {
                t0: *t0,
                t1: *t1,
                from: from * s,
                to: to * s,
            },
            Curve::Polyline(p) => Curve::Polyline(p.iter().map(|&(t, v)| (t, v * s)).collect()),
        }
    }
}

/// Value and slope of a [`Curve::Table`] at `t` (binary search for the segment).
fn table(points: &[[f64; 2]], t: f64) -> (f64, f64) {
    let n = points.len();
    if t <= points[0][0] {
        return (points[0][1], 0.0);
    }
    if t >= points[n - 1][0] {
        return (points[n - 1][1], 0.0);
    }
    // Binary search for the segment.
    let i = points.partition_point(|p| p[0] <= t) - 1;
    let (a, b) = (points[i], points[i + 1]);
    let slope = (b[1] - a[1]) / (b[0] - a[0]);
    (a[1] + slope * (t - a[0]), slope)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smooth_step_between_ends_and_rate() {
        let c = Curve::SmoothStepBetween {
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
    fn polyline_interpolates() {
        let c = Curve::Polyline(vec![(0.0, 0.0), (1.0, 2.0), (2.0, 2.0)]);
        assert_eq!(c.value(0.5), 1.0);
        assert_eq!(c.value(5.0), 2.0);
        assert_eq!(c.rate(0.5), 2.0);
    }

    /// The two families describe the same functions: they agree to round-off.
    #[test]
    fn the_two_families_agree() {
        let a = Curve::SmoothStep {
            amplitude: 3.0,
            duration: 2.0,
            start: 0.5,
        };
        let b = Curve::SmoothStepBetween {
            t0: 0.5,
            t1: 2.5,
            from: 0.0,
            to: 3.0,
        };
        let r = Curve::Ramp {
            amplitude: 3.0,
            duration: 2.0,
            start: 0.5,
        };
        let p = Curve::Polyline(vec![(0.5, 0.0), (2.5, 3.0)]);
        let t = Curve::Table {
            points: vec![[0.5, 0.0], [2.5, 3.0]],
        };
        for k in 0..=60 {
            let x = 0.05 * k as f64;
            assert!((a.value(x) - b.value(x)).abs() < 1e-14, "t = {x}");
            assert!((a.rate(x) - b.rate(x)).abs() < 1e-13, "t = {x}");
            assert!((r.value(x) - p.value(x)).abs() < 1e-14, "t = {x}");
            assert!((t.value(x) - p.value(x)).abs() < 1e-14, "t = {x}");
        }
    }

    #[test]
    fn scaled_scales_values_not_times() {
        let c = Curve::SmoothStepBetween {
            t0: 0.0,
            t1: 1.0,
            from: 1.0,
            to: 2.0,
        }
        .scaled(-2.0);
        assert_eq!(c.value(0.0), -2.0);
        assert_eq!(c.value(1.0), -4.0);
        let t = Curve::Table {
            points: vec![[0.0, 1.0], [1.0, 3.0]],
        }
        .scaled(0.5);
        assert_eq!(t.value(1.0), 1.5);
    }
}
