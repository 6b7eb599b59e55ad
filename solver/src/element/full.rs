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
    add_nodal_forces, all_finite, bulk_pressure, critical_step, gradient_rate, max_face_area,
    narrow3, narrow_law_out, sym6, wide_deformation_gradient, ElementOut, Nodal, StepInput,
    FAULT_DISTORTED, FAULT_FORCE,
};
use material::real::Real;
use material::tensor::{cofactor, ddot, det, mul, mul_bt, scale, M3};
use material::Law;

/// Reference data of one fully integrated element (or of one batch, one element per lane).
pub struct FullRef<'a, R: Real = f64> {
    /// Mean gradient, `[component][node]` (1/m).
    pub centre_grad: &'a Nodal<R>,
    /// Gauss-point gradients.
    pub gp_grad: &'a [Nodal<R>; 8],
    /// Gauss weights times det J (m^3).
    pub gp_weight: &'a [R; 8],
    /// Reference volume (m^3).
    pub vol0: R,
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

/// Internal forces of one element, or of a batch (one element per lane); history holds 8
/// consecutive integration-point blocks. Faults are reported per lane in the output.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn compute_forces<R: Real, L: Law>(
    law: &L,
    r: &FullRef<R>,
    fbar: bool,
    x: &Nodal<R>,
    u: &Nodal<R>,
    v: &Nodal<R>,
    density_scale: R,
    input: &StepInput,
    history: &mut [R::Wide],
    fe: &mut Nodal<R>,
) -> ElementOut<R> {
    // The kinematics (F0, F, J0, J, F-bar) and the law run in the law's number type, the
    // gradients, force sums and stress averages in the kernel's.
    let hl = law.history_len();
    let one = R::splat(1.0);
    let one_w = R::Wide::splat(1.0);
    let f0w = wide_deformation_gradient(u, r.centre_grad);
    let j0w = det(&f0w);
    let j0 = R::narrow(j0w);
    let mut out = ElementOut::zero();
    out.fault_where(
        !j0.gt(R::zero()),
        R::splat(material::law::FAULT_JACOBIAN),
        j0,
    );
    // F0^-T = cof(F0) / J0.
    let f0it = narrow3::<R>(&scale(&cofactor(&f0w), one_w / j0w));
    let rho0 = law.density();
    let vol = j0 * r.vol0;
    let l = vol / max_face_area(x);
    let mut cmax = R::zero();
    // Bulk viscosity from the centre rate of volume change.
    let mut trd = R::zero();
    if input.bulk.is_some() {
        trd = ddot(&gradient_rate(v, r.centre_grad), &f0it);
    }
    *fe = [[R::zero(); 8]; 3];
    let mut sig_acc: M3<R> = [[R::zero(); 3]; 3];
    let mut vol_acc = R::zero();
    for gp in 0..8 {
        let g = &r.gp_grad[gp];
        let w = r.gp_weight[gp];
        let fw = wide_deformation_gradient(u, g);
        let jw = det(&fw);
        let j = R::narrow(jw);
        out.fault_where(
            !j.gt(R::splat(MIN_GAUSS_VOLUME_RATIO)),
            R::splat(FAULT_DISTORTED),
            j,
        );
        let h = &mut history[gp * hl..(gp + 1) * hl];
        let fit = narrow3::<R>(&scale(&cofactor(&fw), one_w / jw));
        if fbar {
            let rrw = (j0w / jw).cbrt();
            let fbw = scale(&fw, rrw);
            let resp_w = law.stress(&fbw, input.dt, h);
            let resp = narrow_law_out::<R>(&resp_w);
            out.absorb_law(&resp, w);
            cmax = cmax.max(resp.wave_speed);
            let pbw = mul(&fbw, &resp_w.pk2);
            let pf = R::narrow(ddot(&pbw, &fw) * (1.0 / 3.0));
            let (pb, fb, rr) = (narrow3::<R>(&pbw), narrow3::<R>(&fbw), R::narrow(rrw));
            let wr = w * rr;
            add_nodal_forces(fe, &pb, g, wr);
            add_nodal_forces(fe, &scale(&f0it, pf), r.centre_grad, wr);
            add_nodal_forces(fe, &scale(&fit, -pf), g, wr);
            if input.want_stress {
                let t = mul_bt(&pb, &fb);
                let k = w / j0 * j0;
                for i in 0..3 {
                    for c in 0..3 {
                        sig_acc[i][c] += t[i][c] * k;
                    }
                }
                vol_acc += w * j0;
            }
        } else {
            let resp_w = law.stress(&fw, input.dt, h);
            let resp = narrow_law_out::<R>(&resp_w);
            out.absorb_law(&resp, w);
            cmax = cmax.max(resp.wave_speed);
            let p = narrow3::<R>(&mul(&fw, &resp_w.pk2));
            let f = narrow3::<R>(&fw);
            add_nodal_forces(fe, &p, g, w);
            if input.want_stress {
                let t = mul_bt(&p, &f);
                let k = w / j * j;
                for i in 0..3 {
                    for c in 0..3 {
                        sig_acc[i][c] += t[i][c] * k;
                    }
                }
                vol_acc += w * j;
            }
        }
    }
    let mut q = R::zero();
    let mut qterm = R::zero();
    if let Some(bv) = input.bulk.as_ref() {
        let (qq, qt) = bulk_pressure(bv, trd, R::splat(rho0) / j0, l, cmax);
        q = qq;
        qterm = qt;
        // Pressure -q on the whole element, through the centre gradient (zero where it expands).
        add_nodal_forces(fe, &scale(&f0it, -q * j0), r.centre_grad, r.vol0);
        out.bulk_power = q * (-trd) * vol;
    }
    out.dt = critical_step(l, cmax / density_scale.sqrt(), qterm);
    if input.want_stress {
        // Volume average of Cauchy stress: sum sigma_gp J_gp w / sum J_gp w, where sigma = tau / J.
        let mut s = scale(&sig_acc, one / vol_acc);
        for i in 0..3 {
            s[i][i] -= q;
        }
        out.cauchy = sym6(&s);
    }
    let ok = out.dt.is_finite() & all_finite(fe);
    out.fault_where(!ok, R::splat(FAULT_FORCE), out.dt);
    out
}
