//! The functions the `palpa train`, `palpa predict` and `palpa evaluate` commands call.

use crate::coverage::{principal_variance_factor, Coverage, Z95};
use crate::dataset::Dataset;
use crate::dataset::MODEL_INPUTS;
use crate::domain::TrainingDomain;
use crate::error::{Error, Result};
use crate::fit::{compute_fit, compute_fit_by_location};
use crate::gp::{fit_gp, GpOptions};
use crate::mlp::{train_mlp, MlpOptions};
use crate::model::{Predictor, PredictorImpl, TrainedModel};
use crate::model_kind::ModelKind;
use crate::report::{CostRow, EvaluationReport, LocationFit, TrainReport};
use crate::target::{Target, TargetMap};
use ndarray::{Array2, Axis};
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::time::Instant;

/// Settings of both model families; `train` uses the one its `ModelKind` names.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct TrainOptions {
    /// MLP settings.
    pub mlp: MlpOptions,
    /// GP settings.
    pub gp: GpOptions,
    /// What the model learns (`target`); `None` picks [`Target::default_for`] the model
    /// family and dataset: the tensor for a GP on a dataset with `S`, else the principal stress.
    pub target: Option<Target>,
}

/// One prediction: ROI stress and, for a GP, its variance.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Prediction {
    /// ROI maximum principal stress [Pa], one per ROI element.
    pub stress: Vec<f64>,
    /// GP predictive (latent) variance [Pa^2], shared by all raw outputs: by all ROI elements on
    /// the principal target, by every stress component of every element on the tensor target
    /// (not the variance of the served principal stress); `None` for an MLP.
    pub variance: Option<f64>,
}

/// A named model configuration for `evaluate`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelConfig {
    /// Name in the table.
    pub name: String,
    /// Family.
    pub kind: ModelKind,
    /// Settings.
    pub options: TrainOptions,
}

/// Reads the dataset at `dataset` (see `Dataset::read`), trains a `kind` model on its split-0
/// samples, scores it on its split-1 samples, saves it at `out` (see `model::model_paths`) with
/// its training domain ([`TrainingDomain`]) and returns the report (Fit per test location and overall, training time, latency).
pub fn train(
    dataset: &Path,
    kind: ModelKind,
    opts: &TrainOptions,
    out: &Path,
) -> Result<TrainReport> {
    train_selected(dataset, &TrainingSelection::default(), kind, opts, out)
}

/// Which training samples of a dataset a model learns from ([`Dataset::select_training`]);
/// the default keeps them all.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TrainingSelection {
    /// Only the first n training locations, in the dataset's order.
    pub first_locations: Option<usize>,
    /// Only samples at multiples of this interval (s).
    pub interval: Option<f64>,
    /// Learn the recovered stress target of this width (m; [`crate::recovery`]) instead of the
    /// element stress.
    pub recovery_width: Option<f64>,
    /// Drop a respiratory dataset's `phase` column, so that the model takes x, y and force
    /// only (what the phase input buys, measured on the same runs).
    pub ignore_phase: bool,
    /// Training locations left out, by label, after `first_locations`
    /// ([`Dataset::without_training_locations`]).
    pub leave_out: Vec<String>,
}

impl TrainingSelection {
    /// The dataset this selection trains on: its training samples, and its target.
    pub fn apply(&self, data: &Dataset) -> Result<Dataset> {
        let mut d = data.select_training(self.first_locations, self.interval)?;
        if !self.leave_out.is_empty() {
            d = d.without_training_locations(&self.leave_out)?;
        }
        if self.ignore_phase {
            d = d.without_column("phase");
        }
        match self.recovery_width {
            Some(h) => d.recovered(h),
            None => Ok(d),
        }
    }
}

/// As [`train`], on the training samples that `selection` keeps (the test samples are all
/// scored either way).
pub fn train_selected(
    dataset: &Path,
    selection: &TrainingSelection,
    kind: ModelKind,
    opts: &TrainOptions,
    out: &Path,
) -> Result<TrainReport> {
    let data = selection.apply(&Dataset::read(dataset)?)?;
    let (model, mut report) = train_model(&data, kind, opts)?;
    report.recovery_width = selection.recovery_width;
    model.save_with_domain(
        out,
        data.roi_ids.as_slice().unwrap_or(&data.roi_ids.to_vec()),
        data.roi_centroids.view(),
        &report,
        TrainingDomain::of_training_rows(&data).as_ref(),
    )?;
    Ok(report)
}

/// One-shot prediction with the model saved at `model` for a finger at (`x`, `y`) [m] pressing
/// with `force` [N]. For a stream of inputs, load a [`Predictor`] once instead.
pub fn predict(model: &Path, x: f64, y: f64, force: f64) -> Result<Prediction> {
    for (name, v) in [("x", x), ("y", y), ("force", force)] {
        if !v.is_finite() {
            return Err(Error::invalid(name, format!("{v} is not a finite number")));
        }
    }
    let mut p = Predictor::load(model)?;
    let (stress, variance) = p.predict_with_variance(x, y, force);
    Ok(Prediction {
        stress: stress.to_vec(),
        variance,
    })
}

/// Trains a `kind` model on `data`'s split-0 samples and scores it on its split-1 samples.
pub fn train_model(
    data: &Dataset,
    kind: ModelKind,
    opts: &TrainOptions,
) -> Result<(TrainedModel, TrainReport)> {
    let (model, report, _) = fit_and_score(data, kind, opts)?;
    Ok((model, report))
}

/// As [`train_model`], also returning the model's prediction of every row of `data` (n x R
/// ROI maximum principal stresses, Pa), so a caller can score any subset of rows.
pub fn train_and_predict(
    data: &Dataset,
    kind: ModelKind,
    opts: &TrainOptions,
) -> Result<(TrainedModel, TrainReport, Array2<f64>)> {
    fit_and_score(data, kind, opts)
}

/// Leave-one-location-out cross-validation of each configuration over every location of `data`
/// (both splits): for each location, train on all the others and predict it. Returns the
/// accuracy-versus-cost table. Cost: (number of locations) x (configurations) trainings.
pub fn evaluate(data: &Dataset, configs: &[ModelConfig]) -> Result<EvaluationReport> {
    data.validate()?;
    let mut locations: Vec<i64> = data.location.to_vec();
    locations.sort_unstable();
    locations.dedup();
    if locations.len() < 2 {
        return Err(Error::invalid(
            "location",
            "cross-validation needs at least 2 locations",
        ));
    }
    let mut rows = Vec::new();
    for cfg in configs {
        let mut y_all = Vec::new();
        let mut yhat_all = Vec::new();
        let mut by_location = Vec::new();
        let (mut secs, mut lat) = (0.0, 0.0);
        let (mut size, mut n_params, mut target) = (String::new(), 0, Target::default());
        for &loc in &locations {
            let mut fold = data.clone();
            fold.split = data.location.mapv(|l| u8::from(l == loc));
            let (_, report, yhat) = fit_and_score(&fold, cfg.kind, &cfg.options)?;
            let rows_l: Vec<usize> = (0..data.n_samples())
                .filter(|&i| data.location[i] == loc)
                .collect();
            y_all.push(data.y.select(Axis(0), &rows_l));
            yhat_all.push(yhat.select(Axis(0), &rows_l));
            by_location.extend(report.test_fit_by_location.clone());
            secs += report.train_seconds;
            lat += report.latency_us;
            size = report.size.clone();
            n_params = report.n_params;
            target = report.target;
        }
        let cat = |v: &[Array2<f64>]| {
            let views: Vec<_> = v.iter().map(|a| a.view()).collect();
            ndarray::concatenate(Axis(0), &views)
                .map_err(|e| Error::numerical("evaluate", e.to_string()))
        };
        let (y, yhat) = (cat(&y_all)?, cat(&yhat_all)?);
        let fits: Vec<f64> = by_location.iter().map(|l| l.fit).collect();
        let k = locations.len() as f64;
        rows.push(CostRow {
            name: cfg.name.clone(),
            kind: cfg.kind,
            target,
            size,
            n_params,
            fit_pooled: compute_fit(y.view(), yhat.view()),
            fit_mean: fits.iter().sum::<f64>() / fits.len().max(1) as f64,
            fit_min: fits.iter().copied().fold(f64::INFINITY, f64::min),
            train_seconds: secs / k,
            latency_us: lat / k,
            by_location,
        });
    }
    Ok(EvaluationReport {
        n_folds: locations.len(),
        rows,
    })
}

/// The default table of `evaluate`: the GP (on the stress tensor when the dataset has it), the
/// GP on the principal stress, the paper's MLP, and two smaller MLPs, all trained with Adam for
/// `mlp_epochs` epochs.
pub fn default_evaluation_configs(mlp_epochs: usize) -> Vec<ModelConfig> {
    let mlp = |name: &str, hidden: &[usize]| ModelConfig {
        name: name.into(),
        kind: ModelKind::Mlp,
        options: TrainOptions {
            mlp: MlpOptions {
                hidden: hidden.to_vec(),
                epochs: mlp_epochs,
                ..Default::default()
            },
            gp: GpOptions::default(),
            target: None,
        },
    };
    vec![
        ModelConfig {
            name: "gp".into(),
            kind: ModelKind::Gp,
            options: TrainOptions::default(),
        },
        ModelConfig {
            name: "gp-principal".into(),
            kind: ModelKind::Gp,
            options: TrainOptions {
                target: Some(Target::Principal),
                ..Default::default()
            },
        },
        mlp("mlp-paper", &crate::mlp::PAPER_HIDDEN),
        mlp("mlp-medium", &[32, 64, 128]),
        mlp("mlp-small", &[16, 32]),
    ]
}

/// Trains, predicts every row of `data`, and scores. Returns the predictions too (n x R, Pa).
fn fit_and_score(
    data: &Dataset,
    kind: ModelKind,
    opts: &TrainOptions,
) -> Result<(TrainedModel, TrainReport, Array2<f64>)> {
    data.validate()?;
    let train_rows = data.rows_with_split(crate::Split::Train);
    let test_rows = data.rows_with_split(crate::Split::Test);
    if train_rows.is_empty() {
        return Err(Error::invalid("split", "no training samples (split == 0)"));
    }
    let xin = data.model_inputs();
    let xt = xin.select(Axis(0), &train_rows);
    let target = opts
        .target
        .unwrap_or_else(|| Target::default_for(kind, data));
    let yt = target.training_targets(data, &train_rows)?;
    let start = Instant::now();
    let (model, epochs, objective, size, n_params, settings) = match kind {
        ModelKind::Mlp => {
            let m = train_mlp(xt.view(), yt.view(), &opts.mlp)?;
            let size = m
                .params
                .sizes
                .iter()
                .map(|s| s.to_string())
                .collect::<Vec<_>>()
                .join("-");
            let (e, l, np) = (m.epochs_run, m.final_loss, m.params.n_params());
            let set = serde_json::to_value(&opts.mlp).unwrap_or_default();
            (TrainedModel::Mlp(m), Some(e), l, size, np, set)
        }
        ModelKind::Gp => {
            let g = fit_gp(xt.view(), yt.view(), &opts.gp)?;
            let basis = g.basis.as_ref().map_or(String::new(), |b| {
                format!(
                    ", output basis of {} of {} directions (drops {:.1e})",
                    b.nrows(),
                    b.ncols(),
                    g.dropped_energy
                )
            });
            let size = format!(
                "SE-ARD, n={} ({} in the likelihood){basis}",
                g.train_inputs.nrows(),
                g.likelihood_rows
            );
            let np = g.coef.len() + g.basis.as_ref().map_or(0, |b| b.len());
            let l = g.log_marginal_likelihood;
            let set = serde_json::to_value(&opts.gp).unwrap_or_default();
            (TrainedModel::Gp(g), None, l, size, np, set)
        }
    };
    let train_seconds = start.elapsed().as_secs_f64();
    let mut pred = model.to_predictor();
    let mut map = TargetMap::new(target, data.n_roi());
    let mut yhat = Array2::zeros(data.y.dim());
    for (mut row, xi) in yhat.rows_mut().into_iter().zip(xin.rows()) {
        row.assign(&ndarray::ArrayView1::from(
            map.apply(pred.predict_inputs(&xi.to_vec())),
        ));
    }
    let test_coverage_95 = interval_coverage(&mut pred, target, data, &xin, &test_rows);
    let latency_us = measure_latency(&mut pred, &mut map, &xt);
    let score = |rows: &[usize]| {
        compute_fit(
            data.y.select(Axis(0), rows).view(),
            yhat.select(Axis(0), rows).view(),
        )
    };
    let train_fit = score(&train_rows);
    let (test_fit, test_fit_by_location) = if test_rows.is_empty() {
        (None, Vec::new())
    } else {
        let loc: Vec<i64> = test_rows.iter().map(|&i| data.location[i]).collect();
        let by = compute_fit_by_location(
            data.y.select(Axis(0), &test_rows).view(),
            yhat.select(Axis(0), &test_rows).view(),
            &loc,
        )
        .into_iter()
        .map(|(location, fit)| LocationFit {
            location,
            label: data.location_label(location),
            n_samples: loc.iter().filter(|&&l| l == location).count(),
            fit,
        })
        .collect();
        (Some(score(&test_rows)), by)
    };
    let paper_rows = paper_time_rows(data, &test_rows);
    let test_fit_paper_times = (paper_rows.len() >= 2 && paper_rows.len() < test_rows.len())
        .then(|| score(&paper_rows))
        .filter(|f| f.is_finite());
    let train_locations = data.training_location_order();
    let report = TrainReport {
        kind,
        target,
        size,
        n_params,
        n_train: train_rows.len(),
        n_test: test_rows.len(),
        train_seconds,
        epochs,
        final_objective: objective,
        train_fit,
        test_fit,
        test_fit_by_location,
        test_fit_paper_times,
        test_coverage_95,
        n_train_locations: train_locations.len(),
        recovery_width: None,
        latency_us,
        settings,
    };
    Ok((model, report, yhat))
}

/// The rows of `rows` sampled at a multiple of [`crate::PAPER_SAMPLE_INTERVAL`]; all of them
/// when the dataset has no time column.
fn paper_time_rows(data: &Dataset, rows: &[usize]) -> Vec<usize> {
    let dt = crate::PAPER_SAMPLE_INTERVAL;
    let tol = data.stamp_tolerance(dt);
    match data.manifest.x_columns.iter().position(|c| c == "time") {
        Some(t) => rows
            .iter()
            .copied()
            .filter(|&i| crate::dataset::on_stamp(data.x[(i, t)], dt, tol))
            .collect(),
        None => rows.to_vec(),
    }
}

/// Fraction of the ROI stresses of `rows` inside the GP's 95 % predictive interval
/// (`coverage`); `None` for an MLP or no rows.
fn interval_coverage(
    pred: &mut PredictorImpl,
    target: Target,
    data: &Dataset,
    inputs: &Array2<f64>,
    rows: &[usize],
) -> Option<f64> {
    let PredictorImpl::Gp(g) = pred else {
        return None;
    };
    let noise = g.noise_variance();
    let mut map = TargetMap::new(target, data.n_roi());
    let mut cov = Coverage::default();
    let mut var = vec![0.0; data.n_roi()];
    for &i in rows {
        let (raw, latent) = g.predict_with_variance(&inputs.row(i).to_vec());
        let v = latent + noise;
        match target {
            Target::Principal => var.iter_mut().for_each(|w| *w = v),
            Target::Tensor => {
                for (w, s) in var.iter_mut().zip(raw.chunks_exact(6)) {
                    *w = v * principal_variance_factor(s);
                }
            }
        }
        let mean = map.apply(raw);
        let y = data.y.row(i);
        cov.add(y.as_slice().unwrap_or(&y.to_vec()), mean, &var, Z95);
    }
    cov.fraction()
}

/// Mean latency [us] of one prediction (raw outputs mapped to the principal stress) over the
/// rows of `inputs`, cycled for at least 2000 calls.
fn measure_latency(pred: &mut PredictorImpl, map: &mut TargetMap, inputs: &Array2<f64>) -> f64 {
    let n = inputs.nrows().max(1);
    let calls = 2000usize;
    let start = Instant::now();
    let mut sink = 0.0;
    for k in 0..calls {
        let i = k % n;
        let mut xi = [0.0; MODEL_INPUTS.len()];
        let d = inputs.ncols().min(xi.len());
        for (j, v) in xi.iter_mut().take(d).enumerate() {
            *v = inputs[(i, j)];
        }
        sink += map
            .apply(pred.predict_inputs(&xi[..d]))
            .first()
            .copied()
            .unwrap_or(0.0);
    }
    std::hint::black_box(sink);
    start.elapsed().as_secs_f64() * 1e6 / calls as f64
}
