//! Constitutive laws for palpa.
//!
//! Deformation gradient in; second Piola-Kirchhoff stress, current wave speed and dissipation
//! out (see [`law`]). No mesh, no solver. The solver groups elements by material and resolves
//! the [`Material`] enum once per group with [`with_law!`], so each group's loop is
//! monomorphised for its law: no dynamic dispatch per element or integration point.
#![warn(missing_docs)]

pub mod driver;
pub mod foam;
pub mod law;
pub mod library;
pub mod linear_elastic;
pub mod neo_hookean;
pub mod ogden;
pub mod plasticity;
pub mod principal;
pub mod quantity;
pub mod real;
pub mod real_avx512;
pub mod real_f32;
pub mod spec;
pub mod tensor;
pub mod toml_error;

pub use law::{Law, LawError, Response};
pub use spec::{named, MaterialSpec};
pub use tensor::Mat3;

/// Every law palpa knows, as plain parameter data.
#[derive(Clone, Debug)]
pub enum Material {
    /// Linear isotropic elasticity.
    LinearElastic(linear_elastic::LinearElastic),
    /// Compressible neo-Hookean.
    NeoHookean(neo_hookean::NeoHookean),
    /// N-term Ogden (original form) with optional Prony series.
    Ogden(ogden::Ogden),
    /// Simplified rubber/foam (MAT_181 style).
    SimplifiedRubber(foam::Foam),
    /// Piecewise-linear J2 plasticity (MAT_024 style).
    PiecewiseLinearPlasticity(plasticity::Plasticity),
}

/// Run `$body` with `$l` bound to the concrete law inside a [`Material`]; the body is
/// monomorphised per law.
#[macro_export]
macro_rules! with_law {
    ($mat:expr, $l:ident => $body:expr) => {
        match $mat {
            $crate::Material::LinearElastic($l) => $body,
            $crate::Material::NeoHookean($l) => $body,
            $crate::Material::Ogden($l) => $body,
            $crate::Material::SimplifiedRubber($l) => $body,
            $crate::Material::PiecewiseLinearPlasticity($l) => $body,
        }
    };
}

impl Material {
    /// Reference density (kg/m^3).
    pub fn density(&self) -> f64 {
        with_law!(self, l => l.density())
    }
    /// Initial dilatational wave speed (m/s).
    pub fn initial_wave_speed(&self) -> f64 {
        with_law!(self, l => l.initial_wave_speed())
    }
    /// Instantaneous small-strain shear modulus (Pa).
    pub fn initial_shear_modulus(&self) -> f64 {
        with_law!(self, l => l.initial_shear_modulus())
    }
    /// History values per integration point.
    pub fn history_len(&self) -> usize {
        with_law!(self, l => l.history_len())
    }
    /// Names of the history values.
    pub fn history_names(&self) -> Vec<String> {
        with_law!(self, l => l.history_names())
    }
    /// Short name of the law.
    pub fn law_name(&self) -> &'static str {
        match self {
            Material::LinearElastic(_) => "linear_elastic",
            Material::NeoHookean(_) => "neo_hookean",
            Material::Ogden(_) => "ogden",
            Material::SimplifiedRubber(_) => "simplified_rubber",
            Material::PiecewiseLinearPlasticity(_) => "piecewise_linear_plasticity",
        }
    }
    /// Small-strain bulk modulus K (Pa): `lambda + 2 mu / 3` for the Lame-constant laws, the
    /// law's `K` otherwise.
    pub fn bulk_modulus(&self) -> f64 {
        match self {
            Material::LinearElastic(l) => l.lambda + 2.0 / 3.0 * l.mu,
            Material::NeoHookean(l) => l.lambda + 2.0 / 3.0 * l.mu,
            Material::Ogden(l) => l.bulk,
            Material::SimplifiedRubber(l) => l.bulk,
            Material::PiecewiseLinearPlasticity(l) => l.bulk,
        }
    }
    /// The same law with the small-strain bulk modulus `k` (Pa) and every shear and history
    /// parameter unchanged: the incompressibility knob of a scene (see `max_bulk_ratio` and
    /// `bulk_modulus` under `[[part]]`). The wave speed, and so the stable step, follow it.
    pub fn with_bulk_modulus(&self, k: f64) -> Result<Material, String> {
        if !(k > 0.0 && k.is_finite()) {
            return Err(format!(
                "the bulk modulus must be positive and finite, got {k:e} Pa"
            ));
        }
        let mut m = self.clone();
        match &mut m {
            Material::LinearElastic(l) => l.lambda = k - 2.0 / 3.0 * l.mu,
            Material::NeoHookean(l) => l.lambda = k - 2.0 / 3.0 * l.mu,
            Material::Ogden(l) => l.bulk = k,
            Material::SimplifiedRubber(l) => l.bulk = k,
            Material::PiecewiseLinearPlasticity(l) => l.bulk = k,
        }
        Ok(m)
    }
}
