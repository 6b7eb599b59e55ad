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
pub mod physical;
pub mod precision;

use material::law::LawOut;
use material::real::{Mask, Real};
use material::tensor::M3;
use material::LawError;

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
    /// Physical (assumed-strain) stabilisation in the spirit of Belytschko and Bindeman (1993,
    /// LS-DYNA type 6): the hourglass modes carry the energy of the bending, twisting and
    /// warping strain fields they stand for, with Young's and the shear modulus, so one element
    /// through a thickness bends like beam theory and a nearly incompressible solid does not
    /// lock. Q = 1 is the exact stiffness of a rectangular elastic element. See
    /// [`physical`].
    Physical,
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
    /// Modulus that scales the resistance (the viscous and stiffness forms; the physical form
    /// uses the law's Young's and shear moduli).
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
                if h.modulus == HourglassModulus::Shear && h.form != HourglassForm::Physical {
                    "shear-scaled "
                } else {
                    ""
                },
                match h.form {
                    HourglassForm::Viscous => "viscous",
                    HourglassForm::Stiffness => "stiffness",
                    HourglassForm::Physical => "physical (assumed-strain)",
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
    /// The kernels' number type.
    pub precision: precision::Precision,
    /// Subcycling ([`crate::subcycle`]): at a macro time, the macro step the slow groups'
    /// laws integrate over (it replaces `dt` for them); `None` between macro times, when
    /// they are not evaluated. Irrelevant in a run without subcycling.
    pub macro_dt: Option<f64>,
}

/// What one element (or one batch of elements, one per lane) returns besides its nodal forces.
#[derive(Clone, Copy, Debug)]
pub struct ElementOut<R: Real = f64> {
    /// Critical time step of the element (s).
    pub dt: R,
    /// Hourglass energy: stored (stiffness form, total) (J).
    pub hourglass_stored: R,
    /// Hourglass dissipation power (viscous form) (W).
    pub hourglass_power: R,
    /// Bulk-viscous dissipation power (W).
    pub bulk_power: R,
    /// Law dissipation over the step (J).
    pub law_dissipation: R,
    /// Volume-averaged Cauchy stress, if requested (Pa), xx yy zz xy yz zx.
    pub cauchy: [R; 6],
    /// An integration point reached its failure criterion.
    pub failed: R::Mask,
    /// 0 where the element was evaluated, else a law fault code
    /// ([`material::law::FAULT_JACOBIAN`], ...) or [`FAULT_DISTORTED`] / [`FAULT_FORCE`].
    pub fault: R,
    /// The quantity the fault names (det F).
    pub fault_value: R,
}

impl<R: Real> ElementOut<R> {
    /// All zero, no fault.
    #[inline(always)]
    pub fn zero() -> Self {
        let z = R::zero();
        ElementOut {
            dt: z,
            hourglass_stored: z,
            hourglass_power: z,
            bulk_power: z,
            law_dissipation: z,
            cauchy: [z; 6],
            failed: R::Mask::splat(false),
            fault: z,
            fault_value: z,
        }
    }

    /// Take in one integration point's law answer: its fault (if no earlier one), its
    /// dissipation times the point's weight `w` (J), its failure.
    #[inline(always)]
    pub fn absorb_law(&mut self, resp: &LawOut<R>, w: R) {
        self.fault_where(resp.fault.ne(R::zero()), resp.fault, resp.fault_value);
        self.law_dissipation += resp.dissipation * w;
        self.failed = self.failed | resp.failed;
    }

    /// Record a fault where `m` is set and no earlier fault is.
    #[inline(always)]
    pub fn fault_where(&mut self, m: R::Mask, code: R, value: R) {
        let m = m & !self.fault.ne(R::zero());
        self.fault = R::select(m, code, self.fault);
        self.fault_value = R::select(m, value, self.fault_value);
    }
}

/// Element fault code: a Gauss point's volume ratio fell below [`full::MIN_GAUSS_VOLUME_RATIO`].
pub const FAULT_DISTORTED: f64 = 10.0;
/// Element fault code: the step or a nodal force is not finite.
pub const FAULT_FORCE: f64 = 11.0;

/// The error an element fault code stands for (`what`: the law's name).
pub fn fault_error(code: f64, value: f64, what: &'static str) -> LawError {
    if code == FAULT_DISTORTED {
        if value > 0.0 {
            LawError::ExcessiveDistortion(value, full::MIN_GAUSS_VOLUME_RATIO)
        } else {
            LawError::NonPositiveJacobian(value)
        }
    } else if code == FAULT_FORCE {
        LawError::NotFinite("element force")
    } else {
        material::law::fault_error(code, value, what)
    }
}

/// Eight nodal values of one component.
pub type Vec8<R = f64> = [R; 8];
/// Nodal vectors of one element in component-major order: `v[i][a]` is component i of node a.
/// Kernels work on this layout so that the loops over the eight nodes vectorise; in a batch each
/// entry holds the lanes of eight elements.
pub type Nodal<R = f64> = [Vec8<R>; 3];

/// sum_a x_a y_a, summed pairwise in a fixed order (so it vectorises and stays deterministic).
#[inline(always)]
pub fn dot8<R: Real>(x: &Vec8<R>, y: &Vec8<R>) -> R {
    let t: [R; 4] = material::arr![4, |k| x[k] * y[k] + x[k + 4] * y[k + 4]];
    (t[0] + t[1]) + (t[2] + t[3])
}

/// F = I + sum_a u_a (x) grad N_a.
#[inline(always)]
pub fn deformation_gradient<R: Real>(u: &Nodal<R>, g: &Nodal<R>) -> M3<R> {
    let mut f = gradient_rate(u, g);
    for i in 0..3 {
        f[i][i] += R::splat(1.0);
    }
    f
}

/// F = I + sum_a u_a (x) grad N_a in the law's number type ([`Real::Wide`]): the displacement
/// gradient is summed in `R` and widened before the identity is added, so single-precision
/// kernels hand the law an `F` whose `J - 1` is accurate relative to the strain (see
/// [`material::real_f32`]). For `f64` kernels this is [`deformation_gradient`], operation for
/// operation.
#[inline(always)]
pub fn wide_deformation_gradient<R: Real>(u: &Nodal<R>, g: &Nodal<R>) -> M3<R::Wide> {
    let h = gradient_rate(u, g);
    let mut f: M3<R::Wide> = material::arr![3, |i| material::arr![3, |j| h[i][j].widen()]];
    for i in 0..3 {
        f[i][i] += R::Wide::splat(1.0);
    }
    f
}

/// A matrix of the law's number type in the kernel's ([`Real::narrow`]).
#[inline(always)]
pub fn narrow3<R: Real>(m: &M3<R::Wide>) -> M3<R> {
    material::arr![3, |i| material::arr![3, |j| R::narrow(m[i][j])]]
}

/// A law's answer in the kernel's number type ([`Real::narrow`]); the identity for `f64` kernels.
#[inline(always)]
pub fn narrow_law_out<R: Real>(o: &LawOut<R::Wide>) -> LawOut<R> {
    LawOut {
        pk2: narrow3::<R>(&o.pk2),
        wave_speed: R::narrow(o.wave_speed),
        dissipation: R::narrow(o.dissipation),
        failed: R::narrow_mask(o.failed),
        fault: R::narrow(o.fault),
        fault_value: R::narrow(o.fault_value),
    }
}

/// Rate of F: sum_a v_a (x) grad N_a.
#[inline(always)]
pub fn gradient_rate<R: Real>(v: &Nodal<R>, g: &Nodal<R>) -> M3<R> {
    material::arr![3, |i| material::arr![3, |j| dot8(&v[i], &g[j])]]
}

/// fe_a += w * P grad N_a.
#[inline(always)]
pub fn add_nodal_forces<R: Real>(fe: &mut Nodal<R>, p: &M3<R>, g: &Nodal<R>, w: R) {
    for i in 0..3 {
        let (p0, p1, p2) = (w * p[i][0], w * p[i][1], w * p[i][2]);
        for a in 0..8 {
            fe[i][a] += p0 * g[0][a] + p1 * g[1][a] + p2 * g[2][a];
        }
    }
}

/// Largest face area of an element (m^2), from its current coordinates: each face's area is
/// half the norm of the cross product of its diagonals (exact for planar quads).
#[inline(always)]
pub fn max_face_area<R: Real>(x: &Nodal<R>) -> R {
    let mut amax = R::zero();
    for f in crate::mesh::FACES.iter() {
        let d1: [R; 3] = material::arr![3, |i| x[i][f[2]] - x[i][f[0]]];
        let d2: [R; 3] = material::arr![3, |i| x[i][f[3]] - x[i][f[1]]];
        let c = [
            d1[1] * d2[2] - d1[2] * d2[1],
            d1[2] * d2[0] - d1[0] * d2[2],
            d1[0] * d2[1] - d1[1] * d2[0],
        ];
        amax = amax.max(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    }
    amax.sqrt() * 0.5
}

/// Symmetric 3x3 to Voigt-like (xx yy zz xy yz zx).
#[inline(always)]
pub fn sym6<R: Real>(m: &M3<R>) -> [R; 6] {
    [m[0][0], m[1][1], m[2][2], m[0][1], m[1][2], m[2][0]]
}

/// Bulk viscous pressure q (Pa) and the Q term of the time-step formula, zero where the element
/// expands. `trd` = tr D (1/s), `rho` current density, `l` characteristic length, `c` wave speed.
#[inline(always)]
pub fn bulk_pressure<R: Real>(bv: &BulkViscosity, trd: R, rho: R, l: R, c: R) -> (R, R) {
    let comp = trd.lt(R::zero());
    let q = rho * l * (l * bv.quadratic * trd * trd - c * bv.linear * trd);
    let qt = c * bv.linear + l * bv.quadratic * (-trd);
    (
        R::select(comp, q, R::zero()),
        R::select(comp, qt, R::zero()),
    )
}

/// Whether every entry of the nodal forces is finite.
#[inline(always)]
pub fn all_finite<R: Real>(fe: &Nodal<R>) -> R::Mask {
    let mut m = R::Mask::splat(true);
    for row in fe {
        let mut s = R::zero();
        for x in row {
            s += *x * 0.0;
        }
        // x * 0 is 0 for finite x and NaN otherwise; one test per row.
        m = m & s.is_finite();
    }
    m
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
pub fn critical_step<R: Real>(l: R, c: R, qterm: R) -> R {
    l / (qterm + (qterm * qterm + c * c).sqrt())
}
