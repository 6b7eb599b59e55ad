//! Simplified rubber/foam (LS-DYNA `*MAT_SIMPLIFIED_RUBBER/FOAM`, MAT_181 style): the flesh of
//! the reference study.
//!
//! # Elastic part: Valanis-Landel driven by a uniaxial curve
//!
//! The strain energy is separable in the isochoric principal stretches (Valanis & Landel 1967):
//!
//! ```text
//! Psi = sum_i w(lb_i) + K/2 (ln J)^2,       lb_i = J^(-1/3) l_i,
//! tau_i = f(lb_i) - 1/3 sum_j f(lb_j) + K ln J,      f(l) = l w'(l),
//! S = sum_i tau_i / l_i^2 N_i (x) N_i.
//! ```
//!
//! `f` is not given but identified from a uniaxial nominal stress-stretch curve `P(l)`, as in
//! Kolling, Du Bois, Benson & Feng (2007), "A tabulated formulation of hyperelasticity with rate
//! effects and damping for the explicit finite element method", LS-DYNA Anwenderforum. In
//! incompressible uniaxial stress (`l_2 = l_3 = l^(-1/2)`, `sigma_2 = 0`) the law gives
//! `sigma_1 = l P(l) = f(l) - f(l^(-1/2))`. Writing `g(l) = l P(l)` and `x = ln l`, this
//! functional equation has the convergent solution (with `f(1) = 0`)
//!
//! ```text
//! f(x) = sum_{k >= 0} g(exp((-1/2)^k x)),
//! ```
//!
//! so the law reproduces its input curve exactly in incompressible uniaxial stress, and to
//! `O(G/K)` for a finite bulk modulus. `f` and `df/dx` are tabulated once, at build time, on a
//! uniform grid in `x = ln lb` over stretches 0.05 to 20 (4097 points) and evaluated by cubic
//! Hermite interpolation (error ~1e-13 G for the default curve; each interval stores its cubic's
//! four coefficients, evaluated by Horner's rule), with linear extrapolation in `x` beyond. The input curve is interpolated linearly in stretch and extrapolated linearly beyond
//! its ends (as LS-DYNA load curves are); a point (1, 0) is inserted if absent, and the stress
//! must increase strictly with stretch.
//!
//! Without a curve the default is the incompressible neo-Hookean curve `P = G (l - l^-2)`,
//! for which `f = G (l^2 - 1)` and the law is the compressible neo-Hookean solid on isochoric
//! stretches. The small-strain shear modulus is `f'(0)/2` (`= G` by default) and the small-strain
//! bulk modulus is `K` (the Kirchhoff pressure is `K ln J`).
//!
//! # Damping
//!
//! LS-DYNA's MAT_181 takes a dimensionless damping coefficient `MU` (0.05 to 0.5, paper: 0.40).
//! Here it is a Kelvin-Voigt deviatoric viscous stress whose viscosity scales with the time step,
//! like an artificial bulk viscosity: `eta = MU G dt`, so that
//!
//! ```text
//! S_v = 2 eta dev(dE/dt) = 2 MU G dev(E^{n+1} - E^n),       E = (C - I)/2,
//! ```
//!
//! with `G` the card's shear modulus (or `f'(0)/2` for a curve without one). It damps the
//! highest mesh frequencies (fraction of critical ~ `MU G / M` in the highest mode) and vanishes
//! under quasi-static loading; it makes the response depend on the step size, so a
//! material-point run with large steps shows it. History: `E^n` (6 numbers) when `MU > 0`.
//! Dissipation: `S_v : (E^{n+1} - E^n) >= 0`. LS-DYNA's frictional damping (`SIGF`) and rate
//! tables are not implemented.
//!
//! # Wave speed
//!
//! `c^2 = M / rho_0`, `M = K max(1, 1 - 2 ln J) + 2/3 max_i f'(ln lb_i) + 2 max_i |tau_dev_i|`
//! (`2/3 f'` is `4/3` times the current tangent shear modulus `f'/2`), times
//! `1 / (sqrt(1 + xi^2) - xi)^2` with `xi = MU G / M`, the reduction of the stable step that
//! stiffness-proportional damping causes. Paper flesh: `K = 2 GPa`, `G = 40 kPa`, rho = 1060:
//! `c = 1374 m/s`.

use crate::law::{faults, full, Law, LawOut};
use crate::principal::{all_finite6, ddot6, Principal, Sym6};
use crate::real::{Mask, Real};
use crate::tensor::{det, M3};

/// A uniaxial nominal stress-stretch curve.
#[derive(Clone, Debug, PartialEq)]
pub enum UniaxialCurve {
    /// `P = G (l - l^-2)` with `G` in Pa.
    NeoHookean(f64),
    /// Points (stretch, nominal stress in Pa), strictly increasing, through (1, 0).
    Table(Vec<f64>, Vec<f64>),
}

impl UniaxialCurve {
    /// Validate a table of (stretch, nominal stress in Pa) points.
    pub fn table(name: &str, points: &[(f64, f64)]) -> Result<UniaxialCurve, String> {
        if points.len() < 2 {
            return Err(format!(
                "material `{name}`: the uniaxial curve needs at least two points"
            ));
        }
        let mut l: Vec<f64> = Vec::with_capacity(points.len() + 1);
        let mut p: Vec<f64> = Vec::with_capacity(points.len() + 1);
        let pmax = points.iter().fold(0.0f64, |m, q| m.max(q.1.abs()));
        for (k, &(s, st)) in points.iter().enumerate() {
            if !(s > 0.0 && s.is_finite() && st.is_finite()) {
                return Err(format!("material `{name}`: curve point {} has stretch {s} and stress {st}: stretches must be positive", k + 1));
            }
            if let Some(&last) = l.last() {
                if s <= last {
                    return Err(format!(
                        "material `{name}`: curve stretches must increase strictly (point {})",
                        k + 1
                    ));
                }
            }
            if (s - 1.0).abs() < 1e-12 && st.abs() > 1e-9 * pmax {
                return Err(format!("material `{name}`: the curve must pass through (1, 0); it has stress {st:e} Pa at stretch 1"));
            }
            l.push(s);
            p.push(st);
        }
        if !l.iter().any(|s| (s - 1.0).abs() < 1e-12) {
            let at = l.partition_point(|&s| s < 1.0);
            l.insert(at, 1.0);
            p.insert(at, 0.0);
        }
        for k in 1..l.len() {
            if p[k] <= p[k - 1] {
                return Err(format!(
                    "material `{name}`: the uniaxial nominal stress must increase strictly with stretch (it does not between stretches {} and {})",
                    l[k - 1], l[k]
                ));
            }
        }
        Ok(UniaxialCurve::Table(l, p))
    }

    /// Nominal stress (Pa) and its derivative dP/dl at stretch `l`.
    pub fn nominal(&self, l: f64) -> (f64, f64) {
        match self {
            UniaxialCurve::NeoHookean(g) => {
                (g * (l - 1.0 / (l * l)), g * (1.0 + 2.0 / (l * l * l)))
            }
            UniaxialCurve::Table(s, p) => {
                let n = s.len();
                let k = s.partition_point(|&x| x <= l).clamp(1, n - 1);
                let slope = (p[k] - p[k - 1]) / (s[k] - s[k - 1]);
                (p[k - 1] + slope * (l - s[k - 1]), slope)
            }
        }
    }
}

const X_MIN: f64 = -2.995_732_273_553_991; // ln 0.05
const X_MAX: f64 = 2.995_732_273_553_991; // ln 20
const N_GRID: usize = 4097;

/// Simplified rubber/foam law.
#[derive(Clone, Debug)]
pub struct Foam {
    /// Reference density (kg/m^3).
    pub rho: f64,
    /// Bulk modulus K (Pa).
    pub bulk: f64,
    /// Shear modulus used by the damping term (Pa).
    pub shear: f64,
    /// Dimensionless damping coefficient MU.
    pub damping: f64,
    /// The uniaxial curve the law was built from.
    pub curve: UniaxialCurve,
    inv_h: f64,
    h: f64,
    /// Per grid interval `k`, the cubic Hermite interpolant `f = c0 + s (c1 + s (c2 + s c3))` in
    /// the local coordinate `s = (x - x_k)/h` in [0, 1].
    cubic: Vec<[f64; 4]>,
    /// `(f, h df/dx)` at the first and the last grid point, for the linear extrapolation.
    ends: [[f64; 2]; 2],
}

impl Foam {
    /// Build the law; `shear` (Pa) is required without a curve and optional with one.
    pub fn new(
        name: &str,
        rho: f64,
        bulk: f64,
        shear: Option<f64>,
        damping: f64,
        curve: Option<UniaxialCurve>,
    ) -> Result<Foam, String> {
        let pos = |what: &str, v: f64| {
            if v > 0.0 && v.is_finite() {
                Ok(v)
            } else {
                Err(format!(
                    "material `{name}`: `{what}` must be positive, got {v:e} (SI)"
                ))
            }
        };
        pos("density", rho)?;
        pos("bulk_modulus", bulk)?;
        if !(damping >= 0.0 && damping.is_finite()) {
            return Err(format!(
                "material `{name}`: `damping` must be >= 0, got {damping}"
            ));
        }
        let curve = match (curve, shear) {
            (Some(c), _) => c,
            (None, Some(g)) => UniaxialCurve::NeoHookean(pos("shear_modulus", g)?),
            (None, None) => {
                return Err(format!(
                    "material `{name}`: give `shear_modulus` (default curve P = G (l - l^-2)) or a uniaxial `curve`/`curve_file`"
                ))
            }
        };
        let h = (X_MAX - X_MIN) / (N_GRID - 1) as f64;
        let table: Vec<[f64; 2]> = (0..N_GRID)
            .map(|k| {
                let x = if k == (N_GRID - 1) / 2 {
                    0.0
                } else {
                    X_MIN + k as f64 * h
                };
                let (f, df) = series(&curve, x);
                [f, df * h]
            })
            .collect();
        // Hermite data (f_k, h f'_k), (f_k+1, h f'_k+1) on an interval give the cubic
        // c0 = f_k, c1 = h f'_k, c2 = 3 (f_k+1 - f_k) - 2 h f'_k - h f'_k+1,
        // c3 = 2 (f_k - f_k+1) + h f'_k + h f'_k+1.
        let cubic = table
            .windows(2)
            .map(|w| {
                let ([f0, d0], [f1, d1]) = (w[0], w[1]);
                [
                    f0,
                    d0,
                    3.0 * (f1 - f0) - 2.0 * d0 - d1,
                    2.0 * (f0 - f1) + d0 + d1,
                ]
            })
            .collect();
        let mut law = Foam {
            rho,
            bulk,
            shear: 0.0,
            damping,
            curve,
            inv_h: 1.0 / h,
            h,
            cubic,
            ends: [table[0], table[N_GRID - 1]],
        };
        let g0 = 0.5 * law.f_and_slope(0.0).1;
        if !(g0 > 0.0) {
            return Err(format!(
                "material `{name}`: the curve gives a non-positive small-strain shear modulus"
            ));
        }
        law.shear = match shear {
            Some(g) => pos("shear_modulus", g)?,
            None => g0,
        };
        Ok(law)
    }

    /// `f(x)` and `df/dx` at `x = ln lb` (Pa).
    #[inline(always)]
    pub fn f_and_slope(&self, x: f64) -> (f64, f64) {
        self.f_and_slope_r(x)
    }

    /// [`Foam::f_and_slope`] in every lane: the interval's cubic is fetched per lane (a gather),
    /// the rest is lane-wise, and lanes beyond the table take its linear extrapolation.
    #[inline(always)]
    pub fn f_and_slope_r<R: Real>(&self, x: R) -> (R, R) {
        let t = (x - X_MIN) * self.inv_h;
        let n = (N_GRID - 1) as f64;
        let below = t.le(R::zero());
        let above = t.ge(R::splat(n));
        // The gather: plain arrays per coefficient, loaded as whole lane vectors afterwards.
        let mut tl = [0.0; crate::real::LANES];
        t.write_to(&mut tl);
        let mut cl = [[0.0; crate::real::LANES]; 5];
        for l in 0..R::LANES {
            // Truncation inside the table; clamped (NaN to 0) so that every lane reads a cubic.
            let k = (tl[l].clamp(0.0, n - 1.0) as u32 as usize).min(N_GRID - 2);
            let q = &self.cubic[k];
            cl[0][l] = q[0];
            cl[1][l] = q[1];
            cl[2][l] = q[2];
            cl[3][l] = q[3];
            cl[4][l] = k as f64;
        }
        let [c0, c1, c2, c3, kf] = crate::arr![5, |i| R::from_slice(&cl[i])];
        let s = t - kf;
        let f = c0 + s * (c1 + s * (c2 + s * c3));
        let df = c1 + s * (c2 * 2.0 + s * 3.0 * c3);
        let [[f0, d0], [f1, d1]] = self.ends;
        let f = R::select(below, t * d0 + f0, R::select(above, (t - n) * d1 + f1, f));
        let df = R::select(below, R::splat(d0), R::select(above, R::splat(d1), df));
        (f, df * self.inv_h)
    }

    /// Grid spacing of the table in ln(stretch).
    pub fn grid_spacing(&self) -> f64 {
        self.h
    }
}

/// `f(x) = sum_k g(exp((-1/2)^k x))` and its derivative, with `g(l) = l P(l)`.
///
/// Terms are summed while `|x_k| > 1e-10`; the tail is `g'(0) x_k 2/3` (and `w_k 2/3 g'(0)` for
/// the derivative), with `g'(0) = P'(1)` (the mean of both sides at a kink of a table).
fn series(curve: &UniaxialCurve, x: f64) -> (f64, f64) {
    let mut f = 0.0;
    let mut df = 0.0;
    let mut xk = x;
    let mut w = 1.0; // d xk / dx
    while xk.abs() > 1e-10 {
        let l = xk.exp();
        let (p, dp) = curve.nominal(l);
        f += l * p;
        // d(l P)/dx_k = l (P + l P')
        df += w * l * (p + l * dp);
        xk *= -0.5;
        w *= -0.5;
    }
    let g0 = 0.5 * (curve.nominal(1.0 - 1e-9).1 + curve.nominal(1.0 + 1e-9).1);
    (f + g0 * xk * (2.0 / 3.0), df + g0 * w * (2.0 / 3.0))
}

impl Law for Foam {
    fn density(&self) -> f64 {
        self.rho
    }
    fn history_len(&self) -> usize {
        if self.damping > 0.0 {
            6
        } else {
            0
        }
    }
    fn init_history(&self, h: &mut [f64]) {
        h.iter_mut().for_each(|x| *x = 0.0);
    }
    fn history_names(&self) -> Vec<String> {
        if self.damping > 0.0 {
            ["E_xx", "E_yy", "E_zz", "E_xy", "E_yz", "E_zx"]
                .iter()
                .map(|s| s.to_string())
                .collect()
        } else {
            Vec::new()
        }
    }
    fn initial_wave_speed(&self) -> f64 {
        let m = self.bulk + 2.0 / 3.0 * self.f_and_slope(0.0).1;
        damped_wave_speed::<f64>(m, self.damping * self.shear, self.rho)
    }

    fn initial_shear_modulus(&self) -> f64 {
        self.f_and_slope(0.0).1 / 2.0
    }

    fn name(&self) -> &'static str {
        "simplified_rubber"
    }

    #[inline(always)]
    fn stress<R: Real>(&self, f: &M3<R>, _dt: f64, history: &mut [R]) -> LawOut<R> {
        let j = det(f);
        let (p, collapsed) = Principal::of(f);
        let lb = p.ln_isochoric();
        let (f0, d0) = self.f_and_slope_r(lb[0]);
        let (f1, d1) = self.f_and_slope_r(lb[1]);
        let (f2, d2) = self.f_and_slope_r(lb[2]);
        let mean = (f0 + f1 + f2) * (1.0 / 3.0);
        let dev = [f0 - mean, f1 - mean, f2 - mean];
        let pk = p.ln_j * self.bulk;
        let mut pk2 = p.pk2_from_kirchhoff(&[dev[0] + pk, dev[1] + pk, dev[2] + pk]);
        let tmax = dev[0].abs().max(dev[1].abs()).max(dev[2].abs());
        let m = (R::splat(1.0) - p.ln_j * 2.0).max(R::splat(1.0)) * self.bulk
            + d0.max(d1).max(d2) * (2.0 / 3.0)
            + tmax * 2.0;
        let mut dissipation = R::zero();
        if self.damping > 0.0 {
            let c1 = &p.c_minus_i;
            let prev: &mut [R] = &mut history[..6];
            let mut de: Sym6<R> = [R::zero(); 6];
            for k in 0..6 {
                let e = c1[k] * 0.5;
                de[k] = e - prev[k];
                prev[k] = e;
            }
            let tr = (de[0] + de[1] + de[2]) * (1.0 / 3.0);
            let c = 2.0 * self.damping * self.shear;
            let sv: Sym6<R> = [
                (de[0] - tr) * c,
                (de[1] - tr) * c,
                (de[2] - tr) * c,
                de[3] * c,
                de[4] * c,
                de[5] * c,
            ];
            dissipation = ddot6(&sv, &de);
            for k in 0..6 {
                pk2[k] += sv[k];
            }
        }
        let wave_speed = damped_wave_speed(m, R::splat(self.damping * self.shear), self.rho);
        let finite = wave_speed.is_finite() & all_finite6(&pk2);
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

/// `sqrt(M / rho / (sqrt(1 + xi^2) - xi)^2)` with `xi = D / M`, `D = MU G`: the wave speed whose
/// stable step carries the reduction of stiffness-proportional damping with fraction of critical
/// `xi` in the highest mode (module doc, "Wave speed"). Since `(sqrt(1 + xi^2) - xi)(sqrt(1 + xi^2) + xi) = 1`,
/// it equals `(sqrt(M^2 + D^2) + D) / sqrt(M rho)`: no cancellation, and the two square roots
/// run side by side.
#[inline(always)]
fn damped_wave_speed<R: Real>(m: R, d: R, rho: f64) -> R {
    ((m * m + d * d).sqrt() + d) / (m * rho).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    #[allow(unused_imports)]
    use crate::law::LawError;
    use crate::tensor::Mat3;
    use nalgebra::Vector3;

    fn flesh() -> Foam {
        Foam::new("flesh", 1060.0, 2e9, Some(4e4), 0.4, None).unwrap()
    }

    #[test]
    fn default_table_is_neo_hookean() {
        let law = flesh();
        for x in [-1.5, -0.3, -1e-6, 0.0, 1e-9, 0.2, 0.77, 2.0] {
            let (f, d) = law.f_and_slope(x);
            let want = 4e4 * ((2.0 * x).exp() - 1.0);
            let dwant = 8e4 * (2.0 * x).exp();
            assert!(
                (f - want).abs() < 1e-9 * 4e4 * (2.0 * x).exp(),
                "x={x}: {f} vs {want}"
            );
            assert!((d - dwant).abs() < 1e-6 * dwant, "x={x}: {d} vs {dwant}");
        }
    }

    #[test]
    fn small_strain_bulk_response_is_k() {
        let law = Foam::new("flesh", 1060.0, 2e9, Some(4e4), 0.0, None).unwrap();
        let e = 1e-7;
        let f = Mat3::from_diagonal(&Vector3::new(1.0 + e, 1.0 + e, 1.0 + e));
        let r = law.evaluate(&f, 0.0, &mut []).unwrap();
        let j = (1.0 + e).powi(3);
        // PK2 = K ln J / l^2 on the diagonal: the bulk modulus is K = p / ln J.
        let p = r.pk2[(0, 0)] * (1.0 + e) * (1.0 + e);
        assert!((p / j.ln() - 2e9).abs() < 1e-6 * 2e9, "{}", p / j.ln());
        assert!((r.pk2[(0, 0)] - r.pk2[(1, 1)]).abs() < 1e-9 * r.pk2[(0, 0)].abs());
    }

    #[test]
    fn flesh_at_thirty_percent_compression_is_finite() {
        let law = flesh();
        let mut h = [0.0; 6];
        // Uniaxial compression at fixed volume-ish lateral expansion, and confined compression.
        for f in [
            Mat3::from_diagonal(&Vector3::new(0.7, 1.0 / 0.7f64.sqrt(), 1.0 / 0.7f64.sqrt())),
            Mat3::from_diagonal(&Vector3::new(0.7, 1.0, 1.0)),
        ] {
            let r = law.evaluate(&f, 1e-6, &mut h).unwrap();
            assert!(r.pk2.iter().all(|x| x.is_finite()));
            // At least the bulk wave speed sqrt((K + 4G/3)/rho) = 1373.6 m/s.
            assert!(
                r.wave_speed.is_finite() && r.wave_speed >= 1373.6,
                "{}",
                r.wave_speed
            );
        }
        let c0 = law.initial_wave_speed();
        assert!((c0 - 1373.6).abs() < 1.0, "{c0}");
    }

    #[test]
    fn curve_must_be_increasing_and_through_origin() {
        assert!(UniaxialCurve::table("f", &[(0.5, -1.0), (1.0, 0.5), (1.5, 2.0)]).is_err());
        assert!(UniaxialCurve::table("f", &[(0.5, -1.0), (1.2, -2.0), (1.5, 2.0)]).is_err());
        let c = UniaxialCurve::table("f", &[(0.5, -1.0), (1.5, 2.0)]).unwrap();
        assert_eq!(c.nominal(1.0).0, 0.0);
    }
}
