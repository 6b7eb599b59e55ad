//! One-point (mean-gradient) hexahedron with Flanagan-Belytschko hourglass control, total
//! Lagrangian: F = I + sum_a u_a (x) b_a with the reference mean gradient b_a, one law call per
//! element, f_a = V0 P b_a, plus the hourglass forces (see [`super::HourglassForm`]).
//! Hourglass generalised displacements and velocities: q_ialpha = sum_a u_ia gamma_alpha,a and
//! qdot_ialpha = sum_a v_ia gamma_alpha,a (FB 1981 eq. 32).

use super::{
    add_nodal_forces, bulk_pressure, critical_step, deformation_gradient, sym6, ElementOut,
    HourglassForm, StepInput,
};
use crate::hex::max_face_area;
use material::{Law, LawError};

/// Reference data of one one-point element.
pub struct OnePointRef<'a> {
    /// Mean gradient [component][node] (1/m).
    pub grad: &'a [[f64; 8]; 3],
    /// Hourglass shape vectors.
    pub gamma: &'a [[f64; 8]; 4],
    /// Reference volume (m^3).
    pub vol0: f64,
    /// Hourglass stiffness a_s (N/m), stiffness form only.
    pub hg_stiffness: f64,
}

/// Internal forces of one element. `x` current coordinates, `u` displacements, `v` velocities
/// (at the previous half step), `density_scale` the mass-scaling factor of the element (>= 1).
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn compute_forces<L: Law>(
    law: &L,
    r: &OnePointRef,
    hg_form: HourglassForm,
    hg_q: f64,
    x: &[[f64; 3]; 8],
    u: &[[f64; 3]; 8],
    v: &[[f64; 3]; 8],
    density_scale: f64,
    input: &StepInput,
    history: &mut [f64],
    fe: &mut [[f64; 3]; 8],
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
    let fit = if input.bulk.is_some() || input.want_stress {
        f.try_inverse().map(|m| m.transpose())
    } else {
        None
    };
    if let (Some(bv), Some(fit)) = (input.bulk.as_ref(), fit.as_ref()) {
        let fdot = deformation_gradient(v, r.grad);
        let trd = fdot.component_mul(fit).sum();
        let (qq, qt) = bulk_pressure(bv, trd, rho0 / j, l, resp.wave_speed);
        q = qq;
        qterm = qt;
        if q != 0.0 {
            p -= fit * (q * j);
            out.bulk_power = q * (-trd) * vol;
        }
    }
    out.dt = critical_step(l, c, qterm);
    *fe = [[0.0; 3]; 8];
    add_nodal_forces(fe, &p, r.grad, r.vol0);
    // Hourglass.
    match hg_form {
        HourglassForm::Viscous => {
            let a = hg_q * rho0 * density_scale * c * r.vol0.powf(2.0 / 3.0) * 0.25;
            for al in 0..4 {
                let g = &r.gamma[al];
                let mut qd = [0.0; 3];
                for b in 0..8 {
                    for i in 0..3 {
                        qd[i] += v[b][i] * g[b];
                    }
                }
                out.hourglass_power += a * (qd[0] * qd[0] + qd[1] * qd[1] + qd[2] * qd[2]);
                for b in 0..8 {
                    for i in 0..3 {
                        fe[b][i] += a * qd[i] * g[b];
                    }
                }
            }
        }
        HourglassForm::Stiffness => {
            let a = r.hg_stiffness;
            for al in 0..4 {
                let g = &r.gamma[al];
                let mut qv = [0.0; 3];
                for b in 0..8 {
                    for i in 0..3 {
                        qv[i] += u[b][i] * g[b];
                    }
                }
                out.hourglass_stored += 0.5 * a * (qv[0] * qv[0] + qv[1] * qv[1] + qv[2] * qv[2]);
                for b in 0..8 {
                    for i in 0..3 {
                        fe[b][i] += a * qv[i] * g[b];
                    }
                }
            }
        }
    }
    if input.want_stress {
        let mut sigma = f * resp.pk2 * f.transpose() / j;
        sigma[(0, 0)] -= q;
        sigma[(1, 1)] -= q;
        sigma[(2, 2)] -= q;
        out.cauchy = sym6(&sigma);
    }
    if !out.dt.is_finite() || !fe.iter().all(|r| r.iter().all(|x| x.is_finite())) {
        return Err(LawError::NotFinite("element force"));
    }
    Ok(out)
}
