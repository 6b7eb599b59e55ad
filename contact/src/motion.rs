//! Indenter motion: prescribed displacement or velocity curves, and force control.
//!
//! An indenter translates along its unit pressing direction `d`; its offset from the initial
//! placement is `u(t) = s(t) d`, with `s` the travel (m).
//!
//! **Curves** ([`Curve`], see [`crate::curve`]) give a scalar of time; a motion's curve is one
//! of the forms a motion file may write (`curve = "smooth_step"`, `"ramp"`, `"table"`,
//! `"constant"`):
//! - `smooth_step`: `a * S((t - t0) / T)` with the quintic `S(r) = 10 r^3 - 15 r^4 + 6 r^5`
//!   (`S(0) = 0`, `S(1) = 1`, zero velocity and acceleration at both ends; peak rate
//!   `1.875 a / T`), held at `a` after `t0 + T`. "15 mm in 25 ms" is
//!   `{ curve = "smooth_step", amplitude = 0.015, duration = 0.025 }`.
//! - `ramp`: linear from 0 to `a` over `[t0, t0 + T]`, then held.
//! - `table`: piecewise linear through `(t, value)` points, held constant outside.
//! - `constant`.
//!
//! **Prescribed displacement** uses the curve as `s(t)`; **prescribed velocity** as `ds/dt`,
//! integrated with the midpoint rule over each step.
//!
//! **Force control** ([`ForceControl`]) presses along `d` until the reaction
//! `R = -F_body_on_indenter . d` reaches `target`, then holds it. The law is a velocity command,
//! evaluated once per step after the contact forces are known:
//! 1. `R_f`: first-order low-pass of `R`, time constant `filter_time` (explicit dynamics makes the
//!    raw contact force ring);
//! 2. before first contact: `v = approach_speed`;
//! 3. after first contact at travel `s_c` and time `t_c`: reference `F_ref = target * min(1, (t - t_c)
//!    / ramp_time)`, secant stiffness `k_s = R_f / max(s - s_c, 1e-9 m)`, and
//!    `v = clamp((F_ref - R_f) / (k_s * time_constant), -approach_speed, approach_speed)`.
//!
//! For a body whose force grows with depth as `R = k(s - s_c)` this is a first-order lag of
//! time constant `time_constant` towards `F_ref`, independent of `k` (the secant stiffness is
//! measured on line, so no stiffness needs to be known); a stiffening body (Hertz: tangent =
//! 1.5 secant) only makes it faster. Since position integrates velocity, the law has no
//! steady-state error for a constant target on an elastic body; on a relaxing (viscoelastic) body it
//! follows the relaxation with a lag error about `time_constant * |dR/dt|_relax`. Saturation at
//! `approach_speed` bounds the speed in every phase, so a wrong stiffness estimate can never drive
//! the indenter away. Keep `filter_time` a few times below `time_constant` for stability.
//!
//! The controller holds the force on whatever the body does: on a body that creeps at rate
//! `v_c` at constant load it follows the creep with the lag error `k_s * time_constant * v_c`,
//! and on a body that collapses it keeps pushing. A held load on one-point hexahedra with
//! *viscous* hourglass control is such a case (the hourglass modes resist only rates, so the
//! elements under the indenter drift and flatten during a hold); for force-controlled holds use
//! stiffness hourglass control or the F-bar element (`scene/tests/integration/contact_force_control.rs`
//! measures both, and checks that the depth holds still).

use crate::curve::Curve;
use serde::Deserialize;

/// Force-control parameters. See the module doc for the law. The quantities are of types `F`
/// (force), `T` (time) and `V` (speed): `f64` in SI by default, what the stage runs; a scene file
/// reads them with units ([`ForceControl::to_si`] converts). Absent keys take the defaults.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(
    deny_unknown_fields,
    bound(deserialize = "F: Deserialize<'de>, T: Deserialize<'de> + From<f64>, \
                         V: Deserialize<'de> + From<f64>")
)]
pub struct ForceControl<F = f64, T = f64, V = f64> {
    /// Target reaction force along the pressing direction (N).
    pub target: F,
    /// Time to ramp the force reference from 0 to `target`, counted from first contact (s).
    /// Default 0 (step).
    #[serde(default = "default_ramp")]
    pub ramp_time: T,
    /// Speed before contact, and speed limit at all times (m/s). Default 0.1.
    #[serde(default = "default_approach")]
    pub approach_speed: V,
    /// Closed-loop time constant (s). Default 5 ms.
    #[serde(default = "default_tau")]
    pub time_constant: T,
    /// Low-pass time constant of the measured force (s). Default 0.5 ms.
    #[serde(default = "default_filter")]
    pub filter_time: T,
}

fn default_ramp<T: From<f64>>() -> T {
    T::from(0.0)
}
fn default_approach<V: From<f64>>() -> V {
    V::from(0.1)
}
fn default_tau<T: From<f64>>() -> T {
    T::from(5e-3)
}
fn default_filter<T: From<f64>>() -> T {
    T::from(5e-4)
}

impl ForceControl {
    /// Force control towards `target` (N) with default gains.
    pub fn new(target: f64) -> Self {
        ForceControl {
            target,
            ramp_time: default_ramp(),
            approach_speed: default_approach(),
            time_constant: default_tau(),
            filter_time: default_filter(),
        }
    }
}

impl<F: Copy + Into<f64>, T: Copy + Into<f64>, V: Copy + Into<f64>> ForceControl<F, T, V> {
    /// The same parameters in SI.
    pub fn to_si(&self) -> ForceControl {
        ForceControl {
            target: self.target.into(),
            ramp_time: self.ramp_time.into(),
            approach_speed: self.approach_speed.into(),
            time_constant: self.time_constant.into(),
            filter_time: self.filter_time.into(),
        }
    }
}

/// How an indenter moves along its direction. The curves and the force control are of types
/// `D` (travel), `V` (speed) and `F`: [`Curve`] and [`ForceControl`] in SI by default, what the
/// stage runs; a scene file gives its curves and force with units and the scene maps them.
///
/// Deserialises from a table with a `kind` tag and, for a prescribed motion, its `curve`:
/// `{ kind = "displacement", curve = { curve = "smooth_step", amplitude = 0.015, duration = 0.025 } }`,
/// `{ kind = "force", target = 20.0, ramp_time = 0.01 }`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum MotionSpec<D = Curve, V = Curve, F = ForceControl> {
    /// Does not move.
    Fixed,
    /// Prescribed travel `s(t)` (m) along the direction.
    Displacement {
        /// Travel (m) versus time.
        curve: D,
    },
    /// Prescribed speed `ds/dt` (m/s) along the direction.
    Velocity {
        /// Speed (m/s) versus time.
        curve: V,
    },
    /// Force control (see [`ForceControl`]).
    Force(F),
}

impl MotionSpec {
    pub(crate) fn validate(&self) -> Result<(), String> {
        match self {
            MotionSpec::Fixed => Ok(()),
            MotionSpec::Displacement { curve } | MotionSpec::Velocity { curve } => {
                if let Curve::Constant { value } = curve {
                    if !value.is_finite() {
                        return Err("constant curve is not finite".into());
                    }
                }
                curve.validate()
            }
            MotionSpec::Force(f) => {
                let ok = f.target.is_finite()
                    && f.ramp_time >= 0.0
                    && f.approach_speed > 0.0
                    && f.time_constant > 0.0
                    && f.filter_time >= 0.0;
                if ok {
                    Ok(())
                } else {
                    Err("force control needs finite target, ramp_time >= 0, approach_speed > 0, time_constant > 0, filter_time >= 0".into())
                }
            }
        }
    }
}

/// Run-time state of a motion along the direction.
#[derive(Clone, Debug, Default)]
pub(crate) struct MotionState {
    /// Travel (m).
    pub s: f64,
    /// Travel rate (m/s).
    pub v: f64,
    /// Filtered reaction (N), force control.
    pub r_filt: f64,
    /// Travel and time at first contact.
    pub contact: Option<(f64, f64)>,
    /// Time of the last update.
    pub t: Option<f64>,
}

impl MotionState {
    /// Advance the travel to time `t` (before the contact evaluation).
    pub fn advance(&mut self, spec: &MotionSpec, t: f64) {
        let t_prev = self.t.unwrap_or(t);
        match spec {
            MotionSpec::Fixed => {
                self.s = 0.0;
                self.v = 0.0;
            }
            MotionSpec::Displacement { curve } => {
                self.s = curve.value(t);
                self.v = curve.rate(t);
            }
            MotionSpec::Velocity { curve } => {
                if self.t.is_some() {
                    self.s += curve.value(0.5 * (t + t_prev)) * (t - t_prev);
                }
                self.v = curve.value(t);
            }
            MotionSpec::Force(_) => {
                // Velocity command from the previous step.
                self.s += self.v * (t - t_prev);
            }
        }
        self.t = Some(t);
    }

    /// After the contact evaluation at time `t`: record first contact and update the force law.
    /// `reaction` is the force the body exerts on the indenter along `-direction` (N), `dt` the step.
    pub fn after_contact(
        &mut self,
        spec: &MotionSpec,
        t: f64,
        dt: f64,
        reaction: f64,
        touching: bool,
    ) {
        if self.contact.is_none() && touching {
            self.contact = Some((self.s, t));
        }
        if let MotionSpec::Force(fc) = spec {
            let a = if fc.filter_time > 0.0 {
                1.0 - (-dt / fc.filter_time).exp()
            } else {
                1.0
            };
            self.r_filt += a * (reaction - self.r_filt);
            self.v = match self.contact {
                None => fc.approach_speed,
                Some((s_c, t_c)) => {
                    let f_ref = if fc.ramp_time > 0.0 {
                        fc.target * ((t - t_c) / fc.ramp_time).min(1.0)
                    } else {
                        fc.target
                    };
                    let k_s = self.r_filt.max(0.0) / (self.s - s_c).max(1e-9);
                    let e = f_ref - self.r_filt;
                    let denom = k_s * fc.time_constant;
                    let v = if denom > 0.0 {
                        e / denom
                    } else {
                        fc.approach_speed * e.signum()
                    };
                    v.clamp(-fc.approach_speed, fc.approach_speed)
                }
            };
        }
    }
}
