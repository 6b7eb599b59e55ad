//! Free vibration against closed forms (issue 2). (The struck bar's wave front is the
//! verification crate's `wave_arrival`, tested there and in `palpa verify`.)
//!
//! Cantilever free vibration: a clamped beam (nu = 0) started with the velocity of its first
//! Euler-Bernoulli mode, v_z(x) = v0 phi(x), phi = cosh bx - cos bx - s (sinh bx - sin bx),
//! bL = 1.87510, s = (cosh bL + cos bL)/(sinh bL + sin bL). The first period
//! T = 2 pi / ((bL)^2 sqrt(E I / (rho A L^4))) must be matched within 3 %.

use material::linear_elastic::{Kinematics, LinearElastic};
use material::Material;
use solver::bc::{Constraint, Kinematic};
use solver::element::{Formulation, Hourglass};
use solver::generate::{box_mesh, BoxSpec};
use solver::model::{Model, Part};
use solver::simulation::{LoopSettings, Simulation};

fn elastic(e: f64, nu: f64, rho: f64) -> Material {
    let (lambda, mu) = material::law::lame(e, nu);
    Material::LinearElastic(LinearElastic {
        rho,
        lambda,
        mu,
        kinematics: Kinematics::Green,
    })
}

fn cantilever_period(form: Formulation, div: [usize; 3], window: f64) -> (f64, f64) {
    let (e, rho, l, h) = (1e6, 1000.0, 0.1, 0.01);
    let mesh = box_mesh(
        &BoxSpec {
            size: [l, h, h],
            divisions: div,
            ..Default::default()
        },
        "beam",
    )
    .unwrap();
    let clamp = mesh.node_sets["xmin"].clone();
    let bl: f64 = 1.875_104_068_711_961;
    let s = (bl.cosh() + bl.cos()) / (bl.sinh() + bl.sin());
    let b = bl / l;
    let phi = |x: f64| (b * x).cosh() - (b * x).cos() - s * ((b * x).sinh() - (b * x).sin());
    let v0 = 1e-3;
    let vel: Vec<[f64; 3]> = mesh
        .nodes
        .iter()
        .map(|p| [0.0, 0.0, v0 * phi(p[0]) / phi(l)])
        .collect();
    let tip: Vec<u32> = mesh.node_sets["xmax"].clone();
    let model = Model::build(
        mesh,
        vec![Part {
            name: "beam".into(),
            material: elastic(e, 0.0, rho),
            formulation: form,
        }],
        None,
        0.9,
    )
    .unwrap();
    let c: Vec<Constraint> = (0..3)
        .map(|d| Constraint {
            nodes: clamp.clone(),
            dof: d,
            kind: Kinematic::Fixed,
        })
        .collect();
    let mut sim = Simulation::new(
        model,
        LoopSettings::default(),
        c,
        Vec::new(),
        Some(vel),
        false,
    )
    .unwrap();
    let t_eb = 2.0 * std::f64::consts::PI / (bl * bl * (e * h * h / 12.0 / rho / l.powi(4)).sqrt());
    let mut crossings = Vec::new();
    let mut prev = (0.0, 0.0);
    let mut max_err: f64 = 0.0;
    while sim.time < window * t_eb && crossings.len() < 2 {
        sim.step(f64::INFINITY).unwrap();
        let w: f64 = tip.iter().map(|&k| sim.u[k as usize][2]).sum::<f64>() / tip.len() as f64;
        if sim.step > 1 && prev.1 * w < 0.0 {
            crossings.push(prev.0 + (0.0 - prev.1) / (w - prev.1) * (sim.time - prev.0));
        }
        prev = (sim.time, w);
        if sim.time > 0.05 * t_eb {
            max_err = max_err.max(sim.energy.error());
        }
    }
    assert!(
        crossings.len() >= 2,
        "too few zero crossings: {crossings:?}"
    );
    // Crossings at T/2 and T: the period is twice their spacing.
    let t = 2.0 * (crossings[1] - crossings[0]);
    println!(
        "{} {:?}: period {:.5} s, beam theory {:.5} s, ratio {:.4}, max energy error {:.2e}",
        form.label(),
        div,
        t,
        t_eb,
        t / t_eb,
        max_err
    );
    (t / t_eb, max_err)
}

#[test]
/// Same layering effect as the viscous form; the stiffness form adds only a little bending stiffness.
fn cantilever_first_period_one_point_stiffness_hourglass() {
    let hg = Hourglass {
        form: solver::element::HourglassForm::Stiffness,
        coefficient: 0.1,
        modulus: solver::element::HourglassModulus::PWave,
    };
    let (ratio, err) = cantilever_period(Formulation::OnePoint(hg), [40, 4, 4], 1.3);
    assert!(ratio > 1.0 && ratio < 1.05, "period ratio {ratio}");
    assert!(err < 0.01, "energy error {err}");
}

#[test]
fn cantilever_first_period_fully_integrated() {
    let (ratio, err) = cantilever_period(Formulation::Full { fbar: false }, [40, 4, 4], 1.3);
    assert!((ratio - 1.0).abs() < 0.03, "period ratio {ratio}");
    assert!(err < 0.01, "energy error {err}");
}

/// One-point with viscous hourglass control on the same mesh: constant strain per layer gives
/// a bending stiffness of (1 - 1/n^2) of the exact one for n layers, so the period is about
/// 1/sqrt(1 - 1/16) = 3.3 % long on 4 layers, plus about 1 % of shear (Timoshenko): asserted
/// within 5 %, and longer than beam theory.
#[test]
fn cantilever_one_point_viscous_is_soft_by_layering() {
    let (ratio, err) =
        cantilever_period(Formulation::OnePoint(Hourglass::default()), [40, 4, 4], 1.3);
    assert!(ratio > 1.0 && ratio < 1.05, "period ratio {ratio}");
    assert!(err < 0.01, "energy error {err}");
}

/// Coarse mesh (one element through the depth): the fully integrated element locks in shear
/// (period too short) and the one-point element bends only through its hourglass stiffness
/// (period too long). Printed for the report; asserted only in direction.
#[test]
fn cantilever_coarse_mesh_formulations_differ() {
    let hg = Hourglass {
        form: solver::element::HourglassForm::Stiffness,
        coefficient: 0.1,
        modulus: solver::element::HourglassModulus::PWave,
    };
    let (r1, _) = cantilever_period(Formulation::OnePoint(hg), [10, 1, 1], 20.0);
    let (r2, _) = cantilever_period(Formulation::Full { fbar: false }, [10, 1, 1], 2.0);
    assert!(
        r2 < 1.0,
        "fully integrated coarse beam should lock (too stiff): ratio {r2}"
    );
    assert!(
        r1 > 1.0,
        "one-point coarse beam bends through hourglass stiffness only: ratio {r1}"
    );
}

/// One-point elements with physical hourglass stabilisation, one element through the depth:
/// the hourglass modes carry the bending energy, so the first period of the 10x1x1 beam is
/// that of beam theory within 3 % (Euler-Bernoulli; shear and rotary inertia lengthen it by
/// about 1 %), where the stiffness form is several times too long. The hourglass energy is
/// stored, so the balance closes to 1 %.
#[test]
fn cantilever_first_period_one_point_physical_on_one_element_through_the_depth() {
    let hg = Hourglass {
        form: solver::element::HourglassForm::Physical,
        coefficient: 1.0,
        modulus: solver::element::HourglassModulus::Shear,
    };
    for div in [[10, 1, 1], [20, 2, 2]] {
        let (ratio, err) = cantilever_period(Formulation::OnePoint(hg), div, 1.3);
        assert!((ratio - 1.0).abs() < 0.03, "{div:?}: period ratio {ratio}");
        assert!(err < 0.01, "{div:?}: energy error {err}");
    }
}
