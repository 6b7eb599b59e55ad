//! `palpa train DATASET --model mlp|gp --out MODEL`: train a stress surrogate on a palpation
//! dataset, print its Fit (paper eq. 5) on the held-out test locations (split 1), per location
//! and overall, with the training time and the serving latency, and save the model as
//! safetensors + JSON metadata.
//!
//! Training, scoring and saving are [`surrogate::train`]'s; this module only maps the command
//! line onto [`surrogate::TrainOptions`] and checks the paths first, so that a wrong path gets a
//! message naming it. Beside the model it writes the plan-view geometry (`view.json`, see
//! [`super::view_geometry`]) when the dataset comes from a phantom, so that the model can be
//! drawn and served without the solver.

use surrogate::mlp::{AdamOptions, GdxOptions, Optimiser};
use surrogate::model::model_paths;
use surrogate::{ModelKind, Target, TrainOptions};

use std::path::{Path, PathBuf};

/// The model family, as `--model` spells it.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum ModelArg {
    /// The paper's multilayer perceptron (3-64-126-256-512-R, ReLU).
    Mlp,
    /// Gaussian process with one SE-ARD kernel shared by all ROI outputs.
    Gp,
}

impl From<ModelArg> for ModelKind {
    fn from(m: ModelArg) -> ModelKind {
        match m {
            ModelArg::Mlp => ModelKind::Mlp,
            ModelArg::Gp => ModelKind::Gp,
        }
    }
}

/// The MLP optimiser, as `--optimizer` spells it.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum OptimizerArg {
    /// Gradient descent with momentum and adaptive learning rate (MATLAB's traingdx, the paper's).
    Gdx,
    /// Adam with a geometrically decaying learning rate.
    Adam,
}

/// What the model learns, as `--target` spells it.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum TargetArg {
    /// The ROI's maximum principal stress itself (the paper's target, Y).
    Principal,
    /// The ROI's six Cauchy stress components (S); predictions report their largest eigenvalue.
    Tensor,
}

impl From<TargetArg> for Target {
    fn from(t: TargetArg) -> Target {
        match t {
            TargetArg::Principal => Target::Principal,
            TargetArg::Tensor => Target::Tensor,
        }
    }
}

/// `palpa train`'s arguments.
#[derive(clap::Args)]
pub struct TrainArgs {
    /// The dataset: a directory holding dataset.npz + manifest.json, or NAME.npz beside
    /// NAME.json. Split-0 samples train, split-1 samples (held-out locations) are scored.
    pub dataset: PathBuf,
    /// Model family.
    #[arg(long, value_enum)]
    pub model: ModelArg,
    /// Where to save the model: a directory (model.safetensors + model.json) or
    /// NAME.safetensors (beside NAME.json).
    #[arg(long)]
    pub out: PathBuf,
    /// What the model learns [default: tensor for a GP on a dataset with stress tensors,
    /// principal otherwise]. Either way it predicts, and is scored on, the ROI's maximum
    /// principal stress.
    #[arg(long, value_enum)]
    pub target: Option<TargetArg>,
    /// MLP optimiser.
    #[arg(long, value_enum, default_value = "adam")]
    pub optimizer: OptimizerArg,
    /// MLP epochs [default: 3000; training stops early past 110 s].
    #[arg(long)]
    pub epochs: Option<usize>,
    /// Seed of the MLP's initial weights and batch order, and of the GP's restarts
    /// [default: 42 (MLP), 7 (GP)].
    #[arg(long)]
    pub seed: Option<u64>,
    /// MLP hidden layer widths, comma-separated [default: the paper's 64,126,256,512].
    #[arg(long, value_delimiter = ',')]
    pub hidden: Option<Vec<usize>>,
    /// GP: random restarts of the marginal-likelihood search besides the default start
    /// [default: 3].
    #[arg(long)]
    pub restarts: Option<usize>,
    /// GP: the largest fraction of the normalised training targets' energy that the mean's
    /// output basis may drop (the accuracy-versus-latency knob of the GP's serving cost)
    /// [default: 1e-4]; 0 keeps every output direction, the exact posterior mean.
    #[arg(long)]
    pub output_tolerance: Option<f64>,
    /// Train on the first N training locations only, in the dataset's (the campaign's) order:
    /// the first N points of a Sobol design are themselves a design [default: all].
    #[arg(long, value_name = "N")]
    pub train_locations: Option<usize>,
    /// Leave these training locations out, by label, comma-separated (after
    /// --train-locations): what a run does to the model, e.g. `--train-locations 60 --leave-out
    /// ad05-08`.
    #[arg(long, value_name = "LABEL,..", value_delimiter = ',')]
    pub leave_out: Vec<String>,
    #[command(flatten)]
    pub sample_target: super::selection::SampleTargetArgs,
    /// Worker threads of the global pool [default: all cores]. The trainers themselves run on
    /// one thread, so that a seed gives the same model on any machine.
    #[arg(long)]
    pub threads: Option<usize>,
}

/// A dataset path that does not exist gets a message naming it and saying what is expected.
pub fn check_dataset_path(path: &Path) -> Result<(), String> {
    let (npz, json) = surrogate::dataset::dataset_paths(path);
    if !path.exists() {
        return Err(format!(
            "dataset {}: no such file or directory (expected a directory holding dataset.npz and \
             manifest.json, or NAME.npz beside NAME.json)",
            path.display()
        ));
    }
    for f in [&npz, &json] {
        if !f.is_file() {
            return Err(format!(
                "dataset {}: {} is missing",
                path.display(),
                f.display()
            ));
        }
    }
    Ok(())
}

/// The training options the flags ask for, on top of the crate's defaults.
fn options(a: &TrainArgs) -> Result<TrainOptions, String> {
    let mut opts = TrainOptions::default();
    let mlp = &mut opts.mlp;
    mlp.optimiser = match a.optimizer {
        OptimizerArg::Gdx => Optimiser::Gdx(GdxOptions::default()),
        OptimizerArg::Adam => Optimiser::Adam(AdamOptions::default()),
    };
    if let Some(e) = a.epochs {
        if e == 0 {
            return Err("--epochs must be at least 1".into());
        }
        mlp.epochs = e;
    }
    if let Some(h) = &a.hidden {
        if h.is_empty() || h.contains(&0) {
            return Err(format!(
                "--hidden {h:?}: give one or more positive layer widths, e.g. 64,126,256,512"
            ));
        }
        mlp.hidden = h.clone();
    }
    if let Some(s) = a.seed {
        mlp.seed = s;
        opts.gp.seed = s;
    }
    if let Some(r) = a.restarts {
        opts.gp.restarts = r;
    }
    if let Some(t) = a.output_tolerance {
        if !(0.0..1.0).contains(&t) {
            return Err(format!(
                "--output-tolerance {t}: give a fraction in [0, 1), e.g. 1e-4 (0 = exact mean)"
            ));
        }
        opts.gp.output_tolerance = t;
    }
    if a.sample_target.likelihood_rows.is_some() && matches!(a.model, ModelArg::Mlp) {
        return Err(
            "--likelihood-rows sets the GP's hyperparameter search: give it with --model gp".into(),
        );
    }
    a.sample_target.set_likelihood_rows(&mut opts.gp)?;
    opts.target = a.target.map(Target::from);
    Ok(opts)
}

/// Train, report and save.
pub fn train(a: &TrainArgs) -> Result<(), String> {
    super::set_threads(a.threads)?;
    check_dataset_path(&a.dataset)?;
    let opts = options(a)?;
    let kind = ModelKind::from(a.model);
    let what = match kind {
        ModelKind::Mlp => {
            let opt = match a.optimizer {
                OptimizerArg::Gdx => "traingdx",
                OptimizerArg::Adam => "Adam",
            };
            format!(
                "MLP, hidden {:?}, {opt}, {} epochs at most ({:.0} s cap), seed {}",
                opts.mlp.hidden, opts.mlp.epochs, opts.mlp.max_seconds, opts.mlp.seed
            )
        }
        ModelKind::Gp => format!(
            "GP, SE-ARD kernel by marginal likelihood, {} restart(s), seed {}",
            opts.gp.restarts, opts.gp.seed
        ),
    };
    let target = match a.target {
        Some(t) => Target::from(t).to_string(),
        None => "default".into(),
    };
    eprintln!(
        "palpa train: {what}, {target} target, on {} ...",
        a.dataset.display()
    );
    let interval = a.sample_target.interval()?;
    if a.train_locations == Some(0) {
        return Err("--train-locations must be at least 1".into());
    }
    let recovery_width = a.sample_target.recovery_width()?;
    if recovery_width.is_some() && matches!(a.target, Some(TargetArg::Tensor)) {
        return Err("--recover averages the principal stress: it takes no --target tensor".into());
    }
    let selection = surrogate::TrainingSelection {
        first_locations: a.train_locations,
        interval,
        recovery_width,
        ignore_phase: a.sample_target.ignore_phase,
        leave_out: a.leave_out.clone(),
    };
    let report = surrogate::train_selected(&a.dataset, &selection, kind, &opts, &a.out)
        .map_err(|e| format!("train {}: {e}", a.dataset.display()))?;
    println!("Fit = 1 - sqrt(SSE / SST), paper eq. 5 (1 perfect, 0 no better than the mean)");
    println!("{report}");
    println!("training time: {:.2} s", report.train_seconds);
    let (st, js) = model_paths(&a.out);
    println!("saved {} and {}", st.display(), js.display());
    write_view(&a.dataset, &a.out)
}

/// The dataset's plan-view geometry beside the model at `model`, if it has one.
fn write_view(dataset: &Path, model: &Path) -> Result<(), String> {
    let t0 = std::time::Instant::now();
    match super::view_geometry::for_dataset(dataset)? {
        Some(view) => {
            let path = surrogate::view::view_path(model);
            view.write(&path)
                .map_err(|e| format!("{}: {e}", path.display()))?;
            println!(
                "saved {} (plan geometry: {} liver and {} rib outline(s), {} ROI cells; {:.1} s)",
                path.display(),
                view.liver.len(),
                view.ribs.len(),
                view.roi_cells.len(),
                t0.elapsed().as_secs_f64()
            );
        }
        None => println!(
            "no plan geometry: the dataset names no phantom (predict --png draws the ROI alone)"
        ),
    }
    Ok(())
}
