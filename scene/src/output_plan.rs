//! The scene's output plan (`[output]`): VTK fields and interval, history rows, reactions on
//! node sets, the probe element set, and the limit on how many rows and frames a run may write.

use super::def::OutputPlan;
use super::locate::Locate;
use super::node_sets::node_set;
use super::spec::OutputSpec;
use solver::mesh::Mesh;

/// The fields a VTK frame can carry (`[output] fields`, which also takes `history`).
pub const VTK_FIELDS: [&str; 6] = [
    "displacement",
    "velocity",
    "part",
    "stress",
    "von_mises",
    "max_principal",
];

/// The most history rows, or frames, a scene may ask for unless `[output] max_outputs` raises
/// the limit.
pub const DEFAULT_MAX_OUTPUTS: f64 = 1e6;

/// The output plan of `[output]` for a run of `end_time` seconds.
pub(crate) fn output_plan(
    out: &OutputSpec,
    end_time: f64,
    mesh: &Mesh,
    at: Locate,
) -> Result<OutputPlan, String> {
    let known: Vec<&str> = VTK_FIELDS.iter().copied().chain(["history"]).collect();
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
            return Err(at.err(
                "output.fields",
                Some(&format!("\"{f}\"")),
                &format!("unknown field `{f}`; known: {known:?}"),
            ));
        }
    }
    let mut reactions = Vec::new();
    for r in out.reactions.clone().unwrap_or_default() {
        let nodes = node_set(mesh, at, &r, "output.reactions")?;
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
        return Err(at.err(
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
            return Err(at.err(
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
            at.err(
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
                at.err(
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
        return Err(at.err("output.interval", Some("interval"), &"must be positive"));
    }
    if let Some(m) = too_many("output.interval", "interval", "frames", frame_interval) {
        return Err(m);
    }
    Ok(OutputPlan {
        vtk_interval,
        frame_interval: (vtk_interval.is_some() || probe.is_some()).then_some(frame_interval),
        history_interval,
        fields,
        reactions,
        probe,
    })
}
