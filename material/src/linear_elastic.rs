//! Linear isotropic elasticity, for verification.
//!
//! Default kinematics `Green` (Saint Venant-Kirchhoff): S = lambda tr(E) I + 2 mu E with the
//! Green-Lagrange strain E = (F^T F - I)/2. It is objective (no stress under rigid rotation) and
//! equal to Hooke's law to first order in the displacement gradient.
//!
//! Kinematics `Small`: sigma = lambda tr(eps) I + 2 mu eps with eps = sym(F) - I, returned so
//! that the first Piola-Kirchhoff stress P = F S equals sigma exactly. The total Lagrangian
//! element then reproduces a small-strain linear finite-element code (scikit-fem, FEniCSx)
//! to round-off, which is what the reference comparisons need. Not objective; do not use it
//! for large rotations.
//!
//! Wave speed: c = sqrt((lambda + 2 mu) / rho).

use crate::law::{checked_jacobian, Law, LawError, Mat3, Response};

/// Strain measure of the linear law.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kinematics {
    /// Green-Lagrange strain (Saint Venant-Kirchhoff).
    Green,
    /// Infinitesimal strain, P = sigma (verification against linear codes).
    Small,
}

/// Linear elastic law.
#[derive(Clone, Debug)]
pub struct LinearElastic {
    /// Density (kg/m^3).
    pub rho: f64,
    /// First Lame constant (Pa).
    pub lambda: f64,
    /// Shear modulus (Pa).
    pub mu: f64,
    /// Strain measure.
    pub kinematics: Kinematics,
}

impl Law for LinearElastic {
    fn density(&self) -> f64 {
        self.rho
    }
    fn initial_wave_speed(&self) -> f64 {
        ((self.lambda + 2.0 * self.mu) / self.rho).sqrt()
    }
    fn initial_shear_modulus(&self) -> f64 {
        self.mu
    }
    #[inline]
    fn evaluate(&self, f: &Mat3, _dt: f64, _h: &mut [f64]) -> Result<Response, LawError> {
        checked_jacobian(f)?;
        let i = Mat3::identity();
        let pk2 = match self.kinematics {
            Kinematics::Green => {
                let e = (f.transpose() * f - i) * 0.5;
                i * (self.lambda * e.trace()) + e * (2.0 * self.mu)
            }
            Kinematics::Small => {
                let eps = (f + f.transpose()) * 0.5 - i;
                let sigma = i * (self.lambda * eps.trace()) + eps * (2.0 * self.mu);
                f.try_inverse().ok_or(LawError::NotFinite("singular F"))? * sigma
            }
        };
        Ok(Response {
            pk2,
            wave_speed: self.initial_wave_speed(),
            dissipation: 0.0,
            failed: false,
        })
    }
}
