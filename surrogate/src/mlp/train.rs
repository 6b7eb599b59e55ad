//! MLP training: full-batch gradient descent with momentum and an adaptive learning rate
//! (after MATLAB's `traingdx`, the paper's trainer), or Adam (full or mini-batch).
//!
//! `traingdx` as documented by MathWorks: each step is `dX = mc dX_prev - lr mc g` (g the
//! gradient of the loss); if the new loss exceeds the old one by more than `max_perf_inc`
//! (1.04) the step is discarded, the learning rate multiplied by `lr_dec` (0.7) and the momentum
//! history cleared; otherwise the step is kept, and if the loss fell the learning rate is
//! multiplied by `lr_inc` (1.05). Defaults `lr = 0.01`, `mc = 0.9`.
//!
//! Adam: D. P. Kingma and J. Ba, "Adam: a method for stochastic optimization", ICLR 2015,
//! Algorithm 1, optionally with decoupled weight decay (I. Loshchilov and F. Hutter, "Decoupled
//! weight decay regularization", ICLR 2019), and with the learning rate decayed geometrically from `lr` to `lr_final` over the
//! epochs.
//!
//! Every run is reproducible: the seed fixes the initial weights and the mini-batch order, and
//! the GEMMs run on one thread.

use super::network::{backward_batch, compute_loss, forward_batch, BatchWorkspace, MlpParams};
use crate::error::{Error, Result};
use crate::normalise::Scaling;
use crate::rng::Rng;
use ndarray::ArrayView2;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// The paper's hidden layer sizes.
pub const PAPER_HIDDEN: [usize; 4] = [64, 126, 256, 512];

/// `traingdx` settings (MATLAB's defaults).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct GdxOptions {
    /// Initial learning rate.
    pub lr: f64,
    /// Learning-rate factor after a step that lowered the loss.
    pub lr_inc: f64,
    /// Learning-rate factor after a rejected step.
    pub lr_dec: f64,
    /// Largest accepted ratio of new to old loss.
    pub max_perf_inc: f64,
    /// Momentum constant mc.
    pub momentum: f64,
    /// L2 penalty `lambda/2 * sum w^2` on the weights (not biases), added to the loss that the
    /// accept/reject test compares (MATLAB's `performParam.regularization` plays this role).
    pub l2: f64,
}

impl Default for GdxOptions {
    fn default() -> Self {
        GdxOptions {
            lr: 0.01,
            lr_inc: 1.05,
            lr_dec: 0.7,
            max_perf_inc: 1.04,
            momentum: 0.9,
            l2: 1e-4,
        }
    }
}

/// Adam settings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct AdamOptions {
    /// Initial learning rate.
    pub lr: f64,
    /// Learning rate reached at the last epoch (geometric decay).
    pub lr_final: f64,
    /// First-moment decay.
    pub beta1: f64,
    /// Second-moment decay.
    pub beta2: f64,
    /// Denominator guard.
    pub eps: f64,
    /// Mini-batch size; `None` for full batch.
    pub batch_size: Option<usize>,
    /// Decoupled weight decay per unit learning rate (AdamW; weights only, not biases).
    pub weight_decay: f64,
}

impl Default for AdamOptions {
    fn default() -> Self {
        AdamOptions {
            lr: 2e-3,
            lr_final: 2e-5,
            beta1: 0.9,
            beta2: 0.999,
            eps: 1e-8,
            batch_size: None,
            weight_decay: 1.0,
        }
    }
}

/// Which optimiser trains the MLP.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Optimiser {
    /// Gradient descent with momentum and adaptive learning rate (the paper's).
    Gdx(GdxOptions),
    /// Adam.
    Adam(AdamOptions),
}

/// MLP architecture and training settings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct MlpOptions {
    /// Hidden layer sizes (the paper's: 64, 126, 256, 512).
    pub hidden: Vec<usize>,
    /// Optimiser and its settings.
    pub optimiser: Optimiser,
    /// Number of epochs (passes over the training set).
    pub epochs: usize,
    /// Seed of the initial weights and batch order.
    pub seed: u64,
    /// Wall-clock limit of the training loop [s]; training stops early past it.
    pub max_seconds: f64,
}

impl Default for MlpOptions {
    fn default() -> Self {
        MlpOptions {
            hidden: PAPER_HIDDEN.to_vec(),
            optimiser: Optimiser::Adam(AdamOptions::default()),
            epochs: 3000,
            seed: 42,
            max_seconds: 110.0,
        }
    }
}

/// A trained MLP in normalised units plus its scalings.
#[derive(Clone, Debug)]
pub struct MlpModel {
    /// Weights and biases.
    pub params: MlpParams,
    /// Input scaling (physical -> normalised).
    pub input_scaling: Scaling,
    /// Output scaling (normalised -> physical).
    pub output_scaling: Scaling,
    /// Epochs actually run.
    pub epochs_run: usize,
    /// Final training loss (mean squared error, normalised units).
    pub final_loss: f64,
}

/// Trains an MLP on inputs `x` (n x D, physical) and targets `y` (n x R, physical).
pub fn train_mlp(x: ArrayView2<f64>, y: ArrayView2<f64>, opts: &MlpOptions) -> Result<MlpModel> {
    let (n, nd) = x.dim();
    if n == 0 {
        return Err(Error::invalid("X", "no training samples"));
    }
    if y.nrows() != n {
        return Err(Error::invalid(
            "Y",
            format!("has {} rows, X has {n}", y.nrows()),
        ));
    }
    if opts.hidden.iter().any(|&h| h == 0) {
        return Err(Error::invalid(
            "MlpOptions.hidden",
            "a hidden layer has size 0",
        ));
    }
    let r = y.ncols();
    let input_scaling = Scaling::compute_zscore(x);
    let output_scaling = Scaling::compute_pooled(y);
    let u: Vec<f32> = input_scaling
        .compute_forward(x)
        .iter()
        .map(|&v| v as f32)
        .collect();
    let v: Vec<f32> = output_scaling
        .compute_forward(y)
        .iter()
        .map(|&v| v as f32)
        .collect();
    let mut sizes = vec![nd];
    sizes.extend(&opts.hidden);
    sizes.push(r);
    let mut params = MlpParams::new_random(&sizes, opts.seed);
    let start = Instant::now();
    let (epochs_run, final_loss) = match &opts.optimiser {
        Optimiser::Gdx(g) => run_gdx(&mut params, &u, &v, n, g, opts, start)?,
        Optimiser::Adam(a) => run_adam(&mut params, &u, &v, n, a, opts, start)?,
    };
    Ok(MlpModel {
        params,
        input_scaling,
        output_scaling,
        epochs_run,
        final_loss,
    })
}

fn run_gdx(
    p: &mut MlpParams,
    u: &[f32],
    v: &[f32],
    n: usize,
    g: &GdxOptions,
    opts: &MlpOptions,
    start: Instant,
) -> Result<(usize, f64)> {
    let mut ws = BatchWorkspace::new(&p.sizes, n);
    ws.h[0].copy_from_slice(u);
    let mut grad = p.zeros_like();
    let mut step = p.zeros_like();
    let mut trial = p.clone();
    let penalty = |q: &MlpParams| {
        0.5 * g.l2
            * q.weights
                .iter()
                .flatten()
                .map(|w| (w * w) as f64)
                .sum::<f64>()
    };
    let add_l2 = |q: &MlpParams, gr: &mut MlpParams| {
        if g.l2 > 0.0 {
            for (gw, w) in gr.weights.iter_mut().zip(&q.weights) {
                for (a, b) in gw.iter_mut().zip(w) {
                    *a += g.l2 as f32 * b;
                }
            }
        }
    };
    forward_batch(p, &mut ws);
    let mut loss = compute_loss(p, &ws, v) + penalty(p);
    backward_batch(p, &mut ws, v, &mut grad);
    add_l2(p, &mut grad);
    let mut lr = g.lr;
    let mc = g.momentum;
    let mut epochs = 0;
    while epochs < opts.epochs && start.elapsed().as_secs_f64() < opts.max_seconds {
        epochs += 1;
        // dX = mc dX_prev - lr mc g ; X_trial = X + dX
        for ((s, gr), (t, x)) in step
            .slices_mut()
            .zip(grad.slices())
            .zip(trial.slices_mut().zip(p.slices()))
        {
            for (((si, gi), ti), xi) in s.iter_mut().zip(gr).zip(t.iter_mut()).zip(x) {
                *si = (mc * *si as f64 - lr * mc * *gi as f64) as f32;
                *ti = xi + *si;
            }
        }
        forward_batch(&trial, &mut ws);
        let new_loss = compute_loss(&trial, &ws, v) + penalty(&trial);
        if !new_loss.is_finite() || new_loss > loss * g.max_perf_inc {
            lr *= g.lr_dec;
            step.slices_mut()
                .for_each(|s| s.iter_mut().for_each(|x| *x = 0.0));
            continue;
        }
        if new_loss < loss {
            lr *= g.lr_inc;
        }
        std::mem::swap(p, &mut trial);
        loss = new_loss;
        backward_batch(p, &mut ws, v, &mut grad);
        add_l2(p, &mut grad);
    }
    check_finite(loss)?;
    Ok((epochs, loss))
}

fn run_adam(
    p: &mut MlpParams,
    u: &[f32],
    v: &[f32],
    n: usize,
    a: &AdamOptions,
    opts: &MlpOptions,
    start: Instant,
) -> Result<(usize, f64)> {
    let nd = p.sizes[0];
    let r = *p.sizes.last().unwrap_or(&0);
    let b = a.batch_size.unwrap_or(n).clamp(1, n);
    let mut ws_full = BatchWorkspace::new(&p.sizes, b);
    let rem = n % b;
    let mut ws_rem = BatchWorkspace::new(&p.sizes, rem.max(1));
    let mut target_full = vec![0.0f32; b * r];
    let mut target_rem = vec![0.0f32; rem.max(1) * r];
    let mut grad = p.zeros_like();
    let mut m1 = p.zeros_like();
    let mut m2 = p.zeros_like();
    let mut order: Vec<usize> = (0..n).collect();
    let mut rng = Rng::new(opts.seed ^ 0xA5A5);
    let decay = if opts.epochs > 1 && a.lr_final > 0.0 {
        (a.lr_final / a.lr).powf(1.0 / (opts.epochs - 1) as f64)
    } else {
        1.0
    };
    let mut t = 0i32;
    let mut epochs = 0;
    let mut lr = a.lr;
    while epochs < opts.epochs && start.elapsed().as_secs_f64() < opts.max_seconds {
        epochs += 1;
        if b < n {
            rng.shuffle(&mut order);
        }
        for chunk in order.chunks(b) {
            let (ws, target) = if chunk.len() == b {
                (&mut ws_full, &mut target_full)
            } else {
                (&mut ws_rem, &mut target_rem)
            };
            for (k, &i) in chunk.iter().enumerate() {
                ws.h[0][k * nd..(k + 1) * nd].copy_from_slice(&u[i * nd..(i + 1) * nd]);
                target[k * r..(k + 1) * r].copy_from_slice(&v[i * r..(i + 1) * r]);
            }
            forward_batch(p, ws);
            backward_batch(p, ws, target, &mut grad);
            t += 1;
            let c1 = 1.0 - a.beta1.powi(t);
            let c2 = 1.0 - a.beta2.powi(t);
            let step = (lr * c2.sqrt() / c1) as f32;
            let (b1, b2, eps) = (a.beta1 as f32, a.beta2 as f32, (a.eps * c2.sqrt()) as f32);
            if a.weight_decay > 0.0 {
                let keep = (1.0 - lr * a.weight_decay) as f32;
                p.weights.iter_mut().flatten().for_each(|w| *w *= keep);
            }
            for (((x, gr), mm), vv) in p
                .slices_mut()
                .zip(grad.slices())
                .zip(m1.slices_mut())
                .zip(m2.slices_mut())
            {
                for (((xi, gi), mi), vi) in
                    x.iter_mut().zip(gr).zip(mm.iter_mut()).zip(vv.iter_mut())
                {
                    *mi = b1 * *mi + (1.0 - b1) * gi;
                    *vi = b2 * *vi + (1.0 - b2) * gi * gi;
                    *xi -= step * *mi / (vi.sqrt() + eps);
                }
            }
        }
        lr *= decay;
    }
    // final full-batch loss
    let mut ws = BatchWorkspace::new(&p.sizes, n);
    ws.h[0].copy_from_slice(u);
    forward_batch(p, &mut ws);
    let loss = compute_loss(p, &ws, v);
    check_finite(loss)?;
    Ok((epochs, loss))
}

fn check_finite(loss: f64) -> Result<()> {
    if loss.is_finite() {
        Ok(())
    } else {
        Err(Error::numerical(
            "MLP training",
            "the loss diverged (non-finite)",
        ))
    }
}
