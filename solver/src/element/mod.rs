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
//! with L_e = V / A_max in the current configuration and c the wave speed the law reports.
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

/// Hourglass control of a part.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hourglass {
    /// Form.
    pub form: HourglassForm,
    /// Coefficient Q (LS-DYNA QH, default 0.1).
    pub coefficient: f64,
}

impl Default for Hourglass {
    fn default() -> Self {
        Hourglass {
            form: HourglassForm::Viscous,
            coefficient: 0.1,
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
                "one-point, {} hourglass Q={}",
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

/// F = I + sum_a u_a (x) grad N_a.
#[inline(always)]
pub fn deformation_gradient(u: &[[f64; 3]; 8], g: &[[f64; 8]; 3]) -> Mat3 {
    let mut f = Mat3::identity();
    for a in 0..8 {
        for i in 0..3 {
            let ui = u[a][i];
            f[(i, 0)] += ui * g[0][a];
            f[(i, 1)] += ui * g[1][a];
            f[(i, 2)] += ui * g[2][a];
        }
    }
    f
}

/// fe_a += w * P grad N_a.
#[inline(always)]
pub fn add_nodal_forces(fe: &mut [[f64; 3]; 8], p: &Mat3, g: &[[f64; 8]; 3], w: f64) {
    for a in 0..8 {
        for i in 0..3 {
            fe[a][i] += w * (p[(i, 0)] * g[0][a] + p[(i, 1)] * g[1][a] + p[(i, 2)] * g[2][a]);
        }
    }
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

/// Critical step L / (Q + sqrt(Q^2 + c^2)).
#[inline(always)]
pub fn critical_step(l: f64, c: f64, qterm: f64) -> f64 {
    l / (qterm + (qterm * qterm + c * c).sqrt())
}
