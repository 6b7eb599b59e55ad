//! The scene's run control and loop settings: end time, time-step factor and kernel precision
//! (`[run]`), bulk viscosity, mass scaling, damping, gravity, dynamic relaxation and the
//! hourglass guard.

use super::def::HourglassGuard;
use super::locate::Locate;
use super::spec::{RunSpec, SceneSpec};
use solver::element::precision::Precision;
use solver::element::BulkViscosity;
use solver::model::MassScaling;
use solver::simulation::DynamicRelaxation;
use solver::simulation::StepEstimate;

/// `[run]`'s end time (s), time-step factor and kernel precision, checked.
pub(crate) fn run_control(run: &RunSpec, at: Locate) -> Result<(f64, f64, Precision), String> {
    let end_time = run.end_time.0;
    if !(end_time > 0.0) {
        return Err(at.err("run.end_time", Some("end_time"), &"must be positive"));
    }
    if !end_time.is_finite() {
        return Err(at.err(
            "run.end_time",
            Some("end_time"),
            &format!("must be finite, got {end_time}"),
        ));
    }
    let dt_factor = run
        .dt_factor
        .map(|x| x.0)
        .unwrap_or(solver::simulation::DEFAULT_DT_FACTOR);
    if !(dt_factor > 0.0 && dt_factor <= 1.0) {
        return Err(at.err(
            "run.dt_factor",
            Some("dt_factor"),
            &format!("must lie in (0, 1], got {dt_factor}"),
        ));
    }
    let precision = match &run.precision {
        None => Precision::F64,
        Some(p) => {
            Precision::parse(p).map_err(|m| at.err("run.precision", Some("precision"), &m))?
        }
    };
    Ok((end_time, dt_factor, precision))
}

/// The loop settings besides the time step.
pub(crate) struct Settings {
    pub bulk: Option<BulkViscosity>,
    pub mass_scaling: Option<MassScaling>,
    pub damping: Option<f64>,
    pub gravity: Option<[f64; 3]>,
    pub relaxation: Option<DynamicRelaxation>,
    pub hourglass_guard: Option<HourglassGuard>,
}

/// Bulk viscosity (on by default), mass scaling, damping, gravity, relaxation and the
/// hourglass guard of a scene.
pub(crate) fn settings(spec: &SceneSpec, at: Locate) -> Result<Settings, String> {
    let bulk = match &spec.bulk_viscosity {
        Some(b) if b.enabled == Some(false) => None,
        Some(b) => {
            let quadratic = b.quadratic.map(|x| x.0).unwrap_or(1.5);
            let linear = b.linear.map(|x| x.0).unwrap_or(0.06);
            for (key, v) in [("quadratic", quadratic), ("linear", linear)] {
                if !(v >= 0.0 && v.is_finite()) {
                    return Err(at.err(
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
                at.path.display(),
                r.0
            ))
        }
        Some(r) => Some(HourglassGuard {
            ratio: r.0,
            after: spec.run.hourglass_check_after.map(|t| t.0),
        }),
        None => None,
    };
    Ok(Settings {
        bulk,
        mass_scaling,
        damping,
        gravity,
        relaxation,
        hourglass_guard,
    })
}

/// `[run] subcycling`: the most steps a slow part's interior may take as one (a power of two
/// from 1, off, to 1024; [`solver::subcycle`]).
pub(crate) fn subcycling(run: &RunSpec, at: Locate) -> Result<u32, String> {
    match run.subcycling.map(|x| x.0) {
        None => Ok(1),
        Some(k)
            if (1.0..=1024.0).contains(&k) && k.fract() == 0.0 && (k as u32).is_power_of_two() =>
        {
            Ok(k as u32)
        }
        Some(k) => Err(at.err(
            "run.subcycling",
            Some("subcycling"),
            &format!("must be a power of two from 1 (off) to 1024, got {k}"),
        )),
    }
}

/// `[run] step_estimate`: `"element"` (default) or `"global"` ([`solver::global_step`]).
pub(crate) fn step_estimate(run: &RunSpec, at: Locate) -> Result<StepEstimate, String> {
    match &run.step_estimate {
        None => Ok(StepEstimate::Element),
        Some(s) => StepEstimate::parse(s)
            .map_err(|m| at.err("run.step_estimate", Some("step_estimate"), &m)),
    }
}

/// `[run] max_steps`, checked.
pub(crate) fn max_steps(run: &RunSpec, at: Locate) -> Result<Option<f64>, String> {
    Ok(match run.max_steps.map(|x| x.0) {
        None => None,
        Some(m) if m >= 1.0 && m.is_finite() => Some(m),
        Some(m) => {
            return Err(at.err(
                "run.max_steps",
                Some("max_steps"),
                &format!("must be a positive finite count, got {m}"),
            ))
        }
    })
}
