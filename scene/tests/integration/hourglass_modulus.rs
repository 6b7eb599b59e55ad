//! `hourglass_modulus = "shear"`: the stiffness-form hourglass coefficient of each element is
//! scaled by 2 mu instead of lambda + 2 mu, so the ratio of the two per element is
//! 2 mu / (lambda + 2 mu) = (1 - 2 nu) / (1 - nu) for a linear elastic or neo-Hookean solid;
//! the viscous form by sqrt of that ratio (c -> c sqrt(2 mu / (lambda + 2 mu))). Any other value is
//! refused with a message that names the key.

use crate::common;
use scene::build::build_scene;
use scene::SceneSpec;
use std::path::Path;

fn scene(form: &str, modulus: &str) -> String {
    format!(
        r#"
[run]
end_time = "1 ms"
[mesh]
generator = "box"
size = ["10 mm", "10 mm", "10 mm"]
divisions = [3, 3, 3]
distortion = 0.2
part = "block"
[materials.gel]
law = "neo_hookean"
density = "1000 kg/m^3"
youngs_modulus = "30 kPa"
poisson_ratio = 0.49
[[part]]
name = "block"
material = "gel"
hourglass = "{form}"
{modulus}
"#
    )
}

fn scales(src: &str) -> Vec<f64> {
    let sc = common::scene_from_str(src);
    sc.sim.model.groups[0].hg_scale.clone()
}

#[test]
fn shear_scaled_hourglass_uses_two_mu() {
    let nu: f64 = 0.49;
    let ratio = (1.0 - 2.0 * nu) / (1.0 - nu);
    for (form, expect) in [("stiffness", ratio), ("viscous", ratio.sqrt())] {
        let p = scales(&scene(form, ""));
        let s = scales(&scene(form, "hourglass_modulus = \"shear\""));
        assert_eq!(p.len(), 27);
        for (a, b) in p.iter().zip(&s) {
            let r = b / a;
            assert!(
                (r - expect).abs() < 1e-12 * expect,
                "{form}: ratio {r}, expected {expect}"
            );
        }
    }
}

#[test]
fn unknown_hourglass_modulus_is_refused_by_name() {
    let src = scene("viscous", "hourglass_modulus = \"bulk\"");
    let spec: SceneSpec = toml::from_str(&src).unwrap();
    let err = build_scene(spec, Path::new("hg.toml"), &src)
        .err()
        .expect("must be refused");
    assert!(err.contains("hourglass_modulus"), "{err}");
    assert!(err.contains("hg.toml"), "{err}");
}
