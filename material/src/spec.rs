//! Material cards as written in a scene file (`[materials.NAME]`), with explicit units,
//! and their validation into a [`Material`].
//!
//! ```toml
//! [materials.rubber]
//! law = "neo_hookean"            # linear_elastic | neo_hookean | ... (see README)
//! density = "1000 kg/m^3"
//! youngs_modulus = "1 MPa"       # or shear_modulus + bulk_modulus, or shear_modulus + poisson_ratio
//! poisson_ratio = 0.3
//! ```

use crate::linear_elastic::{Kinematics, LinearElastic};
use crate::neo_hookean::NeoHookean;
use crate::quantity::{Density, Number, Pressure};
use crate::Material;
use serde::Deserialize;

/// Isotropic elastic constants: any two of E, nu, G, K.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IsotropicSpec {
    /// Density.
    pub density: Density,
    /// Young's modulus.
    pub youngs_modulus: Option<Pressure>,
    /// Poisson ratio.
    pub poisson_ratio: Option<Number>,
    /// Shear modulus.
    pub shear_modulus: Option<Pressure>,
    /// Bulk modulus.
    pub bulk_modulus: Option<Pressure>,
    /// `green` (default, objective) or `small` (linear_elastic only; exact small-strain Hooke).
    pub strain: Option<String>,
}

/// A material card, tagged by `law`.
#[derive(Clone, Debug, Deserialize)]
#[serde(tag = "law", rename_all = "snake_case")]
pub enum MaterialSpec {
    /// Linear isotropic elasticity.
    LinearElastic(IsotropicSpec),
    /// Compressible neo-Hookean.
    NeoHookean(IsotropicSpec),
}

fn positive(name: &str, field: &str, v: f64) -> Result<f64, String> {
    if v > 0.0 && v.is_finite() {
        Ok(v)
    } else {
        Err(format!("material `{name}`: `{field}` must be positive, got {v:e} (SI)"))
    }
}

impl IsotropicSpec {
    /// (lambda, mu) from whichever pair of constants is given.
    pub fn lame(&self, name: &str) -> Result<(f64, f64), String> {
        positive(name, "density", self.density.0)?;
        let e = self.youngs_modulus.map(|x| x.0);
        let nu = self.poisson_ratio.map(|x| x.0);
        let g = self.shear_modulus.map(|x| x.0);
        let k = self.bulk_modulus.map(|x| x.0);
        let check_nu = |nu: f64| {
            if nu > -1.0 && nu < 0.5 {
                Ok(nu)
            } else {
                Err(format!("material `{name}`: `poisson_ratio` must lie in (-1, 0.5), got {nu}"))
            }
        };
        let (mu, kb) = match (e, nu, g, k) {
            (Some(e), Some(nu), None, None) => {
                let e = positive(name, "youngs_modulus", e)?;
                let nu = check_nu(nu)?;
                (e / (2.0 * (1.0 + nu)), e / (3.0 * (1.0 - 2.0 * nu)))
            }
            (None, None, Some(g), Some(k)) => (
                positive(name, "shear_modulus", g)?,
                positive(name, "bulk_modulus", k)?,
            ),
            (None, Some(nu), Some(g), None) => {
                let g = positive(name, "shear_modulus", g)?;
                let nu = check_nu(nu)?;
                (g, 2.0 * g * (1.0 + nu) / (3.0 * (1.0 - 2.0 * nu)))
            }
            (Some(e), None, Some(g), None) => {
                let e = positive(name, "youngs_modulus", e)?;
                let g = positive(name, "shear_modulus", g)?;
                (g, e * g / (3.0 * (3.0 * g - e)))
            }
            _ => {
                return Err(format!(
                    "material `{name}`: give exactly two elastic constants: youngs_modulus + poisson_ratio, \
                     shear_modulus + bulk_modulus, shear_modulus + poisson_ratio, or youngs_modulus + shear_modulus"
                ))
            }
        };
        let lambda = kb - 2.0 * mu / 3.0;
        if !(kb > 0.0) || !(lambda + 2.0 * mu > 0.0) {
            return Err(format!("material `{name}`: elastic constants give a non-positive bulk modulus"));
        }
        Ok((lambda, mu))
    }
}

impl MaterialSpec {
    /// Validate and build the law.
    pub fn build(&self, name: &str) -> Result<Material, String> {
        Ok(match self {
            MaterialSpec::LinearElastic(s) => {
                let (lambda, mu) = s.lame(name)?;
                let kinematics = match s.strain.as_deref() {
                    None | Some("green") => Kinematics::Green,
                    Some("small") => Kinematics::Small,
                    Some(o) => {
                        return Err(format!("material `{name}`: `strain` must be `green` or `small`, got `{o}`"))
                    }
                };
                Material::LinearElastic(LinearElastic { rho: s.density.0, lambda, mu, kinematics })
            }
            MaterialSpec::NeoHookean(s) => {
                if s.strain.is_some() {
                    return Err(format!("material `{name}`: `strain` applies to linear_elastic only"));
                }
                let (lambda, mu) = s.lame(name)?;
                Material::NeoHookean(NeoHookean { rho: s.density.0, lambda, mu })
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn negative_modulus_is_refused_by_name() {
        let s: MaterialSpec = toml::from_str(
            "law = \"neo_hookean\"\ndensity = \"1000 kg/m^3\"\nyoungs_modulus = \"-1 MPa\"\npoisson_ratio = 0.3",
        )
        .unwrap();
        let e = s.build("rubber").unwrap_err();
        assert!(e.contains("rubber") && e.contains("youngs_modulus"), "{e}");
    }

    #[test]
    fn constants_convert() {
        let s: MaterialSpec = toml::from_str(
            "law = \"linear_elastic\"\ndensity = 1000\nshear_modulus = \"40 kPa\"\nbulk_modulus = \"2 GPa\"",
        )
        .unwrap();
        match s.build("flesh").unwrap() {
            Material::LinearElastic(l) => {
                assert!((l.mu - 4e4).abs() < 1e-6);
                assert!((l.lambda + 2.0 * l.mu / 3.0 - 2e9).abs() < 1e-3);
            }
            _ => panic!(),
        }
    }
}
