//! One-point (mean-gradient) hexahedron with Flanagan-Belytschko hourglass control, total
//! Lagrangian: F = I + sum_a u_a (x) b_a with the reference mean gradient b_a, one law call per
//! element, f_a = V0 P b_a, plus the hourglass forces (see [`super::HourglassForm`]).
//! Hourglass generalised displacements and velocities: q_ialpha = sum_a u_ia gamma_alpha,a and
//! qdot_ialpha = sum_a v_ia gamma_alpha,a (FB 1981 eq. 32).

use super::{
    add_nodal_forces, bulk_pressure, cofactor, critical_step, deformation_gradient, dot8,
    gradient_rate, max_face_area, sym6, ElementOut, HourglassForm, Nodal, StepInput,
};
use material::{Law, LawError};

/// Reference data of one one-point element.
pub struct OnePointRef<'a> {
    /// Mean gradient [component][node] (1/m).
    pub grad: &'a Nodal,
    /// Hourglass shape vectors.
    pub gamma: &'a [[f64; 8]; 4],
    /// Reference volume (m^3).
    pub vol0: f64,
    /// Hourglass scale: a_s (N/m) for the stiffness form; Q rho0 V0^(2/3) / 4 (kg/m) for the
    /// viscous form, to be multiplied by the wave speed.
    pub hg_scale: f64,
}

/// Internal forces of one element. `x` current coordinates, `u` displacements, `v` velocities
/// (at the previous half step), `density_scale` the mass-scaling factor of the element (>= 1).
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn compute_forces<L: Law>(
    law: &L,
    r: &OnePointRef,
    hg_form: HourglassForm,
    x: &Nodal,
    u: &Nodal,
    v: &Nodal,
    density_scale: f64,
    input: &StepInput,
    history: &mut [f64],
    fe: &mut Nodal,
) -> Result<ElementOut, LawError> {
    let f = deformation_gradient(u, r.grad);
    let resp = law.evaluate(&f, input.dt, history)?;
    let j = f.determinant();
    let mut p = f * resp.pk2;
    let rho0 = law.density();
    let c = resp.wave_speed / density_scale.sqrt();
    let vol = j * r.vol0;
    let l = vol / max_face_area(x);
    let mut out = ElementOut {
        law_dissipation: resp.dissipation * r.vol0,
        failed: resp.failed,
        ..Default::default()
    };
    let mut qterm = 0.0;
    let mut q = 0.0;
    if let Some(bv) = input.bulk.as_ref() {
        // tr D = Fdot : F^-T = Fdot : cof(F) / J.
        let cof = cofactor(&f);
        let trd = gradient_rate(v, r.grad).component_mul(&cof).sum() / j;
        let (qq, qt) = bulk_pressure(bv, trd, rho0 / j, l, resp.wave_speed);
        q = qq;
        qterm = qt;
        if q != 0.0 {
            p -= cof * q;
            out.bulk_power = q * (-trd) * vol;
        }
    }
    out.dt = critical_step(l, c, qterm);
    *fe = [[0.0; 8]; 3];
    add_nodal_forces(fe, &p, r.grad, r.vol0);
    // Hourglass: generalised displacements (stiffness) or velocities (viscous) per mode.
    let (a, w) = match hg_form {
        HourglassForm::Viscous => (r.hg_scale * density_scale.sqrt() * c, v),
        HourglassForm::Stiffness => (r.hg_scale, u),
    };
    let mut qq = [[0.0; 4]; 3];
    let mut sumsq = 0.0;
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
    match hg_form {
        HourglassForm::Viscous => out.hourglass_power = a * sumsq,
        HourglassForm::Stiffness => out.hourglass_stored = 0.5 * a * sumsq,
    }
    if input.want_stress {
        let mut sigma = f * resp.pk2 * f.transpose() / j;
        sigma[(0, 0)] -= q;
        sigma[(1, 1)] -= q;
        sigma[(2, 2)] -= q;
        out.cauchy = sym6(&sigma);
    }
    if !(out.dt.is_finite() && fe.iter().all(|r| r.iter().all(|x| x.is_finite()))) {
        return Err(LawError::NotFinite("element force"));
    }
    Ok(out)
}
