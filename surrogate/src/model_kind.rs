//! The surrogate families ([`ModelKind`]): what a model file, a training report and the
//! choice of training target name.

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// The surrogate families.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ModelKind {
    /// Multilayer perceptron.
    Mlp,
    /// Gaussian process.
    Gp,
}

impl std::fmt::Display for ModelKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            ModelKind::Mlp => "mlp",
            ModelKind::Gp => "gp",
        })
    }
}

impl std::str::FromStr for ModelKind {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s.to_ascii_lowercase().as_str() {
            "mlp" => Ok(ModelKind::Mlp),
            "gp" => Ok(ModelKind::Gp),
            other => Err(Error::invalid(
                "model kind",
                format!("{other:?}, expected mlp or gp"),
            )),
        }
    }
}
