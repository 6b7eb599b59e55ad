//! Real-time stress surrogates for palpation: datasets in, trained models and predictions out.
//!
//! The reference study (a 2022 abdomen-palpation article, summarised in
//! `docs/paper.md`) trained a multilayer perceptron mapping the finger's
//! position and contact force to the maximum principal stress of 377 liver elements, and scored
//! it with the Fit of its eq. 5 (92.64 % on three unseen locations). This crate provides:
//!
//! - [`dataset`]: the `.npz` + JSON dataset the campaign writes ([`Dataset`]).
//! - [`mlp`]: the paper's MLP (3-64-126-256-512-R, ReLU), trained by `traingdx`-style gradient
//!   descent or Adam with a hand-written single-threaded trainer, served by a hand-written
//!   forward pass.
//! - [`gp`]: a Gaussian process with one SE-ARD kernel shared by all outputs, hyperparameters
//!   by marginal likelihood, predictive variance.
//! - [`target`]: what a model learns, the principal stress itself or the stress tensor whose
//!   largest eigenvalue ([`principal`]) it reports.
//! - [`recovery`]: the recovered stress target, element stresses averaged over a stated width.
//! - [`fit`]: paper eq. 5, per location and overall; [`coverage`]: how often held-out values
//!   fall inside the GP's 95 % intervals.
//! - [`model`]: safetensors + JSON model files and the serving [`Predictor`].
//! - [`api`]: [`train`], [`predict`], [`evaluate`] for the command line.
//! - [`domain`]: what a model was trained on (recorded in `model.json`) and whether an input
//!   lies outside it.
//! - [`view`]: the plan-view geometry that travels with a model (`view.json`).
//! - [`colour`] and [`render`]: the colour scale and the stress picture as a PNG
//!   ([`render_picture`]).
//! - [`serving`]: a model with its geometry and domain, as `palpa predict --png` and
//!   `palpa serve` show it ([`ServedModel`]).
//! - [`sensor`]: the live inputs of `palpa serve`: the force plate's four load cells, its
//!   calibration to the body, the force filter and recorded sensor logs.
//!
//! It depends on no other palpa crate.

#![warn(missing_docs)]

pub mod api;
pub mod colour;
pub mod coverage;
pub mod dataset;
pub mod domain;
pub mod error;
pub mod fit;
pub mod glyphs;
pub mod gp;
pub mod json_f64;
pub mod kernels;
pub mod lbfgs;
pub mod mlp;
pub mod model;
pub mod model_kind;
pub mod normalise;
pub mod principal;
pub mod recovery;
pub mod render;
pub mod report;
pub mod rng;
pub mod sensor;
pub mod serving;
pub mod split;
pub mod synthetic;
pub mod target;
pub mod tensor_file;
pub mod view;

pub use api::{
    default_evaluation_configs, evaluate, predict, train, train_and_predict, train_model,
    train_selected, ModelConfig, Prediction, TrainOptions, TrainingSelection,
};
pub use colour::ColourScale;
pub use dataset::{Dataset, Manifest};
pub use domain::TrainingDomain;
pub use error::{Error, Result};
pub use fit::{compute_fit, compute_fit_by_location};
pub use model::{ModelMeta, Predictor, TrainedModel};
pub use model_kind::ModelKind;
pub use render::{render_map, render_picture, Hand, Picture};
pub use report::{CostRow, EvaluationReport, LocationFit, TrainReport};
pub use serving::{Served, ServedModel, Warning};
pub use split::Split;
pub use target::Target;

/// The paper's sampling interval (s): its six samples a run, at 0, 5, ..., 25 ms. Datasets
/// sampled more densely are also scored at these stamps alone ([`TrainReport`]).
pub const PAPER_SAMPLE_INTERVAL: f64 = 0.005;
pub use view::ViewGeometry;
