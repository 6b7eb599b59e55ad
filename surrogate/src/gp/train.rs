//! Gaussian-process fitting: hyperparameters by maximising the marginal likelihood with L-BFGS
//! on the log-parameters, from a default start and a few random restarts drawn from a fixed seed.

use super::kernel::SeArd;
use super::likelihood::{compute_factorised, compute_nll_and_gradient, PairwiseSquares};
use crate::error::{Error, Result};
use crate::lbfgs::{minimise, LbfgsOptions};
use crate::normalise::Scaling;
use crate::rng::Rng;
use nalgebra::DMatrix;
use ndarray::{Array2, ArrayView2};
use serde::{Deserialize, Serialize};

/// Settings of the GP fit.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct GpOptions {
    /// Random restarts in addition to the default start (length scales 1, s2 = 1, sn2 = 1e-2).
    pub restarts: usize,
    /// Seed of the restart draws.
    pub seed: u64,
    /// L-BFGS iterations per start.
    pub max_iterations: usize,
}

impl Default for GpOptions {
    fn default() -> Self {
        GpOptions {
            restarts: 3,
            seed: 7,
            max_iterations: 200,
        }
    }
}

/// A fitted GP: everything prediction needs, in normalised units.
#[derive(Clone, Debug)]
pub struct GpModel {
    /// Kernel hyperparameters (normalised units).
    pub kernel: SeArd,
    /// Input scaling (physical -> normalised).
    pub input_scaling: Scaling,
    /// Output scaling (normalised -> physical).
    pub output_scaling: Scaling,
    /// Normalised training inputs, n x D.
    pub train_inputs: Array2<f64>,
    /// `K^-1 V`, n x R.
    pub alpha: Array2<f64>,
    /// `K^-1`, n x n, for the predictive variance.
    pub k_inv: Array2<f64>,
    /// Log marginal likelihood per target at the optimum.
    pub log_marginal_likelihood: f64,
}

/// Fits a GP to inputs `x` (n x D, physical) and targets `y` (n x R, physical).
pub fn fit_gp(x: ArrayView2<f64>, y: ArrayView2<f64>, opts: &GpOptions) -> Result<GpModel> {
    let (n, nd) = x.dim();
    if n < 2 {
        return Err(Error::invalid(
            "X",
            format!("GP needs at least 2 training samples, got {n}"),
        ));
    }
    if y.nrows() != n {
        return Err(Error::invalid(
            "Y",
            format!("has {} rows, X has {n}", y.nrows()),
        ));
    }
    let input_scaling = Scaling::compute_zscore(x);
    let output_scaling = Scaling::compute_pooled(y);
    let u = input_scaling.compute_forward(x);
    let v = output_scaling.compute_forward(y);
    let um = DMatrix::from_fn(n, nd, |i, j| u[(i, j)]);
    let vm = DMatrix::from_fn(n, y.ncols(), |i, j| v[(i, j)]);
    let pw = PairwiseSquares::compute(&um);

    let mut bounds = vec![(0.01f64.ln(), 100.0f64.ln()); nd];
    bounds.push((1e-4f64.ln(), 1e4f64.ln()));
    bounds.push((1e-8f64.ln(), 10.0f64.ln()));
    let mut starts = vec![{
        let mut t = vec![0.0; nd];
        t.push(0.0);
        t.push(1e-2f64.ln());
        t
    }];
    let mut rng = Rng::new(opts.seed);
    for _ in 0..opts.restarts {
        let mut t: Vec<f64> = (0..nd)
            .map(|_| rng.uniform_in(0.2f64.ln(), 5.0f64.ln()))
            .collect();
        t.push(rng.uniform_in(0.1f64.ln(), 10.0f64.ln()));
        t.push(rng.uniform_in(1e-5f64.ln(), 1e-1f64.ln()));
        starts.push(t);
    }
    let lopts = LbfgsOptions {
        max_iterations: opts.max_iterations,
        ..Default::default()
    };
    let mut best: Option<(Vec<f64>, f64)> = None;
    for s in &starts {
        let r = minimise(
            |t| compute_nll_and_gradient(t, &pw, &vm),
            s,
            &bounds,
            &lopts,
        );
        if let Some((t, f)) = r {
            if best.as_ref().map_or(true, |b| f < b.1) {
                best = Some((t, f));
            }
        }
    }
    let (theta, nll) = best.ok_or_else(|| {
        Error::numerical("GP fit", "kernel matrix not positive definite at any start")
    })?;
    let kernel = SeArd::from_log_params(&theta);
    let f = compute_factorised(&kernel, &pw, &vm)
        .ok_or_else(|| Error::numerical("GP fit", "final kernel matrix not positive definite"))?;
    let to_nd =
        |m: &DMatrix<f64>| Array2::from_shape_fn((m.nrows(), m.ncols()), |(i, j)| m[(i, j)]);
    Ok(GpModel {
        kernel,
        input_scaling,
        output_scaling,
        train_inputs: u,
        alpha: to_nd(&f.alpha),
        k_inv: to_nd(&f.k_inv),
        log_marginal_likelihood: -nll,
    })
}
