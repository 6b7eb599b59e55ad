//! The options of `palpa train` and `palpa front` that choose which samples a model learns
//! from and which target (`--train-interval`, `--recover`, `--ignore-phase`), and how many rows
//! the GP's hyperparameter search takes (`--likelihood-rows`).

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
    /// GP: the most training rows the marginal likelihood of the hyperparameter search takes,
    /// an evenly strided subset of the distinct rows beyond it (the posterior conditions on
    /// every row either way; surrogate/src/gp/train.rs) [default: 600]. More rows cost
    /// O(N^3) a likelihood evaluation.
    #[arg(long, value_name = "N")]
    pub likelihood_rows: Option<usize>,
}

impl SampleTargetArgs {
    /// `--train-interval` in s.
    pub fn interval(&self) -> Result<Option<f64>, String> {
        self.train_interval
            .as_deref()
            .map(|v| units::time(v, "--train-interval"))
            .transpose()
    }

    /// `--likelihood-rows` set into `gp`, checked.
    pub fn set_likelihood_rows(&self, gp: &mut surrogate::gp::GpOptions) -> Result<(), String> {
        match self.likelihood_rows {
            Some(n) if n < 2 => Err(format!(
                "--likelihood-rows {n}: give at least 2 rows, e.g. 600 (the default)"
            )),
            Some(n) => {
                gp.max_likelihood_rows = n;
                Ok(())
            }
            None => Ok(()),
        }
    }

    /// What a model trained with these options learns and how, in one line that `palpa front`
    /// records beside each point: the target, the training samples, the GP's likelihood rows
    /// (`gp`, after [`Self::set_likelihood_rows`]) and whether the phase input is left out, e.g.
    /// `element stress; every sample; 600 likelihood rows`.
    pub fn settings(&self, gp: &surrogate::gp::GpOptions) -> Result<String, String> {
        // in mm or ms, shortest at 12 significant digits (a unit's conversion leaves no 1e-16)
        let short = |v: f64| {
            let v = v * 1e3;
            format!("{}", format!("{v:.11e}").parse::<f64>().unwrap_or(v))
        };
        let mut s = match self.recovery_width()? {
            Some(h) => format!("recovered H = {} mm", short(h)),
            None => "element stress".into(),
        };
        match self.interval()? {
            Some(dt) => s += &format!("; samples every {} ms", short(dt)),
            None => s += "; every sample",
        }
        s += &format!("; {} likelihood rows", gp.max_likelihood_rows);
        if self.ignore_phase {
            s += "; phase ignored";
        }
        Ok(s)
    }

    /// `--recover` in m.
    pub fn recovery_width(&self) -> Result<Option<f64>, String> {
        self.recover
            .as_deref()
            .map(|v| units::length(v, "--recover"))
            .transpose()
    }
}
