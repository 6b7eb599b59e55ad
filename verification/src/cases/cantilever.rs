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
//! - One-point integration with physical hourglass stabilisation
//!   ([`solver::element::physical`]) gives the hourglass modes the energy of bending, so even
//!   one element through the thickness bends as beam theory says: within
//!   [`PHYSICAL_TOLERANCE`] of Timoshenko on every mesh, and on generated 10x1x1 and 10x2x2
//!   beams at nu = 0.3 and 0.49 (the form does not lock as nu -> 1/2). At 0.49 the converged
//!   beam (40x4x4, physical and F-bar alike) is 3 % below Timoshenko, from the clamped face;
//!   the 10x2x2 beam (2:1 elements, two across) is 5 % stiffer again and is shown only, the
//!   20x2x2 beam is checked.
//!
//! Timoshenko: P L^3/(3 E I) + P L/(kappa G A) = 0.4024 mm, kappa = 5/6 (at nu = 0; the
//! generated beams use G = E / (2 (1 + nu)) and kappa = 10 (1 + nu) / (12 + 11 nu), Cowper's
//! rectangular section).

use super::{short, FULL, FULL_FBAR, ONE_POINT_PHYSICAL, ONE_POINT_STIFFNESS};
use crate::data::{self, at, f, mesh, s, vec3, vec_u32};
use crate::quasi::{model, on, relax};
use crate::{CaseOutput, Row, Series};
use contact::Curve;
use material::linear_elastic::{Kinematics, LinearElastic};
use material::Material;
use solver::bc::NodalLoad;
use solver::element::Formulation;

/// Tolerance of palpa's plain fully integrated element against scikit-fem Q1 (relative).
pub const Q1_TOLERANCE: f64 = 1e-5;

/// Tolerance of the one-point element with physical hourglass stabilisation against
/// Timoshenko beam theory (relative).
pub const PHYSICAL_TOLERANCE: f64 = 0.05;

/// Tip deflection (m) of a generated beam `L x h x h` (the stored geometry), `divisions`
/// elements, Young's modulus `e` and Poisson ratio `nu`, clamped at x = 0 and loaded by the
/// stored total force as a uniform traction on x = L (Q1-consistent nodal forces); the tip
/// deflection is the load-weighted mean `f . u / P`. Returns it with the relaxation steps.
pub fn generated_tip(
    v: &serde_json::Value,
    divisions: [usize; 3],
    form: Formulation,
    e: f64,
    nu: f64,
) -> Result<(f64, u64), String> {
    let size = [
        f(v, "geometry.length"),
        f(v, "geometry.width_y"),
        f(v, "geometry.height_z"),
    ];
    let p = f(v, "load.total_force.2");
    let mesh = solver::generate::box_mesh(
        &solver::generate::BoxSpec {
            size,
            divisions,
            ..Default::default()
        },
        "beam",
    )?;
    let tol = 1e-9 * size[0];
    let clamp = mesh.nodes_on_plane(0, 0.0, tol);
    let tip_nodes = mesh.nodes_on_plane(0, size[0], tol);
    // Q1-consistent forces of a uniform traction: a quarter of each face's share per corner.
    let mut nodal = std::collections::BTreeMap::<u32, f64>::new();
    for face in mesh.boundary_faces() {
        if face.nodes.iter().all(|n| tip_nodes.contains(n)) {
            let share = p / (divisions[1] * divisions[2]) as f64 / 4.0;
            for n in face.nodes {
                *nodal.entry(n).or_default() += share;
            }
        }
    }
    let loads = nodal
        .iter()
        .map(|(&n, &fz)| NodalLoad {
            nodes: vec![n],
            dof: 2,
            curve: Curve::Constant { value: fz },
        })
        .collect();
    let c = (0..3).map(|d| on(&clamp, d, None)).collect();
    let mu = e / (2.0 * (1.0 + nu));
    let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let mat = Material::LinearElastic(LinearElastic {
        rho: 1000.0,
        lambda,
        mu,
        kinematics: Kinematics::Small,
    });
    let r = relax(model(mesh, mat, form)?, c, loads, 1e-8, 2_000_000)?.converged()?;
    let work: f64 = nodal
        .iter()
        .map(|(&n, &fz)| fz * r.sim.u[n as usize][2])
        .sum();
    Ok((work / p, r.steps))
}

/// Timoshenko tip deflection (m) of the stored beam at Young's modulus `e` and Poisson ratio
/// `nu` (Cowper's shear coefficient of a rectangle).
pub fn timoshenko(v: &serde_json::Value, e: f64, nu: f64) -> f64 {
    let (l, b, h) = (
        f(v, "geometry.length"),
        f(v, "geometry.width_y"),
        f(v, "geometry.height_z"),
    );
    let p = f(v, "load.total_force.2");
    let i = b * h.powi(3) / 12.0;
    let g = e / (2.0 * (1.0 + nu));
    let kappa = 10.0 * (1.0 + nu) / (12.0 + 11.0 * nu);
    p * l.powi(3) / (3.0 * e * i) + p * l / (kappa * g * b * h)
}

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
                    curve: Curve::Constant { value: v[d] },
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
    let r = relax(model(mesh, mat, form)?, c, loads, 1e-10, 600_000)?.converged()?;
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
    for form in [FULL, FULL_FBAR, ONE_POINT_STIFFNESS, ONE_POINT_PHYSICAL] {
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
                        (form == ONE_POINT_PHYSICAL).then_some(PHYSICAL_TOLERANCE),
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
    // Generated beams across Poisson ratios. At nu = 0.49 the converged 3-D beam is itself
    // about 3 % stiffer than Timoshenko (the clamped face restrains the contraction; F-bar
    // 40x4x4 shows it), and the 10x2x2 beam, whose elements are 2:1 with two across the
    // section, is 5 % stiffer again (shown, not checked; 20x2x2 is within 5 %).
    let e = f(&v, "material.E");
    for (div, nu, form, tol) in [
        (
            [10, 2, 2],
            0.0,
            ONE_POINT_PHYSICAL,
            Some(PHYSICAL_TOLERANCE),
        ),
        (
            [10, 1, 1],
            0.3,
            ONE_POINT_PHYSICAL,
            Some(PHYSICAL_TOLERANCE),
        ),
        (
            [10, 2, 2],
            0.3,
            ONE_POINT_PHYSICAL,
            Some(PHYSICAL_TOLERANCE),
        ),
        (
            [10, 1, 1],
            0.49,
            ONE_POINT_PHYSICAL,
            Some(PHYSICAL_TOLERANCE),
        ),
        ([10, 2, 2], 0.49, ONE_POINT_PHYSICAL, None),
        (
            [20, 2, 2],
            0.49,
            ONE_POINT_PHYSICAL,
            Some(PHYSICAL_TOLERANCE),
        ),
        (
            [40, 4, 4],
            0.49,
            ONE_POINT_PHYSICAL,
            Some(PHYSICAL_TOLERANCE),
        ),
        ([40, 4, 4], 0.49, FULL_FBAR, None),
    ] {
        let case = format!(
            "cantilever {}x{}x{} (generated), nu = {nu}, {}",
            div[0],
            div[1],
            div[2],
            short(&form)
        );
        let t = timoshenko(&v, e, nu);
        match generated_tip(&v, div, form, e, nu) {
            Ok((uz, steps)) => {
                out.rows.push(Row::compare(
                    &case,
                    "tip f.u/P (m)",
                    "Timoshenko beam (Cowper kappa)",
                    t,
                    uz,
                    t,
                    tol,
                ));
                out.notes.push(format!(
                    "{case}: tip {uz:.5e} m = {:.3} x Timoshenko ({steps} relaxation steps)",
                    uz / t
                ));
            }
            Err(err) => out.rows.push(Row::failed(&case, "tip f.u/P (m)", err)),
        }
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
