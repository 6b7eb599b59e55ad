//! Gaussian-process fitting: hyperparameters by maximising the marginal likelihood with L-BFGS
//! on the log-parameters, from a default start and a few random restarts drawn from a fixed seed.
//!
//! **Repeated targets are counted once in the likelihood.** A campaign's dataset has one row at
//! t = 0 per location: zero force and the unloaded stress, the same target row 25 times over at
//! 25 different (x, y). Counted 25 times, those rows reward a near-zero noise variance without
//! bound. Noise sn2 gives a block of m identical rows a log-determinant of about
//! (m - 1) ln sn2. Maximising the likelihood then met that block with a force length scale at
//! its lower bound (0.01) and sn2 = 5e-6. Every other sample became uncorrelated with the rest.
//! On the 25 mm-fat paper campaign that gave a training Fit of 0.999 and a held-out Fit of 0.15.
//! So the hyperparameters maximise the likelihood of the rows whose target row differs from
//! every earlier row's, the first occurrence kept. On that campaign this is 126 of 150 rows, and
//! the optimiser lands on length scales 0.99, 0.74, 1.41 (x, y, force) and sn2 = 0.055, held-out
//! Fit 0.665. The posterior (`alpha`, `K^-1`) then conditions on every training row with those
//! hyperparameters.
//!
//! **At most [`GpOptions::max_likelihood_rows`] rows in the likelihood.** Each likelihood
//! evaluation factorises an n x n matrix and solves for every output: O(n^3 + n^2 M). A
//! campaign sampled every millisecond (26 samples a run) with 100 runs has 2,600 rows, and
//! the search would take hours on 2 cores. Beyond the cap, the hyperparameters maximise the
//! likelihood of an evenly strided subset of the distinct rows (every k-th in dataset order,
//! so every location and time keeps its share); the posterior still conditions on every row.
//! This is the subset-of-data approximation for hyperparameters (Rasmussen and Williams 2006,
//! section 8.3.3). The cap (600) is far above the paper-protocol campaigns' 126-150 rows, which
//! it leaves as they were.
//!
//! **Output basis.** The predictive mean of all M outputs, `mu + s A^T k*` with `A = K^-1 V`
//! (n x M), costs n M multiply-adds. With the thin singular value decomposition of the
//! normalised targets, `V = U Sigma W^T`, every row of `A` lies in the row space of `V`, so
//! `A = (A W) W^T` exactly, and keeping only the leading r right singular vectors `W_r` gives
//! `A ~ (A W_r) W_r^T`: the mean becomes `mu + s W_r ((A W_r)^T k*)`, r (n + M) multiply-adds,
//! the projection of the exact mean on the training targets' leading r output directions (the
//! principal-component output basis of Higdon, Gattiker, Williams & Rightley, "Computer model
//! calibration using high-dimensional output", JASA 103, 2008). r is the smallest rank whose
//! dropped energy `sum_(i > r) sigma_i^2 / sum_i sigma_i^2` is at most
//! [`GpOptions::output_tolerance`], and the basis is kept only when it costs less than `A`.
//! On the default 3 mm campaign's 6 x 377 tensor components (150 rows), a tolerance of 1e-4
//! keeps about 35 directions and cuts the mean's cost about 4 times; the held-out Fit moves by
//! less than 1e-3 (docs/surrogate.md). The variance does not use `A` and is exact.

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
    /// Largest fraction of the normalised targets' energy the output basis may drop (module
    /// doc); 0 keeps every direction (the exact posterior mean).
    pub output_tolerance: f64,
    /// Most rows the hyperparameter search's likelihood takes (module doc).
    pub max_likelihood_rows: usize,
}

impl Default for GpOptions {
    fn default() -> Self {
        GpOptions {
            restarts: 3,
            seed: 7,
            max_iterations: 200,
            output_tolerance: 1e-4,
            max_likelihood_rows: 600,
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
    /// Coefficients of the mean: `A W_r`, n x r, or `A = K^-1 V`, n x M, without a basis.
    pub coef: Array2<f64>,
    /// Output basis `W_r^T`, r x M (module doc), when it is cheaper than `A`.
    pub basis: Option<Array2<f64>>,
    /// Fraction of the normalised training targets' energy outside the basis (0 without one).
    pub dropped_energy: f64,
    /// `K^-1`, n x n, for the predictive variance.
    pub k_inv: Array2<f64>,
    /// Log marginal likelihood per target at the optimum (over the likelihood's rows).
    pub log_marginal_likelihood: f64,
    /// Training rows the likelihood was taken over: those with distinct targets, at most
    /// [`GpOptions::max_likelihood_rows`] (module doc).
    pub likelihood_rows: usize,
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
    // the likelihood's rows: first occurrences of each distinct target row (module doc)
    let mut distinct = distinct_rows(&vm);
    let cap = opts.max_likelihood_rows.max(2);
    if distinct.len() > cap {
        let m = distinct.len();
        distinct = (0..cap).map(|k| distinct[k * m / cap]).collect();
    }
    let subset = (distinct.len() < n).then(|| {
        let u = DMatrix::from_fn(distinct.len(), nd, |i, j| um[(distinct[i], j)]);
        let v = DMatrix::from_fn(distinct.len(), vm.ncols(), |i, j| vm[(distinct[i], j)]);
        (PairwiseSquares::compute(&u), v)
    });
    let (pw_l, vm_l) = subset.as_ref().map_or((&pw, &vm), |(p, v)| (p, v));

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
            |t| compute_nll_and_gradient(t, pw_l, vm_l),
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
    let (coef, basis, dropped_energy) = match compute_output_basis(&vm, opts.output_tolerance) {
        Some((w_t, dropped)) => (
            to_nd(&(&f.alpha * w_t.transpose())),
            Some(to_nd(&w_t)),
            dropped,
        ),
        None => (to_nd(&f.alpha), None, 0.0),
    };
    Ok(GpModel {
        kernel,
        input_scaling,
        output_scaling,
        train_inputs: u,
        coef,
        basis,
        dropped_energy,
        k_inv: to_nd(&f.k_inv),
        log_marginal_likelihood: -nll,
        likelihood_rows: distinct.len(),
    })
}

/// The leading right singular vectors of `v` (n x M) as rows, `W_r^T` (r x M), and the dropped
/// energy fraction, for the smallest r that drops at most `tolerance` (module doc); `None` when
/// such a basis would cost no less than the full coefficients (r (n + M) >= n M), or when the
/// decomposition fails.
fn compute_output_basis(v: &DMatrix<f64>, tolerance: f64) -> Option<(DMatrix<f64>, f64)> {
    let (n, m) = v.shape();
    if !(tolerance > 0.0) || n == 0 || m == 0 {
        return None;
    }
    // `svd` sorts the singular values in descending order (nalgebra's guarantee)
    let svd = v.clone().svd(false, true);
    let w_t = svd.v_t?;
    let energy: Vec<f64> = svd.singular_values.iter().map(|s| s * s).collect();
    let total: f64 = energy.iter().sum();
    if !(total > 0.0) {
        return None;
    }
    let mut kept = 0.0;
    let mut r = energy.len();
    for (i, e) in energy.iter().enumerate() {
        kept += e;
        if (total - kept) / total <= tolerance {
            r = i + 1;
            break;
        }
    }
    if r * (n + m) >= n * m {
        return None;
    }
    Some((
        w_t.rows(0, r).into_owned(),
        ((total - kept) / total).max(0.0),
    ))
}

/// Indices of the rows of `v` that differ from every earlier row (exact comparison).
fn distinct_rows(v: &DMatrix<f64>) -> Vec<usize> {
    let mut seen = std::collections::HashSet::new();
    (0..v.nrows())
        .filter(|&i| seen.insert(v.row(i).iter().map(|x| x.to_bits()).collect::<Vec<u64>>()))
        .collect()
}
