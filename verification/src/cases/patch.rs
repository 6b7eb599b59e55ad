//! Distorted-hexahedron patch tests against scikit-fem and FEniCSx.
//!
//! The 3x3x3 distorted cube of `patch_skfem.json` / `patch_fenicsx.json`, small-strain linear
//! elasticity (`LinearElastic` with `Kinematics::Small`, so P = sigma and palpa's total
//! Lagrangian element is the linear element to round-off), all 56 boundary nodes prescribed to
//! u = A X + b. palpa relaxes the 8 interior nodes by dynamic relaxation. Compared: every nodal
//! displacement (max |u - u_ref| / max |u_ref|) and every boundary reaction (max |R - R_ref| /
//! max |R_ref|), tolerance 1e-8, for the one-point (viscous and stiffness hourglass) and the
//! fully integrated (F-bar and plain) formulations.

use super::{short, FULL, FULL_FBAR, ONE_POINT_PHYSICAL, ONE_POINT_STIFFNESS, ONE_POINT_VISCOUS};
use crate::data::{self, f, mesh, vec3, vec_u32};
use crate::quasi::{max_abs, model, prescribe_node, relax};
use crate::{CaseOutput, Row};
use material::linear_elastic::{Kinematics, LinearElastic};
use material::Material;
use solver::element::Formulation;

/// Tolerance on the relative displacement and reaction errors.
pub const TOLERANCE: f64 = 1e-8;

/// Result of one patch test.
#[derive(Clone, Copy, Debug)]
pub struct PatchResult {
    /// max |u_ref| and palpa's max |u| (m).
    pub u_max: (f64, f64),
    /// max |u - u_ref| / max |u_ref|.
    pub u_error: f64,
    /// max |R_ref| and palpa's max |R| on the boundary nodes (N).
    pub r_max: (f64, f64),
    /// max |R - R_ref| / max |R_ref|.
    pub r_error: f64,
    /// Relaxation steps.
    pub steps: u64,
}

/// Run one patch test against one reference file.
pub fn patch_errors(reference: &str, form: Formulation) -> Result<PatchResult, String> {
    let v = data::parse(reference);
    let m = mesh(&v, "mesh", "patch");
    let mat = Material::LinearElastic(LinearElastic {
        rho: 1000.0,
        lambda: f(&v, "material.lambda"),
        mu: f(&v, "material.mu"),
        kinematics: Kinematics::Small,
    });
    let nodes = vec_u32(&v, "boundary_conditions.dirichlet.nodes");
    let vals = vec3(&v, "boundary_conditions.dirichlet.values");
    let mut c = Vec::new();
    for (&n, &u) in nodes.iter().zip(&vals) {
        prescribe_node(&mut c, n, u);
    }
    let r = relax(model(m, mat, form)?, c, Vec::new(), 1e-12, 200_000)?;
    if !r.converged {
        return Err(format!(
            "dynamic relaxation did not converge: residual {:.2e} after {} steps",
            r.residual, r.steps
        ));
    }
    let uref = vec3(&v, "solution.displacement");
    let mut du: f64 = 0.0;
    for (a, b) in r.sim.u.iter().zip(&uref) {
        for d in 0..3 {
            du = du.max((a[d] - b[d]).abs());
        }
    }
    let rn = vec_u32(&v, "solution.reaction_forces.nodes");
    let rv = vec3(&v, "solution.reaction_forces.values");
    let mut dr: f64 = 0.0;
    for (&n, rr) in rn.iter().zip(&rv) {
        for d in 0..3 {
            dr = dr.max((r.sim.reaction[n as usize][d] - rr[d]).abs());
        }
    }
    let rp: Vec<[f64; 3]> = rn.iter().map(|&n| r.sim.reaction[n as usize]).collect();
    Ok(PatchResult {
        u_max: (max_abs(&uref), max_abs(&r.sim.u)),
        u_error: du / max_abs(&uref),
        r_max: (max_abs(&rv), max_abs(&rp)),
        r_error: dr / max_abs(&rv),
        steps: r.steps,
    })
}

/// All patch-test rows.
pub fn run() -> CaseOutput {
    let mut out = CaseOutput::default();
    for (reference, text) in [
        ("scikit-fem", data::PATCH_SKFEM),
        ("FEniCSx", data::PATCH_FENICSX),
    ] {
        for form in [
            ONE_POINT_VISCOUS,
            ONE_POINT_STIFFNESS,
            ONE_POINT_PHYSICAL,
            FULL_FBAR,
            FULL,
        ] {
            let case = format!("patch test, {}", short(&form));
            let src = format!("{reference} Q1 (distorted 3x3x3)");
            match patch_errors(text, form) {
                Ok(p) => {
                    out.rows.push(Row::with_error(
                        &case,
                        "max |u| (m); error = max nodal |du| / max |u|",
                        &src,
                        p.u_max.0,
                        p.u_max.1,
                        p.u_error,
                        Some(TOLERANCE),
                    ));
                    out.rows.push(Row::with_error(
                        &case,
                        "max |R| (N); error = max nodal |dR| / max |R|",
                        &src,
                        p.r_max.0,
                        p.r_max.1,
                        p.r_error,
                        Some(TOLERANCE),
                    ));
                    out.notes.push(format!(
                        "{case} vs {reference}: {} relaxation steps",
                        p.steps
                    ));
                }
                Err(e) => out.rows.push(Row::failed(&case, "nodal displacements", e)),
            }
        }
    }
    out
}
