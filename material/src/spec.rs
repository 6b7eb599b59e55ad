//! Material cards as written in a scene file (`[materials.NAME]`), with explicit units,
//! and their validation into a [`Material`].
//!
//! ```toml
//! [materials.rubber]
//! law = "neo_hookean"            # linear_elastic | neo_hookean | ogden | simplified_rubber
//!                                # | piecewise_linear_plasticity
//! density = "1000 kg/m^3"
//! youngs_modulus = "1 MPa"       # or shear_modulus + bulk_modulus, or shear_modulus + poisson_ratio
//! poisson_ratio = 0.3
//!
//! [materials.liver]
//! law = "ogden"                  # ORIGINAL Ogden form: Psi = sum mu_p/alpha_p (l1^a + l2^a + l3^a - 3)
//! density = "1050 kg/m^3"
//! mu = ["89.14 Pa", "9.965 Pa", "-92.75 Pa"]
//! alpha = [1.0, 19.0656, -10.9604]
//! poisson_ratio = 0.49           # or bulk_modulus = "32.2 kPa"
//! # convention = "abaqus"        # if mu_p are Abaqus/CalculiX/FElupe constants (2 mu_p/alpha_p^2 form)
//! prony = [{ modulus = "6970.1 Pa", tau = "10 ms" },      # or decay = "100 1/s" (beta = 1/tau)
//!          { modulus = "58327 Pa", tau = "100 ms" },
//!          { modulus = "35291 Pa", tau = "1 s" }]
//! prony_on = "green_lagrange"    # (paper eq. 2, default) or "deviatoric"
//!
//! [materials.flesh]
//! law = "simplified_rubber"      # MAT_181 style; alias "foam"
//! density = "1060 kg/m^3"
//! bulk_modulus = "2 GPa"
//! shear_modulus = "40 kPa"       # without a curve: P = G (l - l^-2)
//! damping = 0.40
//! # curve = [[0.5, "-140 kPa"], [1.0, 0], [1.5, "42.2 kPa"]]  # nominal stress vs stretch
//! # curve_file = "flesh.csv"     # rows: stretch, stress (plain numbers are Pa; "12 kPa" allowed)
//!
//! [materials.ribs]
//! law = "piecewise_linear_plasticity"   # MAT_024 style; alias "plasticity"
//! density = "1000 kg/m^3"
//! youngs_modulus = "40 MPa"
//! poisson_ratio = 0.45
//! yield_stress = "1.8 MPa"
//! tangent_modulus = "1 MPa"      # or hardening = [[0, "1.8 MPa"], [0.1, "1.9 MPa"], ...]
//! # failure_strain = 0.3         # effective plastic strain at which the element is eroded
//!
//! [materials.liver_again]
//! library = "paper:liver"        # a named material (see `library`); a bare string
//!                                # "paper:liver" is accepted wherever a card is
//! ```

use crate::foam::{Foam, UniaxialCurve};
use crate::linear_elastic::{Kinematics, LinearElastic};
use crate::neo_hookean::NeoHookean;
use crate::ogden::{Ogden, PronyOn, PronyTerm};
use crate::plasticity::Plasticity;
use crate::quantity::{Density, Number, Pressure, Quantity, Rate, Time};
use crate::Material;
use serde::{Deserialize, Deserializer};
use std::path::{Path, PathBuf};

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

/// One Prony term: `{ modulus = "6970.1 Pa", tau = "10 ms" }` or `{ modulus = ..., decay = "100 1/s" }`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PronySpec {
    /// Shear relaxation modulus G_i.
    pub modulus: Pressure,
    /// Relaxation time tau_i.
    pub tau: Option<Time>,
    /// Decay constant beta_i = 1/tau_i (LS-DYNA's BETA).
    pub decay: Option<Rate>,
}

/// `law = "ogden"`: N-term Ogden (original form) with optional Prony series.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OgdenSpec {
    /// Density.
    pub density: Density,
    /// Ogden moduli mu_p, original form `mu_p / alpha_p` unless `convention = "abaqus"`.
    pub mu: Vec<Pressure>,
    /// Ogden exponents alpha_p.
    pub alpha: Vec<Number>,
    /// Bulk modulus K (or give `poisson_ratio`).
    pub bulk_modulus: Option<Pressure>,
    /// Poisson ratio: K = 2 mu0 (1 + nu) / (3 (1 - 2 nu)), mu0 = 1/2 sum mu_p alpha_p.
    pub poisson_ratio: Option<Number>,
    /// `original` (default; alias `ls_dyna`) or `abaqus` (`2 mu_p / alpha_p^2` form).
    pub convention: Option<String>,
    /// Prony terms.
    #[serde(default)]
    pub prony: Vec<PronySpec>,
    /// `green_lagrange` (default, paper eq. 2) or `deviatoric`.
    pub prony_on: Option<String>,
}

/// `law = "simplified_rubber"` (alias `foam`): MAT_181-style tabulated Valanis-Landel law.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FoamSpec {
    /// Density.
    pub density: Density,
    /// Bulk modulus K.
    pub bulk_modulus: Pressure,
    /// Shear modulus G: the default curve P = G (l - l^-2) and the damping scale.
    pub shear_modulus: Option<Pressure>,
    /// Dimensionless damping coefficient (LS-DYNA MU; 0 by default).
    pub damping: Option<Number>,
    /// Uniaxial nominal stress against stretch: `[[stretch, "stress"], ...]`.
    pub curve: Option<Vec<(Number, Pressure)>>,
    /// The same curve from a CSV file (`stretch, stress` per row), relative to the scene file.
    pub curve_file: Option<String>,
}

/// `law = "piecewise_linear_plasticity"` (alias `plasticity`): MAT_024-style J2 plasticity.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlasticitySpec {
    /// Density.
    pub density: Density,
    /// Young's modulus E.
    pub youngs_modulus: Pressure,
    /// Poisson ratio.
    pub poisson_ratio: Number,
    /// Initial yield stress (with `tangent_modulus`).
    pub yield_stress: Option<Pressure>,
    /// Tangent modulus E_t of the bilinear stress-strain curve (0 for perfect plasticity).
    pub tangent_modulus: Option<Pressure>,
    /// Or: yield stress against effective plastic strain, `[[0, "1.8 MPa"], [0.1, "2 MPa"]]`.
    pub hardening: Option<Vec<(Number, Pressure)>>,
    /// Effective plastic strain at which the point fails (element erosion).
    pub failure_strain: Option<Number>,
}

/// The parsed card of a named material ([`crate::library`]).
pub fn named(name: &str) -> Result<MaterialSpec, String> {
    let text = crate::library::card(name)?;
    toml::from_str::<MaterialSpec>(text).map_err(|e| format!("library material `{name}`: {e}"))
}

/// A material card, tagged by `law`. It also deserializes from a library name
/// (`"paper:liver"`) or a `{ library = "paper:liver" }` table, which resolve through
/// [`named`] to the card stored in [`crate::library`].
#[derive(Clone, Debug)]
pub enum MaterialSpec {
    /// Linear isotropic elasticity.
    LinearElastic(IsotropicSpec),
    /// Compressible neo-Hookean.
    NeoHookean(IsotropicSpec),
    /// Ogden + Prony.
    Ogden(OgdenSpec),
    /// Simplified rubber/foam.
    SimplifiedRubber(FoamSpec),
    /// Piecewise-linear plasticity.
    PiecewiseLinearPlasticity(PlasticitySpec),
}

/// The tagged form of a card, as derived by serde.
#[derive(Deserialize)]
#[serde(tag = "law", rename_all = "snake_case")]
enum TaggedCard {
    LinearElastic(IsotropicSpec),
    NeoHookean(IsotropicSpec),
    Ogden(OgdenSpec),
    #[serde(alias = "foam")]
    SimplifiedRubber(FoamSpec),
    #[serde(alias = "plasticity")]
    PiecewiseLinearPlasticity(PlasticitySpec),
}

impl From<TaggedCard> for MaterialSpec {
    fn from(t: TaggedCard) -> Self {
        match t {
            TaggedCard::LinearElastic(s) => MaterialSpec::LinearElastic(s),
            TaggedCard::NeoHookean(s) => MaterialSpec::NeoHookean(s),
            TaggedCard::Ogden(s) => MaterialSpec::Ogden(s),
            TaggedCard::SimplifiedRubber(s) => MaterialSpec::SimplifiedRubber(s),
            TaggedCard::PiecewiseLinearPlasticity(s) => MaterialSpec::PiecewiseLinearPlasticity(s),
        }
    }
}

impl<'de> Deserialize<'de> for MaterialSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        let v = toml::Value::deserialize(d)?;
        match &v {
            toml::Value::String(name) => named(name).map_err(D::Error::custom),
            toml::Value::Table(t) if t.contains_key("library") => {
                if t.len() != 1 {
                    return Err(D::Error::custom(
                        "a `library = \"...\"` material takes no other keys (copy the card to change it)",
                    ));
                }
                match &t["library"] {
                    toml::Value::String(name) => named(name).map_err(D::Error::custom),
                    _ => Err(D::Error::custom(
                        "`library` must be a string such as \"paper:liver\"",
                    )),
                }
            }
            _ => TaggedCard::deserialize(v.clone())
                .map(MaterialSpec::from)
                .map_err(|e| D::Error::custom(crate::toml_error::name_nested(&v, e.message()))),
        }
    }
}

fn positive(name: &str, field: &str, v: f64) -> Result<f64, String> {
    if v > 0.0 && v.is_finite() {
        Ok(v)
    } else {
        Err(format!(
            "material `{name}`: `{field}` must be positive, got {v:e} (SI)"
        ))
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
                Err(format!(
                    "material `{name}`: `poisson_ratio` must lie in (-1, 0.5), got {nu}"
                ))
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
            return Err(format!(
                "material `{name}`: elastic constants give a non-positive bulk modulus"
            ));
        }
        Ok((lambda, mu))
    }
}

impl MaterialSpec {
    /// The same card with the small-strain bulk modulus `k` (Pa), given the law's shear modulus
    /// `g` (Pa): isotropic cards become `shear_modulus` + `bulk_modulus`, an Ogden card states
    /// `bulk_modulus` instead of a Poisson ratio, a plasticity card gets the Young's modulus and
    /// Poisson ratio of (`k`, `g`). It describes [`crate::Material::with_bulk_modulus`], so an
    /// exported deck carries the bulk modulus that ran.
    pub fn with_bulk_modulus(&self, k: f64, g: f64) -> MaterialSpec {
        let mut s = self.clone();
        match &mut s {
            MaterialSpec::LinearElastic(i) | MaterialSpec::NeoHookean(i) => {
                i.youngs_modulus = None;
                i.poisson_ratio = None;
                i.shear_modulus = Some(Pressure(g));
                i.bulk_modulus = Some(Pressure(k));
            }
            MaterialSpec::Ogden(o) => {
                o.poisson_ratio = None;
                o.bulk_modulus = Some(Pressure(k));
            }
            MaterialSpec::SimplifiedRubber(f) => f.bulk_modulus = Pressure(k),
            MaterialSpec::PiecewiseLinearPlasticity(p) => {
                let (e, nu) = crate::law::young_poisson(k, g);
                p.youngs_modulus = Pressure(e);
                p.poisson_ratio = Number(nu);
            }
        }
        s
    }

    /// Validate and build the law (a `curve_file` is read relative to the working directory).
    pub fn build(&self, name: &str) -> Result<Material, String> {
        self.build_in(name, None)
    }

    /// Validate and build the law; a relative `curve_file` is read from `base_dir` (the scene
    /// file's directory) when given.
    pub fn build_in(&self, name: &str, base_dir: Option<&Path>) -> Result<Material, String> {
        Ok(match self {
            MaterialSpec::Ogden(s) => Material::Ogden(s.build(name)?),
            MaterialSpec::SimplifiedRubber(s) => {
                Material::SimplifiedRubber(s.build(name, base_dir)?)
            }
            MaterialSpec::PiecewiseLinearPlasticity(s) => {
                Material::PiecewiseLinearPlasticity(s.build(name)?)
            }
            MaterialSpec::LinearElastic(s) => {
                let (lambda, mu) = s.lame(name)?;
                let kinematics = match s.strain.as_deref() {
                    None | Some("green") => Kinematics::Green,
                    Some("small") => Kinematics::Small,
                    Some(o) => {
                        return Err(format!(
                            "material `{name}`: `strain` must be `green` or `small`, got `{o}`"
                        ))
                    }
                };
                Material::LinearElastic(LinearElastic {
                    rho: s.density.0,
                    lambda,
                    mu,
                    kinematics,
                })
            }
            MaterialSpec::NeoHookean(s) => {
                if s.strain.is_some() {
                    return Err(format!(
                        "material `{name}`: `strain` applies to linear_elastic only"
                    ));
                }
                let (lambda, mu) = s.lame(name)?;
                Material::NeoHookean(NeoHookean {
                    rho: s.density.0,
                    lambda,
                    mu,
                })
            }
        })
    }
}

impl OgdenSpec {
    /// Validate and build the Ogden law.
    pub fn build(&self, name: &str) -> Result<Ogden, String> {
        positive(name, "density", self.density.0)?;
        let alpha: Vec<f64> = self.alpha.iter().map(|a| a.0).collect();
        let mut mu: Vec<f64> = self.mu.iter().map(|m| m.0).collect();
        match self.convention.as_deref() {
            None | Some("original") | Some("ls_dyna") => {}
            Some("abaqus") => {
                for (m, a) in mu.iter_mut().zip(&alpha) {
                    *m = 2.0 * *m / a;
                }
            }
            Some(o) => {
                return Err(format!(
                    "material `{name}`: `convention` must be `original` (mu_p/alpha_p, LS-DYNA, the paper) or `abaqus` (2 mu_p/alpha_p^2), got `{o}`"
                ))
            }
        }
        let prony_on = match self.prony_on.as_deref() {
            None | Some("green_lagrange") => PronyOn::GreenLagrange,
            Some("deviatoric") => PronyOn::Deviatoric,
            Some(o) => {
                return Err(format!(
                "material `{name}`: `prony_on` must be `green_lagrange` or `deviatoric`, got `{o}`"
            ))
            }
        };
        let mut prony = Vec::with_capacity(self.prony.len());
        for (i, t) in self.prony.iter().enumerate() {
            let tau = match (t.tau, t.decay) {
                (Some(tau), None) => positive(name, &format!("prony[{i}].tau"), tau.0)?,
                (None, Some(b)) => 1.0 / positive(name, &format!("prony[{i}].decay"), b.0)?,
                _ => {
                    return Err(format!(
                        "material `{name}`: Prony term {} needs exactly one of `tau` (relaxation time) or `decay` (1/tau)",
                        i + 1
                    ))
                }
            };
            prony.push(PronyTerm {
                modulus: positive(name, &format!("prony[{i}].modulus"), t.modulus.0)?,
                tau,
            });
        }
        if mu.len() != alpha.len() || mu.is_empty() {
            return Err(format!(
                "material `{name}`: `mu` and `alpha` must be non-empty lists of the same length"
            ));
        }
        let mu0 = Ogden::mu0_of(&mu, &alpha);
        let bulk = match (self.bulk_modulus, self.poisson_ratio) {
            (Some(k), None) => positive(name, "bulk_modulus", k.0)?,
            (None, Some(nu)) => {
                let nu = nu.0;
                if !(nu > -1.0 && nu < 0.5) {
                    return Err(format!(
                        "material `{name}`: `poisson_ratio` must lie in (-1, 0.5), got {nu}"
                    ));
                }
                2.0 * mu0 * (1.0 + nu) / (3.0 * (1.0 - 2.0 * nu))
            }
            _ => {
                return Err(format!(
                    "material `{name}`: give exactly one of `bulk_modulus` or `poisson_ratio`"
                ))
            }
        };
        // Ogden::new refuses mu0 <= 0 with a message naming the material; check it before the
        // bulk modulus so that a poisson_ratio-derived K does not hide the cause.
        if !(mu0 > 0.0) {
            return Ogden::new(name, self.density.0, &mu, &alpha, 1.0, &prony, prony_on);
        }
        Ogden::new(name, self.density.0, &mu, &alpha, bulk, &prony, prony_on)
    }
}

impl FoamSpec {
    /// Validate and build the simplified rubber/foam law.
    pub fn build(&self, name: &str, base_dir: Option<&Path>) -> Result<Foam, String> {
        let curve = match (&self.curve, &self.curve_file) {
            (Some(_), Some(_)) => {
                return Err(format!(
                    "material `{name}`: give `curve` or `curve_file`, not both"
                ))
            }
            (Some(c), None) => {
                let pts: Vec<(f64, f64)> = c.iter().map(|(l, p)| (l.0, p.0)).collect();
                Some(UniaxialCurve::table(name, &pts)?)
            }
            (None, Some(file)) => {
                let path = match base_dir {
                    Some(b) if Path::new(file).is_relative() => b.join(file),
                    _ => PathBuf::from(file),
                };
                let text = std::fs::read_to_string(&path).map_err(|e| {
                    format!(
                        "material `{name}`: cannot read curve_file `{}`: {e}",
                        path.display()
                    )
                })?;
                let pts = parse_curve_csv(&text).map_err(|e| {
                    format!("material `{name}`: curve_file `{}`: {e}", path.display())
                })?;
                Some(UniaxialCurve::table(name, &pts)?)
            }
            (None, None) => None,
        };
        Foam::new(
            name,
            self.density.0,
            self.bulk_modulus.0,
            self.shear_modulus.map(|g| g.0),
            self.damping.map(|d| d.0).unwrap_or(0.0),
            curve,
        )
    }
}

/// Parse `stretch, stress` rows (comma, semicolon, tab or space separated; `#` comments; an
/// optional header row). A stress may carry a unit (`12 kPa`); plain numbers are Pa.
pub fn parse_curve_csv(text: &str) -> Result<Vec<(f64, f64)>, String> {
    let mut pts = Vec::new();
    for (ln, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let mut cols = line
            .split([',', ';', '\t'])
            .map(str::trim)
            .filter(|c| !c.is_empty());
        let (a, b) = match (cols.next(), cols.next()) {
            (Some(a), Some(b)) => (a, b),
            (Some(a), None) => match a.split_once(char::is_whitespace) {
                Some((a, b)) => (a, b),
                None => return Err(format!("line {}: expected two columns", ln + 1)),
            },
            _ => return Err(format!("line {}: expected two columns", ln + 1)),
        };
        let l: f64 = match a.parse() {
            Ok(v) => v,
            Err(_) if pts.is_empty() => continue, // header row
            Err(_) => return Err(format!("line {}: `{a}` is not a stretch", ln + 1)),
        };
        let p = Quantity::parse(b)
            .and_then(|q| q.get(crate::quantity::Dim::PRESSURE))
            .map_err(|e| format!("line {}: {e}", ln + 1))?;
        pts.push((l, p));
    }
    Ok(pts)
}

impl PlasticitySpec {
    /// Validate and build the plasticity law.
    pub fn build(&self, name: &str) -> Result<Plasticity, String> {
        positive(name, "density", self.density.0)?;
        let e = positive(name, "youngs_modulus", self.youngs_modulus.0)?;
        let nu = self.poisson_ratio.0;
        if !(nu > -1.0 && nu < 0.5) {
            return Err(format!(
                "material `{name}`: `poisson_ratio` must lie in (-1, 0.5), got {nu}"
            ));
        }
        let curve = match (self.yield_stress, self.tangent_modulus, &self.hardening) {
            (Some(sy), et, None) => {
                let sy = positive(name, "yield_stress", sy.0)?;
                Plasticity::bilinear_curve(e, et.map(|x| x.0).unwrap_or(0.0), sy)
                    .map_err(|m| format!("material `{name}`: {m}"))?
            }
            (None, None, Some(h)) => h.iter().map(|(a, b)| (a.0, b.0)).collect(),
            _ => {
                return Err(format!(
                    "material `{name}`: give `yield_stress` (and optionally `tangent_modulus`), or a `hardening` table"
                ))
            }
        };
        Plasticity::new(
            name,
            self.density.0,
            e / (3.0 * (1.0 - 2.0 * nu)),
            e / (2.0 * (1.0 + nu)),
            &curve,
            self.failure_strain.map(|x| x.0),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Law;

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
