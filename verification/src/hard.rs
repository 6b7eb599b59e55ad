//! The hard-case suite (`palpa verify --hard`).
//!
//! Each case runs palpa's explicit loop on a deliberately difficult problem. It passes when the
//! run ends with an energy error of at most 1 %, a hourglass energy of at most 10 % of the
//! internal energy (after the first 10 % of the run) and no NaN; or when it stops with an error
//! that names the element and the simulated time (`SolverError::ElementFailure`), which counts
//! as a clear, named stop. Anything else fails.
//!
//! The energy error of a run is `max_t |E_bal(t)| / max_t E_scale(t)`, with
//! `E_bal = KE + IE + E_hg + E_bv + E_damp + E_contact - W_ext` and
//! `E_scale = max(|KE|, |IE|, |W_ext|)`: the largest imbalance relative to the run's energy.
//! The instantaneous ratio `|E_bal(t)| / E_scale(t)` (Belytschko, Liu and Moran 2000,
//! sec. 6.2.3) is reported beside it for information: in the first steps of a run it divides
//! the central-difference start-up offset (a constant of order 1e-11 J in the liver block) by
//! an energy that is itself still near zero, so it measures how early the window opens rather
//! than the balance.
//!
//! Runs with one-point elements carry the solver's hourglass guard (`[run]
//! max_hourglass_ratio = 0.1` in a scene, [`solver::simulation::HourglassLimit`]): where the
//! zero-energy modes carry the load, the run stops and names the element with the largest
//! hourglass energy; the same case then runs with the fully integrated F-bar element.
//!
//! Cases: the paper's flesh (K/G = 5e4) under 30 % compression between glued plates (one-point
//! and F-bar); the paper's liver law taken through stretches 0.5-1.6; a palpation-like
//! indentation of a flesh block at 1 m/s and 5 m/s by a rigid spherical finger in penalty
//! contact (also on the global step estimate, [`solver::global_step`]); the paper's ribs yielding in three-point bending; an element whose corner is
//! driven 2 edge lengths through the opposite face; a finger smaller than an element; and
//! the liver's negative instantaneous Poisson ratio (with the Prony series on the deviatoric
//! strain, K_inst = K = 32 kPa < 2/3 G_inst, nu_inst = (3K - 2G)/(2(3K + G)) < 0).

use crate::cases::{short, FULL_FBAR, ONE_POINT_VISCOUS_SHEAR};
use crate::{CaseOutput, Row, Status};
use contact::Curve;
use material::neo_hookean::NeoHookean;
use material::Material;
use solver::bc::{Constraint, Kinematic};
use solver::element::Formulation;
use solver::generate::{box_mesh, BoxSpec};
use solver::mesh::Mesh;
use solver::model::{Model, Part, SolverError};
use solver::simulation::{HourglassLimit, LoopSettings, Simulation};

/// Energy-error limit.
pub const ENERGY_LIMIT: f64 = 0.01;
/// Hourglass / internal energy limit.
pub const HOURGLASS_LIMIT: f64 = 0.10;

/// What an explicit hard run ended with.
#[derive(Clone, Debug, Default)]
pub struct HardRun {
    /// Largest energy imbalance over the run's largest energy scale.
    pub energy_error: f64,
    /// Largest instantaneous energy error after 10 % of the run (information).
    pub energy_error_pointwise: f64,
    /// Largest hourglass / internal energy after 10 % of the run.
    pub hourglass_ratio: f64,
    /// A NaN appeared in the displacements.
    pub nan: bool,
    /// The error the run stopped with.
    pub stop: Option<String>,
    /// Whether the stop names the element and the time.
    pub named: bool,
    /// Time reached (s) and steps.
    pub time: f64,
    /// Steps.
    pub steps: u64,
}

/// Load a library material.
pub fn library(name: &str) -> Material {
    material::named(name)
        .and_then(|s| s.build(name))
        .expect("library material builds")
}

/// Run `sim` to `end` and watch the criteria; `watch` is called after every step.
pub fn run_explicit(sim: &mut Simulation, end: f64, mut watch: impl FnMut(&Simulation)) -> HardRun {
    let mut r = HardRun::default();
    let (mut worst, mut peak) = (0.0f64, 0.0f64);
    sim.settings.hourglass_limit = Some(HourglassLimit {
        ratio: HOURGLASS_LIMIT,
        after: 0.1 * end,
    });
    while sim.time < end {
        if let Err(e) = sim.step(f64::INFINITY) {
            r.named = matches!(e, SolverError::ElementFailure { .. });
            r.stop = Some(e.to_string());
            break;
        }
        watch(sim);
        if sim.step % 16 == 0
            && sim
                .u
                .iter()
                .any(|u| !(u[0].is_finite() && u[1].is_finite() && u[2].is_finite()))
        {
            r.nan = true;
            r.stop = Some(format!("NaN displacement at t = {:.6} ms", sim.time * 1e3));
            break;
        }
        worst = worst.max(sim.energy.imbalance().abs());
        peak = peak.max(sim.energy.scale());
        if sim.time > 0.1 * end {
            r.energy_error_pointwise = r.energy_error_pointwise.max(sim.energy.error());
            let ei = sim.energy.internal.abs();
            if ei > 0.0 {
                r.hourglass_ratio = r.hourglass_ratio.max(sim.energy.hourglass.abs() / ei);
            }
        }
    }
    r.energy_error = if peak > 0.0 { worst / peak } else { 0.0 };
    r.time = sim.time;
    r.steps = sim.step;
    r
}

/// Rows of one hard run.
pub fn judge(case: &str, r: &HardRun, extra: &str) -> Vec<Row> {
    let mut rows = Vec::new();
    if let Some(stop) = &r.stop {
        let named = r.named && stop.contains("element") && stop.contains("t =");
        let mut row = Row::with_error(
            case,
            "run outcome",
            "named stop (element, time)",
            f64::NAN,
            r.time,
            f64::NAN,
            None,
        )
        .detail(format!("{stop}{extra}"));
        row.status = if named {
            Status::NamedStop
        } else {
            Status::Fail
        };
        rows.push(row);
        return rows;
    }
    rows.push(
        Row::with_error(
            case,
            "max energy error",
            "energy balance",
            0.0,
            r.energy_error,
            r.energy_error,
            Some(ENERGY_LIMIT),
        )
        .detail(format!(
            "{} steps to t = {:.3} ms{extra}",
            r.steps,
            r.time * 1e3
        )),
    );
    if r.energy_error_pointwise > 0.0 {
        rows.push(Row::with_error(
            case,
            "instantaneous energy error after 10 % (info)",
            "energy balance",
            0.0,
            r.energy_error_pointwise,
            f64::NAN,
            None,
        ));
    }
    rows.push(Row::with_error(
        case,
        "max hourglass / internal energy",
        "limit",
        0.0,
        r.hourglass_ratio,
        r.hourglass_ratio,
        Some(HOURGLASS_LIMIT),
    ));
    rows
}

fn sim(
    mesh: Mesh,
    mat: Material,
    form: Formulation,
    c: Vec<Constraint>,
) -> Result<Simulation, String> {
    let part = Part {
        name: mesh.part_names[0].clone(),
        material: mat,
        formulation: form,
    };
    let model = Model::build(mesh, vec![part], None, 0.9).map_err(|e| e.to_string())?;
    Simulation::new(model, LoopSettings::default(), c, Vec::new(), None, false)
        .map_err(|e| e.to_string())
}

fn fixed(nodes: &[u32], dof: usize) -> Constraint {
    Constraint {
        nodes: nodes.to_vec(),
        dof,
        kind: Kinematic::Fixed,
    }
}

fn disp(nodes: &[u32], dof: usize, curve: Curve) -> Constraint {
    Constraint {
        nodes: nodes.to_vec(),
        dof,
        kind: Kinematic::Displacement(curve),
    }
}

fn boxm(size: [f64; 3], div: [usize; 3], part: &str) -> Mesh {
    box_mesh(
        &BoxSpec {
            size,
            divisions: div,
            ..Default::default()
        },
        part,
    )
    .expect("box")
}

fn push_run(out: &mut CaseOutput, case: &str, r: Result<HardRun, String>, extra: &str) {
    match r {
        Ok(r) => out.rows.extend(judge(case, &r, extra)),
        Err(e) => out.rows.push(Row::failed(case, "run outcome", e)),
    }
}

/// Flesh (K/G = 5e4) compressed 30 % between glued plates in 20 ms.
pub fn flesh_compression(form: Formulation) -> Result<HardRun, String> {
    let m = boxm([0.02, 0.02, 0.01], [6, 6, 3], "flesh");
    let ns = m.node_sets.clone();
    let mut c: Vec<Constraint> = (0..3).map(|d| fixed(&ns["zmin"], d)).collect();
    c.push(fixed(&ns["zmax"], 0));
    c.push(fixed(&ns["zmax"], 1));
    c.push(disp(
        &ns["zmax"],
        2,
        Curve::SmoothStepBetween {
            t0: 0.0,
            t1: 0.02,
            from: 0.0,
            to: -0.003,
        },
    ));
    let mut s = sim(m, library("paper:flesh"), form, c)?;
    Ok(run_explicit(&mut s, 0.025, |_| {}))
}

/// Liver block on rollers taken to stretch 0.5, then to 1.6, in 200 ms.
pub fn liver_stretches() -> Result<HardRun, String> {
    let h = 0.01;
    let m = boxm([h; 3], [3, 3, 3], "liver");
    let ns = m.node_sets.clone();
    let c = vec![
        fixed(&ns["xmin"], 0),
        fixed(&ns["ymin"], 1),
        fixed(&ns["zmin"], 2),
        disp(
            &ns["zmax"],
            2,
            Curve::Polyline(vec![(0.0, 0.0), (0.1, -0.5 * h), (0.2, 0.6 * h)]),
        ),
    ];
    let mut s = sim(m, library("paper:liver"), ONE_POINT_VISCOUS_SHEAR, c)?;
    Ok(run_explicit(&mut s, 0.2, |_| {}))
}

/// Rib bar 80 x 10 x 10 mm, ends clamped, midspan top line pushed 6 mm in 20 ms: yields.
pub fn ribs_bending() -> Result<(HardRun, f64), String> {
    let m = boxm([0.08, 0.01, 0.01], [24, 3, 3], "ribs");
    let ns = m.node_sets.clone();
    let mid: Vec<u32> = m.nodes_in_box(
        [0.04 - 1e-9, -1.0, 0.01 - 1e-9],
        [0.04 + 1e-9, 1.0, 0.01 + 1e-9],
    );
    let mut c: Vec<Constraint> = Vec::new();
    for set in ["xmin", "xmax"] {
        for d in 0..3 {
            c.push(fixed(&ns[set], d));
        }
    }
    c.push(disp(
        &mid,
        2,
        Curve::SmoothStepBetween {
            t0: 0.0,
            t1: 0.02,
            from: 0.0,
            to: -0.006,
        },
    ));
    let mat = library("paper:ribs");
    let names = mat.history_names();
    let mut s = sim(m, mat, FULL_FBAR, c)?;
    let r = run_explicit(&mut s, 0.025, |_| {});
    let k = names.iter().position(|n| n == "eps_p");
    let hl = names.len();
    let eps_max = match k {
        Some(k) if hl > 0 => s.model.groups[0]
            .history_values(k, hl)
            .into_iter()
            .fold(0.0f64, f64::max),
        _ => f64::NAN,
    };
    Ok((r, eps_max))
}

/// One neo-Hookean element whose top corner node (+, +, +) is driven (smoothly, from rest)
/// along the diagonal through the opposite face, 2 edge lengths in 10 ms.
pub fn inversion() -> Result<HardRun, String> {
    let h = 0.01;
    let m = boxm([h; 3], [1, 1, 1], "cube");
    let ns = m.node_sets.clone();
    let corner = 7u32; // (+, +, +): box nodes are numbered x fastest, then y, then z
    let others: Vec<u32> = ns["zmin"].clone();
    let mut c: Vec<Constraint> = (0..3).map(|d| fixed(&others, d)).collect();
    for d in 0..3 {
        c.push(disp(
            &[corner],
            d,
            Curve::SmoothStepBetween {
                t0: 0.0,
                t1: 0.01,
                from: 0.0,
                to: -2.0 * h,
            },
        ));
    }
    let mat = Material::NeoHookean(NeoHookean {
        rho: 1000.0,
        lambda: 1.5e6,
        mu: 1e6,
    });
    let mut s = sim(m, mat, Formulation::Full { fbar: false }, c)?;
    Ok(run_explicit(&mut s, 0.01, |_| {}))
}

/// The library's liver card with its Prony series on `prony_on`, changed on the parsed card
/// (an edit of the card's text that stopped matching would silently keep the library's
/// setting).
fn liver_with_prony_on(prony_on: &str) -> Result<material::MaterialSpec, String> {
    let mut card = material::named("paper:liver")?;
    match &mut card {
        material::MaterialSpec::Ogden(o) => {
            o.prony_on = Some(prony_on.to_string());
            Ok(card)
        }
        _ => Err("paper:liver is not an Ogden card".into()),
    }
}

/// Instantaneous Poisson ratio of the liver law (material driver, jump to stretch 0.99):
/// (observed, closed form) for `prony_on`.
pub fn liver_poisson(prony_on: &str) -> Result<(f64, f64), String> {
    let mut spec: material::driver::DriverSpec = toml::from_str(
        "material = \"paper:liver\"\nmode = \"uniaxial_stress\"\n[[segment]]\nramp_to = 0.999\nduration = 0\nsteps = 1\n",
    )
    .map_err(|e| e.to_string())?;
    spec.material = liver_with_prony_on(prony_on)?;
    let o = material::driver::run_driver(&spec, None)?;
    let ly = o.column("stretch_y").ok_or("no stretch_y")?;
    let l = o.column("stretch").ok_or("no stretch")?;
    let n = l.len() - 1;
    let nu = -(ly[n] - 1.0) / (l[n] - 1.0);
    let mat = library("paper:liver");
    let (k, g, gsum) = match &mat {
        Material::Ogden(o) => (
            o.bulk,
            o.mu0(),
            o.prony().iter().map(|t| t.modulus).sum::<f64>(),
        ),
        _ => return Err("paper:liver is not Ogden".into()),
    };
    let (kin, gin) = if prony_on == "deviatoric" {
        (k, g + gsum)
    } else {
        (k + 2.0 / 3.0 * gsum, g + gsum)
    };
    Ok((nu, (3.0 * kin - 2.0 * gin) / (2.0 * (3.0 * kin + gin))))
}

/// Liver block (deviatoric Prony) compressed 5 % in 2 ms on rollers: runs, and the lateral
/// faces move inwards (negative Poisson ratio).
pub fn liver_negative_poisson_block() -> Result<(HardRun, f64), String> {
    let h = 0.002;
    let m = boxm([h; 3], [2, 2, 2], "liver");
    let ns = m.node_sets.clone();
    let c = vec![
        fixed(&ns["xmin"], 0),
        fixed(&ns["ymin"], 1),
        fixed(&ns["zmin"], 2),
        disp(
            &ns["zmax"],
            2,
            Curve::SmoothStepBetween {
                t0: 0.0,
                t1: 0.002,
                from: 0.0,
                to: -0.05 * h,
            },
        ),
    ];
    let mat = liver_with_prony_on("deviatoric")?.build("liver")?;
    let xmax = ns["xmax"].clone();
    let mut s = sim(m, mat, ONE_POINT_VISCOUS_SHEAR, c)?;
    let r = run_explicit(&mut s, 0.003, |_| {});
    let ux = xmax.iter().map(|&n| s.u[n as usize][0]).sum::<f64>() / xmax.len() as f64;
    Ok((r, -(ux / h) / (-0.05)))
}

/// Result of a scene run through `palpa run`'s machinery.
#[derive(Clone, Debug)]
pub struct SceneRun {
    /// |indenter force| at the end (N).
    pub force: f64,
    /// Largest energy error of the run.
    pub energy_error: f64,
    /// Hourglass / internal energy at the end.
    pub hourglass_ratio: f64,
    /// Simulated time reached (s).
    pub time: f64,
    /// Steps taken.
    pub steps: u64,
    /// Elements.
    pub elements: usize,
    /// Wall time of the run (s).
    pub wall: f64,
    /// Mass added by mass scaling, percent of the physical mass.
    pub added_mass_percent: f64,
}

/// Write `scene` to a temporary directory, run it, and read the indenter `name`'s force.
pub fn run_contact_scene(scene: &str, tag: &str, name: &str) -> Result<SceneRun, String> {
    let dir = std::env::temp_dir().join(format!("palpa-verify-{}-{tag}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let path = dir.join("scene.toml");
    std::fs::write(&path, scene).map_err(|e| e.to_string())?;
    let result = (|| {
        let mut sc = scene::load_scene(&path)?;
        let stop = std::sync::atomic::AtomicBool::new(false);
        let out = dir.join("out");
        let (summary, err) = scene::run::run_scene(&mut sc, &out, &stop, |_| {});
        if let Some(e) = err {
            return Err(e);
        }
        let (cols, rows) = solver::output::history::read_history(&out.join("history.csv"))?;
        let fz = solver::output::history::column(&cols, &rows, &format!("{name}_force_z"))
            .ok_or_else(|| format!("history.csv has no `{name}_force_z` column"))?;
        Ok(SceneRun {
            force: fz.last().copied().unwrap_or(f64::NAN).abs(),
            energy_error: summary.max_energy_error,
            hourglass_ratio: summary.hourglass_energy.abs()
                / summary.internal_energy.abs().max(1e-300),
            time: summary.time,
            steps: summary.steps,
            elements: summary.elements,
            wall: summary.wall_seconds,
            added_mass_percent: summary.added_mass_percent(),
        })
    })();
    let _ = std::fs::remove_dir_all(&dir);
    result
}

/// A flesh block 40 x 40 x 20 mm on a fixed base, `div` elements along x and y (half as many
/// along z), pressed by a rigid spherical finger of radius `radius` (m) through penalty
/// contact. `motion` is the indenter's motion table (TOML), `end` the end time (s) and
/// `element` the part's formulation keys. The hourglass guard is on.
pub fn finger_scene(div: usize, radius: f64, motion: &str, end: f64, element: &str) -> String {
    format!(
        r#"
[run]
title = "flesh block pressed by a rigid finger"
end_time = "{end_ms} ms"
max_hourglass_ratio = {HOURGLASS_LIMIT}

[mesh]
generator = "box"
size = ["40 mm", "40 mm", "20 mm"]
divisions = [{div}, {div}, {half}]
part = "flesh"

[materials.flesh]
library = "paper:flesh"

[[part]]
name = "flesh"
material = "flesh"
{element}

[[boundary]]
nodes = "zmin"
fix = ["all"]

[[indenter]]
name = "finger"
direction = [0, 0, -1]
motion = {motion}
part = [{{ shape = "sphere", center = ["21 mm", "22 mm", "{zc_mm} mm"], radius = "{r_mm} mm" }}]

[contact]
surface = "zmax"

[output]
interval = "{end_ms} ms"
history_interval = "{hist_ms} ms"
fields = ["displacement"]
"#,
        end_ms = end * 1e3,
        half = div / 2,
        zc_mm = 20.0 + radius * 1e3,
        r_mm = radius * 1e3,
        hist_ms = end * 1e3 / 40.0,
    )
}

/// Part keys of the two formulations the contact cases run with.
const SCENE_ELEMENTS: [(&str, &str); 2] = [
    (
        "1-pt viscous HG",
        "formulation = \"one_point\"\nhourglass_modulus = \"shear\"",
    ),
    ("full F-bar", "formulation = \"full_fbar\""),
];

/// Rows of one contact-scene case.
fn push_scene(out: &mut CaseOutput, case: &str, scene: &str, tag: &str) {
    match run_contact_scene(scene, tag, "finger") {
        Err(e) => {
            let named = e.contains("element") && e.contains("t =");
            let mut row = Row::failed(case, "run outcome", e);
            if named {
                row.status = Status::NamedStop;
            }
            out.rows.push(row)
        }
        Ok(r) => {
            let hr = HardRun {
                energy_error: r.energy_error,
                hourglass_ratio: r.hourglass_ratio,
                time: r.time,
                steps: r.steps,
                ..Default::default()
            };
            out.rows.extend(judge(
                case,
                &hr,
                &format!("; finger force {:.3e} N", r.force),
            ));
        }
    }
}

/// The hard-case suite.
pub fn run() -> CaseOutput {
    let mut out = CaseOutput::default();
    for form in [ONE_POINT_VISCOUS_SHEAR, FULL_FBAR] {
        push_run(
            &mut out,
            &format!("flesh K/G 5e4, 30 % compression, {}", short(&form)),
            flesh_compression(form),
            "",
        );
    }
    push_run(
        &mut out,
        "liver law, stretch 1 -> 0.5 -> 1.6 (200 ms)",
        liver_stretches(),
        "",
    );
    for v in [1.0, 5.0] {
        // Reach speed v over the first 10 % of the 6 mm, then hold it.
        let depth = 0.006;
        let t_ramp = 0.2 * depth / v;
        let end = depth / v + 0.5 * t_ramp;
        let motion = format!(
            "{{ kind = \"velocity\", curve = {{ kind = \"ramp\", value = \"{v} m/s\", end = \"{} ms\" }} }}",
            t_ramp * 1e3
        );
        for (label, element) in SCENE_ELEMENTS {
            push_scene(
                &mut out,
                &format!("palpation: finger R 7.5 mm, 6 mm at {v} m/s (flesh), {label}"),
                &finger_scene(16, 0.0075, &motion, end, element),
                &format!("palpation-{v}-{}", label.len()),
            );
        }
        // the same press with F-bar elements (the one-point ones stop on their hourglass
        // modes) on the mesh's own critical step (solver::global_step)
        let (label, element) = SCENE_ELEMENTS[1];
        push_scene(
            &mut out,
            &format!(
                "palpation: finger R 7.5 mm, 6 mm at {v} m/s (flesh), {label}, global step estimate"
            ),
            &finger_scene(16, 0.0075, &motion, end, element).replacen(
                "[run]\n",
                "[run]\nstep_estimate = \"global\"\n",
                1,
            ),
            &format!("palpation-{v}-global"),
        );
    }
    match ribs_bending() {
        Ok((r, eps)) => {
            out.rows.extend(judge(
                "ribs yielding, 3-point bending 6 mm",
                &r,
                &format!("; max eps_p = {eps:.3e}"),
            ));
            out.rows.push(Row::with_error(
                "ribs yielding, 3-point bending 6 mm",
                "max plastic strain eps_p (must be > 0)",
                "yield reached",
                0.0,
                eps,
                f64::NAN,
                None,
            ));
            if !(eps > 0.0) {
                out.rows.last_mut().unwrap().status = Status::Fail;
            }
        }
        Err(e) => out
            .rows
            .push(Row::failed("ribs yielding", "run outcome", e)),
    }
    push_run(
        &mut out,
        "element driven towards inversion (corner through the face)",
        inversion(),
        "",
    );
    let motion = "{ kind = \"displacement\", curve = { kind = \"smooth_step\", value = \"3 mm\", end = \"20 ms\" } }";
    for (label, element) in SCENE_ELEMENTS {
        push_scene(
            &mut out,
            &format!("finger (R 1 mm) smaller than an element (5 mm), {label}"),
            &finger_scene(8, 0.001, motion, 0.02, element),
            &format!("small-finger-{}", label.len()),
        );
    }
    for p in ["deviatoric", "green_lagrange"] {
        let case = format!("liver instantaneous Poisson ratio, Prony on {p}");
        match liver_poisson(p) {
            Ok((nu, want)) => out.rows.push(Row::compare(
                &case,
                "nu_inst = -(l_y - 1)/(l - 1) at l = 0.999",
                "(3K - 2G)/(2(3K + G)), instantaneous moduli",
                want,
                nu,
                want,
                Some(0.01),
            )),
            Err(e) => out.rows.push(Row::failed(&case, "nu_inst", e)),
        }
    }
    match liver_negative_poisson_block() {
        Ok((r, nu)) => {
            let case = "liver (deviatoric Prony) block, 5 % in 2 ms";
            out.rows.extend(judge(case, &r, ""));
            out.rows.push(Row::with_error(
                case,
                "apparent Poisson ratio -e_x/e_z at 3 ms",
                "negative expected",
                f64::NAN,
                nu,
                f64::NAN,
                None,
            ));
        }
        Err(e) => out.rows.push(Row::failed(
            "liver negative Poisson block",
            "run outcome",
            e,
        )),
    }
    out
}
