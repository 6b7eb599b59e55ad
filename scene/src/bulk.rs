//! The incompressibility knob of a part: `max_bulk_ratio = R` caps the law's small-strain bulk
//! modulus at `R G0` (its initial shear modulus), `bulk_modulus = "..."` replaces it. The law
//! and its card change together ([`material::Material::with_bulk_modulus`],
//! [`material::MaterialSpec::with_bulk_modulus`]), so the wave speed `sqrt((K + 4 G / 3) / rho)`,
//! the stable step and an exported deck follow; the change is recorded as a [`BulkChange`] that
//! the notes, `palpa check` and the summary state.

use super::spec::PartSpec;
use material::Material;

/// A part's bulk modulus as a scene changed it (`max_bulk_ratio` or `bulk_modulus` under
/// `[[part]]`): stated before the run and in the summary, never applied silently.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct BulkChange {
    /// Part name.
    pub part: String,
    /// What the scene asked for: `max_bulk_ratio = ...` or `bulk_modulus = ...`.
    pub setting: String,
    /// The law's own bulk modulus (Pa).
    pub original_pa: f64,
    /// The bulk modulus that runs (Pa).
    pub applied_pa: f64,
    /// The law's initial shear modulus (Pa).
    pub shear_pa: f64,
    /// Initial wave speed before and after (m/s).
    pub wave_speed_m_s: [f64; 2],
}

impl BulkChange {
    /// One line for the console.
    pub fn describe(&self) -> String {
        if self.applied_pa == self.original_pa {
            format!(
                "part `{}`: {} does not bind (K = {:.4e} Pa, K/G = {:.4e})",
                self.part,
                self.setting,
                self.original_pa,
                self.original_pa / self.shear_pa
            )
        } else {
            format!(
                "part `{}`: {}: bulk modulus {:.4e} -> {:.4e} Pa (K/G {:.4e} -> {:.4e}), wave speed {:.4e} -> {:.4e} m/s",
                self.part,
                self.setting,
                self.original_pa,
                self.applied_pa,
                self.original_pa / self.shear_pa,
                self.applied_pa / self.shear_pa,
                self.wave_speed_m_s[0],
                self.wave_speed_m_s[1]
            )
        }
    }
}

/// The incompressibility knob of a part (`max_bulk_ratio` or `bulk_modulus`): the law and its
/// card with the bulk modulus that runs, and the change to state.
pub fn bulk_knob(
    p: &PartSpec,
    material: Material,
    card: material::MaterialSpec,
) -> Result<(Material, material::MaterialSpec, Option<BulkChange>), String> {
    let k0 = material.bulk_modulus();
    let g0 = material.initial_shear_modulus();
    let (setting, k) = match (p.max_bulk_ratio, p.bulk_modulus) {
        (None, None) => return Ok((material, card, None)),
        (Some(_), Some(_)) => {
            return Err("give max_bulk_ratio or bulk_modulus, not both".into());
        }
        (Some(r), None) => {
            let r = r.0;
            if !(r.is_finite() && r > 2.0 / 3.0) {
                return Err(format!(
                    "max_bulk_ratio must be a finite K/G above 2/3 (Poisson ratio above 0), got {r}"
                ));
            }
            (format!("max_bulk_ratio = {r}"), k0.min(r * g0))
        }
        (None, Some(k)) => (format!("bulk_modulus = {:e} Pa", k.0), k.0),
    };
    if k != k0 && matches!(material, Material::PiecewiseLinearPlasticity(_)) {
        return Err(format!(
            "{setting} would change the bulk modulus of a piecewise_linear_plasticity law, whose hardening is given through its Young's modulus: change the card's youngs_modulus and poisson_ratio instead"
        ));
    }
    let c0 = material.initial_wave_speed();
    let m = if k == k0 {
        material
    } else {
        material
            .with_bulk_modulus(k)
            .map_err(|e| format!("{setting}: {e}"))?
    };
    let change = BulkChange {
        part: p.name.clone(),
        setting,
        original_pa: k0,
        applied_pa: k,
        shear_pa: g0,
        wave_speed_m_s: [c0, m.initial_wave_speed()],
    };
    let card = if k == k0 {
        card
    } else {
        card.with_bulk_modulus(k, g0)
    };
    Ok((m, card, Some(change)))
}
