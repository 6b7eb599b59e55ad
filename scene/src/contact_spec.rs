//! Scene tables for rigid indenters (`[[indenter]]`), two-finger hands (`[[hand]]`) and the
//! contact settings (`[contact]`). Every physical quantity takes a unit (`"15 mm"`, `"25 ms"`,
//! `"20 N"`); plain numbers are SI; unknown keys are errors. The tables translate one to one into
//! the `contact` crate's SI specs ([`contact::IndenterSpec`], [`contact::HandSpec`],
//! [`contact::ContactParams`]); see that crate's docs for the equations.
//!
//! ```toml
//! # A rigid sphere pressed 1 mm into the top face (z = 0) with a smooth step over 40 ms.
//! [[indenter]]
//! name = "ball"                       # history columns ball_force_x, ..., ball_depth, ...
//! direction = [0, 0, -1]              # pressing direction (normalised)
//! motion = { kind = "displacement", curve = { kind = "smooth_step", value = "1 mm", end = "40 ms" } }
//! part = [{ shape = "sphere", center = [0, 0, "10 mm"], radius = "10 mm" }]
//!
//! # The paper's two-finger hand, 15 mm in 25 ms.
//! [[hand]]
//! name = "hand"
//! point = ["0 mm", "0 mm", "0 mm"]    # between the fingertips, on the surface
//! direction = [0, 0, -1]
//! diameter = "15 mm"
//! spacing = "20 mm"                   # centre to centre
//! length = "60 mm"
//! motion = { kind = "displacement", curve = { kind = "smooth_step", value = "15 mm", end = "25 ms" } }
//!
//! # Force control: press until the reaction reaches 20 N, then hold.
//! # motion = { kind = "force", target = "20 N", ramp_time = "10 ms" }
//!
//! [contact]                           # optional; every key has a default
//! surface = "skin"                    # node set: only faces with all 4 nodes in it
//! friction = 0.0
//! ```
//!
//! Shapes (`shape = ...`): `sphere` (`center`, `radius`), `capsule` (`center` of the tip
//! hemisphere, `axis` tip to hand, `radius`, `length` of the straight part), `cylinder` (flat
//! punch: `center` of the pressing face, `axis` into the punch, `radius`, `length`), `box`
//! (`center`, `half_extents`, optional `axes`), `plane` (`point`, outward `normal`), `stl`
//! (`path` relative to the scene, `unit` = length of one file unit, e.g. `"1 mm"`, `translate`),
//! `triangles` (`vertices`, `triangles`: a closed surface given inline). They are the contact
//! crate's [`contact::ShapeSpec`] with lengths that carry units (`ShapeSpec<Length>`), mapped to
//! m by [`contact::ShapeSpec::map`].
//!
//! Motions (`kind = ...`): `fixed`; `displacement` and `velocity` with a `curve` (the same curve
//! tables as `[[boundary]]`: `constant`, `smooth_step` (from 0), `ramp`, `table`); `force` with
//! `target` and optional `ramp_time`, `approach_speed`, `time_constant`, `filter_time`.
//!
//! ## Default penalty (why "soft")
//! The default is the LS-DYNA `SOFT=1`-style penalty `k_f = soft_scale * m_f / dt_0^2` (`m_f`
//! mean nodal mass of the face, `dt_0` = `design_dt`, by default the run's initial time step
//! `dt_factor * dt_crit`, after mass scaling and `dt_max`), with `soft_scale = 0.4` and the
//! crate's per-node cap `k_a <= 0.1 m_a (2/dt_0)^2`. Why:
//! - it is tied to the step the solver really takes, so it is stable for any law and any mass
//!   scaling: the contact adds at most 10 % to `omega^2 dt^2 / 4` of a node, and
//!   `0.9^2 + 0.1 < 1` (see [`solver::contact_stage`] for the time-step rule);
//! - for an interior surface node it gives a contact spring about `0.6 M h` (`M = rho c^2` the
//!   P-wave modulus, `h` the element size), i.e. a penetration of order `p h / M`. Soft tissue is
//!   nearly incompressible (paper flesh `K/G = 5e4`, liver `K/G ~ 50`), so `M >> E`, and the
//!   penetration is a small fraction of the indentation depth (`g/d ~ (E*/M)(h/a)/soft_scale`, `a`
//!   the contact radius);
//! - the segment formula `k_f = s K A^2 / V` is about `s K h` for a cube element: with the
//!   LS-DYNA default `s = 0.1` that is ~2.5 times softer than the default above, it depends on
//!   which modulus stands for `K` (palpa passes `K = rho c0^2` of the part's law, the P-wave
//!   modulus, and the element's reference volume), and it does not follow the step the run
//!   actually takes (`dt_max`, mass scaling). It stays available (`penalty = "segment"` or
//!   `"max"`).
//!
//! For a compressible body (Poisson ratio 0.3) on a coarse mesh the default penalty lets the
//! surface sink by tens of percent of the depth into a fingertip two elements wide; raise
//! `soft_scale` and `stiffness_cap` there (the contact stage then lowers the step, see
//! [`solver::contact_stage`]).

use contact::{ForceControl, MotionSpec, ShapeSpec};
use material::quantity::{Force, Length, Number, Time, Velocity};
use serde::Deserialize;

use super::curve_spec::CurveSpec;

/// `[[indenter]]`: a rigid indenter, the union of its parts, moving along `direction`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IndenterScene {
    /// Name; output columns are `<name>_force_x`, ...
    pub name: String,
    /// Pressing direction (normalised).
    pub direction: [f64; 3],
    /// Motion along the direction.
    pub motion: MotionScene,
    /// Rigid parts (at least one), world coordinates at t = 0.
    pub part: Vec<ShapeSpec<Length>>,
    /// Coulomb friction coefficient (default: `[contact] friction`).
    pub friction: Option<Number>,
}

/// `[[hand]]`: the two-finger hand (two parallel capsule fingers, one indenter).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HandScene {
    /// Name of the resulting indenter.
    pub name: String,
    /// Point between the two fingertips, usually on the body surface (or give `location`/`at`).
    pub point: Option<[Length; 3]>,
    /// Pressing direction, e.g. the inward surface normal at `point` (default: the inward skin
    /// normal when the hand is placed by `location` or `at`).
    pub direction: Option<[f64; 3]>,
    /// A phantom palpation location ("A", "B", "C", "P01".."P25"): sets `point` and `direction`.
    pub location: Option<String>,
    /// A point (x, y) of the phantom's body surface: sets `point` and `direction`.
    pub at: Option<[Length; 2]>,
    /// Direction from finger 1 to finger 2 (default world x, or y when x is the direction).
    pub spacing_axis: Option<[f64; 3]>,
    /// Finger diameter.
    pub diameter: Length,
    /// Centre-to-centre spacing.
    pub spacing: Length,
    /// Finger length, tip to far end.
    pub length: Length,
    /// Tilt of the finger axes from the pressing direction, in degrees (default 0).
    pub tilt_deg: Option<f64>,
    /// Initial stand-off of the fingertips from `point` along `-direction` (default 0).
    pub gap: Option<Length>,
    /// Motion along the direction.
    pub motion: MotionScene,
    /// Coulomb friction coefficient (default: `[contact] friction`).
    pub friction: Option<Number>,
}

/// How an indenter moves along its direction, as a scene gives it: the contact crate's
/// [`MotionSpec`] with a travel curve in lengths, a speed curve in speeds and the force control
/// with units ([`crate::contact_build`] maps it to SI).
pub type MotionScene =
    MotionSpec<CurveSpec<Length>, CurveSpec<Velocity>, ForceControl<Force, Time, Velocity>>;

/// `[contact]`: settings shared by all indenters. All optional.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactScene {
    /// Node set of the contact surface: only boundary faces whose four nodes are all in the set
    /// take part (default: the whole boundary).
    pub surface: Option<String>,
    /// Parts whose boundary faces take part (default: all).
    pub parts: Option<Vec<String>>,
    /// `soft` (default), `segment` or `max`.
    pub penalty: Option<String>,
    /// Segment formula scale `s` (LS-DYNA SLSFAC, default 0.1).
    pub penalty_scale: Option<Number>,
    /// Soft formula scale (LS-DYNA SOFSCL analogue, default 0.4 here; see the module doc).
    pub soft_scale: Option<Number>,
    /// Step the soft penalty and the cap refer to (default: the run's initial step).
    pub design_dt: Option<Time>,
    /// Cap on a node's contact stiffness as a fraction of `m (2/design_dt)^2` (default 0.1;
    /// 0 disables the cap).
    pub stiffness_cap: Option<Number>,
    /// Coulomb friction coefficient (default 0).
    pub friction: Option<Number>,
    /// Friction regularisation speed (default 1 mm/s).
    pub friction_velocity: Option<Velocity>,
    /// Normal contact damping as a fraction of critical (LS-DYNA VDC/100, default 0).
    pub damping_ratio: Option<Number>,
    /// Fewest samples per face direction (default 2).
    pub samples_min: Option<u32>,
    /// Most samples per face direction (default 12).
    pub samples_max: Option<u32>,
    /// Sample spacing as a fraction of the smallest indenter feature (default 0.125).
    pub sample_spacing: Option<Number>,
    /// Broad-phase margin (default: the mean face edge length).
    pub margin: Option<Length>,
    /// Most steps between broad-phase rebuilds (default 200).
    pub rebuild_interval: Option<u32>,
}

/// Default `soft_scale` of palpa's contact (see the module doc).
pub const DEFAULT_SOFT_SCALE: f64 = 0.4;
