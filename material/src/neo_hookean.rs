//! Compressible neo-Hookean solid (Simo & Pister form; Bonet & Wood, Nonlinear Continuum
//! Mechanics for FEA, 2nd ed., eq. 6.28):
//!
//!   Psi = mu/2 (I1 - 3) - mu ln J + lambda/2 (ln J)^2,
//!   S   = mu (I - C^-1) + lambda ln J C^-1.
//!
//! The spatial tangent is c = lambda/J I(x)I + 2 (mu - lambda ln J)/J II (Bonet & Wood eq. 6.40),
//! so the dilatational wave speed in the current state is
//!   c_d^2 = (lambda + 2 mu - 2 lambda ln J) / rho_0,
//! which grows under compression (ln J < 0): the "stretch-stiffened" speed the time step needs.

use crate::law::{faults, Law, LawOut};
use crate::real::{Mask, Real};
use crate::tensor::{cofactor, det, mul, scale, M3};

/// Compressible neo-Hookean law.
#[derive(Clone, Debug)]
pub struct NeoHookean {
    /// Density (kg/m^3).
    pub rho: f64,
    /// First Lame constant (Pa).
    pub lambda: f64,
    /// Shear modulus (Pa).
    pub mu: f64,
}

impl Law for NeoHookean {
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
        "neo_hookean"
    }
    #[inline(always)]
    fn stress<R: Real>(&self, f: &M3<R>, _dt: f64, _h: &mut [R]) -> LawOut<R> {
        let j = det(f);
        // C = F^T F and C^-1 = cof(C) / det C with det C = J^2 (C is symmetric).
        let ft = [
            [f[0][0], f[1][0], f[2][0]],
            [f[0][1], f[1][1], f[2][1]],
            [f[0][2], f[1][2], f[2][2]],
        ];
        let c = mul(&ft, f);
        let ci = scale(&cofactor(&c), R::splat(1.0) / (j * j));
        let lnj = j.ln();
        let k = lnj * self.lambda - self.mu;
        let mut pk2 = scale(&ci, k);
        for i in 0..3 {
            pk2[i][i] += R::splat(self.mu);
        }
        let m = (R::splat(self.lambda + 2.0 * self.mu) - lnj * (2.0 * self.lambda))
            .max(R::splat(self.mu));
        let wave_speed = (m / self.rho).sqrt();
        let finite = wave_speed.is_finite() & pk2[0][0].is_finite() & pk2[1][1].is_finite();
        let (fault, fault_value) = faults(j, R::Mask::splat(false), finite);
        LawOut {
            pk2,
            wave_speed,
            dissipation: R::zero(),
            failed: R::Mask::splat(false),
            fault,
            fault_value,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::law::LawError;
    use crate::tensor::Mat3;
    use nalgebra::Rotation3;

    fn law() -> NeoHookean {
        NeoHookean {
            rho: 1000.0,
            lambda: 2.0e6,
            mu: 1.0e6,
        }
    }

    #[test]
    fn small_strain_matches_hooke() {
        let eps = 1e-7;
        let f = Mat3::new(1.0 + eps, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
        let r = law().evaluate(&f, 0.0, &mut []).unwrap();
        let s11 = (2.0e6 + 2.0e6) * eps;
        assert!((r.pk2[(0, 0)] - s11).abs() < 1e-6 * s11);
        assert!((r.pk2[(1, 1)] - 2.0e6 * eps).abs() < 1e-6 * s11);
    }

    #[test]
    fn rigid_rotation_is_stress_free() {
        let rot = Rotation3::from_euler_angles(0.3, 1.1, -0.7).into_inner();
        let r = law().evaluate(&rot, 0.0, &mut []).unwrap();
        assert!(r.pk2.norm() < 1e-8 * 1e6);
    }

    #[test]
    fn inverted_point_is_an_error() {
        let f = Mat3::new(-1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
        assert!(matches!(
            law().evaluate(&f, 0.0, &mut []),
            Err(LawError::NonPositiveJacobian(_))
        ));
    }
}
