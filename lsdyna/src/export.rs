//! `palpa export --lsdyna`: a scene, as palpa runs it, written as a keyword deck that LS-DYNA
//! or the OpenRadioss starter reads.
//!
//! The deck is what [`crate::scene`] reads back: the mesh as `*NODE` / `*ELEMENT_SOLID` (ids
//! from 1 in palpa's order), each part with its `*SECTION_SOLID`, `*HOURGLASS` and `*MAT_...`,
//! the boundary conditions on titled node sets (the scene's set names), the indenters as
//! `*MAT_RIGID` parts meshed with hexahedra ([`contact::tessellate`]) and moved by
//! `*BOUNDARY_PRESCRIBED_MOTION_RIGID`, the contact as one
//! `*CONTACT_AUTOMATIC_SURFACE_TO_SURFACE` per indenter against a `*SET_SEGMENT` of exactly the
//! faces palpa's contact uses, and the output requests.
//!
//! Numbers: the long format (`*KEYWORD LONG=Y`, 20 columns) by default. Each number is written
//! as the shortest decimal that converts back (with [`crate::units`]'s one correctly rounded
//! operation) to the very same binary SI value, when one fits the field; otherwise with as many
//! digits as fit (the export reports how many values that is and the largest rounding).
//!
//! Where LS-DYNA has no exact form of the scene, the deck holds LS-DYNA's nearest form and a
//! `$palpa:` comment with palpa's own ([`crate::annotate`]), and the export lists each case:
//! - a smooth-step curve is tabulated (`--curve-points`, 2001 by default: at most 1.8e-7 of
//!   the step's amplitude off the quintic);
//! - an analytic indenter (sphere, capsule, cylinder, box) is meshed; the chord of `4n`
//!   segments is `r (1 - cos(pi / 4n))` off the exact surface (`--segments`, 64 by default);
//! - palpa's compressible neo-Hookean law is written as the one-term Ogden law (alpha = 2) with
//!   the same small-strain moduli; a simplified-rubber law without a curve gets its neo-Hookean
//!   curve tabulated; Prony terms on the deviatoric strain, `strain = "small"` and the plain
//!   fully integrated element (`full`, no F-bar) have no LS-DYNA switch;
//! - shear-scaled hourglass control is written as the P-wave-scaled LS-DYNA type with the
//!   equivalent coefficient `QM = Q sqrt(2 mu / (lambda + 2 mu))` (viscous) or
//!   `Q 2 mu / (lambda + 2 mu)` (stiffness), which LS-DYNA runs identically;
//! - palpa's soft penalty is `SOFT = 1` with SFS small enough that the segment-based stiffness
//!   never exceeds the soft one on the surface (LS-DYNA takes the larger of the two);
//! - the hourglass guard, dynamic relaxation, a `dt_min` time and palpa's contact numerics
//!   (stiffness cap, samples, margins) are comments only.

use crate::units::Units;
use ::scene::def::DtMin;
use ::scene::Scene;
use contact::tessellate::{self as shapes, HexMesh};
use contact::{Curve, MotionSpec, PenaltyKind, ShapeSpec};
use material::quantity::Dim;
use material::{Material, MaterialSpec};
use solver::bc::Kinematic;
use solver::element::precision::Precision;
use solver::element::{Formulation, HourglassForm, HourglassModulus};
use solver::model::StepTarget;
use solver::simulation::StepEstimate;
use std::collections::HashMap;
use std::fmt::Write;

/// How to write a deck.
#[derive(Clone, Debug)]
pub struct ExportOptions {
    /// The deck's unit system.
    pub units: Units,
    /// Long format (20 columns per field) or the standard one.
    pub long: bool,
    /// Points of a tabulated smooth step.
    pub curve_points: usize,
    /// Segments around a circle of a meshed indenter.
    pub segments: usize,
    /// The scene file, named in the header.
    pub source: String,
}

impl Default for ExportOptions {
    fn default() -> Self {
        ExportOptions {
            units: Units::parse("kg-mm-ms").expect("a known system"),
            long: true,
            curve_points: 2001,
            segments: 64,
            source: String::new(),
        }
    }
}

/// A written deck and what the export had to approximate.
#[derive(Clone, Debug)]
pub struct Exported {
    /// The deck.
    pub text: String,
    /// What LS-DYNA reads differently from palpa, and how (one line each).
    pub notes: Vec<String>,
    /// Numbers written.
    pub values: usize,
    /// Numbers that could not be written exactly in their field.
    pub inexact: usize,
    /// The largest relative rounding of those.
    pub max_rounding: f64,
}

/// The next binary number up or down.
fn step(x: f64, up: bool) -> f64 {
    if x == 0.0 {
        let tiny = f64::from_bits(1);
        return if up { tiny } else { -tiny };
    }
    let b = x.to_bits();
    f64::from_bits(if (x > 0.0) == up { b + 1 } else { b - 1 })
}

/// The shortest decimal of `v` that fits `w` columns with a space before it, and the number it
/// reads back as. Plain notation is preferred while it is at most four characters longer.
fn fmt_num(v: f64, w: usize) -> (String, f64) {
    if v == 0.0 {
        return ("0.0".into(), 0.0);
    }
    let room = w.saturating_sub(1).max(1);
    let disp = {
        let s = format!("{v}");
        if s.contains(['.', 'e', 'E']) {
            s
        } else {
            format!("{s}.")
        }
    };
    let exp = format!("{v:e}");
    if disp.len() <= room && (1e-4..1e15).contains(&v.abs()) {
        return (disp, v);
    }
    if exp.len() <= room {
        return (exp, v);
    }
    if disp.len() <= room {
        return (disp, v);
    }
    for p in (0..=16).rev() {
        let s = format!("{v:.p$e}");
        let s = match s.split_once('e') {
            Some((m, e)) if m.contains('.') => {
                let m = m.trim_end_matches('0').trim_end_matches('.');
                format!("{m}e{e}")
            }
            _ => s,
        };
        if s.len() <= room {
            let back = s.parse::<f64>().unwrap_or(v);
            return (s, back);
        }
    }
    let s = format!("{v:.0e}");
    let back = s.parse::<f64>().unwrap_or(v);
    (s, back)
}

struct W {
    out: String,
    long: bool,
    u: Units,
    values: usize,
    inexact: usize,
    max_rel: f64,
}

impl W {
    fn width(&self, std: usize) -> usize {
        if self.long {
            20
        } else {
            std
        }
    }
    fn kw(&mut self, k: &str) {
        self.out.push('*');
        self.out.push_str(k);
        self.out.push('\n');
    }
    fn comment(&mut self, s: &str) {
        for line in s.lines() {
            let _ = writeln!(self.out, "$ {line}");
        }
    }
    fn palpa(&mut self, key: &str, value: &str) {
        let _ = writeln!(self.out, "$palpa: {key} = {value}");
    }
    fn text_line(&mut self, s: &str) {
        self.out.push_str(s);
        self.out.push('\n');
    }
    /// A card of cells (already formatted to width).
    fn card(&mut self, cells: &[String]) {
        let s: String = cells.concat();
        self.out.push_str(s.trim_end());
        self.out.push('\n');
    }
    fn int(&self, v: i64, std: usize) -> String {
        format!("{:>w$}", v, w = self.width(std))
    }
    fn blank(&self, std: usize) -> String {
        " ".repeat(self.width(std))
    }
    fn text(&self, s: &str, std: usize) -> String {
        format!("{:<w$}", s, w = self.width(std))
    }
    /// A plain number.
    fn num(&mut self, v: f64, std: usize) -> String {
        self.back(v, v, |x| x, std)
    }
    /// An SI value of dimension `d`, in deck units, reading back exactly when it can.
    fn si(&mut self, v: f64, d: Dim, std: usize) -> String {
        let u = self.u.clone();
        self.back(v, u.from_si(v, d), move |x| u.to_si(x, d), std)
    }
    /// A node coordinate: its exact text when one fits (see [`Units::si_text`]), and whether
    /// it is exact.
    fn coordinate(&mut self, v: f64) -> (String, bool) {
        let w = self.width(16);
        let t = self
            .u
            .si_text(v, Dim::LENGTH, w - 1)
            .or_else(|| self.u.si_text(v, Dim::LENGTH, w));
        match t {
            Some(t) => {
                self.values += 1;
                (format!("{t:>w$}"), true)
            }
            // The reader converts coordinates from their text: without an exact text the
            // comment carries the value.
            None => (self.si(v, Dim::LENGTH, 16), false),
        }
    }
    /// Write a deck number `x` near `guess` such that `back(x) == target`, if one exists
    /// within a few binary steps and fits the field.
    fn back(&mut self, target: f64, guess: f64, back: impl Fn(f64) -> f64, std: usize) -> String {
        let w = self.width(std);
        self.values += 1;
        let mut cands = vec![guess];
        let (mut up, mut dn) = (guess, guess);
        for _ in 0..6 {
            up = step(up, true);
            dn = step(dn, false);
            cands.push(up);
            cands.push(dn);
        }
        let exact = cands.iter().copied().find(|&x| back(x) == target);
        let x = exact.unwrap_or(guess);
        let (mut s, mut read) = fmt_num(x, w);
        if back(read) != target {
            // Exactly, at the price of the space before it.
            let (s2, r2) = fmt_num(x, w + 1);
            if s2.len() <= w && back(r2) == target {
                (s, read) = (s2, r2);
            }
        }
        let got = back(read);
        if got != target {
            if std::env::var_os("PALPA_EXPORT_DEBUG").is_some() {
                eprintln!("inexact: target {target:e} wrote {s} (exact candidate: {exact:?})");
            }
            self.inexact += 1;
            let rel = if target != 0.0 {
                ((got - target) / target).abs()
            } else {
                got.abs()
            };
            self.max_rel = self.max_rel.max(rel);
        }
        format!("{s:>w$}")
    }
}

/// A TOML number (shortest round trip, always with a `.` or an exponent).
fn tn(v: f64) -> String {
    let s = format!("{v:?}");
    if s.contains(['.', 'e', 'E']) || s.contains("inf") || s.contains("NaN") {
        s
    } else {
        format!("{s}.0")
    }
}

fn tv(v: &[f64]) -> String {
    format!(
        "[{}]",
        v.iter().map(|&x| tn(x)).collect::<Vec<_>>().join(", ")
    )
}

fn tv3(v: [f64; 3]) -> String {
    tv(&v)
}

/// A scene material card as inline TOML (SI).
fn card_toml(spec: &MaterialSpec, built: &Material) -> String {
    match spec {
        MaterialSpec::LinearElastic(s) | MaterialSpec::NeoHookean(s) => {
            let law = if matches!(spec, MaterialSpec::LinearElastic(_)) {
                "linear_elastic"
            } else {
                "neo_hookean"
            };
            let mut f = vec![
                format!("law = \"{law}\""),
                format!("density = {}", tn(s.density.0)),
            ];
            for (k, v) in [
                ("youngs_modulus", s.youngs_modulus.map(|x| x.0)),
                ("poisson_ratio", s.poisson_ratio.map(|x| x.0)),
                ("shear_modulus", s.shear_modulus.map(|x| x.0)),
                ("bulk_modulus", s.bulk_modulus.map(|x| x.0)),
            ] {
                if let Some(v) = v {
                    f.push(format!("{k} = {}", tn(v)));
                }
            }
            if let Some(st) = &s.strain {
                f.push(format!("strain = \"{st}\""));
            }
            format!("{{ {} }}", f.join(", "))
        }
        MaterialSpec::Ogden(s) => {
            let mut f = vec![
                "law = \"ogden\"".to_string(),
                format!("density = {}", tn(s.density.0)),
                format!("mu = {}", tv(&s.mu.iter().map(|x| x.0).collect::<Vec<_>>())),
                format!(
                    "alpha = {}",
                    tv(&s.alpha.iter().map(|x| x.0).collect::<Vec<_>>())
                ),
            ];
            if let Some(k) = s.bulk_modulus {
                f.push(format!("bulk_modulus = {}", tn(k.0)));
            }
            if let Some(nu) = s.poisson_ratio {
                f.push(format!("poisson_ratio = {}", tn(nu.0)));
            }
            if let Some(c) = &s.convention {
                f.push(format!("convention = \"{c}\""));
            }
            if !s.prony.is_empty() {
                let terms: Vec<String> = s
                    .prony
                    .iter()
                    .map(|p| match (p.tau, p.decay) {
                        (Some(t), _) => {
                            format!("{{ modulus = {}, tau = {} }}", tn(p.modulus.0), tn(t.0))
                        }
                        (None, Some(d)) => {
                            format!("{{ modulus = {}, decay = {} }}", tn(p.modulus.0), tn(d.0))
                        }
                        _ => format!("{{ modulus = {} }}", tn(p.modulus.0)),
                    })
                    .collect();
                f.push(format!("prony = [{}]", terms.join(", ")));
            }
            if let Some(p) = &s.prony_on {
                f.push(format!("prony_on = \"{p}\""));
            }
            format!("{{ {} }}", f.join(", "))
        }
        MaterialSpec::SimplifiedRubber(s) => {
            let mut f = vec![
                "law = \"simplified_rubber\"".to_string(),
                format!("density = {}", tn(s.density.0)),
                format!("bulk_modulus = {}", tn(s.bulk_modulus.0)),
            ];
            if let Some(g) = s.shear_modulus {
                f.push(format!("shear_modulus = {}", tn(g.0)));
            }
            if let Some(d) = s.damping {
                f.push(format!("damping = {}", tn(d.0)));
            }
            let pts: Option<Vec<(f64, f64)>> = match (&s.curve, &s.curve_file, built) {
                (Some(c), _, _) => Some(c.iter().map(|(l, p)| (l.0, p.0)).collect()),
                (None, Some(_), Material::SimplifiedRubber(foam)) => match &foam.curve {
                    material::foam::UniaxialCurve::Table(l, p) => {
                        Some(l.iter().copied().zip(p.iter().copied()).collect())
                    }
                    _ => None,
                },
                _ => None,
            };
            if let Some(pts) = pts {
                f.push(format!(
                    "curve = [{}]",
                    pts.iter()
                        .map(|(l, p)| format!("[{}, {}]", tn(*l), tn(*p)))
                        .collect::<Vec<_>>()
                        .join(", ")
                ));
            }
            format!("{{ {} }}", f.join(", "))
        }
        MaterialSpec::PiecewiseLinearPlasticity(s) => {
            let mut f = vec![
                "law = \"piecewise_linear_plasticity\"".to_string(),
                format!("density = {}", tn(s.density.0)),
                format!("youngs_modulus = {}", tn(s.youngs_modulus.0)),
                format!("poisson_ratio = {}", tn(s.poisson_ratio.0)),
            ];
            if let Some(y) = s.yield_stress {
                f.push(format!("yield_stress = {}", tn(y.0)));
            }
            if let Some(t) = s.tangent_modulus {
                f.push(format!("tangent_modulus = {}", tn(t.0)));
            }
            if let Some(h) = &s.hardening {
                f.push(format!(
                    "hardening = [{}]",
                    h.iter()
                        .map(|(e, y)| format!("[{}, {}]", tn(e.0), tn(y.0)))
                        .collect::<Vec<_>>()
                        .join(", ")
                ));
            }
            if let Some(fs) = s.failure_strain {
                f.push(format!("failure_strain = {}", tn(fs.0)));
            }
            format!("{{ {} }}", f.join(", "))
        }
    }
}

/// Registry of titled node sets (by members).
#[derive(Default)]
struct Sets {
    by_nodes: HashMap<Vec<u32>, i64>,
    list: Vec<(i64, String, Vec<u32>)>,
    titles: HashMap<String, usize>,
}

impl Sets {
    fn get(&mut self, nodes: &[u32], name: &str) -> i64 {
        let mut key = nodes.to_vec();
        key.sort_unstable();
        key.dedup();
        if let Some(&sid) = self.by_nodes.get(&key) {
            return sid;
        }
        let sid = self.list.len() as i64 + 1;
        let n = self.titles.entry(name.to_string()).or_insert(0);
        *n += 1;
        let title = if *n == 1 {
            name.to_string()
        } else {
            format!("{name}_{n}")
        };
        self.by_nodes.insert(key.clone(), sid);
        self.list.push((sid, title, key));
        sid
    }
}

struct CurveOut {
    id: i64,
    title: String,
    /// Points in SI with the dimensions of the use.
    points: Vec<(f64, f64)>,
    xdim: Dim,
    ydim: Dim,
    note: Option<(String, String)>,
}

/// Write a scene as a deck.
pub fn export(scene: &Scene, opts: &ExportOptions) -> Result<Exported, String> {
    let setup = &scene.setup;
    let model = &scene.sim.model;
    let mesh = &model.mesh;
    let mut notes: Vec<String> = Vec::new();
    let mut w = W {
        out: String::new(),
        long: opts.long,
        u: opts.units.clone(),
        values: 0,
        inexact: 0,
        max_rel: 0.0,
    };
    let u = opts.units.clone();
    let end = scene.end_time;
    let mut curves: Vec<CurveOut> = Vec::new();
    // Curves against time; a material curve's abscissa is a number (`x` dimension NONE).
    let mut new_curve = |title: &str,
                         points: Vec<(f64, f64)>,
                         xdim: Dim,
                         ydim: Dim,
                         note: Option<(String, String)>| {
        let id = curves.len() as i64 + 1;
        curves.push(CurveOut {
            id,
            title: title.to_string(),
            points,
            xdim,
            ydim,
            note,
        });
        id
    };
    let n_pts = opts.curve_points.max(3);
    // Sample times: round numbers in the deck's time unit (12 significant digits), and the
    // curve evaluated at exactly the time the deck states.
    let ut = u.clone();
    let nice = move |t: f64| -> f64 {
        if t == 0.0 {
            return 0.0;
        }
        let d = ut.from_si(t, Dim::TIME);
        let r: f64 = format!("{d:.11e}").parse().unwrap_or(d);
        ut.to_si(r, Dim::TIME)
    };
    let sample = |t0: f64, t1: f64, f: &dyn Fn(f64) -> f64| -> Vec<(f64, f64)> {
        let mut p = Vec::with_capacity(n_pts + 2);
        if t0 > 0.0 {
            p.push((0.0, f(0.0)));
        }
        for k in 0..n_pts {
            let t = if k == 0 {
                t0
            } else if k + 1 == n_pts {
                t1
            } else {
                nice(t0 + (t1 - t0) * k as f64 / (n_pts - 1) as f64)
            };
            p.push((t, f(t)));
        }
        if t1 < end {
            p.push((end, f(end)));
        }
        p
    };
    // A scene's boundary curves take the boundary forms (constant, polyline, smooth step
    // between two values); a motion's forms, which a scene never gives a boundary, are
    // written as their points without a comment.
    let bc_points = |c: &Curve| -> (Vec<(f64, f64)>, Option<(String, String)>) {
        match c {
            Curve::Constant { value: v } => (vec![(0.0, *v), (end, *v)], None),
            Curve::Polyline(p) => (p.clone(), None),
            Curve::SmoothStep { .. } | Curve::Ramp { .. } | Curve::Table { .. } => {
                (motion_points(c, end, 1.0, &sample).0, None)
            }
            Curve::SmoothStepBetween { t0, t1, from, to } => (
                sample(*t0, *t1, &|t| c.value(t)),
                Some((
                    "curve".into(),
                    format!(
                        "{{ kind = \"smooth_step\", t0 = {}, t1 = {}, from = {}, to = {} }}",
                        tn(*t0),
                        tn(*t1),
                        tn(*from),
                        tn(*to)
                    ),
                )),
            ),
        }
    };

    // Header.
    w.kw(if opts.long {
        "KEYWORD LONG=Y"
    } else {
        "KEYWORD"
    });
    w.comment(&format!(
        "Written by palpa export --lsdyna from {} (`{}`).",
        if opts.source.is_empty() {
            "a scene"
        } else {
            &opts.source
        },
        scene.title
    ));
    w.comment(&format!(
        "Units: {} (mass-length-time); stresses in {}, forces in {}, densities in {}.",
        u.name,
        u.unit_name(Dim::PRESSURE),
        u.unit_name(Dim::FORCE),
        u.unit_name(Dim::DENSITY)
    ));
    w.comment("Lines starting with $palpa: carry palpa's exact scene where LS-DYNA's keywords approximate it;\nLS-DYNA skips them like any comment (see docs/lsdyna.md).");
    let mut run_note = Vec::new();
    if let Some(g) = setup.hourglass_guard {
        run_note.push(format!("max_hourglass_ratio = {}", tn(g.ratio)));
        if let Some(a) = g.after {
            run_note.push(format!("hourglass_check_after = {}", tn(a)));
        }
        notes.push("the hourglass guard (run.max_hourglass_ratio) has no LS-DYNA keyword: a $palpa comment".into());
    }
    if let Some(DtMin::Time(t)) = setup.dt_min {
        run_note.push(format!("dt_min = {}", tn(t)));
    }
    if setup.precision != Precision::F64 {
        run_note.push(format!("precision = {:?}", setup.precision.label()));
        notes.push(format!(
            "run.precision = \"{}\" has no LS-DYNA keyword (LS-DYNA's precision is its executable's): a $palpa comment",
            setup.precision.label()
        ));
    }
    if setup.subcycling > 1 {
        run_note.push(format!("subcycling = {}", setup.subcycling));
        notes.push(format!(
            "run.subcycling = {} is palpa's own nodal-partition subcycling, not written as an LS-DYNA keyword: a $palpa comment",
            setup.subcycling
        ));
    }
    if setup.step_estimate != StepEstimate::Element {
        run_note.push(format!("step_estimate = {:?}", setup.step_estimate.name()));
        notes.push(
            "run.step_estimate = \"global\" has no LS-DYNA keyword (LS-DYNA estimates the step element by element): a $palpa comment"
                .into(),
        );
    }
    if !run_note.is_empty() {
        w.palpa("run", &format!("{{ {} }}", run_note.join(", ")));
    }
    if let Some(r) = setup.relaxation {
        w.palpa(
            "relaxation",
            &format!("{{ tolerance = {} }}", tn(r.tolerance)),
        );
        notes.push("[relaxation] (palpa's dynamic relaxation to a static solution) has no LS-DYNA equivalent: LS-DYNA runs the deck as a transient; a $palpa comment".into());
    }
    w.kw("TITLE");
    w.text_line(&scene.title);
    if let Some([l, t, m]) = u.control_units_words() {
        w.kw("CONTROL_UNITS");
        let cells = [w.text(l, 10), w.text(t, 10), w.text(m, 10), w.text("k", 10)];
        w.card(&cells);
    } else {
        w.comment(&format!(
            "(*CONTROL_UNITS has no words for {}: state the units when reading the deck)",
            u.name
        ));
    }

    // Control.
    let dt0 = model.scaled_dt.min(model.initial_dt.0);
    w.kw("CONTROL_TERMINATION");
    {
        let endtim = w.si(end, Dim::TIME, 10);
        let dtmin = match setup.dt_min {
            Some(DtMin::Factor(f)) => w.num(f, 10),
            _ => w.blank(10),
        };
        let endmas = match &setup.mass_scaling {
            Some(m) => {
                let t = m.max_added;
                w.back(t, 100.0 * t, |x| x / 100.0, 10)
            }
            None => w.blank(10),
        };
        let cells = [endtim, w.blank(10), dtmin, w.blank(10), endmas];
        w.card(&cells);
    }
    w.kw("CONTROL_TIMESTEP");
    if let Some(StepTarget::Step(t)) = setup.mass_scaling.map(|m| m.target) {
        w.palpa("target_dt", &tn(t));
    }
    let f = setup.dt_factor;
    let mut lctm = 0;
    if let Some(dm) = setup.dt_max {
        lctm = new_curve(
            "largest time step",
            vec![(0.0, dm), (end, dm)],
            Dim::TIME,
            Dim::TIME,
            None,
        );
    }
    {
        let tssfac = w.num(f, 10);
        let (dt2ms, dt2msf) = match setup.mass_scaling.map(|m| m.target) {
            None => (w.blank(10), None),
            Some(StepTarget::Step(t)) => {
                let u2 = u.clone();
                (
                    w.back(
                        t,
                        -u.from_si(t / f, Dim::TIME),
                        move |x| f * u2.to_si(-x, Dim::TIME),
                        10,
                    ),
                    None,
                )
            }
            Some(StepTarget::Initial(k)) => {
                // DT2MS states the step LS-DYNA reaches (informative), DT2MSF the multiple.
                let step = k * f * model.initial_dt.0;
                let s = w.si(-step / f, Dim::TIME, 10);
                (s, Some(k))
            }
        };
        let lc = if lctm > 0 {
            w.int(lctm, 10)
        } else {
            w.blank(10)
        };
        let cells = [w.blank(10), tssfac, w.blank(10), w.blank(10), dt2ms, lc];
        w.card(&cells);
        if let Some(k) = dt2msf {
            let c = [w.num(k, 10)];
            w.card(&c);
        }
    }
    let _ = dt0;
    w.kw("CONTROL_BULK_VISCOSITY");
    match setup.bulk {
        Some(b) => {
            let cells = [w.num(b.quadratic, 10), w.num(b.linear, 10), w.int(1, 10)];
            w.card(&cells);
        }
        None => {
            w.palpa("bulk_viscosity", "false");
            let cells = [w.num(1e-9, 10), w.num(1e-9, 10), w.int(1, 10)];
            w.card(&cells);
            notes.push("bulk viscosity off: LS-DYNA cannot switch it off (0 means its default); written as Q1 = Q2 = 1e-9 with a $palpa comment".into());
        }
    }
    if let Some(a) = setup.damping {
        w.kw("DAMPING_GLOBAL");
        let cells = [w.blank(10), w.si(a, Dim::RATE, 10)];
        w.card(&cells);
    }
    if let Some(g) = setup.gravity {
        for (k, axis) in ["X", "Y", "Z"].iter().enumerate() {
            if g[k] != 0.0 {
                let lc = new_curve(
                    &format!("gravity {}", axis.to_lowercase()),
                    vec![(0.0, -g[k]), (end, -g[k])],
                    Dim::TIME,
                    Dim::ACCELERATION,
                    None,
                );
                w.kw(&format!("LOAD_BODY_{axis}"));
                let cells = [w.int(lc, 10), w.num(1.0, 10)];
                w.card(&cells);
            }
        }
    }

    // Parts, sections, laws, hourglass control.
    let n_parts = setup.parts.len();
    let mut max_e: f64 = 0.0;
    for (pi, p) in setup.parts.iter().enumerate() {
        let pid = pi as i64 + 1;
        let m = &p.material;
        let c0 = m.initial_wave_speed();
        let lambda2mu = m.density() * c0 * c0;
        let two_mu = 2.0 * m.initial_shear_modulus();
        let g0 = m.initial_shear_modulus();
        let k0 = lambda2mu - 2.0 * two_mu / 3.0;
        max_e = max_e.max(material::law::young_poisson(k0, g0).0);
        w.kw("PART");
        w.text_line(&p.name);
        let (elform, ihq, qm, element_note) = match p.formulation {
            Formulation::OnePoint(h) => {
                let ratio = match (h.modulus, h.form) {
                    (_, HourglassForm::Physical) | (HourglassModulus::PWave, _) => 1.0,
                    (HourglassModulus::Shear, HourglassForm::Viscous) => {
                        (two_mu / lambda2mu).sqrt()
                    }
                    (HourglassModulus::Shear, HourglassForm::Stiffness) => two_mu / lambda2mu,
                };
                let form = match h.form {
                    HourglassForm::Viscous => "viscous",
                    HourglassForm::Stiffness => "stiffness",
                    HourglassForm::Physical => "physical",
                };
                let ihq = match h.form {
                    HourglassForm::Viscous => 2,
                    HourglassForm::Stiffness => 4,
                    HourglassForm::Physical => 6,
                };
                let modulus = match h.modulus {
                    HourglassModulus::PWave => "p_wave",
                    HourglassModulus::Shear => "shear",
                };
                if h.form == HourglassForm::Physical {
                    notes.push(format!(
                        "part `{}`: physical hourglass control Q = {} written as LS-DYNA type 6 (Belytschko-Bindeman assumed strain, a co-rotational rate form; palpa's acts on the Green strain of the modes: they agree at small strain)",
                        p.name, h.coefficient
                    ));
                } else if h.modulus == HourglassModulus::Shear {
                    notes.push(format!(
                        "part `{}`: shear-scaled {form} hourglass control Q = {} written as LS-DYNA type {ihq} with the equivalent QM = {:.6e}",
                        p.name,
                        h.coefficient,
                        h.coefficient * ratio
                    ));
                }
                let keys = if h.form == HourglassForm::Physical {
                    String::new()
                } else {
                    format!(", hourglass_modulus = \"{modulus}\"")
                };
                (
                    1,
                    ihq,
                    h.coefficient * ratio,
                    format!(
                        "{{ formulation = \"one_point\", hourglass = \"{form}\", hourglass_coefficient = {}{keys} }}",
                        tn(h.coefficient)
                    ),
                )
            }
            Formulation::Full { fbar } => {
                if !fbar {
                    notes.push(format!(
                        "part `{}`: palpa's plain fully integrated element (no F-bar) has no LS-DYNA form; written as ELFORM 2 (selectively reduced) with a $palpa comment",
                        p.name
                    ));
                }
                (
                    2,
                    0,
                    0.0,
                    format!(
                        "{{ formulation = \"{}\" }}",
                        if fbar { "full_fbar" } else { "full" }
                    ),
                )
            }
        };
        w.palpa("element", &element_note);
        let cells = [
            w.int(pid, 10),
            w.int(pid, 10),
            w.int(pid, 10),
            w.int(0, 10),
            if elform == 1 {
                w.int(pid, 10)
            } else {
                w.int(0, 10)
            },
        ];
        w.card(&cells);
        w.kw("SECTION_SOLID");
        let cells = [w.int(pid, 10), w.int(elform, 10)];
        w.card(&cells);
        if elform == 1 {
            w.kw("HOURGLASS");
            let cells = [w.int(pid, 10), w.int(ihq, 10), w.num(qm, 10)];
            w.card(&cells);
        }
        if let Some(b) = p.bulk.as_ref().filter(|b| b.applied_pa != b.original_pa) {
            notes.push(format!(
                "part `{}`: the card carries the bulk modulus that ran, {:e} Pa, set by `{}` (the law's own is {:e} Pa)",
                p.name, b.applied_pa, b.setting, b.original_pa
            ));
        }
        write_material(&mut w, pid, p, &mut notes, &mut new_curve)?;
    }

    // Sets from the mesh's names.
    let mut names: HashMap<Vec<u32>, String> = HashMap::new();
    for (n, nodes) in &mesh.node_sets {
        names.entry(nodes.clone()).or_insert_with(|| n.clone());
    }
    let mut sets = Sets::default();
    let set_for = |nodes: &[u32], fallback: &str, sets: &mut Sets| -> i64 {
        let mut key = nodes.to_vec();
        key.sort_unstable();
        key.dedup();
        let name = names
            .get(&key)
            .cloned()
            .unwrap_or_else(|| fallback.to_string());
        sets.get(&key, &name)
    };
    let all_nodes = nodes_all(mesh.nodes.len());

    // Boundary conditions.
    let mut fixed: Vec<(i64, [bool; 3])> = Vec::new();
    let mut motions: Vec<String> = Vec::new();
    let mut motion_sids: Vec<i64> = Vec::new();
    for (i, c) in setup.constraints.iter().enumerate() {
        let sid = set_for(&c.nodes, &format!("boundary_{}", i + 1), &mut sets);
        match &c.kind {
            Kinematic::Fixed => match fixed.iter_mut().find(|f| f.0 == sid) {
                Some(f) => f.1[c.dof] = true,
                None => {
                    let mut d = [false; 3];
                    d[c.dof] = true;
                    fixed.push((sid, d));
                }
            },
            Kinematic::Displacement(cv) | Kinematic::Velocity(cv) => {
                let vel = matches!(c.kind, Kinematic::Velocity(_));
                let (pts, note) = bc_points(cv);
                let lc = new_curve(
                    &format!(
                        "{} {} of set {sid}",
                        if vel { "velocity" } else { "displacement" },
                        ["x", "y", "z"][c.dof]
                    ),
                    pts,
                    Dim::TIME,
                    if vel { Dim::VELOCITY } else { Dim::LENGTH },
                    note,
                );
                let cells = [
                    w.int(sid, 10),
                    w.int(c.dof as i64 + 1, 10),
                    w.int(if vel { 0 } else { 2 }, 10),
                    w.int(lc, 10),
                    w.num(1.0, 10),
                ];
                motions.push(cells.concat().trim_end().to_string());
                motion_sids.push(sid);
            }
        }
    }
    let mut load_cards = Vec::new();
    for (i, l) in setup.loads.iter().enumerate() {
        let sid = set_for(&l.nodes, &format!("load_{}", i + 1), &mut sets);
        let (pts, note) = bc_points(&l.curve);
        let lc = new_curve(
            &format!("force {} per node of set {sid}", ["x", "y", "z"][l.dof]),
            pts,
            Dim::TIME,
            Dim::FORCE,
            note,
        );
        let cells = [
            w.int(sid, 10),
            w.int(l.dof as i64 + 1, 10),
            w.int(lc, 10),
            w.num(1.0, 10),
        ];
        load_cards.push(cells.concat().trim_end().to_string());
    }
    let mut iv_cards = Vec::new();
    for (i, (nodes, v)) in setup.initial_velocity.iter().enumerate() {
        let sid = if *nodes == all_nodes {
            0
        } else {
            set_for(nodes, &format!("initial_velocity_{}", i + 1), &mut sets)
        };
        iv_cards.push((sid, *v));
    }
    // Reactions: SPCFORC for fixed sets, BNDOUT for prescribed ones.
    let (mut spcforc, mut bndout) = (false, false);
    for (name, nodes) in &setup.output.reactions {
        let mut key = nodes.clone();
        key.sort_unstable();
        key.dedup();
        match sets.by_nodes.get(&key) {
            Some(sid) if fixed.iter().any(|f| f.0 == *sid) => spcforc = true,
            Some(sid) if motion_sids.contains(sid) => bndout = true,
            _ => notes.push(format!(
                "reaction of set `{name}`: the set carries no boundary condition, and LS-DYNA reports reactions only where it does; not written"
            )),
        }
    }

    // Output.
    let out = &setup.output;
    if let Some(dt) = out.vtk_interval {
        w.kw("DATABASE_BINARY_D3PLOT");
        let fields: Vec<String> = out.fields.iter().map(|f| format!("\"{f}\"")).collect();
        w.palpa("fields", &format!("[{}]", fields.join(", ")));
        let cells = [w.si(dt, Dim::TIME, 10)];
        w.card(&cells);
    }
    let h = out.history_interval;
    let mut ascii = vec!["GLSTAT"];
    if setup.contact.is_some() {
        ascii.push("RCFORC");
    }
    if spcforc {
        ascii.push("SPCFORC");
    }
    if bndout {
        ascii.push("BNDOUT");
    }
    for a in ascii {
        w.kw(&format!("DATABASE_{a}"));
        let cells = [w.si(h, Dim::TIME, 10)];
        w.card(&cells);
    }
    let mut probe_set = None;
    if let Some((name, els)) = &out.probe {
        probe_set = Some((1i64, name.clone(), els.clone()));
        if out.vtk_interval.is_none() {
            if let Some(fi) = out.frame_interval {
                w.kw("DATABASE_ELOUT");
                let cells = [w.si(fi, Dim::TIME, 10)];
                w.card(&cells);
            }
        }
        w.kw("DATABASE_HISTORY_SOLID_SET");
        let cells = [w.int(1, 10)];
        w.card(&cells);
    }

    // Indenters: rigid parts.
    let mut rigid: Vec<(i64, HexMesh, Option<(Vec<[f64; 3]>, Vec<[u32; 3]>)>)> = Vec::new();
    let mut motion_rigid: Vec<String> = Vec::new();
    let mut vectors: Vec<[f64; 3]> = Vec::new();
    let mut contact_cards: Vec<(i64, Option<f64>)> = Vec::new();
    if let Some(c) = &setup.contact {
        for (k, ind) in c.indenters.iter().enumerate() {
            let s = &ind.spec;
            let pid = (n_parts + k) as i64 + 1;
            let mut hm = HexMesh::default();
            let mut tris: Option<(Vec<[f64; 3]>, Vec<[u32; 3]>)> = None;
            let mut exact = Vec::new();
            for part in &s.parts {
                match part {
                    ShapeSpec::Stl { .. } | ShapeSpec::Triangles { .. } => {
                        let shape = contact::Shape::from_spec(part)
                            .map_err(|e| format!("indenter `{}`: {e}", s.name))?;
                        let contact::Shape::Mesh(tm) = shape else {
                            unreachable!()
                        };
                        let t = tris.get_or_insert_with(Default::default);
                        let off = t.0.len() as u32;
                        t.0.extend_from_slice(tm.vertices());
                        t.1.extend(tm.triangles().iter().map(|x| x.map(|i| i + off)));
                    }
                    other => {
                        let m = shapes::mesh(other, opts.segments)
                            .map_err(|e| format!("indenter `{}`: {e}", s.name))?;
                        let off = hm.nodes.len() as u32;
                        hm.nodes.extend(m.nodes);
                        hm.elements
                            .extend(m.elements.iter().map(|e| e.map(|i| i + off)));
                        exact.push(shape_toml(other));
                    }
                }
            }
            w.kw("PART");
            w.text_line(&s.name);
            w.palpa("direction", &tv3(s.direction));
            if tris.is_none() {
                w.palpa("indenter", &format!("[{}]", exact.join(", ")));
                notes.push(format!(
                    "indenter `{}`: {} exact shape(s) meshed with {} hexahedra ({} segments around a circle); LS-DYNA reads the mesh",
                    s.name,
                    exact.len(),
                    hm.elements.len(),
                    opts.segments
                ));
            } else {
                notes.push(format!(
                    "indenter `{}`: its triangle mesh written as shells",
                    s.name
                ));
            }
            let cells = [w.int(pid, 10), w.int(pid, 10), w.int(pid, 10)];
            w.card(&cells);
            w.kw(if tris.is_some() {
                "SECTION_SHELL"
            } else {
                "SECTION_SOLID"
            });
            if tris.is_some() {
                let cells = [w.int(pid, 10), w.int(2, 10)];
                w.card(&cells);
                let t = 1e-6 * bbox(&tris.as_ref().map(|t| t.0.clone()).unwrap_or_default());
                let cells = [
                    w.si(t, Dim::LENGTH, 10),
                    w.si(t, Dim::LENGTH, 10),
                    w.si(t, Dim::LENGTH, 10),
                    w.si(t, Dim::LENGTH, 10),
                ];
                w.card(&cells);
            } else {
                let cells = [w.int(pid, 10), w.int(1, 10)];
                w.card(&cells);
            }
            // Motion: along an axis (DOF 1-3) or a vector (DOF -4).
            let d = unit(s.direction);
            let axis = (0..3).find(|&a| d[a].abs() == 1.0);
            let (con1, fixed_part) = match &s.motion {
                MotionSpec::Fixed => (7, true),
                _ => (
                    match axis {
                        Some(0) => 5,
                        Some(1) => 6,
                        Some(2) => 4,
                        _ => 0,
                    },
                    false,
                ),
            };
            w.kw("MAT_RIGID");
            let e_rigid = if max_e > 0.0 { max_e } else { 1e6 };
            let cells = [
                w.int(pid, 10),
                w.si(1000.0, Dim::DENSITY, 10),
                w.si(e_rigid, Dim::PRESSURE, 10),
                w.num(0.3, 10),
            ];
            w.card(&cells);
            let cells = [w.num(1.0, 10), w.int(con1, 10), w.int(7, 10)];
            w.card(&cells);
            if !fixed_part {
                let (vel, curve) = match &s.motion {
                    MotionSpec::Displacement { curve } => (false, curve),
                    MotionSpec::Velocity { curve } => (true, curve),
                    MotionSpec::Force(_) => {
                        return Err(format!(
                            "indenter `{}`: force control has no LS-DYNA prescribed motion (it is a controller that palpa runs); give the indenter a displacement or velocity curve to export it",
                            s.name
                        ))
                    }
                    MotionSpec::Fixed => unreachable!(),
                };
                let sign = match axis {
                    Some(a) => d[a],
                    None => 1.0,
                };
                let (pts, note) = motion_points(curve, end, sign, &sample);
                let lc = new_curve(
                    &format!("{} of {}", if vel { "speed" } else { "travel" }, s.name),
                    pts,
                    Dim::TIME,
                    if vel { Dim::VELOCITY } else { Dim::LENGTH },
                    note,
                );
                let (dof, vid) = match axis {
                    Some(a) => (a as i64 + 1, None),
                    None => {
                        vectors.push(d);
                        (-4, Some(vectors.len() as i64))
                    }
                };
                let mut cells = vec![
                    w.int(pid, 10),
                    w.int(dof, 10),
                    w.int(if vel { 0 } else { 2 }, 10),
                    w.int(lc, 10),
                    w.num(1.0, 10),
                ];
                if let Some(v) = vid {
                    cells.push(w.int(v, 10));
                }
                motion_rigid.push(cells.concat().trim_end().to_string());
            }
            contact_cards.push((pid, s.friction));
            rigid.push((pid, hm, tris));
        }
    }

    // Node sets.
    for (sid, title, nodes) in &sets.list {
        w.kw("SET_NODE_LIST_TITLE");
        w.text_line(title);
        let c = [w.int(*sid, 10)];
        w.card(&c);
        for chunk in nodes.chunks(8) {
            let cells: Vec<String> = chunk.iter().map(|&n| w.int(n as i64 + 1, 10)).collect();
            w.card(&cells);
        }
    }
    if let Some((sid, title, els)) = &probe_set {
        w.kw("SET_SOLID_TITLE");
        w.text_line(title);
        let c = [w.int(*sid, 10)];
        w.card(&c);
        for chunk in els.chunks(8) {
            let cells: Vec<String> = chunk.iter().map(|&e| w.int(e as i64 + 1, 10)).collect();
            w.card(&cells);
        }
    }
    for (sid, dofs) in &fixed {
        w.kw("BOUNDARY_SPC_SET");
        let cells = [
            w.int(*sid, 10),
            w.int(0, 10),
            w.int(dofs[0] as i64, 10),
            w.int(dofs[1] as i64, 10),
            w.int(dofs[2] as i64, 10),
        ];
        w.card(&cells);
    }
    if !motions.is_empty() {
        w.kw("BOUNDARY_PRESCRIBED_MOTION_SET");
        for m in &motions {
            w.text_line(m);
        }
    }
    if !load_cards.is_empty() {
        w.kw("LOAD_NODE_SET");
        for l in &load_cards {
            w.text_line(l);
        }
    }
    for (sid, v) in &iv_cards {
        w.kw("INITIAL_VELOCITY");
        let c = [w.int(*sid, 10)];
        w.card(&c);
        let cells = [
            w.si(v[0], Dim::VELOCITY, 10),
            w.si(v[1], Dim::VELOCITY, 10),
            w.si(v[2], Dim::VELOCITY, 10),
        ];
        w.card(&cells);
    }
    if !motion_rigid.is_empty() {
        w.kw("BOUNDARY_PRESCRIBED_MOTION_RIGID");
        for m in &motion_rigid {
            w.text_line(m);
        }
    }
    for (i, v) in vectors.iter().enumerate() {
        w.kw("DEFINE_VECTOR");
        let cells = [
            w.int(i as i64 + 1, 10),
            w.num(0.0, 10),
            w.num(0.0, 10),
            w.num(0.0, 10),
            w.num(v[0], 10),
            w.num(v[1], 10),
            w.num(v[2], 10),
        ];
        w.card(&cells);
    }

    // Contact.
    if let Some(c) = &setup.contact {
        let faces = contact_faces(scene);
        w.kw("SET_SEGMENT_TITLE");
        w.text_line("contact surface");
        let cells = [w.int(1, 10)];
        w.card(&cells);
        for f in &faces {
            let cells: Vec<String> = f.iter().map(|&n| w.int(n as i64 + 1, 10)).collect();
            w.card(&cells);
        }
        let p = &c.params;
        let (soft, sfs, slsfac) = match p.penalty {
            PenaltyKind::Segment => (0, 1.0, p.penalty_scale),
            PenaltyKind::Max => (1, 1.0, p.penalty_scale),
            PenaltyKind::Soft => {
                let sfs = soft_sfs(scene, &faces);
                notes.push(format!(
                    "contact: palpa's soft penalty written as SOFT = 1 with SFS = {sfs:e}, so that the segment-based stiffness (SLSFAC SFS K A^2 / V) stays below the soft one on every face and LS-DYNA uses the soft constraint"
                ));
                (1, sfs, 0.1)
            }
        };
        if slsfac != 0.1 {
            w.kw("CONTROL_CONTACT");
            let cells = [w.num(slsfac, 10)];
            w.card(&cells);
        }
        let d = contact::ContactParams::default();
        let mut note = vec![format!(
            "penalty = \"{}\"",
            match p.penalty {
                PenaltyKind::Soft => "soft",
                PenaltyKind::Segment => "segment",
                PenaltyKind::Max => "max",
            }
        )];
        note.push(format!("soft_scale = {}", tn(p.soft_scale)));
        note.push(format!(
            "stiffness_cap = {}",
            tn(p.stiffness_cap.unwrap_or(0.0))
        ));
        if let Some(t) = p.design_dt {
            note.push(format!("design_dt = {}", tn(t)));
        }
        if p.friction_velocity != d.friction_velocity {
            note.push(format!("friction_velocity = {}", tn(p.friction_velocity)));
        }
        if p.samples_min != d.samples_min {
            note.push(format!("samples_min = {}", p.samples_min));
        }
        if p.samples_max != d.samples_max {
            note.push(format!("samples_max = {}", p.samples_max));
        }
        if p.sample_spacing != d.sample_spacing {
            note.push(format!("sample_spacing = {}", tn(p.sample_spacing)));
        }
        if let Some(m) = p.margin {
            note.push(format!("margin = {}", tn(m)));
        }
        if p.rebuild_interval != d.rebuild_interval {
            note.push(format!("rebuild_interval = {}", p.rebuild_interval));
        }
        for (pid, fr) in &contact_cards {
            w.kw("CONTACT_AUTOMATIC_SURFACE_TO_SURFACE");
            w.palpa("contact", &format!("{{ {} }}", note.join(", ")));
            let cells = [w.int(1, 10), w.int(*pid, 10), w.int(0, 10), w.int(3, 10)];
            w.card(&cells);
            let mu = fr.unwrap_or(p.friction);
            let cells = [
                w.num(mu, 10),
                w.num(mu, 10),
                w.num(0.0, 10),
                w.num(0.0, 10),
                w.back(p.damping_ratio, 100.0 * p.damping_ratio, |x| x / 100.0, 10),
            ];
            w.card(&cells);
            let cells = [w.num(sfs, 10), w.num(1.0, 10)];
            w.card(&cells);
            let cells = [w.int(soft, 10), w.num(p.soft_scale, 10)];
            w.card(&cells);
        }
    }

    // Curves.
    for c in &curves {
        w.kw("DEFINE_CURVE_TITLE");
        w.text_line(&c.title);
        if let Some((k, v)) = &c.note {
            w.palpa(k, v);
        }
        let cells = [w.int(c.id, 10)];
        w.card(&cells);
        for &(t, v) in &c.points {
            let cells = [w.si(t, c.xdim, 20), w.si(v, c.ydim, 20)];
            w.card(&cells);
        }
    }

    // Nodes and elements.
    w.kw("NODE");
    // A node whose coordinates do not all fit their 20 columns exactly (a few near zero need
    // 21 characters) gets its exact coordinates in a comment before it.
    let node_line = |w: &mut W, id: i64, x: [f64; 3]| {
        let mut cells = vec![w.int(id, 8)];
        let mut exact = true;
        for &c in &x {
            let (t, ok) = w.coordinate(c);
            exact &= ok;
            cells.push(t);
        }
        if !exact {
            w.palpa(&format!("n{id}"), &tv3(x));
        }
        w.card(&cells);
    };
    for (i, &x) in mesh.nodes.iter().enumerate() {
        node_line(&mut w, i as i64 + 1, x);
    }
    let mut next_node = mesh.nodes.len() as i64 + 1;
    let mut rigid_node_base = Vec::new();
    for (_, hm, tris) in &rigid {
        rigid_node_base.push(next_node);
        for &x in &hm.nodes {
            node_line(&mut w, next_node, x);
            next_node += 1;
        }
        if let Some((v, _)) = tris {
            for &x in v {
                node_line(&mut w, next_node, x);
                next_node += 1;
            }
        }
    }
    w.kw("ELEMENT_SOLID");
    for (e, c) in mesh.elements.iter().enumerate() {
        let mut cells = vec![
            w.int(e as i64 + 1, 8),
            w.int(mesh.element_part[e] as i64 + 1, 8),
        ];
        cells.extend(c.iter().map(|&n| w.int(n as i64 + 1, 8)));
        w.card(&cells);
    }
    let mut next_el = mesh.elements.len() as i64 + 1;
    for ((pid, hm, _), base) in rigid.iter().zip(&rigid_node_base) {
        for c in &hm.elements {
            let mut cells = vec![w.int(next_el, 8), w.int(*pid, 8)];
            cells.extend(c.iter().map(|&n| w.int(n as i64 + base, 8)));
            w.card(&cells);
            next_el += 1;
        }
    }
    if rigid.iter().any(|r| r.2.is_some()) {
        w.kw("ELEMENT_SHELL");
        for ((pid, hm, tris), base) in rigid.iter().zip(&rigid_node_base) {
            if let Some((_, t)) = tris {
                let off = base + hm.nodes.len() as i64;
                for tri in t {
                    let cells = [
                        w.int(next_el, 8),
                        w.int(*pid, 8),
                        w.int(tri[0] as i64 + off, 8),
                        w.int(tri[1] as i64 + off, 8),
                        w.int(tri[2] as i64 + off, 8),
                        w.int(tri[2] as i64 + off, 8),
                    ];
                    w.card(&cells);
                    next_el += 1;
                }
            }
        }
    }
    w.kw("END");
    Ok(Exported {
        text: w.out,
        notes,
        values: w.values,
        inexact: w.inexact,
        max_rounding: w.max_rel,
    })
}

fn nodes_all(n: usize) -> Vec<u32> {
    (0..n as u32).collect()
}

fn unit(a: [f64; 3]) -> [f64; 3] {
    let n = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    [a[0] / n, a[1] / n, a[2] / n]
}

fn bbox(v: &[[f64; 3]]) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in v {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max)
}

fn shape_toml(s: &ShapeSpec) -> String {
    match s {
        ShapeSpec::Sphere { center, radius } => format!(
            "{{ shape = \"sphere\", center = {}, radius = {} }}",
            tv3(*center),
            tn(*radius)
        ),
        ShapeSpec::Capsule {
            center,
            axis,
            radius,
            length,
        } => format!(
            "{{ shape = \"capsule\", center = {}, axis = {}, radius = {}, length = {} }}",
            tv3(*center),
            tv3(*axis),
            tn(*radius),
            tn(*length)
        ),
        ShapeSpec::Cylinder {
            center,
            axis,
            radius,
            length,
        } => format!(
            "{{ shape = \"cylinder\", center = {}, axis = {}, radius = {}, length = {} }}",
            tv3(*center),
            tv3(*axis),
            tn(*radius),
            tn(*length)
        ),
        ShapeSpec::Box {
            center,
            half_extents,
            axes,
        } => match axes {
            None => format!(
                "{{ shape = \"box\", center = {}, half_extents = {} }}",
                tv3(*center),
                tv3(*half_extents)
            ),
            Some(a) => format!(
                "{{ shape = \"box\", center = {}, half_extents = {}, axes = [{}, {}, {}] }}",
                tv3(*center),
                tv3(*half_extents),
                tv3(a[0]),
                tv3(a[1]),
                tv3(a[2])
            ),
        },
        _ => String::new(),
    }
}

/// An indenter's motion curve as points (the direction's `sign` along an axis) and the exact
/// curve as a comment.
fn motion_points(
    c: &Curve,
    end: f64,
    sign: f64,
    sample: &dyn Fn(f64, f64, &dyn Fn(f64) -> f64) -> Vec<(f64, f64)>,
) -> (Vec<(f64, f64)>, Option<(String, String)>) {
    let note = |s: String| Some(("motion".to_string(), s));
    let (pts, n) = match c {
        Curve::Table { points } => (points.iter().map(|p| (p[0], p[1])).collect(), None),
        // the boundary forms, which no motion takes: their points, without a comment
        Curve::Polyline(p) => (p.clone(), None),
        Curve::SmoothStepBetween { t0, t1, .. } => (sample(*t0, *t1, &|t| c.value(t)), None),
        Curve::Constant { value } => (
            vec![(0.0, *value), (end, *value)],
            note(format!(
                "{{ curve = \"constant\", value = {} }}",
                tn(*value)
            )),
        ),
        Curve::SmoothStep {
            amplitude,
            duration,
            start,
        } => (
            sample(*start, start + duration, &|t| c.value(t)),
            note(format!(
                "{{ curve = \"smooth_step\", amplitude = {}, duration = {}, start = {} }}",
                tn(*amplitude),
                tn(*duration),
                tn(*start)
            )),
        ),
        Curve::Ramp {
            amplitude,
            duration,
            start,
        } => {
            let mut p = Vec::new();
            if *start > 0.0 {
                p.push((0.0, 0.0));
            }
            p.push((*start, 0.0));
            p.push((start + duration, *amplitude));
            if start + duration < end {
                p.push((end, *amplitude));
            }
            (
                p,
                note(format!(
                    "{{ curve = \"ramp\", amplitude = {}, duration = {}, start = {} }}",
                    tn(*amplitude),
                    tn(*duration),
                    tn(*start)
                )),
            )
        }
    };
    // Along a negative axis the deck moves the part the other way; the comment keeps palpa's
    // travel (the reader flips the table back before it compares).
    if sign < 0.0 {
        (pts.into_iter().map(|(t, v)| (t, -v)).collect(), n)
    } else {
        (pts, n)
    }
}

/// The faces palpa's contact uses (outward node order), as the stage built them.
fn contact_faces(scene: &Scene) -> Vec<[u32; 4]> {
    let mesh = &scene.sim.model.mesh;
    let Some(c) = &scene.setup.contact else {
        return Vec::new();
    };
    let sel = &c.surface;
    mesh.boundary_faces()
        .into_iter()
        .filter(|f| {
            let part = mesh.element_part[f.element as usize] as usize;
            sel.parts.as_ref().map_or(true, |ok| ok[part])
                && sel
                    .nodes
                    .as_ref()
                    .map_or(true, |m| f.nodes.iter().all(|&n| m[n as usize]))
                && sel.faces.as_ref().map_or(true, |fs| {
                    let mut k = f.nodes;
                    k.sort_unstable();
                    fs.contains(&k)
                })
        })
        .map(|f| f.nodes)
        .collect()
}

/// SFS such that `SLSFAC SFS K A^2 / V <= soft_scale m / dt^2 / 10` on every face (SLSFAC
/// 0.1), rounded down to one significant digit, at most 1.
fn soft_sfs(scene: &Scene, faces: &[[u32; 4]]) -> f64 {
    let model = &scene.sim.model;
    let mesh = &model.mesh;
    let Some(c) = &scene.setup.contact else {
        return 1.0;
    };
    let design = c.params.design_dt.unwrap_or_else(|| {
        (scene.setup.dt_factor * model.scaled_dt).min(scene.setup.dt_max.unwrap_or(f64::INFINITY))
    });
    let mut vol = vec![0.0; mesh.elements.len()];
    for g in &model.groups {
        for (&e, &v) in g.elements.iter().zip(&g.vol0) {
            vol[e as usize] = v;
        }
    }
    let mut owner: HashMap<[u32; 4], u32> = HashMap::new();
    for f in mesh.boundary_faces() {
        owner.insert(f.nodes, f.element);
    }
    let mut worst: f64 = 0.0;
    for f in faces {
        let Some(&e) = owner.get(f) else { continue };
        let part = &model.parts[mesh.element_part[e as usize] as usize];
        let c0 = part.material.initial_wave_speed();
        let k = part.material.density() * c0 * c0;
        let p: Vec<[f64; 3]> = f.iter().map(|&n| mesh.nodes[n as usize]).collect();
        let d1 = [p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]];
        let d2 = [p[3][0] - p[1][0], p[3][1] - p[1][1], p[3][2] - p[1][2]];
        let cr = [
            d1[1] * d2[2] - d1[2] * d2[1],
            d1[2] * d2[0] - d1[0] * d2[2],
            d1[0] * d2[1] - d1[1] * d2[0],
        ];
        let area = 0.5 * (cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]).sqrt();
        let seg = 0.1 * k * area * area / vol[e as usize].max(1e-300);
        let m: f64 = f.iter().map(|&n| model.mass[n as usize]).sum::<f64>() / 4.0;
        let soft = c.params.soft_scale * m / (design * design);
        worst = worst.max(seg / soft.max(1e-300));
    }
    let sfs = (0.1 / worst.max(1e-300)).min(1.0);
    let e = sfs.log10().floor();
    let p = 10f64.powf(e);
    (sfs / p).floor() * p
}

fn write_material(
    w: &mut W,
    pid: i64,
    p: &::scene::def::PartDef,
    notes: &mut Vec<String>,
    new_curve: &mut impl FnMut(&str, Vec<(f64, f64)>, Dim, Dim, Option<(String, String)>) -> i64,
) -> Result<(), String> {
    let m = &p.material;
    let card = card_toml(&p.spec, m);
    match (m, &p.spec) {
        (Material::LinearElastic(l), s) => {
            w.kw("MAT_ELASTIC");
            w.palpa("card", &card);
            let (lam, mu) = (l.lambda, l.mu);
            let (e, nu) = match s {
                MaterialSpec::LinearElastic(i)
                    if i.youngs_modulus.is_some() && i.poisson_ratio.is_some() =>
                {
                    (
                        i.youngs_modulus.map_or(0.0, |x| x.0),
                        i.poisson_ratio.map_or(0.0, |x| x.0),
                    )
                }
                _ => (
                    mu * (3.0 * lam + 2.0 * mu) / (lam + mu),
                    lam / (2.0 * (lam + mu)),
                ),
            };
            if l.kinematics == material::linear_elastic::Kinematics::Small {
                notes.push(format!(
                    "part `{}`: linear_elastic with strain = \"small\" has no LS-DYNA switch (LS-DYNA's *MAT_ELASTIC is hypoelastic); a $palpa comment",
                    p.name
                ));
            }
            let cells = [
                w.int(pid, 10),
                w.si(l.rho, Dim::DENSITY, 10),
                w.si(e, Dim::PRESSURE, 10),
                w.num(nu, 10),
            ];
            w.card(&cells);
        }
        (Material::NeoHookean(n), _) => {
            notes.push(format!(
                "part `{}`: palpa's compressible neo-Hookean law has no LS-DYNA counterpart; written as *MAT_OGDEN_RUBBER, one term, alpha = 2, mu = {:.6e} Pa, PR from lambda and mu (the same small-strain moduli; at finite strain the volumetric terms differ), with palpa's card as a $palpa comment",
                p.name, n.mu
            ));
            w.kw("MAT_OGDEN_RUBBER");
            w.palpa("card", &card);
            let nu = n.lambda / (2.0 * (n.lambda + n.mu));
            let cells = [w.int(pid, 10), w.si(n.rho, Dim::DENSITY, 10), w.num(nu, 10)];
            w.card(&cells);
            let cells = [w.si(n.mu, Dim::PRESSURE, 10)];
            w.card(&cells);
            let cells = [w.num(2.0, 10)];
            w.card(&cells);
        }
        (Material::Ogden(o), s) => {
            w.kw("MAT_OGDEN_RUBBER");
            w.palpa("card", &card);
            let spec_nu = match s {
                MaterialSpec::Ogden(os) => os.poisson_ratio.map(|x| x.0),
                _ => None,
            };
            let mu0 = o.mu0();
            let nu = spec_nu.unwrap_or((3.0 * o.bulk - 2.0 * mu0) / (2.0 * (3.0 * o.bulk + mu0)));
            if o.mu().len() > 8 {
                return Err(format!(
                    "part `{}`: *MAT_OGDEN_RUBBER takes at most 8 terms, the law has {}",
                    p.name,
                    o.mu().len()
                ));
            }
            if o.prony_on == material::ogden::PronyOn::Deviatoric {
                notes.push(format!(
                    "part `{}`: Prony terms on the deviatoric strain (prony_on = \"deviatoric\") have no LS-DYNA switch; LS-DYNA applies them to the Green strain; a $palpa comment",
                    p.name
                ));
            }
            let cells = [w.int(pid, 10), w.si(o.rho, Dim::DENSITY, 10), w.num(nu, 10)];
            w.card(&cells);
            let cells: Vec<String> = o.mu().iter().map(|&x| w.si(x, Dim::PRESSURE, 10)).collect();
            w.card(&cells);
            let cells: Vec<String> = o.alpha().iter().map(|&a| w.num(a, 10)).collect();
            w.card(&cells);
            let prony_spec: Vec<Option<f64>> = match s {
                MaterialSpec::Ogden(os) => os.prony.iter().map(|t| t.decay.map(|d| d.0)).collect(),
                _ => Vec::new(),
            };
            for (i, t) in o.prony().iter().enumerate() {
                // The decay constant BETA = 1/tau; read back, palpa computes tau = 1/beta.
                let beta = prony_spec.get(i).copied().flatten();
                let u = w.u.clone();
                let tau = t.tau;
                let b = match beta {
                    Some(b) => w.si(b, Dim::RATE, 10),
                    None => w.back(
                        tau,
                        u.from_si(1.0 / tau, Dim::RATE),
                        move |x| 1.0 / u.to_si(x, Dim::RATE),
                        10,
                    ),
                };
                let cells = [w.si(t.modulus, Dim::PRESSURE, 10), b];
                w.card(&cells);
            }
        }
        (Material::SimplifiedRubber(f), _) => {
            let pts: Vec<(f64, f64)> = match &f.curve {
                material::foam::UniaxialCurve::Table(l, s) => {
                    l.iter().copied().zip(s.iter().copied()).collect()
                }
                material::foam::UniaxialCurve::NeoHookean(g) => {
                    notes.push(format!(
                        "part `{}`: simplified_rubber without a curve (palpa's neo-Hookean P = G (l - 1/l^2)) tabulated for LS-DYNA at 121 stretches from 0.2 to 3.2 (step 0.025); palpa reads its exact curve from a $palpa comment",
                        p.name
                    ));
                    (0..=120)
                        .map(|k| {
                            let l = (8 + k) as f64 / 40.0;
                            (l, g * (l - 1.0 / (l * l)))
                        })
                        .collect()
                }
            };
            // LS-DYNA's curve: force against change of a unit gauge length (SGL = SW = ST = 1).
            let lc = new_curve(
                &format!("{}: nominal stress against dl (SGL = SW = ST = 1)", p.name),
                pts.iter().map(|&(l, s)| (l - 1.0, s)).collect(),
                Dim::NONE,
                Dim::PRESSURE,
                None,
            );
            w.kw("MAT_SIMPLIFIED_RUBBER/FOAM");
            w.palpa("card", &card);
            let shear = match &p.spec {
                MaterialSpec::SimplifiedRubber(s) => s.shear_modulus.map(|g| g.0),
                _ => None,
            };
            let cells = [
                w.int(pid, 10),
                w.si(f.rho, Dim::DENSITY, 10),
                w.si(f.bulk, Dim::PRESSURE, 10),
                w.num(f.damping, 10),
                match shear {
                    Some(g) => w.si(g, Dim::PRESSURE, 10),
                    None => w.blank(10),
                },
            ];
            w.card(&cells);
            let cells = [
                w.num(1.0, 10),
                w.num(1.0, 10),
                w.num(1.0, 10),
                w.int(lc, 10),
            ];
            w.card(&cells);
        }
        (Material::PiecewiseLinearPlasticity(_), MaterialSpec::PiecewiseLinearPlasticity(s)) => {
            let lcss = s.hardening.as_ref().map(|h| {
                new_curve(
                    &format!("{}: yield stress against effective plastic strain", p.name),
                    h.iter().map(|(e, y)| (e.0, y.0)).collect(),
                    Dim::NONE,
                    Dim::PRESSURE,
                    None,
                )
            });
            w.kw("MAT_PIECEWISE_LINEAR_PLASTICITY");
            w.palpa("card", &card);
            let cells = [
                w.int(pid, 10),
                w.si(s.density.0, Dim::DENSITY, 10),
                w.si(s.youngs_modulus.0, Dim::PRESSURE, 10),
                w.num(s.poisson_ratio.0, 10),
                match s.yield_stress {
                    Some(y) => w.si(y.0, Dim::PRESSURE, 10),
                    None => w.blank(10),
                },
                match s.tangent_modulus {
                    Some(t) => w.si(t.0, Dim::PRESSURE, 10),
                    None => w.blank(10),
                },
                match s.failure_strain {
                    Some(f) => w.num(f.0, 10),
                    None => w.blank(10),
                },
            ];
            w.card(&cells);
            let cells = [
                w.num(0.0, 10),
                w.num(0.0, 10),
                match lcss {
                    Some(l) => w.int(l, 10),
                    None => w.blank(10),
                },
            ];
            w.card(&cells);
            w.card(&[]);
            w.card(&[]);
        }
        (Material::PiecewiseLinearPlasticity(_), _) => {
            return Err(format!("part `{}`: plasticity without its card", p.name))
        }
    }
    Ok(())
}
