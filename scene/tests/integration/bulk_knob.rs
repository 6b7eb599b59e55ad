//! The incompressibility knob (`max_bulk_ratio` or `bulk_modulus` under `[[part]]`) and the
//! physical hourglass form in scenes.
//!
//! - A binding cap sets the law's bulk modulus to `ratio x G0`; the initial wave speed becomes
//!   `sqrt((K + 4 G / 3) / rho)`, and the stable step follows it with the surface-mode factor of
//!   the new moduli ([`solver::element::surface_mode_factor`]). The change is recorded for the
//!   summary. A cap above the law's K/G changes nothing, bit for bit, and says so.
//! - Both keys, a ratio at or below 2/3 (Poisson ratio 0 or less) or a non-positive modulus are
//!   refused with a message that names the part.
//! - One-point elements with physical hourglass stabilisation at K/G = 5e4 (the paper's flesh),
//!   pressed fast (20 % of the height in 1 ms, a smooth step peaking at 3.75 m/s) close their
//!   energy balance to 1 %.

use crate::common;
use scene::build::build_scene;
use scene::SceneSpec;
use solver::element::surface_mode_factor;
use std::path::Path;

fn scene(part_keys: &str, nu: f64) -> String {
    format!(
        r#"
[run]
end_time = "1 ms"
[mesh]
generator = "box"
size = ["10 mm", "10 mm", "10 mm"]
divisions = [3, 3, 3]
part = "block"
[materials.gel]
law = "neo_hookean"
density = "1000 kg/m^3"
shear_modulus = "10 kPa"
poisson_ratio = {nu}
[[part]]
name = "block"
material = "gel"
{part_keys}
[[boundary]]
nodes = "zmin"
fix = ["all"]
"#
    )
}

fn build_err(src: &str) -> String {
    let spec: SceneSpec = toml::from_str(src).unwrap();
    build_scene(spec, Path::new("knob.toml"), src)
        .err()
        .expect("must be refused")
}

#[test]
fn a_binding_cap_sets_k_and_the_step_follows() {
    let g = 1e4;
    let rho = 1000.0;
    let full = common::scene_from_str(&scene("", 0.49999));
    let capped = common::scene_from_str(&scene("max_bulk_ratio = 100", 0.49999));
    let m = &capped.setup.parts[0].material;
    assert!((m.bulk_modulus() - 100.0 * g).abs() < 1e-9 * 100.0 * g);
    assert!((m.initial_shear_modulus() - g).abs() < 1e-9 * g);
    let change = capped.setup.parts[0].bulk.as_ref().expect("stated");
    assert_eq!(change.applied_pa, m.bulk_modulus());
    assert!(change.original_pa > 1e4 * g);
    let c = ((100.0 * g + 4.0 / 3.0 * g) / rho).sqrt();
    assert!((m.initial_wave_speed() - c).abs() < 1e-12 * c);
    assert!((change.wave_speed_m_s[1] - c).abs() < 1e-12 * c);
    // The step: L / c times the surface-mode factor, each from the run's own moduli.
    let k_full = full.setup.parts[0].material.bulk_modulus();
    let c_full = ((k_full + 4.0 / 3.0 * g) / rho).sqrt();
    let kappa = |k: f64| surface_mode_factor(k + 4.0 / 3.0 * g, g);
    let expect = (c_full / c) * (kappa(100.0 * g) / kappa(k_full));
    let ratio = capped.sim.model.initial_dt.0 / full.sim.model.initial_dt.0;
    assert!(
        (ratio - expect).abs() < 1e-9 * expect,
        "step ratio {ratio}, expected {expect}"
    );
    assert!(capped
        .notes
        .iter()
        .any(|n| n.contains("max_bulk_ratio = 100")));
}

#[test]
fn a_cap_that_does_not_bind_changes_nothing_and_says_so() {
    let plain = common::scene_from_str(&scene("", 0.3));
    let capped = common::scene_from_str(&scene("max_bulk_ratio = 5000", 0.3));
    let (a, b) = (
        &plain.setup.parts[0].material,
        &capped.setup.parts[0].material,
    );
    assert_eq!(a.bulk_modulus().to_bits(), b.bulk_modulus().to_bits());
    assert_eq!(
        plain.sim.model.initial_dt.0.to_bits(),
        capped.sim.model.initial_dt.0.to_bits()
    );
    let change = capped.setup.parts[0].bulk.as_ref().expect("stated");
    assert_eq!(change.applied_pa, change.original_pa);
    assert!(change.describe().contains("does not bind"));
}

#[test]
fn a_stated_bulk_modulus_replaces_the_laws() {
    let s = common::scene_from_str(&scene("bulk_modulus = \"2 MPa\"", 0.49));
    assert!((s.setup.parts[0].material.bulk_modulus() - 2e6).abs() < 1e-6);
    // The card the deck exporter writes carries it too.
    match &s.setup.parts[0].spec {
        material::MaterialSpec::NeoHookean(i) => {
            assert_eq!(i.bulk_modulus.map(|k| k.0), Some(2e6));
            assert!(i.poisson_ratio.is_none());
        }
        other => panic!("card {other:?}"),
    }
}

#[test]
fn bad_knob_settings_are_refused_naming_the_part() {
    for (keys, needle) in [
        ("max_bulk_ratio = 10\nbulk_modulus = \"1 MPa\"", "not both"),
        ("max_bulk_ratio = 0.5", "max_bulk_ratio"),
        ("bulk_modulus = \"-1 MPa\"", "bulk modulus"),
        (
            "hourglass = \"physical\"\nhourglass_modulus = \"shear\"",
            "hourglass_modulus",
        ),
    ] {
        let err = build_err(&scene(keys, 0.45));
        assert!(err.contains(needle), "{keys}: {err}");
        assert!(err.contains("block"), "{keys}: {err}");
        assert!(err.contains("knob.toml"), "{keys}: {err}");
    }
}

#[test]
fn physical_hourglass_at_k_over_g_5e4_closes_its_energy_balance_in_a_fast_press() {
    // nu = 0.49999: K/G = 2 (1 + nu) / (3 (1 - 2 nu)) = 5.0e4.
    let src = scene("hourglass = \"physical\"", 0.49999).replace(
        "[[boundary]]\nnodes = \"zmin\"\nfix = [\"all\"]",
        "[[boundary]]\nnodes = \"zmin\"\nfix = [\"all\"]\n\
         [[boundary]]\nnodes = \"zmax\"\ndisplacement = { z = { kind = \"smooth_step\", value = \"-2 mm\", end = \"1 ms\" } }",
    );
    let mut s = common::scene_from_str(&src);
    assert!(!s.sim.model.groups[0].hg_frame.is_empty());
    let (cols, rows) = common::run_to_end(&mut s, "physical-press");
    let col = |n: &str| cols.iter().position(|c| c == n).unwrap();
    let last = rows.last().unwrap();
    let (err, hg, int) = (
        last[col("energy_error")],
        last[col("hourglass_energy")],
        last[col("internal_energy")],
    );
    assert!(err.is_finite() && err < 0.01, "energy error {err}");
    // The physical form books its energy as internal energy; no spurious modes here.
    assert!(int > 0.0 && hg == 0.0, "internal {int}, hourglass {hg}");
}
