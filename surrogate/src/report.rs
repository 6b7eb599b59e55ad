//! What training and evaluation report: Fit per location and overall, training time, latency,
//! and the accuracy-versus-cost table.

use crate::model_kind::ModelKind;
use crate::target::Target;
use serde::{Deserialize, Serialize};
use std::fmt;

/// Fit (paper eq. 5) on one location's samples.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LocationFit {
    /// Location index.
    pub location: i64,
    /// Location label from the dataset manifest.
    pub label: String,
    /// Samples scored.
    pub n_samples: usize,
    /// Fit on them (1 perfect, 0 no better than their mean).
    #[serde(with = "crate::json_f64")]
    pub fit: f64,
}

/// Outcome of training one model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrainReport {
    /// Model family.
    pub kind: ModelKind,
    /// What the outputs stand for (`target`); models saved before it existed learned `Y`.
    /// A saved model's target is this one.
    #[serde(default)]
    pub target: Target,
    /// Architecture in words, e.g. `3-64-126-256-512-377` or `SE-ARD, n=150`.
    pub size: String,
    /// Number of stored parameters (weights and biases; for a GP, the entries of its mean's
    /// coefficients and output basis).
    pub n_params: usize,
    /// Training samples.
    pub n_train: usize,
    /// Test (held-out) samples scored.
    pub n_test: usize,
    /// Wall time of the fit [s].
    pub train_seconds: f64,
    /// Epochs run (MLP).
    pub epochs: Option<usize>,
    /// Final training loss (MLP, normalised mean squared error) or log marginal likelihood per
    /// target (GP).
    #[serde(with = "crate::json_f64")]
    pub final_objective: f64,
    /// Fit on the training samples.
    #[serde(with = "crate::json_f64")]
    pub train_fit: f64,
    /// Fit on all test samples pooled (`None` without test samples).
    #[serde(with = "crate::json_f64::option", default)]
    pub test_fit: Option<f64>,
    /// Fit per test location.
    pub test_fit_by_location: Vec<LocationFit>,
    /// Fit on the test samples at the paper's time stamps (multiples of
    /// [`crate::PAPER_SAMPLE_INTERVAL`]) when the test set also holds samples between them;
    /// `None` otherwise.
    #[serde(with = "crate::json_f64::option", default)]
    pub test_fit_paper_times: Option<f64>,
    /// Fraction of the test samples' ROI stresses inside the GP's 95 % predictive interval
    /// (`coverage`); `None` for an MLP or without test samples.
    #[serde(with = "crate::json_f64::option", default)]
    pub test_coverage_95: Option<f64>,
    /// Training locations (distinct location ids among the training samples).
    #[serde(default)]
    pub n_train_locations: usize,
    /// Width (m) of the recovered stress target the model learned and was scored on
    /// ([`crate::recovery`]); `None` for the element stress.
    #[serde(default)]
    pub recovery_width: Option<f64>,
    /// Mean single-prediction latency of the serving predictor [us], one thread.
    pub latency_us: f64,
    /// Training settings, as JSON.
    pub settings: serde_json::Value,
}

impl fmt::Display for TrainReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "model {} on the {} target ({}, {} parameters), {} training samples from {} locations, trained in {:.2} s{}",
            self.kind,
            self.target,
            self.size,
            self.n_params,
            self.n_train,
            self.n_train_locations,
            self.train_seconds,
            self.epochs
                .map(|e| format!(" ({e} epochs)"))
                .unwrap_or_default()
        )?;
        if let Some(h) = self.recovery_width {
            writeln!(
                f,
                "target: the recovered stress, element stresses averaged over a Gaussian of width {:.3} mm (every Fit below is against the recovered field)",
                h * 1e3
            )?;
        }
        writeln!(f, "Fit on training samples: {:.4}", self.train_fit)?;
        for l in &self.test_fit_by_location {
            writeln!(
                f,
                "Fit on test location {} ({} samples): {:.4}",
                l.label, l.n_samples, l.fit
            )?;
        }
        match self.test_fit {
            Some(v) => writeln!(f, "Fit on all {} test samples: {:.4}", self.n_test, v)?,
            None => writeln!(f, "no test samples (split == 1) in the dataset")?,
        }
        if let Some(v) = self.test_fit_paper_times {
            writeln!(
                f,
                "Fit on the test samples at the paper's time stamps (every {} ms): {v:.4}",
                crate::PAPER_SAMPLE_INTERVAL * 1e3
            )?;
        }
        if let Some(c) = self.test_coverage_95 {
            writeln!(
                f,
                "95 % predictive intervals cover {:.1} % of the test samples' ROI stresses",
                100.0 * c
            )?;
        }
        write!(f, "prediction latency: {:.1} us", self.latency_us)
    }
}

/// One row of the accuracy-versus-cost table: a model configuration under leave-one-location-out
/// cross-validation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CostRow {
    /// Configuration name.
    pub name: String,
    /// Model family.
    pub kind: ModelKind,
    /// What the outputs stand for (`target`); models saved before it existed learned `Y`.
    #[serde(default)]
    pub target: Target,
    /// Architecture in words.
    pub size: String,
    /// Stored parameters.
    pub n_params: usize,
    /// Fit over all held-out predictions pooled.
    pub fit_pooled: f64,
    /// Mean of the per-location Fits.
    pub fit_mean: f64,
    /// Worst per-location Fit.
    pub fit_min: f64,
    /// Mean training time per fold [s].
    pub train_seconds: f64,
    /// Mean prediction latency [us].
    pub latency_us: f64,
    /// Fit per held-out location.
    pub by_location: Vec<LocationFit>,
}

/// Result of `evaluate`: one row per configuration.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EvaluationReport {
    /// Number of folds (locations) per configuration.
    pub n_folds: usize,
    /// The table.
    pub rows: Vec<CostRow>,
}

impl fmt::Display for EvaluationReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "leave-one-location-out cross-validation, {} folds",
            self.n_folds
        )?;
        writeln!(
            f,
            "| model | kind | target | size | params | Fit pooled | Fit mean | Fit min | train s/fold | latency us |"
        )?;
        writeln!(f, "|---|---|---|---|---:|---:|---:|---:|---:|---:|")?;
        for r in &self.rows {
            writeln!(
                f,
                "| {} | {} | {} | {} | {} | {:.4} | {:.4} | {:.4} | {:.2} | {:.1} |",
                r.name,
                r.kind,
                r.target,
                r.size,
                r.n_params,
                r.fit_pooled,
                r.fit_mean,
                r.fit_min,
                r.train_seconds,
                r.latency_us
            )?;
        }
        Ok(())
    }
}
