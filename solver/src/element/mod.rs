//! Element kernels of the total Lagrangian hexahedron.
//!
//! Each kernel takes one element's nodal displacements and velocities, its precomputed
//! reference data and its law, and returns the element's internal nodal forces
//! f_a = int_V0 P grad_0 N_a dV (P = F S, the first Piola-Kirchhoff stress), its critical time
//! step, and its energy terms. Kernels are generic over the law, so each group's loop is
//! monomorphised; they never allocate.
//!
//! Stable step of an element (LS-DYNA theory manual, solid elements, with bulk viscosity):
//!   dt_e = L_e / (Q + sqrt(Q^2 + c^2)),  Q = C1 c + C0 L_e |tr D|  in compression, else 0,
//! with L_e = V / A_max in the current configuration and c the wave speed the law reports,
//! times the part's surface-mode factor [`surface_mode_factor`] (1 for compressible solids,
//! 0.82 for nearly incompressible ones), which the caller applies once per group.
//!
//! Bulk viscosity (von Neumann-Richtmyer with a linear term, LS-DYNA *CONTROL_BULK_VISCOSITY):
//!   q = rho L (C0 L (tr D)^2 - C1 c tr D)  if tr D < 0, else 0,
//! added to the Cauchy stress as -q I, i.e. P_q = -q J F^-T.

pub mod full;
pub mod one_point;

use material::Mat3;

/// Bulk-viscosity coefficients (quadratic C0, linear C1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BulkViscosity {
    /// Quadratic coefficient (LS-DYNA Q1, default 1.5).
    pub quadratic: f64,
    /// Linear coefficient (LS-DYNA Q2, default 0.06).
    pub linear: f64,
}

impl Default for BulkViscosity {
    fn default() -> Self {
        BulkViscosity {
            quadratic: 1.5,
            linear: 0.06,
        }
    }
}

/// Hourglass-control form of the one-point element.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum HourglassForm {
    /// Viscous (LS-DYNA type 1-3 style): f = -a_v gamma (gamma . v), a_v = Q rho c V^(2/3) / 4.
    Viscous,
    /// Stiffness (Flanagan-Belytschko, LS-DYNA type 4-5 style):
    /// f = -a_s gamma (gamma . u), a_s = Q (lambda + 2 mu)_0 sum_ia (V b_ia)^2 / (3 V) / 64.
    Stiffness,
}

/// Which modulus scales the hourglass resistance.
///
/// Flanagan and Belytschko (1981) scale both forms by the dilatational (P-wave) modulus
/// `lambda + 2 mu` (the viscous form through `rho c`), as LS-DYNA types 1-5 do. For a nearly
/// incompressible solid (soft tissue, K/G up to 5e4) that modulus is the bulk modulus, and the
/// hourglass forces then resist the isochoric hourglass modes thousands of times more than the
/// material itself does: the mesh locks and the viscous form dissipates much of the work.
/// The hourglass modes are deviatoric, so Belytschko and Bindeman (1993, LS-DYNA type 6) and
/// Puso (2000) scale them by the shear modulus instead. `Shear` replaces `lambda + 2 mu` by
/// `2 mu` (the P-wave modulus of a solid with the same shear modulus and lambda = 0) in the
/// stiffness form, and `c` by `c * sqrt(2 mu0 / (rho c0^2))` in the viscous form, so that the
/// viscous coefficient follows the law's stretch stiffening like the P-wave form does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HourglassModulus {
    /// `lambda + 2 mu` (LS-DYNA types 1-5, OpenRadioss Iset 1-3).
    PWave,
    /// `2 mu` (shear-scaled, in the spirit of LS-DYNA type 6).
    Shear,
}

/// Hourglass control of a part.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hourglass {
    /// Form.
    pub form: HourglassForm,
    /// Coefficient Q (LS-DYNA QH, default 0.1).
    pub coefficient: f64,
    /// Modulus that scales the resistance.
    pub modulus: HourglassModulus,
}

impl Default for Hourglass {
    fn default() -> Self {
        Hourglass {
            form: HourglassForm::Viscous,
            coefficient: 0.1,
            modulus: HourglassModulus::PWave,
        }
    }
}

/// Element formulation of a part.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Formulation {
    /// One-point integration (mean gradient) with hourglass control.
    OnePoint(Hourglass),
    /// 2x2x2 Gauss integration; with `fbar` the volumetric part of F is taken from the element
    /// centre (F-bar, de Souza Neto et al. 1996) to avoid volumetric locking.
    Full {
        /// Use F-bar.
        fbar: bool,
    },
}

impl Formulation {
    /// Integration points per element.
    pub fn n_ip(&self) -> usize {
        match self {
            Formulation::OnePoint(_) => 1,
            Formulation::Full { .. } => 8,
        }
    }
    /// A short label.
    pub fn label(&self) -> String {
        match self {
            Formulation::OnePoint(h) => format!(
                "one-point, {}{} hourglass Q={}",
                if h.modulus == HourglassModulus::Shear {
                    "shear-scaled "
                } else {
                    ""
                },
                if h.form == HourglassForm::Viscous {
                    "viscous"
                } else {
                    "stiffness"
                },
                h.coefficient
            ),
            Formulation::Full { fbar: true } => "fully integrated, F-bar".into(),
            Formulation::Full { fbar: false } => "fully integrated".into(),
        }
    }
}

/// Per-step inputs shared by all elements.
#[derive(Clone, Copy, Debug)]
pub struct StepInput {
    /// Length of the step the laws integrate over (s).
    pub dt: f64,
    /// Bulk viscosity, if active.
    pub bulk: Option<BulkViscosity>,
    /// Also return the Cauchy stress (output step).
    pub want_stress: bool,
}

/// What one element returns besides its nodal forces.
#[derive(Clone, Copy, Debug, Default)]
pub struct ElementOut {
    /// Critical time step of the element (s).
    pub dt: f64,
    /// Hourglass energy: stored (stiffness form, total) (J).
    pub hourglass_stored: f64,
    /// Hourglass dissipation power (viscous form) (W).
    pub hourglass_power: f64,
    /// Bulk-viscous dissipation power (W).
    pub bulk_power: f64,
    /// Law dissipation over the step (J).
    pub law_dissipation: f64,
    /// Volume-averaged Cauchy stress, if requested (Pa), xx yy zz xy yz zx.
    pub cauchy: [f64; 6],
    /// An integration point reached its failure criterion.
    pub failed: bool,
}

/// Eight nodal values of one component.
pub type Vec8 = [f64; 8];
/// Nodal vectors of one element in component-major order: `v[i][a]` is component i of node a.
/// Kernels work on this layout so that the loops over the eight nodes vectorise.
pub type Nodal = [Vec8; 3];

/// sum_a x_a y_a, summed pairwise in a fixed order (so it vectorises and stays deterministic).
#[inline(always)]
pub fn dot8(x: &Vec8, y: &Vec8) -> f64 {
    let mut t = [0.0; 4];
    for k in 0..4 {
        t[k] = x[k] * y[k] + x[k + 4] * y[k + 4];
    }
    (t[0] + t[1]) + (t[2] + t[3])
}

/// F = I + sum_a u_a (x) grad N_a.
#[inline(always)]
pub fn deformation_gradient(u: &Nodal, g: &Nodal) -> Mat3 {
    Mat3::new(
        1.0 + dot8(&u[0], &g[0]),
        dot8(&u[0], &g[1]),
        dot8(&u[0], &g[2]),
        dot8(&u[1], &g[0]),
        1.0 + dot8(&u[1], &g[1]),
        dot8(&u[1], &g[2]),
        dot8(&u[2], &g[0]),
        dot8(&u[2], &g[1]),
        1.0 + dot8(&u[2], &g[2]),
    )
}

/// Rate of F: sum_a v_a (x) grad N_a.
#[inline(always)]
pub fn gradient_rate(v: &Nodal, g: &Nodal) -> Mat3 {
    Mat3::new(
        dot8(&v[0], &g[0]),
        dot8(&v[0], &g[1]),
        dot8(&v[0], &g[2]),
        dot8(&v[1], &g[0]),
        dot8(&v[1], &g[1]),
        dot8(&v[1], &g[2]),
        dot8(&v[2], &g[0]),
        dot8(&v[2], &g[1]),
        dot8(&v[2], &g[2]),
    )
}

/// Cofactor matrix cof F = det(F) F^-T, without a division.
#[inline(always)]
pub fn cofactor(f: &Mat3) -> Mat3 {
    let (a, b, c) = (f[(0, 0)], f[(0, 1)], f[(0, 2)]);
    let (d, e, g) = (f[(1, 0)], f[(1, 1)], f[(1, 2)]);
    let (h, i, k) = (f[(2, 0)], f[(2, 1)], f[(2, 2)]);
    Mat3::new(
        e * k - g * i,
        g * h - d * k,
        d * i - e * h,
        c * i - b * k,
        a * k - c * h,
        b * h - a * i,
        b * g - c * e,
        c * d - a * g,
        a * e - b * d,
    )
}

/// fe_a += w * P grad N_a.
#[inline(always)]
pub fn add_nodal_forces(fe: &mut Nodal, p: &Mat3, g: &Nodal, w: f64) {
    for i in 0..3 {
        let (p0, p1, p2) = (w * p[(i, 0)], w * p[(i, 1)], w * p[(i, 2)]);
        for a in 0..8 {
            fe[i][a] += p0 * g[0][a] + p1 * g[1][a] + p2 * g[2][a];
        }
    }
}

/// Largest face area of an element (m^2), from its current coordinates: each face's area is
/// half the norm of the cross product of its diagonals (exact for planar quads).
#[inline(always)]
pub fn max_face_area(x: &Nodal) -> f64 {
    let mut amax: f64 = 0.0;
    for f in crate::mesh::FACES.iter() {
        let d1 = [
            x[0][f[2]] - x[0][f[0]],
            x[1][f[2]] - x[1][f[0]],
            x[2][f[2]] - x[2][f[0]],
        ];
        let d2 = [
            x[0][f[3]] - x[0][f[1]],
            x[1][f[3]] - x[1][f[1]],
            x[2][f[3]] - x[2][f[1]],
        ];
        let c = [
            d1[1] * d2[2] - d1[2] * d2[1],
            d1[2] * d2[0] - d1[0] * d2[2],
            d1[0] * d2[1] - d1[1] * d2[0],
        ];
        amax = amax.max(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    }
    0.5 * amax.sqrt()
}

/// Symmetric 3x3 to Voigt-like (xx yy zz xy yz zx).
#[inline]
pub fn sym6(m: &Mat3) -> [f64; 6] {
    [
        m[(0, 0)],
        m[(1, 1)],
        m[(2, 2)],
        m[(0, 1)],
        m[(1, 2)],
        m[(2, 0)],
    ]
}

/// Bulk viscous pressure q (Pa) and the Q term of the time-step formula.
/// `trd` = tr D (1/s), `rho` current density, `l` characteristic length, `c` wave speed.
#[inline(always)]
pub fn bulk_pressure(bv: &BulkViscosity, trd: f64, rho: f64, l: f64, c: f64) -> (f64, f64) {
    if trd < 0.0 {
        let q = rho * l * (bv.quadratic * l * trd * trd - bv.linear * c * trd);
        (q, bv.linear * c + bv.quadratic * l * (-trd))
    } else {
        (0.0, 0.0)
    }
}

/// Constant of [`surface_mode_factor`], fitted below every measured curve.
pub const SURFACE_MODE_BETA: f64 = 0.475;

/// Stable-step factor of a part for the free-surface dilatational modes of a lumped-mass
/// hexahedral mesh: `kappa = sqrt(M / (M + beta lambda))`, with `M = lambda + 2 mu` the P-wave
/// modulus, `lambda = max(M - 2 mu, 0)` and `beta` = [`SURFACE_MODE_BETA`].
///
/// `L / c` with `L = V / A_max` is the exact critical step of the interior of a regular mesh
/// (the 1-D dilatational mode, omega = 2 c / h), but free faces, edges and corners carry modes in
/// which a surface node moves against the bulk; their frequency grows with `lambda / M`, so a
/// nearly incompressible solid goes unstable well below the factor 0.9 that LS-DYNA and
/// OpenRadioss use. Largest eigenvalue of `M^-1 K` (lumped mass, no hourglass or bulk
/// viscosity), as `dt_crit / (h / c)`, on cubes of size h
/// (`verification/python/hex_stability_eigen.py`):
///
/// | nu     | one-point, free | one-point, base fixed | 2x2x2, free | `kappa` |
/// |--------|-----------------|-----------------------|-------------|---------|
/// | 0.0    | 1.000           | 1.035                 | 1.000       | 1.000   |
/// | 0.3    | 0.970           | 0.983                 | 0.950       | 0.912   |
/// | 0.45   | 0.886           | 0.893                 | 0.862       | 0.849   |
/// | 0.49   | 0.855           | 0.860                 | 0.832       | 0.829   |
/// | 0.4999 | 0.847           | 0.852                 | 0.825       | 0.823   |
///
/// `kappa` stays below every column (within 0.2 % of the tightest at nu -> 0.5, up to 4 %
/// conservative near nu = 0.3), so the default safety factor 0.9 keeps its usual 10 % margin on
/// the true limit for any Poisson ratio. The moduli are the law's initial ones
/// (`rho c0^2` and its initial shear modulus), so a law with a negative or zero Poisson ratio
/// gets 1.
pub fn surface_mode_factor(p_wave_modulus: f64, shear_modulus: f64) -> f64 {
    let m = p_wave_modulus;
    let lambda = (m - 2.0 * shear_modulus).max(0.0);
    if m > 0.0 && m.is_finite() {
        (m / (m + SURFACE_MODE_BETA * lambda)).sqrt()
    } else {
        1.0
    }
}

/// Critical step L / (Q + sqrt(Q^2 + c^2)).
#[inline(always)]
pub fn critical_step(l: f64, c: f64, qterm: f64) -> f64 {
    l / (qterm + (qterm * qterm + c * c).sqrt())
}
