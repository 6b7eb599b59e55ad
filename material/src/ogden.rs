//! N-term Ogden solid with an optional Prony-series viscoelastic part: the liver of the
//! reference study (paper eqs. 1-3).
//!
//! # Elastic part (paper eq. 1, the *original* Ogden form, as in LS-DYNA)
//!
//! ```text
//! Psi = sum_p mu_p / alpha_p (lb_1^a_p + lb_2^a_p + lb_3^a_p - 3) + U(J),
//! lb_i = J^(-1/3) l_i  (isochoric principal stretches),   U(J) = K/2 (ln J)^2.
//! ```
//!
//! Principal Kirchhoff stresses (`tau_i = l_i dPsi/dl_i`):
//!
//! ```text
//! tau_i = sum_p mu_p (lb_i^a_p - 1/3 sum_j lb_j^a_p) + K ln J,
//! S     = sum_i tau_i / l_i^2  N_i (x) N_i                 (N_i: eigenvectors of C).
//! ```
//!
//! The volumetric function `U = K/2 (ln J)^2` gives the Kirchhoff pressure `K ln J`; it is convex
//! in `ln J` and stays finite at large compression. The initial shear modulus is
//! `mu0 = 1/2 sum_p mu_p alpha_p`. The bulk modulus `K` is given directly, or from a Poisson
//! ratio: `K = 2 mu0 (1 + nu) / (3 (1 - 2 nu))` (paper liver: mu0 = 647.85 Pa, nu = 0.49,
//! K = 32.2 kPa). A set with `mu0 <= 0` is refused; so is `alpha_p = 0`.
//!
//! **Convention warning.** Abaqus, CalculiX, FElupe (and Nastran, Radioss law 42) write
//! `Psi = sum_p 2 mu_p / alpha_p^2 (...)`, in which `mu0 = sum_p mu_p`. The same numbers fed to the
//! two forms are two different materials (the paper's liver read the Abaqus way has
//! `mu0 = 6.4 Pa` instead of 648 Pa). Scene cards take the original form by default; write
//! `convention = "abaqus"` to enter Abaqus-style constants, which are converted with
//! `mu_original = 2 mu_abaqus / alpha`.
//!
//! Powers are evaluated as `exp(alpha ln lb)` from the logarithmic stretches, so no
//! intermediate overflows: alpha = 19.07 at stretch 2 is 5.5e5, alpha = -10.96 at 0.3 is 5.4e5.
//! Principal stretches come from the shared eigen-kernel ([`crate::principal`]); the stress
//! formula has no division by stretch differences, so equal or nearly equal stretches are exact.
//!
//! # Viscous part (paper eqs. 2-3)
//!
//! ```text
//! S(t) = S_inf(t) + sum_i h_i(t),   h_i(t) = int_0^t 2 G_i exp(-(t - s)/tau_i) dE/ds ds.
//! ```
//!
//! `G(t) = sum_i G_i exp(-t/tau_i)` is read as a *shear* relaxation modulus, hence the factor 2:
//! at small strain a term adds `G_i` to the instantaneous shear modulus (`S_12 = 2 G_i E_12 =
//! G_i gamma`), as LS-DYNA's Prony terms do. With `prony_on = "green_lagrange"` (default, eq. 2
//! as written) `E` is the full Green-Lagrange strain `(C - I)/2`, so each term also adds
//! `2/3 G_i` of instantaneous bulk modulus; with `prony_on = "deviatoric"`, `E` is replaced by
//! `dev E = E - tr(E)/3 I` and the viscous response is purely deviatoric at small strain.
//!
//! Update (exact for a strain that is linear in time over the step; Taylor, Pister & Goudreau
//! 1970, Simo & Hughes, *Computational Inelasticity*, sec. 10.3):
//!
//! ```text
//! h_i^{n+1} = exp(-dt/tau_i) h_i^n + 2 G_i (1 - exp(-dt/tau_i)) / (dt/tau_i) (E^{n+1} - E^n).
//! ```
//!
//! The factors `exp(-dt/tau_i)`, `2 G_i (1 - exp(-dt/tau_i)) / (dt/tau_i)` and the dissipation
//! weights `dt / (4 G_i tau_i)` depend only on the law and `dt`; each thread keeps the last set it
//! computed, keyed on the law's identity and the bits of `dt`, so the `exp_m1` and the divisions
//! run once per law and step length instead of at every point (a hit returns exactly the
//! recomputed numbers: results are the same with or without the cache).
//!
//! History per point: 6 numbers per term (`h_i`, Sym6) followed by the 6 of `E^n`.
//! Decay constants `beta_i = 1/tau_i` (LS-DYNA cards) are accepted by the scene card.
//!
//! Dissipation: term `i` is a Maxwell element whose dashpot dissipates `|h_i|^2 / (2 G_i tau_i)`
//! per unit time; the step's dissipation is its trapezoidal integral
//! `dt / (4 G_i tau_i) (|h_i^n|^2 + |h_i^{n+1}|^2) >= 0` (J per m^3 of reference volume).
//!
//! # Wave speed
//!
//! `c^2 = M / rho_0` with a conservative bound `M` on the longitudinal Kirchhoff tangent in the
//! current state (Kirchhoff moduli over rho_0 equal Cauchy moduli over the current density):
//!
//! ```text
//! M = K max(1, 1 - 2 ln J) + 4/3 mu_eff + 2 max_i |tau_iso_i| + M_visc,
//! mu_eff = 1/2 sum_p |mu_p alpha_p| max_i lb_i^a_p      (stretch-stiffened shear modulus),
//! M_visc = 2 sum G_i l_max^4   (green_lagrange)   or   4/3 sum G_i l_max^4   (deviatoric).
//! ```
//!
//! At the reference state this is `K + 4/3 mu0 + M_visc(1)` exactly (when every
//! `mu_p alpha_p > 0`). `l_max^4` is the square of the largest eigenvalue of `C`.

use std::cell::RefCell;
use std::sync::atomic::{AtomicU64, Ordering};

use crate::law::{faults, full, Law, LawOut};
use crate::principal::{all_finite6, ddot6, Principal, Sym6};
use crate::real::{Mask, Real};
use crate::tensor::{det, M3};

/// Most Ogden terms a card may give.
pub const MAX_TERMS: usize = 6;
/// Most Prony terms a card may give.
pub const MAX_PRONY: usize = 8;

/// Which strain the Prony series acts on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PronyOn {
    /// The full Green-Lagrange strain (paper eq. 2; default).
    GreenLagrange,
    /// The deviatoric part `E - tr(E)/3 I`.
    Deviatoric,
}

/// One Prony term.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PronyTerm {
    /// Shear relaxation modulus G_i (Pa).
    pub modulus: f64,
    /// Relaxation time tau_i (s).
    pub tau: f64,
}

/// N-term Ogden law with optional Prony series.
#[derive(Clone, Debug)]
pub struct Ogden {
    /// Reference density (kg/m^3).
    pub rho: f64,
    n: usize,
    mu: [f64; MAX_TERMS],
    alpha: [f64; MAX_TERMS],
    /// Bulk modulus K (Pa).
    pub bulk: f64,
    np: usize,
    prony: [PronyTerm; MAX_PRONY],
    /// Strain the Prony series acts on.
    pub prony_on: PronyOn,
    /// `|mu_p alpha_p| / 2` (Pa), for the stretch-stiffened shear modulus bound.
    half_abs_mu_alpha: [f64; MAX_TERMS],
    /// `sum_i G_i` (Pa).
    prony_sum: f64,
    /// Identifies this law's (immutable, private) Prony terms in the per-thread cache of step
    /// factors; clones share it, as they share the terms.
    id: u64,
}

/// Source of [`Ogden`] identities.
static NEXT_ID: AtomicU64 = AtomicU64::new(1);

/// The Prony step factors of one law and one step length, per term `i`:
/// `a_i = exp(-dt/tau_i)`, `g_i = 2 G_i (1 - a_i) / (dt/tau_i)` (`a_i = 1`, `g_i = 2 G_i` for
/// `dt = 0`) and `w_i = dt / (4 G_i tau_i)` (the dissipation weight).
#[derive(Clone, Copy)]
struct PronyFactors {
    /// Law id and `dt.to_bits()` the factors were computed for (id 0: empty).
    key: (u64, u64),
    f: [[f64; 3]; MAX_PRONY],
}

thread_local! {
    /// The last Prony step factors this thread computed. An explicit step evaluates every
    /// integration point of a group with the same `dt`, so this saves the `exp_m1` and the
    /// divisions of every term at all but the first point. A hit returns exactly the numbers a
    /// recomputation would (a pure function of the key), so results do not depend on the
    /// cache's state or on the thread schedule.
    static PRONY_CACHE: RefCell<PronyFactors> = const {
        RefCell::new(PronyFactors {
            key: (0, 0),
            f: [[0.0; 3]; MAX_PRONY],
        })
    };
}

impl Ogden {
    /// Build from `mu_p` (Pa, original form), `alpha_p`, the bulk modulus (Pa) and Prony terms.
    /// `name` is the material's name for error messages.
    pub fn new(
        name: &str,
        rho: f64,
        mu: &[f64],
        alpha: &[f64],
        bulk: f64,
        prony: &[PronyTerm],
        prony_on: PronyOn,
    ) -> Result<Ogden, String> {
        if mu.is_empty() || mu.len() != alpha.len() {
            return Err(format!(
                "material `{name}`: `mu` and `alpha` must be non-empty lists of the same length (got {} and {})",
                mu.len(),
                alpha.len()
            ));
        }
        if mu.len() > MAX_TERMS {
            return Err(format!(
                "material `{name}`: at most {MAX_TERMS} Ogden terms"
            ));
        }
        if prony.len() > MAX_PRONY {
            return Err(format!(
                "material `{name}`: at most {MAX_PRONY} Prony terms"
            ));
        }
        if alpha.iter().any(|a| *a == 0.0 || !a.is_finite()) || mu.iter().any(|m| !m.is_finite()) {
            return Err(format!(
                "material `{name}`: every `alpha` must be finite and non-zero"
            ));
        }
        let mu0 = Self::mu0_of(mu, alpha);
        if !(mu0 > 0.0) {
            return Err(format!(
                "material `{name}`: the Ogden constants give an initial shear modulus mu0 = 1/2 sum mu_p alpha_p = {mu0:.4e} Pa <= 0: \
                 the material is unstable. The card takes the original (LS-DYNA) form mu_p/alpha_p; for Abaqus/CalculiX/FElupe \
                 constants (2 mu_p/alpha_p^2) write convention = \"abaqus\""
            ));
        }
        if !(rho > 0.0 && rho.is_finite()) {
            return Err(format!("material `{name}`: `density` must be positive"));
        }
        if !(bulk > 0.0 && bulk.is_finite()) {
            return Err(format!(
                "material `{name}`: the bulk modulus must be positive, got {bulk:e} Pa"
            ));
        }
        for t in prony {
            if !(t.modulus > 0.0 && t.modulus.is_finite() && t.tau > 0.0 && t.tau.is_finite()) {
                return Err(format!(
                    "material `{name}`: every Prony term needs a positive modulus and relaxation time (got {} Pa, {} s)",
                    t.modulus, t.tau
                ));
            }
        }
        let mut o = Ogden {
            rho,
            n: mu.len(),
            mu: [0.0; MAX_TERMS],
            alpha: [1.0; MAX_TERMS],
            bulk,
            np: prony.len(),
            prony: [PronyTerm::default(); MAX_PRONY],
            prony_on,
            half_abs_mu_alpha: [0.0; MAX_TERMS],
            prony_sum: prony.iter().map(|t| t.modulus).sum(),
            id: NEXT_ID.fetch_add(1, Ordering::Relaxed),
        };
        o.mu[..mu.len()].copy_from_slice(mu);
        o.alpha[..alpha.len()].copy_from_slice(alpha);
        o.prony[..prony.len()].copy_from_slice(prony);
        for k in 0..mu.len() {
            o.half_abs_mu_alpha[k] = 0.5 * (mu[k] * alpha[k]).abs();
        }
        Ok(o)
    }

    /// `mu0 = 1/2 sum mu_p alpha_p` (Pa).
    pub fn mu0_of(mu: &[f64], alpha: &[f64]) -> f64 {
        0.5 * mu.iter().zip(alpha).map(|(m, a)| m * a).sum::<f64>()
    }

    /// Initial shear modulus mu0 (Pa).
    pub fn mu0(&self) -> f64 {
        Self::mu0_of(self.mu(), self.alpha())
    }

    /// Ogden moduli mu_p (Pa, original form).
    pub fn mu(&self) -> &[f64] {
        &self.mu[..self.n]
    }

    /// Ogden exponents alpha_p.
    pub fn alpha(&self) -> &[f64] {
        &self.alpha[..self.n]
    }

    /// Prony terms.
    pub fn prony(&self) -> &[PronyTerm] {
        &self.prony[..self.np]
    }

    /// Elastic small-strain shear modulus mu0 = 1/2 sum |mu_p alpha_p| and the summed Prony
    /// moduli.
    fn initial_shear_parts(&self) -> (f64, f64) {
        let g: f64 = self.prony().iter().map(|t| t.modulus).sum();
        let mu_eff: f64 = 0.5
            * self
                .mu()
                .iter()
                .zip(self.alpha())
                .map(|(m, a)| (m * a).abs())
                .sum::<f64>();
        (mu_eff, g)
    }

    fn visc_modulus_factor(&self) -> f64 {
        match self.prony_on {
            PronyOn::GreenLagrange => 2.0,
            PronyOn::Deviatoric => 4.0 / 3.0,
        }
    }

    /// The Prony step factors `(a_i, g_i, w_i)` for a step `dt` (see [`PronyFactors`]).
    fn compute_prony_factors(&self, dt: f64) -> PronyFactors {
        let mut f = [[0.0; 3]; MAX_PRONY];
        for (i, term) in self.prony().iter().enumerate() {
            let x = dt / term.tau;
            let (a, b) = if x > 0.0 {
                let em1 = (-x).exp_m1();
                (1.0 + em1, -em1 / x)
            } else {
                (1.0, 1.0)
            };
            f[i] = [
                a,
                2.0 * term.modulus * b,
                dt / (4.0 * term.modulus * term.tau),
            ];
        }
        PronyFactors {
            key: (self.id, dt.to_bits()),
            f,
        }
    }

    /// The Prony step factors of `dt`, from this thread's cache when it holds them.
    #[inline(always)]
    fn prony_factors(&self, dt: f64) -> PronyFactors {
        PRONY_CACHE.with(|cache| {
            let key = (self.id, dt.to_bits());
            if cache.borrow().key != key {
                *cache.borrow_mut() = self.compute_prony_factors(dt);
            }
            *cache.borrow()
        })
    }

    /// Update the Prony history for the strain increment `de` over a step `dt`; returns the
    /// summed viscous stresses `sum_i h_i` and the step's dissipation.
    #[inline(always)]
    fn prony_update<R: Real>(&self, dt: f64, de: &Sym6<R>, hs: &mut [R]) -> (Sym6<R>, R) {
        let factors = self.prony_factors(dt);
        let mut sv: Sym6<R> = [R::zero(); 6];
        let mut dissipation = R::zero();
        for (h, &[a, g, w]) in hs.chunks_exact_mut(6).zip(&factors.f[..self.np]) {
            let old: Sym6<R> = [h[0], h[1], h[2], h[3], h[4], h[5]];
            let mut new: Sym6<R> = [R::zero(); 6];
            for k in 0..6 {
                new[k] = old[k] * a + de[k] * g;
                sv[k] += new[k];
            }
            h.copy_from_slice(&new);
            dissipation += (ddot6(&old, &old) + ddot6(&new, &new)) * w;
        }
        (sv, dissipation)
    }

    /// Principal Kirchhoff stresses of the elastic (long-term) part, the stretch-stiffened shear
    /// modulus bound and the largest |tau_iso|.
    #[inline(always)]
    fn elastic_kirchhoff<R: Real>(&self, p: &Principal<R>) -> ([R; 3], R, R) {
        let lb = p.ln_isochoric();
        let mut tau = [R::zero(); 3];
        let mut mu_eff = R::zero();
        for k in 0..self.n {
            let (m, a) = (self.mu[k], self.alpha[k]);
            let e = [(lb[0] * a).exp(), (lb[1] * a).exp(), (lb[2] * a).exp()];
            let mean = (e[0] + e[1] + e[2]) * (1.0 / 3.0);
            tau[0] += (e[0] - mean) * m;
            tau[1] += (e[1] - mean) * m;
            tau[2] += (e[2] - mean) * m;
            mu_eff += e[0].max(e[1]).max(e[2]) * self.half_abs_mu_alpha[k];
        }
        let tmax = tau[0].abs().max(tau[1].abs()).max(tau[2].abs());
        let pk = p.ln_j * self.bulk;
        ([tau[0] + pk, tau[1] + pk, tau[2] + pk], mu_eff, tmax)
    }
}

impl Law for Ogden {
    fn density(&self) -> f64 {
        self.rho
    }
    fn history_len(&self) -> usize {
        if self.np == 0 {
            0
        } else {
            6 * (self.np + 1)
        }
    }
    fn init_history(&self, h: &mut [f64]) {
        h.iter_mut().for_each(|x| *x = 0.0);
    }
    fn history_names(&self) -> Vec<String> {
        if self.np == 0 {
            return Vec::new();
        }
        let c = ["xx", "yy", "zz", "xy", "yz", "zx"];
        let mut v = Vec::new();
        for i in 0..self.np {
            for s in c {
                v.push(format!("prony{}_{s}", i + 1));
            }
        }
        let e = match self.prony_on {
            PronyOn::GreenLagrange => "E",
            PronyOn::Deviatoric => "Edev",
        };
        for s in c {
            v.push(format!("{e}_{s}"));
        }
        v
    }
    fn initial_wave_speed(&self) -> f64 {
        let (mu_eff, g) = self.initial_shear_parts();
        ((self.bulk + 4.0 / 3.0 * mu_eff + self.visc_modulus_factor() * g) / self.rho).sqrt()
    }

    fn initial_shear_modulus(&self) -> f64 {
        // The Prony term adds visc_modulus_factor * g to the P-wave modulus, i.e. 3/4 of that
        // to the shear modulus.
        let (mu_eff, g) = self.initial_shear_parts();
        mu_eff + 0.75 * self.visc_modulus_factor() * g
    }

    fn name(&self) -> &'static str {
        "ogden"
    }

    #[inline(always)]
    fn stress<R: Real>(&self, f: &M3<R>, dt: f64, history: &mut [R]) -> LawOut<R> {
        let j = det(f);
        let (p, collapsed) = Principal::of(f);
        let (tau, mu_eff, tmax) = self.elastic_kirchhoff(&p);
        let mut pk2 = p.pk2_from_kirchhoff(&tau);
        let mut m = (R::splat(1.0) - p.ln_j * 2.0).max(R::splat(1.0)) * self.bulk
            + mu_eff * (4.0 / 3.0)
            + tmax * 2.0;
        let mut dissipation = R::zero();
        if self.np > 0 {
            let c1 = &p.c_minus_i;
            let mut e: Sym6<R> = crate::arr![6, |k| c1[k] * 0.5];
            if self.prony_on == PronyOn::Deviatoric {
                let t = (e[0] + e[1] + e[2]) * (1.0 / 3.0);
                e[0] -= t;
                e[1] -= t;
                e[2] -= t;
            }
            let (hs, eprev) = history.split_at_mut(6 * self.np);
            let eprev: &mut [R] = &mut eprev[..6];
            let mut de = [R::zero(); 6];
            for k in 0..6 {
                de[k] = e[k] - eprev[k];
                eprev[k] = e[k];
            }
            let (sv, d) = self.prony_update(dt, &de, hs);
            for k in 0..6 {
                pk2[k] += sv[k];
            }
            dissipation = d;
            // exp(4 ln l_max) = l_max^4.
            let l2max = p.stretch_sq[0].max(p.stretch_sq[1]).max(p.stretch_sq[2]);
            m += (l2max * l2max).max(R::splat(1.0)) * (self.visc_modulus_factor() * self.prony_sum);
        }
        let wave_speed = (m / self.rho).sqrt();
        let finite = wave_speed.is_finite() & all_finite6(&pk2) & dissipation.is_finite();
        let (fault, fault_value) = faults(j, collapsed, finite);
        LawOut {
            pk2: full(&pk2),
            wave_speed,
            dissipation,
            failed: R::Mask::splat(false),
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

    const MU: [f64; 3] = [89.14, 9.965, -92.75];
    const ALPHA: [f64; 3] = [1.0, 19.0656, -10.9604];

    fn liver_elastic(k: f64) -> Ogden {
        Ogden::new("liver", 1050.0, &MU, &ALPHA, k, &[], PronyOn::GreenLagrange).unwrap()
    }

    /// Closed-form principal Kirchhoff stress for a diagonal F.
    fn tau_closed(o: &Ogden, l: [f64; 3]) -> [f64; 3] {
        let j = l[0] * l[1] * l[2];
        let lb = l.map(|x| x * j.powf(-1.0 / 3.0));
        let mut t = [o.bulk * j.ln(); 3];
        for k in 0..3 {
            let s: f64 = lb.iter().map(|x| x.powf(ALPHA[k])).sum::<f64>() / 3.0;
            for i in 0..3 {
                t[i] += MU[k] * (lb[i].powf(ALPHA[k]) - s);
            }
        }
        t
    }

    #[test]
    fn paper_liver_mu0_and_bulk() {
        let mu0 = Ogden::mu0_of(&MU, &ALPHA);
        assert!((mu0 - 647.85).abs() < 0.01, "{mu0}");
        let k = 2.0 * mu0 * 1.49 / (3.0 * 0.02);
        assert!((k - 32_177.0).abs() < 5.0, "{k}");
    }

    #[test]
    fn non_positive_mu0_is_refused_by_name() {
        // The paper's constants with every alpha sign flipped: mu0 < 0.
        let e = Ogden::new(
            "bad liver",
            1050.0,
            &MU,
            &[-1.0, -19.0656, 10.9604],
            1e4,
            &[],
            PronyOn::GreenLagrange,
        )
        .unwrap_err();
        assert!(e.contains("bad liver") && e.contains("mu0"), "{e}");
        let e = Ogden::new(
            "x",
            1050.0,
            &[1.0, -1.0],
            &[2.0, 2.0],
            1e4,
            &[],
            PronyOn::GreenLagrange,
        )
        .unwrap_err();
        assert!(e.contains("mu0"), "{e}");
    }

    #[test]
    fn equal_and_nearly_equal_stretches_are_exact() {
        let o = liver_elastic(32_177.0);
        let r = Rotation3::from_euler_angles(0.7, -0.4, 1.9).into_inner();
        let q = Rotation3::from_euler_angles(-1.1, 0.3, 0.5).into_inner();
        for l in [
            [1.3, 1.3, 1.3],
            [1.3, 0.9, 0.9],
            [1.3, 0.9, 0.9 + 1e-8],
            [1.0, 1.0 + 1e-8, 1.0 - 1e-8],
            [0.6, 0.6 + 1e-8, 1.5],
        ] {
            // F = R diag(l) Q^T: S must be Q diag(tau_i / l_i^2) Q^T.
            let f = r * Mat3::from_diagonal(&Vector3::from(l)) * q.transpose();
            let s = o.evaluate(&f, 0.0, &mut []).unwrap().pk2;
            let t = tau_closed(&o, l);
            let s_ref =
                q * Mat3::from_diagonal(&Vector3::new(
                    t[0] / (l[0] * l[0]),
                    t[1] / (l[1] * l[1]),
                    t[2] / (l[2] * l[2]),
                )) * q.transpose();
            let scale = s_ref.norm().max(o.mu0() * 1e-6);
            assert!(
                (s - s_ref).norm() <= 1e-9 * scale.max(1.0),
                "l={l:?}: err {:e} of {scale:e}",
                (s - s_ref).norm()
            );
        }
    }

    #[test]
    fn large_alpha_does_not_overflow() {
        let o = liver_elastic(32_177.0);
        for l in [2.0, 0.3, 3.0, 0.2] {
            let f = Mat3::from_diagonal(&Vector3::new(l, 1.0 / l.sqrt(), 1.0 / l.sqrt()));
            let r = o.evaluate(&f, 0.0, &mut []).unwrap();
            let t = tau_closed(&o, [l, 1.0 / l.sqrt(), 1.0 / l.sqrt()]);
            let s11 = t[0] / (l * l);
            assert!(r.pk2.iter().all(|x| x.is_finite()) && r.wave_speed.is_finite());
            assert!(
                (r.pk2[(0, 0)] - s11).abs() <= 1e-10 * s11.abs(),
                "l={l}: {} vs {s11}",
                r.pk2[(0, 0)]
            );
        }
        // Stretch 2 with alpha = 19.07: lb^alpha = 2^19.07 ~ 5.5e5, the stress is ~ mu * 5.5e5 / l^2.
        let f = Mat3::from_diagonal(&Vector3::new(2.0, 1.0 / 2f64.sqrt(), 1.0 / 2f64.sqrt()));
        let s = o.evaluate(&f, 0.0, &mut []).unwrap().pk2[(0, 0)];
        assert!(s > 1e5 && s < 1e7, "{s}");
    }

    #[test]
    fn inverted_is_an_error_not_nan() {
        let o = liver_elastic(32_177.0);
        let f = Mat3::from_diagonal(&Vector3::new(-1.0, 1.0, 1.0));
        assert!(matches!(
            o.evaluate(&f, 0.0, &mut []),
            Err(LawError::NonPositiveJacobian(_))
        ));
        let f = Mat3::from_diagonal(&Vector3::new(0.0, 1.0, 1.0));
        assert!(matches!(
            o.evaluate(&f, 0.0, &mut []),
            Err(LawError::NonPositiveJacobian(_))
        ));
    }

    #[test]
    fn small_strain_prony_adds_shear_modulus_gi() {
        let g = 1000.0;
        let o = Ogden::new(
            "x",
            1000.0,
            &[2.0],
            &[2.0],
            1e6,
            &[PronyTerm {
                modulus: g,
                tau: 1.0,
            }],
            PronyOn::Deviatoric,
        )
        .unwrap();
        let gamma = 1e-6;
        let f = Mat3::new(1.0, gamma, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
        let mut h = vec![0.0; o.history_len()];
        let r = o.evaluate(&f, 0.0, &mut h).unwrap();
        // Instantaneous: mu0 + G = 2 + 1000.
        let s12 = r.pk2[(0, 1)];
        assert!((s12 / gamma - 1002.0).abs() < 1e-3, "{}", s12 / gamma);
        let m = Ogden::new(
            "x",
            1000.0,
            &[2.0],
            &[2.0],
            1e6,
            &[PronyTerm {
                modulus: g,
                tau: 1.0,
            }],
            PronyOn::GreenLagrange,
        )
        .unwrap();
        let c0 = m.initial_wave_speed();
        assert!((c0 - ((1e6 + 4.0 / 3.0 * 2.0 + 2.0 * g) / 1000.0f64).sqrt()).abs() < 1e-9);
    }

    #[test]
    fn prony_factors_follow_the_law_and_the_step() {
        // Two laws with different relaxation times, evaluated in turn with changing steps on one
        // thread: every update must use its own law's exp(-dt/tau) and dt.
        let law = |tau: f64| {
            Ogden::new(
                "x",
                1000.0,
                &[2.0],
                &[2.0],
                1e6,
                &[PronyTerm {
                    modulus: 1000.0,
                    tau,
                }],
                PronyOn::GreenLagrange,
            )
            .unwrap()
        };
        let laws = [law(1e-3), law(5e-2)];
        let mut hist = [vec![0.0; 12], vec![0.0; 12]];
        for k in 1..=12 {
            let i = k % 2;
            let dt = [1e-4, 3e-4, 0.0][(k / 2) % 3];
            let g = 1e-3 * k as f64;
            let f = Mat3::new(1.0, g, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
            let h = &mut hist[i];
            let (h_old, e_old) = (h[3], h[9]);
            laws[i].evaluate(&f, dt, h).unwrap();
            let x = dt / laws[i].prony()[0].tau;
            let (a, b) = if x > 0.0 {
                ((-x).exp(), (1.0 - (-x).exp()) / x)
            } else {
                (1.0, 1.0)
            };
            let want = a * h_old + 2.0 * 1000.0 * b * (0.5 * g - e_old);
            assert!(
                (h[3] - want).abs() <= 1e-12 * want.abs(),
                "k={k}: {} vs {want}",
                h[3]
            );
        }
        // A clone shares the terms and may share the cached factors.
        let c = laws[0].clone();
        let f = Mat3::new(1.0, 0.01, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
        let (mut h1, mut h2) = (vec![0.0; 12], vec![0.0; 12]);
        let r1 = laws[0].evaluate(&f, 1e-4, &mut h1).unwrap();
        let r2 = c.evaluate(&f, 1e-4, &mut h2).unwrap();
        assert_eq!(r1.pk2, r2.pk2);
        assert_eq!(h1, h2);
    }

    #[test]
    fn rigid_rotation_is_stress_free() {
        let o = liver_elastic(32_177.0);
        let r = Rotation3::from_euler_angles(0.3, 1.1, -0.7).into_inner();
        let s = o.evaluate(&r, 0.0, &mut []).unwrap().pk2;
        assert!(s.norm() < 1e-9, "{}", s.norm());
    }
}
