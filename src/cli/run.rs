//! `palpa run SCENE --out DIR`. A run stopped by Ctrl-C keeps its complete output up to the
//! stop and exits with status 130.

use super::input::{load, print_report, DeckArgs};
use super::progress::{stop_flag, time_bar};
use scene::run::RunStatus;
use scene::run::{run_scene_on_pool, RunSummary};
use scene::Scene;
use std::path::Path;
use std::time::Instant;

/// Print the run summary.
/// A fraction as a percentage that keeps two significant digits however small it is.
fn percent(f: f64) -> String {
    let p = 100.0 * f;
    if p == 0.0 || p >= 0.01 {
        format!("{p:.3} %")
    } else {
        format!("{p:.1e} %")
    }
}

pub fn print_summary(s: &RunSummary) {
    println!("run `{}`: {}", s.title, s.status);
    println!(
        "  simulated {:.4} ms in {} steps, {:.2} s wall on {} thread(s): {:.3} M element-cycles/s",
        s.time * 1e3,
        s.steps,
        s.wall_seconds,
        s.threads,
        s.element_cycles_per_second / 1e6
    );
    println!(
        "  {} elements, {} nodes; dt {:.4e} .. {:.4e} s; element kernels in {}{}",
        s.elements,
        s.nodes,
        s.dt_min,
        s.dt_max,
        s.precision,
        if s.precision == "f32" {
            " (laws, history and nodal state in f64)"
        } else {
            ""
        }
    );
    println!(
        "  energy: kinetic {:.4e} J, internal {:.4e} J, hourglass {:.4e} J, external work {:.4e} J; error {} (largest over the run {} of its largest energy)",
        s.kinetic_energy,
        s.internal_energy,
        s.hourglass_energy,
        s.external_work,
        percent(s.energy_error),
        percent(s.max_energy_error)
    );
    println!("  active stages: {}", s.active_stages.join(", "));
    if let Some(sc) = &s.subcycling {
        let parts: Vec<String> = sc
            .parts
            .iter()
            .map(|(p, n, all)| format!("{p} {n} of {all} elements"))
            .collect();
        println!(
            "  subcycling: every {} steps for {} ({} slow nodes); {:.1} % of element evaluations skipped",
            sc.ratio,
            parts.join(", "),
            sc.slow_nodes,
            100.0 * sc.saved_fraction
        );
    }
    if let Some(g) = &s.global_step {
        println!(
            "  step estimate: global, {} estimates ({} Lanczos iterations, {:.2} s); the mesh's critical step is {:.2}-{:.2} times the smallest element estimate",
            g.estimates, g.iterations, g.seconds, g.ratio_min, g.ratio_max
        );
    }
    println!("  where the time went:");
    for st in &s.stage_times {
        println!(
            "    {:<24} {:>8.3} s  {:>5.1} %",
            st.stage,
            st.seconds,
            100.0 * st.share
        );
    }
    for m in &s.mass {
        println!(
            "  part {:<12} mass {:.4e} kg, added {:.4e} kg ({:.3} %)",
            m.part, m.physical_kg, m.added_kg, m.added_percent
        );
    }
    for b in &s.bulk_modulus {
        println!("  bulk modulus: {}", b.describe());
    }
    for w in &s.warnings {
        println!("  warning: {w}");
    }
    if let Some(e) = &s.first_eroded {
        println!(
            "  eroded elements: {} (the first, element {} of part `{}`, at {:.4} ms)",
            s.eroded_elements,
            e.element,
            e.part,
            e.time * 1e3
        );
    }
}

/// Run a scene file or an LS-DYNA deck.
pub fn run(scene_path: &Path, out: &Path, quiet: bool, deck: &DeckArgs) -> Result<(), String> {
    let t0 = Instant::now();
    let loaded = load(scene_path, deck)?;
    if let Some(r) = &loaded.report {
        println!("deck {}: units {}", scene_path.display(), r.units);
        print_report(r, false);
    }
    let mut scene = loaded.scene;
    if !quiet {
        println!(
            "scene {}: {} elements, {} nodes, built in {:.2} s",
            scene_path.display(),
            scene.sim.model.mesh.elements.len(),
            scene.sim.model.mesh.nodes.len(),
            t0.elapsed().as_secs_f64()
        );
    }
    let (summary, err) = run_loaded(&mut scene, out, quiet);
    print_summary(&summary);
    println!("  output: {}", out.display());
    match err {
        Some(e) => Err(e),
        None if summary.status == RunStatus::Stopped => {
            // Ctrl-C: the output up to the stop is complete, but the run is not.
            eprintln!(
                "stopped by Ctrl-C at {:.4} ms of {:.4} ms; {} holds the output up to there",
                summary.time * 1e3,
                scene.end_time * 1e3,
                out.display()
            );
            std::process::exit(STOPPED_EXIT);
        }
        None => Ok(()),
    }
}

/// The exit status of a run stopped by Ctrl-C (128 + SIGINT, as a shell reports it).
pub const STOPPED_EXIT: i32 = 130;

/// Run a built scene into `out` with a progress bar and Ctrl-C handling; print the added mass
/// first. Returns the summary and the error, if the run failed.
pub fn run_loaded(scene: &mut Scene, out: &Path, quiet: bool) -> (RunSummary, Option<String>) {
    for n in &scene.notes {
        println!("  note: {n}");
    }
    if !quiet && scene.sim.model.added_mass() > 0.0 {
        for m in scene
            .sim
            .model
            .part_mass
            .iter()
            .filter(|m| m.physical > 0.0)
        {
            println!(
                "  mass scaling: part {} +{:.3} % ({} of {} elements scaled)",
                m.name,
                100.0 * m.added_fraction(),
                m.scaled_elements,
                m.elements
            );
        }
    }
    let stop = stop_flag();
    let pb = time_bar(scene.end_time, quiet);
    let wall = Instant::now();
    let res = run_scene_on_pool(scene, out, &stop, |p| {
        pb.set_position((p.sim.time * 1e6) as u64);
        let rate = p.sim.step as f64 / wall.elapsed().as_secs_f64().max(1e-9);
        pb.set_message(format!(
            "t = {:.3} ms, {:.0} steps/s",
            p.sim.time * 1e3,
            rate
        ));
    });
    pb.finish_and_clear();
    res
}
