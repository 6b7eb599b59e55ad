//! Build a [`Scene`] (model, simulation, output plan) from a [`SceneSpec`].

use super::bulk::bulk_knob;
use super::contact_spec::HandScene;
use super::def::{DtMin, HourglassGuard, OutputPlan, PartDef, Scene, SceneDef, Setup};
use super::spec::*;
use crate::bc::{Constraint, Kinematic, NodalLoad};
use crate::element::precision::Precision;
use crate::element::{BulkViscosity, Formulation, Hourglass, HourglassForm, HourglassModulus};
use crate::generate::{box_mesh, BoxSpec};
use crate::mesh::Mesh;
use crate::model::MassScaling;
use crate::phantom::Phantom;
use crate::simulation::DynamicRelaxation;
use material::quantity::Length;
use material::Material;
use std::path::Path;

/// A scene error with its location.
fn err(
    path: &Path,
    src: &str,
    key: &str,
    needle: Option<&str>,
    msg: impl std::fmt::Display,
) -> String {
    let line = needle.and_then(|n| src.lines().position(|l| l.contains(n)).map(|i| i + 1));
    match line {
        Some(l) => format!("{}:{}: `{}`: {}", path.display(), l, key, msg),
        None => format!("{}: `{}`: {}", path.display(), key, msg),
    }
}

/// Read, parse and build a scene file.
pub fn load_scene(path: &Path) -> Result<Scene, String> {
    load_scene_with(path, None)
}

/// [`load_scene`], reusing an already built phantom (see [`build_scene_with`]).
pub fn load_scene_with(path: &Path, prebuilt: Option<Phantom>) -> Result<Scene, String> {
    let src = std::fs::read_to_string(path)
        .map_err(|e| format!("{}: cannot read the scene file: {e}", path.display()))?;
    let spec: SceneSpec = toml::from_str(&src)
        .map_err(|e| format!("{}: {}", path.display(), e.to_string().trim_end()))?;
    build_scene_with(spec, path, &src, prebuilt)
}

fn axis(s: &str) -> Option<usize> {
    match s {
        "x" => Some(0),
        "y" => Some(1),
        "z" => Some(2),
        _ => None,
    }
}

fn read_mesh(
    spec: &MeshSpec,
    scene: &Path,
    src: &str,
    prebuilt: Option<Phantom>,
    notes: &mut Vec<String>,
) -> Result<(Mesh, Option<Phantom>), String> {
    if spec.phantom.is_some() && spec.generator.as_deref() != Some("phantom") {
        return Err(err(
            scene,
            src,
            "mesh.phantom",
            Some("[mesh.phantom]"),
            "`[mesh.phantom]` needs `generator = \"phantom\"`",
        ));
    }
    if spec.generator.as_deref() == Some("phantom") {
        if spec.file.is_some() {
            return Err(err(
                scene,
                src,
                "mesh.file",
                Some("file"),
                "give either `generator` or `file`, not both",
            ));
        }
        let params = spec
            .phantom
            .clone()
            .unwrap_or_default()
            .to_params()
            .map_err(|m| err(scene, src, "mesh.phantom", Some("[mesh.phantom]"), m))?;
        let ph = match prebuilt {
            Some(ph) if ph.params == params => ph,
            _ => crate::phantom::build(&params)
                .map_err(|m| err(scene, src, "mesh.phantom", Some("[mesh.phantom]"), m))?,
        };
        return Ok((ph.mesh.clone(), Some(ph)));
    }
    let mesh = match (&spec.generator, &spec.file) {
        (Some(g), None) if g == "box" => {
            let size = spec
                .size
                .ok_or_else(|| err(scene, src, "mesh.size", None, "a box needs `size`"))?;
            let divisions = spec.divisions.ok_or_else(|| {
                err(
                    scene,
                    src,
                    "mesh.divisions",
                    None,
                    "a box needs `divisions`",
                )
            })?;
            let limit = spec
                .max_elements
                .map(|x| x.0)
                .unwrap_or(crate::generate::DEFAULT_MAX_ELEMENTS);
            let count = divisions.iter().map(|&d| d as f64).product::<f64>();
            if count > limit {
                return Err(err(
                    scene,
                    src,
                    "mesh.divisions",
                    Some("divisions"),
                    format!(
                        "{divisions:?} gives {count:.4e} elements, more than the limit of {limit:.0} (about {:.0} GiB of memory); use fewer divisions, or raise `[mesh] max_elements` if you mean it",
                        count * crate::generate::BYTES_PER_ELEMENT / 1073741824.0
                    ),
                ));
            }
            let b = BoxSpec {
                origin: spec
                    .origin
                    .map(|o| [o[0].0, o[1].0, o[2].0])
                    .unwrap_or([0.0; 3]),
                size: [size[0].0, size[1].0, size[2].0],
                divisions,
                grading: spec.grading.unwrap_or([1.0; 3]),
                distortion: spec.distortion.unwrap_or(0.0),
                seed: spec.seed.unwrap_or(1),
            };
            box_mesh(&b, spec.part.as_deref().unwrap_or("body"))
                .map_err(|e| err(scene, src, "mesh", Some("[mesh]"), e))
        }
        (Some(g), None) => Err(err(
            scene,
            src,
            "mesh.generator",
            Some("generator"),
            format!("unknown generator `{g}` (known: box, phantom)"),
        )),
        (None, Some(f)) => {
            let p = scene.parent().unwrap_or(Path::new(".")).join(f);
            let scale = mesh_units(spec, &p)
                .map_err(|e| err(scene, src, "mesh.units", Some("units"), e))?;
            crate::mesh_io::read_mesh(&p, scale)
                .map(|m| {
                    notes.extend(m.notes);
                    m.mesh
                })
                .map_err(|e| err(scene, src, "mesh.file", Some("file"), e))
        }
        _ => Err(err(
            scene,
            src,
            "mesh",
            Some("[mesh]"),
            "give either `generator = \"box\"` or `file = \"mesh.vtu\"`",
        )),
    }?;
    Ok((mesh, None))
}

/// Metres per unit of a mesh file's coordinates: `[mesh] units`, required for formats that
/// carry no unit (Gmsh, Abaqus); VTK files default to m, as palpa writes them.
fn mesh_units(spec: &MeshSpec, file: &Path) -> Result<f64, String> {
    match &spec.units {
        Some(u) => {
            let q = material::quantity::Quantity::parse(&format!("1 {u}"))?;
            q.get(material::quantity::Dim::LENGTH)
                .map_err(|_| format!("`{u}` is not a length unit (give e.g. \"mm\" or \"m\")"))
        }
        None => {
            let ext = file
                .extension()
                .map(|e| e.to_string_lossy().to_ascii_lowercase())
                .unwrap_or_default();
            if ext == "msh" || ext == "inp" {
                Err(format!(
                    "{} states no unit: give the length unit of its coordinates, e.g. `units = \"mm\"` under [mesh]",
                    file.display()
                ))
            } else {
                Ok(1.0)
            }
        }
    }
}

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

/// Build a scene from its parsed spec. `path` and `src` are used for error messages and to
/// resolve relative file names.
pub fn build_scene(spec: SceneSpec, path: &Path, src: &str) -> Result<Scene, String> {
    build_scene_with(spec, path, src, None)
}

/// [`build_scene`], reusing an already built phantom when the scene's `[mesh.phantom]` asks
/// for the same parameters (campaigns build the phantom once for all their runs).
pub fn build_scene_with(
    spec: SceneSpec,
    path: &Path,
    src: &str,
    prebuilt: Option<Phantom>,
) -> Result<Scene, String> {
    super::def::assemble(resolve_scene(spec, path, src, prebuilt)?)
}

/// The most history rows, or frames, a scene may ask for unless `[output] max_outputs` raises
/// the limit.
pub const DEFAULT_MAX_OUTPUTS: f64 = 1e6;

/// Resolve a parsed scene to SI ([`SceneDef`]): the mesh with its node sets, the parts' laws,
/// boundary conditions, loads, settings, output and contact. [`super::def::assemble`] builds
/// the model from it.
pub fn resolve_scene(
    mut spec: SceneSpec,
    path: &Path,
    src: &str,
    prebuilt: Option<Phantom>,
) -> Result<SceneDef, String> {
    let e = |key: &str, needle: Option<&str>, msg: &dyn std::fmt::Display| {
        err(path, src, key, needle, msg)
    };
    let end_time = spec.run.end_time.0;
    if !(end_time > 0.0) {
        return Err(e("run.end_time", Some("end_time"), &"must be positive"));
    }
    if !end_time.is_finite() {
        return Err(e(
            "run.end_time",
            Some("end_time"),
            &format!("must be finite, got {end_time}"),
        ));
    }
    let dt_factor = spec
        .run
        .dt_factor
        .map(|x| x.0)
        .unwrap_or(crate::simulation::DEFAULT_DT_FACTOR);
    if !(dt_factor > 0.0 && dt_factor <= 1.0) {
        return Err(e(
            "run.dt_factor",
            Some("dt_factor"),
            &format!("must lie in (0, 1], got {dt_factor}"),
        ));
    }
    let precision = match &spec.run.precision {
        None => Precision::F64,
        Some(p) => Precision::parse(p).map_err(|m| e("run.precision", Some("precision"), &m))?,
    };
    let mut notes = Vec::new();
    let (mut mesh, mut phantom) = read_mesh(&spec.mesh, path, src, prebuilt, &mut notes)?;
    for (i, h) in spec.hands.iter_mut().enumerate() {
        place_hand(h, phantom.as_ref())
            .map_err(|m| e(&format!("hand[{i}]"), Some(&format!("\"{}\"", h.name)), &m))?;
    }
    if let Some(ph) = phantom.as_mut() {
        // the scene owns the mesh from here on; keep the phantom's other data
        ph.mesh = Mesh::default();
    }
    // Node sets.
    for (name, ns) in &spec.node_sets {
        let key = format!("node_sets.{name}");
        let mut nodes: Vec<u32> = Vec::new();
        let mut given = 0;
        if let (Some(lo), Some(hi)) = (ns.box_min, ns.box_max) {
            nodes.extend(
                mesh.nodes_in_box([lo[0].0, lo[1].0, lo[2].0], [hi[0].0, hi[1].0, hi[2].0]),
            );
            given += 1;
        }
        if let (Some(ax), Some(val)) = (&ns.plane_axis, ns.plane_value) {
            let a = axis(ax)
                .ok_or_else(|| e(&key, Some("plane_axis"), &"plane_axis must be x, y or z"))?;
            nodes.extend(mesh.nodes_on_plane(a, val.0, ns.tolerance.map(|t| t.0).unwrap_or(1e-9)));
            given += 1;
        }
        if let Some(ids) = &ns.nodes {
            if let Some(bad) = ids.iter().find(|&&n| n as usize >= mesh.nodes.len()) {
                return Err(e(
                    &key,
                    Some(&format!("[node_sets.{name}]")),
                    &format!("node {bad} does not exist"),
                ));
            }
            nodes.extend(ids);
            given += 1;
        }
        if given != 1 {
            return Err(e(
                &key,
                Some(&format!("[node_sets.{name}]")),
                &"give exactly one of box_min+box_max, plane_axis+plane_value, nodes",
            ));
        }
        nodes.sort_unstable();
        nodes.dedup();
        if nodes.is_empty() {
            return Err(e(
                &key,
                Some(&format!("[node_sets.{name}]")),
                &"selects no node",
            ));
        }
        mesh.node_sets.insert(name.clone(), nodes);
    }
    let all: Vec<u32> = (0..mesh.nodes.len() as u32).collect();
    let set = |name: &str, key: &str| -> Result<Vec<u32>, String> {
        if name == "all" {
            return Ok(all.clone());
        }
        mesh.node_sets.get(name).cloned().ok_or_else(|| {
            let known: Vec<&String> = mesh.node_sets.keys().collect();
            e(
                key,
                Some(&format!("\"{name}\"")),
                &format!("no node set `{name}`; known: all, {known:?}"),
            )
        })
    };
    // Materials and parts.
    let mut parts = Vec::new();
    if spec.parts.is_empty() {
        return Err(e("part", None, &"the scene defines no [[part]]"));
    }
    for pname in &mesh.part_names {
        let ps = spec
            .parts
            .iter()
            .find(|p| &p.name == pname)
            .ok_or_else(|| {
                e(
                    "part",
                    None,
                    &format!("the mesh has a part `{pname}` but no [[part]] gives it a material"),
                )
            })?;
        let key = format!("part `{pname}`");
        let base = path.parent();
        let material: Material = match spec.materials.get(&ps.material) {
            Some(card) => card.build_in(&ps.material, base).map_err(|m| {
                e(
                    &format!("materials.{}", ps.material),
                    Some(&format!("[materials.{}]", ps.material)),
                    &m,
                )
            })?,
            None if material::library::is_library_name(&ps.material) => {
                material::named(&ps.material)
                    .and_then(|c| c.build_in(&ps.material, base))
                    .map_err(|m| e(&format!("{key}.material"), Some(&ps.material), &m))?
            }
            None => {
                let known: Vec<&String> = spec.materials.keys().collect();
                return Err(e(
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
            formulation(ps).map_err(|m| e(&key, Some(&format!("\"{pname}\"")), &m))?;
        let card = match spec.materials.get(&ps.material) {
            Some(card) => card.clone(),
            None => material::named(&ps.material)
                .map_err(|m| e(&format!("{key}.material"), Some(&ps.material), &m))?,
        };
        let (material, card, bulk) = bulk_knob(ps, material, card)
            .map_err(|m| e(&key, Some(&format!("\"{pname}\"")), &m))?;
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
            return Err(e(
                "part.name",
                Some(&format!("\"{}\"", ps.name)),
                &format!(
                    "the mesh has no part `{}`; its parts: {:?}",
                    ps.name, mesh.part_names
                ),
            ));
        }
    }
    // Boundary conditions.
    let mut constraints = Vec::new();
    for (i, b) in spec.boundaries.iter().enumerate() {
        let key = format!("boundary[{i}]");
        let nodes = set(&b.nodes, &format!("{key}.nodes"))?;
        let mut fixed = [false; 3];
        if let Some(f) = &b.fix {
            for d in f {
                if d == "all" {
                    fixed = [true; 3];
                } else {
                    let a = axis(d).ok_or_else(|| {
                        e(
                            &format!("{key}.fix"),
                            Some("fix"),
                            &format!("`{d}` is not x, y, z or all"),
                        )
                    })?;
                    fixed[a] = true;
                }
            }
        }
        if let Some(s) = &b.symmetry {
            let a = axis(s).ok_or_else(|| {
                e(
                    &format!("{key}.symmetry"),
                    Some("symmetry"),
                    &format!("`{s}` is not x, y or z"),
                )
            })?;
            fixed[a] = true;
        }
        for (a, f) in fixed.iter().enumerate() {
            if *f {
                constraints.push(Constraint {
                    nodes: nodes.clone(),
                    dof: a,
                    kind: Kinematic::Fixed,
                });
            }
        }
        if let Some(d) = &b.displacement {
            for (a, c) in [&d.x, &d.y, &d.z].into_iter().enumerate() {
                if let Some(c) = c {
                    let cv = c
                        .boundary_curve()
                        .map_err(|m| e(&format!("{key}.displacement"), Some("displacement"), &m))?;
                    constraints.push(Constraint {
                        nodes: nodes.clone(),
                        dof: a,
                        kind: Kinematic::Displacement(cv),
                    });
                }
            }
        }
        if let Some(d) = &b.velocity {
            for (a, c) in [&d.x, &d.y, &d.z].into_iter().enumerate() {
                if let Some(c) = c {
                    let cv = c
                        .boundary_curve()
                        .map_err(|m| e(&format!("{key}.velocity"), Some("velocity"), &m))?;
                    constraints.push(Constraint {
                        nodes: nodes.clone(),
                        dof: a,
                        kind: Kinematic::Velocity(cv),
                    });
                }
            }
        }
    }
    let mut loads = Vec::new();
    for (i, l) in spec.loads.iter().enumerate() {
        let key = format!("load[{i}]");
        let nodes = set(&l.nodes, &format!("{key}.nodes"))?;
        let share = if l.total.unwrap_or(false) {
            1.0 / nodes.len() as f64
        } else {
            1.0
        };
        for (a, c) in [&l.force.x, &l.force.y, &l.force.z].into_iter().enumerate() {
            if let Some(c) = c {
                let cv = c
                    .boundary_curve()
                    .map_err(|m| e(&format!("{key}.force"), Some("force"), &m))?
                    .scaled(share);
                loads.push(NodalLoad {
                    nodes: nodes.clone(),
                    dof: a,
                    curve: cv,
                });
            }
        }
    }
    let mut initial_velocity = Vec::new();
    for (i, iv) in spec.initial_velocities.iter().enumerate() {
        let nodes = set(&iv.nodes, &format!("initial_velocity[{i}].nodes"))?;
        initial_velocity.push((
            nodes,
            [iv.velocity[0].0, iv.velocity[1].0, iv.velocity[2].0],
        ));
    }
    // Output plan.
    let out = &spec.output;
    let known = [
        "displacement",
        "velocity",
        "part",
        "stress",
        "von_mises",
        "max_principal",
        "history",
    ];
    let fields = out.fields.clone().unwrap_or_else(|| {
        vec![
            "displacement".into(),
            "velocity".into(),
            "part".into(),
            "von_mises".into(),
        ]
    });
    for f in &fields {
        if !known.contains(&f.as_str()) {
            return Err(e(
                "output.fields",
                Some(&format!("\"{f}\"")),
                &format!("unknown field `{f}`; known: {known:?}"),
            ));
        }
    }
    let mut reactions = Vec::new();
    for r in out.reactions.clone().unwrap_or_default() {
        let nodes = set(&r, "output.reactions")?;
        reactions.push((r, nodes));
    }
    let vtk_interval = if out.vtk == Some(false) {
        None
    } else {
        Some(out.interval.map(|t| t.0).unwrap_or(end_time / 10.0))
    };
    let history_interval = out
        .history_interval
        .map(|t| t.0)
        .unwrap_or(end_time / 500.0);
    if !(history_interval >= 0.0 && history_interval.is_finite()) {
        return Err(e(
            "output.history_interval",
            Some("history_interval"),
            &format!(
                "must be zero (every step) or a positive finite time, got {history_interval} s"
            ),
        ));
    }
    let max_outputs = match out.max_outputs.map(|x| x.0) {
        None => DEFAULT_MAX_OUTPUTS,
        Some(m) if m >= 1.0 && m.is_finite() => m,
        Some(m) => {
            return Err(e(
                "output.max_outputs",
                Some("max_outputs"),
                &format!("must be a positive finite count, got {m}"),
            ))
        }
    };
    // Outputs on the interval grid: a tiny interval would write rows or frames without end
    // (and stall the run) rather than fail.
    let too_many = |key: &str, needle: &str, what: &str, interval: f64| {
        let n = end_time / interval;
        (interval > 0.0 && n > max_outputs).then(|| {
            e(
                key,
                Some(needle),
                &format!(
                    "an interval of {interval:e} s over end_time {end_time:e} s gives {n:.3e} {what}, more than the limit of {max_outputs:.0}; use a longer interval, or raise `[output] max_outputs` if you mean it"
                ),
            )
        })
    };
    if let Some(m) = too_many(
        "output.history_interval",
        "history_interval",
        "history rows",
        history_interval,
    ) {
        return Err(m);
    }
    let probe = match &out.probe {
        None => None,
        Some(name) => {
            let els = mesh.element_sets.get(name).cloned().ok_or_else(|| {
                let known: Vec<&String> = mesh.element_sets.keys().collect();
                e(
                    "output.probe",
                    Some("probe"),
                    &format!("no element set `{name}`; known: {known:?}"),
                )
            })?;
            Some((name.clone(), els))
        }
    };
    let frame_interval = out.interval.map(|t| t.0).unwrap_or(end_time / 10.0);
    if !(frame_interval > 0.0) {
        return Err(e("output.interval", Some("interval"), &"must be positive"));
    }
    if let Some(m) = too_many("output.interval", "interval", "frames", frame_interval) {
        return Err(m);
    }
    let plan = OutputPlan {
        vtk_interval,
        frame_interval: (vtk_interval.is_some() || probe.is_some()).then_some(frame_interval),
        history_interval,
        fields,
        reactions,
        probe,
    };
    // Settings.
    let bulk = match &spec.bulk_viscosity {
        Some(b) if b.enabled == Some(false) => None,
        Some(b) => {
            let quadratic = b.quadratic.map(|x| x.0).unwrap_or(1.5);
            let linear = b.linear.map(|x| x.0).unwrap_or(0.06);
            for (key, v) in [("quadratic", quadratic), ("linear", linear)] {
                if !(v >= 0.0 && v.is_finite()) {
                    return Err(e(
                        &format!("bulk_viscosity.{key}"),
                        Some(key),
                        &format!("must be zero or a positive finite coefficient, got {v}"),
                    ));
                }
            }
            Some(BulkViscosity { quadratic, linear })
        }
        None => Some(BulkViscosity::default()),
    };
    let mass_scaling = spec.mass_scaling.as_ref().map(|m| MassScaling {
        target: m.target_dt,
        max_added: m.max_added.map(|x| x.0).unwrap_or(0.05),
    });
    let damping = spec
        .damping
        .as_ref()
        .map(|d| d.mass_proportional.0)
        .filter(|&a| a != 0.0);
    let gravity = spec
        .gravity
        .as_ref()
        .map(|g| {
            [
                g.acceleration[0].0,
                g.acceleration[1].0,
                g.acceleration[2].0,
            ]
        })
        .filter(|g| g.iter().any(|&x| x != 0.0));
    let relaxation = spec.relaxation.as_ref().map(|r| DynamicRelaxation {
        tolerance: r.tolerance.map(|x| x.0).unwrap_or(1e-10),
    });
    let hourglass_guard = match spec.run.max_hourglass_ratio {
        Some(r) if !(r.0 > 0.0) => {
            return Err(format!(
                "{}: run.max_hourglass_ratio must be positive (got {})",
                path.display(),
                r.0
            ))
        }
        Some(r) => Some(HourglassGuard {
            ratio: r.0,
            after: spec.run.hourglass_check_after.map(|t| t.0),
        }),
        None => None,
    };
    // Contact exists only when the scene has indenters or hands.
    let contact = if !spec.indenters.is_empty() || !spec.hands.is_empty() {
        Some(crate::contact_stage::resolve_contact(
            &mesh,
            &spec.indenters,
            &spec.hands,
            spec.contact.as_ref(),
            path,
            src,
        )?)
    } else {
        None
    };
    let setup = Setup {
        parts,
        constraints,
        loads,
        initial_velocity,
        dt_factor,
        precision,
        dt_max: spec.run.dt_max.map(|t| t.0),
        dt_min: spec.run.dt_min.map(|t| DtMin::Time(t.0)),
        max_steps: match spec.run.max_steps.map(|x| x.0) {
            None => None,
            Some(m) if m >= 1.0 && m.is_finite() => Some(m),
            Some(m) => {
                return Err(e(
                    "run.max_steps",
                    Some("max_steps"),
                    &format!("must be a positive finite count, got {m}"),
                ))
            }
        },
        hourglass_guard,
        bulk,
        damping,
        gravity,
        relaxation,
        mass_scaling,
        output: plan,
        contact,
    };
    Ok(SceneDef {
        title: spec.run.title.clone().unwrap_or_else(|| {
            path.file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default()
        }),
        path: path.to_path_buf(),
        end_time,
        mesh,
        phantom,
        setup,
        notes,
    })
}

/// Place a hand by a phantom location (`location` or `at`): its point is the skin point there
/// and its direction the inward skin normal, unless the scene gives `direction` itself.
fn place_hand(h: &mut HandScene, phantom: Option<&Phantom>) -> Result<(), String> {
    let loc = match (&h.location, &h.at) {
        (None, None) => return Ok(()),
        (Some(_), Some(_)) => return Err("give `location` or `at`, not both".into()),
        _ if h.point.is_some() => {
            return Err("give `point`, or `location`/`at`, not both".into());
        }
        (Some(name), None) => {
            let ph =
                phantom.ok_or("`location` needs a phantom mesh (`generator = \"phantom\"`)")?;
            ph.locations
                .get(name)
                .cloned()
                .ok_or_else(|| format!("no palpation location `{name}` (A, B, C, P01..P25)"))?
        }
        (None, Some(xy)) => {
            let ph = phantom.ok_or("`at` needs a phantom mesh (`generator = \"phantom\"`)")?;
            crate::phantom::location_at(
                &ph.mesh,
                &ph.skin_faces,
                &ph.volume,
                "at",
                xy[0].0,
                xy[1].0,
            )?
        }
    };
    h.point = Some(loc.surface.map(Length));
    if h.direction.is_none() {
        h.direction = Some(loc.inward_normal);
    }
    Ok(())
}
