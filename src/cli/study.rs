//! `palpa study [--quick] [--out DIR]`: accuracy against cost of every speed knob (mesh size,
//! element formulation, mass scaling, time-step factor) on the phantom palpation; see
//! [`verification::study`]. Writes `study.csv`, `study.md` and the Pareto plots.

use indicatif::{ProgressBar, ProgressStyle};
use scene::run::RunStatus;
use solver::output::atomic::write_atomic;
use std::path::Path;

/// Run the study.
pub fn study(quick: bool, out: &Path, quiet: bool) -> Result<(), String> {
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let pb = if quiet {
        ProgressBar::hidden()
    } else {
        let pb = ProgressBar::new(1);
        pb.set_style(
            ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} {msg} (ETA {eta})",
            )
            .map_err(|e| e.to_string())?,
        );
        pb.enable_steady_tick(std::time::Duration::from_millis(200));
        pb
    };
    let rows = verification::study::run_study(quick, out, |i, n, what| {
        pb.set_length(n as u64);
        pb.set_position(i as u64);
        pb.set_message(what.to_string());
    })?;
    pb.finish_and_clear();
    let md = verification::study::to_markdown(&rows);
    write_atomic(
        &out.join("study.csv"),
        verification::study::to_csv(&rows).as_bytes(),
    )?;
    write_atomic(&out.join("study.md"), md.as_bytes())?;
    let files = verification::study::plots(&rows, out)?;
    println!("{md}");
    for r in rows.iter().filter(|r| r.status != RunStatus::Completed) {
        println!("  {} = {}: {}", r.knob, r.setting, r.status);
    }
    println!(
        "wrote study.csv, study.md, {} into {}",
        files.join(", "),
        out.display()
    );
    Ok(())
}
