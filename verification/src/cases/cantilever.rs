//! Cantilever tip deflection against scikit-fem Q1 and Timoshenko beam theory.
//!
//! `cantilever_skfem.json`: the beam 100 x 10 x 10 mm, E = 1 MPa, nu = 0, clamped at x = 0,
//! tip shear P = 1 mN applied as the stored Q1-consistent nodal forces, meshes 10x1x1, 20x2x2
//! and 40x4x4. Small-strain linear elasticity (`Kinematics::Small`), relaxed to equilibrium.
//!
//! - palpa's plain fully integrated element is scikit-fem's Q1 element: the tip deflections must
//!   agree to the relaxation tolerance (1e-5 relative). Both shear-lock: 67 %, 89 %, 97 % of
//!   Timoshenko.
//! - F-bar changes only the volumetric part (nothing to fix at nu = 0): it locks the same way.
//! - One-point integration with stiffness hourglass control does not lock; its bending
//!   stiffness with one element through the thickness comes only from the hourglass
//!   stiffness, so the coarse meshes are far too soft (hourglass effect). The viscous form has no
//!   static hourglass stiffness at all (a mechanism in bending) and is not run here.
//!
//! Timoshenko: P L^3/(3 E I) + P L/(kappa G A) = 0.4024 mm, kappa = 5/6.

use super::{short, FULL, FULL_FBAR, ONE_POINT_STIFFNESS};
use crate::data::{self, at, f, mesh, s, vec3, vec_u32};
use crate::quasi::{model, on, relax};
use crate::{CaseOutput, Row, Series};
use material::linear_elastic::{Kinematics, LinearElastic};
use material::Material;
use solver::bc::NodalLoad;
use solver::curve::Curve;
use solver::element::Formulation;

/// Tolerance of palpa's plain fully integrated element against scikit-fem Q1 (relative).
pub const Q1_TOLERANCE: f64 = 1e-5;

/// palpa's tip deflection (m) on one stored mesh, and the relaxation steps.
pub fn tip_deflection(
    m: &serde_json::Value,
    form: Formulation,
    lambda: f64,
    mu: f64,
) -> Result<(f64, u64), String> {
    let mesh = mesh(m, "mesh", "beam");
    let clamp = vec_u32(m, "boundary_conditions.clamped.nodes");
    let c = (0..3).map(|d| on(&clamp, d, None)).collect();
    let ln = vec_u32(m, "loads.nodal_forces.nodes");
    let lv = vec3(m, "loads.nodal_forces.values");
    let mut loads = Vec::new();
    for (&n, v) in ln.iter().zip(&lv) {
        for d in 0..3 {
            if v[d] != 0.0 {
                loads.push(NodalLoad {
                    nodes: vec![n],
                    dof: d,
                    curve: Curve::Constant(v[d]),
                });
            }
        }
    }
    let mat = Material::LinearElastic(LinearElastic {
        rho: 1000.0,
        lambda,
        mu,
        kinematics: Kinematics::Small,
    });
    let r = relax(model(mesh, mat, form)?, c, loads, 1e-10, 600_000)?;
    if !r.converged {
        return Err(format!(
            "relaxation: residual {:.2e} after {} steps",
            r.residual, r.steps
        ));
    }
    let tip = vec_u32(m, "tip_centre_nodes");
    let uz = tip.iter().map(|&n| r.sim.u[n as usize][2]).sum::<f64>() / tip.len() as f64;
    Ok((uz, r.steps))
}

/// Cantilever rows and the locking plot.
pub fn run() -> CaseOutput {
    let v = data::parse(data::CANTILEVER_SKFEM);
    let (lambda, mu) = (f(&v, "material.lambda"), f(&v, "material.mu"));
    let timo = f(&v, "closed_form.timoshenko_tip_uz");
    let mut out = CaseOutput::default();
    let mut series = Series {
        plot: "cantilever_locking".into(),
        title: "Cantilever: tip deflection / Timoshenko".into(),
        axes: (
            "elements along the length".into(),
            "u_tip / u_Timoshenko".into(),
        ),
        log: false,
        curves: Vec::new(),
    };
    let meshes = at(&v, "meshes").as_array().unwrap();
    series.curves.push((
        "scikit-fem Q1".into(),
        meshes
            .iter()
            .map(|m| {
                (
                    vec_u32(m, "divisions")[0] as f64,
                    f(m, "solution.tip_uz_centre") / timo,
                )
            })
            .collect(),
    ));
    for form in [FULL, FULL_FBAR, ONE_POINT_STIFFNESS] {
        let mut pts = Vec::new();
        for m in meshes {
            let name = s(m, "name");
            let case = format!("cantilever {name}, {}", short(&form));
            let reference = f(m, "solution.tip_uz_centre");
            match tip_deflection(m, form, lambda, mu) {
                Ok((uz, steps)) => {
                    if form == FULL {
                        out.rows.push(Row::compare(
                            &case,
                            "tip u_z (m)",
                            format!("scikit-fem Q1 {name}"),
                            reference,
                            uz,
                            reference,
                            Some(Q1_TOLERANCE),
                        ));
                    }
                    out.rows.push(Row::compare(
                        &case,
                        "tip u_z (m)",
                        "Timoshenko beam",
                        timo,
                        uz,
                        timo,
                        None,
                    ));
                    out.notes.push(format!(
                        "{case}: tip {uz:.5e} m = {:.3} x Timoshenko ({steps} relaxation steps)",
                        uz / timo
                    ));
                    pts.push((vec_u32(m, "divisions")[0] as f64, uz / timo));
                }
                Err(e) => out.rows.push(Row::failed(&case, "tip u_z (m)", e)),
            }
        }
        series.curves.push((format!("palpa {}", short(&form)), pts));
    }
    for q in at(&v, "reference_q2").as_array().unwrap() {
        let uz = f(q, "tip_uz_centre");
        out.rows.push(Row::compare(
            format!("cantilever, scikit-fem {}", s(q, "name")),
            "tip u_z (m) (3-D reference, not palpa)",
            "Timoshenko beam",
            timo,
            uz,
            timo,
            None,
        ));
    }
    out.series.push(series);
    out
}
