//! Scene tables for rigid indenters, hands and contact settings (placeholder; being written).

use serde::Deserialize;

/// `[[indenter]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IndenterScene {}

/// `[[hand]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HandScene {}

/// `[contact]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactScene {}
