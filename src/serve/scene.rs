//! The page's scene (`GET /scene.json`): everything static the page draws and needs, computed
//! once at start from the model, its `view.json`, its training domain and the calibration,
//! so that the page holds no geometry, colour or unit rule of its own:
//!
//! - `model`: path, family, target, inputs, whether it gives a predictive deviation (a GP) and
//!   takes the respiratory phase;
//! - `view`: the plan geometry (torso, model box, liver, ribs; null without `view.json`),
//!   `cells`: each ROI element's plan polygon (the view's, or squares around the centroids),
//!   `fingers`, and `extent`: the picture's plan extent [m] ([`surrogate::render::plan_extent`],
//!   the PNG's);
//! - `scale`: the fixed colour scale over the training stress range [Pa], its kind and a
//!   256-entry lookup table ([`surrogate::ColourScale::lut`], the PNG's colours), `palette`:
//!   the outline colours ([`surrogate::render::PALETTE`]);
//! - `domain`: the training hull, the largest training force [N], the stress range [Pa];
//!   `force_limit_n`: the top of the force slider and gauge;
//! - `sensor`: the plate, its calibration and the force filter's window [s]; `replay`: the
//!   `--replay` log (file, rows, duration), or null.

use serde_json::json;
use surrogate::render::{plan_extent, roi_cells, PALETTE};
use surrogate::sensor::Sensor;
use surrogate::view::Ring;
use surrogate::{ColourScale, ServedModel};

/// What the scene is built from.
pub struct SceneParts<'a> {
    /// The model.
    pub model: &'a ServedModel,
    /// Its path, as given.
    pub model_path: String,
    /// The fixed colour scale.
    pub scale: ColourScale,
    /// The sensor (plate, calibration, filter).
    pub sensor: &'a Sensor,
    /// Where the calibration came from, in words.
    pub calibration_source: String,
    /// The replay log: (file, rows, duration [s]).
    pub replay: Option<(String, usize, f64)>,
}

/// The scene's cells and extent, also used by the server (deviation maps).
pub struct Layout {
    /// ROI cells [m].
    pub cells: Vec<Ring>,
    /// Plan extent: lower-left and upper-right corners [m].
    pub extent: ([f64; 2], [f64; 2]),
}

/// The cells and extent of a model's picture.
pub fn layout(model: &ServedModel) -> Layout {
    let cells = roi_cells(model.view.as_ref(), model.predictor.roi_centroids());
    let hull = model.domain().map(|d| d.hull.as_slice());
    let extent = plan_extent(model.view.as_ref(), &cells, hull, &[]);
    Layout { cells, extent }
}

/// The top of the force slider: 1.25 x the largest training force, rounded up to 5 N.
pub fn force_limit(force_max: f64) -> f64 {
    ((1.25 * force_max / 5.0).ceil() * 5.0).max(5.0)
}

/// The scene JSON.
pub fn scene_json(p: &SceneParts, layout: &Layout) -> String {
    let meta = p.model.predictor.meta();
    let lut: Vec<String> = p
        .scale
        .lut(256)
        .iter()
        .map(|c| format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2]))
        .collect();
    let domain = p.model.domain();
    let view = p.model.view.as_ref();
    let cal = &p.sensor.calibration;
    let inputs: Vec<&str> = meta.input_columns.iter().map(String::as_str).collect();
    json!({
        "model": {
            "path": p.model_path,
            "kind": meta.kind.to_string(),
            "target": meta.report.target.to_string(),
            "inputs": inputs,
            "units": {"x": "m", "y": "m", "force": "N", "phase": "0 exhalation .. 1 inspiration", "stress": "Pa"},
            "roi_elements": meta.roi_ids.len(),
            "deviation": p.model.predictor.prior_deviation().is_some(),
            "prior_deviation_pa": p.model.predictor.prior_deviation(),
            "takes_phase": p.model.predictor.takes_phase(),
            "test_fit": meta.report.test_fit,
        },
        "view": view.map(|v| json!({
            "torso": v.torso,
            "model_box": v.model_box,
            "liver": v.liver,
            "ribs": v.ribs,
            "source": v.source,
            "respiratory_phase": v.respiratory_phase,
        })),
        "cells": layout.cells,
        "fingers": view.map(|v| v.fingers.clone()).unwrap_or_default(),
        "extent": {"lo": layout.extent.0, "hi": layout.extent.1},
        "scale": {
            "lo": p.scale.lo,
            "hi": p.scale.hi,
            "kind": p.scale.kind(),
            "lut": lut,
            "unit": "Pa",
        },
        "palette": PALETTE,
        "domain": domain.map(|d| json!({
            "hull": d.hull,
            "locations": d.locations,
            "force_max_n": d.force_max_n,
            "stress_range_pa": d.stress_range_pa,
        })),
        "force_limit_n": force_limit(domain.map_or(50.0, |d| d.force_max_n)),
        "sensor": {
            "plate": cal.plate,
            "affine": cal.affine,
            "calibration": p.calibration_source,
            "filter_s": p.sensor.filter_window(),
        },
        "replay": p.replay.as_ref().map(|(f, n, d)| json!({"file": f, "rows": n, "duration_s": d})),
    })
    .to_string()
}

/// The hand's home before the first input: the centre of the training locations (or of the
/// picture).
pub fn home(model: &ServedModel, layout: &Layout) -> [f64; 2] {
    match model.domain() {
        Some(d) if !d.locations.is_empty() => {
            let n = d.locations.len() as f64;
            let s = d
                .locations
                .iter()
                .fold([0.0, 0.0], |a, p| [a[0] + p[0], a[1] + p[1]]);
            [s[0] / n, s[1] / n]
        }
        _ => {
            let (lo, hi) = layout.extent;
            [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0]
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn force_limit_rounds_up() {
        assert_eq!(force_limit(54.08), 70.0);
        assert_eq!(force_limit(40.0), 50.0);
        assert_eq!(force_limit(0.0), 5.0);
    }
}
