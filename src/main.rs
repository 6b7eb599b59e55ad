//! `palpa`: the command-line front of the palpa explicit solver, and `palpa serve`, the live
//! training view (a web front; `serve/`).

mod cli;
mod serve;

use clap::Parser;

fn main() {
    let args = cli::Cli::parse();
    if !args.is_serve() {
        quiet_broken_pipe();
    }
    if let Err(e) = cli::dispatch(args) {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

/// Let a closed stdout end the process as it ends any Unix tool (`palpa check SCENE | head -1`):
/// quietly, by SIGPIPE, instead of a panic in `println!` (exit 101). Rust ignores SIGPIPE by
/// default; `serve` keeps that, as a browser closing its socket must not end the server.
fn quiet_broken_pipe() {
    #[cfg(unix)]
    // SAFETY: restoring the default disposition of SIGPIPE before any thread is started.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}
