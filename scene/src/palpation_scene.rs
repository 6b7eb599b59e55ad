//! A palpation's scene: built in memory ([`PalpationSetup::scene_spec`]), the typed
//! [`SceneSpec`] that `palpa palpate`, campaigns and the accuracy study run, with no TOML text in
//! between; and as a file ([`PalpationSetup::scene_toml`], saved as `scene.toml` so that
//! `palpa run` repeats the run), which parses to exactly the same value: a test holds the two
//! equal for every kind of setting.

use crate::build::build_scene_with;
use crate::contact_spec::{ContactScene, HandScene, MotionScene};
use crate::curve_spec::CurveSpec;
use crate::palpation::{ElementChoice, PalpationSetup, Place};
use crate::phantom_spec::{PhantomScene, TumourScene};
use crate::spec::{
    BoundarySpec, MassScalingSpec, MeshSpec, OutputSpec, PartSpec, RunSpec, SceneSpec,
};
use crate::Scene;
use material::quantity::{Density, Length, Number, Pressure, Time};
use material::spec::{OgdenSpec, PronySpec};
use material::MaterialSpec;
use phantom::Phantom;
use solver::element::{HourglassForm, HourglassModulus};
use solver::output::atomic::write_atomic;
use solver::simulation::StepEstimate;
use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::Path;

/// `s` as a TOML string (the toml crate's quoting: a basic string `"..."` for an ordinary
/// title, as Rust's `{:?}` writes it; escapes or a literal string where needed).
fn toml_str(s: &str) -> String {
    toml::Value::String(s.to_string()).to_string()
}

/// A plain number as TOML reads it back: as Rust prints it, unless that would be an integer
/// too large for TOML (then in exponent form). The value must be finite.
fn toml_num(x: f64) -> String {
    if x.abs() < 1e15 {
        format!("{x}")
    } else {
        format!("{x:?}")
    }
}

/// The phantom parts and their laws (see the palpation module doc); tumours come after them.
const PART_MATERIALS: [(&str, &str); 5] = [
    ("flesh", "paper:flesh"),
    ("liver", "paper:liver"),
    ("ribs", "paper:ribs"),
    ("viscera", "paper:flesh"),
    ("spine", "paper:ribs"),
];

/// The fields of a palpation's VTK frames.
const FRAME_FIELDS: [&str; 4] = ["displacement", "part", "von_mises", "max_principal"];

/// The liver's Ogden moduli mu_p (Pa), exponents and Prony moduli (Pa) with their times (ms).
const LIVER_MU: [f64; 3] = [89.14, 9.965, -92.75];
const LIVER_ALPHA: [f64; 3] = [1.0, 19.0656, -10.9604];
const LIVER_PRONY: [f64; 3] = [6970.1, 58327.0, 35291.0];
const LIVER_TAU_MS: [f64; 3] = [10.0, 100.0, 1000.0];

/// The liver card with its moduli scaled by `s` (a tumour's stiffness factor).
fn scaled_liver(s: f64) -> ([f64; 3], [f64; 3]) {
    (LIVER_MU.map(|m| m * s), LIVER_PRONY.map(|m| m * s))
}

/// The liver law with its shear and Prony moduli scaled by `s`.
fn scaled_liver_spec(s: f64) -> MaterialSpec {
    let (mu, g) = scaled_liver(s);
    MaterialSpec::Ogden(OgdenSpec {
        density: Density(1050.0),
        mu: mu.map(Pressure).to_vec(),
        alpha: LIVER_ALPHA.map(Number).to_vec(),
        bulk_modulus: None,
        poisson_ratio: Some(Number(0.49)),
        convention: None,
        prony: g
            .iter()
            .zip(LIVER_TAU_MS)
            .map(|(&g, tau)| PronySpec {
                modulus: Pressure(g),
                tau: Some(Time(tau * 1e-3)),
                decay: None,
            })
            .collect(),
        prony_on: Some("green_lagrange".into()),
    })
}

/// Text of the liver card with its moduli scaled by `s`, for the scene file.
fn scaled_liver_card(s: f64) -> String {
    let (mu, g) = scaled_liver(s);
    let a = LIVER_ALPHA;
    let t = LIVER_TAU_MS;
    format!(
        "law = \"ogden\"\ndensity = \"1050 kg/m^3\"\nmu = [\"{} Pa\", \"{} Pa\", \"{} Pa\"]\n\
         alpha = [{:?}, {}, {}]\npoisson_ratio = 0.49\nprony = [\n  \
         {{ modulus = \"{} Pa\", tau = \"{} ms\" }},\n  {{ modulus = \"{} Pa\", tau = \"{} ms\" }},\n  \
         {{ modulus = \"{} Pa\", tau = \"{} ms\" }},\n]\nprony_on = \"green_lagrange\"\n",
        mu[0], mu[1], mu[2], a[0], a[1], a[2], g[0], t[0], g[1], t[1], g[2], t[2]
    )
}

impl ElementChoice {
    /// Scene keys of the choice, one per line.
    fn scene_keys(&self) -> String {
        let (formulation, hourglass, coefficient, modulus) = self.part_keys();
        let mut s = format!("formulation = {formulation:?}");
        if let Some(h) = hourglass {
            s += &format!("\nhourglass = {h:?}");
        }
        if let Some(c) = coefficient {
            s += &format!("\nhourglass_coefficient = {c:?}");
        }
        if let Some(m) = modulus {
            s += &format!("\nhourglass_modulus = {m:?}");
        }
        s
    }

    /// The `[[part]]` keys of the choice: formulation, hourglass form, coefficient and modulus.
    fn part_keys(
        &self,
    ) -> (
        &'static str,
        Option<&'static str>,
        Option<f64>,
        Option<&'static str>,
    ) {
        match self.hourglass() {
            None => ("full_fbar", None, None, None),
            Some((HourglassForm::Physical, _)) => ("one_point", Some("physical"), Some(1.0), None),
            Some((form, modulus)) => (
                "one_point",
                Some(match form {
                    HourglassForm::Viscous => "viscous",
                    _ => "stiffness",
                }),
                None,
                Some(match modulus {
                    HourglassModulus::PWave => "p_wave",
                    HourglassModulus::Shear => "shear",
                }),
            ),
        }
    }
}

impl PalpationSetup {
    /// The `[mesh.phantom]` table of its scene.
    pub fn phantom_scene(&self) -> PhantomScene {
        PhantomScene {
            variant: Some(self.variant.clone()),
            voxel: Some(Length(self.voxel)),
            fat_thickness: Some(Length(self.fat_thickness)),
            respiratory_phase: Some(Number(self.respiratory_phase)),
            skin: (self.skin != phantom::Skin::Voxel).then(|| self.skin.name().to_string()),
            tumours: self
                .tumours
                .iter()
                .map(|t| TumourScene {
                    center: t.center.map(Length),
                    radius: Length(t.radius),
                    stiffness: Number(t.stiffness_factor),
                })
                .collect(),
            ..Default::default()
        }
    }

    /// The element choice of part `part`: its own entry, the liver's for a tumour, else the
    /// common one.
    fn element_of(&self, part: &str) -> ElementChoice {
        let tumour = phantom::is_tumour_part(part);
        *self
            .part_elements
            .get(part)
            .or_else(|| tumour.then(|| self.part_elements.get("liver")).flatten())
            .unwrap_or(&self.element)
    }

    /// The scene, typed, as the solver runs it.
    pub fn scene_spec(&self) -> SceneSpec {
        let tumour_names: Vec<String> = (0..self.tumours.len())
            .map(phantom::tumour_part_name)
            .collect();
        let materials: BTreeMap<String, MaterialSpec> = tumour_names
            .iter()
            .zip(&self.tumours)
            .map(|(n, t)| (n.clone(), scaled_liver_spec(t.stiffness_factor)))
            .collect();
        let parts = PART_MATERIALS
            .iter()
            .map(|&(p, m)| (p.to_string(), m.to_string()))
            .chain(tumour_names.iter().map(|n| (n.clone(), n.clone())))
            .map(|(name, material)| self.part_spec(name, material))
            .collect();
        SceneSpec {
            run: RunSpec {
                end_time: Time(self.duration),
                dt_factor: Some(Number(self.dt_factor)),
                precision: Some(self.precision.label().into()),
                dt_max: None,
                dt_min: None,
                max_hourglass_ratio: None,
                hourglass_check_after: None,
                max_steps: None,
                subcycling: (self.subcycling > 1).then_some(Number(self.subcycling as f64)),
                step_estimate: (self.step_estimate != StepEstimate::Element)
                    .then(|| self.step_estimate.name().into()),
                title: Some(self.title.clone()),
            },
            mesh: MeshSpec {
                generator: Some("phantom".into()),
                file: None,
                units: None,
                origin: None,
                size: None,
                divisions: None,
                grading: None,
                distortion: None,
                seed: None,
                part: None,
                max_elements: None,
                phantom: Some(self.phantom_scene()),
                numbering: None,
            },
            materials,
            parts,
            node_sets: BTreeMap::new(),
            boundaries: self.boundaries(),
            loads: Vec::new(),
            gravity: None,
            damping: None,
            bulk_viscosity: None,
            mass_scaling: self.mass_scaling.map(|t| MassScalingSpec {
                target_dt: t,
                max_added: Some(Number(self.mass_scaling_limit)),
            }),
            relaxation: None,
            initial_velocities: Vec::new(),
            output: OutputSpec {
                interval: Some(Time(self.sample_interval)),
                vtk: Some(self.vtk),
                fields: Some(FRAME_FIELDS.map(String::from).to_vec()),
                probe: Some("roi".into()),
                ..Default::default()
            },
            indenters: Vec::new(),
            hands: vec![self.hand()],
            contact: Some(ContactScene {
                surface: Some("skin".into()),
                ..Default::default()
            }),
        }
    }

    /// The scene file text: [`PalpationSetup::scene_spec`] as a file (a test holds the two
    /// equal). Every quantity is written in SI with its unit.
    pub fn scene_toml(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "# A two-finger palpation of the built-in abdomen phantom, written by palpa.\n\
             # Run it again with `palpa run scene.toml --out DIR`.\n"
        );
        let mut subcycling = match self.subcycling {
            1 => String::new(),
            k => format!("subcycling = {k}\n"),
        };
        if self.step_estimate != StepEstimate::Element {
            subcycling += &format!("step_estimate = {:?}\n", self.step_estimate.name());
        }
        let _ = writeln!(
            s,
            "[run]\ntitle = {}\nend_time = \"{} s\"\ndt_factor = {}\nprecision = {:?}\n{subcycling}",
            toml_str(&self.title),
            self.duration,
            toml_num(self.dt_factor),
            self.precision.label()
        );
        self.write_mesh(&mut s);
        self.write_parts(&mut s);
        s.push_str("[[boundary]]\nnodes = \"back\"\nfix = [\"all\"]\n\n");
        for (set, ax) in self.rollers() {
            let _ = writeln!(s, "[[boundary]]\nnodes = {set:?}\nfix = [{ax:?}]\n");
        }
        if let Some(t) = self.mass_scaling {
            let _ = writeln!(
                s,
                "[mass_scaling]\ntarget_dt = \"{t}\"\nmax_added = {}\n",
                toml_num(self.mass_scaling_limit)
            );
        }
        let place = match &self.place {
            Place::Named(n) => format!("location = {}", toml_str(n)),
            Place::At(x, y) => format!("at = [\"{x} m\", \"{y} m\"]"),
        };
        let _ = writeln!(
            s,
            "[[hand]]\nname = \"hand\"\n{place}\ndiameter = \"{} m\"\nspacing = \"{} m\"\n\
             length = \"{HAND_LENGTH} m\"\nmotion = {{ kind = \"displacement\", curve = {{ kind = \"smooth_step\", \
             value = \"{} m\", end = \"{} s\" }} }}\n",
            self.finger_diameter, self.finger_spacing, self.depth, self.duration
        );
        s.push_str("[contact]\nsurface = \"skin\"\n\n");
        let _ = writeln!(
            s,
            "[output]\ninterval = \"{} s\"\nvtk = {}\nfields = {:?}\nprobe = \"roi\"",
            self.sample_interval, self.vtk, FRAME_FIELDS
        );
        s
    }

    /// `[mesh]` and `[mesh.phantom]` of the scene file.
    fn write_mesh(&self, s: &mut String) {
        let _ = writeln!(
            s,
            "[mesh]\ngenerator = \"phantom\"\n\n[mesh.phantom]\nvariant = {}\nvoxel = \"{} m\"\n\
             fat_thickness = \"{} m\"\nrespiratory_phase = {}",
            toml_str(&self.variant),
            self.voxel,
            self.fat_thickness,
            toml_num(self.respiratory_phase)
        );
        if self.skin != phantom::Skin::Voxel {
            let _ = writeln!(s, "skin = {}", toml_str(self.skin.name()));
        }
        if !self.tumours.is_empty() {
            s.push_str("tumours = [\n");
            for t in &self.tumours {
                let _ = writeln!(
                    s,
                    "  {{ center = [\"{} m\", \"{} m\", \"{} m\"], radius = \"{} m\", stiffness = {} }},",
                    t.center[0],
                    t.center[1],
                    t.center[2],
                    t.radius,
                    toml_num(t.stiffness_factor)
                );
            }
            s.push_str("]\n");
        }
        s.push('\n');
    }

    /// The tumours' `[materials]` and every `[[part]]` of the scene file.
    fn write_parts(&self, s: &mut String) {
        let el = |part: &str| {
            let keys = self.element_of(part).scene_keys();
            match self.max_bulk_ratio {
                Some(r) => format!("{keys}\nmax_bulk_ratio = {r:?}"),
                None => keys,
            }
        };
        let tumour_names: Vec<String> = (0..self.tumours.len())
            .map(phantom::tumour_part_name)
            .collect();
        for (n, t) in tumour_names.iter().zip(&self.tumours) {
            let _ = writeln!(
                s,
                "[materials.{n}]\n{}",
                scaled_liver_card(t.stiffness_factor)
            );
        }
        for (p, m) in &PART_MATERIALS {
            let _ = writeln!(s, "[[part]]\nname = {p:?}\nmaterial = {m:?}\n{}\n", el(p));
        }
        for n in &tumour_names {
            let _ = writeln!(s, "[[part]]\nname = {n:?}\nmaterial = {n:?}\n{}\n", el(n));
        }
    }

    /// Write the scene file into `dir` (`scene.toml`, atomically) and build the scene from
    /// [`PalpationSetup::scene_spec`], reusing `phantom` if given (it must be the phantom of
    /// [`PalpationSetup::phantom_params`]). The file's text only serves error messages.
    pub fn build_scene(&self, dir: &Path, phantom: Option<Phantom>) -> Result<Scene, String> {
        let path = dir.join("scene.toml");
        let src = self.scene_toml();
        write_atomic(&path, src.as_bytes())?;
        build_scene_with(self.scene_spec(), &path, &src, phantom)
    }

    /// The `[[part]]` of part `name` with law `material`.
    fn part_spec(&self, name: String, material: String) -> PartSpec {
        let (formulation, hourglass, coefficient, modulus) = self.element_of(&name).part_keys();
        PartSpec {
            name,
            material,
            formulation: Some(formulation.into()),
            hourglass: hourglass.map(String::from),
            hourglass_coefficient: coefficient.map(Number),
            hourglass_modulus: modulus.map(String::from),
            max_bulk_ratio: self.max_bulk_ratio.map(Number),
            bulk_modulus: None,
        }
    }

    /// The back fixed, rollers on the cut planes (the reduced phantom is cut at x too).
    fn boundaries(&self) -> Vec<BoundarySpec> {
        let fixed = |nodes: &str, dir: &str| BoundarySpec {
            nodes: nodes.into(),
            fix: Some(vec![dir.into()]),
            symmetry: None,
            displacement: None,
            velocity: None,
        };
        let mut b = vec![fixed("back", "all")];
        b.extend(self.rollers().iter().map(|(set, ax)| fixed(set, ax)));
        b
    }

    /// The cut planes and the direction each roller fixes.
    fn rollers(&self) -> &'static [(&'static str, &'static str)] {
        if self.variant == "full" {
            &[("cut_ymin", "y"), ("cut_ymax", "y")]
        } else {
            &[("cut_xmax", "x"), ("cut_ymin", "y"), ("cut_ymax", "y")]
        }
    }

    /// The two-finger hand, pressing `depth` in `duration` with a smooth step.
    fn hand(&self) -> HandScene {
        let (location, at) = match &self.place {
            Place::Named(n) => (Some(n.clone()), None),
            Place::At(x, y) => (None, Some([Length(*x), Length(*y)])),
        };
        HandScene {
            name: "hand".into(),
            point: None,
            direction: None,
            location,
            at,
            spacing_axis: None,
            diameter: Length(self.finger_diameter),
            spacing: Length(self.finger_spacing),
            length: Length(HAND_LENGTH),
            tilt_deg: None,
            gap: None,
            motion: MotionScene::Displacement {
                curve: CurveSpec::SmoothStep {
                    value: Length(self.depth),
                    from: None,
                    start: None,
                    end: Time(self.duration),
                },
            },
            friction: None,
        }
    }
}

/// Finger length, tip to far end (m).
const HAND_LENGTH: f64 = 0.06;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::palpation::Fidelity;
    use phantom::Tumour;
    use solver::element::precision::Precision;
    use solver::model::StepTarget;

    /// The scene file of a setup parses to the scene the solver runs, for every kind of
    /// setting: places, tumours, per-part elements, mass scaling on and off, the K/G cap,
    /// precision, subcycling, the global step estimate, the full phantom.
    #[test]
    fn the_scene_file_parses_to_the_scene_built_in_memory() {
        let mut setups = vec![PalpationSetup::default()];
        let mut s = PalpationSetup {
            title: "P07 \"quoted\" \\ tab\t bell\u{7} nul\u{0} é".into(),
            place: Place::At(-0.0725, 0.1815),
            tumours: vec![
                Tumour {
                    center: [-0.06, 0.18, 0.15],
                    radius: 0.01,
                    stiffness_factor: 5.0,
                },
                Tumour {
                    center: [-0.05, 0.2, 0.14],
                    radius: 0.008,
                    stiffness_factor: 2e16,
                },
            ],
            mass_scaling: Some(StepTarget::Step(4e-6)),
            mass_scaling_limit: 3e19,
            max_bulk_ratio: Some(5000.0),
            precision: Precision::F32,
            vtk: false,
            depth: 0.0123,
            duration: 0.0217,
            ..Default::default()
        };
        s.part_elements
            .insert("liver".into(), ElementChoice::FullFbar);
        s.part_elements
            .insert("ribs".into(), ElementChoice::OnePointStiffness);
        setups.push(s);
        let mut fast = PalpationSetup {
            variant: "full".into(),
            mass_scaling: None,
            ..Default::default()
        };
        Fidelity::Fast.apply(&mut fast);
        setups.push(fast);
        setups.push(PalpationSetup {
            subcycling: 16,
            ..Default::default()
        });
        setups.push(PalpationSetup {
            step_estimate: StepEstimate::Global,
            ..Default::default()
        });
        for e in ElementChoice::ALL {
            setups.push(PalpationSetup {
                element: e,
                mass_scaling: Some(StepTarget::Initial(2.0)),
                ..Default::default()
            });
        }
        for s in &setups {
            let text = s.scene_toml();
            let parsed: SceneSpec = toml::from_str(&text).unwrap();
            assert_eq!(
                format!("{parsed:#?}"),
                format!("{:#?}", s.scene_spec()),
                "{text}"
            );
        }
    }

    /// An ordinary title or location is written as before (`{:?}`): the scene files of
    /// earlier runs keep their bytes.
    #[test]
    fn ordinary_strings_are_quoted_as_before() {
        for t in [
            "palpation",
            "paper protocol: P07",
            "quick: A_d15mm_t25ms",
            "reduced",
            "B",
        ] {
            assert_eq!(toml_str(t), format!("{t:?}"));
        }
    }

    /// Values the scene file could not carry are refused before it is written.
    #[test]
    fn non_finite_values_are_refused() {
        let bad = [
            PalpationSetup {
                mass_scaling_limit: f64::NAN,
                ..Default::default()
            },
            PalpationSetup {
                tumours: vec![Tumour {
                    center: [0.0, 0.1, f64::INFINITY],
                    radius: 0.01,
                    stiffness_factor: 2.0,
                }],
                ..Default::default()
            },
            PalpationSetup {
                respiratory_phase: f64::NAN,
                ..Default::default()
            },
        ];
        for s in bad {
            let e = s.validate().unwrap_err();
            assert!(e.contains("finite"), "{e}");
        }
    }
}
