//! `palpa`: the command-line front of the palpa explicit solver, and `palpa serve`, the live
//! training view (a web front; `serve/`).

mod cli;
mod serve;

use clap::Parser;

fn main() {
    let args = cli::Cli::parse();
    if let Err(e) = cli::dispatch(args) {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}
