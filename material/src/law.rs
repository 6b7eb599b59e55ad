//! The law interface shared by every constitutive model.
//!
//! The solver works in the total Lagrangian frame: a law receives the deformation gradient
//! `F = I + Grad u` of one integration point and returns the second Piola-Kirchhoff stress `S`
//! (Pa), the current dilatational wave speed `c` (m/s) used for the stable time step
//! (`dt <= L / c`), and the energy it dissipated over the step (J per m^3 of reference volume),
//! which the solver adds to the energy balance.
//!
//! History (viscoelastic internal variables, plastic strain) is stored by the solver in one
//! contiguous buffer per element group, `history_len()` numbers per integration point; a law
//! with `history_len() == 0` gets an empty slice and the solver allocates nothing for it.
//! The slice holds the state at the start of the step on entry and must hold the state at the
//! end of the step on return.
//!
//! Every law is written once, generic over the number type ([`Law::stress`] over a
//! [`Real`]): `f64` evaluates one point ([`Law::evaluate`], the material-point driver and the
//! tests), [`crate::real::F64x8`] evaluates eight points of a batch at once (the solver's element
//! loop), with the history of the batch in struct-of-arrays form (value `k` of the eight points
//! is `history[k]`). Where a lane cannot be evaluated (inverted, non-finite), the law sets its
//! fault code ([`LawOut::fault`]) instead of returning early; [`fault_error`] turns a code into
//! the [`LawError`] the scalar path reports.

use crate::principal::Sym6;
use crate::real::Real;
use crate::tensor::{from_mat3, to_mat3, Mat3, M3};
use thiserror::Error;

/// What a law returns for one integration point and one step.
#[derive(Clone, Copy, Debug)]
pub struct Response {
    /// Second Piola-Kirchhoff stress S (Pa).
    pub pk2: Mat3,
    /// Current dilatational wave speed (m/s), including viscous moduli and stretch stiffening.
    pub wave_speed: f64,
    /// Energy dissipated during this step (J/m^3 of reference volume), >= 0.
    pub dissipation: f64,
    /// The point has reached its failure criterion and its element should be eroded.
    pub failed: bool,
}

/// What a law returns for one point or one batch of points ([`Law::stress`]).
#[derive(Clone, Copy, Debug)]
pub struct LawOut<R: Real> {
    /// Second Piola-Kirchhoff stress S (Pa).
    pub pk2: M3<R>,
    /// Current dilatational wave speed (m/s).
    pub wave_speed: R,
    /// Energy dissipated during this step (J/m^3 of reference volume).
    pub dissipation: R,
    /// The point reached its failure criterion.
    pub failed: R::Mask,
    /// 0 where the point was evaluated, else one of the `FAULT_*` codes.
    pub fault: R,
    /// The quantity the fault names (det F for [`FAULT_JACOBIAN`]).
    pub fault_value: R,
}

/// Fault code: det F <= 0 (or not finite).
pub const FAULT_JACOBIAN: f64 = 1.0;
/// Fault code: a principal stretch collapsed to zero.
pub const FAULT_COLLAPSED: f64 = 2.0;
/// Fault code: the stress or the wave speed is not finite.
pub const FAULT_NOT_FINITE: f64 = 3.0;

/// Fault codes of a law evaluation in order of precedence: the Jacobian first (as a scalar
/// check would stop there), then a collapsed stretch, then a non-finite result. Returns
/// `(fault, fault_value)`.
#[inline(always)]
pub fn faults<R: Real>(j: R, collapsed: R::Mask, finite: R::Mask) -> (R, R) {
    let mut code = R::select(finite, R::zero(), R::splat(FAULT_NOT_FINITE));
    code = R::select(collapsed, R::splat(FAULT_COLLAPSED), code);
    let jac_bad = !(j.gt(R::zero()) & j.is_finite());
    code = R::select(jac_bad, R::splat(FAULT_JACOBIAN), code);
    (code, j)
}

/// The error a fault code stands for; `what` names the law in a non-finite result.
pub fn fault_error(code: f64, value: f64, what: &'static str) -> LawError {
    if code == FAULT_JACOBIAN {
        LawError::NonPositiveJacobian(value)
    } else if code == FAULT_COLLAPSED {
        LawError::NotFinite("principal stretch collapsed to zero")
    } else {
        LawError::NotFinite(what)
    }
}

/// A symmetric stress given as Sym6, as a full matrix over `R`.
#[inline(always)]
pub fn full<R: Real>(s: &Sym6<R>) -> M3<R> {
    [[s[0], s[3], s[5]], [s[3], s[1], s[4]], [s[5], s[4], s[2]]]
}

/// Why a law could not evaluate a state.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum LawError {
    /// det F <= 0: the element has inverted.
    #[error("non-positive Jacobian det F = {0:.3e} (element inverted)")]
    NonPositiveJacobian(f64),
    /// A fully integrated element's Gauss point has lost nearly all its volume.
    #[error(
        "excessively distorted: Gauss-point volume ratio det F = {0:.3e} is below {1} (the \
         element is nearly inverted and its stable-step estimate no longer bounds its modes)"
    )]
    ExcessiveDistortion(f64, f64),
    /// The stress or wave speed is not finite.
    #[error("non-finite stress or wave speed ({0})")]
    NotFinite(&'static str),
}

/// A constitutive law. Implementations are plain data (parameters); all state lives in the
/// history slice so that one law value serves every element of a group.
pub trait Law: Sync + Send {
    /// Reference density (kg/m^3).
    fn density(&self) -> f64;
    /// Number of history values per integration point (0 for a law without memory).
    fn history_len(&self) -> usize {
        0
    }
    /// Fill the history of one integration point with its initial (undeformed) state.
    fn init_history(&self, _history: &mut [f64]) {}
    /// Names of the history values, for output.
    fn history_names(&self) -> Vec<String> {
        Vec::new()
    }
    /// Dilatational wave speed of the undeformed material (m/s).
    fn initial_wave_speed(&self) -> f64;
    /// Instantaneous small-strain shear modulus of the undeformed material (Pa): the modulus
    /// that resists isochoric deformation, which shear-scaled hourglass control uses.
    fn initial_shear_modulus(&self) -> f64;
    /// Short name of the law, for messages.
    fn name(&self) -> &'static str;
    /// Evaluate the stress at deformation gradient `f` (one point, or one per lane) at the end of
    /// a step of length `dt` (s). `history` holds `history_len()` values of the point(s).
    fn stress<R: Real>(&self, f: &M3<R>, dt: f64, history: &mut [R]) -> LawOut<R>;
    /// [`Law::stress`] at one point, with the fault as an error.
    #[inline]
    fn evaluate(&self, f: &Mat3, dt: f64, history: &mut [f64]) -> Result<Response, LawError> {
        let o = self.stress::<f64>(&from_mat3(f), dt, history);
        if o.fault != 0.0 {
            return Err(fault_error(o.fault, o.fault_value, self.name()));
        }
        Ok(Response {
            pk2: to_mat3(&o.pk2),
            wave_speed: o.wave_speed,
            dissipation: o.dissipation,
            failed: o.failed,
        })
    }
}

/// det F, refusing non-positive values.
#[inline]
pub fn checked_jacobian(f: &Mat3) -> Result<f64, LawError> {
    let j = f.determinant();
    if j > 0.0 && j.is_finite() {
        Ok(j)
    } else {
        Err(LawError::NonPositiveJacobian(j))
    }
}

/// Cauchy stress from PK2: sigma = F S F^T / J.
#[inline]
pub fn cauchy_from_pk2(f: &Mat3, s: &Mat3) -> Mat3 {
    let j = f.determinant();
    f * s * f.transpose() / j
}

/// PK2 from Kirchhoff stress: S = F^-1 tau F^-T.
#[inline]
pub fn pk2_from_kirchhoff(f: &Mat3, tau: &Mat3) -> Option<Mat3> {
    let fi = f.try_inverse()?;
    Some(fi * tau * fi.transpose())
}

/// Lame constants from Young's modulus and Poisson ratio: (lambda, mu).
pub fn lame(e: f64, nu: f64) -> (f64, f64) {
    let mu = e / (2.0 * (1.0 + nu));
    let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    (lambda, mu)
}

/// Young's modulus and Poisson ratio from the bulk and shear moduli: (E, nu),
/// `E = 9 K G / (3 K + G)`, `nu = (3 K - 2 G) / (2 (3 K + G))`.
pub fn young_poisson(k: f64, g: f64) -> (f64, f64) {
    (
        9.0 * k * g / (3.0 * k + g),
        (3.0 * k - 2.0 * g) / (2.0 * (3.0 * k + g)),
    )
}
