//! Fully integrated (2x2x2) hexahedron, total Lagrangian, with an optional F-bar treatment of
//! the volumetric part (de Souza Neto, Peric, Dutko, Owen 1996, IJSS 33:3277).
//!
//! With F0 = I + sum_a u_a (x) b_a the deformation gradient of the Flanagan-Belytschko mean
//! gradient b_a (the volume average of grad N_a; for a parallelepiped the centre gradient),
//! J0 = det F0 and, at each Gauss
//! point, F, J = det F, r = (J0/J)^(1/3), the modified gradient is Fbar = r F. The law gives
//! Pbar = Fbar S(Fbar). The nodal forces are the exact variation of the stored energy,
//!   f_a = sum_gp w detJ r [ Pbar g_a + 1/3 (Pbar : F) (F0^-T g0_a - F^-T g_a) ],
//! with g_a = grad N_a at the Gauss point and g0_a = b_a, so energy is conserved and the patch
//! test is passed on distorted meshes: for homogeneous F, r = 1, and the correction sums to
//! (1/3)(P:F) F^-T sum_gp w detJ (b_a - g_a) = 0 because b_a is the volume average of g_a.
//! (With the centre gradient instead, the correction does not vanish on distorted elements.)
//! Without F-bar: f_a = sum_gp w detJ P g_a.

use super::{
    add_nodal_forces, bulk_pressure, cofactor, critical_step, deformation_gradient, gradient_rate,
    max_face_area, sym6, ElementOut, Nodal, StepInput,
};
use material::{Law, LawError, Mat3};

/// Reference data of one fully integrated element.
pub struct FullRef<'a> {
    /// Mean gradient [component][node] (1/m).
    pub centre_grad: &'a Nodal,
    /// Gauss-point gradients.
    pub gp_grad: &'a [Nodal; 8],
    /// Gauss weights times det J (m^3).
    pub gp_weight: &'a [f64; 8],
    /// Reference volume (m^3).
    pub vol0: f64,
}

/// Smallest Gauss-point volume ratio det F a fully integrated element may reach before the run
/// stops with an excessive-distortion error naming it (Abaqus/Explicit stops on excessively
/// distorted elements in the same spirit). The element's stable step comes from its centre
/// volume and largest face, so it does not see one corner collapsing: in the hard case of a
/// corner driven through the opposite face, a Gauss point at det F = 0.03 (centre 1.7) broke
/// the energy balance by 5 % within one step, while the run stayed balanced to 0.1 % down to
/// det F = 0.05. Soft tissue is nearly incompressible (det F near 1), so a 95 % local volume
/// loss is never physical there.
pub const MIN_GAUSS_VOLUME_RATIO: f64 = 0.05;

/// Internal forces of one element; history holds 8 consecutive integration-point blocks.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn compute_forces<L: Law>(
    law: &L,
    r: &FullRef,
    fbar: bool,
    x: &Nodal,
    u: &Nodal,
    v: &Nodal,
    density_scale: f64,
    input: &StepInput,
    history: &mut [f64],
    fe: &mut Nodal,
) -> Result<ElementOut, LawError> {
    let hl = law.history_len();
    let f0 = deformation_gradient(u, r.centre_grad);
    let j0 = f0.determinant();
    if !(j0 > 0.0) {
        return Err(LawError::NonPositiveJacobian(j0));
    }
    let f0it = f0
        .try_inverse()
        .ok_or(LawError::NotFinite("F0"))?
        .transpose();
    let rho0 = law.density();
    let vol = j0 * r.vol0;
    let l = vol / max_face_area(x);
    let mut out = ElementOut::default();
    let mut q = 0.0;
    let mut qterm = 0.0;
    let mut cmax: f64 = 0.0;
    // Bulk viscosity from the centre rate of volume change.
    let mut trd = 0.0;
    if input.bulk.is_some() {
        trd = gradient_rate(v, r.centre_grad).component_mul(&f0it).sum();
    }
    *fe = [[0.0; 8]; 3];
    let mut sig_acc = Mat3::zeros();
    let mut vol_acc = 0.0;
    for gp in 0..8 {
        let g = &r.gp_grad[gp];
        let w = r.gp_weight[gp];
        let f = deformation_gradient(u, g);
        let j = f.determinant();
        if !(j > MIN_GAUSS_VOLUME_RATIO) {
            return Err(if j > 0.0 {
                LawError::ExcessiveDistortion(j, MIN_GAUSS_VOLUME_RATIO)
            } else {
                LawError::NonPositiveJacobian(j)
            });
        }
        let h = &mut history[gp * hl..(gp + 1) * hl];
        let fit = cofactor(&f) / j;
        if fbar {
            let rr = (j0 / j).cbrt();
            let fb = f * rr;
            let resp = law.evaluate(&fb, input.dt, h)?;
            cmax = cmax.max(resp.wave_speed);
            out.law_dissipation += resp.dissipation * w;
            out.failed |= resp.failed;
            let pb = fb * resp.pk2;
            let pf = pb.component_mul(&f).sum() / 3.0;
            add_nodal_forces(fe, &pb, g, w * rr);
            add_nodal_forces(fe, &(f0it * pf), r.centre_grad, w * rr);
            add_nodal_forces(fe, &(fit * (-pf)), g, w * rr);
            if input.want_stress {
                sig_acc += fb * resp.pk2 * fb.transpose() * (w / j0 * j0);
                vol_acc += w * j0;
            }
        } else {
            let resp = law.evaluate(&f, input.dt, h)?;
            cmax = cmax.max(resp.wave_speed);
            out.law_dissipation += resp.dissipation * w;
            out.failed |= resp.failed;
            let p = f * resp.pk2;
            add_nodal_forces(fe, &p, g, w);
            if input.want_stress {
                sig_acc += f * resp.pk2 * f.transpose() * (w / j * j);
                vol_acc += w * j;
            }
        }
    }
    if let Some(bv) = input.bulk.as_ref() {
        let (qq, qt) = bulk_pressure(bv, trd, rho0 / j0, l, cmax);
        q = qq;
        qterm = qt;
        if q != 0.0 {
            // Pressure -q on the whole element, through the centre gradient.
            add_nodal_forces(fe, &(f0it * (-q * j0)), r.centre_grad, r.vol0);
            out.bulk_power = q * (-trd) * vol;
        }
    }
    out.dt = critical_step(l, cmax / density_scale.sqrt(), qterm);
    if input.want_stress {
        // Volume average of Cauchy stress: sum sigma_gp J_gp w / sum J_gp w, where sigma = tau / J.
        let mut s = sig_acc / vol_acc;
        s[(0, 0)] -= q;
        s[(1, 1)] -= q;
        s[(2, 2)] -= q;
        out.cauchy = sym6(&s);
    }
    if !out.dt.is_finite() || !fe.iter().all(|r| r.iter().all(|x| x.is_finite())) {
        return Err(LawError::NotFinite("element force"));
    }
    Ok(out)
}
