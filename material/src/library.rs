//! Named materials: the three tissues of the reference study, usable from any scene as
//! `material = "paper:liver"` (or a `{ library = "paper:liver" }` card).
//!
//! The cards are stored exactly as an LS-DYNA user would type them, in the paper's
//! kg-mm-ms-GPa unit system (`"1.05e-6 kg/mm^3"`, `"8.914e-8 GPa"`, `"0.1 1/ms"`), and go through
//! the same parsing and unit conversion as a scene's own cards, so the library doubles as a test
//! of the unit handling. Values: `docs/paper.md` (liver: Ogden eq. 1 + Prony
//! eqs. 2-3; flesh: simplified rubber/foam; ribs: piecewise-linear plasticity).

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

/// The card text of a named material; [`crate::named`] parses it.
pub fn card(name: &str) -> Result<&'static str, String> {
    ENTRIES
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, t)| *t)
        .ok_or_else(|| {
            let known: Vec<&str> = ENTRIES.iter().map(|(n, _)| *n).collect();
            format!(
                "unknown library material `{name}` (known: {})",
                known.join(", ")
            )
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unknown_names_list_the_known_ones() {
        assert!(card("paper:liver").unwrap().contains("law = \"ogden\""));
        let e = card("paper:spleen").unwrap_err();
        assert!(e.contains("paper:liver"), "{e}");
    }
}
