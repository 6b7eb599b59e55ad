//! Trained models on disk and the serving-time [`Predictor`].
//!
//! A model is two files: `NAME.safetensors` with the arrays and `NAME.json` with the metadata
//! ([`ModelMeta`]: kind, architecture, scalings, kernel, training settings and report). Given a
//! directory instead, they are `DIR/model.safetensors` and `DIR/model.json`.
//!
//! Tensors (row-major):
//! - MLP: `layers.L.weight` `[n_out, n_in]` f32 (the PyTorch `nn.Linear` layout) and
//!   `layers.L.bias` `[n_out]` f32, for L = 0 .. layers-1; normalised units (see `normalise`).
//! - GP: `train_inputs` `[n, D]`, `coef` `[n, r]`, `basis` `[r, M]` (the mean's output basis,
//!   see `gp::train`; without `basis`, `coef` is `[n, M]` = K^-1 V), `k_inv` `[n, n]`, all
//!   f64, normalised units. Version-1 files name `coef` `alpha` and have no basis.
//! - Both: `roi_centroids` `[R, 3]` f64 [m], for rendering maps from the model alone.
//!
//! The safetensors header's `__metadata__` says what the file is without the JSON beside it
//! (all values strings, lists as JSON): `format` (`palpa-surrogate`), `version`, `kind` (`mlp`
//! or `gp`), `target` (`principal` or `tensor`), `input_columns` (`["x","y","force"]`, or
//! with `"phase"` appended for a model trained on a respiratory campaign), `input_units`
//! (`["m","m","N"]`, `"1"` for the phase), `output` (what the served values are) and `output_unit`
//! (`Pa`). `python/palpa_surrogate.py` reads both files with numpy alone.
//!
//! M is the number of raw outputs: R for the principal-stress target, 6R for the tensor target
//! (`target`, recorded as the training report's `target`); [`Predictor`] always serves the R
//! maximum principal stresses.

use crate::dataset::write_atomic;
use crate::domain::TrainingDomain;
use crate::error::{Error, Result};
use crate::gp::{GpModel, GpPredictor, SeArd};
use crate::mlp::{DenseLayer, MlpModel, MlpPredictor};
use crate::model_kind::ModelKind;
use crate::normalise::Scaling;
use crate::report::TrainReport;
use crate::target::TargetMap;
use crate::tensor_file::{
    read_metadata, read_tensors, take_f32, take_f64, write_tensors, Tensor, TensorData, TensorSet,
};
use ndarray::{Array2, ArrayView2};
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Value of [`ModelMeta::format`].
pub const MODEL_FORMAT: &str = "palpa-surrogate";
/// Newest value of [`ModelMeta::version`]: 3, a model whose fourth input is the respiratory
/// phase. A model of x, y and force is still written as version 2, the format that older
/// readers take; they refuse a version-3 file instead of feeding it three inputs.
pub const MODEL_VERSION: u32 = 3;

/// Metadata sidecar of a saved model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelMeta {
    /// Always `"palpa-surrogate"`.
    pub format: String,
    /// Format version: 2, or 3 for a model with the phase input ([`MODEL_VERSION`]).
    pub version: u32,
    /// Model family.
    pub kind: ModelKind,
    /// Names of the inputs, in order (`x`, `y`, `force`); units m, m, N.
    pub input_columns: Vec<String>,
    /// ROI element ids, in order; the served outputs are their maximum principal stress [Pa].
    pub roi_ids: Vec<i64>,
    /// Input scaling (physical -> normalised).
    pub input_scaling: Scaling,
    /// Output scaling (normalised -> physical).
    pub output_scaling: Scaling,
    /// MLP layer widths `n_0 .. n_L` (empty for a GP).
    #[serde(default)]
    pub layer_sizes: Vec<usize>,
    /// MLP hidden activation, `"relu"` (output layer linear).
    #[serde(default)]
    pub activation: String,
    /// GP kernel hyperparameters (normalised units).
    #[serde(default)]
    pub kernel: Option<SeArd>,
    /// Training settings and results.
    pub report: TrainReport,
    /// What the model was trained on (locations, their hull, largest force, stress range);
    /// absent from models saved before it was recorded.
    #[serde(default)]
    pub domain: Option<TrainingDomain>,
}

/// A model in memory, as training produces it.
#[derive(Clone, Debug)]
pub enum TrainedModel {
    /// An MLP.
    Mlp(MlpModel),
    /// A GP.
    Gp(GpModel),
}

/// The `.safetensors` and `.json` paths for `path` (see the module doc).
pub fn model_paths(path: &Path) -> (PathBuf, PathBuf) {
    match path.extension().and_then(|e| e.to_str()) {
        Some("safetensors") => (path.to_path_buf(), path.with_extension("json")),
        Some("json") => (path.with_extension("safetensors"), path.to_path_buf()),
        _ => (path.join("model.safetensors"), path.join("model.json")),
    }
}

impl TrainedModel {
    /// The model family.
    pub fn kind(&self) -> ModelKind {
        match self {
            TrainedModel::Mlp(_) => ModelKind::Mlp,
            TrainedModel::Gp(_) => ModelKind::Gp,
        }
    }

    /// Number of raw outputs M (R or 6R, see the module doc).
    pub fn n_outputs(&self) -> usize {
        match self {
            TrainedModel::Mlp(m) => m.output_scaling.len(),
            TrainedModel::Gp(g) => g.output_scaling.len(),
        }
    }

    /// Number of inputs D: 3 (x, y, force) or 4 (and the respiratory phase), the first D of
    /// [`crate::dataset::MODEL_INPUTS`].
    pub fn n_inputs(&self) -> usize {
        match self {
            TrainedModel::Mlp(m) => m.input_scaling.len(),
            TrainedModel::Gp(g) => g.input_scaling.len(),
        }
    }

    /// A serving predictor over this model (same arithmetic as after save and load). Its outputs
    /// are the raw ones (6R stress components on the tensor target); map them with
    /// `target::TargetMap` as [`Predictor`] does.
    pub fn to_predictor(&self) -> PredictorImpl {
        match self {
            TrainedModel::Mlp(m) => {
                let p = &m.params;
                let layers = (0..p.n_layers())
                    .map(|l| DenseLayer {
                        n_in: p.sizes[l],
                        n_out: p.sizes[l + 1],
                        weight: p.weights[l].clone(),
                        bias: p.biases[l].clone(),
                    })
                    .collect();
                PredictorImpl::Mlp(MlpPredictor::new(
                    layers,
                    m.input_scaling.clone(),
                    m.output_scaling.clone(),
                ))
            }
            TrainedModel::Gp(g) => PredictorImpl::Gp(GpPredictor::new(
                g.kernel.clone(),
                g.input_scaling.clone(),
                g.output_scaling.clone(),
                &g.train_inputs.iter().copied().collect::<Vec<_>>(),
                g.coef.iter().copied().collect(),
                g.basis
                    .as_ref()
                    .map(|b| b.iter().copied().collect())
                    .unwrap_or_default(),
                g.k_inv.iter().copied().collect(),
            )),
        }
    }

    /// Saves the model with its ROI (ids, centroids R x 3 [m]) and training report (whose
    /// `target` says what the outputs stand for).
    pub fn save(
        &self,
        path: impl AsRef<Path>,
        roi_ids: &[i64],
        roi_centroids: ArrayView2<f64>,
        report: &TrainReport,
    ) -> Result<()> {
        self.save_with_domain(path, roi_ids, roi_centroids, report, None)
    }

    /// [`TrainedModel::save`], recording the training domain too (`domain` in `model.json`).
    pub fn save_with_domain(
        &self,
        path: impl AsRef<Path>,
        roi_ids: &[i64],
        roi_centroids: ArrayView2<f64>,
        report: &TrainReport,
        domain: Option<&TrainingDomain>,
    ) -> Result<()> {
        let (st, js) = model_paths(path.as_ref());
        let inputs = &crate::dataset::MODEL_INPUTS[..self.n_inputs().min(4)];
        // version 3 only where it is needed: a model with the phase input (MODEL_VERSION)
        let version = if inputs.len() > 3 { 3 } else { 2 };
        if let Some(dir) = st.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
        }
        let m = self.n_outputs();
        let r = roi_ids.len();
        if report.target.n_outputs(r) != m || roi_centroids.dim() != (r, 3) {
            return Err(Error::invalid(
                "roi",
                format!(
                    "{r} ids and centroids {:?} for a model of {m} outputs on the {} target",
                    roi_centroids.dim(),
                    report.target
                ),
            ));
        }
        let mut set = TensorSet::new();
        set.insert(
            "roi_centroids".into(),
            Tensor {
                shape: vec![r, 3],
                data: TensorData::F64(roi_centroids.iter().copied().collect()),
            },
        );
        let (input_scaling, output_scaling, layer_sizes, activation, kernel) = match self {
            TrainedModel::Mlp(m) => {
                let p = &m.params;
                for l in 0..p.n_layers() {
                    let (ni, no) = (p.sizes[l], p.sizes[l + 1]);
                    // stored [n_out, n_in]: transpose of the input-major trainer layout
                    let mut w = vec![0.0f32; ni * no];
                    for i in 0..ni {
                        for o in 0..no {
                            w[o * ni + i] = p.weights[l][i * no + o];
                        }
                    }
                    set.insert(
                        format!("layers.{l}.weight"),
                        Tensor {
                            shape: vec![no, ni],
                            data: TensorData::F32(w),
                        },
                    );
                    set.insert(
                        format!("layers.{l}.bias"),
                        Tensor {
                            shape: vec![no],
                            data: TensorData::F32(p.biases[l].clone()),
                        },
                    );
                }
                (
                    m.input_scaling.clone(),
                    m.output_scaling.clone(),
                    p.sizes.clone(),
                    "relu".to_string(),
                    None,
                )
            }
            TrainedModel::Gp(g) => {
                let put = |set: &mut TensorSet, name: &str, a: &Array2<f64>| {
                    set.insert(
                        name.into(),
                        Tensor {
                            shape: vec![a.nrows(), a.ncols()],
                            data: TensorData::F64(a.iter().copied().collect()),
                        },
                    );
                };
                put(&mut set, "train_inputs", &g.train_inputs);
                put(&mut set, "coef", &g.coef);
                if let Some(b) = &g.basis {
                    put(&mut set, "basis", b);
                }
                put(&mut set, "k_inv", &g.k_inv);
                (
                    g.input_scaling.clone(),
                    g.output_scaling.clone(),
                    Vec::new(),
                    String::new(),
                    Some(g.kernel.clone()),
                )
            }
        };
        let meta = ModelMeta {
            format: MODEL_FORMAT.into(),
            version,
            kind: self.kind(),
            input_columns: inputs.iter().map(|c| c.to_string()).collect(),
            roi_ids: roi_ids.to_vec(),
            input_scaling,
            output_scaling,
            layer_sizes,
            activation,
            kernel,
            report: report.clone(),
            domain: domain.cloned(),
        };
        let metadata = [
            ("format", MODEL_FORMAT.to_string()),
            ("version", version.to_string()),
            ("kind", self.kind().to_string()),
            ("target", report.target.to_string()),
            (
                "input_columns",
                serde_json::to_string(inputs).unwrap_or_default(),
            ),
            (
                "input_units",
                serde_json::to_string(&["m", "m", "N", "1"][..inputs.len()]).unwrap_or_default(),
            ),
            (
                "output",
                "maximum principal Cauchy stress of each ROI element".to_string(),
            ),
            ("output_unit", "Pa".to_string()),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect();
        write_tensors(&st, &set, &metadata)?;
        let text =
            serde_json::to_string_pretty(&meta).map_err(|e| Error::format(&js, e.to_string()))?;
        write_atomic(&js, |mut f| {
            f.write_all(text.as_bytes()).map_err(|e| Error::io(&js, e))
        })
    }
}

/// The evaluator behind a [`Predictor`].
#[derive(Clone, Debug)]
pub enum PredictorImpl {
    /// Hand-written MLP forward pass.
    Mlp(MlpPredictor),
    /// GP mean and variance.
    Gp(GpPredictor),
}

impl PredictorImpl {
    /// Prediction [Pa] at physical inputs (x [m], y [m], force [N]).
    pub fn predict_inputs(&mut self, inputs: &[f64]) -> &[f64] {
        match self {
            PredictorImpl::Mlp(m) => m.predict_inputs(inputs),
            PredictorImpl::Gp(g) => g.predict_inputs(inputs),
        }
    }
}

/// A loaded model ready to serve: reusable buffers, no allocation per prediction.
#[derive(Clone, Debug)]
pub struct Predictor {
    meta: ModelMeta,
    roi_centroids: Array2<f64>,
    inner: PredictorImpl,
    map: TargetMap,
    /// The respiratory phase a model with a `phase` input is evaluated at
    /// ([`Predictor::set_phase`]).
    phase: f64,
}

impl Predictor {
    /// Loads `path` (`NAME.safetensors`, `NAME.json`, or a directory holding `model.*`).
    pub fn load(path: impl AsRef<Path>) -> Result<Predictor> {
        let (st, js) = model_paths(path.as_ref());
        let text = std::fs::read_to_string(&js).map_err(|e| Error::io(&js, e))?;
        let meta: ModelMeta =
            serde_json::from_str(&text).map_err(|e| Error::format(&js, e.to_string()))?;
        if meta.format != MODEL_FORMAT || meta.version > MODEL_VERSION {
            return Err(Error::format(
                &js,
                format!(
                    "format {:?} version {}, expected {MODEL_FORMAT:?} version <= {MODEL_VERSION}",
                    meta.format, meta.version
                ),
            ));
        }
        let inputs = &crate::dataset::MODEL_INPUTS;
        if meta.input_columns != inputs[..3] && meta.input_columns != inputs[..4] {
            return Err(Error::format(
                &js,
                format!(
                    "input_columns {:?}: a model takes {:?} or {:?}",
                    meta.input_columns,
                    &inputs[..3],
                    &inputs[..4]
                ),
            ));
        }
        let r = meta.roi_ids.len();
        // what the raw outputs stand for: the training report's target (version-1 files have
        // none, and learned the principal stress)
        let target = meta.report.target;
        let m = target.n_outputs(r);
        let d = meta.input_columns.len();
        if meta.input_scaling.len() != d || meta.output_scaling.len() != m {
            return Err(Error::format(
                &js,
                format!(
                    "input_scaling has {} columns for {d} inputs, output_scaling {} for {r} ROI ids \
                     ({m} outputs on the {} target)",
                    meta.input_scaling.len(),
                    meta.output_scaling.len(),
                    target
                ),
            ));
        }
        // The tensors' own header must agree with the JSON beside them (files written before
        // the header carried metadata have none).
        let header = read_metadata(&st)?;
        for (key, want) in [
            ("kind", meta.kind.to_string()),
            ("target", target.to_string()),
        ] {
            if let Some(got) = header.get(key) {
                if *got != want {
                    return Err(Error::format(
                        &st,
                        format!(
                            "__metadata__ {key} is {got:?} but {} says {want:?}",
                            js.display()
                        ),
                    ));
                }
            }
        }
        let mut set = read_tensors(&st)?;
        let c = take_f64(&mut set, &st, "roi_centroids", &[r, 3])?;
        let roi_centroids =
            Array2::from_shape_vec((r, 3), c).map_err(|e| Error::format(&st, e.to_string()))?;
        let inner = match meta.kind {
            ModelKind::Mlp => {
                let s = &meta.layer_sizes;
                if s.len() < 2 || s[0] != d || s[s.len() - 1] != m {
                    return Err(Error::format(
                        &js,
                        format!("layer_sizes {s:?} do not match {d} inputs and {m} outputs"),
                    ));
                }
                let mut layers = Vec::new();
                for l in 0..s.len() - 1 {
                    let (ni, no) = (s[l], s[l + 1]);
                    let w = take_f32(&mut set, &st, &format!("layers.{l}.weight"), &[no, ni])?;
                    let bias = take_f32(&mut set, &st, &format!("layers.{l}.bias"), &[no])?;
                    let mut weight = vec![0.0f32; ni * no];
                    for o in 0..no {
                        for i in 0..ni {
                            weight[i * no + o] = w[o * ni + i];
                        }
                    }
                    layers.push(DenseLayer {
                        n_in: ni,
                        n_out: no,
                        weight,
                        bias,
                    });
                }
                PredictorImpl::Mlp(MlpPredictor::new(
                    layers,
                    meta.input_scaling.clone(),
                    meta.output_scaling.clone(),
                ))
            }
            ModelKind::Gp => {
                let kernel = meta
                    .kernel
                    .clone()
                    .ok_or_else(|| Error::format(&js, "GP model without a kernel field"))?;
                if kernel.length_scales.len() != d {
                    return Err(Error::format(
                        &js,
                        "kernel.length_scales: one per input expected",
                    ));
                }
                let n = set
                    .get("train_inputs")
                    .map(|t| t.shape.first().copied().unwrap_or(0))
                    .ok_or_else(|| Error::format(&st, "missing tensor train_inputs"))?;
                let u = take_f64(&mut set, &st, "train_inputs", &[n, d])?;
                let (coef, basis) = if meta.version < 2 {
                    (take_f64(&mut set, &st, "alpha", &[n, m])?, Vec::new())
                } else if let Some(rank) = set.get("basis").and_then(|t| t.shape.first().copied()) {
                    if rank == 0 || rank > n.min(m) {
                        return Err(Error::format(
                            &st,
                            format!(
                                "basis has {rank} rows, expected 1 to {} (n = {n}, M = {m})",
                                n.min(m)
                            ),
                        ));
                    }
                    let b = take_f64(&mut set, &st, "basis", &[rank, m])?;
                    (take_f64(&mut set, &st, "coef", &[n, rank])?, b)
                } else {
                    (take_f64(&mut set, &st, "coef", &[n, m])?, Vec::new())
                };
                let k_inv = take_f64(&mut set, &st, "k_inv", &[n, n])?;
                PredictorImpl::Gp(GpPredictor::new(
                    kernel,
                    meta.input_scaling.clone(),
                    meta.output_scaling.clone(),
                    &u,
                    coef,
                    basis,
                    k_inv,
                ))
            }
        };
        let map = TargetMap::new(target, r);
        Ok(Predictor {
            meta,
            roi_centroids,
            inner,
            map,
            phase: 0.0,
        })
    }

    /// Whether the model takes the respiratory phase as a fourth input (trained on a
    /// respiratory campaign).
    pub fn takes_phase(&self) -> bool {
        self.meta.input_columns.iter().any(|c| c == "phase")
    }

    /// The respiratory phase (0 exhalation .. 1 inspiration) at which later predictions are
    /// made; 0 (the paper's frame) until set. A model without a phase input ignores it.
    pub fn set_phase(&mut self, phase: f64) {
        self.phase = phase;
    }

    /// The phase of [`Predictor::set_phase`].
    pub fn phase(&self) -> f64 {
        self.phase
    }

    /// ROI maximum principal stress [Pa] for a finger at (`x`, `y`) [m] pressing with `force` [N]
    /// (at the phase of [`Predictor::set_phase`] for a model that takes one).
    /// Allocation-free; the slice is valid until the next call.
    pub fn predict(&mut self, x: f64, y: f64, force: f64) -> &[f64] {
        let inputs = [x, y, force, self.phase];
        self.map.apply(self.inner.predict_inputs(&inputs))
    }

    /// Like [`Predictor::predict`], plus the GP's predictive (latent) variance [Pa^2], shared
    /// by all raw outputs (for a tensor target, by every stress component); `None` for an MLP.
    /// Costs a little more than the mean alone.
    pub fn predict_with_variance(&mut self, x: f64, y: f64, force: f64) -> (&[f64], Option<f64>) {
        let (raw, var) = match &mut self.inner {
            PredictorImpl::Gp(g) => {
                let (m, v) = g.predict_with_variance(&[x, y, force, self.phase]);
                (m, Some(v))
            }
            PredictorImpl::Mlp(m) => (m.predict_inputs(&[x, y, force, self.phase]), None),
        };
        (self.map.apply(raw), var)
    }

    /// The GP's prior (latent) standard deviation [Pa], `s_y sigma_f`: the deviation it
    /// predicts far from every training input; `None` for an MLP.
    pub fn prior_deviation(&self) -> Option<f64> {
        let k = self.meta.kernel.as_ref()?;
        let s_y = self.meta.output_scaling.std.first().copied().unwrap_or(1.0);
        Some(k.signal_variance.max(0.0).sqrt() * s_y)
    }

    /// The model's metadata (kind, architecture, training report, ...).
    pub fn meta(&self) -> &ModelMeta {
        &self.meta
    }

    /// ROI element centroids, R x 3 [m].
    pub fn roi_centroids(&self) -> ArrayView2<'_, f64> {
        self.roi_centroids.view()
    }

    /// Number of ROI outputs R.
    pub fn n_outputs(&self) -> usize {
        self.meta.roi_ids.len()
    }
}
