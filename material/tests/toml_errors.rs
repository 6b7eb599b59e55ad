//! `material::toml_error`: an unknown key in a material card placed on its own line, a
//! nested table's unknown field named with its table, toml's own message otherwise.

use material::spec::MaterialSpec;
use material::toml_error::describe;
use std::collections::BTreeMap;
use std::path::Path;

#[derive(Debug, serde::Deserialize)]
#[allow(dead_code)]
struct Scene {
    materials: BTreeMap<String, MaterialSpec>,
}

fn message(src: &str) -> String {
    let e = toml::from_str::<Scene>(src).unwrap_err();
    describe(Path::new("s.toml"), src, &e)
}

#[test]
fn an_unknown_key_in_a_material_card_is_placed_on_its_line() {
    let src = "# a scene\n[materials.rubber]\nlaw = \"neo_hookean\"\ndensity = \"1000 kg/m^3\"\n  shear_modulas = \"1 kPa\"\n\n[materials.other]\nlaw = \"neo_hookean\"\n";
    let m = message(src);
    assert!(
        m.starts_with("s.toml: TOML parse error at line 5, column 3\n"),
        "{m}"
    );
    assert!(
        m.contains("\n5 |   shear_modulas = \"1 kPa\"\n  |   ^^^^^^^^^^^^^\n"),
        "{m}"
    );
    assert!(
        m.contains("unknown field `shear_modulas`, expected one of"),
        "{m}"
    );
    // quoted, with spaces before `=`
    let m = message(&src.replace("  shear_modulas =", "\"shear_modulas\"   ="));
    assert!(m.contains("line 5, column 1"), "{m}");
}

#[test]
fn a_nested_field_named_like_a_card_key_is_not_placed_on_the_card_s_key() {
    // a Prony term's unknown `density`: the card's own `density` (line 3) is valid
    let card = "[materials.a]\nlaw = \"ogden\"\ndensity = \"1000 kg/m^3\"\nmu = [\"1 kPa\"]\nalpha = [2.0]\nbulk_modulus = \"1 MPa\"\n";
    for prony in [
        "[[materials.a.prony]]\nmodulus = \"1 kPa\"\ndensity = 3.0\n",
        "prony = [{ modulus = \"1 kPa\", tau = \"1 ms\" }, { modulus = \"1 kPa\", density = 2.0 }]\n",
    ] {
        let src = if prony.starts_with('[') {
            format!("{card}{prony}")
        } else {
            card.replace("mu =", &format!("{prony}mu ="))
        };
        let m = message(&src);
        assert!(!m.contains("line 3"), "{m}");
        assert!(m.contains("in `prony` (entry "), "{m}");
        assert!(m.contains("unknown field `density`, expected"), "{m}");
    }
    // the nested term's own line is not found from the card's header: toml's place stays
    let m = message(&format!(
        "{card}[[materials.a.prony]]\nmodulus = \"1 kPa\"\ntaux = 1.0\n"
    ));
    assert!(
        m.contains("in `prony` (entry 1): unknown field `taux`"),
        "{m}"
    );
}

#[test]
fn carets_count_characters_and_keep_tabs() {
    let src = "[materials.rubber]\nlaw = \"neo_hookean\"\n\t\"dénsité x\" = 1.0\n";
    let m = message(src);
    assert!(m.contains("line 3, column 2\n"), "{m}");
    assert!(m.contains("\n  | \t^^^^^^^^^^^\n"), "{m}");
}

#[test]
fn other_errors_are_toml_s_own() {
    // a missing field, and a syntax error
    let src = "[materials.rubber]\nlaw = \"neo_hookean\"\n[materials.b]\nbogus = 1\n";
    let e = toml::from_str::<Scene>(src).unwrap_err();
    assert_eq!(
        describe(Path::new("s.toml"), src, &e),
        format!("s.toml: {}", e.to_string().trim_end())
    );
    let src = "[materials.rubber\n";
    let e = toml::from_str::<Scene>(src).unwrap_err();
    assert_eq!(
        describe(Path::new("s.toml"), src, &e),
        format!("s.toml: {}", e.to_string().trim_end())
    );
}
