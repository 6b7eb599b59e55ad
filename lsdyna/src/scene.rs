//! A parsed deck ([`Deck`]) turned into a palpa scene ([`SceneDef`], SI).
//!
//! The mapping, keyword by keyword (docs/lsdyna.md has the full table):
//! - geometry: `*NODE` (TC fixes directions), `*ELEMENT_SOLID` of deformable parts become the
//!   mesh (node order as VTK_HEXAHEDRON); nodes that no deformable solid uses are dropped;
//!   `*SET_NODE`, `*SET_SOLID` become named sets (their `_TITLE`, else `set_node_<SID>`).
//! - parts and laws: `*MAT_ELASTIC` is palpa's `linear_elastic` (St. Venant-Kirchhoff: equal to
//!   LS-DYNA's hypoelastic law at small strain), `*MAT_OGDEN_RUBBER` its `ogden` with the Prony
//!   terms on the Green strain, `*MAT_SIMPLIFIED_RUBBER/FOAM` its `simplified_rubber` with the
//!   load curve read as nominal stress `F/(SW ST)` against stretch `1 + dL/SGL`,
//!   `*MAT_PIECEWISE_LINEAR_PLASTICITY` its `piecewise_linear_plasticity`; a `*MAT_RIGID` part is
//!   an indenter (below).
//! - elements: ELFORM 1 is `one_point` with the `*HOURGLASS` form (IHQ 1-3 viscous, 4-5
//!   stiffness, both scaled by the P-wave modulus as LS-DYNA does) and QM; ELFORM 2, -1 and -2
//!   (fully integrated, selectively reduced) are `full_fbar`.
//! - control: ENDTIM, TSSFAC, DT2MS (< 0: mass added to elements whose step is below
//!   `TSSFAC |DT2MS|`; DT2MSF: `DT2MSF x` the initial step), ENDMAS (the added-mass limit),
//!   DTMIN, LCTM (largest step), `*CONTROL_BULK_VISCOSITY` Q1/Q2, `*DAMPING_GLOBAL` VALDMP,
//!   `*LOAD_BODY_X/Y/Z` (a positive value pulls towards `-x/-y/-z`, as gravity in LS-DYNA).
//! - boundary: SPCs fix directions; prescribed motion of nodes (VAD 0 velocity, 2
//!   displacement); `*LOAD_NODE` forces; `*INITIAL_VELOCITY`.
//! - contact: each `*CONTACT` pairs deformable parts (their boundary faces, or a segment or node
//!   set) with rigid parts. A rigid part becomes an indenter: its surface (the boundary of its
//!   solids, or its shells) as a triangle mesh, moved along one direction by its
//!   `*BOUNDARY_PRESCRIBED_MOTION_RIGID` (DOF 1-3, or -4 along a `*DEFINE_VECTOR`), the other
//!   translations and the rotations held by `*MAT_RIGID` CMO = 1, CON1, CON2 (CON2 = 7). SOFT
//!   = 0 is palpa's `segment` penalty with `SLSFAC x SFS`, SOFT = 1 its `max` (the larger of the
//!   segment and the soft-constraint stiffness, SOFSCL); FS is the friction, VDC the damping.
//! - output: `*DATABASE_BINARY_D3PLOT` DT is the VTK frame interval; the smallest DT of
//!   `*DATABASE_GLSTAT`, `RCFORC`, `SPCFORC`, `BNDOUT` the history interval; SPCFORC adds the
//!   reactions of the SPC sets to history.csv, BNDOUT those of prescribed-motion sets;
//!   `*DATABASE_HISTORY_SOLID(_SET)` is the probe (`probe.csv`, sampled with the frames or at
//!   the `*DATABASE_ELOUT` interval).

use crate::annotate::{self, BcCurve, ElementNote, RelaxationNote, RunNote};
use crate::keywords::{ContactCard, CurveCard, Deck, Key, MatCard, MatKind, PartCard, Target};
use crate::lex::Loc;
use crate::units::Units;
use ::scene::contact_def::{ContactDef, IndenterDef, SurfaceSel};
use ::scene::def::{DtMin, HourglassGuard, OutputPlan, PartDef, SceneDef, Setup};
use contact::{ContactParams, Curve, IndenterSpec, MotionSpec, PenaltyKind, ShapeSpec};
use material::quantity::{Density, Dim, Number, Pressure, Rate};
use material::spec::{FoamSpec, IsotropicSpec, OgdenSpec, PlasticitySpec, PronySpec};
use material::{Material, MaterialSpec};
use serde::Deserialize;
use solver::bc::{Constraint, Kinematic, NodalLoad};
use solver::element::precision::Precision;
use solver::element::{BulkViscosity, Formulation, Hourglass, HourglassForm, HourglassModulus};
use solver::mesh::Mesh;
use solver::model::{MassScaling, StepTarget};
use solver::simulation::{DynamicRelaxation, StepEstimate};
use std::collections::{BTreeMap, HashMap, HashSet};
use std::path::{Path, PathBuf};

/// How to read a deck.
#[derive(Clone, Debug, Default)]
pub struct ReadOptions {
    /// The unit system the user names (`--units`); `*CONTROL_UNITS` may state it instead.
    pub units: Option<Units>,
    /// Read `$palpa:` comments (default true; false reads the deck as LS-DYNA does).
    pub ignore_palpa_comments: bool,
}

/// What reading a deck found, for `palpa check` and the run's notes.
#[derive(Clone, Debug, Default)]
pub struct Report {
    /// Files read.
    pub files: Vec<PathBuf>,
    /// Unit system and where it came from.
    pub units: String,
    /// Keywords and how often they appear.
    pub counts: BTreeMap<String, usize>,
    /// What was ignored, and why.
    pub warnings: Vec<String>,
    /// How each part, indenter and setting was mapped.
    pub mapping: Vec<String>,
}

/// A deck that palpa cannot run: every error found (and the warnings).
#[derive(Clone, Debug, Default)]
pub struct DeckError {
    /// Errors, each with file, line and field.
    pub errors: Vec<String>,
    /// Warnings.
    pub warnings: Vec<String>,
}

impl std::fmt::Display for DeckError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let n = self.errors.len();
        if n == 1 {
            write!(f, "{}", self.errors[0])
        } else {
            writeln!(f, "{n} problems in the deck:")?;
            for (i, e) in self.errors.iter().enumerate().take(30) {
                if i > 0 {
                    writeln!(f)?;
                }
                write!(f, "  {e}")?;
            }
            if n > 30 {
                write!(f, "\n  ... and {} more", n - 30)?;
            }
            Ok(())
        }
    }
}

impl DeckError {
    fn one(e: String, warnings: Vec<String>) -> DeckError {
        DeckError {
            errors: vec![e],
            warnings,
        }
    }
}

/// A part name that is safe in history columns and file names.
pub fn sanitize(s: &str) -> Option<String> {
    let t: String = s
        .trim()
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' || c == '-' || c == '.' {
                c
            } else {
                '_'
            }
        })
        .collect();
    let t = t.trim_matches('_').to_string();
    (!t.is_empty()).then_some(t)
}

fn unique(name: String, taken: &mut HashSet<String>, fallback: &str) -> String {
    let mut n = name;
    if taken.contains(&n) {
        n = format!("{n}_{fallback}");
    }
    while taken.contains(&n) {
        n.push('_');
    }
    taken.insert(n.clone());
    n
}

struct Ctx<'a> {
    d: &'a Deck,
    u: Units,
    warn: Vec<String>,
    mapping: Vec<String>,
    notes: Vec<String>,
    palpa: bool,
}

impl Ctx<'_> {
    fn si(&self, v: f64, d: Dim) -> f64 {
        self.u.to_si(v, d)
    }

    fn comments(&mut self, lines: &[(Loc, String)]) -> Option<toml::Table> {
        if !self.palpa {
            return None;
        }
        annotate::table(lines, &mut self.warn)
    }

    /// A curve's points in SI: abscissa of dimension `xd`, ordinate `sf` times the curve, of
    /// dimension `yd`.
    fn curve(
        &self,
        lcid: &Key,
        sf: f64,
        xd: Dim,
        yd: Dim,
        used_at: &str,
    ) -> Result<(Vec<(f64, f64)>, &'_ CurveCard), String> {
        if lcid.is_empty() || lcid == "0" {
            return Err(format!("{used_at}: a load curve (LCID) is required"));
        }
        let c = self.d.curves.get(lcid).ok_or_else(|| {
            format!("{used_at}: load curve {lcid} is not defined (no *DEFINE_CURVE {lcid})")
        })?;
        if c.sidr == 1 {
            return Err(format!(
                "{used_at}: load curve {lcid} ({}) is for dynamic relaxation only (SIDR = 1); palpa has no such phase",
                c.at
            ));
        }
        Ok((
            c.scaled()
                .into_iter()
                .map(|(x, y)| (self.si(x, xd), self.si(sf * y, yd)))
                .collect(),
            c,
        ))
    }

    /// A curve that must not change in time: its value.
    fn constant(&self, lcid: &Key, sf: f64, yd: Dim, used_at: &str) -> Result<f64, String> {
        let (p, c) = self.curve(lcid, sf, Dim::TIME, yd, used_at)?;
        let v = p[0].1;
        if p.iter().any(|q| q.1 != v) {
            return Err(format!(
                "{used_at}: load curve {lcid} ({}) varies in time; palpa needs a constant here",
                c.at
            ));
        }
        Ok(v)
    }

    /// A boundary curve (solver curve), exact from its `$palpa: curve` comment when that
    /// matches the table.
    fn bc_curve(&mut self, lcid: &Key, sf: f64, yd: Dim, used_at: &str) -> Result<Curve, String> {
        let (pts, c) = self.curve(lcid, sf, Dim::TIME, yd, used_at)?;
        let (cat, cpalpa) = (c.at.clone(), c.palpa.clone());
        let mut t = self.comments(&cpalpa);
        if let Some(exact) = annotate::take::<BcCurve>(&mut t, "curve", &cat, &mut self.warn) {
            let cv = exact.to_curve();
            if annotate::points_on(&pts, |x| cv.value(x)) {
                return Ok(cv);
            }
            self.warn.push(format!(
                "{cat}: `$palpa: curve` does not match the points of *DEFINE_CURVE {lcid}; the table is used"
            ));
        }
        let cv = Curve::Polyline(pts);
        cv.validate().map_err(|m| format!("{cat}: {m}"))?;
        Ok(cv)
    }
}

/// The TC/CON1 code's directions (1 x, 2 y, 3 z, 4 xy, 5 yz, 6 zx, 7 all).
fn code_dofs(code: i64) -> Option<[bool; 3]> {
    Some(match code {
        0 => [false; 3],
        1 => [true, false, false],
        2 => [false, true, false],
        3 => [false, false, true],
        4 => [true, true, false],
        5 => [false, true, true],
        6 => [true, false, true],
        7 => [true; 3],
        _ => return None,
    })
}

/// Read a parsed deck into a scene.
pub fn to_scene(
    d: &Deck,
    path: &Path,
    files: &[PathBuf],
    opts: &ReadOptions,
) -> Result<(SceneDef, Report), DeckError> {
    let mut warnings = d.warnings.clone();
    if !d.errors.is_empty() {
        return Err(DeckError {
            errors: d.errors.clone(),
            warnings,
        });
    }
    // Units.
    let stated = match &d.control_units {
        Some((w, at)) => Some((
            Units::from_control_units(&w[0], &w[1], &w[2]).map_err(|m| {
                DeckError::one(format!("{at}: *CONTROL_UNITS: {m}"), warnings.clone())
            })?,
            at.clone(),
        )),
        None => None,
    };
    let (u, units_from) = match (&opts.units, stated) {
        (Some(u), Some((s, at))) => {
            if !u.same_as(&s) {
                return Err(DeckError::one(
                    format!(
                        "{at}: *CONTROL_UNITS says {} but --units says {}; drop one of them",
                        s.name, u.name
                    ),
                    warnings,
                ));
            }
            (u.clone(), format!("--units and *CONTROL_UNITS ({at})"))
        }
        (Some(u), None) => (u.clone(), "--units".to_string()),
        (None, Some((s, at))) => (s, format!("*CONTROL_UNITS ({at})")),
        (None, None) => {
            return Err(DeckError::one(
                format!(
                    "{}: an LS-DYNA deck carries no units; say which system its numbers are in, with --units (e.g. --units kg-mm-ms, {}) or a *CONTROL_UNITS keyword in the deck",
                    path.display(),
                    crate::units::EXAMPLES
                ),
                warnings,
            ))
        }
    };
    let mut cx = Ctx {
        d,
        u,
        warn: Vec::new(),
        mapping: Vec::new(),
        notes: Vec::new(),
        palpa: !opts.ignore_palpa_comments,
    };
    let result = build(&mut cx, path);
    warnings.append(&mut cx.warn);
    match result {
        Ok(mut def) => {
            def.notes.append(&mut cx.notes);
            let report = Report {
                files: files.to_vec(),
                units: format!("{} (from {units_from})", cx.u.name),
                counts: d.counts.clone(),
                warnings,
                mapping: cx.mapping,
            };
            Ok((def, report))
        }
        Err(errors) => Err(DeckError { errors, warnings }),
    }
}

struct PartInfo<'a> {
    card: &'a PartCard,
    mat: &'a MatCard,
    rigid: bool,
}

fn build(cx: &mut Ctx, path: &Path) -> Result<SceneDef, Vec<String>> {
    let d = cx.d;
    let mut errors: Vec<String> = Vec::new();
    macro_rules! bail {
        () => {
            if !errors.is_empty() {
                return Err(errors);
            }
        };
    }
    let mut header = cx.comments(&d.header_palpa);
    let hdr_at = d.header_palpa.first().map(|x| x.0.clone()).unwrap_or(Loc {
        file: std::sync::Arc::new(path.to_path_buf()),
        line: 1,
    });
    // End time.
    let end_time = match &d.termination {
        None => {
            return Err(vec![format!(
                "{}: no *CONTROL_TERMINATION: palpa needs its ENDTIM (the end time)",
                path.display()
            )])
        }
        Some(t) if !(t.endtim > 0.0) => {
            return Err(vec![format!(
                "{}: *CONTROL_TERMINATION, field ENDTIM: the end time must be positive, got {}",
                t.at, t.endtim
            )])
        }
        Some(t) => cx.si(t.endtim, Dim::TIME),
    };

    // Parts.
    let mut parts: Vec<PartInfo> = Vec::new();
    let mut part_index: HashMap<&str, usize> = HashMap::new();
    for p in &d.parts {
        if part_index.contains_key(p.id.as_str()) {
            errors.push(format!("{}: *PART {} is defined twice", p.at, p.id));
            continue;
        }
        let Some(mat) = d.mats.get(&p.material) else {
            errors.push(format!(
                "{}: *PART {} (`{}`), field MID: material {} is not defined",
                p.at, p.id, p.title, p.material
            ));
            continue;
        };
        let rigid = matches!(mat.kind, MatKind::Rigid { .. });
        part_index.insert(p.id.as_str(), parts.len());
        parts.push(PartInfo {
            card: p,
            mat,
            rigid,
        });
    }
    bail!();

    // Nodes.
    let mut node_index: HashMap<i64, usize> = HashMap::with_capacity(d.nodes.len());
    for (i, n) in d.nodes.iter().enumerate() {
        if node_index.insert(n.id, i).is_some() {
            errors.push(format!("{}: *NODE {} is defined twice", n.at, n.id));
        }
    }
    bail!();
    // Elements.
    let mut deformable: Vec<(usize, usize)> = Vec::new(); // (solid index, part index)
    let mut rigid_solids: Vec<Vec<usize>> = vec![Vec::new(); parts.len()];
    let mut rigid_shells: Vec<Vec<usize>> = vec![Vec::new(); parts.len()];
    let mut seen_eid: HashSet<i64> = HashSet::new();
    for (k, e) in d.solids.iter().enumerate() {
        if !seen_eid.insert(e.id) {
            errors.push(format!(
                "{}: *ELEMENT_SOLID {} is defined twice",
                e.at, e.id
            ));
            continue;
        }
        let Some(&pi) = part_index.get(e.part.as_str()) else {
            errors.push(format!(
                "{}: *ELEMENT_SOLID {}, field PID: part {} is not defined (no *PART {})",
                e.at, e.id, e.part, e.part
            ));
            continue;
        };
        if let Some(n) = e.nodes.iter().find(|n| !node_index.contains_key(n)) {
            errors.push(format!(
                "{}: *ELEMENT_SOLID {} refers to node {n}, which no *NODE defines",
                e.at, e.id
            ));
            continue;
        }
        let mut s = e.nodes.clone();
        s.sort_unstable();
        s.dedup();
        if s.len() < 8 {
            errors.push(format!(
                "{}: *ELEMENT_SOLID {} repeats a node ({:?}): a degenerate hexahedron (a wedge, pyramid or tetrahedron); palpa has 8-node hexahedra only",
                e.at, e.id, e.nodes
            ));
            continue;
        }
        if parts[pi].rigid {
            rigid_solids[pi].push(k);
        } else {
            deformable.push((k, pi));
        }
    }
    for (k, e) in d.shells.iter().enumerate() {
        let Some(&pi) = part_index.get(e.part.as_str()) else {
            errors.push(format!(
                "{}: *ELEMENT_SHELL {}, field PID: part {} is not defined",
                e.at, e.id, e.part
            ));
            continue;
        };
        if !parts[pi].rigid {
            errors.push(format!(
                "{}: *ELEMENT_SHELL {} belongs to part {} (`{}`), which is not rigid: palpa has solid elements only, and reads shells only as the surface of a *MAT_RIGID part",
                e.at, e.id, e.part, parts[pi].card.title
            ));
            continue;
        }
        if let Some(n) = e.nodes.iter().find(|n| !node_index.contains_key(n)) {
            errors.push(format!(
                "{}: *ELEMENT_SHELL {} refers to node {n}, which no *NODE defines",
                e.at, e.id
            ));
            continue;
        }
        rigid_shells[pi].push(k);
    }
    bail!();
    if deformable.is_empty() {
        return Err(vec![format!(
            "{}: the deck has no solid element of a deformable part (*ELEMENT_SOLID of a part whose material is not *MAT_RIGID)",
            path.display()
        )]);
    }

    // The mesh: deformable parts in *PART order, their nodes in *NODE order.
    let mut mesh = Mesh::default();
    let mut mesh_part: Vec<Option<u32>> = vec![None; parts.len()];
    let mut taken = HashSet::new();
    for (pi, p) in parts.iter().enumerate() {
        if p.rigid || !deformable.iter().any(|&(_, q)| q == pi) {
            continue;
        }
        mesh_part[pi] = Some(mesh.part_names.len() as u32);
        let name = sanitize(&p.card.title).unwrap_or_else(|| format!("part_{}", p.card.id));
        mesh.part_names
            .push(unique(name, &mut taken, &format!("pid{}", p.card.id)));
    }
    let mut used = vec![false; d.nodes.len()];
    for &(k, _) in &deformable {
        for n in &d.solids[k].nodes {
            used[node_index[n]] = true;
        }
    }
    let mut palpa_node: Vec<Option<u32>> = vec![None; d.nodes.len()];
    for (i, n) in d.nodes.iter().enumerate() {
        if used[i] {
            palpa_node[i] = Some(mesh.nodes.len() as u32);
            mesh.nodes.push(std::array::from_fn(|k| {
                cx.u.to_si_text(&n.text[k], Dim::LENGTH)
                    .unwrap_or_else(|| cx.si(n.x[k], Dim::LENGTH))
            }));
        }
    }
    // Exact coordinates from `$palpa: n<ID> = [x, y, z]` comments, when within 1e-9 of the
    // mesh size of the card's.
    if let Some(t) = cx.comments(&d.node_palpa.clone()) {
        let (lo, hi) = mesh.bounds();
        let size = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max);
        let at = d.node_palpa[0].0.clone();
        let mut bad = 0;
        for (k, v) in t {
            let id = k.strip_prefix('n').and_then(|x| x.parse::<i64>().ok());
            let x: Option<[f64; 3]> = <[f64; 3]>::deserialize(v).ok();
            match (id.and_then(|i| node_index.get(&i)), x) {
                (Some(&i), Some(x)) => match palpa_node[i] {
                    Some(p) => {
                        let q = &mut mesh.nodes[p as usize];
                        if (0..3).all(|c| (q[c] - x[c]).abs() <= 1e-9 * size) {
                            *q = x;
                        } else {
                            bad += 1;
                        }
                    }
                    None => {}
                },
                _ => bad += 1,
            }
        }
        if bad > 0 {
            cx.warn.push(format!(
                "{at}: {bad} `$palpa: n<ID>` node comment(s) ignored (no such node, or not where the card puts it)"
            ));
        }
    }
    let mut rigid_node = vec![false; d.nodes.len()];
    for pi in 0..parts.len() {
        for &k in &rigid_solids[pi] {
            for n in &d.solids[k].nodes {
                rigid_node[node_index[n]] = true;
            }
        }
        for &k in &rigid_shells[pi] {
            for n in &d.shells[k].nodes {
                rigid_node[node_index[n]] = true;
            }
        }
    }
    let dropped = (0..d.nodes.len())
        .filter(|&i| !used[i] && !rigid_node[i])
        .count();
    if dropped > 0 {
        cx.notes.push(format!(
            "{dropped} node(s) belong to no element and were dropped"
        ));
    }
    let mut element_of_eid: HashMap<i64, u32> = HashMap::new();
    for &(k, pi) in &deformable {
        let e = &d.solids[k];
        let conn: [u32; 8] =
            std::array::from_fn(|a| palpa_node[node_index[&e.nodes[a]]].unwrap_or(0));
        let x: [[f64; 3]; 8] = std::array::from_fn(|a| mesh.nodes[conn[a] as usize]);
        let (det, _) = solver::hex::corner_jacobians(&x);
        if let Some(c) = det.iter().position(|&j| !(j > 0.0)) {
            errors.push(format!(
                "{}: *ELEMENT_SOLID {} (part {} `{}`) is inverted or degenerate: its Jacobian at node N{} ({}) is {:.3e}; check the node order (N1-N4 one face, N5-N8 the opposite face, both counter-clockwise seen from N1-N4 towards N5-N8... i.e. as LS-DYNA and VTK number a hexahedron)",
                e.at,
                e.id,
                parts[pi].card.id,
                parts[pi].card.title,
                c + 1,
                e.nodes[c],
                det[c]
            ));
            continue;
        }
        element_of_eid.insert(e.id, mesh.elements.len() as u32);
        mesh.elements.push(conn);
        mesh.element_part.push(mesh_part[pi].unwrap_or(0));
    }
    bail!();

    // Node lookup for conditions.
    let node_of = |id: i64, at: &str| -> Result<Option<u32>, String> {
        let i = *node_index
            .get(&id)
            .ok_or_else(|| format!("{at}: node {id} is not defined (no *NODE {id})"))?;
        if rigid_node[i] && palpa_node[i].is_none() {
            return Err(format!(
                "{at}: node {id} belongs to a rigid part; constrain or move a rigid part through *MAT_RIGID (CMO, CON1, CON2) and *BOUNDARY_PRESCRIBED_MOTION_RIGID"
            ));
        }
        Ok(palpa_node[i])
    };
    // Node sets.
    let mut set_name: BTreeMap<i64, String> = BTreeMap::new();
    let mut set_nodes: BTreeMap<i64, Vec<u32>> = BTreeMap::new();
    let mut taken_sets: HashSet<String> = HashSet::new();
    for (&sid, s) in &d.node_sets {
        let at = format!("{}: *SET_NODE {sid}", s.at);
        let mut nodes = Vec::with_capacity(s.ids.len());
        let mut free = 0;
        for &n in &s.ids {
            match node_of(n, &at) {
                Ok(Some(p)) => nodes.push(p),
                Ok(None) => free += 1,
                Err(e) => {
                    // A set of rigid-part nodes is fine until a condition uses it.
                    if !e.contains("rigid part") {
                        errors.push(e);
                    }
                }
            }
        }
        if free > 0 {
            cx.warn.push(format!(
                "{at}: {free} of its nodes belong to no element; left out"
            ));
        }
        nodes.sort_unstable();
        nodes.dedup();
        let name = s
            .title
            .as_deref()
            .and_then(sanitize)
            .unwrap_or_else(|| format!("set_node_{sid}"));
        let name = unique(name, &mut taken_sets, &sid.to_string());
        if !nodes.is_empty() {
            mesh.node_sets.insert(name.clone(), nodes.clone());
        }
        set_name.insert(sid, name);
        set_nodes.insert(sid, nodes);
    }
    for (&sid, s) in &d.solid_sets {
        let mut els = Vec::new();
        for &e in &s.ids {
            match element_of_eid.get(&e) {
                Some(&p) => els.push(p),
                None => errors.push(format!(
                    "{}: *SET_SOLID {sid}: element {e} is not a solid of a deformable part",
                    s.at
                )),
            }
        }
        els.sort_unstable();
        els.dedup();
        let name = s
            .title
            .as_deref()
            .and_then(sanitize)
            .unwrap_or_else(|| format!("set_solid_{sid}"));
        mesh.element_sets.insert(name, els);
    }
    bail!();
    let nodes_of = |t: &Target, at: &str| -> Result<(Vec<u32>, Option<String>), String> {
        match t {
            Target::Node(n) => Ok((node_of(*n, at)?.into_iter().collect(), None)),
            Target::NodeSet(s) => {
                let nodes = set_nodes.get(s).ok_or_else(|| {
                    format!("{at}: node set {s} is not defined (no *SET_NODE {s})")
                })?;
                if nodes.is_empty() {
                    return Err(format!(
                        "{at}: node set {s} has no node of the solid mesh (are its nodes those of a rigid part? Then use *MAT_RIGID and *BOUNDARY_PRESCRIBED_MOTION_RIGID)"
                    ));
                }
                Ok((nodes.clone(), set_name.get(s).cloned()))
            }
            Target::Part(p) => Err(format!("{at}: part {p} is not a node or node set")),
        }
    };

    // Laws and elements.
    let mut part_defs = Vec::new();
    for (pi, p) in parts.iter().enumerate() {
        let Some(mi) = mesh_part[pi] else { continue };
        let name = mesh.part_names[mi as usize].clone();
        match part_def(cx, p, &name) {
            Ok(pd) => part_defs.push(pd),
            Err(e) => errors.push(e),
        }
    }
    bail!();

    // Boundary conditions.
    let mut constraints = Vec::new();
    let mut spc_sets: Vec<(String, Vec<u32>)> = Vec::new();
    let mut spc_nodes: Vec<u32> = Vec::new();
    for (i, n) in d.nodes.iter().enumerate() {
        if n.tc == 0 {
            continue;
        }
        let Some(dofs) = code_dofs(n.tc) else {
            errors.push(format!(
                "{}: *NODE {}, field TC: {} is not a constraint code (0-7)",
                n.at, n.id, n.tc
            ));
            continue;
        };
        let Some(p) = palpa_node[i] else {
            if rigid_node[i] {
                errors.push(format!("{}: *NODE {}, field TC: a node of a rigid part; constrain the part through *MAT_RIGID", n.at, n.id));
            }
            continue;
        };
        for (a, &f) in dofs.iter().enumerate() {
            if f {
                constraints.push(Constraint {
                    nodes: vec![p],
                    dof: a,
                    kind: Kinematic::Fixed,
                });
            }
        }
        spc_nodes.push(p);
    }
    for s in &d.spcs {
        let at = format!("{}: *BOUNDARY_SPC", s.at);
        match nodes_of(&s.target, &at) {
            Ok((nodes, name)) => {
                if nodes.is_empty() {
                    continue;
                }
                for (a, &f) in s.dof.iter().enumerate() {
                    if f {
                        constraints.push(Constraint {
                            nodes: nodes.clone(),
                            dof: a,
                            kind: Kinematic::Fixed,
                        });
                    }
                }
                match name {
                    Some(n) if !spc_sets.iter().any(|x| x.0 == n) => spc_sets.push((n, nodes)),
                    Some(_) => {}
                    None => spc_nodes.extend(nodes),
                }
            }
            Err(e) => errors.push(e),
        }
    }
    let mut motion_sets: Vec<(String, Vec<u32>)> = Vec::new();
    let mut motion_nodes: Vec<u32> = Vec::new();
    let mut rigid_motions: HashMap<&str, Vec<&crate::keywords::MotionCard>> = HashMap::new();
    for m in &d.motions {
        let at = format!("{}: *BOUNDARY_PRESCRIBED_MOTION", m.at);
        if let Target::Part(p) = &m.target {
            match part_index.get(p.as_str()) {
                Some(&pi) if parts[pi].rigid => {
                    rigid_motions.entry(parts[pi].card.id.as_str()).or_default().push(m)
                }
                Some(_) => errors.push(format!(
                    "{at}_RIGID: part {p} is not rigid (its material is not *MAT_RIGID); move its nodes with *BOUNDARY_PRESCRIBED_MOTION_SET"
                )),
                None => errors.push(format!("{at}_RIGID: part {p} is not defined")),
            }
            continue;
        }
        let r = (|| -> Result<(), String> {
            let (nodes, name) = nodes_of(&m.target, &at)?;
            let yd = match m.vad {
                0 => Dim::VELOCITY,
                2 => Dim::LENGTH,
                v => {
                    return Err(format!(
                        "{at}, field VAD: {v} is not supported (0: velocity, 2: displacement)"
                    ))
                }
            };
            let dirs: Vec<(usize, f64)> = match m.dof {
                1..=3 => vec![((m.dof - 1) as usize, 1.0)],
                -4 => {
                    let v = vector(cx.d, m.vid, &at)?;
                    (0..3).map(|k| (k, v[k])).collect()
                }
                o => {
                    return Err(format!(
                        "{at}, field DOF: {o} is not supported for nodes (1, 2, 3: x, y, z; -4: along VID); palpa's nodes have no rotations"
                    ))
                }
            };
            let base = cx.bc_curve(&m.lcid, m.sf, yd, &at)?;
            for (a, s) in dirs {
                let cv = if s == 1.0 {
                    base.clone()
                } else {
                    base.scaled(s)
                };
                constraints.push(Constraint {
                    nodes: nodes.clone(),
                    dof: a,
                    kind: if m.vad == 0 {
                        Kinematic::Velocity(cv)
                    } else {
                        Kinematic::Displacement(cv)
                    },
                });
            }
            match name {
                Some(n) if !motion_sets.iter().any(|x| x.0 == n) => motion_sets.push((n, nodes)),
                Some(_) => {}
                None => motion_nodes.extend(nodes),
            }
            Ok(())
        })();
        if let Err(e) = r {
            errors.push(e);
        }
    }
    let mut loads = Vec::new();
    for l in &d.node_loads {
        let at = format!("{}: *LOAD_NODE", l.at);
        let r = (|| -> Result<(), String> {
            let (nodes, _) = nodes_of(&l.target, &at)?;
            if !(1..=3).contains(&l.dof) {
                return Err(format!(
                    "{at}, field DOF: {} is not supported (1, 2, 3: x, y, z forces)",
                    l.dof
                ));
            }
            let cv = cx.bc_curve(&l.lcid, l.sf, Dim::FORCE, &at)?;
            loads.push(NodalLoad {
                nodes,
                dof: (l.dof - 1) as usize,
                curve: cv,
            });
            Ok(())
        })();
        if let Err(e) = r {
            errors.push(e);
        }
    }
    let mut initial_velocity = Vec::new();
    for v in &d.init_vel {
        let at = format!("{}: *INITIAL_VELOCITY", v.at);
        let nodes = match &v.target {
            Target::NodeSet(0) => (0..mesh.nodes.len() as u32).collect(),
            t => match nodes_of(t, &at) {
                Ok((n, _)) => n,
                Err(e) => {
                    errors.push(e);
                    continue;
                }
            },
        };
        initial_velocity.push((nodes, v.v.map(|x| cx.si(x, Dim::VELOCITY))));
    }
    bail!();

    // Settings.
    let mut dt_factor = solver::simulation::DEFAULT_DT_FACTOR;
    let mut mass_scaling = None;
    let mut dt_max = None;
    if let Some(t) = &d.timestep {
        dt_factor = t.tssfac;
        if !(dt_factor > 0.0 && dt_factor <= 1.0) {
            errors.push(format!(
                "{}: *CONTROL_TIMESTEP, field TSSFAC: must lie in (0, 1], got {dt_factor}",
                t.at
            ));
        }
        let limit = d
            .termination
            .as_ref()
            .map(|t| t.endmas)
            .filter(|&m| m > 0.0)
            .map(|m| m / 100.0);
        if t.dt2ms > 0.0 {
            errors.push(format!(
                "{}: *CONTROL_TIMESTEP, field DT2MS: a positive DT2MS (mass added to and taken from every element) is not supported; give it negative (mass added only to elements whose step is below TSSFAC |DT2MS|)",
                t.at
            ));
        } else if t.dt2msf > 0.0 {
            mass_scaling = Some(StepTarget::Initial(t.dt2msf));
            cx.mapping.push(format!(
                "mass scaling: elements whose step falls below {} x the initial step get mass (DT2MSF)",
                t.dt2msf
            ));
        } else if t.dt2ms < 0.0 {
            let mut target = t.tssfac * cx.si(-t.dt2ms, Dim::TIME);
            let mut note = cx.comments(&t.palpa.clone());
            if let Some(exact) = annotate::take::<f64>(&mut note, "target_dt", &t.at, &mut cx.warn)
            {
                if (exact - target).abs() <= 1e-9 * target {
                    target = exact;
                } else {
                    cx.warn.push(format!(
                        "{}: `$palpa: target_dt` is not TSSFAC |DT2MS|; the deck's step is used",
                        t.at
                    ));
                }
            }
            mass_scaling = Some(StepTarget::Step(target));
            cx.mapping.push(format!(
                "mass scaling: elements whose step falls below TSSFAC |DT2MS| = {target:.4e} s get mass"
            ));
        }
        if mass_scaling.is_some() && limit.is_none() {
            cx.notes.push("mass scaling: no ENDMAS in *CONTROL_TERMINATION; palpa stops a run whose added mass passes 5 % of the physical mass".into());
        }
        if let Some(lc) = &t.lctm {
            match cx.constant(
                lc,
                1.0,
                Dim::TIME,
                &format!("{}: *CONTROL_TIMESTEP, field LCTM", t.at),
            ) {
                Ok(v) => dt_max = Some(v),
                Err(e) => errors.push(e),
            }
        }
    }
    let mass_scaling = mass_scaling.map(|target| MassScaling {
        target,
        max_added: d
            .termination
            .as_ref()
            .map(|t| t.endmas)
            .filter(|&m| m > 0.0)
            .map(|m| m / 100.0)
            .unwrap_or(0.05),
    });
    let mut dt_min = d
        .termination
        .as_ref()
        .map(|t| t.dtmin)
        .filter(|&f| f > 0.0)
        .map(DtMin::Factor);
    let mut bulk = match &d.bulk {
        None => Some(BulkViscosity::default()),
        Some((q1, q2, _)) => Some(BulkViscosity {
            quadratic: *q1,
            linear: *q2,
        }),
    };
    if let Some((q1, q2, at)) = &d.bulk {
        let mut t = cx.comments(&d.bulk_palpa.clone());
        if annotate::take::<bool>(&mut t, "bulk_viscosity", at, &mut cx.warn) == Some(false) {
            if *q1 <= 1e-6 && *q2 <= 1e-6 {
                bulk = None;
            } else {
                cx.warn.push(format!(
                    "{at}: `$palpa: bulk_viscosity = false` ignored: Q1 and Q2 are not near zero"
                ));
            }
        }
    }
    // Per-part bulk viscosity of *HOURGLASS cards must agree with the global one.
    for p in &d.parts {
        if let Some(h) = d.hourglass.get(&p.hourglass) {
            let (g1, g2) = bulk.map_or((0.0, 0.0), |b| (b.quadratic, b.linear));
            let (q1, q2) = h.q1q2;
            if q1.is_some_and(|q| q != g1 && q != 0.0) || q2.is_some_and(|q| q != g2 && q != 0.0) {
                errors.push(format!(
                    "{}: *HOURGLASS {}, fields Q1/Q2: a bulk viscosity per part is not supported; palpa uses *CONTROL_BULK_VISCOSITY ({g1}, {g2}) for every part",
                    h.at, p.hourglass
                ));
            }
        }
    }
    let damping = d
        .damping
        .as_ref()
        .map(|(v, _)| cx.si(*v, Dim::RATE))
        .filter(|&a| a != 0.0);
    let mut gravity = [0.0; 3];
    let mut gravity_set = [false; 3];
    for bl in &d.body {
        let at = format!("{}: *LOAD_BODY", bl.at);
        match cx.constant(&bl.lcid, bl.sf, Dim::ACCELERATION, &at) {
            Ok(v) => {
                if gravity_set[bl.axis] {
                    errors.push(format!("{at}: a second body load along the same axis"));
                }
                gravity_set[bl.axis] = true;
                // LS-DYNA applies body loads as a base acceleration: a positive value pulls
                // the model towards the negative axis.
                gravity[bl.axis] = -v;
            }
            Err(e) => errors.push(e),
        }
    }
    let gravity = gravity.iter().any(|&g| g != 0.0).then_some(gravity);
    let run_note: RunNote =
        annotate::take(&mut header, "run", &hdr_at, &mut cx.warn).unwrap_or_default();
    let relaxation =
        annotate::take::<RelaxationNote>(&mut header, "relaxation", &hdr_at, &mut cx.warn).map(
            |r| DynamicRelaxation {
                tolerance: r.tolerance,
            },
        );
    if let Some(t) = run_note.dt_min {
        dt_min = Some(DtMin::Time(t));
    }
    let precision = match run_note.precision.as_deref() {
        None => Precision::F64,
        Some(p) => match Precision::parse(p) {
            Ok(p) => p,
            Err(m) => {
                errors.push(format!("{hdr_at}: $palpa run: precision: {m}"));
                Precision::F64
            }
        },
    };
    let subcycling = match run_note.subcycling {
        None => 1,
        Some(k) if (1..=1024).contains(&k) && k.is_power_of_two() => k,
        Some(k) => {
            errors.push(format!(
                "{hdr_at}: $palpa run: subcycling: must be a power of two from 1 (off) to 1024, got {k}"
            ));
            1
        }
    };
    let step_estimate = match &run_note.step_estimate {
        None => StepEstimate::Element,
        Some(s) => StepEstimate::parse(s).unwrap_or_else(|m| {
            errors.push(format!("{hdr_at}: $palpa run: step_estimate: {m}"));
            StepEstimate::Element
        }),
    };
    if subcycling > 1 && step_estimate == StepEstimate::Global {
        errors.push(format!(
            "{hdr_at}: $palpa run: step_estimate = \"global\" cannot be combined with subcycling"
        ));
    }
    let hourglass_guard = run_note.max_hourglass_ratio.map(|ratio| HourglassGuard {
        ratio,
        after: run_note.hourglass_check_after,
    });
    bail!();

    // Output.
    let mut fields: Vec<String> = ::scene::output_plan::VTK_FIELDS
        .iter()
        .map(|s| s.to_string())
        .collect();
    let vtk_interval = match &d.d3plot {
        None => None,
        Some(p) => {
            let mut t = cx.comments(&p.palpa.clone());
            if let Some(f) = annotate::take::<Vec<String>>(&mut t, "fields", &p.at, &mut cx.warn) {
                fields = f;
            }
            if p.dt > 0.0 {
                Some(cx.si(p.dt, Dim::TIME))
            } else if p.npltc > 0 {
                Some(end_time / p.npltc as f64)
            } else {
                errors.push(format!(
                    "{}: *DATABASE_BINARY_D3PLOT: give DT (or NPLTC) for the frame interval",
                    p.at
                ));
                None
            }
        }
    };
    let out_dt = |what: &[&str]| -> Option<f64> {
        d.outputs
            .iter()
            .filter(|o| what.contains(&o.what.as_str()))
            .map(|o| o.dt)
            .fold(None, |m: Option<f64>, x| Some(m.map_or(x, |m| m.min(x))))
    };
    let history_interval = out_dt(&["GLSTAT", "RCFORC", "SPCFORC", "BNDOUT"])
        .map(|t| cx.si(t, Dim::TIME))
        .unwrap_or(end_time / 500.0);
    let mut reactions = Vec::new();
    if out_dt(&["SPCFORC"]).is_some() {
        reactions.extend(spc_sets.iter().cloned());
        spc_nodes.sort_unstable();
        spc_nodes.dedup();
        if !spc_nodes.is_empty() {
            reactions.push(("spc_nodes".to_string(), spc_nodes.clone()));
        }
    }
    if out_dt(&["BNDOUT"]).is_some() {
        reactions.extend(motion_sets.iter().cloned());
        motion_nodes.sort_unstable();
        motion_nodes.dedup();
        if !motion_nodes.is_empty() {
            reactions.push(("motion_nodes".to_string(), motion_nodes.clone()));
        }
    }
    let mut probe = None;
    for (i, (sid, ids, at)) in d.history_solid.iter().enumerate() {
        if i > 0 {
            cx.warn.push(format!(
                "{at}: palpa samples one element set; only the first *DATABASE_HISTORY_SOLID request is used"
            ));
            break;
        }
        match sid {
            Some(s) => match d.solid_sets.get(s) {
                Some(set) => {
                    let name = set
                        .title
                        .as_deref()
                        .and_then(sanitize)
                        .unwrap_or_else(|| format!("set_solid_{s}"));
                    probe = Some((name.clone(), mesh.element_sets[&name].clone()));
                }
                None => errors.push(format!(
                    "{at}: *DATABASE_HISTORY_SOLID_SET: set {s} is not defined (no *SET_SOLID {s})"
                )),
            },
            None => {
                let mut els = Vec::new();
                for e in ids {
                    match element_of_eid.get(e) {
                        Some(&p) => els.push(p),
                        None => errors.push(format!(
                            "{at}: *DATABASE_HISTORY_SOLID: element {e} is not a solid of a deformable part"
                        )),
                    }
                }
                mesh.element_sets
                    .insert("history_solid".into(), els.clone());
                probe = Some(("history_solid".to_string(), els));
            }
        }
    }
    let frame_interval = vtk_interval.or_else(|| {
        probe.as_ref().map(|_| {
            out_dt(&["ELOUT"])
                .map(|t| cx.si(t, Dim::TIME))
                .unwrap_or(end_time / 10.0)
        })
    });
    if let (Some(_), Some(e)) = (vtk_interval, out_dt(&["ELOUT"])) {
        if probe.is_some() && cx.si(e, Dim::TIME) != vtk_interval.unwrap_or(0.0) {
            cx.warn.push(
                "*DATABASE_ELOUT: palpa samples the solid history with the d3plot frames (its DT)"
                    .into(),
            );
        }
    }
    let output = OutputPlan {
        vtk_interval,
        history_interval,
        fields,
        reactions,
        frame_interval,
        probe,
    };
    bail!();

    // Contact.
    let contact = match contact_def(
        cx,
        &parts,
        &part_index,
        &mesh_part,
        &mesh,
        &node_index,
        &palpa_node,
        &set_nodes,
        &rigid_solids,
        &rigid_shells,
        &rigid_motions,
    ) {
        Ok(c) => c,
        Err(mut e) => {
            errors.append(&mut e);
            None
        }
    };
    bail!();
    if let Some(t) = header.as_ref().filter(|t| !t.is_empty()) {
        cx.warn.push(format!(
            "{hdr_at}: `$palpa:` keys not understood: {}",
            t.keys().cloned().collect::<Vec<_>>().join(", ")
        ));
    }
    let title = d
        .title
        .clone()
        .filter(|t| !t.is_empty())
        .unwrap_or_else(|| {
            path.file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default()
        });
    Ok(SceneDef {
        title,
        path: path.to_path_buf(),
        end_time,
        mesh,
        phantom: None,
        setup: Setup {
            parts: part_defs,
            constraints,
            loads,
            initial_velocity,
            dt_factor,
            // LS-DYNA chooses its precision by executable, not by keyword: a deck runs in
            // f64 unless palpa's own `$palpa run` note says otherwise.
            precision,
            dt_max,
            dt_min,
            max_steps: None,
            // LS-DYNA's own subcycling keyword is not read; palpa's is kept in its note
            subcycling,
            step_estimate,
            hourglass_guard,
            bulk,
            damping,
            gravity,
            relaxation,
            mass_scaling,
            output,
            contact,
        },
        notes: Vec::new(),
    })
}

fn vector(d: &Deck, vid: Option<i64>, at: &str) -> Result<[f64; 3], String> {
    let vid = vid.ok_or_else(|| format!("{at}, field VID: DOF -4 needs a vector (VID)"))?;
    let (v, vat) = d.vectors.get(&vid).ok_or_else(|| {
        format!("{at}, field VID: vector {vid} is not defined (no *DEFINE_VECTOR {vid})")
    })?;
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if !(n > 0.0) {
        return Err(format!("{vat}: *DEFINE_VECTOR {vid} has zero length"));
    }
    Ok(*v)
}

/// The law and element of a deformable part.
fn part_def(cx: &mut Ctx, p: &PartInfo, name: &str) -> Result<PartDef, String> {
    let m = p.mat;
    let mid = &p.card.material;
    let here = format!(
        "{}: {} {mid} (part {} `{}`)",
        m.at, m.keyword, p.card.id, p.card.title
    );
    let (spec, summary) = lsdyna_card(cx, m, &here)?;
    let mut material = spec
        .build_in(name, None)
        .map_err(|e| format!("{here}: {e}"))?;
    let mut spec = spec;
    let mut t = cx.comments(&m.palpa.clone());
    let mut law_note = summary;
    if let Some(card) = annotate::take::<MaterialSpec>(&mut t, "card", &m.at, &mut cx.warn) {
        match card.build_in(name, None) {
            Ok(exact) => {
                if describes(&exact, &material) {
                    law_note = format!(
                        "{} (palpa's own card from the `$palpa: card` comment; LS-DYNA reads {law_note})",
                        exact.law_name()
                    );
                    material = exact;
                    spec = card;
                } else {
                    cx.warn.push(format!(
                        "{}: `$palpa: card` does not describe {} {mid} (its constants are not those the LS-DYNA card holds); the LS-DYNA card is used",
                        m.at, m.keyword
                    ));
                }
            }
            Err(e) => cx
                .warn
                .push(format!("{}: `$palpa: card` ignored: {e}", m.at)),
        }
    }
    let formulation = element(cx, p, &material)?;
    cx.mapping.push(format!(
        "part {} `{name}`: {law_note}; {}",
        p.card.id,
        formulation.label()
    ));
    Ok(PartDef {
        name: name.to_string(),
        material,
        spec,
        formulation,
        bulk: None,
    })
}

/// Whether palpa's card (`exact`) is the one the LS-DYNA card (`deck`) was written from: the
/// constants both hold agree to 1e-9 (the export writes them to 1e-13 or exactly).
fn describes(exact: &Material, deck: &Material) -> bool {
    let eq = |a: f64, b: f64| (a - b).abs() <= 1e-9 * a.abs().max(b.abs());
    let all = |a: &[f64], b: &[f64]| a.len() == b.len() && a.iter().zip(b).all(|(x, y)| eq(*x, *y));
    if !eq(exact.density(), deck.density()) {
        return false;
    }
    match (exact, deck) {
        (Material::Ogden(a), Material::Ogden(b)) => {
            let ta: Vec<f64> = a.prony().iter().flat_map(|t| [t.modulus, t.tau]).collect();
            let tb: Vec<f64> = b.prony().iter().flat_map(|t| [t.modulus, t.tau]).collect();
            all(a.mu(), b.mu()) && all(a.alpha(), b.alpha()) && eq(a.bulk, b.bulk) && all(&ta, &tb)
        }
        // Written as a one-term Ogden law, alpha = 2, mu, with the same bulk modulus.
        (Material::NeoHookean(a), Material::Ogden(b)) => {
            all(b.mu(), &[a.mu])
                && all(b.alpha(), &[2.0])
                && eq(b.bulk, a.lambda + 2.0 * a.mu / 3.0)
        }
        (Material::LinearElastic(a), Material::LinearElastic(b)) => {
            eq(a.lambda, b.lambda) && eq(a.mu, b.mu)
        }
        (Material::SimplifiedRubber(a), Material::SimplifiedRubber(b)) => {
            eq(a.bulk, b.bulk)
                && eq(a.damping, b.damping)
                && (eq(a.shear, b.shear) || b.shear == 0.0)
        }
        (Material::PiecewiseLinearPlasticity(a), Material::PiecewiseLinearPlasticity(b)) => {
            eq(a.bulk, b.bulk) && eq(a.shear, b.shear)
        }
        _ => false,
    }
}

/// The scene card an LS-DYNA material stands for, and a one-line summary.
fn lsdyna_card(cx: &Ctx, m: &MatCard, here: &str) -> Result<(MaterialSpec, String), String> {
    let den = |v: f64| Density(cx.si(v, Dim::DENSITY));
    let pa = |v: f64| Pressure(cx.si(v, Dim::PRESSURE));
    Ok(match &m.kind {
        MatKind::Elastic { ro, e, pr } => (
            MaterialSpec::LinearElastic(IsotropicSpec {
                density: den(*ro),
                youngs_modulus: Some(pa(*e)),
                poisson_ratio: Some(Number(*pr)),
                shear_modulus: None,
                bulk_modulus: None,
                strain: None,
            }),
            "*MAT_ELASTIC as linear_elastic (St. Venant-Kirchhoff)".into(),
        ),
        MatKind::Ogden {
            ro,
            pr,
            mu,
            alpha,
            prony,
        } => (
            MaterialSpec::Ogden(OgdenSpec {
                density: den(*ro),
                mu: mu.iter().map(|&x| pa(x)).collect(),
                alpha: alpha.iter().map(|&a| Number(a)).collect(),
                bulk_modulus: None,
                poisson_ratio: Some(Number(*pr)),
                convention: None,
                prony: prony
                    .iter()
                    .map(|&(g, b)| PronySpec {
                        modulus: pa(g),
                        tau: None,
                        decay: Some(Rate(cx.si(b, Dim::RATE))),
                    })
                    .collect(),
                prony_on: None,
            }),
            format!(
                "*MAT_OGDEN_RUBBER as ogden, {} term(s), {} Prony term(s) on the Green strain",
                mu.len(),
                prony.len()
            ),
        ),
        MatKind::SimplifiedRubber {
            ro,
            km,
            mu,
            g,
            gauge,
            lc,
        } => {
            let curve = match lc {
                None => {
                    if !(*g > 0.0) {
                        return Err(format!(
                            "{here}: field LC/TBID: a load curve is required (or G, for palpa's neo-Hookean curve P = G (l - 1/l^2))"
                        ));
                    }
                    None
                }
                Some(lc) => {
                    let [sgl, sw, st] = *gauge;
                    if !(sgl > 0.0 && sw > 0.0 && st > 0.0) {
                        return Err(format!(
                            "{here}: fields SGL, SW, ST: the gauge length, width and thickness must be positive"
                        ));
                    }
                    let c = cx.d.curves.get(lc).ok_or_else(|| {
                        format!("{here}: field LC/TBID: load curve {lc} is not defined")
                    })?;
                    Some(
                        c.scaled()
                            .into_iter()
                            .map(|(dl, f)| {
                                (
                                    Number(1.0 + dl / sgl),
                                    Pressure(cx.si(f / (sw * st), Dim::PRESSURE)),
                                )
                            })
                            .collect(),
                    )
                }
            };
            (
                MaterialSpec::SimplifiedRubber(FoamSpec {
                    density: den(*ro),
                    bulk_modulus: pa(*km),
                    shear_modulus: (*g > 0.0).then(|| pa(*g)),
                    damping: Some(Number(*mu)),
                    curve,
                    curve_file: None,
                }),
                if lc.is_some() {
                    "*MAT_SIMPLIFIED_RUBBER/FOAM as simplified_rubber with its load curve".into()
                } else {
                    "*MAT_SIMPLIFIED_RUBBER/FOAM without a curve as simplified_rubber with the neo-Hookean curve of G".into()
                },
            )
        }
        MatKind::Plasticity {
            ro,
            e,
            pr,
            sigy,
            etan,
            fail,
            lcss,
            table,
        } => {
            let (yield_stress, tangent_modulus, hardening) = if let Some(lc) = lcss {
                let (pts, _) = cx.curve(
                    lc,
                    1.0,
                    Dim::NONE,
                    Dim::PRESSURE,
                    &format!("{here}: field LCSS"),
                )?;
                (
                    None,
                    None,
                    Some(
                        pts.into_iter()
                            .map(|(x, y)| (Number(x), Pressure(y)))
                            .collect(),
                    ),
                )
            } else if !table.is_empty() {
                (
                    None,
                    None,
                    Some(table.iter().map(|&(x, y)| (Number(x), pa(y))).collect()),
                )
            } else {
                (Some(pa(*sigy)), Some(pa(*etan)), None)
            };
            (
                MaterialSpec::PiecewiseLinearPlasticity(PlasticitySpec {
                    density: den(*ro),
                    youngs_modulus: pa(*e),
                    poisson_ratio: Number(*pr),
                    yield_stress,
                    tangent_modulus,
                    hardening,
                    failure_strain: fail.map(Number),
                }),
                "*MAT_PIECEWISE_LINEAR_PLASTICITY as piecewise_linear_plasticity".into(),
            )
        }
        MatKind::Rigid { .. } => unreachable!("rigid parts are indenters"),
    })
}

/// The element formulation of a deformable part.
fn element(cx: &mut Ctx, p: &PartInfo, material: &Material) -> Result<Formulation, String> {
    let d = cx.d;
    let sec = d.sections.get(&p.card.section).ok_or_else(|| {
        format!(
            "{}: *PART {} (`{}`), field SECID: section {} is not defined (no *SECTION_SOLID {})",
            p.card.at, p.card.id, p.card.title, p.card.section, p.card.section
        )
    })?;
    if sec.shell {
        return Err(format!(
            "{}: *PART {} (`{}`) has a shell section but solid elements; give it a *SECTION_SOLID",
            p.card.at, p.card.id, p.card.title
        ));
    }
    let hg = d.hourglass.get(&p.card.hourglass);
    if !p.card.hourglass.is_empty() && p.card.hourglass != "0" && hg.is_none() {
        return Err(format!(
            "{}: *PART {} (`{}`), field HGID: hourglass card {} is not defined",
            p.card.at, p.card.id, p.card.title, p.card.hourglass
        ));
    }
    let (ctl_ihq, ctl_qh) = d
        .control_hourglass
        .as_ref()
        .map_or((1, 0.1), |c| (if c.0 == 0 { 1 } else { c.0 }, c.1));
    let ihq = hg.map(|h| h.ihq).filter(|&i| i != 0).unwrap_or(ctl_ihq);
    let qm = hg
        .and_then(|h| h.qm)
        .filter(|&q| q != 0.0)
        .unwrap_or(ctl_qh);
    let hg_at = hg.map_or(sec.at.to_string(), |h| h.at.to_string());
    // Said only where the LS-DYNA element is used (not when palpa's own comment restores it).
    let mut physical_note: Option<String> = None;
    let lsdyna = match sec.elform {
        0 | 1 => {
            let form = match ihq {
                1..=3 => HourglassForm::Viscous,
                4 | 5 => HourglassForm::Stiffness,
                6 | 7 => HourglassForm::Physical,
                o => {
                    return Err(format!(
                        "{hg_at}: hourglass type IHQ = {o} is not supported (palpa: 1-3 viscous, 4-5 stiffness, Flanagan-Belytschko, scaled by the P-wave modulus; 6-7 physical, assumed strain)"
                    ))
                }
            };
            if form == HourglassForm::Physical {
                physical_note = Some(format!(
                    "{hg_at}: IHQ = {ihq} read as palpa's physical hourglass form with QM = {qm} as its coefficient (Belytschko-Bindeman assumed strain on the Green strain of the modes; LS-DYNA's type 6 is a co-rotational rate form, type 7 a total-strain one: they agree at small strain)"
                ));
            }
            if !(0.0..=1.0).contains(&qm) {
                return Err(format!("{hg_at}: hourglass coefficient QM must lie in [0, 1], got {qm}"));
            }
            Formulation::OnePoint(Hourglass {
                form,
                coefficient: qm,
                modulus: HourglassModulus::PWave,
            })
        }
        2 | -1 | -2 => {
            if sec.elform != 2 {
                cx.warn.push(format!(
                    "{}: *SECTION_SOLID ELFORM {} read as palpa's fully integrated F-bar element (as ELFORM 2)",
                    sec.at, sec.elform
                ));
            }
            Formulation::Full { fbar: true }
        }
        o => {
            return Err(format!(
                "{}: *SECTION_SOLID, field ELFORM: {o} is not supported (palpa: 1 one-point with hourglass control; 2, -1, -2 fully integrated, as F-bar)",
                sec.at
            ))
        }
    };
    let mut t = cx.comments(&p.card.palpa.clone());
    let Some(note) = annotate::take::<ElementNote>(&mut t, "element", &p.card.at, &mut cx.warn)
    else {
        cx.warn.extend(physical_note);
        return Ok(lsdyna);
    };
    // The palpa element the comment names must be the LS-DYNA one, up to the hourglass scaling.
    let c0 = material.initial_wave_speed();
    let lambda2mu = material.density() * c0 * c0;
    let two_mu = 2.0 * material.initial_shear_modulus();
    let exact = match (note.formulation.as_str(), lsdyna) {
        ("full", Formulation::Full { .. }) => Some(Formulation::Full { fbar: false }),
        ("full_fbar", Formulation::Full { .. }) => Some(Formulation::Full { fbar: true }),
        ("one_point", Formulation::OnePoint(h)) => {
            let form = match note.hourglass.as_deref() {
                None | Some("viscous") => HourglassForm::Viscous,
                Some("stiffness") => HourglassForm::Stiffness,
                Some("physical") => HourglassForm::Physical,
                _ => h.form,
            };
            let modulus = match note.hourglass_modulus.as_deref() {
                Some("shear") => HourglassModulus::Shear,
                _ => HourglassModulus::PWave,
            };
            let q = note
                .hourglass_coefficient
                .unwrap_or(if form == HourglassForm::Physical {
                    1.0
                } else {
                    0.1
                });
            let ratio = match (modulus, form) {
                (_, HourglassForm::Physical) | (HourglassModulus::PWave, _) => 1.0,
                (HourglassModulus::Shear, HourglassForm::Viscous) => (two_mu / lambda2mu).sqrt(),
                (HourglassModulus::Shear, HourglassForm::Stiffness) => two_mu / lambda2mu,
            };
            (form == h.form && (q * ratio - h.coefficient).abs() <= 1e-9 * h.coefficient.abs())
                .then_some(Formulation::OnePoint(Hourglass {
                    form,
                    coefficient: q,
                    modulus,
                }))
        }
        _ => None,
    };
    match exact {
        Some(f) => Ok(f),
        None => {
            cx.warn.push(format!(
                "{}: `$palpa: element` does not match the part's ELFORM, IHQ and QM; the LS-DYNA element is used",
                p.card.at
            ));
            cx.warn.extend(physical_note);
            Ok(lsdyna)
        }
    }
}

/// The surface and rigid parts of one side of a contact.
enum Side {
    Parts(Vec<usize>),
    Segments(HashSet<[u32; 4]>),
    Nodes(Vec<bool>),
}

#[allow(clippy::too_many_arguments)]
fn contact_def(
    cx: &mut Ctx,
    parts: &[PartInfo],
    part_index: &HashMap<&str, usize>,
    mesh_part: &[Option<u32>],
    mesh: &Mesh,
    node_index: &HashMap<i64, usize>,
    palpa_node: &[Option<u32>],
    set_nodes: &BTreeMap<i64, Vec<u32>>,
    rigid_solids: &[Vec<usize>],
    rigid_shells: &[Vec<usize>],
    rigid_motions: &HashMap<&str, Vec<&crate::keywords::MotionCard>>,
) -> Result<Option<ContactDef>, Vec<String>> {
    let d = cx.d;
    if d.contacts.is_empty() {
        for (pi, p) in parts.iter().enumerate() {
            if p.rigid && (!rigid_solids[pi].is_empty() || !rigid_shells[pi].is_empty()) {
                cx.warn.push(format!(
                    "{}: rigid part {} (`{}`) takes part in no *CONTACT; palpa ignores it",
                    p.card.at, p.card.id, p.card.title
                ));
            }
        }
        return Ok(None);
    }
    let mut errors = Vec::new();
    let slsfac = d.slsfac.as_ref().map_or(0.1, |s| s.0);
    let side = |c: &ContactCard, k: usize| -> Result<Side, String> {
        let (id, ty) = (c.ids[k], c.types[k]);
        let field = if k == 0 { "SSID" } else { "MSID" };
        let at = format!("{}: {}, field {field}", c.at, c.keyword);
        let part = |p: &str| -> Result<usize, String> {
            part_index
                .get(p)
                .copied()
                .ok_or_else(|| format!("{at}: part {p} is not defined"))
        };
        match ty {
            2 | 3 if id == 0 => Err(format!("{at}: a part or part set is required")),
            3 => Ok(Side::Parts(vec![part(&id.to_string())?])),
            2 => {
                let s = d
                    .part_sets
                    .get(&id)
                    .ok_or_else(|| format!("{at}: part set {id} is not defined (no *SET_PART {id})"))?;
                Ok(Side::Parts(
                    s.ids.iter().map(|p| part(p)).collect::<Result<_, _>>()?,
                ))
            }
            5 if c.single || k == 0 => Ok(Side::Parts((0..parts.len()).collect())),
            0 if c.single && id == 0 => Ok(Side::Parts((0..parts.len()).collect())),
            0 => {
                let s = d
                    .segment_sets
                    .get(&id)
                    .ok_or_else(|| format!("{at}: segment set {id} is not defined (no *SET_SEGMENT {id})"))?;
                let mut faces = HashSet::new();
                for seg in &s.segments {
                    let mut f = [0u32; 4];
                    for (a, n) in seg.iter().enumerate() {
                        let i = node_index
                            .get(n)
                            .ok_or_else(|| format!("{}: *SET_SEGMENT {id}: node {n} is not defined", s.at))?;
                        f[a] = palpa_node[*i].ok_or_else(|| {
                            format!(
                                "{}: *SET_SEGMENT {id}: node {n} is not a node of the solid mesh (rigid surfaces are given as parts)",
                                s.at
                            )
                        })?;
                    }
                    f.sort_unstable();
                    faces.insert(f);
                }
                Ok(Side::Segments(faces))
            }
            4 => {
                let s = set_nodes
                    .get(&id)
                    .ok_or_else(|| format!("{at}: node set {id} is not defined"))?;
                let mut m = vec![false; mesh.nodes.len()];
                for &n in s {
                    m[n as usize] = true;
                }
                Ok(Side::Nodes(m))
            }
            o => Err(format!(
                "{at}: surface type {o} is not supported (0 segment set, 2 part set, 3 part, 4 node set{})",
                if c.single { ", 5 all" } else { "" }
            )),
        }
    };
    // One deformable surface, one set of penalty settings, and the rigid parts of each contact.
    let mut surface: Option<(SurfaceSel, String)> = None;
    let mut params: Option<(ContactParams, String)> = None;
    let mut rigid_of: Vec<(usize, f64, &ContactCard)> = Vec::new(); // (part, friction, card)
    for c in &d.contacts {
        let r = (|| -> Result<(), String> {
            let sides: Vec<Side> = if c.single {
                vec![side(c, 0)?]
            } else {
                vec![side(c, 0)?, side(c, 1)?]
            };
            let (mut rig, mut def_sel, mut def_k) = (Vec::new(), None, 0usize);
            for (k, s) in sides.into_iter().enumerate() {
                match s {
                    Side::Parts(ps) => {
                        let (r, f): (Vec<usize>, Vec<usize>) =
                            ps.into_iter().partition(|&p| parts[p].rigid);
                        if !r.is_empty() && !f.is_empty() && !c.single {
                            return Err(format!(
                                "{}: {}: one side mixes rigid and deformable parts; palpa's contact is between deformable parts (one side) and rigid parts (the other)",
                                c.at, c.keyword
                            ));
                        }
                        if !r.is_empty() {
                            rig.extend(r);
                        }
                        if !f.is_empty() {
                            let mut ok = vec![false; mesh.part_names.len()];
                            for p in f {
                                if let Some(i) = mesh_part[p] {
                                    ok[i as usize] = true;
                                }
                            }
                            def_sel = Some(SurfaceSel {
                                parts: Some(ok),
                                ..Default::default()
                            });
                            def_k = k;
                        }
                    }
                    Side::Segments(f) => {
                        def_sel = Some(SurfaceSel {
                            faces: Some(f),
                            ..Default::default()
                        });
                        def_k = k;
                    }
                    Side::Nodes(m) => {
                        def_sel = Some(SurfaceSel {
                            nodes: Some(m),
                            ..Default::default()
                        });
                        def_k = k;
                    }
                }
            }
            let Some(sel) = def_sel else {
                return Err(format!(
                    "{}: {}: no deformable side; palpa's contact is between deformable parts and rigid parts",
                    c.at, c.keyword
                ));
            };
            if rig.is_empty() {
                return Err(format!(
                    "{}: {}: no rigid side; palpa's contact is between deformable parts and rigid (*MAT_RIGID) parts (contact between deformable bodies is not supported)",
                    c.at, c.keyword
                ));
            }
            let sf_def = if c.single { c.sf[0] } else { c.sf[def_k] };
            let sf_rig = if c.single { 1.0 } else { c.sf[1 - def_k] };
            if sf_rig != 1.0 {
                return Err(format!(
                    "{}: {}, field {}: palpa's penalty comes from the deformable side; put the scale factor {sf_rig} on {} instead",
                    c.at,
                    c.keyword,
                    if def_k == 0 { "SFM" } else { "SFS" },
                    if def_k == 0 { "SFS" } else { "SFM" }
                ));
            }
            let friction = if c.dc == 0.0 || c.fd == c.fs || c.fd == 0.0 && c.dc == 0.0 {
                c.fs
            } else {
                return Err(format!(
                    "{}: {}, fields FD, DC: velocity-dependent friction is not supported; palpa's Coulomb friction is FS",
                    c.at, c.keyword
                ));
            };
            let mut p = ContactParams {
                penalty: if c.soft == 1 {
                    PenaltyKind::Max
                } else {
                    PenaltyKind::Segment
                },
                penalty_scale: slsfac * sf_def,
                soft_scale: c.sofscl,
                design_dt: None,
                damping_ratio: c.vdc / 100.0,
                ..ContactParams::default()
            };
            let mut t = cx.comments(&c.palpa.clone());
            if let Some(note) = annotate::take::<::scene::contact_spec::ContactScene>(
                &mut t,
                "contact",
                &c.at,
                &mut cx.warn,
            ) {
                match ::scene::contact_build::contact_params(Some(&note), 0.0) {
                    Ok(mut q) if c.soft == 1 && q.soft_scale == c.sofscl => {
                        q.design_dt = note.design_dt.map(|t| t.0);
                        q.friction = p.friction;
                        q.damping_ratio = p.damping_ratio;
                        if note.penalty.as_deref() != Some("soft") {
                            q.penalty_scale = p.penalty_scale;
                        }
                        p = q;
                    }
                    _ => cx.warn.push(format!(
                        "{}: `$palpa: contact` does not match SOFT and SOFSCL; the LS-DYNA settings are used",
                        c.at
                    )),
                }
            }
            let key = format!(
                "{:?}",
                (
                    p.penalty,
                    p.penalty_scale,
                    p.soft_scale,
                    p.damping_ratio,
                    p.stiffness_cap,
                    p.design_dt
                )
            );
            match &params {
                None => params = Some((p, key)),
                Some((_, k)) if *k == key => {}
                Some(_) => {
                    return Err(format!(
                        "{}: {}: palpa uses one set of penalty settings (SOFT, SOFSCL, SLSFAC x SFS, VDC) for every contact; this one differs from the first",
                        c.at, c.keyword
                    ))
                }
            }
            let sel_key = surface_key(&sel);
            match &surface {
                None => surface = Some((sel, sel_key)),
                Some((_, k)) if *k == sel_key => {}
                Some(_) => {
                    return Err(format!(
                        "{}: {}: palpa has one deformable contact surface; this contact's deformable side differs from the first contact's",
                        c.at, c.keyword
                    ))
                }
            }
            for r in rig {
                rigid_of.push((r, friction, c));
            }
            Ok(())
        })();
        if let Err(e) = r {
            errors.push(e);
        }
    }
    if !errors.is_empty() {
        return Err(errors);
    }
    let (Some((surface, _)), Some((mut params, _))) = (surface, params) else {
        return Ok(None);
    };
    // Friction: common, or per indenter.
    let fr: Vec<f64> = rigid_of.iter().map(|r| r.1).collect();
    let common = fr.iter().all(|&f| f == fr[0]);
    params.friction = if common { fr[0] } else { 0.0 };
    let mut indenters = Vec::new();
    let mut seen = HashSet::new();
    let mut names = HashSet::new();
    for (pi, friction, c) in &rigid_of {
        if !seen.insert(*pi) {
            continue;
        }
        match indenter(
            cx,
            &parts[*pi],
            node_index,
            &rigid_solids[*pi],
            &rigid_shells[*pi],
            rigid_motions.get(parts[*pi].card.id.as_str()),
            (!common).then_some(*friction),
            &mut names,
        ) {
            Ok(i) => indenters.push(i),
            Err(e) => errors.push(e),
        }
        let _ = c;
    }
    for (pi, p) in parts.iter().enumerate() {
        if p.rigid
            && !seen.contains(&pi)
            && (!rigid_solids[pi].is_empty() || !rigid_shells[pi].is_empty())
        {
            cx.warn.push(format!(
                "{}: rigid part {} (`{}`) takes part in no *CONTACT; palpa ignores it",
                p.card.at, p.card.id, p.card.title
            ));
        }
    }
    if !errors.is_empty() {
        return Err(errors);
    }
    cx.mapping.push(format!(
        "contact: {} penalty (penalty scale {}, soft scale {}), friction {}, damping {} % of critical; {} indenter(s): {}",
        match params.penalty {
            PenaltyKind::Soft => "soft",
            PenaltyKind::Segment => "segment (SOFT = 0)",
            PenaltyKind::Max => "max (SOFT = 1)",
        },
        params.penalty_scale,
        params.soft_scale,
        if common { fr[0].to_string() } else { "per indenter".into() },
        params.damping_ratio * 100.0,
        indenters.len(),
        indenters
            .iter()
            .map(|i: &IndenterDef| i.spec.name.clone())
            .collect::<Vec<_>>()
            .join(", ")
    ));
    let first = &d.contacts[0];
    Ok(Some(ContactDef {
        indenters,
        hands: Vec::new(),
        surface,
        params,
        origin: format!("{}: {}", first.at, first.keyword),
        empty_hint: "its deformable side selects no boundary face of the solid mesh".into(),
    }))
}

fn surface_key(s: &SurfaceSel) -> String {
    let mut f: Vec<&[u32; 4]> = s.faces.iter().flatten().collect();
    f.sort_unstable();
    format!("{:?}{:?}{:?}", s.nodes, s.parts, f)
}

/// A rigid part as an indenter.
#[allow(clippy::too_many_arguments)]
fn indenter(
    cx: &mut Ctx,
    p: &PartInfo,
    node_index: &HashMap<i64, usize>,
    solids: &[usize],
    shells: &[usize],
    motions: Option<&Vec<&crate::keywords::MotionCard>>,
    friction: Option<f64>,
    names: &mut HashSet<String>,
) -> Result<IndenterDef, String> {
    let d = cx.d;
    let here = format!("{}: *PART {} (`{}`)", p.card.at, p.card.id, p.card.title);
    let name = sanitize(&p.card.title).unwrap_or_else(|| format!("part_{}", p.card.id));
    let name = unique(name, names, &p.card.id);
    if solids.is_empty() && shells.is_empty() {
        return Err(format!("{here}: a rigid part in *CONTACT without elements"));
    }
    // Its surface.
    let mut local: HashMap<usize, u32> = HashMap::new();
    let mut verts: Vec<[f64; 3]> = Vec::new();
    let vid = |deck_node: i64, local: &mut HashMap<usize, u32>, verts: &mut Vec<[f64; 3]>| {
        let i = node_index[&deck_node];
        *local.entry(i).or_insert_with(|| {
            let n = &d.nodes[i];
            verts.push(std::array::from_fn(|k| {
                cx.u.to_si_text(&n.text[k], Dim::LENGTH)
                    .unwrap_or_else(|| cx.u.to_si(n.x[k], Dim::LENGTH))
            }));
            (verts.len() - 1) as u32
        })
    };
    let mut tris: Vec<[u32; 3]> = Vec::new();
    if !solids.is_empty() {
        let mut m = Mesh::default();
        for &k in solids {
            let e = &d.solids[k];
            m.elements.push(std::array::from_fn(|a| {
                vid(e.nodes[a], &mut local, &mut verts)
            }));
        }
        m.nodes = verts.clone();
        for f in m.boundary_faces() {
            quad_tris(f.nodes, &mut tris);
        }
    }
    let mut shell_tris = Vec::new();
    for &k in shells {
        let e = &d.shells[k];
        let q = [
            vid(e.nodes[0], &mut local, &mut verts),
            vid(e.nodes[1], &mut local, &mut verts),
            vid(e.nodes[2], &mut local, &mut verts),
            vid(e.nodes[3], &mut local, &mut verts),
        ];
        quad_tris(q, &mut shell_tris);
    }
    if !shell_tris.is_empty() {
        let t = orient_closed(&verts, shell_tris).map_err(|m| format!("{here}: {m}"))?;
        tris.extend(t);
        cx.warn.push(format!(
            "{here}: its shells are read as its surface (their mid-surface: palpa's contact ignores the shell thickness, LS-DYNA's offsets the surface by half of it)"
        ));
    } else {
        check_closed(&tris).map_err(|m| format!("{here}: {m}"))?;
    }
    let size = bbox_diag(&verts);
    let shape = ShapeSpec::Triangles {
        vertices: verts.clone(),
        triangles: tris,
    };
    let mut shape_note = format!(
        "its surface mesh ({} triangles)",
        match &shape {
            ShapeSpec::Triangles { triangles, .. } => triangles.len(),
            _ => 0,
        }
    );
    let mut t = cx.comments(&p.card.palpa.clone());
    let mut parts_spec = None;
    if let Some(exact) =
        annotate::take::<Vec<ShapeSpec>>(&mut t, "indenter", &p.card.at, &mut cx.warn)
    {
        if exact_matches(&exact, &verts, size) {
            shape_note = format!(
                "{} exact shape(s) from the `$palpa: indenter` comment (LS-DYNA reads the mesh)",
                exact.len()
            );
            parts_spec = Some(exact);
        } else {
            cx.warn.push(format!(
                "{here}: `$palpa: indenter` does not describe the part's mesh (moved or edited?); the mesh is used"
            ));
        }
    }
    let parts_spec = match parts_spec {
        Some(p) => p,
        None => vec![shape],
    };
    // Its motion.
    let MatKind::Rigid {
        cmo, con1, con2, ..
    } = p.mat.kind
    else {
        unreachable!()
    };
    let held_t = if cmo > 0.0 {
        code_dofs(con1)
    } else {
        Some([false; 3])
    };
    let held_r = if cmo > 0.0 {
        code_dofs(con2)
    } else {
        Some([false; 3])
    };
    let (Some(held_t), Some(held_r)) = (held_t, held_r) else {
        return Err(format!(
            "{}: {} {}, fields CON1/CON2: {con1}/{con2} are not constraint codes (0-7)",
            p.mat.at, p.mat.keyword, p.card.material
        ));
    };
    let (direction, motion, how) = match motions.map(|v| v.as_slice()).unwrap_or(&[]) {
        [] => {
            if held_t != [true; 3] || held_r != [true; 3] {
                return Err(format!(
                    "{here}: a rigid part without *BOUNDARY_PRESCRIBED_MOTION_RIGID must be fixed (CMO = 1, CON1 = 7, CON2 = 7 in its *MAT_RIGID, {}); palpa has no free rigid bodies",
                    p.mat.at
                ));
            }
            ([0.0, 0.0, -1.0], MotionSpec::Fixed, "fixed".to_string())
        }
        [m] => {
            let at = format!("{}: *BOUNDARY_PRESCRIBED_MOTION_RIGID", m.at);
            // palpa's rigid parts move along the prescribed direction only. LS-DYNA leaves the
            // degrees of freedom that *MAT_RIGID does not hold free: the two agree when the
            // contact pushes the part neither sideways nor round, as in a normal indentation.
            let free_t: Vec<&str> = match m.dof {
                1..=3 => (0..3)
                    .filter(|&k| k != (m.dof - 1) as usize && !held_t[k])
                    .map(|k| ["x", "y", "z"][k])
                    .collect(),
                _ => Vec::new(),
            };
            if held_r != [true; 3] || !free_t.is_empty() {
                let (code, along) = match m.dof {
                    1 => ("5", "x"),
                    2 => ("6", "y"),
                    3 => ("4", "z"),
                    _ => ("7", "its vector"),
                };
                let mut free = Vec::new();
                if !free_t.is_empty() {
                    free.push(format!("its translation along {}", free_t.join(" and ")));
                }
                if held_r != [true; 3] {
                    free.push("its rotations".to_string());
                }
                cx.warn.push(format!(
                    "{}: {} {} (rigid part {} `{}`): palpa moves the part along {along} only and holds {}, which LS-DYNA leaves free (CMO = {cmo}, CON1 = {con1}, CON2 = {con2}); set CMO = 1, CON1 = {code}, CON2 = 7 for the same model in both",
                    p.mat.at,
                    p.mat.keyword,
                    p.card.material,
                    p.card.id,
                    p.card.title,
                    free.join(" and "),
                ));
            }
            let dir: [f64; 3] = match m.dof {
                1..=3 => {
                    let mut v = [0.0; 3];
                    v[(m.dof - 1) as usize] = 1.0;
                    v
                }
                -4 => vector(d, m.vid, &at)?,
                4 => {
                    return Err(format!(
                        "{at}, field DOF: 4 lets the part move in the plane normal to the vector, which palpa does not; use DOF = -4"
                    ))
                }
                o => {
                    return Err(format!(
                        "{at}, field DOF: {o} is not supported (1, 2, 3: along x, y, z; -4: along VID)"
                    ))
                }
            };
            let yd = match m.vad {
                0 => Dim::VELOCITY,
                2 => Dim::LENGTH,
                v => {
                    return Err(format!(
                        "{at}, field VAD: {v} is not supported (0: velocity, 2: displacement)"
                    ))
                }
            };
            let (pts, c) = cx.curve(&m.lcid, m.sf, Dim::TIME, yd, &at)?;
            let (cat, cpalpa) = (c.at.clone(), c.palpa.clone());
            // Press along the direction in which the part goes furthest.
            let peak = pts.iter().fold(0.0f64, |a, p| if p.1.abs() > a.abs() { p.1 } else { a });
            let sign = if peak < 0.0 { -1.0 } else { 1.0 };
            let pts: Vec<[f64; 2]> = pts.iter().map(|&(t, v)| [t, sign * v]).collect();
            let mut curve = contact::Curve::Table { points: pts.clone() };
            let mut tc = cx.comments(&cpalpa);
            if let Some(exact) =
                annotate::take::<contact::Curve>(&mut tc, "motion", &cat, &mut cx.warn)
            {
                let tp: Vec<(f64, f64)> = pts.iter().map(|p| (p[0], p[1])).collect();
                if annotate::points_on(&tp, |x| exact.value(x)) {
                    curve = exact;
                } else {
                    cx.warn.push(format!(
                        "{cat}: `$palpa: motion` does not match the points of *DEFINE_CURVE {}; the table is used",
                        m.lcid
                    ));
                }
            }
            let motion = if m.vad == 0 {
                MotionSpec::Velocity { curve }
            } else {
                MotionSpec::Displacement { curve }
            };
            (
                if sign < 0.0 { dir.map(|x| -x) } else { dir },
                motion,
                {
                    // Rounded first, so that a tiny negative component prints as 0.0000.
                    let r = |x: f64| (x * sign * 1e4).round() / 1e4 + 0.0;
                    format!(
                        "{} along ({:.4}, {:.4}, {:.4})",
                        if m.vad == 0 { "velocity" } else { "displacement" },
                        r(dir[0]),
                        r(dir[1]),
                        r(dir[2])
                    )
                },
            )
        }
        many => {
            return Err(format!(
                "{}: rigid part {} (`{}`) has {} prescribed motions; palpa moves a rigid part along one direction (one *BOUNDARY_PRESCRIBED_MOTION_RIGID, DOF 1-3 or -4)",
                many[1].at,
                p.card.id,
                p.card.title,
                many.len()
            ))
        }
    };
    // The exact direction from the comment, when it is the deck's (to 1e-9 rad).
    let mut direction = direction;
    if let Some(exact) = annotate::take::<[f64; 3]>(&mut t, "direction", &p.card.at, &mut cx.warn) {
        let n = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        let (a, b) = (n(exact), n(direction));
        let c =
            (exact[0] * direction[0] + exact[1] * direction[1] + exact[2] * direction[2]) / (a * b);
        if a > 0.0 && b > 0.0 && c > 1.0 - 1e-15 {
            direction = exact;
        } else if !matches!(motion, MotionSpec::Fixed) {
            cx.warn.push(format!(
                "{here}: `$palpa: direction` is not the direction of its prescribed motion; the deck's is used"
            ));
        }
    }
    cx.mapping.push(format!(
        "rigid part {} as indenter `{name}`: {shape_note}; {how}",
        p.card.id
    ));
    Ok(IndenterDef {
        spec: IndenterSpec {
            name,
            parts: parts_spec,
            direction,
            motion,
            friction,
        },
        origin: format!("{}", p.card.at),
    })
}

fn quad_tris(q: [u32; 4], out: &mut Vec<[u32; 3]>) {
    if q[2] == q[3] || q[3] == q[0] {
        if q[0] != q[1] && q[1] != q[2] && q[0] != q[2] {
            out.push([q[0], q[1], q[2]]);
        }
        return;
    }
    out.push([q[0], q[1], q[2]]);
    out.push([q[0], q[2], q[3]]);
}

fn bbox_diag(v: &[[f64; 3]]) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in v {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt()
}

/// Whether exact shapes describe a mesh: no node outside them, and the same bounding box.
fn exact_matches(shapes: &[ShapeSpec], verts: &[[f64; 3]], size: f64) -> bool {
    let built: Vec<contact::Shape> = match shapes.iter().map(contact::Shape::from_spec).collect() {
        Ok(b) => b,
        Err(_) => return false,
    };
    if built.is_empty() {
        return false;
    }
    let tol = 1e-6 * size;
    let phi = |x: [f64; 3]| {
        built
            .iter()
            .map(|s| s.signed_distance(x).0)
            .fold(f64::INFINITY, f64::min)
    };
    if verts.iter().any(|&x| phi(x) > tol) {
        return false;
    }
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for b in &built {
        let Some(bb) = b.aabb() else { return false };
        for k in 0..3 {
            lo[k] = lo[k].min(bb.min[k]);
            hi[k] = hi[k].max(bb.max[k]);
        }
    }
    let mut mlo = [f64::INFINITY; 3];
    let mut mhi = [f64::NEG_INFINITY; 3];
    for p in verts {
        for k in 0..3 {
            mlo[k] = mlo[k].min(p[k]);
            mhi[k] = mhi[k].max(p[k]);
        }
    }
    (0..3).all(|k| (lo[k] - mlo[k]).abs() <= 1e-3 * size && (hi[k] - mhi[k]).abs() <= 1e-3 * size)
}

/// Edges used once or more than twice: the surface is not closed.
fn check_closed(tris: &[[u32; 3]]) -> Result<(), String> {
    let mut count: HashMap<(u32, u32), i32> = HashMap::new();
    for t in tris {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *count.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let open = count.values().filter(|&&c| c != 2).count();
    if open > 0 {
        return Err(format!(
            "its surface is not closed ({open} edge(s) not shared by exactly two faces); palpa's rigid surfaces must be closed"
        ));
    }
    Ok(())
}

/// Orient a closed triangle surface (from shells) consistently and outward.
fn orient_closed(v: &[[f64; 3]], mut tris: Vec<[u32; 3]>) -> Result<Vec<[u32; 3]>, String> {
    check_closed(&tris).map_err(|e| {
        format!("{e} (a rigid part given as shells must enclose a volume, e.g. a meshed sphere surface)")
    })?;
    let mut by_edge: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    for (i, t) in tris.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            by_edge.entry((a.min(b), a.max(b))).or_default().push(i);
        }
    }
    let n = tris.len();
    let mut comp = vec![usize::MAX; n];
    let mut ncomp = 0;
    for s in 0..n {
        if comp[s] != usize::MAX {
            continue;
        }
        comp[s] = ncomp;
        let mut stack = vec![s];
        while let Some(i) = stack.pop() {
            let t = tris[i];
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                for &j in &by_edge[&(a.min(b), a.max(b))] {
                    if j == i || comp[j] != usize::MAX {
                        continue;
                    }
                    // A consistently oriented neighbour runs the shared edge the other way.
                    let u = tris[j];
                    let same_dir = (0..3).any(|m| u[m] == a && u[(m + 1) % 3] == b);
                    if same_dir {
                        tris[j] = [u[0], u[2], u[1]];
                    }
                    comp[j] = ncomp;
                    stack.push(j);
                }
            }
        }
        ncomp += 1;
    }
    // Outward: positive enclosed volume per component.
    let mut vol = vec![0.0; ncomp];
    for (i, t) in tris.iter().enumerate() {
        let (a, b, c) = (v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]);
        vol[comp[i]] += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
            + a[2] * (b[0] * c[1] - b[1] * c[0]);
    }
    for (i, t) in tris.iter_mut().enumerate() {
        if vol[comp[i]] < 0.0 {
            *t = [t[0], t[2], t[1]];
        }
    }
    Ok(tris)
}
