//! Command-line parsing and dispatch.

mod bench;
mod calibrate;
mod campaign;
mod check;
mod evaluate;
mod export;
mod front;
mod front_row;
mod input;
mod material;
mod mesh;
mod palpate;
mod predict;
mod predict_line;
mod progress;
mod run;
mod selection;
mod study;
mod train;
mod units;
mod verify;
mod view_geometry;

use clap::{Parser, Subcommand};
use std::path::PathBuf;

/// palpa: explicit total-Lagrangian finite elements for soft-tissue indentation.
#[derive(Parser)]
#[command(name = "palpa", version, about)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

impl Cli {
    /// Whether the command is `serve` (which keeps writing to sockets that clients close).
    pub fn is_serve(&self) -> bool {
        matches!(self.command, Command::Serve(_))
    }
}

#[derive(Subcommand)]
enum Command {
    /// The main job: press the two-finger hand 15 mm into the built-in abdomen phantom with the
    /// paper's materials, and write VTK frames, history, ROI stresses and plots into --out.
    Palpate(palpate::PalpateArgs),
    /// Run a palpation campaign (the paper's protocol by default, or CAMPAIGN.toml) and write
    /// the surrogate's training dataset (dataset.npz + manifest.json); `merge` joins shards.
    Campaign(campaign::CampaignArgs),
    /// Run a scene (TOML) or an LS-DYNA keyword deck (.k) and write VTK frames, history.csv and
    /// summary.json into --out.
    Run {
        /// The scene file (TOML) or keyword deck (.k, .key, .dyn).
        scene: PathBuf,
        /// Output directory.
        #[arg(long, default_value = "results")]
        out: PathBuf,
        /// Worker threads (default: all cores).
        #[arg(long)]
        threads: Option<usize>,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
        #[command(flatten)]
        deck: input::DeckArgs,
    },
    /// Validate a scene or keyword deck and report mesh, quality, stable step, mass scaling,
    /// memory and stages (for a deck also its units, keywords, mapping and every warning).
    Check {
        /// The scene file (TOML) or keyword deck (.k, .key, .dyn).
        scene: PathBuf,
        /// Run the pilot (the scene with K/G capped at 5000, about a third of the run's steps)
        /// whatever it costs; by default it runs when it costs at most 5e7 element-cycles.
        #[arg(long, conflicts_with = "no_pilot")]
        pilot: bool,
        /// Estimate the steps from the starting step alone.
        #[arg(long)]
        no_pilot: bool,
        #[command(flatten)]
        deck: input::DeckArgs,
    },
    /// Write a scene as an LS-DYNA keyword deck (`--lsdyna`) that LS-DYNA or the OpenRadioss
    /// starter reads and `palpa run` runs to the same numbers.
    Export(export::ExportArgs),
    /// Material-point driver: drive one law through the path of FILE.toml (uniaxial stress or
    /// strain, simple shear, equibiaxial; ramps, holds, cycles) and write the CSV table
    /// (time, stretch, nominal and Cauchy stress, wave speed, dissipation, history).
    Material {
        /// The driver file (TOML), e.g. scenes/materials/liver-uniaxial.toml.
        file: PathBuf,
        /// Write the CSV here (atomically) instead of to stdout.
        #[arg(long, value_name = "FILE.csv")]
        out: Option<PathBuf>,
    },
    /// Build meshes: the procedural abdomen phantom, or a user's labelled segmentation.
    Mesh {
        #[command(subcommand)]
        what: mesh::MeshCommand,
    },
    /// Run the verification suite (reference solvers and closed forms), print the table, write
    /// a Markdown report and plots into --out; non-zero exit if any case fails.
    Verify {
        /// Run the hard-case suite instead.
        #[arg(long)]
        hard: bool,
        /// Output directory for the report and plots.
        #[arg(long, default_value = "verification-report")]
        out: PathBuf,
    },
    /// Accuracy against cost: vary mesh size, element formulation, mass scaling, the bulk
    /// modulus cap, the time-step factor and the step estimate on the phantom palpation; write
    /// study.csv, study.md and Pareto plots into --out.
    Study {
        /// The quick profile (coarse phantom, 6 mm in 6 ms): a few minutes on 2 cores.
        #[arg(long, conflicts_with = "paper")]
        quick: bool,
        /// The study at the paper's resolution: 3 mm voxels, 25 mm of fat, A, B and C, every
        /// knob against one F-bar reference (hours on 2 cores; resumable from the records in
        /// --out; docs/study/README.md).
        #[arg(long)]
        paper: bool,
        /// Locations of the --paper study, comma-separated (A, B, C).
        #[arg(
            long,
            value_delimiter = ',',
            default_value = "A,B,C",
            requires = "paper"
        )]
        locations: Vec<String>,
        /// Write the --paper report from the records already in --out; run nothing.
        #[arg(long, requires = "paper")]
        report_only: bool,
        /// Print the --paper plan (settings, and which have a record) and run nothing.
        #[arg(long, requires = "paper", conflicts_with = "report_only")]
        dry_run: bool,
        /// Output directory.
        #[arg(long, default_value = "results/study")]
        out: PathBuf,
        /// Worker threads (default: all cores).
        #[arg(long)]
        threads: Option<usize>,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
    },
    /// Train a stress surrogate (MLP or GP) on a dataset, print its Fit (paper eq. 5) on the
    /// held-out test locations and the training time, save it as safetensors + JSON.
    Train(train::TrainArgs),
    /// Predict the ROI stress [Pa] with a saved surrogate for a finger at x, y [m] pressing with
    /// a force [N], optionally rendering the map; or stream JSON lines with --stdin.
    Predict(predict::PredictArgs),
    /// The live training view: serve a web page that draws the model's liver stress under the
    /// trainee's fingers (pointer, force plate over WebSocket or stdin, or a replayed sensor
    /// log), on localhost:8080 by default.
    Serve(crate::serve::ServeArgs),
    /// Fit the force plate's map to the body from presses recorded at known body points (a
    /// sensor log CSV with x_m, y_m); write calibration.json for `palpa serve --calibration`.
    Calibrate(calibrate::CalibrateArgs),
    /// Leave-one-location-out cross-validation of each surrogate type and size, and the
    /// accuracy-versus-cost table (Fit, training time, prediction latency).
    Evaluate(evaluate::EvaluateArgs),
    /// The accuracy-per-run front of surrogate designs: the GP trained on each campaign's
    /// first n training runs, held-out Fit and interval coverage against n and core-hours.
    Front(front::FrontArgs),
    /// Whole-run throughput: element-cycles per second of 100k-element blocks (neo-Hookean
    /// one-point and F-bar, the two-finger press on the paper's flesh with the contact
    /// stage's share, and the paper's liver), with the memory roof, on each thread count.
    Bench {
        /// Cases: nh-1pt, nh-fbar, press, ogden.
        #[arg(long, value_delimiter = ',', default_values_t = ["nh-1pt".to_string(), "nh-fbar".to_string(), "press".to_string(), "ogden".to_string()])]
        cases: Vec<String>,
        /// Thread counts to compare.
        #[arg(long, value_delimiter = ',', default_values_t = [1usize, 2])]
        threads: Vec<usize>,
        /// Explicit steps per case.
        #[arg(long, default_value_t = 100)]
        steps: usize,
        /// Element-kernel precisions to compare: f64, f32 or both (`f64,f32`).
        #[arg(long, value_delimiter = ',', default_values_t = ["f64".to_string()])]
        precision: Vec<String>,
        /// Node numberings to compare: as_given (the block's raster), rcm (reverse
        /// Cuthill-McKee), shuffled (a seeded random order); e.g. `as_given,shuffled,rcm`.
        #[arg(long, value_delimiter = ',', default_values_t = ["as_given".to_string()])]
        numbering: Vec<String>,
    },
}

/// Worker stacks of the global pool: `palpate` and `run` put their whole time loop on a worker
/// ([`scene::run::run_scene_on_pool`]), so it gets the main thread's 8 MiB and more.
const WORKER_STACK: usize = 16 << 20;

/// Set the global thread pool: `threads` workers (default: one per core).
pub fn set_threads(threads: Option<usize>) -> Result<(), String> {
    if threads == Some(0) {
        return Err("--threads must be at least 1".into());
    }
    let built = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .stack_size(WORKER_STACK)
        .build_global();
    match (built, threads) {
        // without --threads, a pool already built (by an earlier call) is as good
        (Ok(()), _) | (Err(_), None) => Ok(()),
        (Err(e), Some(_)) => Err(e.to_string()),
    }
}

/// Run the chosen command.
pub fn dispatch(cli: Cli) -> Result<(), String> {
    match cli.command {
        Command::Palpate(a) => {
            set_threads(a.threads)?;
            palpate::palpate(&a)
        }
        Command::Campaign(a) => campaign::campaign(&a),
        Command::Run {
            scene,
            out,
            threads,
            quiet,
            deck,
        } => {
            set_threads(threads)?;
            run::run(&scene, &out, quiet, &deck)
        }
        Command::Check {
            scene,
            pilot,
            no_pilot,
            deck,
        } => check::check(
            &scene,
            &deck,
            match (pilot, no_pilot) {
                (true, _) => check::Pilot::Always,
                (_, true) => check::Pilot::Never,
                _ => check::Pilot::WhenCheap,
            },
        ),
        Command::Export(a) => export::export(&a),
        Command::Study {
            quick,
            paper,
            locations,
            report_only,
            dry_run,
            out,
            threads,
            quiet,
        } => {
            set_threads(threads)?;
            if paper {
                let how = study::PaperMode::new(report_only, dry_run);
                study::study_paper(&out, &locations, how, quiet)
            } else {
                study::study(quick, &out, quiet)
            }
        }
        Command::Material { file, out } => material::material(&file, out.as_deref()),
        Command::Mesh { what } => mesh::mesh(what),
        Command::Verify { hard, out } => verify::verify(hard, &out),
        Command::Train(a) => train::train(&a),
        Command::Predict(a) => predict::predict(&a),
        Command::Serve(a) => crate::serve::serve(&a),
        Command::Calibrate(a) => calibrate::calibrate(&a),
        Command::Evaluate(a) => evaluate::run(&a),
        Command::Front(a) => front::run(&a),
        Command::Bench {
            cases,
            threads,
            steps,
            precision,
            numbering,
        } => bench::bench(&cases, &threads, steps, &precision, &numbering),
    }
}
