//! The options of `palpa train` and `palpa front` that choose which samples a model learns
//! from and which target: `--train-interval` and `--recover`.

use super::units;

/// `--train-interval TIME` and `--recover LENGTH`.
#[derive(clap::Args, Debug)]
pub struct SampleTargetArgs {
    /// Train on the samples at multiples of this interval only, with units (e.g. "5 ms", the
    /// paper's stamps) [default: every sample]. The test samples are all scored either way.
    #[arg(long, value_name = "TIME")]
    pub train_interval: Option<String>,
    /// Learn the recovered stress target instead of the element stress: each ROI element's
    /// maximum principal stress averaged over the ROI with weights exp(-d^2 / H^2) of this
    /// width H, with units (e.g. "5 mm"; standard deviation H / sqrt 2); scored against the
    /// recovered field (docs/surrogate.md).
    #[arg(long, value_name = "LENGTH")]
    pub recover: Option<String>,
    /// Train on x, y and force only, without a respiratory dataset's phase input (what the
    /// phase buys, on the same runs; the held-out samples are scored either way).
    #[arg(long)]
    pub ignore_phase: bool,
}

impl SampleTargetArgs {
    /// `--train-interval` in s.
    pub fn interval(&self) -> Result<Option<f64>, String> {
        self.train_interval
            .as_deref()
            .map(|v| units::time(v, "--train-interval"))
            .transpose()
    }

    /// `--recover` in m.
    pub fn recovery_width(&self) -> Result<Option<f64>, String> {
        self.recover
            .as_deref()
            .map(|v| units::length(v, "--recover"))
            .transpose()
    }
}
