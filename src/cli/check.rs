//! `palpa check SCENE`: validate without running. A keyword deck is also listed: its files,
//! units, keywords, how each part and indenter was mapped, and every warning; a deck palpa
//! cannot run gets every error listed, each with its file, line and field.

use super::input::{check_failed_deck, load, print_report, DeckArgs};
use solver::hex::corner_jacobians;
use std::path::Path;

/// When `check` runs the pilot that follows the step as elements shrink
/// ([`scene::pilot`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pilot {
    /// Whatever it costs (`--pilot`).
    Always,
    /// When it costs at most [`PILOT_BUDGET`] element-cycles (the default).
    WhenCheap,
    /// Never (`--no-pilot`).
    Never,
}

/// The most element-cycles the pilot may cost, estimated at its own starting step, unless
/// `--pilot` asks for it. The estimate ignores the shrinking it is run to find, so the pilot may
/// cost more: finger-press is estimated at 1.3e7 and takes 3.4e7 (12 s on a shared machine).
pub const PILOT_BUDGET: f64 = 5e7;

/// Validate a scene or deck and report what a run would do.
pub fn check(path: &Path, deck: &DeckArgs, pilot: Pilot) -> Result<(), String> {
    let loaded = match load(path, deck) {
        Ok(l) => l,
        Err(e) => {
            if lsdyna::is_deck(path) {
                if let Some(summary) = check_failed_deck(path, deck) {
                    return Err(summary);
                }
            }
            return Err(e);
        }
    };
    let mut scene = loaded.scene;
    let sim = &scene.sim;
    let m = &sim.model;
    let mesh = &m.mesh;
    println!("scene {} is valid: `{}`", path.display(), scene.title);
    if let Some(r) = &loaded.report {
        print_report(r, true);
    }
    for n in &scene.notes {
        println!("  note: {n}");
    }
    println!(
        "  mesh: {} nodes, {} elements, {} parts",
        mesh.nodes.len(),
        mesh.elements.len(),
        m.parts.len()
    );
    let mut min_scaled = f64::INFINITY;
    let mut worst = 0;
    for (e, c) in mesh.elements.iter().enumerate() {
        let x: [[f64; 3]; 8] = std::array::from_fn(|a| mesh.nodes[c[a] as usize]);
        let (_, s) = corner_jacobians(&x);
        let v = s.iter().cloned().fold(f64::INFINITY, f64::min);
        if v < min_scaled {
            min_scaled = v;
            worst = e;
        }
    }
    println!("  element quality: minimum scaled Jacobian {min_scaled:.4} (element {worst})");
    for (p, pm) in m.parts.iter().zip(&m.part_mass) {
        println!(
            "  part {:<12} {:>8} elements, law {}, {}, mass {:.4e} kg",
            p.name,
            pm.elements,
            p.material.law_name(),
            p.formulation.label(),
            pm.physical
        );
    }
    for b in scene.setup.parts.iter().filter_map(|p| p.bulk.as_ref()) {
        println!("  bulk modulus: {}", b.describe());
    }
    let (dt0, e0) = m.initial_dt;
    let f = sim.settings.dt_factor;
    println!(
        "  stable time step: {:.4e} s (factor {f} x {:.4e} s, element {e0})",
        f * dt0,
        dt0
    );
    if m.added_mass() > 0.0 {
        println!(
            "  mass scaling: step {:.4e} s, added {:.4e} kg = {:.3} % of {:.4e} kg",
            f * m.scaled_dt,
            m.added_mass(),
            100.0 * m.added_mass() / m.physical_mass(),
            m.physical_mass()
        );
    } else if let Some(ms) = &m.mass_scaling {
        println!(
            "  mass scaling: target step {:.4e} s; no element is below it at the start (the run adds mass to elements whose step falls below it, up to {:.3} % of the physical mass)",
            ms.target_dt,
            100.0 * ms.max_added
        );
    } else {
        println!("  mass scaling: none");
    }
    let dt_max = sim.settings.dt_max;
    let steps =
        scene::def::estimated_steps(m, f, dt_max.is_finite().then_some(dt_max), scene.end_time);
    let capped = dt_max.is_finite() && dt_max < f * dt0;
    println!(
        "  estimated steps at the starting step: {:.0} ({:.3e} element-cycles) for end time {:.4} ms{}",
        steps,
        steps * mesh.elements.len() as f64,
        scene.end_time * 1e3,
        if capped {
            format!(", the step capped by dt_max = {dt_max:.4e} s")
        } else {
            String::new()
        }
    );
    let hist: usize = m.groups.iter().map(|g| g.history.len() * 8).sum();
    // f32 kernels keep an f32 copy of the reference data beside the f64 one (half its size).
    let narrow = sim.settings.precision == solver::element::precision::Precision::F32;
    let ref_data: usize = m
        .groups
        .iter()
        .map(|g| {
            let r = g.refs().bytes();
            g.conn.len() * (8 * 4 + 8)
                + r
                + if narrow { r / 2 } else { 0 }
                + g.density_scale.len() * 8
        })
        .sum();
    let nodal = mesh.nodes.len() * 8 * (3 * 7 + 1);
    let bytes = ref_data + hist * 8 + nodal;
    println!(
        "  element kernels: {}{}",
        sim.settings.precision.label(),
        if narrow {
            " (laws, history and nodal state in f64)"
        } else {
            ""
        }
    );
    println!(
        "  memory estimate: {:.1} MiB (history {:.1} MiB)",
        bytes as f64 / 1048576.0,
        hist as f64 * 8.0 / 1048576.0
    );
    for g in &m.groups {
        let (colours, fewest) = g.colouring();
        println!(
            "  element loop, part {}: {} chunks in {colours} colours (fewest {fewest} chunks per colour: the parallelism of its slowest pass)",
            m.parts[g.part].name,
            g.elements.len().div_ceil(solver::model::CHUNK),
        );
    }
    println!("{}", numbering_line(&m.mesh));
    println!("  stages: {}", sim.active_stages().join(", "));
    let elements = mesh.elements.len();
    print_pilot(path, &scene, pilot, lsdyna::is_deck(path), elements);
    print_global_step(&mut scene.sim, scene.end_time)
        .map_err(|e| format!("{}: {e}", path.display()))
}

/// Most bytes the Lanczos basis of `check`'s global estimate may take
/// ([`solver::global_step::BASIS_BYTES_PER_NODE`] per node and iteration, counted at
/// [`LANCZOS_ITERATIONS`]); larger meshes skip it.
const LANCZOS_BUDGET: f64 = 1024.0 * 1048576.0;
/// Lanczos iterations counted in [`LANCZOS_BUDGET`] (the first estimate of the 3 mm phantom
/// takes 28-60).
const LANCZOS_ITERATIONS: f64 = 60.0;

/// The mesh's own critical step at the start ([`solver::global_step`]): what
/// `run.step_estimate = "global"` starts from, printed whichever estimate the scene asks for,
/// with the steps it gives to `end_time` (s). It costs one element loop and one Lanczos
/// estimate, on the scene's own simulation (the last thing `check` does with it). Subcycling
/// and a factor above 0.9, which a run refuses beside the global estimate, are set aside for
/// the estimate and named. A scene that asks for the global estimate where a run refuses it
/// is an error, as the run would be.
fn print_global_step(
    sim: &mut solver::simulation::Simulation,
    end_time: f64,
) -> Result<(), String> {
    use solver::simulation::{StepEstimate, DEFAULT_DT_FACTOR};
    let nodes = sim.model.mesh.nodes.len() as f64;
    let basis = nodes * solver::global_step::BASIS_BYTES_PER_NODE as f64 * LANCZOS_ITERATIONS;
    if basis > LANCZOS_BUDGET {
        println!(
            "  global step estimate: not computed: its Lanczos basis would take up to {:.0} MiB for {nodes} nodes",
            basis / 1048576.0
        );
        return Ok(());
    }
    let asked = sim.settings.step_estimate == StepEstimate::Global;
    let f = sim.settings.dt_factor;
    let mut refused = Vec::new();
    if sim.settings.subcycling > 1 {
        refused.push(format!("run.subcycling = {}", sim.settings.subcycling));
        sim.settings.subcycling = 1;
    }
    if f > DEFAULT_DT_FACTOR {
        refused.push(format!("run.dt_factor = {f}"));
        sim.settings.dt_factor = DEFAULT_DT_FACTOR;
    }
    sim.settings.step_estimate = StepEstimate::Global;
    let estimate = sim.initialise().map_err(|e| e.to_string()).and_then(|()| {
        sim.global_step
            .as_ref()
            .map(|g| (g.critical_step(), g.report))
            .filter(|(g, _)| *g > 0.0)
            .ok_or_else(|| "the estimate broke down (no stiffness)".to_string())
    });
    let (g, r) = match estimate {
        Ok(e) => e,
        Err(e) if asked => return Err(e),
        Err(e) => {
            println!("  global step estimate: not available: {e}");
            return Ok(());
        }
    };
    // the element loop's smallest estimate at the same state (mass scaling and the law's
    // current wave speed included), which the step never goes below
    let element = g / r.ratio.1;
    let f = sim.settings.dt_factor;
    let bound = (f * g.max(element)).min(sim.settings.dt_max);
    println!(
        "  global step estimate: the mesh's critical step {g:.4e} s, {:.2} x the element loop's {element:.4e} s ({} Lanczos iterations, {:.2} s); at factor {f}: {bound:.4e} s, {:.0} steps for end time {:.4} ms (other stages' bounds, such as contact's, may hold the step lower); {}",
        r.ratio.1,
        r.iterations,
        r.seconds,
        (end_time / bound).ceil(),
        end_time * 1e3,
        match (refused.is_empty(), asked) {
            (false, _) => format!("a run refuses it beside {}", refused.join(" and ")),
            (true, true) => "the run uses it".to_string(),
            (true, false) => "run.step_estimate = \"global\" would use it".to_string(),
        }
    );
    if asked && !refused.is_empty() {
        return Err(format!(
            "run.step_estimate = \"global\" is refused beside {}: a run would stop at its start",
            refused.join(" and ")
        ));
    }
    Ok(())
}

/// The mesh's element bandwidth (the largest node-number spread of one element), with a hint
/// where it spans most of the nodes: a numbering without locality, which costs the element loop
/// its cache and its parallel colours (docs/performance.md, node numbering).
fn numbering_line(mesh: &solver::Mesh) -> String {
    let bw = solver::renumber::bandwidth(mesh);
    let n = mesh.n_nodes();
    let hint = if n > 64 && (bw as usize) * 4 > n * 3 {
        ": the nodes are numbered without locality; `[mesh] numbering = \"rcm\"` renumbers them"
    } else {
        ""
    };
    format!("  node numbering: element bandwidth {bw} of {n} nodes{hint}")
}

/// Run the pilot when asked or cheap and print its estimate, or why there is none.
fn print_pilot(path: &Path, scene: &scene::Scene, pilot: Pilot, deck: bool, elements: usize) {
    use scene::pilot::{self, PilotPlan, PILOT_BULK_RATIO};
    let why_not = |why: &str| {
        println!("  pilot: none ({why}); a run may take more steps than the starting step gives when elements shrink under load");
    };
    if pilot == Pilot::Never {
        return why_not("--no-pilot");
    }
    if deck {
        return why_not("a keyword deck keeps the starting estimate");
    }
    let plan = match pilot::plan(path, scene) {
        Ok(p) => p,
        Err(e) => return why_not(&format!("its scene did not build: {e}")),
    };
    let (pilot_scene, cost, capped) = match plan {
        PilotPlan::NotNeeded(why) => {
            println!("  pilot: none ({why}); the starting step is the estimate");
            return;
        }
        PilotPlan::Ready {
            scene,
            element_cycles,
            capped,
        } => (*scene, element_cycles, capped),
    };
    if pilot == Pilot::WhenCheap && cost > PILOT_BUDGET {
        return why_not(&format!(
            "it would cost {cost:.2e} element-cycles, above {PILOT_BUDGET:.0e}; --pilot runs it"
        ));
    }
    let est = pilot::run(pilot_scene, scene);
    println!(
        "  estimated steps with the pilot{}: {:.0} ({:.3e} element-cycles): the pilot (K/G capped at {PILOT_BULK_RATIO} on {}) took {} steps in {:.1} s, the element step falling to {:.2} of its start",
        if est.stopped.is_some() {
            " (up to where it stopped)"
        } else {
            ""
        },
        est.steps,
        est.steps * elements as f64,
        capped.join(", "),
        est.pilot_steps,
        est.wall.as_secs_f64(),
        est.min_ratio
    );
    if let Some(why) = &est.stopped {
        println!(
            "  pilot stopped at t = {:.4} ms (the estimate covers the time up to there): {why}",
            est.reached * 1e3
        );
    }
}
