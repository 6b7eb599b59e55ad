//! The central-difference time loop (Belytschko, Liu, Moran, Nonlinear Finite Elements for
//! Continua and Structures, Box 6.1), on lumped masses:
//!
//!   f_int^n = f_int(u^n, v^(n-1/2))            element loop, also gives dt_crit
//!   a^n = M^-1 (f_ext^n - f_int^n - f_damp^n)
//!   v^(n+1/2) = v^(n-1/2) + (dt^(n-1/2) + dt^(n+1/2))/2 a^n,   then kinematic conditions
//!   u^(n+1) = u^n + dt^(n+1/2) v^(n+1/2)
//!   dt^(n+3/2) = factor * dt_crit(u^(n+1))
//!
//! Energy balance (Belytschko et al. eq. 6.2.14-6.2.17), with the trapezoidal rule on nodal
//! forces: W^n = W^(n-1) + (Delta u^(n-1/2) + Delta u^(n+1/2))/2 . f^n for the internal, external
//! (loads, gravity, constraint reactions) and damping forces, split so that each value refers
//! to time t^n. Kinetic energy at t^n uses v^n = (v^(n-1/2) + v^(n+1/2))/2. The internal work
//! includes the hourglass and bulk-viscous forces; the hourglass energy (stored for the
//! stiffness form, dissipated for the viscous form) and the bulk-viscous dissipation are
//! accumulated from element-level rates and reported separately, and
//!   internal_energy = W_int - E_hourglass - E_bulk.
//! energy_error = |E_kin + E_int + E_dissipated - W_ext - E_kin0| / max(E_kin, E_int, W_ext, E_kin0),
//! with E_kin0 the kinetic energy of a prescribed initial velocity (zero without one).
//!
//! Only the stages the scene asks for exist: damping, gravity, loads, contact and dynamic
//! relaxation are `Option`s decided at construction.

use crate::bc::{Constraint, Kinematic, NodalLoad, Prescribed};
use crate::element::precision::Precision;
use crate::element::{BulkViscosity, Formulation, StepInput};
use crate::forces::element_loop;
use crate::global_step::{self, GlobalStep};
use crate::model::{ElementTotals, Model, SolverError};
use crate::nodal_update::{constrained_chunks, NodalUpdate, StepParams, StepSums, NODE_CHUNK};
use crate::subcycle::{self, Subcycling};
use rayon::prelude::*;
use std::time::{Duration, Instant};

/// Nodes per parallel chunk when the external forces are cleared or set to gravity.
const FILL_CHUNK: usize = 4096;

/// Energies at the current time (J).
#[derive(Clone, Copy, Debug, Default)]
pub struct Energies {
    /// Kinetic energy.
    pub kinetic: f64,
    /// Internal (stress) work, including the laws' dissipated part.
    pub internal: f64,
    /// Hourglass energy.
    pub hourglass: f64,
    /// Bulk-viscous dissipation.
    pub bulk_viscous: f64,
    /// Damping dissipation.
    pub damping: f64,
    /// Contact energy (J): penalty energy stored between body and indenters plus contact
    /// damping and friction dissipation.
    pub contact: f64,
    /// External work: loads, gravity, constraint reactions, and the work of the indenter drivers
    /// (in place of the contact forces' work on the body).
    pub external: f64,
    /// Dissipated by the laws (part of `internal`).
    pub law_dissipation: f64,
    /// Kinetic energy of the initial velocity field (J); it enters the balance like work.
    pub initial_kinetic: f64,
}

impl Energies {
    /// The imbalance `KE + IE + E_hg + E_bv + E_damp + E_contact - W_ext - KE_0` (J).
    pub fn imbalance(&self) -> f64 {
        self.kinetic
            + self.internal
            + self.hourglass
            + self.bulk_viscous
            + self.damping
            + self.contact
            - self.external
            - self.initial_kinetic
    }

    /// The energy scale the imbalance is measured against: `max(|KE|, |IE|, |W_ext|, KE_0)`.
    pub fn scale(&self) -> f64 {
        self.kinetic
            .abs()
            .max(self.internal.abs())
            .max(self.external.abs())
            .max(self.initial_kinetic)
    }

    /// The normalised energy error `|imbalance| / scale` at this instant (Belytschko, Liu and
    /// Moran, *Nonlinear Finite Elements*, 2000, sec. 6.2.3).
    pub fn error(&self) -> f64 {
        let scale = self.scale();
        if scale > 0.0 {
            self.imbalance().abs() / scale
        } else {
            0.0
        }
    }
}

/// Dynamic relaxation for quasi-static solutions: Underwood's adaptive viscous damping
/// (Underwood 1983, "Dynamic relaxation", in *Computational Methods for Transient Analysis*,
/// ch. 5). The central-difference loop runs with mass-proportional damping `f = c m v` whose
/// coefficient follows the lowest mode the solution is creeping along,
/// `c = 2 w0`, `w0^2 = (u . f_int(u)) / (u . M u)` (the secant Rayleigh quotient of the current
/// displacement), so the slowest mode is critically damped and the iteration converges in
/// about `w_max / w0` steps without the limit cycles of kinetic damping.
#[derive(Clone, Copy, Debug)]
pub struct DynamicRelaxation {
    /// Converged when the out-of-balance force norm falls below tol times the internal force norm.
    pub tolerance: f64,
}

/// A named stage with its accumulated wall time.
#[derive(Clone, Debug)]
pub struct StageTime {
    /// Stage name.
    pub name: &'static str,
    /// Wall time spent.
    pub time: Duration,
}

/// An external-force stage (contact): adds forces to `f_ext` given current positions.
pub trait ForceStage: Send {
    /// Name for the run summary.
    fn name(&self) -> &'static str;
    /// Add forces at time `t` for current positions `x` and velocities `v` (at the last half
    /// step) to `force`; `dt` is the step about to be taken.
    fn apply(&mut self, t: f64, dt: f64, x: &[[f64; 3]], v: &[[f64; 3]], force: &mut [[f64; 3]]);
    /// The nodes whose current positions `apply` reads, or `None` for all of them. The solver
    /// forms the positions `x` only at these nodes; `x` holds stale values elsewhere.
    fn nodes_read(&self) -> Option<&[u32]> {
        None
    }
    /// Energy the stage has absorbed (J) (stored penalty energy plus dissipation).
    fn energy(&self) -> f64;
    /// Work the stage's forces have done on the body so far (J), by the solver's trapezoidal rule.
    /// The energy balance books `W_external = W_loads + driver_work - body_work`: the stage's
    /// forces are replaced by what drives the stage. Default 0 (with `driver_work` 0: the stage's
    /// forces count as plain external loads, and `energy` should then be 0).
    fn body_work(&self) -> f64 {
        0.0
    }
    /// Work done on body plus stage by whatever drives the stage (J), e.g. the indenters'
    /// prescribed motion. Default 0.
    fn driver_work(&self) -> f64 {
        0.0
    }
    /// Largest time step the stage allows (s).
    fn max_dt(&self) -> f64 {
        f64::INFINITY
    }
    /// Extra history columns.
    fn history_columns(&self) -> Vec<String> {
        Vec::new()
    }
    /// Values of the extra history columns, appended to `out`.
    fn history_values(&self, _out: &mut Vec<f64>) {}
    /// Per-node scalars for VTK output (name, values).
    fn point_fields(&self) -> Vec<(String, Vec<f64>)> {
        Vec::new()
    }
    /// Rigid surfaces to draw in the VTK frames (the indenters), at the current time.
    fn surfaces(&self) -> Vec<crate::output::vtk::RigidSurface> {
        Vec::new()
    }
}

/// Default time-step safety factor: dt = factor * min_e kappa_p L_e / c_e with L_e = V / A_max
/// and kappa_p the part's surface-mode factor ([`crate::element::surface_mode_factor`]).
///
/// 0.9, as in LS-DYNA and OpenRadioss. Without kappa the estimate L / c is exact only in the
/// interior of a mesh: the free-surface modes of a nearly incompressible solid are up to 1/0.825
/// times faster, and a regular block of the paper's flesh (K/G = 5e4) or of a nu = 0.49
/// neo-Hookean solid went unstable within 30 steps at factors 0.85-0.9 (a linear-elastic
/// nu = 0.49 block too, with bulk viscosity and hourglass control off, so neither causes it).
/// With kappa, 0.9 leaves the usual 10 % margin for any Poisson ratio
/// (`scene/tests/integration/stable_step.rs`). A run that goes unstable anyway stops with an error
/// (negative internal energy) instead of producing garbage.
pub const DEFAULT_DT_FACTOR: f64 = 0.9;

/// Settings of the time loop.
#[derive(Clone, Debug)]
pub struct LoopSettings {
    /// Time-step safety factor (default [`DEFAULT_DT_FACTOR`]).
    pub dt_factor: f64,
    /// Bulk viscosity, if active.
    pub bulk: Option<BulkViscosity>,
    /// Mass-proportional damping coefficient alpha (1/s), f = alpha m v.
    pub damping: Option<f64>,
    /// Gravity (m/s^2).
    pub gravity: Option<[f64; 3]>,
    /// Dynamic relaxation.
    pub relaxation: Option<DynamicRelaxation>,
    /// Largest allowed step (s).
    pub dt_max: f64,
    /// Smallest allowed step before the run is stopped (s).
    pub dt_min: f64,
    /// Stop the run when hourglass energy passes a share of the internal energy.
    pub hourglass_limit: Option<HourglassLimit>,
    /// The element kernels' number type (default `f64`).
    pub precision: Precision,
    /// Subcycling: the most steps a slow part's interior may take as one
    /// ([`crate::subcycle`]); 1 (the default) is off.
    pub subcycling: u32,
    /// How the stable step is estimated (default: element by element).
    pub step_estimate: StepEstimate,
}

/// How the stable step is estimated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum StepEstimate {
    /// `f min_e kappa L_e / c_e`, element by element (LS-DYNA's and OpenRadioss's default).
    #[default]
    Element,
    /// The mesh's largest eigenvalue by Lanczos iteration, renewed during the run
    /// ([`crate::global_step`]); never below the element estimate.
    Global,
}

impl StepEstimate {
    /// From `"element"` or `"global"`; the error names the accepted values.
    pub fn parse(s: &str) -> Result<StepEstimate, String> {
        match s {
            "element" => Ok(StepEstimate::Element),
            "global" => Ok(StepEstimate::Global),
            _ => Err(format!(
                "unknown step estimate {s:?}: expected \"element\" (element by element) or \"global\" (the mesh's largest eigenvalue)"
            )),
        }
    }

    /// The name [`StepEstimate::parse`] reads.
    pub fn name(self) -> &'static str {
        match self {
            StepEstimate::Element => "element",
            StepEstimate::Global => "global",
        }
    }
}

/// The hourglass guard: a run whose hourglass energy exceeds `ratio` x internal energy at any
/// time after `after` stops with an error naming the element with the largest hourglass energy
/// in that step. The guard reads totals the element loop forms anyway, so it costs nothing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HourglassLimit {
    /// Largest allowed hourglass / internal energy.
    pub ratio: f64,
    /// Time (s) from which the ratio is checked (the start, where the internal energy is
    /// still near zero, would trip it on noise).
    pub after: f64,
}

impl Default for LoopSettings {
    fn default() -> Self {
        LoopSettings {
            dt_factor: DEFAULT_DT_FACTOR,
            bulk: Some(BulkViscosity::default()),
            damping: None,
            gravity: None,
            relaxation: None,
            dt_max: f64::INFINITY,
            dt_min: 0.0,
            hourglass_limit: None,
            precision: Precision::F64,
            subcycling: 1,
            step_estimate: StepEstimate::Element,
        }
    }
}

/// The running simulation.
pub struct Simulation {
    /// The model.
    pub model: Model,
    /// Settings.
    pub settings: LoopSettings,
    /// Displacements u^n (m).
    pub u: Vec<[f64; 3]>,
    /// Velocities v^(n-1/2) (m/s).
    pub v: Vec<[f64; 3]>,
    /// Internal forces f_int^n (N).
    pub f_int: Vec<[f64; 3]>,
    /// External forces f_ext^n (N): loads, gravity, contact.
    pub f_ext: Vec<[f64; 3]>,
    /// Constraint reactions R^n (N), on constrained dofs (written only there; zero elsewhere).
    pub reaction: Vec<[f64; 3]>,
    /// Cauchy stress per element at the last output step (Pa), if requested.
    pub stress: Option<Vec<[f64; 6]>>,
    dof_code: Vec<u32>,
    /// Per chunk of the nodal update: whether any of its degrees of freedom has a kinematic
    /// condition.
    constrained_chunks: Vec<bool>,
    prescribed: Vec<Prescribed>,
    loads: Vec<NodalLoad>,
    gravity_force: Option<Vec<[f64; 3]>>,
    /// External force stages (contact).
    pub stages: Vec<Box<dyn ForceStage>>,
    /// Time t^n (s).
    pub time: f64,
    /// Steps taken.
    pub step: u64,
    /// Step dt^(n-1/2) (s).
    pub dt_prev: f64,
    /// Critical step of the last element loop (s), times the factor.
    pub dt_next: f64,
    /// Element that controls the step.
    pub dt_element: u32,
    /// Smallest and largest step taken (s).
    pub dt_range: (f64, f64),
    /// Energies at t^n.
    pub energy: Energies,
    w_int_acc: f64,
    w_ext_acc: f64,
    w_damp_acc: f64,
    /// Dynamic relaxation: the adaptive damping coefficient (1/s) of the next step.
    relax_alpha: f64,
    /// Out-of-balance force norm / internal force norm at the last step (relaxation).
    pub residual: f64,
    /// Stage timers.
    pub timers: Vec<StageTime>,
    /// Elements eroded so far.
    pub erosion: Erosion,
    /// The subcycling partition and its macro clock, once the first step has formed it (when
    /// `settings.subcycling` > 1 and some part is slow enough).
    pub subcycling: Option<Subcycling>,
    /// Why a run that asked for subcycling has none.
    pub subcycling_off: Option<String>,
    /// The global step estimate, when `settings.step_estimate` asks for it.
    pub global_step: Option<GlobalStep>,
    totals: ElementTotals,
    initialised: bool,
    hg_dissipated: f64,
    hg_worst: Option<HourglassPeak>,
    scratch_x: Vec<[f64; 3]>,
    scratch_targets: Vec<f64>,
    scratch_partials: Vec<StepSums>,
}

/// The element with the largest hourglass energy of one step over the run so far.
#[derive(Clone, Copy, Debug)]
pub struct HourglassPeak {
    /// Element (global id).
    pub element: u32,
    /// Its hourglass energy in that step (J): stored energy plus power x dt.
    pub energy: f64,
    /// The time (s).
    pub time: f64,
}

/// Elements eroded by their law's failure criterion.
#[derive(Clone, Copy, Debug, Default)]
pub struct Erosion {
    /// How many so far.
    pub count: u64,
    /// The first one (global id) and the time it eroded (s).
    pub first: Option<(u32, f64)>,
}

/// The timed stages of a step, in the order of [`Simulation::timers`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stage {
    Elements,
    Loads,
    Contact,
    Update,
    MassScaling,
    StepEstimate,
}

impl Simulation {
    /// Set up a simulation. Initial velocities may be given per node.
    pub fn new(
        model: Model,
        settings: LoopSettings,
        constraints: Vec<Constraint>,
        loads: Vec<NodalLoad>,
        initial_velocity: Option<Vec<[f64; 3]>>,
        want_stress: bool,
    ) -> Result<Simulation, SolverError> {
        let nn = model.mesh.nodes.len();
        let (dof_code, prescribed) = dof_codes(&constraints, nn)?;
        check_loads(&loads, nn)?;
        let gravity_force = settings.gravity.map(|g| {
            model
                .mass
                .iter()
                .map(|&m| [m * g[0], m * g[1], m * g[2]])
                .collect()
        });
        let ne = model.mesh.elements.len();
        let v = initial_velocities(initial_velocity, &dof_code, nn)?;
        let initial_kinetic = kinetic_energy(&v, &model.mass);
        let timers = stage_timers();
        Ok(Simulation {
            model,
            settings,
            u: vec![[0.0; 3]; nn],
            v,
            f_int: vec![[0.0; 3]; nn],
            f_ext: vec![[0.0; 3]; nn],
            reaction: vec![[0.0; 3]; nn],
            stress: if want_stress {
                Some(vec![[0.0; 6]; ne])
            } else {
                None
            },
            constrained_chunks: constrained_chunks(&dof_code),
            dof_code,
            prescribed,
            loads,
            gravity_force,
            stages: Vec::new(),
            time: 0.0,
            step: 0,
            dt_prev: 0.0,
            dt_next: 0.0,
            dt_element: 0,
            dt_range: (f64::INFINITY, 0.0),
            energy: Energies {
                initial_kinetic,
                kinetic: initial_kinetic,
                ..Default::default()
            },
            w_int_acc: 0.0,
            w_ext_acc: 0.0,
            w_damp_acc: 0.0,
            relax_alpha: 0.0,
            residual: f64::INFINITY,
            timers,
            erosion: Erosion::default(),
            subcycling: None,
            subcycling_off: None,
            global_step: None,
            totals: ElementTotals::default(),
            initialised: false,
            hg_dissipated: 0.0,
            hg_worst: None,
            scratch_x: vec![[0.0; 3]; nn],
            scratch_targets: Vec::new(),
            scratch_partials: Vec::new(),
        })
    }

    /// Names of the stages that exist in this run.
    pub fn active_stages(&self) -> Vec<String> {
        let mut s = vec![
            "element forces".to_string(),
            "central-difference update".into(),
        ];
        if self.settings.bulk.is_some() {
            s.push("bulk viscosity".into());
        }
        if self.model.groups.iter().any(|g| !g.history.is_empty()) {
            s.push("history variables".into());
        }
        if self
            .model
            .groups
            .iter()
            .any(|g| !g.density_scale.is_empty())
        {
            s.push("mass scaling".into());
        }
        if self.subcycling.is_some() {
            s.push("subcycling".into());
        }
        if self.global_step.is_some() {
            s.push("global step estimate".into());
        }
        if self.settings.damping.is_some() {
            s.push("mass-proportional damping".into());
        }
        if self.gravity_force.is_some() {
            s.push("gravity".into());
        }
        if !self.loads.is_empty() {
            s.push("nodal loads".into());
        }
        if !self.prescribed.is_empty() {
            s.push("prescribed motion".into());
        }
        for st in &self.stages {
            s.push(st.name().to_string());
        }
        if self.settings.relaxation.is_some() {
            s.push("dynamic relaxation".into());
        }
        s
    }

    fn time_stage<R>(&mut self, k: usize, f: impl FnOnce(&mut Self) -> R) -> R {
        let t0 = Instant::now();
        let r = f(self);
        self.timers[k].time += t0.elapsed();
        r
    }

    /// Compute internal forces at the current state. `want_stress` also fills `self.stress`.
    fn internal_forces(&mut self, want_stress: bool) -> Result<(), SolverError> {
        let first = !self.initialised;
        let (macro_dt, slow_stress) = match &mut self.subcycling {
            // the slow groups write their stress at every macro time (an output step between
            // two shows the last one's)
            Some(s) => {
                let m = s.evaluation(self.time, first);
                (m, m.is_some())
            }
            None => (Some(self.dt_prev), false),
        };
        let input = StepInput {
            dt: self.dt_prev,
            bulk: self.settings.bulk,
            want_stress,
            precision: self.settings.precision,
            macro_dt,
        };
        if let Some(g) = &self.global_step {
            if g.due(self.step, g.fall) {
                for gr in self.model.groups.iter_mut() {
                    gr.record_dt = true;
                }
            }
        }
        let t0 = Instant::now();
        let stress = if want_stress || slow_stress {
            self.stress.as_deref_mut()
        } else {
            None
        };
        let Model {
            parts,
            groups,
            mesh,
            ..
        } = &mut self.model;
        let r = element_loop(
            parts,
            groups,
            &mesh.nodes,
            &self.u,
            &self.v,
            &input,
            &mut self.f_int,
            stress,
        );
        self.timers[Stage::Elements as usize].time += t0.elapsed();
        let tot = r.map_err(|(e, reason)| SolverError::ElementFailure {
            element: e,
            part: self.part_of(e),
            time: self.time,
            reason,
        })?;
        self.totals = tot;
        if let Some(sc) = &mut self.subcycling {
            sc.note_step_set_by(self.model.mesh.element_part[tot.dt_elem as usize] as usize);
        }
        if self.model.mass_scaling.is_some() {
            self.time_stage(Stage::MassScaling as usize, |s| {
                s.apply_run_time_mass_scaling()
            })?;
        }
        self.erosion.count += tot.newly_eroded as u64;
        if self.erosion.first.is_none() {
            self.erosion.first = tot.first_eroded.map(|e| (e, self.time));
        }
        if tot.dt_min.is_infinite() && self.erosion.count > 0 {
            // Every element has eroded: the nodes fly free, keep the last step.
            self.dt_next = self.dt_prev;
        } else {
            self.dt_next = self.settings.dt_factor * tot.dt_min;
            self.dt_element = tot.dt_elem;
            if self.global_step.is_some() {
                self.time_stage(Stage::StepEstimate as usize, |s| s.global_step_choice());
            }
        }
        Ok(())
    }

    /// Run-time selective mass scaling (LS-DYNA's negative DT2MS): every element whose step
    /// fell below the target in this element loop gets the density scale that brings it back,
    /// `s' = s (dt_floor / dt_e)^2`, and its nodes the mass `rho (s' - s) V_a` (V_a the lumped
    /// volume of node a). Velocities are kept, so the kinetic energy the new mass carries,
    /// `1/2 dm |v|^2`, enters the external work (the balance stays closed), and the added mass
    /// is reported per part. Applied serially in group, chunk and element order, so the result
    /// does not depend on the thread count. A run whose added mass passes `max_added` stops
    /// with an error that names the element and the time.
    fn apply_run_time_mass_scaling(&mut self) -> Result<(), SolverError> {
        let Some(ms) = self.model.mass_scaling else {
            return Ok(());
        };
        let mut energy = 0.0;
        // The element that needed the largest density scale in this step.
        let mut worst: Option<(f64, u32)> = None;
        let Model {
            parts,
            groups,
            mass,
            part_mass,
            ..
        } = &mut self.model;
        // a group not evaluated in this step (subcycling) holds its last chunks' results
        for g in groups.iter_mut().filter(|g| g.evaluated) {
            let rho = parts[g.part].material.density();
            for ch in g.chunks.iter() {
                for &(le, s_new) in &ch.rescale {
                    let le = le as usize;
                    let s_old = g.density_scale[le];
                    let ds = s_new - s_old;
                    for a in 0..8 {
                        let n = g.conn[le][a] as usize;
                        let dm = rho * ds * g.lumped[le][a];
                        mass[n] += dm;
                        let v = self.v[n];
                        energy += 0.5 * dm * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
                    }
                    let pm = &mut part_mass[g.part];
                    pm.added += rho * ds * g.vol0[le];
                    if s_old == 1.0 {
                        pm.scaled_elements += 1;
                    }
                    g.density_scale[le] = s_new;
                    if worst.is_none_or(|(w, _)| s_new > w) {
                        worst = Some((s_new, g.elements[le]));
                    }
                }
            }
        }
        self.w_ext_acc += energy;
        if let Some((scale, e)) = worst {
            let added = self.model.added_mass();
            let phys = self.model.physical_mass();
            if added > ms.max_added * phys {
                // The part that took the largest share of its own mass.
                let (_, pm) = self
                    .model
                    .part_mass
                    .iter()
                    .enumerate()
                    .max_by(|a, b| a.1.added_fraction().total_cmp(&b.1.added_fraction()))
                    .expect("a model has parts");
                return Err(SolverError::ElementFailure {
                    element: e,
                    part: self.part_of(e),
                    time: self.time,
                    reason: format!(
                        "run-time mass scaling to {:.3e} s has added {:.2} % of the physical mass \
                         (limit {:.2} %); this element needed the largest density scale in this \
                         step ({scale:.1}x), and part `{}` has taken {:.1} % of its own mass over \
                         {} elements: elements are collapsing; lower mass_scaling.target_dt, \
                         raise mass_scaling.max_added, or refine the mesh there",
                        ms.target_dt,
                        100.0 * added / phys,
                        100.0 * ms.max_added,
                        pm.name,
                        100.0 * pm.added_fraction(),
                        pm.scaled_elements
                    ),
                });
            }
        }
        Ok(())
    }

    /// Hourglass energy (J, stored plus dissipated; the physical form's is internal energy and
    /// not counted) per part that has any, largest first.
    pub fn hourglass_by_part(&self) -> Vec<(String, f64)> {
        let mut by_part = vec![0.0; self.model.parts.len()];
        for g in &self.model.groups {
            by_part[g.part] += g.hourglass.total();
        }
        let mut v: Vec<(String, f64)> = by_part
            .into_iter()
            .enumerate()
            .filter(|(_, e)| *e > 0.0)
            .map(|(p, e)| (self.model.parts[p].name.clone(), e))
            .collect();
        v.sort_by(|a, b| b.1.total_cmp(&a.1));
        v
    }

    /// The element with the largest hourglass energy in one step over the run so far.
    pub fn hourglass_peak(&self) -> Option<HourglassPeak> {
        self.hg_worst
    }

    /// Part name of an element.
    pub fn part_of(&self, e: u32) -> String {
        let p = self.model.mesh.element_part[e as usize] as usize;
        self.model
            .parts
            .get(p)
            .map(|p| p.name.clone())
            .unwrap_or_default()
    }

    /// External forces at time t: loads, gravity, then the force stages (contact), which book
    /// their dissipation and regularise friction over the step `dt` about to be taken.
    fn external_forces(&mut self, dt: f64) {
        let t = self.time;
        let t0 = Instant::now();
        match &self.gravity_force {
            Some(g) => self
                .f_ext
                .par_chunks_mut(FILL_CHUNK)
                .zip(g.par_chunks(FILL_CHUNK))
                .for_each(|(f, g)| f.copy_from_slice(g)),
            None => self
                .f_ext
                .par_chunks_mut(FILL_CHUNK)
                .for_each(|f| f.fill([0.0; 3])),
        }
        for l in &self.loads {
            let val = l.curve.value(t);
            for &n in &l.nodes {
                self.f_ext[n as usize][l.dof] += val;
            }
        }
        self.timers[Stage::Loads as usize].time += t0.elapsed();
        if !self.stages.is_empty() {
            let t0 = Instant::now();
            let nodes = &self.model.mesh.nodes;
            // Current positions, reference + displacement, where the stages read them (the
            // contact stage: the nodes of its surface faces; measured in docs/performance.md).
            let cur: &mut Vec<[f64; 3]> = &mut self.scratch_x;
            let u = &self.u;
            let at = |c: &mut [f64; 3], n: usize| {
                let (p, d) = (nodes[n], u[n]);
                *c = [p[0] + d[0], p[1] + d[1], p[2] + d[2]];
            };
            if self.stages.iter().all(|s| s.nodes_read().is_some()) {
                for st in &self.stages {
                    for &n in st.nodes_read().unwrap_or_default() {
                        at(&mut cur[n as usize], n as usize);
                    }
                }
            } else {
                for (n, c) in cur.iter_mut().enumerate() {
                    at(c, n);
                }
            }
            for st in self.stages.iter_mut() {
                st.apply(t, dt, cur, &self.v, &mut self.f_ext);
            }
            self.timers[Stage::Contact as usize].time += t0.elapsed();
        }
    }

    /// Compute the forces of the initial state (called by the first step if not before).
    pub fn initialise(&mut self) -> Result<(), SolverError> {
        if !self.initialised {
            if self.settings.subcycling > 1 {
                self.partition_for_subcycling()?;
            }
            if self.settings.step_estimate == StepEstimate::Global {
                self.start_global_step()?;
            }
            self.internal_forces(self.stress.is_some())?;
            self.initialised = true;
        }
        Ok(())
    }

    /// Lengthen the next step by the global estimate ([`crate::global_step`]), renewing it
    /// when due; never below the element estimate already in `dt_next`.
    fn global_step_choice(&mut self) {
        let Some(g) = &mut self.global_step else {
            return;
        };
        // the loop that has just run recorded every element's step when an estimate was due
        if self.model.groups.iter().any(|gr| gr.record_dt) {
            g.estimate(&mut self.model, &self.u, self.step);
            g.fall = 1.0;
        } else {
            g.fall = GlobalStep::fall(&self.model);
        }
        self.dt_next = self.dt_next.max(self.settings.dt_factor * g.step(g.fall));
    }

    /// Start the global step estimate ([`crate::global_step`]).
    fn start_global_step(&mut self) -> Result<(), SolverError> {
        if self.subcycling.is_some() {
            return Err(SolverError::Invalid(
                "the global step estimate cannot be combined with subcycling (the slow parts' \
                 elements report their step over k): set run.step_estimate = \"element\" or \
                 run.subcycling = 1"
                    .into(),
            ));
        }
        if self.settings.dt_factor > DEFAULT_DT_FACTOR {
            // the contact stage's bound assumes the body at most 0.9 of its critical step, and
            // the global estimate leaves no slack beyond the factor
            return Err(SolverError::Invalid(format!(
                "run.step_estimate = \"global\" needs run.dt_factor <= {DEFAULT_DT_FACTOR}, got {}",
                self.settings.dt_factor
            )));
        }
        if let Some(g) = self
            .model
            .groups
            .iter()
            .find(|g| self.model.parts[g.part].formulation == Formulation::Full { fbar: false })
        {
            return Err(SolverError::Invalid(format!(
                "run.step_estimate = \"global\" does not hold fully integrated elements without F-bar \
                 (part `{}`): use formulation = \"full_fbar\" or run.step_estimate = \"element\"",
                self.model.parts[g.part].name
            )));
        }
        self.global_step = Some(GlobalStep::new(&self.model, global_step::DEFAULT_INTERVAL));
        Ok(())
    }

    /// Form the subcycling partition ([`crate::subcycle::plan`]) and split the model's groups
    /// by it, before the first force evaluation. Nodes with a kinematic condition or a load,
    /// and the nodes a force stage reads, stay fast; a stage that reads every node leaves
    /// nothing to subcycle.
    fn partition_for_subcycling(&mut self) -> Result<(), SolverError> {
        if self.settings.relaxation.is_some() {
            return Err(SolverError::Invalid(
                "subcycling cannot be combined with dynamic relaxation (its damping is formed from \
                 every node's force at every step): set run.subcycling = 1"
                    .into(),
            ));
        }
        let mut pinned: Vec<bool> = self
            .dof_code
            .chunks(3)
            .map(|c| c.iter().any(|&k| k != 0))
            .collect();
        for l in &self.loads {
            for &n in &l.nodes {
                pinned[n as usize] = true;
            }
        }
        for st in &self.stages {
            let Some(nodes) = st.nodes_read() else {
                self.subcycling_off = Some("a force stage reads every node".into());
                return Ok(());
            };
            for &n in nodes {
                pinned[n as usize] = true;
            }
        }
        let m = &self.model;
        let Some(plan) = subcycle::plan(m, &m.part_dt, &pinned, self.settings.subcycling) else {
            self.subcycling_off = Some(
                "no part has a stable step of at least 4 times the model's with an element \
                 whose nodes all lie inside it, away from conditions, loads and contact"
                    .into(),
            );
            return Ok(());
        };
        let parts = self
            .model
            .split_for_subcycling(&plan.slow_element, &plan.slow_part, plan.k)?;
        self.subcycling = Some(Subcycling::new(plan, parts));
        Ok(())
    }

    /// Take one step from t^n to t^(n+1). If the new time reaches `stress_at` (s), the Cauchy
    /// stress of the new state is stored in `self.stress` (when stress output was requested).
    /// Every step runs the run's guards, whoever calls it: the step-size floor
    /// (`settings.dt_min`), the hourglass guard ([`HourglassLimit`], when set) and the
    /// stability guard (non-finite energies or a negative internal energy,
    /// [`SolverError::Unstable`]).
    pub fn step(&mut self, stress_at: f64) -> Result<(), SolverError> {
        self.initialise()?;
        // The step is chosen first, with every clamp (dt_max, relaxation, a stage's own limit),
        // and only then do the stages run with it.
        let mut dt = self.dt_next.min(self.settings.dt_max);
        if self.settings.relaxation.is_some() {
            // Dynamic relaxation steps in fictitious time with a step that never grows: a step
            // that follows the state lets the iteration settle into a limit cycle instead of
            // converging (seen with kinetic damping on a block compressed 20 % at once).
            if self.dt_prev > 0.0 {
                dt = dt.min(self.dt_prev);
            }
        }
        for st in &self.stages {
            dt = dt.min(st.max_dt());
        }
        if !(dt > self.settings.dt_min) || !dt.is_finite() {
            let e = self.dt_element;
            return Err(SolverError::ElementFailure {
                element: e,
                part: self.part_of(e),
                time: self.time,
                reason: format!(
                    "the stable time step fell to {dt:.3e} s (below the minimum {:.3e} s): the element is \
                     collapsing or its wave speed exploded",
                    self.settings.dt_min
                ),
            });
        }
        self.external_forces(dt);
        let t0 = Instant::now();
        self.update(dt);
        self.timers[Stage::Update as usize].time += t0.elapsed();
        self.step += 1;
        self.time += dt;
        self.dt_prev = dt;
        self.dt_range = (self.dt_range.0.min(dt), self.dt_range.1.max(dt));
        self.check_hourglass()?;
        // Forces at the new state, for the next step (and its stable dt).
        let want = self.stress.is_some() && self.time >= stress_at;
        self.internal_forces(want)?;
        self.check_stability()
    }

    /// The hourglass guard ([`HourglassLimit`]), on the energies just formed at t^n.
    fn check_hourglass(&self) -> Result<(), SolverError> {
        let Some(lim) = self.settings.hourglass_limit else {
            return Ok(());
        };
        let (hg, ie) = (self.energy.hourglass, self.energy.internal);
        if self.time < lim.after || !(ie > 0.0) || hg <= lim.ratio * ie {
            return Ok(());
        }
        let e = self.totals.hg_peak_elem;
        Err(SolverError::ElementFailure {
            element: e,
            part: self.part_of(e),
            time: self.time,
            reason: format!(
                "hourglass energy is {:.1} % of the internal energy (limit {:.1} %); this element \
                 has the largest hourglass energy ({:.3e} J in this step). The one-point element's \
                 zero-energy modes carry the deformation here: use the fully integrated element \
                 (full_fbar), the stiffness hourglass form, or a finer mesh under the load",
                100.0 * hg / ie,
                100.0 * lim.ratio,
                self.totals.hg_peak
            ),
        })
    }

    /// The stability guard, on the energies formed in this step (at t^n): every law here is
    /// passive, so the internal energy (stored plus dissipated by the laws) cannot fall below
    /// zero; when the central-difference scheme goes unstable, the spurious high-frequency
    /// energy shows up as a large negative internal energy balanced by hourglass and
    /// bulk-viscous dissipation. Also stops on non-finite energies. The message names the time
    /// after the step and the element that sets the next step.
    fn check_stability(&self) -> Result<(), SolverError> {
        let e = &self.energy;
        let all = [
            e.kinetic,
            e.internal,
            e.hourglass,
            e.bulk_viscous,
            e.damping,
            e.contact,
            e.external,
        ];
        if all.iter().any(|x| !x.is_finite()) {
            return Err(SolverError::Unstable(format!(
                "the energies became non-finite at t = {:.6} ms",
                self.time * 1e3
            )));
        }
        let scale = all.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        if e.internal < -0.05 * scale && scale > 0.0 {
            let el = self.dt_element;
            // The advice follows the dissipation that outran the work: bulk viscosity booked from
            // each element's rate at the start of the step overshoots when a prescribed motion
            // starts abruptly on nearly incompressible material.
            let advice = if e.bulk_viscous >= e.hourglass {
                "the bulk-viscous dissipation outran the work it absorbs, as when a prescribed motion starts abruptly: ramp the motion (kind = \"smooth_step\"), lower `run.dt_factor`, or lower the bulk viscosity"
            } else {
                "the hourglass dissipation outran the work it absorbs: lower `run.dt_factor`, or use stiffness or physical hourglass control"
            };
            return Err(SolverError::Unstable(format!(
                "numerical instability at t = {:.6} ms: the internal energy became negative ({:.4e} J; hourglass {:.4e} J, bulk viscosity {:.4e} J, external work {:.4e} J). The step was set by element {el} (part {}), `run.dt_factor` {}; {advice}{}",
                self.time * 1e3,
                e.internal,
                e.hourglass,
                e.bulk_viscous,
                e.external,
                self.part_of(el),
                self.settings.dt_factor,
                if self.global_step.is_some() {
                    "; the step came from the global estimate: try run.step_estimate = \"element\" (palpate --step-estimate element)"
                } else {
                    ""
                }
            )));
        }
        Ok(())
    }

    /// The nodal update with kinematic conditions and the energy sums.
    fn update(&mut self, dt: f64) {
        let dt_old = self.dt_prev;
        let dt_avg = 0.5 * (dt_old + dt);
        let t = self.time;
        let relax = self.settings.relaxation.is_some();
        let alpha = if relax {
            self.relax_alpha
        } else {
            self.settings.damping.unwrap_or(0.0)
        };
        let damping = relax || self.settings.damping.is_some();
        self.kinematic_targets(t, dt);
        if let Some(sc) = &mut self.subcycling {
            sc.weigh(&mut self.f_int, &mut self.f_ext, dt, dt_old);
        }
        let s = self.integrate(StepParams {
            dt,
            dt_old,
            dt_avg,
            alpha,
            damping,
            relax,
        });
        self.book_energies(&s, dt_avg, t);
        self.residual = if s.f_int2 > 0.0 {
            (s.residual2 / s.f_int2).sqrt()
        } else {
            0.0
        };
        if relax {
            self.relax_alpha = underwood_alpha(&s, dt);
        }
    }

    /// The kinematic conditions' targets for the step `dt` from `t`, once per prescription
    /// (into `scratch_targets`): the velocity at the half step, or the displacement at its end.
    fn kinematic_targets(&mut self, t: f64, dt: f64) {
        let targets: &mut Vec<f64> = &mut self.scratch_targets;
        targets.clear();
        for p in &self.prescribed {
            targets.push(match &p.kind {
                Kinematic::Velocity(c) => c.value(t + 0.5 * dt),
                Kinematic::Displacement(c) => c.value(t + dt),
                Kinematic::Fixed => 0.0,
            });
        }
    }

    /// The central-difference update of velocities, displacements and reactions, and its sums.
    /// Nodes are updated in parallel chunks of fixed size; each chunk's sums are reduced
    /// serially in chunk order, so the result is the same for any thread count.
    fn integrate(&mut self, p: StepParams) -> StepSums {
        let nn = self.u.len();
        let partials = &mut self.scratch_partials;
        partials.clear();
        partials.resize(nn.div_ceil(NODE_CHUNK), StepSums::default());
        let nodal = NodalUpdate {
            p,
            mass: &self.model.mass,
            f_int: &self.f_int,
            f_ext: &self.f_ext,
            dof_code: &self.dof_code,
            constrained: &self.constrained_chunks,
            prescribed: &self.prescribed,
            targets: &self.scratch_targets,
        };
        self.u
            .par_chunks_mut(NODE_CHUNK)
            .zip(self.v.par_chunks_mut(NODE_CHUNK))
            .zip(self.reaction.par_chunks_mut(NODE_CHUNK))
            .zip(partials.par_iter_mut())
            .enumerate()
            .for_each(|(ci, (((uc, vc), rc), s))| *s = nodal.chunk(ci, uc, vc, rc));
        let mut s = StepSums::default();
        for p in partials.iter() {
            s.add(p);
        }
        s
    }

    /// The energies at t^n from the step's sums: the works by the trapezoidal rule, the
    /// hourglass, bulk-viscous and law dissipation from the element loop's rates, and the
    /// stages' contact energy and driver work.
    fn book_energies(&mut self, s: &StepSums, dt_avg: f64, t: f64) {
        let tot = self.totals;
        let w_int = self.w_int_acc + s.w_int_old;
        let w_ext = self.w_ext_acc + s.w_ext_old;
        let w_damp = self.w_damp_acc + s.w_damp_old;
        self.w_int_acc = w_int + s.w_int_new;
        self.w_ext_acc = w_ext + s.w_ext_new;
        self.w_damp_acc = w_damp + s.w_damp_new;
        self.book_hourglass(dt_avg, t);
        let e = &mut self.energy;
        e.hourglass = tot.hg_stored + self.hg_dissipated;
        e.bulk_viscous += tot.bulk_power * dt_avg;
        e.law_dissipation += tot.law_dissipation;
        e.kinetic = s.kinetic;
        e.damping = w_damp;
        // w_ext holds the work of the stages' (contact) forces on the body; replace it by the work
        // of the stages' drivers (the indenters' motion), so that the balance
        // KE + IE + E_contact = W_loads + W_drive also checks the contact's own energy.
        e.contact = self.stages.iter().map(|s| s.energy()).sum();
        e.external = w_ext
            + self
                .stages
                .iter()
                .map(|s| s.driver_work() - s.body_work())
                .sum::<f64>();
        e.internal = w_int - e.hourglass - e.bulk_viscous;
    }

    /// The hourglass power over the step (`dt_avg`), in total and per group, and the
    /// element with the largest hourglass energy so far (this step's at time `t`).
    fn book_hourglass(&mut self, dt_avg: f64, t: f64) {
        let tot = self.totals;
        self.hg_dissipated += tot.hg_power * dt_avg;
        for g in self.model.groups.iter_mut() {
            g.hourglass.dissipated += g.hourglass.power * dt_avg;
        }
        if tot.hg_peak > self.hg_worst.map_or(0.0, |w| w.energy) {
            self.hg_worst = Some(HourglassPeak {
                element: tot.hg_peak_elem,
                energy: tot.hg_peak,
                time: t,
            });
        }
    }
}

/// The code of each degree of freedom (node * 3 + direction) from the kinematic conditions: 0
/// free, 1 fixed, k + 2 prescribed by the k-th of the returned prescriptions (a later condition
/// on the same degree of freedom replaces an earlier one).
fn dof_codes(
    constraints: &[Constraint],
    nn: usize,
) -> Result<(Vec<u32>, Vec<Prescribed>), SolverError> {
    let mut dof_code = vec![0u32; nn * 3];
    let mut prescribed = Vec::new();
    for c in constraints {
        if c.dof > 2 {
            return Err(SolverError::Invalid(
                "constraint direction must be x, y or z".into(),
            ));
        }
        let code = match &c.kind {
            Kinematic::Fixed => 1,
            k => {
                prescribed.push(Prescribed { kind: k.clone() });
                (prescribed.len() + 1) as u32
            }
        };
        for &n in &c.nodes {
            if n as usize >= nn {
                return Err(SolverError::Invalid(format!(
                    "constraint refers to node {n} beyond the mesh"
                )));
            }
            dof_code[n as usize * 3 + c.dof] = code;
        }
    }
    Ok((dof_code, prescribed))
}

/// Every load acts on nodes of the mesh (`nn` nodes).
fn check_loads(loads: &[NodalLoad], nn: usize) -> Result<(), SolverError> {
    for l in loads {
        if let Some(&n) = l.nodes.iter().find(|&&n| n as usize >= nn) {
            return Err(SolverError::Invalid(format!(
                "load refers to node {n} beyond the mesh"
            )));
        }
    }
    Ok(())
}

/// The initial velocities (zero where none are given), zero on fixed degrees of freedom.
fn initial_velocities(
    given: Option<Vec<[f64; 3]>>,
    dof_code: &[u32],
    nn: usize,
) -> Result<Vec<[f64; 3]>, SolverError> {
    let mut v = given.unwrap_or_else(|| vec![[0.0; 3]; nn]);
    if v.len() != nn {
        return Err(SolverError::Invalid(
            "initial velocity has the wrong length".into(),
        ));
    }
    for n in 0..nn {
        for d in 0..3 {
            if dof_code[n * 3 + d] == 1 {
                v[n][d] = 0.0;
            }
        }
    }
    Ok(v)
}

/// Kinetic energy of the velocities `v` on the nodal masses (J).
fn kinetic_energy(v: &[[f64; 3]], mass: &[f64]) -> f64 {
    v.iter()
        .zip(mass)
        .map(|(v, m)| 0.5 * m * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]))
        .sum()
}

/// The stage timers, all at zero, in the order of [`Stage`].
fn stage_timers() -> Vec<StageTime> {
    [
        "element forces",
        "loads",
        "contact",
        "update",
        "mass scaling",
        "global step estimate",
    ]
    .into_iter()
    .map(|name| StageTime {
        name,
        time: Duration::ZERO,
    })
    .collect()
}

/// Dynamic relaxation: Underwood's adaptive damping coefficient (1/s) for the next step,
/// critical for the mode the displacement follows (`w^2 = u.f_int / u.M.u`), kept below
/// 1/dt (past that the explicit damping term would overshoot).
fn underwood_alpha(s: &StepSums, dt: f64) -> f64 {
    let w2 = if s.u_m_u > 0.0 {
        (s.u_f_int / s.u_m_u).max(0.0)
    } else {
        0.0
    };
    (2.0 * w2.sqrt()).min(1.0 / dt)
}
