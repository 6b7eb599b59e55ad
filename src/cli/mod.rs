//! Command-line parsing and dispatch.

mod check;
mod progress;
mod run;

use clap::{Parser, Subcommand};
use std::path::PathBuf;

/// palpa: explicit total-Lagrangian finite elements for soft-tissue indentation.
#[derive(Parser)]
#[command(name = "palpa", version, about)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scene and write VTK frames, history.csv and summary.json into --out.
    Run {
        /// The scene file (TOML).
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
    },
    /// Validate a scene and report mesh, quality, stable step, mass scaling, memory and stages.
    Check {
        /// The scene file (TOML).
        scene: PathBuf,
    },
}

/// Set the global thread pool.
pub fn set_threads(threads: Option<usize>) -> Result<(), String> {
    if let Some(n) = threads {
        if n == 0 {
            return Err("--threads must be at least 1".into());
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// Run the chosen command.
pub fn dispatch(cli: Cli) -> Result<(), String> {
    match cli.command {
        Command::Run {
            scene,
            out,
            threads,
            quiet,
        } => {
            set_threads(threads)?;
            run::run(&scene, &out, quiet)
        }
        Command::Check { scene } => check::check(&scene),
    }
}
