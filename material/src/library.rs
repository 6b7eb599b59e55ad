//! Named materials: the three tissues of the reference study, usable from any scene as
//! `material = "paper:liver"` (or a `{ library = "paper:liver" }` card).
//!
//! The cards are stored exactly as an LS-DYNA user would type them, in the paper's
//! kg-mm-ms-GPa unit system (`"1.05e-6 kg/mm^3"`, `"8.914e-8 GPa"`, `"0.1 1/ms"`), and go through
//! the same parsing and unit conversion as a scene's own cards, so the library doubles as a test
//! of the unit handling. Values: `docs/paper.md` (liver: Ogden eq. 1 + Prony
//! eqs. 2-3; flesh: simplified rubber/foam; ribs: piecewise-linear plasticity).

use crate::spec::MaterialSpec;

/// Prefix of every library name.
pub const PREFIX: &str = "paper:";

/// Liver: 3-term Ogden (original form) + 3-term Prony series, nu = 0.49.
/// Prony decay constants beta_i = 1/tau_i as LS-DYNA writes them (tau = 10, 100, 1000 ms).
pub const LIVER: &str = r#"
law = "ogden"
density = "1.05e-6 kg/mm^3"
mu = ["8.914e-8 GPa", "9.965e-9 GPa", "-9.275e-8 GPa"]
alpha = [1.0, 19.0656, -10.9604]
poisson_ratio = 0.49
prony = [
  { modulus = "6.9701e-6 GPa", decay = "0.1 1/ms" },
  { modulus = "5.8327e-5 GPa", decay = "0.01 1/ms" },
  { modulus = "3.5291e-5 GPa", tau = "1000 ms" },
]
prony_on = "green_lagrange"
"#;

/// Flesh (lumped abdominal tissue): simplified rubber/foam, K = 2 GPa, G = 40 kPa, damping 0.40.
pub const FLESH: &str = r#"
law = "simplified_rubber"
density = "1.06e-6 kg/mm^3"
bulk_modulus = "2 GPa"
shear_modulus = "4e-5 GPa"
damping = 0.40
"#;

/// Ribs: bilinear piecewise-linear plasticity.
pub const RIBS: &str = r#"
law = "piecewise_linear_plasticity"
density = "1e-6 kg/mm^3"
youngs_modulus = "0.04 GPa"
poisson_ratio = 0.45
yield_stress = "0.0018 GPa"
tangent_modulus = "0.001 GPa"
"#;

/// Every library name and its card text.
pub const ENTRIES: [(&str, &str); 3] = [
    ("paper:liver", LIVER),
    ("paper:flesh", FLESH),
    ("paper:ribs", RIBS),
];

/// Whether `name` looks like a library name (starts with `paper:`).
pub fn is_library_name(name: &str) -> bool {
    name.starts_with(PREFIX)
}

/// The card of a named material.
pub fn named(name: &str) -> Result<MaterialSpec, String> {
    let text = ENTRIES
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, t)| *t)
        .ok_or_else(|| {
            let known: Vec<&str> = ENTRIES.iter().map(|(n, _)| *n).collect();
            format!(
                "unknown library material `{name}` (known: {})",
                known.join(", ")
            )
        })?;
    toml::from_str::<MaterialSpec>(text).map_err(|e| format!("library material `{name}`: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Law, Material};

    #[test]
    fn paper_units_convert_to_si() {
        match named("paper:liver").unwrap().build("liver").unwrap() {
            Material::Ogden(o) => {
                assert!((o.rho - 1050.0).abs() < 1e-9);
                assert!((o.mu()[0] - 89.14).abs() < 1e-9 && (o.mu()[2] + 92.75).abs() < 1e-9);
                assert!((o.mu0() - 647.85).abs() < 0.01);
                assert!((o.bulk - 32_177.0).abs() < 5.0, "{}", o.bulk);
                let p = o.prony();
                assert_eq!(p.len(), 3);
                for (t, (g, tau)) in p
                    .iter()
                    .zip([(6970.1, 0.01), (58327.0, 0.1), (35291.0, 1.0)])
                {
                    assert!(
                        (t.modulus - g).abs() < 1e-6 * g && (t.tau - tau).abs() < 1e-12,
                        "{t:?}"
                    );
                }
                assert_eq!(o.history_len(), 24);
            }
            _ => panic!(),
        }
        match named("paper:flesh").unwrap().build("flesh").unwrap() {
            Material::SimplifiedRubber(f) => {
                assert!((f.rho - 1060.0).abs() < 1e-9 && (f.bulk - 2e9).abs() < 1e-3);
                assert!((f.shear - 4e4).abs() < 1e-6 && (f.damping - 0.4).abs() < 1e-15);
                assert!((f.initial_wave_speed() - 1373.6).abs() < 0.5);
            }
            _ => panic!(),
        }
        match named("paper:ribs").unwrap().build("ribs").unwrap() {
            Material::PiecewiseLinearPlasticity(p) => {
                assert!((p.rho - 1000.0).abs() < 1e-9);
                assert!((p.shear - 40e6 / 2.9).abs() < 1e-3);
                assert!((p.yield_stress(0.0) - 1.8e6).abs() < 1e-6);
                // H = E Et / (E - Et) = 40/39 MPa.
                assert!((p.yield_stress(0.1) - 1.8e6 - 0.1 * 40e6 / 39.0).abs() < 1e-3);
            }
            _ => panic!(),
        }
    }

    #[test]
    fn names_resolve_in_cards_and_strings() {
        #[derive(serde::Deserialize)]
        struct S {
            a: MaterialSpec,
            b: MaterialSpec,
        }
        let s: S = toml::from_str("a = \"paper:ribs\"\n[b]\nlibrary = \"paper:liver\"\n").unwrap();
        assert!(matches!(s.a, MaterialSpec::PiecewiseLinearPlasticity(_)));
        assert!(matches!(s.b, MaterialSpec::Ogden(_)));
        let e = named("paper:spleen").unwrap_err();
        assert!(e.contains("paper:liver"), "{e}");
        assert!(toml::from_str::<S>(
            "a = \"paper:ribs\"\n[b]\nlibrary = \"paper:liver\"\ndensity = 1\n"
        )
        .is_err());
    }
}
