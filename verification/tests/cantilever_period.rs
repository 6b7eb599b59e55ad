//! Cantilever free vibration against beam theory (issue 2), on the verification case's beam
//! ([`verification::cases::closed::cantilever_period`]): the first period of each element
//! formulation on a fine and a coarse mesh, and the energy balance.

use solver::element::Formulation;
use verification::cases::{ONE_POINT_PHYSICAL, ONE_POINT_STIFFNESS, ONE_POINT_VISCOUS};

/// Period over beam theory's, and the largest energy error, within `window` periods.
fn cantilever_period(form: Formulation, div: [usize; 3], window: f64) -> (f64, f64) {
    let (t, t_eb, max_err, _) =
        verification::cases::closed::cantilever_period(form, div, window).unwrap();
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
    let (ratio, err) = cantilever_period(ONE_POINT_STIFFNESS, [40, 4, 4], 1.3);
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
    let (ratio, err) = cantilever_period(ONE_POINT_VISCOUS, [40, 4, 4], 1.3);
    assert!(ratio > 1.0 && ratio < 1.05, "period ratio {ratio}");
    assert!(err < 0.01, "energy error {err}");
}

/// Coarse mesh (one element through the depth): the fully integrated element locks in shear
/// (period too short) and the one-point element bends only through its hourglass stiffness
/// (period too long). Printed for the report; asserted only in direction.
#[test]
fn cantilever_coarse_mesh_formulations_differ() {
    let (r1, _) = cantilever_period(ONE_POINT_STIFFNESS, [10, 1, 1], 20.0);
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
    for div in [[10, 1, 1], [20, 2, 2]] {
        let (ratio, err) = cantilever_period(ONE_POINT_PHYSICAL, div, 1.3);
        assert!((ratio - 1.0).abs() < 0.03, "{div:?}: period ratio {ratio}");
        assert!(err < 0.01, "{div:?}: energy error {err}");
    }
}
