//! Build a [`Scene`] (model, simulation, output plan) from a [`SceneSpec`].

use super::contact_spec::HandScene;
use super::def::{DtMin, Scene, SceneDef, Setup};
use super::kinematics;
use super::locate::Locate;
use super::loop_settings::{max_steps, run_control, settings, step_estimate, subcycling};
use super::node_sets::add_node_sets;
use super::output_plan::output_plan;
use super::parts::part_defs;
use super::spec::*;
use material::quantity::Length;
use phantom::Phantom;
use solver::generate::{box_mesh, BoxSpec};
use solver::mesh::Mesh;
use solver::renumber::{renumber, Numbering};
use solver::simulation::StepEstimate;
use std::path::Path;

/// A scene error with its location ([`Locate::err`]).
fn err(
    path: &Path,
    src: &str,
    key: &str,
    needle: Option<&str>,
    msg: impl std::fmt::Display,
) -> String {
    Locate { path, src }.err(key, needle, &msg)
}

/// Read, parse and build a scene file.
pub fn load_scene(path: &Path) -> Result<Scene, String> {
    load_scene_with(path, None)
}

/// [`load_scene`], reusing an already built phantom (see [`build_scene_with`]).
pub fn load_scene_with(path: &Path, prebuilt: Option<Phantom>) -> Result<Scene, String> {
    let src = std::fs::read_to_string(path)
        .map_err(|e| format!("{}: cannot read the scene file: {e}", path.display()))?;
    let spec: SceneSpec =
        toml::from_str(&src).map_err(|e| material::toml_error::describe(path, &src, &e))?;
    build_scene_with(spec, path, &src, prebuilt)
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
            _ => phantom::build(&params)
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
                .unwrap_or(solver::generate::DEFAULT_MAX_ELEMENTS);
            let count = divisions.iter().map(|&d| d as f64).product::<f64>();
            if count > limit {
                return Err(err(
                    scene,
                    src,
                    "mesh.divisions",
                    Some("divisions"),
                    format!(
                        "{divisions:?} gives {count:.4e} elements, more than the limit of {limit:.0} (about {:.0} GiB of memory); use fewer divisions, or raise `[mesh] max_elements` if you mean it",
                        count * solver::generate::BYTES_PER_ELEMENT / 1073741824.0
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
            solver::mesh_io::read_mesh(&p, scale)
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

pub use super::output_plan::DEFAULT_MAX_OUTPUTS;

/// `[mesh] numbering`, checked before the mesh is read or generated: how a box or file mesh's
/// nodes are to be numbered ([`solver::renumber`]). The phantom's nodes stay as its generator
/// numbers them (its ROI and liver surface refer to them).
fn numbering(spec: &MeshSpec, at: Locate) -> Result<Numbering, String> {
    let Some(label) = &spec.numbering else {
        return Ok(Numbering::AsGiven);
    };
    let needle = format!("\"{label}\"");
    let how =
        Numbering::parse(label).map_err(|m| at.err("mesh.numbering", Some(needle.as_str()), &m))?;
    if how != Numbering::AsGiven && spec.generator.as_deref() == Some("phantom") {
        return Err(at.err(
            "mesh.numbering",
            Some(needle.as_str()),
            &"the phantom's nodes are numbered by its generator (its ROI and liver surface refer \
             to them): `numbering` applies to box and file meshes",
        ));
    }
    Ok(how)
}

/// Number the mesh's nodes as [`numbering`] said, noting the element bandwidth before and after.
fn number_nodes(how: Numbering, mesh: &mut Mesh, notes: &mut Vec<String>) {
    if how == Numbering::AsGiven {
        return;
    }
    let (before, after) = renumber(mesh, how, 1);
    notes.push(format!(
        "nodes numbered {}: element bandwidth {before} -> {after}",
        how.label()
    ));
}

/// Resolve a parsed scene to SI ([`SceneDef`]): the mesh with its node sets, the parts' laws,
/// boundary conditions, loads, settings, output and contact. [`super::def::assemble`] builds
/// the model from it.
pub fn resolve_scene(
    mut spec: SceneSpec,
    path: &Path,
    src: &str,
    prebuilt: Option<Phantom>,
) -> Result<SceneDef, String> {
    let at = Locate { path, src };
    let (end_time, dt_factor, precision) = run_control(&spec.run, at)?;
    let mut notes = Vec::new();
    let how_numbered = numbering(&spec.mesh, at)?;
    let (mut mesh, mut phantom) = read_mesh(&spec.mesh, path, src, prebuilt, &mut notes)?;
    for (i, h) in spec.hands.iter_mut().enumerate() {
        place_hand(h, phantom.as_ref())
            .map_err(|m| at.err(&format!("hand[{i}]"), Some(&format!("\"{}\"", h.name)), &m))?;
    }
    if let Some(ph) = phantom.as_mut() {
        // the scene owns the mesh from here on; keep the phantom's other data
        ph.mesh = Mesh::default();
    }
    add_node_sets(&spec.node_sets, &mut mesh, at)?;
    // after the scene's own node sets (explicit ids name the mesh's numbering), which
    // renumbering carries with the nodes
    number_nodes(how_numbered, &mut mesh, &mut notes);
    let parts = part_defs(&spec, &mesh, at, &mut notes)?;
    let constraints = kinematics::constraints(&spec, &mesh, at)?;
    let loads = kinematics::loads(&spec, &mesh, at)?;
    let initial_velocity = kinematics::initial_velocities(&spec, &mesh, at)?;
    let output = output_plan(&spec.output, end_time, &mesh, at)?;
    let st = settings(&spec, at)?;
    let subcycling = subcycling(&spec.run, at)?;
    if subcycling > 1 && st.relaxation.is_some() {
        return Err(at.err(
            "run.subcycling",
            Some("subcycling"),
            &"cannot be combined with [relaxation] (its damping is formed from every node's force at every step)",
        ));
    }
    let step_estimate = step_estimate(&spec.run, at)?;
    if subcycling > 1 && step_estimate == StepEstimate::Global {
        return Err(at.err(
            "run.step_estimate",
            Some("step_estimate"),
            &"\"global\" cannot be combined with run.subcycling (a subcycled part's elements report their step over k)",
        ));
    }
    // Contact exists only when the scene has indenters or hands.
    let contact = if !spec.indenters.is_empty() || !spec.hands.is_empty() {
        Some(crate::contact_build::resolve_contact(
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
        max_steps: max_steps(&spec.run, at)?,
        subcycling,
        step_estimate,
        hourglass_guard: st.hourglass_guard,
        bulk: st.bulk,
        damping: st.damping,
        gravity: st.gravity,
        relaxation: st.relaxation,
        mass_scaling: st.mass_scaling,
        output,
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
            phantom::location_at(&ph.mesh, &ph.skin_faces, &ph.volume, "at", xy[0].0, xy[1].0)?
        }
    };
    h.point = Some(loc.surface.map(Length));
    if h.direction.is_none() {
        h.direction = Some(loc.inward_normal);
    }
    Ok(())
}
