//! A scene resolved to SI, between its source file and the running [`Simulation`].
//!
//! Two readers produce a [`SceneDef`]: the TOML scene ([`super::build`]) and the LS-DYNA keyword
//! deck (the `lsdyna` crate). [`assemble`] turns either into a runnable [`Scene`]: it builds the
//! model (lumped masses, mass scaling, the initial stable step), the loop settings, the
//! simulation and the contact stage. What the model needs before it exists (which faces are the
//! contact surface, where a hand stands) is resolved here, so both readers share every rule.
//!
//! The assembled [`Scene`] keeps its [`Setup`], with the indenters as they run (hands turned
//! into their two capsules and backed off the skin), so that a scene can be written out again
//! (`palpa export --lsdyna`) from exactly what palpa runs.

use super::contact_def::ContactDef;
use material::{Material, MaterialSpec};
use phantom::Phantom;
use solver::bc::{Constraint, NodalLoad};
use solver::element::precision::Precision;
use solver::element::{BulkViscosity, Formulation};
use solver::mesh::Mesh;
use solver::model::{MassScaling, Model, Part};
use solver::simulation::{
    DynamicRelaxation, HourglassLimit, LoopSettings, Simulation, StepEstimate,
};
use std::path::PathBuf;

/// One part: its law, the card it was built from, and its element formulation.
#[derive(Clone, Debug)]
pub struct PartDef {
    /// Part name (as in the mesh).
    pub name: String,
    /// The built law.
    pub material: Material,
    /// The card the law was built from (SI values), kept for export.
    pub spec: MaterialSpec,
    /// Element formulation.
    pub formulation: Formulation,
    /// The incompressibility knob, if the scene set it for this part.
    pub bulk: Option<BulkChange>,
}

pub use super::bulk::BulkChange;

/// The smallest step before a run is stopped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DtMin {
    /// A time (s).
    Time(f64),
    /// A fraction of the initial step (LS-DYNA `*CONTROL_TERMINATION` DTMIN).
    Factor(f64),
}

/// The hourglass guard (see [`HourglassLimit`]); `after` defaults to 10 % of the end time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HourglassGuard {
    /// Largest hourglass / internal energy.
    pub ratio: f64,
    /// From when it is checked (s).
    pub after: Option<f64>,
}

/// Everything but the mesh: what runs on it.
#[derive(Clone, Debug)]
pub struct Setup {
    /// Parts, in the order of the mesh's part names.
    pub parts: Vec<PartDef>,
    /// Kinematic conditions.
    pub constraints: Vec<Constraint>,
    /// Nodal loads.
    pub loads: Vec<NodalLoad>,
    /// Initial velocities, applied in order (a later one overrides an earlier one on a node).
    pub initial_velocity: Vec<(Vec<u32>, [f64; 3])>,
    /// Time-step safety factor.
    pub dt_factor: f64,
    /// The element kernels' number type.
    pub precision: Precision,
    /// Subcycling's largest macro ratio (1: off).
    pub subcycling: u32,
    /// How the stable step is estimated.
    pub step_estimate: StepEstimate,
    /// Largest step (s).
    pub dt_max: Option<f64>,
    /// Smallest step before the run stops (default: 1e-6 of the initial step).
    pub dt_min: Option<DtMin>,
    /// The most steps the run may take by the estimate from its stable step (default
    /// [`DEFAULT_MAX_STEPS`]).
    pub max_steps: Option<f64>,
    /// Hourglass guard.
    pub hourglass_guard: Option<HourglassGuard>,
    /// Bulk viscosity.
    pub bulk: Option<BulkViscosity>,
    /// Mass-proportional damping (1/s).
    pub damping: Option<f64>,
    /// Gravity (m/s^2).
    pub gravity: Option<[f64; 3]>,
    /// Dynamic relaxation.
    pub relaxation: Option<DynamicRelaxation>,
    /// Selective mass scaling.
    pub mass_scaling: Option<MassScaling>,
    /// Output requests.
    pub output: OutputPlan,
    /// Contact, when the scene has indenters.
    pub contact: Option<ContactDef>,
}

/// A scene resolved to SI, ready to [`assemble`].
pub struct SceneDef {
    /// Title.
    pub title: String,
    /// Source file.
    pub path: PathBuf,
    /// End time (s).
    pub end_time: f64,
    /// The mesh, with its node and element sets.
    pub mesh: Mesh,
    /// The phantom the mesh came from (its `mesh` field emptied).
    pub phantom: Option<Phantom>,
    /// What runs on the mesh.
    pub setup: Setup,
    /// Things the reader adjusted that the user should know (printed before the run).
    pub notes: Vec<String>,
}

/// What the output writer is asked for.
#[derive(Clone, Debug)]
pub struct OutputPlan {
    /// Interval between VTK frames (s); None disables VTK output (frames may still be taken
    /// for the probe, see `frame_interval`).
    pub vtk_interval: Option<f64>,
    /// Interval between history rows (s).
    pub history_interval: f64,
    /// Requested point and cell fields.
    pub fields: Vec<String>,
    /// Node sets whose reactions are written: (name, nodes).
    pub reactions: Vec<(String, Vec<u32>)>,
    /// Interval between frames (s): stress snapshots written to VTK and/or the probe files;
    /// None when neither is written.
    pub frame_interval: Option<f64>,
    /// Element set sampled into `probe.csv` at every frame: (name, element ids).
    pub probe: Option<(String, Vec<u32>)>,
}

impl OutputPlan {
    /// Whether a field was requested.
    pub fn has(&self, f: &str) -> bool {
        self.fields.iter().any(|x| x == f)
    }
    /// Whether any stress-derived field was requested.
    pub fn needs_stress(&self) -> bool {
        self.has("stress") || self.has("von_mises") || self.has("max_principal")
    }
}

/// A scene ready to run.
pub struct Scene {
    /// The simulation.
    pub sim: Simulation,
    /// End time (s).
    pub end_time: f64,
    /// Output plan.
    pub output: OutputPlan,
    /// Title.
    pub title: String,
    /// Source file.
    pub path: PathBuf,
    /// The phantom the mesh came from (its ROI, locations and skin faces; its `mesh` field is
    /// emptied, the simulation owns the mesh), for `generator = "phantom"`.
    pub phantom: Option<Phantom>,
    /// Things the builder adjusted that the user should know (printed before the run).
    pub notes: Vec<String>,
    /// What runs on the mesh, as resolved (indenters as they run: hands turned into their
    /// capsules and placed), for `palpa export`.
    pub setup: Setup,
}

/// The most time steps a scene may take by the estimate of [`estimated_steps`] unless
/// `[run] max_steps` raises the limit.
pub const DEFAULT_MAX_STEPS: f64 = 1e9;
/// The slowest initial wave speed (m/s) a material may have: a softer or heavier one is not a
/// material but a typo (its stable step would outlast any run).
pub const MIN_WAVE_SPEED: f64 = 1e-6;
/// The fastest initial wave speed (m/s) a material may have (diamond's is about 1.8e4 m/s).
pub const MAX_WAVE_SPEED: f64 = 1e6;

/// Steps a run to `end_time` takes with the model's stable step at the start: the initial
/// stable step, or the step fixed mass scaling raises it to, times the safety factor, capped by
/// `dt_max`. At least 1. (Elements that shrink during the run lower the step further, so the
/// run may take more.)
pub fn estimated_steps(model: &Model, dt_factor: f64, dt_max: Option<f64>, end_time: f64) -> f64 {
    let stable = model.scaled_dt.max(model.initial_dt.0);
    let dt = (dt_factor * stable).min(dt_max.unwrap_or(f64::INFINITY));
    (end_time / dt).ceil().max(1.0)
}

/// Build the model, the simulation and the contact stage of a resolved scene.
pub fn assemble(def: SceneDef) -> Result<Scene, String> {
    let SceneDef {
        title,
        path,
        end_time,
        mesh,
        phantom,
        mut setup,
        mut notes,
    } = def;
    let n_nodes = mesh.nodes.len();
    let parts: Vec<Part> = setup
        .parts
        .iter()
        .map(|p| Part {
            name: p.name.clone(),
            material: p.material.clone(),
            formulation: p.formulation,
        })
        .collect();
    for p in &setup.parts {
        let c = p.material.initial_wave_speed();
        if !(MIN_WAVE_SPEED..=MAX_WAVE_SPEED).contains(&c) {
            return Err(format!(
                "{}: part `{}`: its material ({}, density {:e} kg/m^3) has a wave speed of {c:.3e} m/s, outside [{MIN_WAVE_SPEED:e}, {MAX_WAVE_SPEED:e}] m/s: the modulus or the density is not physical, and the stable time step would be absurd",
                path.display(),
                p.name,
                p.material.law_name(),
                p.material.density()
            ));
        }
    }
    let model = Model::build(mesh, parts, setup.mass_scaling, setup.dt_factor)
        .map_err(|m| format!("{}: {m}", path.display()))?;
    let max_steps = setup.max_steps.unwrap_or(DEFAULT_MAX_STEPS);
    let steps = estimated_steps(&model, setup.dt_factor, setup.dt_max, end_time);
    if steps.is_nan() || steps > max_steps {
        return Err(format!(
            "{}: the run would take about {steps:.3e} time steps (stable step {:.3e} s at element {}, end time {end_time:e} s), more than the limit of {max_steps:.0}; check the moduli and densities, or raise `[run] max_steps` if you mean it",
            path.display(),
            setup.dt_factor * model.initial_dt.0,
            model.initial_dt.1
        ));
    }
    let dt0 = model.scaled_dt.min(model.initial_dt.0);
    let settings = LoopSettings {
        dt_factor: setup.dt_factor,
        precision: setup.precision,
        bulk: setup.bulk,
        damping: setup.damping,
        gravity: setup.gravity,
        relaxation: setup.relaxation,
        dt_max: setup.dt_max.unwrap_or(f64::INFINITY),
        dt_min: match setup.dt_min {
            None => 1e-6 * dt0,
            Some(DtMin::Time(t)) => t,
            Some(DtMin::Factor(f)) => f * dt0,
        },
        hourglass_limit: setup.hourglass_guard.map(|g| HourglassLimit {
            ratio: g.ratio,
            after: g.after.unwrap_or(0.1 * end_time),
        }),
        subcycling: setup.subcycling,
        step_estimate: setup.step_estimate,
    };
    let v0 = if setup.initial_velocity.is_empty() {
        None
    } else {
        let mut v = vec![[0.0; 3]; n_nodes];
        for (nodes, vel) in &setup.initial_velocity {
            for &n in nodes {
                v[n as usize] = *vel;
            }
        }
        Some(v)
    };
    let want_stress = setup.output.needs_stress() || setup.output.probe.is_some();
    let mut sim = Simulation::new(
        model,
        settings,
        setup.constraints.clone(),
        setup.loads.clone(),
        v0,
        want_stress,
    )
    .map_err(|m| format!("{}: {m}", path.display()))?;
    if let Some(c) = setup.contact.as_mut() {
        if !c.indenters.is_empty() || !c.hands.is_empty() {
            let stage = crate::contact_build::build_stage(&sim, c, &path, &mut notes)?;
            sim.stages.push(Box::new(stage));
        }
    }
    Ok(Scene {
        sim,
        end_time,
        output: setup.output.clone(),
        title,
        path,
        phantom,
        notes,
        setup,
    })
}
