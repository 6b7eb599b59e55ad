//! The scene file format (TOML). Every physical quantity takes a unit (`"40 kPa"`, `"25 ms"`);
//! plain numbers are SI. Unknown keys are errors. See `scenes/*.toml` for commented examples
//! and docs/scenes.md for the full tour.

use material::quantity::{Acceleration, Force, Length, Number, Rate, Time, Velocity};
use material::MaterialSpec;
use serde::Deserialize;
use std::collections::BTreeMap;

use super::curve_spec::CurveSpec;

/// The whole scene.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSpec {
    /// Run control.
    pub run: RunSpec,
    /// The mesh.
    pub mesh: MeshSpec,
    /// Materials by name.
    #[serde(default)]
    pub materials: BTreeMap<String, MaterialSpec>,
    /// Parts.
    #[serde(default, rename = "part")]
    pub parts: Vec<PartSpec>,
    /// Extra node sets.
    #[serde(default)]
    pub node_sets: BTreeMap<String, NodeSetSpec>,
    /// Kinematic boundary conditions.
    #[serde(default, rename = "boundary")]
    pub boundaries: Vec<BoundarySpec>,
    /// Nodal loads.
    #[serde(default, rename = "load")]
    pub loads: Vec<LoadSpec>,
    /// Gravity.
    pub gravity: Option<GravitySpec>,
    /// Mass-proportional damping.
    pub damping: Option<DampingSpec>,
    /// Bulk viscosity (on by default).
    pub bulk_viscosity: Option<BulkViscositySpec>,
    /// Selective mass scaling.
    pub mass_scaling: Option<MassScalingSpec>,
    /// Dynamic relaxation (quasi-static solution).
    pub relaxation: Option<RelaxationSpec>,
    /// Initial velocity.
    #[serde(default, rename = "initial_velocity")]
    pub initial_velocities: Vec<InitialVelocitySpec>,
    /// Output requests.
    #[serde(default)]
    pub output: OutputSpec,
    /// Rigid indenters (`[[indenter]]`).
    #[serde(default, rename = "indenter")]
    pub indenters: Vec<super::contact_spec::IndenterScene>,
    /// Two-finger hands (`[[hand]]`).
    #[serde(default, rename = "hand")]
    pub hands: Vec<super::contact_spec::HandScene>,
    /// Contact settings (`[contact]`).
    pub contact: Option<super::contact_spec::ContactScene>,
}

/// `[run]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunSpec {
    /// End time.
    pub end_time: Time,
    /// Time-step safety factor (default 0.9, see [`solver::simulation::DEFAULT_DT_FACTOR`]).
    pub dt_factor: Option<Number>,
    /// The element kernels' number type: `"f64"` (default) or `"f32"`
    /// ([`solver::element::precision`]).
    pub precision: Option<String>,
    /// Largest step.
    pub dt_max: Option<Time>,
    /// Stop if the step falls below this (default: 1e-6 of the initial step).
    pub dt_min: Option<Time>,
    /// Hourglass guard: stop, naming the element, when hourglass energy exceeds this share of
    /// the internal energy (e.g. 0.1). Off when absent.
    pub max_hourglass_ratio: Option<Number>,
    /// From when the guard checks (default: 10 % of the end time).
    pub hourglass_check_after: Option<Time>,
    /// The most time steps the run may take by the estimate from the stable step (default
    /// [`crate::def::DEFAULT_MAX_STEPS`]); a scene that would take more is refused.
    pub max_steps: Option<Number>,
    /// Subcycling: the most steps the interior of a part with a long stable step (the liver
    /// beside the flesh) may take as one; a power of two, 1 (default) is off
    /// ([`solver::subcycle`]).
    pub subcycling: Option<Number>,
    /// How the stable step is estimated: `"element"` (default, element by element) or
    /// `"global"` (the mesh's largest eigenvalue, [`solver::global_step`]).
    pub step_estimate: Option<String>,
    /// A title.
    pub title: Option<String>,
}

/// `[mesh]`: a generated box or a file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshSpec {
    /// `box` for the structured generator.
    pub generator: Option<String>,
    /// A mesh file (`.vtu`, `.vtk`, `.msh`, `.inp`), relative to the scene file.
    pub file: Option<String>,
    /// The length unit of the file's coordinates (`"mm"`, `"m"`, ...): required for Gmsh and
    /// Abaqus files, which carry none; VTK files are read in m unless it says otherwise.
    pub units: Option<String>,
    /// Box: lower corner.
    pub origin: Option<[Length; 3]>,
    /// Box: edge lengths.
    pub size: Option<[Length; 3]>,
    /// Box: divisions.
    pub divisions: Option<[usize; 3]>,
    /// Box: grading ratios (last/first element length).
    pub grading: Option<[f64; 3]>,
    /// Box: interior distortion as a fraction of the spacing.
    pub distortion: Option<f64>,
    /// Box: distortion seed.
    pub seed: Option<u64>,
    /// Box: its part name (default `body`).
    pub part: Option<String>,
    /// Box: the most elements it may have (default [`solver::generate::DEFAULT_MAX_ELEMENTS`]);
    /// more divisions are refused before anything is allocated.
    pub max_elements: Option<Number>,
    /// Phantom: `[mesh.phantom]` (with `generator = "phantom"`).
    pub phantom: Option<super::phantom_spec::PhantomScene>,
    /// Node numbering: `as_given` (default), `rcm` (reverse Cuthill-McKee) or `shuffled` (a
    /// seeded random order, to measure what locality is worth); box and file meshes only.
    pub numbering: Option<String>,
}

/// `[[part]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PartSpec {
    /// Part name (must exist in the mesh).
    pub name: String,
    /// Material name (a key of `[materials]`, or a library name such as `paper:liver`).
    pub material: String,
    /// `one_point` (default), `full_fbar`, or `full`.
    pub formulation: Option<String>,
    /// `viscous` (default) or `stiffness`.
    pub hourglass: Option<String>,
    /// Hourglass coefficient (default 0.1).
    pub hourglass_coefficient: Option<Number>,
    /// Modulus scaling the hourglass control: `p_wave` (default, lambda + 2 mu as LS-DYNA
    /// types 1-5) or `shear` (2 mu, for nearly incompressible tissue).
    pub hourglass_modulus: Option<String>,
    /// The incompressibility knob: cap the law's bulk modulus at this multiple of its initial
    /// shear modulus (K <= ratio G0). Stated in the summary; the wave speed and step follow.
    pub max_bulk_ratio: Option<Number>,
    /// Or: replace the law's bulk modulus by this value.
    pub bulk_modulus: Option<material::quantity::Pressure>,
}

/// `[node_sets.NAME]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NodeSetSpec {
    /// Nodes inside a box.
    pub box_min: Option<[Length; 3]>,
    /// Upper corner of the box.
    pub box_max: Option<[Length; 3]>,
    /// Nodes on a coordinate plane: axis `x`, `y` or `z`.
    pub plane_axis: Option<String>,
    /// Plane coordinate.
    pub plane_value: Option<Length>,
    /// Plane tolerance (default 1e-9 m).
    pub tolerance: Option<Length>,
    /// Explicit node ids.
    pub nodes: Option<Vec<u32>>,
}

/// Curves per direction.
#[derive(Debug, Deserialize, Clone)]
#[serde(deny_unknown_fields)]
pub struct DirCurves<Q> {
    /// Along x.
    pub x: Option<CurveSpec<Q>>,
    /// Along y.
    pub y: Option<CurveSpec<Q>>,
    /// Along z.
    pub z: Option<CurveSpec<Q>>,
}

/// `[[boundary]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoundarySpec {
    /// Node set name (`all` for every node).
    pub nodes: String,
    /// Fixed directions, e.g. `["x", "z"]` or `["all"]`.
    pub fix: Option<Vec<String>>,
    /// Symmetry plane: `x`, `y` or `z` (fixes the normal direction).
    pub symmetry: Option<String>,
    /// Prescribed displacement curves.
    pub displacement: Option<DirCurves<Length>>,
    /// Prescribed velocity curves.
    pub velocity: Option<DirCurves<Velocity>>,
}

/// `[[load]]`: force per node.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadSpec {
    /// Node set.
    pub nodes: String,
    /// Force per node, per direction.
    pub force: DirCurves<Force>,
    /// Divide the force evenly over the set's nodes instead (total force).
    pub total: Option<bool>,
}

/// `[gravity]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GravitySpec {
    /// Acceleration vector.
    pub acceleration: [Acceleration; 3],
}

/// `[damping]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DampingSpec {
    /// Mass-proportional coefficient alpha (1/s): f = alpha m v.
    pub mass_proportional: Rate,
}

/// `[bulk_viscosity]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BulkViscositySpec {
    /// Turn it off with `false`.
    pub enabled: Option<bool>,
    /// Quadratic coefficient (default 1.5).
    pub quadratic: Option<Number>,
    /// Linear coefficient (default 0.06).
    pub linear: Option<Number>,
}

/// `[mass_scaling]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MassScalingSpec {
    /// Target time step: a time, `"initial"` (the initial stable step: elements get mass only
    /// once they shrink during the run) or `"<k> x initial"`.
    pub target_dt: solver::model::StepTarget,
    /// Largest added mass as a fraction of the physical mass (default 0.05).
    pub max_added: Option<Number>,
}

/// `[relaxation]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RelaxationSpec {
    /// Relative out-of-balance force tolerance (default 1e-10).
    pub tolerance: Option<Number>,
}

/// `[[initial_velocity]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InitialVelocitySpec {
    /// Node set (`all` for every node).
    pub nodes: String,
    /// Velocity vector.
    pub velocity: [Velocity; 3],
}

/// `[output]`.
#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Interval between VTK frames (default: end_time / 10). Zero or absent `vtk = false` disables.
    pub interval: Option<Time>,
    /// Write VTK frames at all (default true).
    pub vtk: Option<bool>,
    /// Interval between history rows (default end_time / 500).
    pub history_interval: Option<Time>,
    /// Fields: displacement, velocity, part, stress, von_mises, max_principal, history.
    pub fields: Option<Vec<String>>,
    /// Node sets whose reaction forces go into history.csv.
    pub reactions: Option<Vec<String>>,
    /// An element set (e.g. the phantom's `roi`) whose stresses are sampled at every frame
    /// time into `probe.csv` (maximum principal stress) and `probe_stress.csv` (tensors).
    pub probe: Option<String>,
    /// The most history rows or frames the run may write (default
    /// [`crate::build::DEFAULT_MAX_OUTPUTS`]); a smaller interval is refused.
    pub max_outputs: Option<Number>,
}
