//! A pilot run for `palpa check`: how many steps a run will take once its elements shrink.
//!
//! The stable step of an explicit run is `dt = f min_e L_e / c_e` (f the step factor, `L_e` an
//! element's characteristic length, `c_e` its dilatational wave speed,
//! `c = sqrt((K + 4G/3) / rho)`). At the start every element has its reference shape, and
//! `check` can estimate the steps as `end_time / dt_0`. A press crushes the elements under the
//! indenter: in `scenes/finger-press.toml` the step the run takes falls from 2.02e-6 s to 5.87e-7 s
//! (to 0.29 of its start) as the fingers sink 15 mm into the 40 mm block, and the run takes 31,537 steps where the starting step predicts 13,903.
//!
//! The pilot runs the same scene with every part's bulk modulus capped at
//! [`PILOT_BULK_RATIO`] times its shear modulus (the scene's own `max_bulk_ratio` knob). For the
//! paper's flesh (K/G = 5e4) the Poisson ratio goes from 0.49999 to 0.4999, the deformation stays
//! nearly the same, and the wave speed, so the number of steps, falls about threefold. At 200
//! evenly spaced times the pilot's shapes give the ratio `r(t) = dt(t) / dt(0)` of the run's
//! element step to its start ([`isochoric_step_at`]: each element's length `V / A_max` at its
//! reference volume, since the run's elements keep theirs, with the run's initial wave speed).
//! The run's step is then `dt(t) = min(r(t) dt_0, dt_max)` and its step count
//!
//! ```text
//! N = sum over pilot steps i of  dt_pilot,i / min(r(t_i) dt_0, dt_max)
//! ```
//!
//! (`r` interpolated linearly between samples). Measured on finger-press (run: 31,537 steps):
//! with the cap at 5e4, the pilot is the run itself and the estimate reads 30,682 (-2.7 %); at
//! 5,000 it reads 34,488 (+9.4 %) after 11,209 pilot steps; at 500 it reads 46,173 (+46 %): the
//! elements under the fingers then distort visibly more (the step ratio falls to 0.15 where the
//! run's falls to 0.27), so the cap stops at 5,000. (The step ratios here are the element shapes' (0.27 for the run
//! itself): the step the run takes also carries the wave speed's small changes.) The pilot does
//! not follow a stage's own step limit (contact's `max_dt`), nor elements the pilot erodes. Raising the capped parts' P-wave-scaled
//! hourglass resistance back to the run's did not help (62,450 at 500, 33,996 at 5,000).
//!
//! The cap is not applied to piecewise-linear plasticity (its hardening is given through its
//! Young's modulus), so a part of it sets the pilot's step as it sets the run's. A scene with
//! mass scaling or dynamic relaxation keeps the starting estimate: mass scaling holds the step
//! at its target, and relaxation steps in fictitious time.

use super::build::build_scene_with;
use super::def::Scene;
use super::spec::SceneSpec;
use material::quantity::Number;
use material::Material;
use solver::model::isochoric_step_at;
use std::path::Path;
use std::time::{Duration, Instant};

/// The K/G cap of the pilot's parts (Poisson ratio 0.4999).
pub const PILOT_BULK_RATIO: f64 = 5000.0;

/// What a pilot found.
#[derive(Clone, Debug)]
pub struct PilotEstimate {
    /// Steps the full run is estimated to take.
    pub steps: f64,
    /// Steps the pilot took.
    pub pilot_steps: u64,
    /// The smallest step ratio `r(t)` met: how far the elements shrank.
    pub min_ratio: f64,
    /// The time the pilot reached (s): the end time unless it stopped.
    pub reached: f64,
    /// Why it stopped early, if it did (the run may stop there too, or the cap let it go
    /// further than the run will).
    pub stopped: Option<String>,
    /// Wall time of the pilot.
    pub wall: Duration,
}

/// Why a scene gets no pilot, or the pilot scene with its estimated cost.
pub enum PilotPlan {
    /// The starting step is the estimate (the reason).
    NotNeeded(String),
    /// The pilot scene, its estimated steps at its own starting step, and the parts it capped.
    Ready {
        /// The scene with capped bulk moduli.
        scene: Box<Scene>,
        /// Its element-cycles at its starting step.
        element_cycles: f64,
        /// The parts whose bulk modulus the pilot capped.
        capped: Vec<String>,
    },
}

/// Build the pilot of the scene file `path`, given the scene as built for the run.
pub fn plan(path: &Path, real: &Scene) -> Result<PilotPlan, String> {
    let m = &real.sim.model;
    if m.mass_scaling.is_some() || m.added_mass() > 0.0 {
        return Ok(PilotPlan::NotNeeded(
            "mass scaling holds the step at its target".into(),
        ));
    }
    if real.sim.settings.relaxation.is_some() {
        return Ok(PilotPlan::NotNeeded(
            "dynamic relaxation steps in fictitious time".into(),
        ));
    }
    let src = std::fs::read_to_string(path)
        .map_err(|e| format!("{}: cannot read the scene file: {e}", path.display()))?;
    let mut spec: SceneSpec =
        toml::from_str(&src).map_err(|e| material::toml_error::describe(path, &src, &e))?;
    let mut capped = Vec::new();
    for ps in spec.parts.iter_mut() {
        let Some(part) = m.parts.iter().find(|p| p.name == ps.name) else {
            continue;
        };
        let law = &part.material;
        let ratio = law.bulk_modulus() / law.initial_shear_modulus();
        if ps.max_bulk_ratio.is_none()
            && ps.bulk_modulus.is_none()
            && !matches!(law, Material::PiecewiseLinearPlasticity(_))
            && ratio > PILOT_BULK_RATIO
        {
            ps.max_bulk_ratio = Some(Number(PILOT_BULK_RATIO));
            capped.push(ps.name.clone());
        }
    }
    if capped.is_empty() {
        return Ok(PilotPlan::NotNeeded(format!(
            "no part has K/G above {PILOT_BULK_RATIO} that a pilot could lower"
        )));
    }
    let scene = build_scene_with(spec, path, &src, None)?;
    let pm = &scene.sim.model;
    let dt0 = scene.sim.settings.dt_factor * pm.initial_dt.0;
    let element_cycles = real.end_time / dt0 * pm.mesh.elements.len() as f64;
    Ok(PilotPlan::Ready {
        scene: Box::new(scene),
        element_cycles,
        capped,
    })
}

/// Where along the run the pilot's shapes are measured.
const SAMPLES: usize = 200;

/// Run the pilot to the end time and estimate the steps of `real`. At `SAMPLES` evenly
/// spaced times the pilot's shapes are measured with
/// [`solver::model::isochoric_step_at`]: each element's length at its
/// reference volume and the run's initial wave speed. The run's laws are not evaluated there:
/// on the pilot's few per cent of volume change they would give the run's bulk modulus a
/// pressure it never sees.
pub fn run(mut pilot: Scene, real: &Scene) -> PilotEstimate {
    let t0 = Instant::now();
    let f = real.sim.settings.dt_factor;
    let dt_max = real.sim.settings.dt_max;
    let end = real.end_time;
    let rm = &real.sim.model;
    let sim = &mut pilot.sim;
    let mut steps_taken: Vec<(f64, f64)> = Vec::new(); // (mid time, dt)
    let mut samples: Vec<(f64, f64)> = Vec::new(); // (time, isochoric step)
    let mut stopped = None;
    let sample = |sim: &solver::simulation::Simulation| {
        (sim.time, isochoric_step_at(&rm.mesh, &rm.parts, &sim.u))
    };
    samples.push(sample(sim));
    let mut next_sample = end / SAMPLES as f64;
    while sim.time < end {
        let before = sim.time;
        if let Err(e) = sim.step(f64::INFINITY) {
            stopped = Some(e.to_string());
            break;
        }
        steps_taken.push((0.5 * (before + sim.time), sim.dt_prev));
        if sim.time >= next_sample || sim.time >= end {
            samples.push(sample(sim));
            while next_sample <= sim.time {
                next_sample += end / SAMPLES as f64;
            }
        }
    }
    let dt_crit0 = samples[0].1;
    let real_dt0 = f * real.sim.model.initial_dt.0;
    let ratio_at = |t: f64| -> f64 {
        let k = samples.partition_point(|s| s.0 <= t);
        let r = |i: usize| samples[i].1 / dt_crit0;
        if k == 0 {
            1.0
        } else if k == samples.len() {
            r(k - 1)
        } else {
            let (a, b) = (samples[k - 1], samples[k]);
            let w = (t - a.0) / (b.0 - a.0);
            (1.0 - w) * r(k - 1) + w * r(k)
        }
    };
    let steps = steps_taken
        .iter()
        .map(|&(t, dt)| dt / (ratio_at(t) * real_dt0).min(dt_max))
        .sum();
    let min_ratio = samples.iter().map(|s| s.1 / dt_crit0).fold(1.0, f64::min);
    PilotEstimate {
        steps,
        pilot_steps: sim.step,
        min_ratio,
        reached: sim.time,
        stopped,
        wall: t0.elapsed(),
    }
}
