//! The contact stage of the time loop: the `contact` crate's penalty contact behind the solver's
//! [`ForceStage`] interface, built from the scene's `[[indenter]]`, `[[hand]]` and `[contact]`
//! tables (see [`crate::scene::contact_spec`] for the format and the default penalty).
//!
//! ## Surface
//! The contact surface is the mesh boundary ([`crate::mesh::Mesh::boundary_faces`], outward
//! quads), optionally restricted to the faces whose four nodes all lie in `[contact] surface`
//! (a node set) and to the elements of `[contact] parts`. Per face the segment formula gets
//! `K = rho c0^2` of the owning element's law (the P-wave modulus `lambda + 2 mu` at the
//! reference state, from [`material::Material::initial_wave_speed`] and the density) and the
//! element's reference volume; the soft formula and the time-step bound use the lumped nodal
//! masses of the model (after mass scaling).
//!
//! ## Time step
//! The crate bounds the contact alone by `dt_c = min_a 2 sqrt(m_a / k_a)` (Gershgorin row sums
//! of the penalty stiffness). The largest eigenvalues of element and contact stiffness add at
//! most, so body plus contact is stable when `(dt/dt_e)^2 + (dt/dt_c)^2 <= 1`. The solver already
//! keeps `dt <= f dt_e` (`f` = `dt_factor`, 0.9), so this stage's [`ForceStage::max_dt`] is
//! `dt_c sqrt(1 - f^2)` (with `f` taken as at most 0.9). With the default penalty (capped at
//! `k_a <= 0.1 m_a (2/dt_0)^2`, `dt_0` the design step) this is `1.38 dt_0` and never binds;
//! it binds only when a scene raises the penalty beyond the cap, and then it lowers the step
//! instead of letting the run blow up.
//!
//! ## Energy
//! The crate's identity is `KE + IE + E_contact = W_other + W_drive`, with `E_contact` the stored
//! penalty energy plus contact dissipation and `W_drive` the work of the indenter drivers. The
//! solver's own external-work sum includes the work of the contact forces on the body, so this
//! stage also accumulates that work, `W_body = sum_n (f^(n-1) + f^n)/2 . v^(n-1/2) (t^n - t^(n-1))`
//! over the nodes that carry contact force (the same trapezoidal rule as the solver's sums), and
//! the simulation books `W_external = W_solver - W_body + W_drive` and `E_contact`. The balance then
//! checks the contact too: it closes only if the contact forces are the gradient of the penalty
//! energy and the driver work is right.
//!
//! ## Output
//! Per indenter, `history.csv` gets `<name>_force_x/_y/_z`: the force the body exerts on the
//! indenter (N), i.e. the resultant on the rigid (master) side as LS-DYNA's RCFORC reports it
//! for a rigid master surface: pressing down (-z) into a body gives a positive `force_z`;
//! `<name>_reaction`: that force along `-direction` (N, positive when pressing);
//! `<name>_travel`: the indenter's travel along its direction (m); `<name>_depth`: travel since
//! first contact (m); `<name>_area`: current area of the penetrating sample points (m^2);
//! `<name>_max_penetration` (m). The VTK frames get `contact_pressure` (Pa), per node the mean of
//! the contact pressures of its surface faces, and each frame the indenters' surfaces (see
//! [`crate::output::vtk::write_surfaces`]).

use crate::mesh::Mesh;
use crate::output::vtk::RigidSurface;
use crate::scene::contact_def::{ContactDef, HandDef, IndenterDef, SurfaceSel};
use crate::scene::contact_spec::{
    ContactScene, HandScene, IndenterScene, MotionScene, ShapeScene, DEFAULT_SOFT_SCALE,
};
use crate::simulation::{ForceStage, Simulation};
use contact::{
    ContactParams, ContactStage, ContactSurface, Curve, ForceControl, HandSpec, IndenterSpec,
    MotionSpec, PenaltyKind, ShapeSpec,
};
use std::collections::HashSet;
use std::path::Path;

/// The contact stage: the `contact` crate's [`ContactStage`] plus the bookkeeping the solver needs
/// (the work of the contact forces on the body, the time-step bound, output columns and fields).
pub struct ContactForceStage {
    stage: ContactStage,
    faces: Vec<[u32; 4]>,
    /// Contact forces of the last evaluation (N), nonzero only on `nodes`.
    fc: Vec<[f64; 3]>,
    mark: Vec<bool>,
    nodes: Vec<u32>,
    /// Surface faces per node (for the nodal pressure average).
    node_faces: Vec<u32>,
    body_work: f64,
    t_prev: Option<f64>,
    max_dt: f64,
    columns: Vec<String>,
    /// Indenter surfaces at t = 0, in the order of the stage's indenters.
    drawn: Vec<RigidSurface>,
}

impl ContactForceStage {
    /// Wrap a contact stage. `faces` must be the surface faces the stage was built with,
    /// `dt_factor` the solver's time-step factor.
    pub fn new(stage: ContactStage, faces: Vec<[u32; 4]>, n_nodes: usize, dt_factor: f64) -> Self {
        let mut node_faces = vec![0u32; n_nodes];
        for f in &faces {
            for &a in f {
                node_faces[a as usize] += 1;
            }
        }
        let f = dt_factor.min(0.9);
        let max_dt = stage.stable_dt_bound() * (1.0 - f * f).sqrt();
        let mut columns = Vec::new();
        for s in stage.indenters() {
            for c in [
                "force_x",
                "force_y",
                "force_z",
                "reaction",
                "travel",
                "depth",
                "area",
                "max_penetration",
            ] {
                columns.push(format!("{}_{c}", s.name));
            }
        }
        ContactForceStage {
            stage,
            faces,
            fc: vec![[0.0; 3]; n_nodes],
            mark: vec![false; n_nodes],
            nodes: Vec::with_capacity(n_nodes.min(1 << 16)),
            node_faces,
            body_work: 0.0,
            t_prev: None,
            max_dt,
            columns,
            drawn: Vec::new(),
        }
    }

    /// The wrapped contact stage (indenter states, counters, penalties).
    pub fn stage(&self) -> &ContactStage {
        &self.stage
    }

    /// Work done by the contact forces on the body so far (J).
    pub fn body_work(&self) -> f64 {
        self.body_work
    }
}

#[inline]
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

impl ForceStage for ContactForceStage {
    fn name(&self) -> &'static str {
        "contact"
    }

    fn apply(&mut self, t: f64, dt: f64, x: &[[f64; 3]], v: &[[f64; 3]], force: &mut [[f64; 3]]) {
        let dtp = self.t_prev.map_or(0.0, |tp| t - tp);
        self.t_prev = Some(t);
        // f^(n-1) . v^(n-1/2) dt / 2, and clear the previous forces.
        let mut w = 0.0;
        for &a in &self.nodes {
            let a = a as usize;
            w += dot(self.fc[a], v[a]);
            self.fc[a] = [0.0; 3];
            self.mark[a] = false;
        }
        self.nodes.clear();
        self.stage.apply(t, dt, x, v, &mut self.fc);
        for &fi in self.stage.touched_faces() {
            for &a in &self.faces[fi as usize] {
                if !self.mark[a as usize] {
                    self.mark[a as usize] = true;
                    self.nodes.push(a);
                }
            }
        }
        // f^n . v^(n-1/2) dt / 2, and add the forces to the solver's array.
        for &a in &self.nodes {
            let a = a as usize;
            let f = self.fc[a];
            w += dot(f, v[a]);
            let o = &mut force[a];
            o[0] += f[0];
            o[1] += f[1];
            o[2] += f[2];
        }
        self.body_work += 0.5 * dtp * w;
    }

    fn energy(&self) -> f64 {
        self.stage.energy()
    }

    fn body_work(&self) -> f64 {
        self.body_work
    }

    fn driver_work(&self) -> f64 {
        self.stage.driver_work()
    }

    fn max_dt(&self) -> f64 {
        self.max_dt
    }

    fn history_columns(&self) -> Vec<String> {
        self.columns.clone()
    }

    fn surfaces(&self) -> Vec<RigidSurface> {
        self.drawn
            .iter()
            .zip(self.stage.indenters())
            .filter(|(d, _)| !d.polygons.is_empty())
            .map(|(d, s)| RigidSurface {
                displacement: s.offset,
                ..d.clone()
            })
            .collect()
    }

    fn history_values(&self, out: &mut Vec<f64>) {
        for s in self.stage.indenters() {
            out.extend([
                s.force[0],
                s.force[1],
                s.force[2],
                s.reaction,
                s.travel,
                s.depth,
                s.area,
                s.max_penetration,
            ]);
        }
    }

    fn point_fields(&self) -> Vec<(String, Vec<f64>)> {
        let mut p = vec![0.0; self.node_faces.len()];
        for (f, &pf) in self.faces.iter().zip(self.stage.face_pressure()) {
            if pf != 0.0 {
                for &a in f {
                    p[a as usize] += pf;
                }
            }
        }
        for (p, &n) in p.iter_mut().zip(&self.node_faces) {
            if n > 0 {
                *p /= n as f64;
            }
        }
        vec![("contact_pressure".into(), p)]
    }
}

fn v3(l: &[material::quantity::Length; 3]) -> [f64; 3] {
    [l[0].0, l[1].0, l[2].0]
}

fn shape(s: &ShapeScene, base: &Path) -> ShapeSpec {
    match s {
        ShapeScene::Sphere { center, radius } => ShapeSpec::Sphere {
            center: v3(center),
            radius: radius.0,
        },
        ShapeScene::Capsule {
            center,
            axis,
            radius,
            length,
        } => ShapeSpec::Capsule {
            center: v3(center),
            axis: *axis,
            radius: radius.0,
            length: length.0,
        },
        ShapeScene::Cylinder {
            center,
            axis,
            radius,
            length,
        } => ShapeSpec::Cylinder {
            center: v3(center),
            axis: *axis,
            radius: radius.0,
            length: length.0,
        },
        ShapeScene::Box {
            center,
            half_extents,
            axes,
        } => ShapeSpec::Box {
            center: v3(center),
            half_extents: v3(half_extents),
            axes: *axes,
        },
        ShapeScene::Plane { point, normal } => ShapeSpec::Plane {
            point: v3(point),
            normal: *normal,
        },
        ShapeScene::Stl {
            path,
            unit,
            translate,
        } => ShapeSpec::Stl {
            path: base.join(path),
            scale: unit.map_or(1.0, |u| u.0),
            translate: translate.as_ref().map_or([0.0; 3], v3),
        },
    }
}

fn motion(m: &MotionScene) -> Result<MotionSpec, String> {
    Ok(match m {
        MotionScene::Fixed => MotionSpec::Fixed,
        MotionScene::Displacement { curve } => MotionSpec::Displacement {
            curve: curve.motion_curve()?,
        },
        MotionScene::Velocity { curve } => MotionSpec::Velocity {
            curve: curve.motion_curve()?,
        },
        MotionScene::Force {
            target,
            ramp_time,
            approach_speed,
            time_constant,
            filter_time,
        } => {
            let mut fc = ForceControl::new(target.0);
            if let Some(t) = ramp_time {
                fc.ramp_time = t.0;
            }
            if let Some(v) = approach_speed {
                fc.approach_speed = v.0;
            }
            if let Some(t) = time_constant {
                fc.time_constant = t.0;
            }
            if let Some(t) = filter_time {
                fc.filter_time = t.0;
            }
            MotionSpec::Force(fc)
        }
    })
}

/// The contact parameters a `[contact]` table asks for, with palpa's defaults (soft penalty,
/// `soft_scale` 0.4, design step = the run's initial step; see [`crate::scene::contact_spec`]).
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
        point: v3(point),
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
    let line_of = |needle: &str| {
        src.lines()
            .position(|l| l.contains(needle))
            .map(|i| format!("{}:{}", path.display(), i + 1))
            .unwrap_or_else(|| path.display().to_string())
    };
    let at = |needle: &str, key: &str, msg: &dyn std::fmt::Display| {
        format!("{}: `{key}`: {msg}", line_of(needle))
    };
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

    // Surface.
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
    let d = ContactScene::default();
    let mut params =
        contact_params(Some(c.unwrap_or(&d)), 0.0).map_err(|m| at("[contact]", "contact", &m))?;
    params.design_dt = c.and_then(|c| c.design_dt).map(|t| t.0);
    Ok(ContactDef {
        indenters: defs,
        hands: hand_defs,
        surface: SurfaceSel {
            nodes,
            parts,
            faces: None,
        },
        params,
        origin: format!("{}: `contact`", path.display()),
        empty_hint: "check `surface` and `parts`".into(),
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

    // Surface.
    let model = &sim.model;
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
    // Largest penetration of each indenter at t = 0 over the face samples, as the stage sees it.
    let zeros = vec![[0.0; 3]; mesh.nodes.len()];
    let measure = |specs: &[IndenterSpec]| -> Result<Vec<f64>, String> {
        let mut st = ContactStage::new(
            specs,
            surface.clone(),
            &mesh.nodes,
            &model.mass,
            params.clone(),
        )
        .map_err(|e| format!("{}: {e}", path.display()))?;
        let mut f = zeros.clone();
        st.apply(0.0, design_dt, &mesh.nodes, &zeros, &mut f);
        Ok(st.indenters().iter().map(|s| s.max_penetration).collect())
    };
    let n_ind = contact.indenters.len();
    let mut gaps = vec![0.0; hands.len()];
    for _ in 0..20 {
        let pens = measure(&specs)?;
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
            for ((spec, pen), origin) in specs.iter().zip(&pens).zip(&origins) {
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
    let drawn = surfaces_of(&specs);
    contact.indenters = specs
        .into_iter()
        .zip(origins)
        .map(|(spec, origin)| IndenterDef { spec, origin })
        .collect();
    let mut st = ContactForceStage::new(stage, faces, mesh.nodes.len(), sim.settings.dt_factor);
    st.drawn = drawn;
    Ok(st)
}

/// Segments around a great circle of the indenter surfaces drawn in the frames.
const DRAW_SEGMENTS: usize = 32;

/// The surfaces of the indenters at t = 0, for the frames: analytic shapes tessellated
/// ([`contact::tessellate::surface`]), triangle meshes as they are; an infinite plane is not
/// drawn.
fn surfaces_of(specs: &[IndenterSpec]) -> Vec<RigidSurface> {
    specs
        .iter()
        .map(|spec| {
            let mut s = RigidSurface {
                name: spec.name.clone(),
                vertices: Vec::new(),
                polygons: Vec::new(),
                displacement: [0.0; 3],
            };
            for part in &spec.parts {
                let base = s.vertices.len() as u32;
                match contact::tessellate::surface(part, DRAW_SEGMENTS) {
                    Ok(q) => {
                        s.vertices.extend(q.verts);
                        s.polygons.extend(
                            q.quads
                                .iter()
                                .map(|q| q.iter().map(|&i| base + i).collect()),
                        );
                    }
                    Err(_) => {
                        if let Ok(contact::Shape::Mesh(m)) = contact::Shape::from_spec(part) {
                            s.vertices.extend_from_slice(m.vertices());
                            s.polygons.extend(
                                m.triangles()
                                    .iter()
                                    .map(|t| t.iter().map(|&i| base + i).collect()),
                            );
                        }
                    }
                }
            }
            s
        })
        .collect()
}
