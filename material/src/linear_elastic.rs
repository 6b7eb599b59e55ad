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

use crate::law::{faults, full, Law, LawOut};
use crate::principal::c_minus_identity;
use crate::real::{Mask, Real};
use crate::tensor::{cofactor, det, mul, M3};

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
    fn name(&self) -> &'static str {
        "linear_elastic"
    }
    #[inline(always)]
    fn stress<R: Real>(&self, f: &M3<R>, _dt: f64, _h: &mut [R]) -> LawOut<R> {
        let j = det(f);
        let pk2 = match self.kinematics {
            Kinematics::Green => {
                // E = (F^T F - I) / 2, S = lambda tr(E) I + 2 mu E.
                let c1 = c_minus_identity(f);
                let e: [R; 6] = crate::arr![6, |k| c1[k] * 0.5];
                let tr = (e[0] + e[1] + e[2]) * self.lambda;
                let mut s: [R; 6] = crate::arr![6, |k| e[k] * (2.0 * self.mu)];
                for x in s.iter_mut().take(3) {
                    *x += tr;
                }
                full(&s)
            }
            Kinematics::Small => {
                // sigma from eps = sym(F) - I, then S = F^-1 sigma so that P = F S = sigma.
                let eps: [R; 6] = [
                    f[0][0] - 1.0,
                    f[1][1] - 1.0,
                    f[2][2] - 1.0,
                    (f[0][1] + f[1][0]) * 0.5,
                    (f[1][2] + f[2][1]) * 0.5,
                    (f[2][0] + f[0][2]) * 0.5,
                ];
                let tr = (eps[0] + eps[1] + eps[2]) * self.lambda;
                let mut s: [R; 6] = crate::arr![6, |k| eps[k] * (2.0 * self.mu)];
                for x in s.iter_mut().take(3) {
                    *x += tr;
                }
                // F^-1 = cof(F)^T / J.
                let cof = cofactor(f);
                let ij = R::splat(1.0) / j;
                let fi: M3<R> = crate::arr![3, |a| crate::arr![3, |b| cof[b][a] * ij]];
                mul(&fi, &full(&s))
            }
        };
        let finite = pk2[0][0].is_finite() & pk2[1][1].is_finite() & pk2[2][2].is_finite();
        let (fault, fault_value) = faults(j, R::Mask::splat(false), finite);
        LawOut {
            pk2,
            wave_speed: R::splat(self.initial_wave_speed()),
            dissipation: R::zero(),
            failed: R::Mask::splat(false),
            fault,
            fault_value,
        }
    }
}
