//! `palpa predict MODEL --x X --y Y --force F [--png map.png]` and `palpa predict MODEL --stdin`:
//! serve a saved surrogate.
//!
//! Inputs are SI: the finger position x, y in metres (the dataset's frame) and the contact force
//! in newtons, and for a model trained on a respiratory campaign the phase (`--phase`, 0
//! exhalation .. 1 inspiration; 0 when not given); outputs are the maximum principal stress of
//! each ROI element in pascals. The `--png` picture draws the liver at the view's phase.
//!
//! - One-shot: prints the ROI stress vector (one `element_id stress_Pa` line per ROI element,
//!   after a header), the GP's predictive standard deviation when the model is a GP, what about
//!   the input lies outside the model's training (outside the body, the training locations'
//!   hull or force range, a large deviation), and with `--png` renders the picture of the ROI
//!   stress ([`surrogate::render_picture`]): in plan view with the outlines of `view.json`
//!   beside the model, the fingers, a title with x, y and the force, and a fixed colour scale
//!   over the training stress range (the live view's, `palpa serve`).
//! - `--stdin`, for a live device loop: reads one JSON object per line,
//!   `{"x": 0.04, "y": 0.05, "force": 20.0}` (an optional `"phase"`, and an optional `"id"` of
//!   any JSON type echoed back),
//!   and writes one JSON line per input line, flushed at once:
//!   `{"line": 1, "stress": [...], "variance": null}` (`variance` [Pa^2] for a GP: the latent
//!   variance shared by its raw outputs, on the tensor target by every stress component). A line that
//!   cannot be used (malformed JSON, invalid UTF-8, a non-finite prediction from a damaged
//!   model) gets `{"line": N, "error": "..."}` and the stream goes on; blank lines are
//!   skipped. A closed stdout (the reader has gone) ends the stream quietly. The model is
//!   loaded once ([`surrogate::Predictor`], the hand-written forward pass).

use super::predict_line::{check_finite, check_phase, parse_input_line};
use serde_json::{json, Map, Value};
use std::fmt::Write as _;
use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};
use surrogate::model::model_paths;
use surrogate::{Predictor, ServedModel};

/// `palpa predict`'s arguments. Units are SI: x and y in metres, force in newtons, stress out
/// in pascals.
#[derive(clap::Args)]
pub struct PredictArgs {
    /// The model `palpa train --out` saved: a directory (model.safetensors + model.json) or
    /// NAME.safetensors / NAME.json.
    pub model: PathBuf,
    /// Finger position x [m], in the dataset's frame (a plain number, e.g. 0.04).
    #[arg(long, allow_negative_numbers = true, required_unless_present = "stdin")]
    pub x: Option<f64>,
    /// Finger position y [m], in the dataset's frame (a plain number, e.g. 0.05).
    #[arg(long, allow_negative_numbers = true, required_unless_present = "stdin")]
    pub y: Option<f64>,
    /// Contact force [N] (a plain number, e.g. 20).
    #[arg(long, allow_negative_numbers = true, required_unless_present = "stdin")]
    pub force: Option<f64>,
    /// Respiratory phase, 0 (exhalation) .. 1 (inspiration), for a model trained on a
    /// respiratory campaign (its inputs end in `phase`); refused for one that takes x, y and
    /// force only.
    #[arg(long, allow_negative_numbers = true)]
    pub phase: Option<f64>,
    /// Also render the 2-D map of the ROI stress (x-y projection of the ROI centroids) to this
    /// PNG file.
    #[arg(long)]
    pub png: Option<PathBuf>,
    /// Stream instead: read JSON lines {"x": m, "y": m, "force": N, "phase": optional, "id":
    /// optional} from stdin,
    /// write one JSON line per input, {"line": n, "id": .., "stress": [Pa, ...], "variance":
    /// Pa^2 or null (a GP's latent variance; on the tensor target, of each stress component)},
    /// flushed at once; a bad line gets {"line": n, "error": ".."} and the stream goes on.
    #[arg(long, conflicts_with_all = ["x", "y", "force", "phase", "png"])]
    pub stdin: bool,
}

/// Run `palpa predict`.
pub fn predict(a: &PredictArgs) -> Result<(), String> {
    match (a.stdin, a.x, a.y, a.force) {
        (true, ..) => predict_stdin(&a.model),
        (false, Some(x), Some(y), Some(force)) => {
            predict_one(&a.model, [x, y, force], a.phase, a.png.as_deref())
        }
        _ => Err("give --x, --y and --force, or --stdin".into()),
    }
}

/// A model path that does not exist gets a message naming it and saying what is expected.
fn check_model_path(path: &Path) -> Result<(), String> {
    let (st, js) = model_paths(path);
    if !path.exists() && !st.exists() && !js.exists() {
        return Err(format!(
            "model {}: no such file or directory (expected a directory holding \
             model.safetensors and model.json, or NAME.safetensors beside NAME.json, as \
             `palpa train --out` writes)",
            path.display()
        ));
    }
    Ok(())
}

/// Loads the model at `path` (see [`check_model_path`]).
pub fn load_model(path: &Path) -> Result<Predictor, String> {
    check_model_path(path)?;
    Predictor::load(path).map_err(|e| format!("model {}: {e}", path.display()))
}

/// Loads the model at `path` with its plan geometry and training domain.
pub fn load_served(path: &Path) -> Result<ServedModel, String> {
    check_model_path(path)?;
    ServedModel::load(path).map_err(|e| format!("model {}: {e}", path.display()))
}

/// A prediction with a NaN or infinite stress or variance (a damaged model) is an error, not
/// an answer.
fn non_finite_output(stress: &[f64], variance: Option<f64>) -> Result<(), String> {
    if let Some(i) = stress.iter().position(|v| !v.is_finite()) {
        return Err(format!(
            "the model predicts a non-finite stress ({}) for ROI output {i}: the model file is damaged",
            stress[i]
        ));
    }
    match variance {
        Some(v) if !(v.is_finite() && v >= 0.0) => Err(format!(
            "the model predicts a variance of {v}: the model file is damaged"
        )),
        _ => Ok(()),
    }
}

/// Set a model's respiratory phase (0, the paper's frame, when not given: a `--stdin` line
/// without `"phase"` does not inherit the line before's); a phase given to a model without a
/// phase input is refused, naming the model.
fn apply_phase(
    p: &mut surrogate::Predictor,
    phase: Option<f64>,
    model: &Path,
) -> Result<(), String> {
    let Some(v) = phase else {
        p.set_phase(0.0);
        return Ok(());
    };
    let v = check_phase(v)?;
    if !p.takes_phase() {
        return Err(format!(
            "model {}: it takes x, y and force only (trained without a respiratory phase); a phase needs a model trained on a respiratory campaign",
            model.display()
        ));
    }
    p.set_phase(v);
    Ok(())
}

/// One-shot prediction: print the vector, optionally render the map.
pub fn predict_one(
    model: &Path,
    [x, y, force]: [f64; 3],
    phase: Option<f64>,
    png: Option<&Path>,
) -> Result<(), String> {
    let x = check_finite("--x", x)?;
    let y = check_finite("--y", y)?;
    let force = check_finite("--force", force)?;
    let mut served = load_served(model)?;
    apply_phase(&mut served.predictor, phase, model)?;
    let meta = served.predictor.meta().clone();
    let prediction = served.predict(x, y, force);
    let stress = &prediction.stress;
    non_finite_output(stress, None).map_err(|e| format!("model {}: {e}", model.display()))?;
    let mut text = format!(
        "{} model {} on the {} target ({}): {} ROI elements\nfinger at x = {x} m, y = {y} m, force = {force} N{}\n",
        meta.kind,
        model.display(),
        meta.report.target,
        meta.report.size,
        stress.len(),
        if served.predictor.takes_phase() {
            format!(", respiratory phase {}", served.predictor.phase())
        } else {
            String::new()
        }
    );
    if let Some(sd) = prediction.sd {
        let of = match meta.report.target {
            surrogate::Target::Principal => "all ROI elements",
            surrogate::Target::Tensor => "every stress component of every ROI element",
        };
        let _ = writeln!(text, "GP predictive standard deviation ({of}): {sd:.6e} Pa");
    }
    for w in &prediction.warnings {
        let _ = writeln!(text, "warning: {w}");
    }
    if let Some(path) = png {
        let scale = served
            .scale()
            .unwrap_or_else(|| surrogate::ColourScale::of_values(stress));
        let scale_note = if served.scale().is_some() {
            "scale: training range"
        } else {
            "scale: this prediction's range (the model records no training range)"
        };
        let picture = surrogate::Picture {
            values: stress,
            centroids: served.predictor.roi_centroids(),
            view: served.view.as_ref(),
            scale,
            hand: Some(surrogate::Hand { x, y, force }),
            time_s: None,
            hull: served.domain().map(|d| d.hull.as_slice()),
            subtitle: format!(
                "ROI maximum principal stress [kPa]: {} surrogate ({} target), {scale_note}",
                meta.kind, meta.report.target
            ),
            warnings: prediction.warnings.iter().map(|w| w.to_string()).collect(),
        };
        surrogate::render_picture(&picture, path)
            .map_err(|e| format!("--png {}: {e}", path.display()))?;
        let _ = writeln!(text, "map: {}", path.display());
    }
    text.push_str("ROI maximum principal stress [Pa]:\nelement_id stress_Pa\n");
    for (id, s) in meta.roi_ids.iter().zip(stress) {
        let _ = writeln!(text, "{id} {s:.6e}");
    }
    let mut out = std::io::stdout().lock();
    write_or_closed(out.write_all(text.as_bytes()).and_then(|_| out.flush())).map(|_| ())
}

/// A write to stdout: `Ok(true)` when done, `Ok(false)` when the reader has gone (a closed
/// pipe, as with `| head`: stop quietly), an error message otherwise.
fn write_or_closed(r: std::io::Result<()>) -> Result<bool, String> {
    match r {
        Ok(()) => Ok(true),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(false),
        Err(e) => Err(format!("writing to stdout: {e}")),
    }
}

/// Streaming prediction: JSON lines in, JSON lines out (see the module doc).
pub fn predict_stdin(model: &Path) -> Result<(), String> {
    let mut p = load_model(model)?;
    let stdin = std::io::stdin();
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    let (mut served, mut failed) = (0usize, 0usize);
    let mut input = stdin.lock();
    let mut buf = Vec::new();
    let mut n = 0usize;
    loop {
        buf.clear();
        let got = input
            .read_until(b'\n', &mut buf)
            .map_err(|e| format!("reading stdin line {}: {e}", n + 1))?;
        if got == 0 {
            break;
        }
        n += 1;
        // A line that is not UTF-8 gets its error reply; the stream goes on.
        let parsed = match parse_input_line(&buf) {
            Ok(None) => continue,
            Ok(Some(v)) => Ok(v),
            Err(e) => Err(e),
        };
        let reply = match parsed.and_then(|line| {
            let [x, y, force] = line.press;
            apply_phase(&mut p, line.phase, model)?;
            let (stress, variance) = p.predict_with_variance(x, y, force);
            non_finite_output(stress, variance)?;
            Ok((stress.to_vec(), variance, line.id))
        }) {
            Ok((stress, variance, id)) => {
                served += 1;
                let mut m = Map::new();
                m.insert("line".into(), json!(n));
                if let Some(id) = id {
                    m.insert("id".into(), id);
                }
                m.insert("stress".into(), json!(stress));
                m.insert("variance".into(), json!(variance));
                Value::Object(m)
            }
            Err(e) => {
                failed += 1;
                json!({ "line": n, "error": format!("line {n}: {e}") })
            }
        };
        let mut bytes = serde_json::to_vec(&reply).map_err(|e| e.to_string())?;
        bytes.push(b'\n');
        if !write_or_closed(out.write_all(&bytes).and_then(|_| out.flush()))? {
            break;
        }
    }
    eprintln!("palpa predict: {served} prediction(s), {failed} line(s) with errors");
    Ok(())
}
