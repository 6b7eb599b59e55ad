//! The smallest runnable scene, shared by the command-line tests: a 10 mm neo-Hookean cube of
//! 2 x 2 x 2 hexahedra, clamped at its base, ending at 1 ms.

/// The scene's text (`end_time = "1 ms"`).
pub const BLOCK: &str = r#"
[run]
end_time = "1 ms"
[mesh]
generator = "box"
size = ["10 mm", "10 mm", "10 mm"]
divisions = [2, 2, 2]
part = "block"
[materials.rubber]
law = "neo_hookean"
density = "1000 kg/m^3"
youngs_modulus = "1 MPa"
poisson_ratio = 0.3
[[part]]
name = "block"
material = "rubber"
[[boundary]]
nodes = "zmin"
fix = ["all"]
"#;
