//! The scene's parts: each mesh part's law (a `[materials.NAME]` card or a library name), its
//! element formulation and hourglass control, and the incompressibility knob.

use super::bulk::bulk_knob;
use super::def::PartDef;
use super::locate::Locate;
use super::spec::{PartSpec, SceneSpec};
use material::Material;
use solver::element::{Formulation, Hourglass, HourglassForm, HourglassModulus};
use solver::mesh::Mesh;

/// One [`PartDef`] per mesh part, in the mesh's order; the bulk-modulus notes go to `notes`.
pub(crate) fn part_defs(
    spec: &SceneSpec,
    mesh: &Mesh,
    at: Locate,
    notes: &mut Vec<String>,
) -> Result<Vec<PartDef>, String> {
    let mut parts = Vec::new();
    if spec.parts.is_empty() {
        return Err(at.err("part", None, &"the scene defines no [[part]]"));
    }
    for pname in &mesh.part_names {
        let ps = spec
            .parts
            .iter()
            .find(|p| &p.name == pname)
            .ok_or_else(|| {
                at.err(
                    "part",
                    None,
                    &format!("the mesh has a part `{pname}` but no [[part]] gives it a material"),
                )
            })?;
        let key = format!("part `{pname}`");
        let base = at.path.parent();
        let material: Material = match spec.materials.get(&ps.material) {
            Some(card) => card.build_in(&ps.material, base).map_err(|m| {
                at.err(
                    &format!("materials.{}", ps.material),
                    Some(&format!("[materials.{}]", ps.material)),
                    &m,
                )
            })?,
            None if material::library::is_library_name(&ps.material) => {
                material::named(&ps.material)
                    .and_then(|c| c.build_in(&ps.material, base))
                    .map_err(|m| at.err(&format!("{key}.material"), Some(&ps.material), &m))?
            }
            None => {
                let known: Vec<&String> = spec.materials.keys().collect();
                return Err(at.err(
                    &format!("{key}.material"),
                    Some(&format!("\"{}\"", ps.material)),
                    &format!(
                        "no material `{}`; known: {known:?} or a library name such as paper:liver",
                        ps.material
                    ),
                ));
            }
        };
        let formulation =
            formulation(ps).map_err(|m| at.err(&key, Some(&format!("\"{pname}\"")), &m))?;
        let card = match spec.materials.get(&ps.material) {
            Some(card) => card.clone(),
            None => material::named(&ps.material)
                .map_err(|m| at.err(&format!("{key}.material"), Some(&ps.material), &m))?,
        };
        let (material, card, bulk) = bulk_knob(ps, material, card)
            .map_err(|m| at.err(&key, Some(&format!("\"{pname}\"")), &m))?;
        if let Some(b) = &bulk {
            notes.push(b.describe());
        }
        parts.push(PartDef {
            name: pname.clone(),
            material,
            spec: card,
            formulation,
            bulk,
        });
    }
    for ps in &spec.parts {
        if !mesh.part_names.contains(&ps.name) {
            return Err(at.err(
                "part.name",
                Some(&format!("\"{}\"", ps.name)),
                &format!(
                    "the mesh has no part `{}`; its parts: {:?}",
                    ps.name, mesh.part_names
                ),
            ));
        }
    }
    Ok(parts)
}

/// A part's element formulation and hourglass control.
fn formulation(p: &PartSpec) -> Result<Formulation, String> {
    let form = match p.hourglass.as_deref() {
        None | Some("viscous") => HourglassForm::Viscous,
        Some("stiffness") => HourglassForm::Stiffness,
        Some("physical") => HourglassForm::Physical,
        Some(o) => {
            return Err(format!(
                "hourglass must be `viscous`, `stiffness` or `physical`, got `{o}`"
            ))
        }
    };
    // The physical form's coefficient scales an energy that is exact at 1.
    let default_q = if form == HourglassForm::Physical {
        1.0
    } else {
        0.1
    };
    let q = p.hourglass_coefficient.map(|x| x.0).unwrap_or(default_q);
    if !(0.0..=1.0).contains(&q) {
        return Err(format!("hourglass_coefficient must lie in [0, 1], got {q}"));
    }
    if form == HourglassForm::Physical && p.hourglass_modulus.is_some() {
        return Err(
            "hourglass_modulus does not apply to `physical` hourglass control (it uses Young's and the shear modulus of the law)"
                .into(),
        );
    }
    let modulus = match p.hourglass_modulus.as_deref() {
        None | Some("p_wave") => HourglassModulus::PWave,
        Some("shear") => HourglassModulus::Shear,
        Some(o) => {
            return Err(format!(
                "hourglass_modulus must be `p_wave` or `shear`, got `{o}`"
            ))
        }
    };
    Ok(match p.formulation.as_deref() {
        None | Some("one_point") => Formulation::OnePoint(Hourglass {
            form,
            coefficient: q,
            modulus,
        }),
        Some("full_fbar") | Some("full")
            if p.hourglass.is_some() || p.hourglass_modulus.is_some() =>
        {
            return Err("hourglass control applies to one_point elements only".into())
        }
        Some("full_fbar") => Formulation::Full { fbar: true },
        Some("full") => Formulation::Full { fbar: false },
        Some(o) => {
            return Err(format!(
                "formulation must be `one_point`, `full_fbar` or `full`, got `{o}`"
            ))
        }
    })
}
