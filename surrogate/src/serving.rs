//! A model with what it takes to show its predictions: the [`Predictor`], its plan geometry
//! (`view.json`, [`ViewGeometry`]) and its training domain (`model.json`'s `domain`), for
//! `palpa predict --png` and `palpa serve`.
//!
//! [`ServedModel::predict`] gives the stress of each ROI element, the GP's predictive deviation
//! and what about the input lies outside what the model knows: outside the body (the torso's
//! plan outline), outside the training locations' hull, above the largest training force, or a
//! large predictive deviation ([`crate::domain`]).

use crate::colour::ColourScale;
use crate::domain::{Outside, TrainingDomain};
use crate::error::{Error, Result};
use crate::model::{model_paths, Predictor};
use crate::view::{point_in_polygon, view_path, ViewGeometry};
use std::path::Path;

/// Why an input lies outside what the model can be trusted with.
#[derive(Clone, Debug, PartialEq)]
pub enum Warning {
    /// The press lies outside the torso's plan outline.
    OutsideBody,
    /// Outside the training domain.
    Domain(Outside),
}

impl Warning {
    /// A short machine-readable code.
    pub fn code(&self) -> &'static str {
        match self {
            Warning::OutsideBody => "outside_body",
            Warning::Domain(Outside::Position { .. }) => "outside_training_locations",
            Warning::Domain(Outside::Force { .. }) => "force_above_training",
            Warning::Domain(Outside::Deviation { .. }) => "large_deviation",
            Warning::Domain(Outside::Phase { .. }) => "phase_outside_training",
        }
    }
}

impl std::fmt::Display for Warning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Warning::OutsideBody => f.write_str("the press lies outside the body"),
            Warning::Domain(o) => o.fmt(f),
        }
    }
}

/// One served prediction.
#[derive(Clone, Debug, PartialEq)]
pub struct Served {
    /// Maximum principal stress of each ROI element [Pa].
    pub stress: Vec<f64>,
    /// The GP's predictive (latent) standard deviation [Pa]; `None` for an MLP.
    pub sd: Option<f64>,
    /// What lies outside the model's knowledge.
    pub warnings: Vec<Warning>,
}

/// A loaded model with its geometry and training domain.
#[derive(Clone, Debug)]
pub struct ServedModel {
    /// The model.
    pub predictor: Predictor,
    /// Its plan geometry, when `view.json` is beside it.
    pub view: Option<ViewGeometry>,
}

impl ServedModel {
    /// Loads the model at `path` and the `view.json` beside it, if any (an error if it does
    /// not belong to the model).
    pub fn load(path: &Path) -> Result<ServedModel> {
        let predictor = Predictor::load(path)?;
        let vp = view_path(path);
        let view = if vp.is_file() {
            let v = ViewGeometry::read(&vp)?;
            v.check_roi(&predictor.meta().roi_ids)
                .map_err(|e| Error::format(&vp, e.to_string()))?;
            Some(v)
        } else {
            None
        };
        Ok(ServedModel { predictor, view })
    }

    /// Where the model's files are: (`.safetensors`, `.json`, `view.json`).
    pub fn paths(path: &Path) -> [std::path::PathBuf; 3] {
        let (st, js) = model_paths(path);
        [st, js, view_path(path)]
    }

    /// The training domain recorded in `model.json`, if any.
    pub fn domain(&self) -> Option<&TrainingDomain> {
        self.predictor.meta().domain.as_ref()
    }

    /// The fixed colour scale over the training stress range; `None` for a model saved
    /// without its domain.
    pub fn scale(&self) -> Option<ColourScale> {
        self.domain()
            .map(|d| ColourScale::over(d.stress_range_pa[0], d.stress_range_pa[1]))
    }

    /// Predicts for a press at (x, y) [m] with `force` [N]; the inputs must be finite.
    pub fn predict(&mut self, x: f64, y: f64, force: f64) -> Served {
        let prior = self.predictor.prior_deviation();
        let (stress, var) = self.predictor.predict_with_variance(x, y, force);
        let stress = stress.to_vec();
        let sd = var.map(|v| v.max(0.0).sqrt());
        let warnings = self.assess(x, y, force, sd.zip(prior));
        Served {
            stress,
            sd,
            warnings,
        }
    }

    /// What lies outside the model's knowledge for a press at (x, y) with `force`, given the
    /// (deviation, prior deviation) when the model has them, and, for a model with a phase
    /// input, at the phase set on its predictor.
    pub fn assess(
        &self,
        x: f64,
        y: f64,
        force: f64,
        deviation: Option<(f64, f64)>,
    ) -> Vec<Warning> {
        let mut w = Vec::new();
        if let Some(v) = &self.view {
            if !point_in_polygon([x, y], &v.torso) {
                w.push(Warning::OutsideBody);
            }
        }
        if let Some(d) = self.domain() {
            w.extend(
                d.assess(x, y, force, deviation)
                    .into_iter()
                    .map(Warning::Domain),
            );
            if self.predictor.takes_phase() {
                w.extend(d.assess_phase(self.predictor.phase()).map(Warning::Domain));
            }
        }
        w
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::api::{train, TrainOptions};
    use crate::model_kind::ModelKind;
    use crate::synthetic::make_synthetic_dataset;
    use crate::view::{Fingers, VIEW_FORMAT, VIEW_VERSION};

    /// A GP trained on the synthetic dataset, with a view beside it: predictions inside the
    /// raster carry no warning; outside the torso, far out and above the force range they
    /// carry theirs.
    #[test]
    fn served_model_flags_what_it_does_not_know() {
        let dir = tempfile::tempdir().unwrap();
        let data = make_synthetic_dataset(6);
        let ds = dir.path().join("data");
        data.write(&ds).unwrap();
        let model = dir.path().join("gp");
        train(&ds, ModelKind::Gp, &TrainOptions::default(), &model).unwrap();
        let square = |c: [f64; 2], h: f64| {
            vec![
                [c[0] - h, c[1] - h],
                [c[0] + h, c[1] - h],
                [c[0] + h, c[1] + h],
                [c[0] - h, c[1] + h],
            ]
        };
        let view = ViewGeometry {
            format: VIEW_FORMAT.into(),
            version: VIEW_VERSION,
            source: "test".into(),
            torso: square([0.05, 0.05], 0.08),
            model_box: None,
            liver: vec![square([0.05, 0.05], 0.05)],
            ribs: vec![],
            roi_ids: data.roi_ids.to_vec(),
            roi_cells: data
                .roi_centroids
                .rows()
                .into_iter()
                .map(|r| square([r[0], r[1]], 0.001))
                .collect(),
            fingers: Fingers::default(),
            respiratory_phase: 0.0,
            max_liver_shift_m: 0.02,
        };
        view.write(&view_path(&model)).unwrap();
        let mut m = ServedModel::load(&model).unwrap();
        let d = m.domain().unwrap().clone();
        let s = m.scale().unwrap();
        assert_eq!(s.hi, d.stress_range_pa[1]);
        let inside = m.predict(0.05, 0.05, 0.5 * d.force_max_n);
        assert_eq!(inside.stress.len(), 6);
        assert!(inside.warnings.is_empty(), "{:?}", inside.warnings);
        assert!(inside.sd.unwrap() >= 0.0);
        let out = m.predict(0.2, 0.05, 2.0 * d.force_max_n);
        let codes: Vec<&str> = out.warnings.iter().map(Warning::code).collect();
        assert!(codes.contains(&"outside_body"), "{codes:?}");
        assert!(codes.contains(&"outside_training_locations"), "{codes:?}");
        assert!(codes.contains(&"force_above_training"), "{codes:?}");
        assert!(codes.contains(&"large_deviation"), "{codes:?}");
        // a view of another model is refused, naming the file
        let mut other = view.clone();
        other.roi_ids[0] += 1;
        other.write(&view_path(&model)).unwrap();
        let e = ServedModel::load(&model).unwrap_err().to_string();
        assert!(e.contains("view.json") && e.contains("ROI"), "{e}");
    }
}
