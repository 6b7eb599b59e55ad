//! The reference problems of the default suite.

pub mod block;
pub mod cantilever;
pub mod closed;
pub mod patch;

use solver::element::{Formulation, Hourglass, HourglassForm, HourglassModulus};

/// One-point integration, viscous hourglass control (LS-DYNA default, Q = 0.1).
pub const ONE_POINT_VISCOUS: Formulation = Formulation::OnePoint(Hourglass {
    form: HourglassForm::Viscous,
    coefficient: 0.1,
    modulus: HourglassModulus::PWave,
});
/// One-point integration, Flanagan-Belytschko stiffness hourglass control, Q = 0.1.
pub const ONE_POINT_STIFFNESS: Formulation = Formulation::OnePoint(Hourglass {
    form: HourglassForm::Stiffness,
    coefficient: 0.1,
    modulus: HourglassModulus::PWave,
});
/// One-point integration, viscous hourglass control scaled by the shear modulus (Q = 0.1): the
/// choice for nearly incompressible tissue, and `palpa palpate`'s default.
pub const ONE_POINT_VISCOUS_SHEAR: Formulation = Formulation::OnePoint(Hourglass {
    form: HourglassForm::Viscous,
    coefficient: 0.1,
    modulus: HourglassModulus::Shear,
});
/// One-point integration, physical (assumed-strain) hourglass stabilisation, Q = 1.
pub const ONE_POINT_PHYSICAL: Formulation = Formulation::OnePoint(Hourglass {
    form: HourglassForm::Physical,
    coefficient: 1.0,
    modulus: HourglassModulus::Shear,
});
/// Fully integrated 2x2x2 with F-bar.
pub const FULL_FBAR: Formulation = Formulation::Full { fbar: true };
/// Fully integrated 2x2x2, plain (standard Q1).
pub const FULL: Formulation = Formulation::Full { fbar: false };

/// Short label of a formulation for the table.
pub fn short(f: &Formulation) -> &'static str {
    match f {
        Formulation::OnePoint(h) if h.form == HourglassForm::Viscous => "1-pt viscous HG",
        Formulation::OnePoint(h) if h.form == HourglassForm::Physical => "1-pt physical HG",
        Formulation::OnePoint(_) => "1-pt stiffness HG",
        Formulation::Full { fbar: true } => "full F-bar",
        Formulation::Full { fbar: false } => "full Q1",
    }
}
