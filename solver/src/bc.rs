//! Boundary conditions and loads on node sets.
//!
//! Kinematic conditions act on the velocity at the half step of the central-difference update:
//! a fixed degree of freedom gets v = 0; a prescribed velocity v(t) gets v = v(t + dt/2); a
//! prescribed displacement d(t) gets v = (d(t + dt) - u(t)) / dt, which lands exactly on the
//! curve. The reaction is the force the constraint exerts on the body,
//!   R = m a - (f_ext - f_int),
//! with a the acceleration the constraint imposed.

use contact::Curve;

/// What a kinematic condition prescribes on one degree of freedom.
#[derive(Clone, Debug, PartialEq)]
pub enum Kinematic {
    /// u = 0, v = 0.
    Fixed,
    /// Displacement (m) as a function of time (s).
    Displacement(Curve),
    /// Velocity (m/s) as a function of time (s).
    Velocity(Curve),
}

/// A kinematic condition on some nodes and directions.
#[derive(Clone, Debug)]
pub struct Constraint {
    /// Node ids.
    pub nodes: Vec<u32>,
    /// Direction index (0 x, 1 y, 2 z).
    pub dof: usize,
    /// The prescription.
    pub kind: Kinematic,
}

/// The prescription of the kinematic conditions that share one code in the nodal update.
#[derive(Clone, Debug)]
pub(crate) struct Prescribed {
    pub(crate) kind: Kinematic,
}

/// A nodal force (N) applied to every node of a set, along one direction, scaled by a curve.
#[derive(Clone, Debug)]
pub struct NodalLoad {
    /// Node ids.
    pub nodes: Vec<u32>,
    /// Direction index.
    pub dof: usize,
    /// Force per node (N) as a function of time.
    pub curve: Curve,
}
