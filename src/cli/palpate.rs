//! `palpa palpate`: the main job. Builds the reduced abdomen phantom, presses the two-finger
//! hand into it with the paper's materials and protocol ([`scene::palpation`]), and writes
//! into `--out`:
//! - `scene.toml`: the scene that was run (`palpa run` repeats it);
//! - `frame_*.vtu` + `frame.pvd` (ParaView), `history.csv`, `summary.json`;
//! - `probe.csv` / `probe_stress.csv`: the ROI's stresses every 5 ms;
//! - `roi_stress.csv`: per ROI element its centroid and maximum principal stress at each sample;
//! - `roi.csv`, `locations.json`: the ROI and the palpation locations of the phantom;
//! - `force_indentation.csv`: the hand's travel and reaction at every history row, raw and after
//!   the 1 ms centred moving average;
//! - `force_indentation.png` (both curves) and `roi_stress_map.png` (the ROI's maximum principal stress at the
//!   end of the press in plan view, with the phantom's outlines and the fingers, drawn as
//!   `palpa serve` draws a prediction: [`surrogate::render_picture`]).

use super::run::{print_summary, run_loaded};
use super::units;
use scene::palpation::{read_probe, ElementChoice, Fidelity, PalpationSetup, Place, ProbeSamples};
use solver::output::atomic::write_atomic;
use solver::output::filter::{moving_average, FORCE_FILTER};
use solver::output::history::{column, read_history};
use solver::simulation::StepEstimate;
use std::fmt::Write;
use std::path::Path;
use std::time::Instant;

/// Command-line options of `palpa palpate`.
#[derive(clap::Args, Debug)]
pub struct PalpateArgs {
    /// Press at a point (x, y) of the body surface, e.g. `-50mm,190mm` (plain numbers: m).
    #[arg(long, allow_hyphen_values = true, conflicts_with = "location")]
    pub at: Option<String>,
    /// Press at a named phantom location: A (liver near the surface), B (deeper), C (under
    /// the ribs), or P01..P25 (the 5 x 5 raster). Default A.
    #[arg(long)]
    pub location: Option<String>,
    /// Indentation depth.
    #[arg(long, default_value = "15mm")]
    pub depth: String,
    /// Time to reach the depth (smooth ramp); the run ends then.
    #[arg(long, default_value = "25ms")]
    pub duration: String,
    /// Interval between ROI stress samples and VTK frames.
    #[arg(long, default_value = "5ms")]
    pub sample_interval: String,
    /// Voxel edge of the phantom: 5mm (default, ~23k hexahedra, about two minutes on 2 cores)
    /// or 3mm (close to the paper's CT, ~105k hexahedra).
    #[arg(long)]
    pub voxel: Option<String>,
    /// The paper's resolution: the same as `--voxel 3mm`.
    #[arg(long, conflicts_with = "voxel")]
    pub paper: bool,
    /// Phantom variant: reduced (the paper's reduced model) or full.
    #[arg(long, default_value = "reduced")]
    pub variant: String,
    /// Subcutaneous fat thickness.
    #[arg(long, default_value = "15mm")]
    pub fat: String,
    /// Respiratory phase, 0 (exhalation) .. 1 (inspiration).
    #[arg(long, default_value_t = 0.0)]
    pub phase: f64,
    /// The skin: `voxel` (smoothed voxel steps, the paper's image-based mesh) or `fitted`
    /// (one node layer on the body's outline, the grid's columns stretched to meet it).
    #[arg(long, default_value = "voxel")]
    pub skin: String,
    /// Element formulation [default: one_point]: one_point (= 1pt-viscous-shear: one-point, viscous hourglass
    /// control scaled by the shear modulus), 1pt-viscous or 1pt-stiffness (hourglass scaled by
    /// the P-wave modulus, LS-DYNA types 1 and 4), 1pt-stiffness-shear, 1pt-physical
    /// (assumed-strain stabilisation, in the spirit of LS-DYNA type 6), or full_fbar.
    #[arg(long)]
    pub element: Option<String>,
    /// Selective mass scaling: `initial` (default: an element gets mass only when it shrinks
    /// below the initial stable step, so the step never falls; the added mass is reported),
    /// `K x initial` (the fast preset's is `1.3x initial`), a time step such as `4us`, or `off`.
    #[arg(long)]
    pub mass_scaling: Option<String>,
    /// Time-step safety factor.
    #[arg(long, default_value_t = solver::simulation::DEFAULT_DT_FACTOR)]
    pub dt_factor: f64,
    /// The incompressibility knob: cap every part's bulk modulus at this multiple of its
    /// initial shear modulus (K/G; the paper's flesh has 5e4). The dilatational wave, and so
    /// the stable step, follow; the summary states the change. Default: the laws' own.
    #[arg(long)]
    pub max_bulk_ratio: Option<f64>,
    /// Preset of the accuracy knobs: `standard` (the options as given) or `fast`
    /// (1pt-physical elements, K/G capped at 5000, f32 kernels and mass scaling to 1.3x the
    /// initial step: about a quarter of the steps; its measured error against F-bar elements is
    /// printed with the summary and in docs/palpate.md).
    #[arg(long, default_value = "standard")]
    pub fidelity: String,
    /// Number type of the element kernels: f64 or f32 (single-precision kernels; the laws,
    /// history and nodal state stay f64; measured cost in docs/performance.md). Default: the
    /// preset's (f64 for standard, f32 for fast).
    #[arg(long)]
    pub precision: Option<String>,
    /// Subcycling: the interior of a part whose stable step is many times the run's (the
    /// liver's, beside the flesh's) steps up to this many times longer (a power of two; 1, the
    /// default, is off). Its measured time and error: docs/performance.md, "Subcycling".
    #[arg(long, default_value_t = 1)]
    pub subcycle: u32,
    /// How the stable step is estimated: global (the mesh's largest eigenvalue by Lanczos
    /// iteration, as Abaqus/Explicit; never below the element estimate) or element (element by
    /// element, as LS-DYNA, and as scenes and campaigns do by default). Default: global, except
    /// with --fidelity fast (whose error budget was measured element by element) and
    /// --subcycle. Its measured time and error: docs/performance.md, "The global step estimate".
    #[arg(long)]
    pub step_estimate: Option<String>,
    /// Skip the VTK frames.
    #[arg(long)]
    pub no_vtk: bool,
    /// Output directory.
    #[arg(long, default_value = "results/palpate")]
    pub out: std::path::PathBuf,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

impl PalpateArgs {
    /// The palpation these options describe.
    pub fn setup(&self) -> Result<PalpationSetup, String> {
        let mut s = PalpationSetup::default();
        s.place = match (&self.at, &self.location) {
            (Some(xy), _) => {
                let v = units::lengths(xy, 2, "--at")?;
                Place::At(v[0], v[1])
            }
            (None, Some(n)) => Place::Named(n.to_uppercase()),
            (None, None) => Place::Named("A".into()),
        };
        s.depth = units::length(&self.depth, "--depth")?;
        s.duration = units::time(&self.duration, "--duration")?;
        s.sample_interval = units::time(&self.sample_interval, "--sample-interval")?;
        if self.paper {
            s.voxel = phantom::PAPER_VOXEL;
        }
        if let Some(v) = &self.voxel {
            s.voxel = units::length(v, "--voxel")?;
        }
        if !["reduced", "full"].contains(&self.variant.as_str()) {
            return Err(format!(
                "--variant: `{}` is not reduced or full",
                self.variant
            ));
        }
        s.variant = self.variant.clone();
        s.fat_thickness = units::length(&self.fat, "--fat")?;
        s.respiratory_phase = self.phase;
        s.skin = self
            .skin
            .parse::<phantom::Skin>()
            .map_err(|e| format!("--skin: {e}"))?;
        s.element = self
            .element
            .as_deref()
            .unwrap_or("one_point")
            .parse::<ElementChoice>()
            .map_err(|e| format!("--element: {e}"))?;
        s.mass_scaling = solver::model::StepTarget::parse_switch(
            self.mass_scaling.as_deref().unwrap_or("initial"),
        )
        .map_err(|e| format!("--mass-scaling: {e}"))?;
        s.dt_factor = self.dt_factor;
        s.max_bulk_ratio = self.max_bulk_ratio;
        let fidelity = self
            .fidelity
            .parse::<Fidelity>()
            .map_err(|e| format!("--fidelity: {e}"))?;
        if fidelity == Fidelity::Fast
            && (self.element.is_some()
                || self.max_bulk_ratio.is_some()
                || self.precision.is_some()
                || self.mass_scaling.is_some())
        {
            return Err(Fidelity::fast_conflict("--fidelity fast", true));
        }
        fidelity.apply(&mut s);
        s.fidelity = fidelity;
        if let Some(p) = &self.precision {
            s.precision = solver::element::precision::Precision::parse(p)
                .map_err(|e| format!("--precision: {e}"))?;
        }
        if !(1..=1024).contains(&self.subcycle) || !self.subcycle.is_power_of_two() {
            return Err(format!(
                "--subcycle: must be a power of two from 1 (off) to 1024, got {}",
                self.subcycle
            ));
        }
        s.subcycling = self.subcycle;
        s.step_estimate = match &self.step_estimate {
            Some(v) => StepEstimate::parse(v).map_err(|e| format!("--step-estimate: {e}"))?,
            None if fidelity == Fidelity::Fast || s.subcycling > 1 => StepEstimate::Element,
            None => StepEstimate::Global,
        };
        if s.subcycling > 1 && s.step_estimate != StepEstimate::Element {
            return Err(
                "--step-estimate global cannot be combined with --subcycle (a subcycled part's \
                 elements report their step over k)"
                    .into(),
            );
        }
        s.vtk = !self.no_vtk;
        s.title = match &s.place {
            Place::Named(n) => format!("palpation at {n}"),
            Place::At(x, y) => format!("palpation at ({:.1} mm, {:.1} mm)", x * 1e3, y * 1e3),
        };
        s.validate()?;
        Ok(s)
    }
}

/// Run `palpa palpate`.
pub fn palpate(args: &PalpateArgs) -> Result<(), String> {
    let setup = args.setup()?;
    let out = &args.out;
    std::fs::create_dir_all(out)
        .map_err(|e| format!("{}: cannot create the output directory: {e}", out.display()))?;
    let t0 = Instant::now();
    let mut scene = setup.build_scene(out, None)?;
    let build_s = t0.elapsed().as_secs_f64();
    let ph = scene
        .phantom
        .as_ref()
        .ok_or("internal: the palpation scene has no phantom")?;
    write_atomic(&out.join("roi.csv"), ph.roi.to_csv().as_bytes())?;
    write_atomic(
        &out.join("locations.json"),
        ph.locations.to_json().as_bytes(),
    )?;
    let centroids = ph.roi.centroids.clone();
    let view = super::view_geometry::from_phantom(
        ph,
        &scene.sim.model.mesh,
        super::view_geometry::fingers(setup.finger_spacing, setup.finger_diameter),
        format!("palpa palpate: {}", setup.title),
    )?;
    let at = match &setup.place {
        Place::At(x, y) => [*x, *y],
        Place::Named(n) => {
            let l = ph
                .locations
                .get(n)
                .ok_or_else(|| format!("location {n}: the phantom has no such location"))?;
            [l.surface[0], l.surface[1]]
        }
    };
    let voxel_mm = setup.voxel * 1e3;
    if !args.quiet {
        println!(
            "{}: {} voxel {:.1} mm: {} hexahedra, {} nodes, ROI {} elements; built in {:.2} s",
            setup.title,
            setup.variant,
            setup.voxel * 1e3,
            scene.sim.model.mesh.elements.len(),
            scene.sim.model.mesh.nodes.len(),
            centroids.len(),
            build_s
        );
    }
    let (summary, err) = run_loaded(&mut scene, out, args.quiet);
    print_summary(&summary);
    println!("  fidelity: {}", setup.fidelity.describe());
    // Post-processing also for a failed run: what was written stays usable.
    let picture = MapSetup {
        view: &view,
        at,
        subtitle: format!(
            "ROI maximum principal stress [kPa], palpa solver ({} phantom, {voxel_mm:.1} mm voxels), end of the press",
            setup.variant
        ),
    };
    let post = postprocess(out, &centroids, &picture);
    match (&post, &err) {
        (Ok(p), _) => {
            println!(
                "  peak force {:.2} N at {:.2} mm indentation ({:.2} N at {:.2} mm after the {:.0} ms moving average); ROI max principal stress {:.3} .. {:.3} kPa (peak |.| {:.3} kPa)",
                p.peak_force,
                p.depth_at_peak * 1e3,
                p.peak_filtered,
                p.depth_at_peak_filtered * 1e3,
                FORCE_FILTER * 1e3,
                p.stress_min / 1e3,
                p.stress_max / 1e3,
                p.stress_min.abs().max(p.stress_max.abs()) / 1e3
            );
        }
        (Err(e), None) => return Err(e.clone()),
        (Err(_), Some(_)) => {}
    }
    println!("  output: {}", out.display());
    match err {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

/// Figures of a finished palpation.
struct Post {
    /// Peak of the raw hand reaction (N) and the indentation there (m).
    peak_force: f64,
    depth_at_peak: f64,
    /// Peak of the filtered hand reaction ([`FORCE_FILTER`]) (N) and the indentation there (m).
    peak_filtered: f64,
    depth_at_peak_filtered: f64,
    stress_min: f64,
    stress_max: f64,
}

/// What the stress map shows besides the stresses.
struct MapSetup<'a> {
    view: &'a surrogate::ViewGeometry,
    /// The hand's position (x, y) [m].
    at: [f64; 2],
    subtitle: String,
}

/// Index and value of the largest entry (None when empty).
fn peak(v: &[f64]) -> Option<(usize, f64)> {
    v.iter()
        .copied()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(&b.1))
}

/// Write `roi_stress.csv`, `force_indentation.csv` and the two plots; return the headline
/// figures. The penalty contact force chatters from one history row to the next, so the force
/// is reported and plotted also after the centred moving average of
/// `solver::output::filter` (the filter the campaign's dataset and the studies use).
fn postprocess(out: &Path, centroids: &[[f64; 3]], map: &MapSetup) -> Result<Post, String> {
    let (cols, rows) = read_history(&out.join("history.csv"))?;
    let time = column(&cols, &rows, "time").ok_or("history.csv has no time")?;
    let travel = column(&cols, &rows, "hand_travel").ok_or("history.csv has no hand_travel")?;
    let force = column(&cols, &rows, "hand_reaction").ok_or("history.csv has no hand_reaction")?;
    let filtered = moving_average(&time, &force, FORCE_FILTER);
    let (k, peak_raw) = peak(&force).ok_or("history.csv is empty")?;
    let (kf, peak_filtered) = peak(&filtered).ok_or("history.csv is empty")?;
    write_atomic(
        &out.join("force_indentation.csv"),
        force_csv(&time, &travel, &force, &filtered).as_bytes(),
    )?;
    let probe = read_probe(out, "hand")?;
    write_atomic(
        &out.join("roi_stress.csv"),
        roi_csv(&probe, centroids).as_bytes(),
    )?;
    let series = verification::Series {
        plot: "force_indentation".into(),
        title: "two-finger palpation: force against indentation".into(),
        axes: ("indentation (mm)".into(), "force (N)".into()),
        log: false,
        curves: [
            ("hand reaction (raw penalty contact force)", &force),
            ("centred 1 ms moving average", &filtered),
        ]
        .into_iter()
        .map(|(name, f)| {
            let points = travel.iter().zip(f).map(|(d, f)| (d * 1e3, *f)).collect();
            (name.to_string(), points)
        })
        .collect(),
    };
    verification::plot::draw(&series, out)?;
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for row in &probe.stress {
        for &s in row {
            lo = lo.min(s);
            hi = hi.max(s);
        }
    }
    if let Some(last) = probe.stress.last() {
        if !last.is_empty() && last.len() == centroids.len() {
            let c = ndarray::Array2::from_shape_fn((centroids.len(), 3), |(i, j)| centroids[i][j]);
            let picture = surrogate::Picture {
                values: last,
                centroids: c.view(),
                view: Some(map.view),
                scale: surrogate::ColourScale::of_values(last),
                hand: Some(surrogate::Hand {
                    x: map.at[0],
                    y: map.at[1],
                    force: probe.force.last().copied().unwrap_or(0.0),
                }),
                time_s: probe.time.last().copied(),
                hull: None,
                subtitle: map.subtitle.clone(),
                warnings: Vec::new(),
            };
            surrogate::render_picture(&picture, &out.join("roi_stress_map.png"))
                .map_err(|e| format!("roi_stress_map.png: {e}"))?;
        }
    }
    Ok(Post {
        peak_force: peak_raw,
        depth_at_peak: travel[k],
        peak_filtered,
        depth_at_peak_filtered: travel[kf],
        stress_min: lo,
        stress_max: hi,
    })
}

/// `time,indentation,force,force_filtered` (s, m, N, N): the hand's travel and reaction at
/// every history row, raw and after the [`FORCE_FILTER`] centred moving average.
fn force_csv(time: &[f64], travel: &[f64], force: &[f64], filtered: &[f64]) -> String {
    let mut s = String::from("time,indentation,force,force_filtered\n");
    for i in 0..time.len() {
        let _ = writeln!(s, "{},{},{},{}", time[i], travel[i], force[i], filtered[i]);
    }
    s
}

/// `element,x,y,z,s_<t ms>...`: per ROI element its centroid (m) and its maximum principal
/// stress (Pa) at each sample time.
fn roi_csv(p: &ProbeSamples, centroids: &[[f64; 3]]) -> String {
    let mut s = String::from("element,x,y,z");
    for t in &p.time {
        let _ = write!(s, ",s_{:.3}ms", t * 1e3);
    }
    s.push('\n');
    for (i, e) in p.elements.iter().enumerate() {
        let c = centroids.get(i).copied().unwrap_or([f64::NAN; 3]);
        let _ = write!(s, "{e},{:.6},{:.6},{:.6}", c[0], c[1], c[2]);
        for row in &p.stress {
            let _ = write!(s, ",{:.6e}", row[i]);
        }
        s.push('\n');
    }
    s
}
