//! Drive a [`Scene`] to its end time: the time loop, VTK frames, `history.csv`, and the run
//! summary. A stop request (Ctrl-C) ends the loop after the current step and leaves complete
//! output up to the last frame; a failing run keeps what it had written and writes its
//! summary with the error.

use crate::Scene;
use serde::Serialize;
use solver::model::SolverError;
use solver::output::history::History;
use solver::output::stress::{principal, von_mises};
use solver::output::vtk::{Frame, Series};
use solver::simulation::Simulation;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// How a run ended. Written as `completed`, `converged`, `stopped` or `failed: <error>` (in
/// `summary.json` and a campaign run's `done.json`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum RunStatus {
    /// Reached its end time.
    Completed,
    /// A relaxation run whose residual fell below its tolerance.
    Converged,
    /// Stopped on request (Ctrl-C), with complete output up to the last frame.
    Stopped,
    /// Failed with this error.
    Failed(String),
}

impl std::fmt::Display for RunStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RunStatus::Completed => f.write_str("completed"),
            RunStatus::Converged => f.write_str("converged"),
            RunStatus::Stopped => f.write_str("stopped"),
            RunStatus::Failed(e) => write!(f, "failed: {e}"),
        }
    }
}

impl std::str::FromStr for RunStatus {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "completed" => Ok(RunStatus::Completed),
            "converged" => Ok(RunStatus::Converged),
            "stopped" => Ok(RunStatus::Stopped),
            _ => match s.strip_prefix("failed: ") {
                Some(e) => Ok(RunStatus::Failed(e.to_string())),
                None => Err(format!(
                    "unknown run status `{s}` (completed, converged, stopped or failed: ...)"
                )),
            },
        }
    }
}

impl Serialize for RunStatus {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl<'de> serde::Deserialize<'de> for RunStatus {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        s.parse().map_err(serde::de::Error::custom)
    }
}

/// Where the time went, per stage.
#[derive(Clone, Debug, Serialize)]
pub struct StageShare {
    /// Stage name.
    pub stage: String,
    /// Seconds.
    pub seconds: f64,
    /// Share of the run's wall time.
    pub share: f64,
}

/// Added mass of one part.
#[derive(Clone, Debug, Serialize)]
pub struct PartMassReport {
    /// Part name.
    pub part: String,
    /// Physical mass (kg).
    pub physical_kg: f64,
    /// Added mass (kg).
    pub added_kg: f64,
    /// Added / physical, percent.
    pub added_percent: f64,
}

/// The run summary, printed and written as `summary.json`.
#[derive(Clone, Debug, Serialize)]
pub struct RunSummary {
    /// Scene title.
    pub title: String,
    /// How the run ended: `completed`, `converged`, `stopped` or `failed: ` and the error.
    pub status: RunStatus,
    /// Simulated time reached (s).
    pub time: f64,
    /// Steps.
    pub steps: u64,
    /// Elements.
    pub elements: usize,
    /// Nodes.
    pub nodes: usize,
    /// Wall time (s).
    pub wall_seconds: f64,
    /// Element-cycles per second.
    pub element_cycles_per_second: f64,
    /// Smallest step (s).
    pub dt_min: f64,
    /// Largest step (s).
    pub dt_max: f64,
    /// Final energy error.
    pub energy_error: f64,
    /// Largest energy imbalance over the run divided by the run's largest energy scale
    /// (`max_t |imbalance| / max_t max(|KE|, |IE|, |W_ext|, KE_0)`): the headline, which a
    /// start-up transient at a tiny energy cannot inflate.
    pub max_energy_error: f64,
    /// Largest instantaneous energy error `|imbalance(t)| / scale(t)` after 1 % of the run: a
    /// stricter measure, dominated by the first steps when the energies are still small.
    pub max_instant_energy_error: f64,
    /// Final energies (J).
    pub kinetic_energy: f64,
    /// Final internal energy (J).
    pub internal_energy: f64,
    /// Final hourglass energy (J).
    pub hourglass_energy: f64,
    /// Final external work (J).
    pub external_work: f64,
    /// The element kernels' number type (`f64` or `f32`).
    pub precision: String,
    /// Active stages.
    pub active_stages: Vec<String>,
    /// Time per stage.
    pub stage_times: Vec<StageShare>,
    /// Mass per part.
    pub mass: Vec<PartMassReport>,
    /// Parts whose bulk modulus the scene changed (the incompressibility knob).
    pub bulk_modulus: Vec<crate::def::BulkChange>,
    /// What the user should look at although the run finished (e.g. the hourglass energy
    /// above [`HOURGLASS_WARNING`] of the internal energy).
    pub warnings: Vec<String>,
    /// Where the hourglass energy sits (per part, the element with the most in one step).
    pub hourglass: HourglassReport,
    /// Threads used.
    pub threads: usize,
    /// Frames written.
    pub frames: usize,
    /// Elements eroded by their law's failure criterion.
    pub eroded_elements: u64,
    /// The first eroded element.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub first_eroded: Option<ErodedElement>,
    /// Subcycling, when the run had slow elements ([`solver::subcycle`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub subcycling: Option<SubcyclingReport>,
    /// The global step estimate, when the run used it ([`solver::global_step`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub global_step: Option<GlobalStepSummary>,
}

/// What the global step estimate did in a run.
#[derive(Clone, Debug, Serialize)]
pub struct GlobalStepSummary {
    /// Estimates made.
    pub estimates: u64,
    /// Lanczos iterations in all.
    pub iterations: u64,
    /// Smallest and largest ratio of the mesh's critical step to the smallest element estimate
    /// (same shape, without bulk viscosity).
    pub ratio_min: f64,
    /// See `ratio_min`.
    pub ratio_max: f64,
    /// Wall time of the estimates (s).
    pub seconds: f64,
}

/// What subcycling did in a run.
#[derive(Clone, Debug, Serialize)]
pub struct SubcyclingReport {
    /// Steps per macro step.
    pub ratio: u32,
    /// Per split part: its name, its slow elements and all its elements.
    pub parts: Vec<(String, usize, usize)>,
    /// Slow nodes.
    pub slow_nodes: usize,
    /// Element evaluations the run skipped, as a fraction of elements x steps.
    pub saved_fraction: f64,
    /// Steps whose stable step an element of a slow part set (its own over the ratio).
    pub slow_bound_steps: u64,
}

impl RunSummary {
    /// Mass added by mass scaling over all parts, as a percentage of the physical mass.
    pub fn added_mass_percent(&self) -> f64 {
        let (p, a) = self
            .mass
            .iter()
            .fold((0.0, 0.0), |(p, a), m| (p + m.physical_kg, a + m.added_kg));
        100.0 * a / p.max(1e-300)
    }
}

/// The hourglass energy, as a fraction of the internal energy, above which the summary warns
/// (LS-DYNA users' rule of thumb: 10 %).
pub const HOURGLASS_WARNING: f64 = 0.1;

/// Where a run's hourglass energy sits: per part, and the element with the most in one step.
#[derive(Clone, Debug, Default, Serialize)]
pub struct HourglassReport {
    /// Hourglass energy (J) per part that has any, largest first.
    pub by_part: Vec<PartEnergy>,
    /// The element with the largest hourglass energy of one step over the run.
    pub peak: Option<HourglassElement>,
}

/// One part's energy.
#[derive(Clone, Debug, Serialize)]
pub struct PartEnergy {
    /// Part name.
    pub part: String,
    /// Energy (J).
    pub energy_j: f64,
}

/// An element's hourglass energy in one step.
#[derive(Clone, Debug, Serialize)]
pub struct HourglassElement {
    /// Element id.
    pub element: u32,
    /// Its part.
    pub part: String,
    /// Its hourglass energy in that step (J).
    pub energy_j: f64,
    /// When (s).
    pub time: f64,
}

impl HourglassReport {
    /// The report of a simulation so far.
    pub fn of(sim: &Simulation) -> Self {
        HourglassReport {
            by_part: sim
                .hourglass_by_part()
                .into_iter()
                .map(|(part, energy_j)| PartEnergy { part, energy_j })
                .collect(),
            peak: sim.hourglass_peak().map(|p| HourglassElement {
                element: p.element,
                part: sim.part_of(p.element),
                energy_j: p.energy,
                time: p.time,
            }),
        }
    }
}

/// The summary's warnings for final energies: the hourglass energy above
/// [`HOURGLASS_WARNING`] of the internal energy, naming the part with the most and the element
/// with the largest in one step.
pub fn energy_warnings(internal: f64, hourglass: f64, hg: &HourglassReport) -> Vec<String> {
    let mut w = Vec::new();
    if internal > 0.0 && hourglass > HOURGLASS_WARNING * internal {
        let mut where_ = String::new();
        if let Some(p) = hg.by_part.first() {
            where_ += &format!(
                "; part `{}` holds {:.0} % of it",
                p.part,
                100.0 * p.energy_j / hourglass.max(1e-300)
            );
        }
        if let Some(e) = &hg.peak {
            where_ += &format!(
                ", and element {} (part `{}`) had the most in one step ({:.3e} J at t = {:.4e} s)",
                e.element, e.part, e.energy_j, e.time
            );
        }
        w.push(format!(
            "the hourglass energy is {:.1} % of the internal energy (above {:.0} %){where_}: the one-point elements deform in modes their mean strain does not see; try hourglass = \"physical\" (or --element 1pt-physical), a finer mesh or F-bar elements, and stop such runs with [run] max_hourglass_ratio",
            100.0 * hourglass / internal,
            100.0 * HOURGLASS_WARNING
        ));
    }
    w
}

/// An eroded element, for the summary.
#[derive(Clone, Debug, Serialize)]
pub struct ErodedElement {
    /// Element id.
    pub element: u32,
    /// Its part.
    pub part: String,
    /// Simulated time of the erosion (s).
    pub time: f64,
}

/// Progress information for a progress bar.
pub struct Progress<'a> {
    /// The simulation.
    pub sim: &'a Simulation,
    /// End time (s).
    pub end_time: f64,
}

/// History column names for a simulation.
pub fn history_columns(sim: &Simulation, reactions: &[(String, Vec<u32>)]) -> Vec<String> {
    let mut cols: Vec<String> = [
        "time",
        "dt",
        "kinetic_energy",
        "internal_energy",
        "hourglass_energy",
        "bulk_viscous_energy",
        "damping_energy",
        "contact_energy",
        "external_work",
        "law_dissipation",
        "energy_error",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    for (name, _) in reactions {
        for d in ["x", "y", "z"] {
            cols.push(format!("{name}_reaction_{d}"));
        }
    }
    for st in &sim.stages {
        cols.extend(st.history_columns());
    }
    cols
}

/// One history row.
pub fn history_row(sim: &Simulation, reactions: &[(String, Vec<u32>)], row: &mut Vec<f64>) {
    let e = &sim.energy;
    row.clear();
    row.extend([
        sim.time,
        sim.dt_prev,
        e.kinetic,
        e.internal,
        e.hourglass,
        e.bulk_viscous,
        e.damping,
        e.contact,
        e.external,
        e.law_dissipation,
        e.error(),
    ]);
    for (_, nodes) in reactions {
        let mut r = [0.0; 3];
        for &n in nodes {
            for d in 0..3 {
                r[d] += sim.reaction[n as usize][d];
            }
        }
        row.extend(r);
    }
    for st in &sim.stages {
        st.history_values(row);
    }
}

fn write_frame(scene: &Scene, series: &mut Series) -> Result<(), String> {
    let sim = &scene.sim;
    let plan = &scene.output;
    let mut frame = Frame {
        displacement: plan.has("displacement").then_some(&sim.u[..]),
        velocity: plan.has("velocity").then_some(&sim.v[..]),
        part: plan.has("part"),
        stress: sim.stress.as_deref(),
        tensor: plan.has("stress"),
        ..Default::default()
    };
    if let Some(s) = &sim.stress {
        if plan.has("von_mises") {
            frame
                .cell_scalars
                .push(("von_mises".into(), s.iter().map(von_mises).collect()));
        }
        if plan.has("max_principal") {
            frame.cell_scalars.push((
                "max_principal_stress".into(),
                s.iter().map(|x| principal(x)[0]).collect(),
            ));
        }
    }
    let mut surfaces = Vec::new();
    for st in &sim.stages {
        frame.point_scalars.extend(st.point_fields());
        surfaces.extend(st.surfaces());
    }
    series
        .write(sim.time, &sim.model.mesh, &frame, &surfaces, &scene.title)
        .map(|_| ())
}

/// The energy figures of the summary, over the history rows: the largest instantaneous error
/// after the first 1 % of the run, and the largest imbalance and energy.
#[derive(Default)]
struct EnergyPeaks {
    error: f64,
    imbalance: f64,
    scale: f64,
}

impl EnergyPeaks {
    fn record(&mut self, sim: &Simulation, end: f64) {
        if sim.time > 0.01 * end {
            self.error = self.error.max(sim.energy.error());
        }
        self.imbalance = self.imbalance.max(sim.energy.imbalance().abs());
        self.scale = self.scale.max(sim.energy.scale());
    }
}

/// Append the probe rows: time, the stages' history values (indenter force, depth, ...), then
/// the maximum principal Cauchy stress (Pa) of each probed element; and the tensors.
fn probe_rows(scene: &Scene, p: &mut History, pt: &mut History, row: &mut Vec<f64>) {
    let sim = &scene.sim;
    let (Some((_, els)), Some(stress)) = (&scene.output.probe, &sim.stress) else {
        return;
    };
    row.clear();
    row.push(sim.time);
    for st in &sim.stages {
        st.history_values(row);
    }
    let head = row.len();
    row.extend(els.iter().map(|&e| principal(&stress[e as usize])[0]));
    p.push(row);
    row.truncate(head);
    for &e in els {
        row.extend(stress[e as usize]);
    }
    pt.push(row);
}

/// The first output time after `t` on the grid `next + k dt` (k = 0, 1, ...), computed in one
/// step rather than by adding `dt` until it passes `t`: a step far longer than the output
/// interval (a huge stable step) would otherwise loop for as many intervals as the step spans,
/// or for ever once `next + dt` rounds back to `next`. Never returns a time at or before `t`
/// when `dt > 0`.
pub fn next_output_time(next: f64, dt: f64, t: f64) -> f64 {
    if dt.is_nan() || dt <= 0.0 || next > t {
        return next;
    }
    let k = ((t - next) / dt).floor() + 1.0;
    let n = next + k * dt;
    if n > t {
        n
    } else if t + dt > t {
        t + dt
    } else {
        t.next_up()
    }
}

/// [`run_scene`] on a worker thread of the global rayon pool (in place when the caller is one
/// already), so that each of the step's parallel loops starts from a worker. Called from
/// outside the pool, every loop hands its job to the pool and puts the calling thread to sleep
/// until the job is done, several times per step (measured in docs/performance.md, "The time
/// loop on a pool worker"). For one run per process, as `palpa palpate` and `palpa run` make:
/// concurrent callers outside any pool would have their whole runs queued on the same workers,
/// so they should each install their own pool, as the campaign does.
pub fn run_scene_on_pool(
    scene: &mut Scene,
    out: &Path,
    stop: &AtomicBool,
    observer: impl FnMut(&Progress) + Send,
) -> (RunSummary, Option<String>) {
    rayon::scope(|_| run_scene(scene, out, stop, observer))
}

/// Run a scene, writing into `out`. `observer` is called every few steps and may update a
/// progress bar. Returns the summary (also on failure, with the error in `status`) and the
/// error if the run failed.
pub fn run_scene(
    scene: &mut Scene,
    out: &Path,
    stop: &AtomicBool,
    observer: impl FnMut(&Progress),
) -> (RunSummary, Option<String>) {
    let t_wall = Instant::now();
    let mut error = None;
    if let Err(e) = std::fs::create_dir_all(out) {
        error = Some(format!(
            "{}: cannot create the output directory: {e}",
            out.display()
        ));
    }
    let mut rec = Recorder::new(scene, out);
    if error.is_none() {
        if let Err(e) = scene.sim.initialise() {
            error = Some(e.to_string());
        }
    }
    let mut status = RunStatus::Completed;
    if error.is_none() {
        match time_loop(scene, &mut rec, stop, observer) {
            Ok(s) => status = s,
            Err(e) => error = Some(e),
        }
    }
    if let Err(e) = rec.history.flush() {
        error.get_or_insert(e);
    }
    if let Some((p, pt)) = &rec.probe {
        if let Err(e) = p.flush().and_then(|_| pt.flush()) {
            error.get_or_insert(e);
        }
    }
    if let Err(e) = rec.series.finish() {
        error.get_or_insert(e);
    }
    if let Some(e) = &error {
        status = RunStatus::Failed(e.clone());
    }
    let summary = summarise(scene, t_wall.elapsed().as_secs_f64(), status, &rec);
    if let Ok(js) = serde_json::to_string_pretty(&summary) {
        if let Err(e) =
            solver::output::atomic::write_atomic(&out.join("summary.json"), js.as_bytes())
        {
            error.get_or_insert(e);
        }
    }
    (summary, error)
}

/// The output files of a run and their clocks: `history.csv`, the VTK frames, the probes.
struct Recorder {
    series: Series,
    history: History,
    /// `probe.csv` and `probe_stress.csv`, when the scene probes elements.
    probe: Option<(History, History)>,
    reactions: Vec<(String, Vec<u32>)>,
    row: Vec<f64>,
    hist_dt: f64,
    vtk_dt: Option<f64>,
    write_vtk: bool,
    next_hist: f64,
    next_vtk: f64,
    peaks: EnergyPeaks,
    last_flush: Instant,
}

impl Recorder {
    fn new(scene: &Scene, out: &Path) -> Recorder {
        let reactions = scene.output.reactions.clone();
        let history = History::new(
            &out.join("history.csv"),
            history_columns(&scene.sim, &reactions),
        );
        let probe = scene.output.probe.as_ref().map(|(_, els)| {
            let mut cols = vec!["time".to_string()];
            for st in &scene.sim.stages {
                cols.extend(st.history_columns());
            }
            let mut tcols = cols.clone();
            cols.extend(els.iter().map(|e| format!("e{e}")));
            for e in els {
                for c in ["xx", "yy", "zz", "xy", "yz", "zx"] {
                    tcols.push(format!("e{e}_{c}"));
                }
            }
            (
                History::new(&out.join("probe.csv"), cols),
                History::new(&out.join("probe_stress.csv"), tcols),
            )
        });
        Recorder {
            series: Series::new(out, "frame"),
            history,
            probe,
            reactions,
            row: Vec::new(),
            hist_dt: scene.output.history_interval.max(0.0),
            vtk_dt: scene.output.frame_interval,
            write_vtk: scene.output.vtk_interval.is_some(),
            next_hist: 0.0,
            next_vtk: 0.0,
            peaks: EnergyPeaks::default(),
            last_flush: Instant::now(),
        }
    }

    /// Append the history row, and write a frame and the probe rows, when their clocks are due
    /// (or `done`: the last state). An error names the file that could not be written.
    fn sample(&mut self, scene: &Scene, done: bool) -> Result<(), String> {
        let sim = &scene.sim;
        let t = sim.time;
        if t >= self.next_hist || done {
            history_row(sim, &self.reactions, &mut self.row);
            self.history.push(&self.row);
            self.next_hist = next_output_time(self.next_hist + self.hist_dt, self.hist_dt, t);
            self.peaks.record(sim, scene.end_time);
        }
        let Some(vdt) = self.vtk_dt else {
            return Ok(());
        };
        if t >= self.next_vtk * (1.0 - 1e-12) || done {
            if let Some((p, pt)) = self.probe.as_mut() {
                probe_rows(scene, p, pt, &mut self.row);
            }
            if self.write_vtk {
                write_frame(scene, &mut self.series)?;
            }
            self.history.flush()?;
            if let Some((p, pt)) = &self.probe {
                p.flush().and_then(|_| pt.flush())?;
            }
            self.last_flush = Instant::now();
            self.next_vtk = next_output_time(self.next_vtk + vdt, vdt, t);
        }
        Ok(())
    }

    /// The last history row (and frame) of a run that converged.
    fn converged(&mut self, scene: &Scene) -> Result<(), String> {
        history_row(&scene.sim, &self.reactions, &mut self.row);
        self.history.push(&self.row);
        if self.write_vtk {
            write_frame(scene, &mut self.series)?;
        }
        Ok(())
    }

    /// The history row of the state that went unstable.
    fn unstable(&mut self, scene: &Scene) {
        history_row(&scene.sim, &self.reactions, &mut self.row);
        self.history.push(&self.row);
        self.peaks.record(&scene.sim, scene.end_time);
    }

    /// Flush `history.csv` if it was last flushed more than 10 s ago.
    fn flush_now_and_then(&mut self) {
        if self.last_flush.elapsed().as_secs_f64() > 10.0 {
            let _ = self.history.flush();
            self.last_flush = Instant::now();
        }
    }
}

/// Step the scene to its end time (or convergence, or a stop request), sampling the output.
fn time_loop(
    scene: &mut Scene,
    rec: &mut Recorder,
    stop: &AtomicBool,
    mut observer: impl FnMut(&Progress),
) -> Result<RunStatus, String> {
    let end = scene.end_time;
    loop {
        let done = scene.sim.time >= end * (1.0 - 1e-12);
        rec.sample(scene, done)?;
        if done {
            return Ok(RunStatus::Completed);
        }
        if let Some(r) = scene.sim.settings.relaxation {
            if scene.sim.step > 10 && scene.sim.residual < r.tolerance {
                rec.converged(scene)?;
                return Ok(RunStatus::Converged);
            }
        }
        if stop.load(Ordering::Relaxed) {
            return Ok(RunStatus::Stopped);
        }
        let stress_at = rec
            .vtk_dt
            .map(|_| rec.next_vtk * (1.0 - 1e-12))
            .unwrap_or(f64::INFINITY)
            .min(end * (1.0 - 1e-12));
        if let Err(e) = scene.sim.step(stress_at) {
            if let SolverError::Unstable(_) = e {
                // the history ends with the state that went unstable
                rec.unstable(scene);
            }
            return Err(format!("{}: {e}", scene.path.display()));
        }
        if scene.sim.step % 64 == 0 {
            observer(&Progress {
                sim: &scene.sim,
                end_time: end,
            });
            rec.flush_now_and_then();
        }
    }
}

/// Where the wall time went: each timed stage, then output and bookkeeping (the rest).
fn stage_times(sim: &Simulation, wall: f64) -> Vec<StageShare> {
    let total_stage: f64 = sim.timers.iter().map(|s| s.time.as_secs_f64()).sum();
    let mut stage_times: Vec<StageShare> = sim
        .timers
        .iter()
        .filter(|s| !s.time.is_zero())
        .map(|s| StageShare {
            stage: s.name.to_string(),
            seconds: s.time.as_secs_f64(),
            share: s.time.as_secs_f64() / wall,
        })
        .collect();
    stage_times.push(StageShare {
        stage: "output and bookkeeping".into(),
        seconds: (wall - total_stage).max(0.0),
        share: (wall - total_stage).max(0.0) / wall,
    });
    stage_times
}

/// The run summary of `scene` after `wall` seconds.
fn summarise(scene: &Scene, wall: f64, status: RunStatus, rec: &Recorder) -> RunSummary {
    let sim = &scene.sim;
    let peaks = &rec.peaks;
    let stage_times = stage_times(sim, wall);
    let e = &sim.energy;
    let hourglass = HourglassReport::of(sim);
    RunSummary {
        title: scene.title.clone(),
        status,
        time: sim.time,
        steps: sim.step,
        elements: sim.model.mesh.elements.len(),
        nodes: sim.model.mesh.nodes.len(),
        wall_seconds: wall,
        element_cycles_per_second: sim.model.mesh.elements.len() as f64 * sim.step as f64
            / wall.max(1e-12),
        subcycling: sim.subcycling.as_ref().map(|s| SubcyclingReport {
            ratio: s.k,
            parts: s.parts.clone(),
            slow_nodes: s.slow_nodes.len(),
            saved_fraction: s.saved as f64
                / (sim.model.mesh.elements.len() as f64 * sim.step.max(1) as f64),
            slow_bound_steps: s.slow_bound_steps,
        }),
        global_step: sim.global_step.as_ref().map(|g| GlobalStepSummary {
            estimates: g.report.estimates,
            iterations: g.report.iterations,
            ratio_min: g.report.ratio.0,
            ratio_max: g.report.ratio.1,
            seconds: g.report.seconds,
        }),
        dt_min: sim.dt_range.0,
        dt_max: sim.dt_range.1,
        energy_error: e.error(),
        max_energy_error: if peaks.scale > 0.0 {
            peaks.imbalance / peaks.scale
        } else {
            0.0
        },
        max_instant_energy_error: peaks.error,
        kinetic_energy: e.kinetic,
        internal_energy: e.internal,
        hourglass_energy: e.hourglass,
        external_work: e.external,
        precision: sim.settings.precision.label().into(),
        active_stages: sim.active_stages(),
        stage_times,
        mass: sim
            .model
            .part_mass
            .iter()
            .map(|p| PartMassReport {
                part: p.name.clone(),
                physical_kg: p.physical,
                added_kg: p.added,
                added_percent: 100.0 * p.added_fraction(),
            })
            .collect(),
        bulk_modulus: scene
            .setup
            .parts
            .iter()
            .filter_map(|p| p.bulk.clone())
            .collect(),
        warnings: energy_warnings(e.internal, e.hourglass, &hourglass)
            .into_iter()
            .chain(sim.subcycling_off.as_ref().map(|why| {
                format!(
                    "subcycling was asked for (run.subcycling = {}) but not used: {why}",
                    sim.settings.subcycling
                )
            }))
            .chain(
                sim.subcycling
                    .as_ref()
                    .filter(|s| s.slow_bound_steps > 0)
                    .map(|s| {
                        format!(
                            "subcycling: an element of a subcycled part set the step in {} of {} steps (its own step over {}): those steps were shorter than without subcycling; a smaller run.subcycling may be faster",
                            s.slow_bound_steps, sim.step, s.k
                        )
                    }),
            )
            .collect(),
        hourglass,
        threads: rayon::current_num_threads(),
        frames: rec.series.len(),
        eroded_elements: sim.erosion.count,
        first_eroded: sim.erosion.first.map(|(element, time)| ErodedElement {
            element,
            part: sim.part_of(element),
            time,
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn run_status_reads_back_what_it_writes() {
        for st in [
            RunStatus::Completed,
            RunStatus::Converged,
            RunStatus::Stopped,
            RunStatus::Failed("scene.toml: element 7 inverted at t = 1.2 ms".into()),
        ] {
            let js = serde_json::to_string(&st).unwrap();
            assert_eq!(serde_json::from_str::<RunStatus>(&js).unwrap(), st, "{js}");
        }
        assert_eq!(
            serde_json::to_string(&RunStatus::Failed("x".into())).unwrap(),
            "\"failed: x\""
        );
        assert!("done".parse::<RunStatus>().is_err());
    }

    #[test]
    fn hourglass_energy_above_a_tenth_of_the_internal_energy_is_warned_about() {
        let hg = HourglassReport {
            by_part: vec![PartEnergy {
                part: "flesh".into(),
                energy_j: 0.18,
            }],
            peak: Some(HourglassElement {
                element: 42,
                part: "flesh".into(),
                energy_j: 1e-4,
                time: 0.01,
            }),
        };
        assert!(energy_warnings(1.0, 0.1, &hg).is_empty());
        let w = energy_warnings(1.0, 0.24, &hg);
        assert_eq!(w.len(), 1);
        assert!(
            w[0].contains("24.0 %")
                && w[0].contains("physical")
                && w[0].contains("part `flesh` holds 75 %")
                && w[0].contains("element 42"),
            "{}",
            w[0]
        );
        assert!(energy_warnings(0.0, 0.5, &hg).is_empty());
    }
}
