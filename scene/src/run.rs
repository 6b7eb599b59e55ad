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
    /// How the run ended: `completed`, `converged`, `stopped` or the error.
    pub status: String,
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

/// Run a scene, writing into `out`. `observer` is called every few steps and may update a
/// progress bar. Returns the summary (also on failure, with the error in `status`) and the
/// error if the run failed.
pub fn run_scene(
    scene: &mut Scene,
    out: &Path,
    stop: &AtomicBool,
    mut observer: impl FnMut(&Progress),
) -> (RunSummary, Option<String>) {
    let t_wall = Instant::now();
    let mut error = None;
    let mut status = "completed".to_string();
    if let Err(e) = std::fs::create_dir_all(out) {
        error = Some(format!(
            "{}: cannot create the output directory: {e}",
            out.display()
        ));
    }
    let stem = "frame";
    let mut series = Series::new(out, stem);
    let reactions = scene.output.reactions.clone();
    let mut history = History::new(
        &out.join("history.csv"),
        history_columns(&scene.sim, &reactions),
    );
    let mut row = Vec::new();
    let end = scene.end_time;
    let hist_dt = scene.output.history_interval.max(0.0);
    let vtk_dt = scene.output.frame_interval;
    let write_vtk = scene.output.vtk_interval.is_some();
    let mut probe = scene.output.probe.as_ref().map(|(_, els)| {
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
    let mut next_hist = 0.0;
    let mut next_vtk = 0.0;
    let mut peaks = EnergyPeaks::default();
    let mut last_flush = Instant::now();
    if error.is_none() {
        if let Err(e) = scene.sim.initialise() {
            error = Some(e.to_string());
        }
    }
    while error.is_none() {
        let sim = &scene.sim;
        let t = sim.time;
        let done = t >= end * (1.0 - 1e-12);
        if t >= next_hist || done {
            history_row(sim, &reactions, &mut row);
            history.push(&row);
            next_hist = next_output_time(next_hist + hist_dt, hist_dt, t);
            peaks.record(sim, end);
        }
        if let Some(vdt) = vtk_dt {
            if t >= next_vtk * (1.0 - 1e-12) || done {
                if let Some((p, pt)) = probe.as_mut() {
                    probe_rows(scene, p, pt, &mut row);
                }
                let written = if write_vtk {
                    write_frame(scene, &mut series)
                } else {
                    Ok(())
                };
                if let Err(e) = written
                    .and_then(|_| history.flush())
                    .and_then(|_| match &probe {
                        Some((p, pt)) => p.flush().and_then(|_| pt.flush()),
                        None => Ok(()),
                    })
                {
                    error = Some(e);
                    break;
                }
                last_flush = Instant::now();
                next_vtk = next_output_time(next_vtk + vdt, vdt, t);
            }
        }
        if done {
            break;
        }
        if let Some(r) = scene.sim.settings.relaxation {
            if scene.sim.step > 10 && scene.sim.residual < r.tolerance {
                status = "converged".into();
                history_row(&scene.sim, &reactions, &mut row);
                history.push(&row);
                if write_vtk {
                    let _ = write_frame(scene, &mut series);
                }
                break;
            }
        }
        if stop.load(Ordering::Relaxed) {
            status = "stopped".into();
            break;
        }
        let stress_at = vtk_dt
            .map(|_| next_vtk * (1.0 - 1e-12))
            .unwrap_or(f64::INFINITY)
            .min(end * (1.0 - 1e-12));
        if let Err(e) = scene.sim.step(stress_at) {
            if let SolverError::Unstable(_) = e {
                // the history ends with the state that went unstable
                history_row(&scene.sim, &reactions, &mut row);
                history.push(&row);
                peaks.record(&scene.sim, end);
            }
            error = Some(format!("{}: {e}", scene.path.display()));
            break;
        }
        if scene.sim.step % 64 == 0 {
            observer(&Progress {
                sim: &scene.sim,
                end_time: end,
            });
            if last_flush.elapsed().as_secs_f64() > 10.0 {
                let _ = history.flush();
                last_flush = Instant::now();
            }
        }
    }
    if let Err(e) = history.flush() {
        error.get_or_insert(e);
    }
    if let Some((p, pt)) = &probe {
        if let Err(e) = p.flush().and_then(|_| pt.flush()) {
            error.get_or_insert(e);
        }
    }
    if let Some(e) = &error {
        status = format!("failed: {e}");
    }
    let sim = &scene.sim;
    let wall = t_wall.elapsed().as_secs_f64();
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
    let e = &sim.energy;
    let hourglass = HourglassReport::of(sim);
    let summary = RunSummary {
        title: scene.title.clone(),
        status,
        time: sim.time,
        steps: sim.step,
        elements: sim.model.mesh.elements.len(),
        nodes: sim.model.mesh.nodes.len(),
        wall_seconds: wall,
        element_cycles_per_second: sim.model.mesh.elements.len() as f64 * sim.step as f64
            / wall.max(1e-12),
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
                added_percent: 100.0 * p.added / p.physical.max(1e-300),
            })
            .collect(),
        bulk_modulus: scene
            .setup
            .parts
            .iter()
            .filter_map(|p| p.bulk.clone())
            .collect(),
        warnings: energy_warnings(e.internal, e.hourglass, &hourglass),
        hourglass,
        threads: rayon::current_num_threads(),
        frames: series.len(),
        eroded_elements: sim.erosion.count,
        first_eroded: sim.erosion.first.map(|(element, time)| ErodedElement {
            element,
            part: sim.part_of(element),
            time,
        }),
    };
    if let Ok(js) = serde_json::to_string_pretty(&summary) {
        if let Err(e) =
            solver::output::atomic::write_atomic(&out.join("summary.json"), js.as_bytes())
        {
            error.get_or_insert(e);
        }
    }
    (summary, error)
}

#[cfg(test)]
mod tests {
    use super::*;

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
