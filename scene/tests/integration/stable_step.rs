//! The default stable step (factor 0.9 on kappa L / c) keeps nearly incompressible solids
//! stable: regular blocks of a nu = 0.49 linear-elastic and neo-Hookean solid and of the
//! paper's flesh (K/G = 5e4), one-point and F-bar, loaded on top, run 700-900 steps and keep
//! the energy balance within 1 %. Before the surface-mode factor kappa (issue 2), every
//! nearly incompressible case here stopped as numerically unstable within 35 steps at the
//! factor 0.9 (a free-surface mode up to 1/0.825 times faster than the interior bound L / c).
//! The eigenvalue study behind kappa is `verification/python/hex_stability_eigen.py`.

use crate::common;
use solver::element::surface_mode_factor;
use solver::output::history::column;

fn block(material: &str, formulation: &str, end_time: &str) -> String {
    format!(
        r#"
[run]
end_time = "{end_time}"

[mesh]
generator = "box"
size = ["10 mm", "8 mm", "6 mm"]
divisions = [10, 8, 6]
part = "block"

[materials.m]
{material}

[[part]]
name = "block"
material = "m"
formulation = "{formulation}"

[[boundary]]
nodes = "zmin"
fix = ["all"]

[[load]]
nodes = "zmax"
force = {{ z = {{ kind = "ramp", value = "-0.05 N", end = "{end_time}" }} }}
total = true

[output]
vtk = false
history_interval = "{end_time}"
"#
    )
}

const NU49: &str = r#"density = "1000 kg/m^3"
youngs_modulus = "300 kPa"
poisson_ratio = 0.49"#;

/// (label, material, end time giving ~800 steps at the expected step).
fn cases() -> Vec<(&'static str, String, &'static str)> {
    vec![
        (
            "linear elastic nu 0.49",
            format!("law = \"linear_elastic\"\n{NU49}"),
            "8 ms",
        ),
        (
            "neo-Hookean nu 0.49",
            format!("law = \"neo_hookean\"\n{NU49}"),
            "8 ms",
        ),
        (
            "paper flesh",
            "library = \"paper:flesh\"".to_string(),
            "0.4 ms",
        ),
    ]
}

#[test]
fn nearly_incompressible_blocks_are_stable_at_the_default_factor() {
    for (label, mat, end) in cases() {
        for form in ["one_point", "full_fbar"] {
            let mut scene = common::scene_from_str(&block(&mat, form, end));
            let model = &scene.sim.model;
            let kappa = model.groups[0].dt_kappa;
            assert!(
                (0.82..0.84).contains(&kappa),
                "{label}: kappa {kappa} for a nearly incompressible law"
            );
            let (cols, rows) = common::run_to_end(&mut scene, "stable-step");
            let err = column(&cols, &rows, "energy_error").unwrap();
            let worst = err.iter().cloned().fold(0.0, f64::max);
            let steps = scene.sim.step;
            println!(
                "{label}, {form}: {steps} steps, kappa {kappa:.4}, max energy error {:.4} %",
                100.0 * worst
            );
            assert!(steps > 500, "{label}, {form}: only {steps} steps");
            assert!(
                worst < 0.01,
                "{label}, {form}: energy error {:.3} %",
                100.0 * worst
            );
        }
    }
}

#[test]
fn surface_mode_factor_stays_below_the_measured_limits() {
    // (nu, smallest dt_crit / (h / c) of the three meshes of hex_stability_eigen.py)
    let measured = [
        (0.0, 1.0),
        (0.3, 0.9495),
        (0.45, 0.8615),
        (0.49, 0.8322),
        (0.4999, 0.8247),
    ];
    for (nu, limit) in measured {
        let lambda = nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let mu = 1.0 / (2.0 * (1.0 + nu));
        let k = surface_mode_factor(lambda + 2.0 * mu, mu);
        assert!(
            k <= limit + 1e-12,
            "nu {nu}: kappa {k} above the limit {limit}"
        );
        assert!(
            k > limit - 0.045,
            "nu {nu}: kappa {k} needlessly small (limit {limit})"
        );
    }
    // A law with a negative Poisson ratio (lambda < 0) gets no reduction.
    assert_eq!(surface_mode_factor(1.0, 0.6), 1.0);
}
