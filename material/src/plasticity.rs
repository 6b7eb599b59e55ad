//! Piecewise-linear J2 plasticity with isotropic hardening (LS-DYNA `*MAT_PIECEWISE_LINEAR_PLASTICITY`,
//! MAT_024 style): the ribs of the reference study.
//!
//! # Kinematics: multiplicative plasticity with logarithmic elastic strain
//!
//! `F = F_e F_p`, with the elastic left Cauchy-Green tensor `b_e = F_e F_e^T = F C_p^-1 F^T` and the
//! Hencky elastic strain `eps_e = 1/2 ln b_e` (Simo 1992, CMAME 99:61-112; Simo & Hughes,
//! *Computational Inelasticity*, ch. 9; de Souza Neto, Peric & Owen, *Computational Methods for
//! Plasticity*, sec. 14.5). The Kirchhoff stress is linear in the Hencky strain,
//!
//! ```text
//! tau = K tr(eps_e) I + 2 G dev(eps_e),
//! ```
//!
//! and the model is objective by construction: a superposed rotation `F -> Q F` gives
//! `b_e -> Q b_e Q^T`, `tau -> Q tau Q^T` and leaves `S` and the history unchanged.
//!
//! # Return mapping
//!
//! Each step: trial `b_e^tr = F C_p^-1(n) F^T`, its spectral decomposition (shared eigen-kernel),
//! trial principal Hencky strains and Kirchhoff stresses, von Mises `q = sqrt(3/2) |dev tau|`.
//! If `q_tr > sigma_y(eps_p^n)`, the exponential-map radial return solves
//!
//! ```text
//! q_tr - 3 G dgamma - sigma_y(eps_p^n + dgamma) = 0,     dev tau = (1 - 3 G dgamma / q_tr) dev tau_tr,
//! ```
//!
//! in principal logarithmic space. The flow direction is the trial one, and with a
//! piecewise-linear hardening curve the scalar equation is solved exactly, segment by segment, so
//! the return is exact for linear (and piecewise-linear) hardening. Then
//! `b_e = sum exp(2 eps_e,i) n_i (x) n_i`, `C_p^-1 = F^-1 b_e F^-T`, `S = F^-1 tau F^-T`.
//! `tau` and `b_e` are assembled from the projector form of the eigen-solution
//! ([`crate::principal::SymEigen`]), `F^-1` from the cofactors and `J`; after a plastic step
//! only, `C_p^-1 - I = F^-1 (b_e - b) F^-T` with
//! `b_e - b = sum_i expm1(2 eps_e,i) n_i (x) n_i - (b - I)`, a difference of two accurate
//! differences. The elastic test compares `q_tr^2` with `sigma_y^2`, so an elastic step takes no
//! square root and leaves the history untouched.
//!
//! Hardening: `sigma_y(eps_p)` from a table of (effective plastic strain, yield stress), or from
//! `E_t`: `sigma_y = sigma_y0 + H eps_p` with `H = E E_t / (E - E_t)`, which makes the uniaxial
//! Kirchhoff stress / log strain curve bilinear with slopes `E` and `E_t` (as MAT_024's ETAN).
//! Beyond the last table point the last slope continues.
//!
//! History (7 per point): effective plastic strain `eps_p` (named `eps_p`), then `C_p^-1 - I`
//! as Sym6 (zero in the virgin state, stored as a difference to keep small strains accurate).
//!
//! Dissipation per step: the plastic work `1/2 (sigma_y^n + sigma_y^{n+1}) dgamma` (J per m^3
//! of reference volume; exact for linear hardening). Failure: with `failure_strain`, the point
//! reports `failed` once `eps_p >= failure_strain`. Wave speed: `sqrt((K + 4/3 G) / rho)`.

use crate::law::{faults, full, Law, LawOut};
use crate::principal::{all_finite6, b_minus_identity, sandwich6, Sym6, SymEigen};
use crate::real::{Mask, Real};
use crate::tensor::{cofactor, det, M3};

/// Piecewise-linear J2 plasticity.
#[derive(Clone, Debug)]
pub struct Plasticity {
    /// Reference density (kg/m^3).
    pub rho: f64,
    /// Bulk modulus K (Pa).
    pub bulk: f64,
    /// Shear modulus G (Pa).
    pub shear: f64,
    /// Hardening curve: (effective plastic strain, yield stress in Pa, slope of the segment
    /// that starts there in Pa), first strain 0; the last slope continues beyond the last point.
    curve: Vec<(f64, f64, f64)>,
    /// Effective plastic strain at failure, if any.
    pub failure_strain: Option<f64>,
}

impl Plasticity {
    /// Build from elastic constants (Pa) and a hardening curve (plastic strain, yield stress in Pa)
    /// that starts at plastic strain 0; one point means perfect plasticity.
    pub fn new(
        name: &str,
        rho: f64,
        bulk: f64,
        shear: f64,
        curve: &[(f64, f64)],
        failure_strain: Option<f64>,
    ) -> Result<Plasticity, String> {
        for (what, v) in [
            ("density", rho),
            ("bulk modulus", bulk),
            ("shear modulus", shear),
        ] {
            if !(v > 0.0 && v.is_finite()) {
                return Err(format!(
                    "material `{name}`: {what} must be positive, got {v:e} (SI)"
                ));
            }
        }
        if curve.is_empty() || curve[0].0 != 0.0 {
            return Err(format!(
                "material `{name}`: the hardening table must start at plastic strain 0"
            ));
        }
        for (k, w) in curve.windows(2).enumerate() {
            if !(w[1].0 > w[0].0) {
                return Err(format!("material `{name}`: hardening plastic strains must increase strictly (point {})", k + 2));
            }
        }
        if curve
            .iter()
            .any(|&(e, s)| !(s > 0.0 && s.is_finite() && e.is_finite()))
        {
            return Err(format!(
                "material `{name}`: yield stresses must be positive"
            ));
        }
        if let Some(fs) = failure_strain {
            if !(fs > 0.0) {
                return Err(format!(
                    "material `{name}`: `failure_strain` must be positive"
                ));
            }
        }
        let last_slope = if curve.len() >= 2 {
            let (a, b) = (curve[curve.len() - 2], curve[curve.len() - 1]);
            (b.1 - a.1) / (b.0 - a.0)
        } else {
            0.0
        };
        if last_slope <= -3.0 * shear {
            return Err(format!("material `{name}`: the softening slope is steeper than 3G: the return mapping has no solution"));
        }
        let curve = curve
            .iter()
            .enumerate()
            .map(|(k, &(e, s))| {
                let slope = match curve.get(k + 1) {
                    Some(&(e1, s1)) => (s1 - s) / (e1 - e),
                    None => last_slope,
                };
                (e, s, slope)
            })
            .collect();
        Ok(Plasticity {
            rho,
            bulk,
            shear,
            curve,
            failure_strain,
        })
    }

    /// Bilinear hardening from E, E_t and the initial yield stress (Pa): `H = E E_t / (E - E_t)`.
    pub fn bilinear_curve(e: f64, etan: f64, yield0: f64) -> Result<Vec<(f64, f64)>, String> {
        if !(etan >= 0.0 && etan < e) {
            return Err(format!(
                "tangent modulus {etan:e} Pa must lie in [0, E = {e:e} Pa)"
            ));
        }
        let h = e * etan / (e - etan);
        Ok(vec![(0.0, yield0), (1.0, yield0 + h)])
    }

    /// Index of the hardening segment that contains effective plastic strain `ep`.
    #[inline(always)]
    fn segment(&self, ep: f64) -> usize {
        let c = &self.curve;
        let mut k = 0;
        while k + 1 < c.len() && c[k + 1].0 <= ep {
            k += 1;
        }
        k
    }

    /// Yield stress (Pa) at effective plastic strain `ep`.
    #[inline(always)]
    pub fn yield_stress(&self, ep: f64) -> f64 {
        let (e, s, slope) = self.curve[self.segment(ep)];
        s + slope * (ep - e)
    }

    /// Exact solution of `q_tr - 3 G dg - sigma_y(ep + dg) = 0` for piecewise-linear hardening,
    /// given `sy = sigma_y(ep)`.
    #[inline(always)]
    fn return_map(&self, q_tr: f64, ep: f64, sy: f64) -> f64 {
        let c = &self.curve;
        let g3 = 3.0 * self.shear;
        let mut k = self.segment(ep);
        let mut e = ep;
        let mut r = q_tr - sy;
        loop {
            let slope = c[k].2;
            let end = c.get(k + 1).map_or(f64::INFINITY, |n| n.0);
            let d = r / (g3 + slope);
            if e + d <= end {
                return e + d - ep;
            }
            r -= (g3 + slope) * (end - e);
            e = end;
            k += 1;
        }
    }
}

impl Law for Plasticity {
    fn density(&self) -> f64 {
        self.rho
    }
    fn history_len(&self) -> usize {
        7
    }
    fn init_history(&self, h: &mut [f64]) {
        h.iter_mut().for_each(|x| *x = 0.0);
    }
    fn history_names(&self) -> Vec<String> {
        [
            "eps_p", "cpinv_xx", "cpinv_yy", "cpinv_zz", "cpinv_xy", "cpinv_yz", "cpinv_zx",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect()
    }
    fn initial_wave_speed(&self) -> f64 {
        ((self.bulk + 4.0 / 3.0 * self.shear) / self.rho).sqrt()
    }

    fn initial_shear_modulus(&self) -> f64 {
        self.shear
    }

    fn name(&self) -> &'static str {
        "piecewise_linear_plasticity"
    }

    /// The trial state is formed in every lane; the return mapping runs where the mask of
    /// plastic lanes is set (the segment search of the hardening table per lane), and the
    /// history changes only there.
    #[inline(always)]
    fn stress<R: Real>(&self, f: &M3<R>, _dt: f64, history: &mut [R]) -> LawOut<R> {
        let j = det(f);
        let ep = history[0];
        let q: Sym6<R> = [
            history[1], history[2], history[3], history[4], history[5], history[6],
        ];
        // b_e^tr - I = (b - I) + F Q F^T with Q = C_p^-1 - I.
        let bm = b_minus_identity(f);
        let fq = sandwich6(f, &q);
        let a: Sym6<R> = crate::arr![6, |k| bm[k] + fq[k]];
        let (eig, mut collapsed) = SymEigen::decompose(&a);
        let ev = eig.values;
        for x in ev {
            collapsed = collapsed | !x.gt(R::splat(-1.0));
        }
        let eps = [
            ev[0].ln_1p() * 0.5,
            ev[1].ln_1p() * 0.5,
            ev[2].ln_1p() * 0.5,
        ];
        let ev_vol = eps[0] + eps[1] + eps[2];
        let m = ev_vol * (1.0 / 3.0);
        let mut dev = [eps[0] - m, eps[1] - m, eps[2] - m];
        let g2 = 2.0 * self.shear;
        // q_tr^2 = 3/2 |2 G dev eps|^2, compared squared: no square root on the elastic path
        // (q_tr > sy, also for a curve softened below zero).
        let q_tr2 = (dev[0] * dev[0] + dev[1] * dev[1] + dev[2] * dev[2]) * (1.5 * g2 * g2);
        let mut sy = R::zero();
        for l in 0..R::LANES {
            sy.set_lane(l, self.yield_stress(ep.lane(l)));
        }
        let plastic = q_tr2.gt(sy * sy) | sy.lt(R::zero());
        let mut dissipation = R::zero();
        let mut ep_new = ep;
        if plastic.any() {
            let q_tr = q_tr2.sqrt();
            let mut dg = R::zero();
            let mut sy_new = sy;
            for l in 0..R::LANES {
                if plastic.lane(l) {
                    let d = self.return_map(q_tr.lane(l), ep.lane(l), sy.lane(l));
                    dg.set_lane(l, d);
                    sy_new.set_lane(l, self.yield_stress(ep.lane(l) + d));
                }
            }
            let factor = R::select(
                plastic,
                R::splat(1.0) - dg * (3.0 * self.shear) / q_tr,
                R::splat(1.0),
            );
            for d in dev.iter_mut() {
                *d *= factor;
            }
            ep_new = ep + dg;
            dissipation = R::select(plastic, (sy + sy_new) * 0.5 * dg, R::zero());
        }
        let p = ev_vol * self.bulk;
        let tau = [dev[0] * g2 + p, dev[1] * g2 + p, dev[2] * g2 + p];
        // F^-1 = cof(F)^T / J.
        let cof = cofactor(f);
        let ij = R::splat(1.0) / j;
        let fi: M3<R> = crate::arr![3, |r| crate::arr![3, |c| cof[c][r] * ij]];
        // S = F^-1 tau F^-T.
        let pk2 = sandwich6(&fi, &eig.spectral6(&tau));
        if plastic.any() {
            // C_p^-1 - I = F^-1 (b_e - b) F^-T, with b_e - b = (b_e - I) - (b - I): both
            // differences are accurate at small strain, and an elastic step would return Q.
            let e2 = [
                ((dev[0] + m) * 2.0).exp_m1(),
                ((dev[1] + m) * 2.0).exp_m1(),
                ((dev[2] + m) * 2.0).exp_m1(),
            ];
            let mut d = eig.spectral6(&e2);
            for k in 0..6 {
                d[k] -= bm[k];
            }
            let qn = sandwich6(&fi, &d);
            history[0] = R::select(plastic, ep_new, ep);
            for k in 0..6 {
                history[1 + k] = R::select(plastic, qn[k], q[k]);
            }
        }
        let failed = match self.failure_strain {
            Some(fs) => ep_new.ge(R::splat(fs)),
            None => R::Mask::splat(false),
        };
        let (fault, fault_value) = faults(j, collapsed, all_finite6(&pk2));
        LawOut {
            pk2: full(&pk2),
            wave_speed: R::splat(self.initial_wave_speed()),
            dissipation,
            failed,
            fault,
            fault_value,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[allow(unused_imports)]
    use crate::law::LawError;
    use crate::tensor::Mat3;
    use nalgebra::{Rotation3, Vector3};

    fn ribs() -> Plasticity {
        let e = 40e6;
        let nu = 0.45;
        let curve = Plasticity::bilinear_curve(e, 1e6, 1.8e6).unwrap();
        Plasticity::new(
            "ribs",
            1000.0,
            e / (3.0 * (1.0 - 2.0 * nu)),
            e / (2.0 * (1.0 + nu)),
            &curve,
            Some(0.5),
        )
        .unwrap()
    }

    #[test]
    fn piecewise_return_is_exact() {
        let l = Plasticity::new(
            "t",
            1.0,
            1.0,
            1.0,
            &[(0.0, 1.0), (0.1, 2.0), (0.2, 2.5)],
            None,
        )
        .unwrap();
        for (q, ep) in [(1.5, 0.0), (4.0, 0.0), (10.0, 0.05), (3.0, 0.25)] {
            let dg = l.return_map(q, ep, l.yield_stress(ep));
            let r = q - 3.0 * dg - l.yield_stress(ep + dg);
            assert!(r.abs() < 1e-12, "q={q} ep={ep}: residual {r}");
            assert!(dg > 0.0);
        }
    }

    #[test]
    fn rigid_rotation_rotates_the_cauchy_stress() {
        let law = ribs();
        let mut h1 = [0.0; 7];
        let mut h2 = [0.0; 7];
        let q = Rotation3::from_euler_angles(0.9, -0.4, 2.2).into_inner();
        // A plastic shear-plus-stretch path, evaluated with and without the rotation.
        for k in 1..=20 {
            let s = k as f64 / 20.0;
            let f = Mat3::new(
                1.0 + 0.1 * s,
                0.2 * s,
                0.0,
                0.0,
                1.0 - 0.03 * s,
                0.05 * s,
                0.0,
                0.0,
                1.0,
            );
            let r1 = law.evaluate(&f, 0.0, &mut h1).unwrap();
            let r2 = law.evaluate(&(q * f), 0.0, &mut h2).unwrap();
            let s1 = crate::law::cauchy_from_pk2(&f, &r1.pk2);
            let s2 = crate::law::cauchy_from_pk2(&(q * f), &r2.pk2);
            let scale = s1.norm();
            assert!(
                (s2 - q * s1 * q.transpose()).norm() < 1e-9 * scale,
                "{:e}",
                (s2 - q * s1 * q.transpose()).norm() / scale
            );
            assert!((r1.pk2 - r2.pk2).norm() < 1e-9 * scale);
        }
        assert!(
            h1[0] > 0.01 && (h1[0] - h2[0]).abs() < 1e-12,
            "{} {}",
            h1[0],
            h2[0]
        );
    }

    #[test]
    fn failure_strain_is_reported() {
        let law = ribs();
        let mut h = [0.0; 7];
        let f = Mat3::from_diagonal(&Vector3::new(1.2, 0.95, 0.95));
        assert!(!law.evaluate(&f, 0.0, &mut h).unwrap().failed);
        let f = Mat3::from_diagonal(&Vector3::new(2.5, 0.7, 0.7));
        let r = law.evaluate(&f, 0.0, &mut h).unwrap();
        assert!(r.failed && h[0] >= 0.5, "{}", h[0]);
    }
}
