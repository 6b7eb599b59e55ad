//! The Hertz block of `palpa study`: accuracy against cost on a contact problem with a closed
//! form.
//!
//! The verification case of `scenes/hertz-sphere.toml` (a rigid sphere, R = 5 mm, pressed
//! 0.5 mm into a nearly incompressible neo-Hookean block, quarter model, penalty contact) runs
//! with the knobs of the palpation study, each changed alone from a base setting: mesh size
//! (graded elements per edge), element formulation, selective mass scaling (targets of 2, 4 and
//! 10 times the initial stable step) and the time-step factor. Its error is the relative error
//! of the final indenter force against Hertz's `F = 4/3 E / (1 - nu^2) sqrt(R) d^1.5`
//! ([`crate::cases::closed::hertz_force`]), so here the reference is exact rather than the most
//! expensive run.

use crate::cases::closed::{hertz_force, hertz_scene};
use crate::hard::run_contact_scene;
use crate::study_row::StudyRow;

/// One Hertz setting.
#[derive(Clone, Debug)]
pub struct HertzSetup {
    /// Graded elements per edge.
    pub div: usize,
    /// Extra `[[part]]` keys (the formulation).
    pub part_keys: &'static str,
    /// Time-step factor (`None`: the default 0.9).
    pub dt_factor: Option<f64>,
    /// Mass-scaling target in multiples of the initial stable step.
    pub mass_scaling: Option<f64>,
}

/// The element formulations compared: (label, part keys).
const ELEMENTS: [(&str, &str); 3] = [
    ("1-pt viscous HG (default)", ""),
    ("1-pt stiffness HG", "hourglass = \"stiffness\""),
    ("full F-bar", "formulation = \"full_fbar\""),
];

/// The Hertz variants: (knob, setting, setup).
pub fn plan(quick: bool) -> Vec<(String, String, HertzSetup)> {
    let (meshes, base_div): (&[usize], usize) = if quick {
        (&[8, 12, 16], 12)
    } else {
        (&[12, 16, 24, 32], 24)
    };
    let base = HertzSetup {
        div: base_div,
        part_keys: "",
        dt_factor: None,
        mass_scaling: None,
    };
    let mut v = Vec::new();
    for &d in meshes {
        v.push((
            "hertz mesh".to_string(),
            format!("{d}^3 graded elements"),
            HertzSetup {
                div: d,
                ..base.clone()
            },
        ));
    }
    for (label, keys) in ELEMENTS {
        v.push((
            "hertz element".to_string(),
            label.to_string(),
            HertzSetup {
                part_keys: keys,
                ..base.clone()
            },
        ));
    }
    for k in [2.0, 4.0, 10.0] {
        v.push((
            "hertz mass scaling".to_string(),
            format!("target {k}x initial step"),
            HertzSetup {
                mass_scaling: Some(k),
                ..base.clone()
            },
        ));
    }
    for f in [0.5, 0.75] {
        v.push((
            "hertz dt factor".to_string(),
            format!("{f}"),
            HertzSetup {
                dt_factor: Some(f),
                ..base.clone()
            },
        ));
    }
    v
}

/// Run every Hertz variant; `progress(i, setting)` is told which one starts.
pub fn run(quick: bool, mut progress: impl FnMut(usize, &str)) -> Vec<StudyRow> {
    let f_hertz = hertz_force();
    plan(quick)
        .into_iter()
        .enumerate()
        .map(|(i, (knob, setting, h))| {
            progress(i, &format!("{knob}: {setting}"));
            let scene = hertz_scene(h.div, h.part_keys, h.dt_factor, h.mass_scaling);
            match run_contact_scene(&scene, &format!("study-hertz-{i}"), "sphere") {
                Ok(r) => StudyRow {
                    knob,
                    setting,
                    against: "Hertz closed form".into(),
                    elements: r.elements,
                    steps: r.steps,
                    element_cycles: r.elements as f64 * r.steps as f64,
                    wall: r.wall,
                    added_mass_percent: r.added_mass_percent,
                    peak_force: r.force,
                    force_error: (r.force - f_hertz).abs() / f_hertz,
                    stress_error: f64::NAN,
                    status: scene::run::RunStatus::Completed,
                },
                Err(e) => StudyRow::failed(knob, setting, e),
            }
        })
        .collect()
}

/// The number of Hertz variants.
pub fn count(quick: bool) -> usize {
    plan(quick).len()
}
