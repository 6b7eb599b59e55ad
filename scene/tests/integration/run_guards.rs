//! The run guards that turn a run gone bad into a clear, named stop (demand 2).
//!
//! - Hourglass guard (`[run] max_hourglass_ratio`): a rigid sphere of radius 1 mm pressed into
//!   5 mm one-point elements of the paper's flesh drives their zero-energy modes. Without the
//!   guard the run ends with hourglass energy well above 10 % of the internal energy; with it
//!   the run stops and names an element of the part and the time.
//! - Excessive distortion: one fully integrated neo-Hookean cube whose (+, +, +) corner is
//!   driven along the diagonal through the opposite face. The run must stop with the
//!   excessive-distortion error (a Gauss point at det F below
//!   [`solver::element::full::MIN_GAUSS_VOLUME_RATIO`]) before any Gauss point inverts, naming
//!   element 0, and must not produce a NaN.

use crate::common;
use scene::build::build_scene;
use scene::run::run_scene;
use scene::SceneSpec;
use std::path::Path;
use std::sync::atomic::AtomicBool;

fn finger_scene(guard: &str) -> String {
    format!(
        r#"
[run]
end_time = "4 ms"
{guard}
[mesh]
generator = "box"
size = ["40 mm", "40 mm", "20 mm"]
divisions = [8, 8, 4]
part = "flesh"
[materials.flesh]
library = "paper:flesh"
[[part]]
name = "flesh"
material = "flesh"
hourglass_modulus = "shear"
[[boundary]]
nodes = "zmin"
fix = ["all"]
[[indenter]]
name = "finger"
direction = [0, 0, -1]
motion = {{ kind = "displacement", curve = {{ kind = "smooth_step", value = "1 mm", end = "4 ms" }} }}
part = [{{ shape = "sphere", center = ["21 mm", "22 mm", "21 mm"], radius = "1 mm" }}]
[contact]
surface = "zmax"
[output]
history_interval = "1 ms"
"#
    )
}

#[test]
fn hourglass_guard_names_the_element_and_the_time() {
    // Without the guard: the run ends, with hourglass energy far above 10 % of internal.
    let mut free = common::scene_from_str(&finger_scene(""));
    let out = common::tmp_dir("hg-free");
    let (summary, err) = run_scene(&mut free, out.path(), &AtomicBool::new(false), |_| {});
    assert!(err.is_none(), "unguarded run failed: {err:?}");
    let ratio = summary.hourglass_energy / summary.internal_energy;
    assert!(
        ratio > 0.1,
        "the case must excite hourglass modes (ratio {ratio})"
    );
    // ... and the summary warns, naming the part that holds it and the element with the most
    // in one step; the per-part energies add up to the run's hourglass energy.
    let w = summary.warnings.join("\n");
    assert!(
        w.contains("hourglass energy is")
            && w.contains("part `flesh` holds 100 %")
            && w.contains("(part `flesh`) had the most in one step"),
        "{w}"
    );
    let parts: f64 = summary.hourglass.by_part.iter().map(|p| p.energy_j).sum();
    assert!(
        (parts - summary.hourglass_energy).abs() <= 1e-12 * summary.hourglass_energy,
        "per part {parts} J, total {} J",
        summary.hourglass_energy
    );

    let mut guarded = common::scene_from_str(&finger_scene("max_hourglass_ratio = 0.1"));
    let out2 = common::tmp_dir("hg-guard");
    let (summary, err) = run_scene(&mut guarded, out2.path(), &AtomicBool::new(false), |_| {});
    let err = err.expect("the guard must stop the run");
    assert!(err.contains("hourglass energy is"), "{err}");
    assert!(
        err.contains("(part `flesh`)") && err.contains("t = "),
        "{err}"
    );
    assert!(summary.time < 4e-3, "stopped at {} s", summary.time);
    // Checked only after 10 % of the end time by default.
    assert!(summary.time >= 0.4e-3, "stopped at {} s", summary.time);
}

#[test]
fn hourglass_guard_refuses_a_non_positive_ratio() {
    let src = finger_scene("max_hourglass_ratio = -0.1");
    let spec: SceneSpec = toml::from_str(&src).unwrap();
    let e = match build_scene(spec, Path::new("guard.toml"), &src) {
        Ok(_) => panic!("a negative ratio must be refused"),
        Err(e) => e,
    };
    assert!(
        e.contains("guard.toml") && e.contains("run.max_hourglass_ratio"),
        "{e}"
    );
}

#[test]
fn excessive_distortion_stops_before_inversion() {
    use contact::Curve;
    use material::neo_hookean::NeoHookean;
    use material::Material;
    use solver::bc::{Constraint, Kinematic};
    use solver::element::Formulation;
    use solver::generate::{box_mesh, BoxSpec};
    use solver::model::{Model, Part, SolverError};
    use solver::simulation::{LoopSettings, Simulation};

    let h = 0.01;
    let mesh = box_mesh(
        &BoxSpec {
            size: [h; 3],
            divisions: [1, 1, 1],
            ..Default::default()
        },
        "cube",
    )
    .unwrap();
    let base = mesh.node_sets["zmin"].clone();
    let mut c: Vec<Constraint> = (0..3)
        .map(|d| Constraint {
            nodes: base.clone(),
            dof: d,
            kind: Kinematic::Fixed,
        })
        .collect();
    for d in 0..3 {
        c.push(Constraint {
            nodes: vec![7],
            dof: d,
            kind: Kinematic::Displacement(Curve::SmoothStepBetween {
                t0: 0.0,
                t1: 0.01,
                from: 0.0,
                to: -2.0 * h,
            }),
        });
    }
    let part = Part {
        name: "cube".into(),
        material: Material::NeoHookean(NeoHookean {
            rho: 1000.0,
            lambda: 1.5e6,
            mu: 1e6,
        }),
        formulation: Formulation::Full { fbar: false },
    };
    let model = Model::build(mesh, vec![part], None, 0.9).unwrap();
    let mut sim =
        Simulation::new(model, LoopSettings::default(), c, Vec::new(), None, false).unwrap();
    let mut stop = None;
    while sim.time < 0.01 {
        if let Err(e) = sim.step(f64::INFINITY) {
            stop = Some(e);
            break;
        }
        assert!(sim.u.iter().flatten().all(|x| x.is_finite()));
    }
    match stop {
        Some(SolverError::ElementFailure {
            element,
            reason,
            time,
            ..
        }) => {
            assert_eq!(element, 0);
            assert!(reason.contains("excessively distorted"), "{reason}");
            assert!(time > 0.0 && time < 0.01);
        }
        other => panic!("expected an excessive-distortion stop, got {other:?}"),
    }
}
