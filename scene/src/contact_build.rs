//! The scene's `[[indenter]]`, `[[hand]]` and `[contact]` tables translated into the solver's
//! contact stage ([`solver::contact_stage::ContactForceStage`]): shapes, motions and the penalty
//! in SI ([`resolve_contact`], against the mesh), then the contact surface, the design step and
//! the hands backed off the skin ([`build_stage`], against the model). The format and the
//! default penalty are in [`crate::contact_spec`].

use crate::contact_def::{ContactDef, HandDef, IndenterDef, SurfaceSel};
use crate::contact_spec::{
    ContactScene, HandScene, IndenterScene, MotionScene, DEFAULT_SOFT_SCALE,
};
use crate::locate::Locate;
use contact::{
    ContactParams, ContactStage, ContactSurface, Curve, HandSpec, IndenterSpec, MotionSpec,
    PenaltyKind, ShapeSpec,
};
use material::quantity::Length;
use solver::contact_stage::ContactForceStage;
use solver::mesh::Mesh;
use solver::model::Model;
use solver::simulation::Simulation;
use std::collections::HashSet;
use std::path::Path;

/// A scene's shape in m, an STL path relative to the scene file's folder `base`.
fn shape(s: &ShapeSpec<Length>, base: &Path) -> ShapeSpec {
    let mut s = s.map(f64::from);
    if let ShapeSpec::Stl { path, .. } = &mut s {
        *path = base.join(&*path);
    }
    s
}

/// A scene's motion in SI: its curves translated
/// ([`crate::curve_spec::CurveSpec::motion_curve`]), its force control mapped.
fn motion(m: &MotionScene) -> Result<MotionSpec, String> {
    Ok(match m {
        MotionSpec::Fixed => MotionSpec::Fixed,
        MotionSpec::Displacement { curve } => MotionSpec::Displacement {
            curve: curve.motion_curve()?,
        },
        MotionSpec::Velocity { curve } => MotionSpec::Velocity {
            curve: curve.motion_curve()?,
        },
        MotionSpec::Force(fc) => MotionSpec::Force(fc.to_si()),
    })
}

/// The contact parameters a `[contact]` table asks for, with palpa's defaults (soft penalty,
/// `soft_scale` 0.4, design step = the run's initial step; see [`crate::contact_spec`]).
/// `design_dt` is the default design step (s).
pub fn contact_params(c: Option<&ContactScene>, design_dt: f64) -> Result<ContactParams, String> {
    let d = ContactScene::default();
    let c = c.unwrap_or(&d);
    let mut p = ContactParams {
        penalty: PenaltyKind::Soft,
        soft_scale: DEFAULT_SOFT_SCALE,
        design_dt: Some(c.design_dt.map_or(design_dt, |t| t.0)),
        ..ContactParams::default()
    };
    if let Some(k) = &c.penalty {
        p.penalty = match k.as_str() {
            "soft" => PenaltyKind::Soft,
            "segment" => PenaltyKind::Segment,
            "max" => PenaltyKind::Max,
            o => {
                return Err(format!(
                    "contact.penalty must be `soft`, `segment` or `max`, got `{o}`"
                ))
            }
        };
    }
    if let Some(x) = c.penalty_scale {
        p.penalty_scale = x.0;
    }
    if let Some(x) = c.soft_scale {
        p.soft_scale = x.0;
    }
    if let Some(x) = c.stiffness_cap {
        p.stiffness_cap = (x.0 > 0.0).then_some(x.0);
    }
    if let Some(x) = c.friction {
        p.friction = x.0;
    }
    if let Some(x) = c.friction_velocity {
        p.friction_velocity = x.0;
    }
    if let Some(x) = c.damping_ratio {
        p.damping_ratio = x.0;
    }
    if let Some(x) = c.samples_min {
        p.samples_min = x;
    }
    if let Some(x) = c.samples_max {
        p.samples_max = x;
    }
    if let Some(x) = c.sample_spacing {
        p.sample_spacing = x.0;
    }
    if let Some(x) = c.margin {
        p.margin = Some(x.0);
    }
    if let Some(x) = c.rebuild_interval {
        p.rebuild_interval = x;
    }
    Ok(p)
}

/// The contact crate's hand for a scene's `[[hand]]` (placed: `point` and `direction` given),
/// with the fingertips `gap` (m) back.
fn hand_spec(h: &HandScene, gap: f64) -> Result<HandSpec, String> {
    let (Some(point), Some(direction)) = (&h.point, h.direction) else {
        return Err(
            "a hand needs `point` and `direction`, or `location`/`at` on a phantom mesh".into(),
        );
    };
    Ok(HandSpec {
        name: h.name.clone(),
        point: point.map(f64::from),
        direction,
        spacing_axis: h.spacing_axis,
        diameter: h.diameter.0,
        spacing: h.spacing.0,
        length: h.length.0,
        tilt: h.tilt_deg.unwrap_or(0.0).to_radians(),
        gap,
        motion: motion(&h.motion)?,
        friction: h.friction.map(|f| f.0),
    })
}

/// Resolve a scene's `[[indenter]]`, `[[hand]]` and `[contact]` tables against its mesh: the
/// indenters in SI, the hands (placed, not yet backed off the skin), the surface selection and
/// the contact parameters. `path` is the scene file (for messages and relative STL paths), `src`
/// its text (for line numbers).
pub fn resolve_contact(
    mesh: &Mesh,
    indenters: &[IndenterScene],
    hands: &[HandScene],
    contact: Option<&ContactScene>,
    path: &Path,
    src: &str,
) -> Result<ContactDef, String> {
    let loc = Locate { path, src };
    let line_of = |needle: &str| loc.place(Some(needle));
    let at = |needle: &str, key: &str, msg: &dyn std::fmt::Display| loc.err(key, Some(needle), msg);
    let base = path.parent().unwrap_or(Path::new("."));
    let mut defs = Vec::new();
    for (i, ind) in indenters.iter().enumerate() {
        let key = format!("indenter[{i}]");
        let name_at = format!("\"{}\"", ind.name);
        if ind.part.is_empty() {
            return Err(at(&name_at, &key, &"an indenter needs at least one `part`"));
        }
        defs.push(IndenterDef {
            spec: IndenterSpec {
                name: ind.name.clone(),
                parts: ind.part.iter().map(|s| shape(s, base)).collect(),
                direction: ind.direction,
                motion: motion(&ind.motion).map_err(|m| at(&name_at, &key, &m))?,
                friction: ind.friction.map(|f| f.0),
            },
            origin: line_of(&name_at),
        });
    }
    let mut hand_defs = Vec::new();
    for (i, h) in hands.iter().enumerate() {
        let key = format!("hand[{i}]");
        let name_at = format!("\"{}\"", h.name);
        let hs = hand_spec(h, h.gap.map_or(0.0, |g| g.0)).map_err(|m| at(&name_at, &key, &m))?;
        hs.to_indenter_spec().map_err(|e| at(&name_at, &key, &e))?;
        hand_defs.push(HandDef {
            hand: hs,
            gap_given: h.gap.is_some(),
            placed: h.location.is_some() || h.at.is_some(),
            origin: line_of(&name_at),
        });
    }
    let mut names = HashSet::new();
    for n in defs
        .iter()
        .map(|d| d.spec.name.as_str())
        .chain(hand_defs.iter().map(|h| h.hand.name.as_str()))
    {
        if !names.insert(n) {
            return Err(at(
                &format!("\"{n}\""),
                "indenter.name",
                &format!("two indenters or hands are named `{n}`"),
            ));
        }
    }

    let surface = surface_selection(mesh, contact, &loc)?;
    let d = ContactScene::default();
    let mut params = contact_params(Some(contact.unwrap_or(&d)), 0.0)
        .map_err(|m| at("[contact]", "contact", &m))?;
    params.design_dt = contact.and_then(|c| c.design_dt).map(|t| t.0);
    Ok(ContactDef {
        indenters: defs,
        hands: hand_defs,
        surface,
        params,
        origin: format!("{}: `contact`", path.display()),
        empty_hint: "check `surface` and `parts`".into(),
    })
}

/// The contact surface's selection from `[contact]`: a node mask from `surface` (a node set)
/// and a part mask from `parts` (no face list: that comes from a deck); `loc` places an error
/// in the scene file.
fn surface_selection(
    mesh: &Mesh,
    contact: Option<&ContactScene>,
    loc: &Locate,
) -> Result<SurfaceSel, String> {
    let at = |needle: &str, key: &str, msg: &dyn std::fmt::Display| loc.err(key, Some(needle), msg);
    let c = contact;
    let nodes: Option<Vec<bool>> = match c.and_then(|c| c.surface.as_ref()) {
        None => None,
        Some(name) => {
            let nodes = mesh.node_sets.get(name).ok_or_else(|| {
                let known: Vec<&String> = mesh.node_sets.keys().collect();
                at(
                    &format!("\"{name}\""),
                    "contact.surface",
                    &format!("no node set `{name}`; known: {known:?}"),
                )
            })?;
            let mut m = vec![false; mesh.nodes.len()];
            for &n in nodes {
                m[n as usize] = true;
            }
            Some(m)
        }
    };
    let parts: Option<Vec<bool>> = match c.and_then(|c| c.parts.as_ref()) {
        None => None,
        Some(ps) => {
            let mut ok = vec![false; mesh.part_names.len()];
            for p in ps {
                let i = mesh.part_names.iter().position(|n| n == p).ok_or_else(|| {
                    at(
                        &format!("\"{p}\""),
                        "contact.parts",
                        &format!("no part `{p}`; parts: {:?}", mesh.part_names),
                    )
                })?;
                ok[i] = true;
            }
            Some(ok)
        }
    };
    Ok(SurfaceSel {
        nodes,
        parts,
        faces: None,
    })
}

/// Build the contact stage of a resolved scene: the surface from the mesh boundary (restricted
/// by the selection), the design step (the run's initial step unless given), and the indenters,
/// with each hand that starts inside the surface backed off until it just touches it. On return
/// `contact.indenters` holds every indenter as it runs (hands included) and `contact.hands` is
/// empty. `path` is the scene file (for messages).
pub fn build_stage(
    sim: &Simulation,
    contact: &mut ContactDef,
    path: &Path,
    notes: &mut Vec<String>,
) -> Result<ContactForceStage, String> {
    let mut specs: Vec<IndenterSpec> = contact.indenters.iter().map(|d| d.spec.clone()).collect();
    let mut origins: Vec<String> = contact.indenters.iter().map(|d| d.origin.clone()).collect();
    for h in &contact.hands {
        specs.push(
            h.hand
                .to_indenter_spec()
                .map_err(|e| format!("{}: `hand`: {e}", h.origin))?,
        );
        origins.push(h.origin.clone());
    }
    let hands = std::mem::take(&mut contact.hands);

    let model = &sim.model;
    let mesh = &model.mesh;
    let surface = contact_surface(model, contact)?;

    // Initial penetration: a hand without an explicit `gap` whose fingertips start inside the
    // surface (a curved skin under two fingers) is backed off until they just touch it; a hand
    // placed on a phantom location then travels that much further, so that its indentation
    // beyond first contact is the requested one. Any other indenter that starts inside the
    // surface by more than 5 % of its feature size is an error that names it.
    let design_dt = (sim.settings.dt_factor * model.scaled_dt).min(sim.settings.dt_max);
    let mut params = contact.params.clone();
    if params.design_dt.is_none() {
        params.design_dt = Some(design_dt);
    }
    let backing = BackOff {
        sim,
        surface: &surface,
        params: &params,
        design_dt,
        path,
    };
    let n_ind = contact.indenters.len();
    let gaps = backing.gaps(&mut specs, &hands, &origins, n_ind)?;
    for (k, h) in hands.iter().enumerate() {
        let gap = gaps[k];
        if gap <= 0.0 {
            continue;
        }
        if h.placed {
            if let MotionSpec::Displacement { curve } = &mut specs[n_ind + k].motion {
                if let Curve::SmoothStep { amplitude, .. } | Curve::Ramp { amplitude, .. } = curve {
                    *amplitude += gap;
                }
            }
        }
        notes.push(format!(
            "hand `{}`: the fingertips started {:.3} mm inside the contact surface; backed off by that much{}",
            h.hand.name,
            gap * 1e3,
            if h.placed {
                " and the travel extended to match"
            } else {
                " (set `gap` to choose)"
            }
        ));
    }
    let faces = surface.faces.clone();
    let stage = ContactStage::new(&specs, surface, &mesh.nodes, &model.mass, params)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    let st = ContactForceStage::new(
        stage,
        &specs,
        faces,
        mesh.nodes.len(),
        sim.settings.dt_factor,
    );
    contact.indenters = specs
        .into_iter()
        .zip(origins)
        .map(|(spec, origin)| IndenterDef { spec, origin })
        .collect();
    Ok(st)
}

/// The contact surface of `contact`'s selection: the mesh boundary faces of the selected parts
/// whose nodes all lie in the selected node set (and, from a deck, among the selected faces),
/// each with its element's P-wave modulus and reference volume.
fn contact_surface(model: &Model, contact: &ContactDef) -> Result<ContactSurface, String> {
    let mesh = &model.mesh;
    let sel = &contact.surface;
    let mut vol = vec![0.0; mesh.elements.len()];
    for g in &model.groups {
        for (&e, &v) in g.elements.iter().zip(&g.vol0) {
            vol[e as usize] = v;
        }
    }
    let modulus: Vec<f64> = model
        .parts
        .iter()
        .map(|p| {
            let c0 = p.material.initial_wave_speed();
            p.material.density() * c0 * c0
        })
        .collect();
    let mut surface = ContactSurface::default();
    for f in mesh.boundary_faces() {
        let part = mesh.element_part[f.element as usize] as usize;
        if let Some(ok) = &sel.parts {
            if !ok[part] {
                continue;
            }
        }
        if let Some(m) = &sel.nodes {
            if !f.nodes.iter().all(|&n| m[n as usize]) {
                continue;
            }
        }
        if let Some(faces) = &sel.faces {
            let mut key = f.nodes;
            key.sort_unstable();
            if !faces.contains(&key) {
                continue;
            }
        }
        surface.faces.push(f.nodes);
        surface.face_bulk_modulus.push(modulus[part]);
        surface.face_element_volume.push(vol[f.element as usize]);
    }
    if surface.faces.is_empty() {
        return Err(format!(
            "{}: the contact surface has no face ({})",
            contact.origin, contact.empty_hint
        ));
    }

    Ok(surface)
}

/// What backing hands off the skin needs: the model, the surface and the stage's parameters.
struct BackOff<'a> {
    sim: &'a Simulation,
    surface: &'a ContactSurface,
    params: &'a ContactParams,
    design_dt: f64,
    path: &'a Path,
}

impl BackOff<'_> {
    /// Largest penetration of each indenter at t = 0 over the face samples, as the stage sees it.
    fn penetrations(&self, specs: &[IndenterSpec]) -> Result<Vec<f64>, String> {
        let mesh = &self.sim.model.mesh;
        let zeros = vec![[0.0; 3]; mesh.nodes.len()];
        let mut st = ContactStage::new(
            specs,
            self.surface.clone(),
            &mesh.nodes,
            &self.sim.model.mass,
            self.params.clone(),
        )
        .map_err(|e| format!("{}: {e}", self.path.display()))?;
        let mut f = zeros.clone();
        st.apply(0.0, self.design_dt, &mesh.nodes, &zeros, &mut f);
        Ok(st.indenters().iter().map(|s| s.max_penetration).collect())
    }

    /// Back each hand without a `gap` off until it just touches the surface (`specs[n_ind + k]`
    /// is hand `k`); returns each hand's gap (m). Any other indenter that starts inside the
    /// surface by more than 5 % of its feature size is an error that names it.
    fn gaps(
        &self,
        specs: &mut [IndenterSpec],
        hands: &[HandDef],
        origins: &[String],
        n_ind: usize,
    ) -> Result<Vec<f64>, String> {
        let mut gaps = vec![0.0; hands.len()];
        for _ in 0..20 {
            let pens = self.penetrations(specs)?;
            let mut moved = false;
            for (k, h) in hands.iter().enumerate() {
                if !h.gap_given && pens[n_ind + k] > 1e-9 {
                    gaps[k] += pens[n_ind + k] + 1e-7;
                    let mut hs = h.hand.clone();
                    hs.gap = gaps[k];
                    specs[n_ind + k] = hs
                        .to_indenter_spec()
                        .map_err(|e| format!("{}: `hand`: {e}", h.origin))?;
                    moved = true;
                }
            }
            if !moved {
                for ((spec, pen), origin) in specs.iter().zip(&pens).zip(origins) {
                    let size = contact::Indenter::from_spec(spec)
                        .map(|i| i.feature_size())
                        .unwrap_or(f64::INFINITY);
                    if *pen > 0.05 * size {
                        return Err(format!(
                            "{origin}: `indenter`: `{}` starts {:.3} mm inside the contact surface; move it out (or give a hand no `gap`, and palpa backs it off)",
                            spec.name,
                            pen * 1e3
                        ));
                    }
                }
                break;
            }
        }
        Ok(gaps)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scene's shapes read with units (one `ShapeSpec` type, lengths in the file's units)
    /// and mapped to m; an STL path resolves against the scene's folder, its `unit` is the
    /// length of one file unit.
    #[test]
    fn scene_shapes_map_to_si_and_stl_paths_resolve_against_the_scene() {
        let src = r#"
            name = "probe"
            direction = [0.0, 0.0, -1.0]
            motion = { kind = "fixed" }
            part = [
                { shape = "sphere", center = ["10 mm", "0 m", "2 cm"], radius = "5 mm" },
                { shape = "stl", path = "meshes/finger.stl", unit = "1 mm", translate = ["1 mm", "0 m", "0 m"] },
                { shape = "stl", path = "/abs/finger.stl" },
            ]
        "#;
        let ind: IndenterScene = toml::from_str(src).unwrap();
        let base = Path::new("/work/scene-dir");
        let s: Vec<ShapeSpec> = ind.part.iter().map(|p| shape(p, base)).collect();
        assert_eq!(
            s[0],
            ShapeSpec::Sphere {
                center: [0.01, 0.0, 0.02],
                radius: 0.005
            }
        );
        assert_eq!(
            s[1],
            ShapeSpec::Stl {
                path: base.join("meshes/finger.stl"),
                scale: 1e-3,
                translate: [1e-3, 0.0, 0.0]
            }
        );
        assert_eq!(
            s[2],
            ShapeSpec::Stl {
                path: "/abs/finger.stl".into(),
                scale: 1.0,
                translate: [0.0; 3]
            }
        );
        // a length without a unit where one is required, and an unknown key, are errors
        let bad = src.replace("\"5 mm\"", "\"5 s\"");
        assert!(toml::from_str::<IndenterScene>(&bad).is_err());
        let bad = src.replace("radius = \"5 mm\"", "radius = \"5 mm\", colour = 1");
        let e = toml::from_str::<IndenterScene>(&bad)
            .unwrap_err()
            .to_string();
        assert!(e.contains("colour"), "{e}");
    }
}
