//! One-point (mean-gradient) hexahedron with Flanagan-Belytschko hourglass control, total
//! Lagrangian: F = I + sum_a u_a (x) b_a with the reference mean gradient b_a, one law call per
//! element, f_a = V0 P b_a, plus the hourglass forces (see [`super::HourglassForm`]).
//! Hourglass generalised displacements and velocities: q_ialpha = sum_a u_ia gamma_alpha,a and
//! qdot_ialpha = sum_a v_ia gamma_alpha,a (FB 1981 eq. 32).

use super::physical::{self, PhysicalRef};
use super::{
    add_nodal_forces, all_finite, bulk_pressure, critical_step, dot8, gradient_rate, max_face_area,
    narrow3, narrow_law_out, sym6, wide_deformation_gradient, ElementOut, HourglassForm, Nodal,
    StepInput, FAULT_FORCE,
};
use material::real::Real;
use material::tensor::{cofactor, ddot, det, mul, mul_bt, scale, M3};
use material::Law;

/// Reference data of one one-point element (or of one batch, one element per lane).
pub struct OnePointRef<'a, R: Real = f64> {
    /// Mean gradient, `[component][node]` (1/m).
    pub grad: &'a Nodal<R>,
    /// Hourglass shape vectors.
    pub gamma: &'a [[R; 8]; 4],
    /// Reference volume (m^3).
    pub vol0: R,
    /// Hourglass scale: a_s (N/m) for the stiffness form; Q rho0 V0^(2/3) / 4 (kg/m) for the
    /// viscous form, to be multiplied by the wave speed; Q V0 / 3 (m^3) for the physical form.
    pub hg_scale: R,
    /// The element frame of the physical form (`None` for the other forms).
    pub physical: Option<PhysicalRef<'a, R>>,
}

/// Internal forces of one element, or of a batch of elements (one per lane). `x` current
/// coordinates, `u` displacements, `v` velocities (at the previous half step), `density_scale`
/// the mass-scaling factor of the element (>= 1). Faults are reported per lane in the output.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn compute_forces<R: Real, L: Law>(
    law: &L,
    r: &OnePointRef<R>,
    hg_form: HourglassForm,
    x: &Nodal<R>,
    u: &Nodal<R>,
    v: &Nodal<R>,
    density_scale: R,
    input: &StepInput,
    history: &mut [R::Wide],
    fe: &mut Nodal<R>,
) -> ElementOut<R> {
    // F, the law, J and P in the law's number type; the rest in the kernel's.
    let fw = wide_deformation_gradient(u, r.grad);
    let resp_w = law.stress(&fw, input.dt, history);
    let (f, j) = (narrow3::<R>(&fw), R::narrow(det(&fw)));
    let mut p = narrow3::<R>(&mul(&fw, &resp_w.pk2));
    let resp = narrow_law_out::<R>(&resp_w);
    let rho0 = law.density();
    let sqrt_scale = density_scale.sqrt();
    let c = resp.wave_speed / sqrt_scale;
    let vol = j * r.vol0;
    let l = vol / max_face_area(x);
    let mut out = ElementOut::zero();
    out.law_dissipation = resp.dissipation * r.vol0;
    out.failed = resp.failed;
    out.fault = resp.fault;
    out.fault_value = resp.fault_value;
    let mut qterm = R::zero();
    let mut q = R::zero();
    if let Some(bv) = input.bulk.as_ref() {
        // tr D = Fdot : F^-T = Fdot : cof(F) / J.
        let cof = cofactor(&f);
        let trd = ddot(&gradient_rate(v, r.grad), &cof) / j;
        let (qq, qt) = bulk_pressure(bv, trd, R::splat(rho0) / j, l, resp.wave_speed);
        q = qq;
        qterm = qt;
        // P -= q cof F (zero where the element expands).
        for i in 0..3 {
            for k in 0..3 {
                p[i][k] -= cof[i][k] * q;
            }
        }
        out.bulk_power = q * (-trd) * vol;
    }
    out.dt = critical_step(l, c, qterm);
    *fe = [[R::zero(); 8]; 3];
    add_nodal_forces(fe, &p, r.grad, r.vol0);
    // Hourglass: generalised displacements (stiffness) or velocities (viscous) per mode.
    let (a, w) = match (hg_form, r.physical.as_ref()) {
        (HourglassForm::Viscous, _) => (r.hg_scale * sqrt_scale * c, v),
        (HourglassForm::Stiffness, _) => (r.hg_scale, u),
        (HourglassForm::Physical, Some(ph)) => {
            // The physical form's energy is the strain energy of the assumed field: it stays in
            // the internal energy (the forces' work), not in the hourglass energy, so the
            // hourglass guard and warning speak only of spurious modes.
            let _stored = physical::add_forces(ph, r.hg_scale, &f, u, r.gamma, r.grad, fe);
            return finish(out, &f, &resp.pk2, j, q, input, fe);
        }
        (HourglassForm::Physical, None) => {
            unreachable!("a physical hourglass group is built with its element frames")
        }
    };
    let mut qq = [[R::zero(); 4]; 3];
    let mut sumsq = R::zero();
    for i in 0..3 {
        for al in 0..4 {
            let h = dot8(&w[i], &r.gamma[al]);
            qq[i][al] = a * h;
            sumsq += h * h;
        }
    }
    for i in 0..3 {
        for b in 0..8 {
            fe[i][b] += qq[i][0] * r.gamma[0][b]
                + qq[i][1] * r.gamma[1][b]
                + qq[i][2] * r.gamma[2][b]
                + qq[i][3] * r.gamma[3][b];
        }
    }
    if hg_form == HourglassForm::Viscous {
        out.hourglass_power = a * sumsq;
    } else {
        out.hourglass_stored = a * sumsq * 0.5;
    }
    finish(out, &f, &resp.pk2, j, q, input, fe)
}

/// The element's Cauchy stress (if asked for) and its fault check, once its forces are summed.
#[inline(always)]
fn finish<R: Real>(
    mut out: ElementOut<R>,
    f: &M3<R>,
    pk2: &M3<R>,
    j: R,
    q: R,
    input: &StepInput,
    fe: &Nodal<R>,
) -> ElementOut<R> {
    if input.want_stress {
        let mut sigma = scale(&mul_bt(&mul(f, pk2), f), R::splat(1.0) / j);
        for i in 0..3 {
            sigma[i][i] -= q;
        }
        out.cauchy = sym6(&sigma);
    }
    let ok = out.dt.is_finite() & all_finite(fe);
    out.fault_where(!ok, R::splat(FAULT_FORCE), out.dt);
    out
}
