//! A scene's curves of time (`{ kind = "smooth_step", value = "-1 mm", end = "20 ms" }`,
//! [`CurveSpec`]) and their two translations into a [`Curve`]: a boundary condition's or load's
//! ([`CurveSpec::boundary_curve`]) and an indenter's motion ([`CurveSpec::motion_curve`]).
//!
//! The two give the same function of time in the two families of [`Curve`] (see
//! [`contact::curve`]): a boundary curve may start a smooth step from a value other than 0 and
//! evaluates its ramps as tables, while a motion's curves are the ones a motion file writes.

use contact::Curve;
use material::quantity::Time;
use serde::Deserialize;

/// A curve of a quantity Q over time.
#[derive(Debug, Deserialize, Clone)]
#[serde(deny_unknown_fields, tag = "kind", rename_all = "snake_case")]
pub enum CurveSpec<Q> {
    /// A constant.
    Constant {
        /// Value.
        value: Q,
    },
    /// Quintic smooth step from 0 (or `from`) to `value` between `start` and `end`.
    SmoothStep {
        /// Final value.
        value: Q,
        /// Initial value (default 0).
        from: Option<Q>,
        /// Start time (default 0).
        start: Option<Time>,
        /// End time.
        end: Time,
    },
    /// Linear ramp from 0 to `value` between `start` and `end`, then held.
    Ramp {
        /// Final value.
        value: Q,
        /// Start time (default 0).
        start: Option<Time>,
        /// End time.
        end: Time,
    },
    /// Piecewise linear table.
    Table {
        /// Times.
        time: Vec<Time>,
        /// Values.
        value: Vec<Q>,
    },
}

impl<Q: Copy + Into<f64>> CurveSpec<Q> {
    /// The curve of a boundary condition or a load, with values already in SI through their
    /// typed unit; checked ([`Curve::validate`]).
    pub fn boundary_curve(&self) -> Result<Curve, String> {
        let cv = match self {
            CurveSpec::Constant { value } => Curve::Constant {
                value: (*value).into(),
            },
            CurveSpec::SmoothStep {
                value,
                from,
                start,
                end,
            } => Curve::SmoothStepBetween {
                t0: start.map(|t| t.0).unwrap_or(0.0),
                t1: end.0,
                from: from.map(|f| f.into()).unwrap_or(0.0),
                to: (*value).into(),
            },
            CurveSpec::Ramp { value, start, end } => {
                let t0 = start.map(|t| t.0).unwrap_or(0.0);
                Curve::Polyline(vec![(t0, 0.0), (end.0, (*value).into())])
            }
            CurveSpec::Table { time, value } => {
                check_table(time, value)?;
                Curve::Polyline(
                    time.iter()
                        .zip(value)
                        .map(|(t, v)| (t.0, (*v).into()))
                        .collect(),
                )
            }
        };
        cv.validate()?;
        Ok(cv)
    }

    /// The curve of an indenter's motion (travel or speed), in SI; the indenter checks it when
    /// it is built.
    pub fn motion_curve(&self) -> Result<Curve, String> {
        Ok(match self {
            CurveSpec::Constant { value } => Curve::Constant {
                value: (*value).into(),
            },
            CurveSpec::SmoothStep {
                value,
                from,
                start,
                end,
            } => {
                if from.is_some_and(|f| Into::<f64>::into(f) != 0.0) {
                    return Err("an indenter's smooth_step starts from 0 (drop `from`)".into());
                }
                let t0 = start.map_or(0.0, |t| t.0);
                Curve::SmoothStep {
                    amplitude: (*value).into(),
                    duration: end.0 - t0,
                    start: t0,
                }
            }
            CurveSpec::Ramp { value, start, end } => {
                let t0 = start.map_or(0.0, |t| t.0);
                Curve::Ramp {
                    amplitude: (*value).into(),
                    duration: end.0 - t0,
                    start: t0,
                }
            }
            CurveSpec::Table { time, value } => {
                check_table(time, value)?;
                Curve::Table {
                    points: time
                        .iter()
                        .zip(value)
                        .map(|(t, v)| [t.0, (*v).into()])
                        .collect(),
                }
            }
        })
    }
}

/// A table needs as many values as times.
fn check_table<Q>(time: &[Time], value: &[Q]) -> Result<(), String> {
    if time.len() != value.len() {
        return Err(format!(
            "table has {} times but {} values",
            time.len(),
            value.len()
        ));
    }
    Ok(())
}
