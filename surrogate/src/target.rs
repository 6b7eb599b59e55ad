//! What a surrogate learns: the ROI's maximum principal stress itself, or the stress tensor it
//! comes from.
//!
//! - [`Target::Principal`] (the paper's): the model's R outputs are the maximum principal
//!   Cauchy stress of the R ROI elements, `Y` of the dataset.
//! - [`Target::Tensor`]: the model's 6R outputs are the six Cauchy components
//!   `[xx, yy, zz, xy, yz, zx]` of each ROI element (`S` of the dataset, element-major), and
//!   the prediction reported is their largest eigenvalue per element (`principal`), the same
//!   quantity as `Y`. The scores (Fit, paper eq. 5) are always on `Y`.
//!
//! Why a tensor target. The maximum principal stress is the largest root of each element's
//! characteristic cubic: a max over three smooth functions of the finger's position and force,
//! with a kink wherever two principal stresses cross and a principal direction that turns as the
//! hand moves. Interpolating the components and taking the eigenvalue afterwards keeps the
//! interpolated quantity smooth. On the default 3 mm campaign, with the test locations left
//! out, the GP scored 0.841 on Y and 0.911 on S over the 9 interior training locations each
//! left out in turn, and 0.800 and 0.881 over the 21 between two raster neighbours
//! (`python surrogate/scripts/model_probes.py data/default-campaign-3mm tensor`).

use crate::dataset::Dataset;
use crate::error::{Error, Result};
use crate::model_kind::ModelKind;
use crate::principal::max_principal_rows;
use ndarray::Array2;
use serde::{Deserialize, Serialize};

/// The quantity a model's outputs stand for (module doc).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Target {
    /// R outputs: ROI maximum principal stress [Pa].
    #[default]
    Principal,
    /// 6R outputs: ROI Cauchy stress components [Pa], reported as their largest eigenvalue.
    Tensor,
}

impl std::fmt::Display for Target {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Target::Principal => "principal",
            Target::Tensor => "tensor",
        })
    }
}

impl std::str::FromStr for Target {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s.to_ascii_lowercase().as_str() {
            "principal" => Ok(Target::Principal),
            "tensor" => Ok(Target::Tensor),
            other => Err(Error::invalid(
                "target",
                format!("{other:?}, expected principal or tensor"),
            )),
        }
    }
}

/// Stress component order a tensor target needs in the dataset's `S`.
pub const TENSOR_COMPONENTS: [&str; 6] = ["xx", "yy", "zz", "xy", "yz", "zx"];

impl Target {
    /// Model outputs for an ROI of `r` elements.
    pub fn n_outputs(self, r: usize) -> usize {
        match self {
            Target::Principal => r,
            Target::Tensor => 6 * r,
        }
    }

    /// The target a `kind` model trains on when none is asked for: the tensor for a GP when the
    /// dataset holds `S` (module doc), the principal stress otherwise (the paper's MLP).
    pub fn default_for(kind: ModelKind, data: &Dataset) -> Target {
        match kind {
            ModelKind::Gp if data.stress.is_some() => Target::Tensor,
            _ => Target::Principal,
        }
    }

    /// The training targets of `rows` of `data`: `Y` (n x R) or `S` flattened element-major
    /// (n x 6R). Fails, naming the field, when a tensor target meets a dataset without `S` or
    /// with its components in another order.
    pub fn training_targets(self, data: &Dataset, rows: &[usize]) -> Result<Array2<f64>> {
        match self {
            Target::Principal => Ok(data.y.select(ndarray::Axis(0), rows)),
            Target::Tensor => {
                let s = data.stress.as_ref().ok_or_else(|| {
                    Error::invalid(
                        "S",
                        "the dataset holds no stress tensors; train with --target principal",
                    )
                })?;
                let order = &data.manifest.stress_components;
                if order.iter().map(String::as_str).ne(TENSOR_COMPONENTS) {
                    return Err(Error::invalid(
                        "manifest.stress_components",
                        format!("{order:?}, a tensor target needs {TENSOR_COMPONENTS:?}"),
                    ));
                }
                let r = s.dim().1;
                Ok(Array2::from_shape_fn((rows.len(), 6 * r), |(i, j)| {
                    s[(rows[i], j / 6, j % 6)]
                }))
            }
        }
    }
}

/// Maps a model's raw outputs to the ROI maximum principal stress; owns its buffer, so it
/// never allocates per prediction.
#[derive(Clone, Debug)]
pub struct TargetMap {
    target: Target,
    out: Vec<f64>,
}

impl TargetMap {
    /// A map for `target` over an ROI of `r` elements.
    pub fn new(target: Target, r: usize) -> Self {
        let len = if target == Target::Tensor { r } else { 0 };
        TargetMap {
            target,
            out: vec![0.0; len],
        }
    }

    /// The target.
    pub fn target(&self) -> Target {
        self.target
    }

    /// ROI maximum principal stress [Pa] from raw outputs (R or 6R values).
    pub fn apply<'a>(&'a mut self, raw: &'a [f64]) -> &'a [f64] {
        match self.target {
            Target::Principal => raw,
            Target::Tensor => {
                max_principal_rows(raw, &mut self.out);
                &self.out
            }
        }
    }
}
