//! The assembled model: element groups in struct-of-arrays form, lumped masses, selective mass
//! scaling, and the chunk colouring that lets the element loop add its forces into the nodal array
//! in parallel without a race.
//!
//! Elements are grouped by part (one law and one formulation per group). Each group stores
//! its reference data contiguously: connectivity, mean or centre gradients, volumes,
//! hourglass vectors (one-point only), Gauss-point gradients (fully integrated only), and one
//! history buffer with `history_len * n_ip` values per element, empty for a law without history.
//!
//! Lumped mass: m_a = sum_e rho_e int_Ve N_a dV (row sum of the consistent mass, exact by 2x2x2
//! quadrature), which is rho V / 8 per node for a parallelepiped.
//!
//! Selective mass scaling (LS-DYNA DT2MS < 0 style): for a target step dt_t and step factor
//! s_f, an element whose own step s_f L/c is below dt_t gets its density multiplied by
//! (dt_t / (s_f L/c))^2, which raises its step to exactly dt_t; other elements are untouched.
//! The added mass is reported per part.

use crate::element::precision::{NarrowRef, Refs};
use crate::element::{max_face_area, Nodal};
use crate::element::{
    physical, surface_mode_factor, Formulation, Hourglass, HourglassForm, HourglassModulus,
};
use crate::hex::{element_geometry, hourglass_gamma, ElementGeometry};
use crate::mesh::Mesh;
use material::real::{F64x8, Real, LANES};
use material::Material;
use std::fmt;

/// One part: a name, a law and an element formulation.
#[derive(Clone, Debug)]
pub struct Part {
    /// Part name.
    pub name: String,
    /// Its law.
    pub material: Material,
    /// Its element formulation.
    pub formulation: Formulation,
}

/// Why a model could not be built or run.
#[derive(Debug, Clone, PartialEq)]
pub enum SolverError {
    /// An element has a non-positive Jacobian in the reference configuration.
    InvertedElement {
        /// Element id (0-based, as ParaView shows cell ids).
        element: u32,
        /// Part name.
        part: String,
        /// Local corner or Gauss point.
        corner: usize,
        /// The determinant found.
        det: f64,
    },
    /// A law failed during the run.
    ElementFailure {
        /// Element id.
        element: u32,
        /// Part name.
        part: String,
        /// Simulated time (s).
        time: f64,
        /// What the law said.
        reason: String,
    },
    /// Mass scaling would add more than the allowed fraction.
    MassScalingLimit {
        /// Added mass / physical mass of the whole model.
        added_fraction: f64,
        /// Limit.
        limit: f64,
        /// Worst part.
        part: String,
    },
    /// The run went unstable: non-finite energies, or a negative internal energy (the
    /// stability guard of [`crate::simulation::Simulation::step`]). The message says when and
    /// why.
    Unstable(String),
    /// Any other invalid input.
    Invalid(String),
}

impl fmt::Display for SolverError {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            SolverError::InvertedElement { element, part, corner, det } => write!(
                f,
                "element {element} (part `{part}`) has a non-positive Jacobian {det:.3e} at corner {corner}: \
                 it is inverted or degenerate; check its node order (VTK_HEXAHEDRON) and coordinates"
            ),
            SolverError::ElementFailure { element, part, time, reason } => write!(
                f,
                "element {element} (part `{part}`) failed at t = {:.6} ms: {reason}",
                time * 1e3
            ),
            SolverError::MassScalingLimit { added_fraction, limit, part } => write!(
                f,
                "mass scaling would add {:.2} % of the physical mass (limit {:.2} %; most in part `{part}`): \
                 lower the target time step or raise mass_scaling.max_added",
                added_fraction * 100.0,
                limit * 100.0
            ),
            SolverError::Unstable(s) | SolverError::Invalid(s) => f.write_str(s),
        }
    }
}

impl std::error::Error for SolverError {}

/// The element loop's scalar results, and their one reduction: an element's results, a
/// chunk's and the whole loop's are all an `ElementTotals`, and [`ElementTotals::combine`] folds
/// them, element by element inside a chunk and chunk by chunk (in chunk order) across the
/// groups, so that the sums are formed in the same order on any thread count.
#[derive(Clone, Copy, Debug)]
pub struct ElementTotals {
    /// Smallest critical step (s).
    pub dt_min: f64,
    /// Element with the smallest step (global id).
    pub dt_elem: u32,
    /// Stored hourglass energy (J).
    pub hg_stored: f64,
    /// Hourglass dissipation power (W).
    pub hg_power: f64,
    /// Largest hourglass energy of one element this step (J): stored energy plus power x dt.
    pub hg_peak: f64,
    /// The element (global id) with that largest hourglass energy.
    pub hg_peak_elem: u32,
    /// Bulk-viscous power (W).
    pub bulk_power: f64,
    /// Law dissipation this step (J).
    pub law_dissipation: f64,
    /// Elements that reached their failure criterion this step and are eroded from the next.
    pub newly_eroded: u32,
    /// The first of them (global id).
    pub first_eroded: Option<u32>,
}

impl ElementTotals {
    /// Nothing yet: the identity of [`ElementTotals::combine`] (an infinite step, zero sums).
    pub const EMPTY: ElementTotals = ElementTotals {
        dt_min: f64::INFINITY,
        dt_elem: 0,
        hg_stored: 0.0,
        hg_power: 0.0,
        hg_peak: 0.0,
        hg_peak_elem: 0,
        bulk_power: 0.0,
        law_dissipation: 0.0,
        newly_eroded: 0,
        first_eroded: None,
    };

    /// Fold `o`, which comes after `self`, into `self`: the smaller step and the larger
    /// hourglass peak win (the earlier one on a tie), sums and counts add, the first eroded
    /// element stays the first.
    #[inline(always)]
    pub fn combine(&mut self, o: &ElementTotals) {
        if o.dt_min < self.dt_min {
            self.dt_min = o.dt_min;
            self.dt_elem = o.dt_elem;
        }
        self.hg_stored += o.hg_stored;
        self.hg_power += o.hg_power;
        if o.hg_peak > self.hg_peak {
            self.hg_peak = o.hg_peak;
            self.hg_peak_elem = o.hg_peak_elem;
        }
        self.bulk_power += o.bulk_power;
        self.law_dissipation += o.law_dissipation;
        self.newly_eroded += o.newly_eroded;
        if self.first_eroded.is_none() {
            self.first_eroded = o.first_eroded;
        }
    }
}

impl Default for ElementTotals {
    fn default() -> Self {
        ElementTotals::EMPTY
    }
}

/// One chunk of the element loop: its [`ElementTotals`] and what the loop applies after it.
#[derive(Clone, Debug, Default)]
pub struct ChunkOut {
    /// The chunk's totals (its smallest step not yet multiplied by the group's `dt_kappa`).
    pub totals: ElementTotals,
    /// First error: (global element, message).
    pub error: Option<(u32, String)>,
    /// Elements (group-local index) that reached their law's failure criterion this step.
    pub failed: Vec<u32>,
    /// Run-time mass scaling: elements (group-local index) whose step fell below the group's
    /// floor this step, with the density scale that brings it back to the floor.
    pub rescale: Vec<(u32, f64)>,
    /// The global step estimate ([`crate::global_step`]): the largest ratio of an element's
    /// step at the last estimate (`Group::dt_reference`) to its step now (0 without one).
    pub rise: f64,
    /// The element (global id) of `rise`.
    pub rise_elem: u32,
    /// Every element's step (before `dt_kappa`; infinite for an eroded or faulted one), in
    /// local order, when the group's `record_dt` asked for it.
    pub dts: Vec<f64>,
}

/// A group of elements with one law and one formulation (struct of arrays).
#[derive(Clone, Debug)]
pub struct Group {
    /// Part index.
    pub part: usize,
    /// Global element ids.
    pub elements: Vec<u32>,
    /// Connectivity.
    pub conn: Vec<[u32; 8]>,
    /// Mean gradient b_a = 1/V int grad N_a dV, [component][node] (F of one-point elements,
    /// F0 of F-bar elements), per batch of [`LANES`] elements (lane = element of the batch).
    pub grad: Vec<Nodal<F64x8>>,
    /// Reference volumes (m^3).
    pub vol0: Vec<f64>,
    /// Hourglass vectors (one-point only), per batch: read by the `f32` kernels (through
    /// [`NarrowRef`]); the `f64` kernels form the same bits from the reference coordinates
    /// (`solver::forces`).
    pub gamma: Vec<[[F64x8; 8]; 4]>,
    /// Hourglass scale per element (one-point only): a_s (N/m) for the stiffness form,
    /// Q rho0 V0^(2/3) / 4 (kg/m) for the viscous form, Q V0 / 3 (m^3) for the physical form.
    pub hg_scale: Vec<f64>,
    /// Element frames `R0` of the physical hourglass form, per batch (empty for other forms).
    pub hg_frame: Vec<[[F64x8; 3]; 3]>,
    /// Inverse half-lengths of the physical form's elements (1/m), per batch.
    pub hg_inv_len: Vec<[F64x8; 3]>,
    /// Young's modulus (Pa), Poisson's ratio and shear modulus (Pa) of the physical form (the
    /// law's initial ones).
    pub hg_moduli: [f64; 3],
    /// Gauss-point gradients (full only), per batch.
    pub gp_grad: Vec<[Nodal<F64x8>; 8]>,
    /// Gauss-point weights (full only), per batch.
    pub gp_weight: Vec<[F64x8; 8]>,
    /// History values per element (history_len * n_ip).
    pub history_stride: usize,
    /// History buffer (empty for a law without history): `history_stride` lane vectors per
    /// batch, value `k` of integration point `ip` at `batch * stride + ip * history_len + k`, so
    /// each history variable of a batch is contiguous over its elements (struct of arrays).
    pub history: Vec<F64x8>,
    /// Density scale factors from mass scaling (empty if none).
    pub density_scale: Vec<f64>,
    /// The group's chunks ([`CHUNK`] elements each) by colour: no two chunks of one colour share
    /// a node, so the chunks of a colour add their element forces straight into the nodal
    /// force array in parallel without a race, and every node receives its contributions in
    /// the same order (colour, then element order within its chunk) on any thread count.
    pub(crate) colours: Vec<Vec<u32>>,
    /// Largest node index of the group's elements, found once when the model is built: the
    /// element loop checks it against the nodal arrays it is given (its kernels index them
    /// without bounds checks).
    pub(crate) max_node: usize,
    /// Scratch: per-chunk partial results.
    pub chunks: Vec<ChunkOut>,
    /// Eroded flags (empty unless the law can fail).
    pub eroded: Vec<bool>,
    /// Surface-mode factor of the part's stable step (see
    /// [`crate::element::surface_mode_factor`]); the element loop multiplies the group's
    /// smallest `L / c` by it.
    pub dt_kappa: f64,
    /// Run-time mass scaling: the smallest `L / c` an element may have,
    /// `target_dt / (dt_factor * dt_kappa)` (0 without mass scaling).
    pub dt_floor: f64,
    /// Lumped volume of each element node (m^3), kept only with mass scaling (to add mass).
    pub lumped: Vec<[f64; 8]>,
    /// Steps per force evaluation: 1, or the macro ratio `k` of a subcycled run's slow
    /// elements ([`crate::subcycle`]).
    pub subcycle: u32,
    /// The group reports its stable step divided by this: `k` for both groups of a
    /// subcycled part, 1 otherwise.
    pub step_ratio: u32,
    /// A subcycled group's totals from its last evaluation, reported in the steps between
    /// (its law dissipation only once).
    pub held: ElementTotals,
    /// Whether the last element loop evaluated this group (its chunks' results are new).
    pub evaluated: bool,
    /// The group's hourglass energy, for the summary's warning that names the part.
    pub hourglass: GroupHourglass,
    /// The reference data in `f32` lanes, built the first time an `f32` run evaluates the
    /// group ([`crate::element::precision`]).
    pub narrow: Option<Box<NarrowRef>>,
    /// The global step estimate ([`crate::global_step`]): each element's step at the last
    /// estimate (local order; empty without one). The element loop reports the largest
    /// ratio of it to the element's step now ([`ChunkOut::rise`]).
    pub dt_reference: Vec<f64>,
    /// Make the next element loop record every element's step ([`ChunkOut::dts`]).
    pub record_dt: bool,
}

/// A group's hourglass energy: the stiffness form's stored energy and the viscous form's power
/// at the last force evaluation, and the power integrated over the run (the physical form's
/// energy is internal energy and is not counted here).
#[derive(Clone, Copy, Debug, Default)]
pub struct GroupHourglass {
    /// Stored energy at the last force evaluation (J).
    pub stored: f64,
    /// Dissipation power at the last force evaluation (W).
    pub power: f64,
    /// Energy dissipated so far (J).
    pub dissipated: f64,
}

impl GroupHourglass {
    /// Stored plus dissipated energy (J).
    pub fn total(&self) -> f64 {
        self.stored + self.dissipated
    }
}

/// Elements per parallel chunk (a multiple of [`LANES`]). Fixed, so partial sums are formed in
/// the same order for any thread count (bitwise determinism).
pub const CHUNK: usize = 512;

impl Group {
    /// The element loop's colouring (see [`Group::colours`]): the number of colours and the
    /// fewest chunks any colour has (the parallelism the element loop can use).
    pub fn colouring(&self) -> (usize, usize) {
        let fewest = self.colours.iter().map(|c| c.len()).min().unwrap_or(0);
        (self.colours.len(), fewest)
    }
    /// Number of batches of [`LANES`] elements (the last one padded with copies of the group's
    /// last element, whose results are discarded).
    pub fn batches(&self) -> usize {
        self.elements.len().div_ceil(LANES)
    }

    /// The group's `f64` reference data, borrowed (the `f64` kernels read all but the
    /// hourglass vectors: [`Group::kernel_bytes`]).
    pub fn refs(&self) -> Refs<'_, F64x8> {
        Refs {
            grad: &self.grad,
            gamma: &self.gamma,
            hg_frame: &self.hg_frame,
            hg_inv_len: &self.hg_inv_len,
            gp_grad: &self.gp_grad,
            gp_weight: &self.gp_weight,
        }
    }

    /// Bytes of reference data the element kernels read per step: the `f32` copy when it
    /// exists (an `f32` run), else the `f64` data less the hourglass vectors, which the `f64`
    /// kernels form (`solver::forces`).
    pub fn kernel_bytes(&self) -> usize {
        match self.narrow.as_deref() {
            Some(n) => n.refs().bytes(),
            None => self.refs().bytes() - std::mem::size_of_val(self.gamma.as_slice()),
        }
    }

    /// History value `k` of integration point `ip` of group-local element `le`.
    pub fn history_value(&self, le: usize, ip: usize, k: usize, history_len: usize) -> f64 {
        self.history[(le / LANES) * self.history_stride + ip * history_len + k].lane(le % LANES)
    }

    /// History value `k` of every integration point of every element (padding excluded).
    pub fn history_values(&self, k: usize, history_len: usize) -> Vec<f64> {
        let n_ip = self.history_stride / history_len.max(1);
        (0..self.elements.len())
            .flat_map(|le| (0..n_ip).map(move |ip| (le, ip)))
            .map(|(le, ip)| self.history_value(le, ip, k, history_len))
            .collect()
    }
}

/// Colour the chunks of a group (elements in chunks of [`CHUNK`], in order) so that no two chunks
/// of one colour share a node: greedy, each chunk taking the lowest colour none of the earlier
/// chunks it shares a node with has. A mesh numbered for locality (slabs of elements) needs a few
/// colours; each colour lists its chunks in ascending order.
pub(crate) fn colour_chunks(conn: &[[u32; 8]], n_nodes: usize) -> Vec<Vec<u32>> {
    let n_chunks = conn.len().div_ceil(CHUNK);
    // For each node, the chunks (ascending) that touch it.
    let mut node_chunks: Vec<Vec<u32>> = vec![Vec::new(); n_nodes];
    for (e, c) in conn.iter().enumerate() {
        let ci = (e / CHUNK) as u32;
        for &n in c {
            let list = &mut node_chunks[n as usize];
            if list.last() != Some(&ci) {
                list.push(ci);
            }
        }
    }
    let mut colour = vec![u32::MAX; n_chunks];
    let mut colours: Vec<Vec<u32>> = Vec::new();
    let mut taken: Vec<bool> = Vec::new();
    for ci in 0..n_chunks {
        taken.iter_mut().for_each(|t| *t = false);
        for c in &conn[ci * CHUNK..((ci + 1) * CHUNK).min(conn.len())] {
            for &n in c {
                for &other in &node_chunks[n as usize] {
                    if (other as usize) < ci {
                        taken[colour[other as usize] as usize] = true;
                    }
                }
            }
        }
        let k = taken.iter().position(|t| !t).unwrap_or(taken.len());
        if k == colours.len() {
            colours.push(Vec::new());
            taken.push(false);
        }
        colour[ci] = k as u32;
        colours[k].push(ci as u32);
    }
    colours
}

/// Lane vectors of per-element data, batch by batch; lanes past the end repeat the last element.
fn batched<T: Copy, U>(aos: &[T], f: impl Fn(&[&T; LANES]) -> U) -> Vec<U> {
    let n = aos.len();
    (0..n.div_ceil(LANES))
        .map(|b| {
            let items: [&T; LANES] = std::array::from_fn(|l| &aos[(b * LANES + l).min(n - 1)]);
            f(&items)
        })
        .collect()
}

/// One lane vector from eight per-element values.
#[inline]
fn lanes(f: impl Fn(usize) -> f64) -> F64x8 {
    F64x8::new(std::array::from_fn(f))
}

/// Mass-scaling request.
#[derive(Clone, Copy, Debug)]
pub struct MassScaling {
    /// Target time step.
    pub target: StepTarget,
    /// Largest allowed added mass as a fraction of physical mass.
    pub max_added: f64,
}

/// The target step of mass scaling.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StepTarget {
    /// A step (s).
    Step(f64),
    /// A multiple of the model's initial stable step `dt_factor * min_e kappa L_e / c_e`
    /// (scene: `"initial"` for 1, `"4 x initial"`). With 1, no element gets mass at the start,
    /// and an element gets mass only once it shrinks during the run: the step never falls
    /// below its initial value (LS-DYNA's DT2MS = -TSSFAC * dt_initial).
    Initial(f64),
}

impl StepTarget {
    /// Parse `"initial"`, `"<k> x initial"` or a time with its unit (`"2 us"`; a plain number
    /// is seconds).
    pub fn parse(s: &str) -> Result<StepTarget, String> {
        let t = s.trim();
        if let Some(k) = t.strip_suffix("initial") {
            let k = k.trim();
            let k = if k.is_empty() {
                1.0
            } else {
                let num = k
                    .strip_suffix(['x', '*'])
                    .ok_or_else(|| format!("`{s}`: expected \"initial\" or \"<k> x initial\""))?;
                num.trim()
                    .parse::<f64>()
                    .map_err(|_| format!("`{s}`: expected \"<k> x initial\" with a number k"))?
            };
            if !(k > 0.0 && k.is_finite()) {
                return Err(format!("`{s}`: the multiple must be positive"));
            }
            return Ok(StepTarget::Initial(k));
        }
        let hint = "expected a time step such as \"2 us\", \"initial\" or \"<k> x initial\"";
        let q = material::quantity::Quantity::parse(t).map_err(|e| format!("{e}; {hint}"))?;
        let v = q
            .get(material::quantity::Dim::TIME)
            .map_err(|e| format!("{e}; {hint}"))?;
        if !(v > 0.0 && v.is_finite()) {
            return Err(format!("`{s}`: the target step must be positive"));
        }
        Ok(StepTarget::Step(v))
    }
}

impl StepTarget {
    /// Parse a command-line or campaign switch: `"off"` (or `"none"`) for no mass scaling,
    /// otherwise as [`StepTarget::parse`].
    pub fn parse_switch(s: &str) -> Result<Option<StepTarget>, String> {
        match s.trim() {
            "off" | "none" => Ok(None),
            t => StepTarget::parse(t).map(Some),
        }
    }
}

/// In a scene: a time with its unit (a plain number is seconds), `"initial"` or
/// `"<k> x initial"`.
impl<'de> serde::Deserialize<'de> for StepTarget {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        #[derive(serde::Deserialize)]
        #[serde(untagged)]
        enum Raw {
            Number(f64),
            Text(String),
        }
        match Raw::deserialize(d)? {
            Raw::Number(v) => StepTarget::parse(&v.to_string()),
            Raw::Text(s) => StepTarget::parse(&s),
        }
        .map_err(serde::de::Error::custom)
    }
}

impl fmt::Display for StepTarget {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            StepTarget::Step(t) => write!(f, "{t} s"),
            StepTarget::Initial(k) if *k == 1.0 => f.write_str("initial"),
            StepTarget::Initial(k) => write!(f, "{k} x initial"),
        }
    }
}

/// Mass scaling as the model applies it: the target resolved to a step.
#[derive(Clone, Copy, Debug)]
pub struct ResolvedMassScaling {
    /// Target time step (s).
    pub target_dt: f64,
    /// Largest allowed added mass as a fraction of physical mass.
    pub max_added: f64,
}

/// Per-part mass report.
#[derive(Clone, Debug, Default)]
pub struct PartMass {
    /// Part name.
    pub name: String,
    /// Physical mass (kg).
    pub physical: f64,
    /// Added mass (kg).
    pub added: f64,
    /// Elements in the part.
    pub elements: usize,
    /// Elements that received mass.
    pub scaled_elements: usize,
}

impl PartMass {
    /// Added mass as a fraction of the physical mass (0 for a massless part).
    pub fn added_fraction(&self) -> f64 {
        self.added / self.physical.max(1e-300)
    }
}

/// The assembled model.
#[derive(Clone, Debug)]
pub struct Model {
    /// The mesh.
    pub mesh: Mesh,
    /// Parts.
    pub parts: Vec<Part>,
    /// Element groups.
    pub groups: Vec<Group>,
    /// Nodal mass including mass scaling (kg).
    pub mass: Vec<f64>,
    /// Per-part mass report.
    pub part_mass: Vec<PartMass>,
    /// Initial critical step without mass scaling (s), and its element.
    pub initial_dt: (f64, u32),
    /// Initial critical step with mass scaling (s).
    pub scaled_dt: f64,
    /// Selective mass scaling, if requested: applied at build time to the elements whose
    /// initial step is below the target, and again during the run to every element whose
    /// step falls below it (LS-DYNA's negative DT2MS), see
    /// [`crate::simulation::Simulation`].
    pub mass_scaling: Option<ResolvedMassScaling>,
    /// Smallest initial step `kappa L / c` of each part, with mass scaling (s; infinite for a
    /// part without elements).
    pub part_dt: Vec<f64>,
    /// The time-step factor the model was built with.
    dt_factor: f64,
}

/// Initial critical step of one element (s): L / c with L = V / A_max.
pub fn initial_element_dt(x: &[[f64; 3]; 8], volume: f64, c: f64) -> f64 {
    let xt = std::array::from_fn(|i| std::array::from_fn(|a| x[a][i]));
    volume / max_face_area(&xt) / c
}

/// A law's initial wave speed `c0` (m/s) and the surface-mode factor `kappa` of its stable step.
fn step_constants(law: &Material) -> (f64, f64) {
    let c0 = law.initial_wave_speed();
    let m = law.density() * c0 * c0;
    (c0, surface_mode_factor(m, law.initial_shear_modulus()))
}

/// Smallest `kappa L / c0` over the mesh displaced by `u` (s), each element's length
/// `L = V / A_max` taken at its reference volume (`L (V0 / V)^(1/3)`): the step that the same
/// shapes would give a nearly incompressible run, whose elements keep their volume. Inverted
/// elements are skipped. `palpa check`'s pilot follows the run's step with it.
pub fn isochoric_step_at(mesh: &Mesh, parts: &[Part], u: &[[f64; 3]]) -> f64 {
    let props: Vec<(f64, f64)> = parts.iter().map(|p| step_constants(&p.material)).collect();
    let mut dt = f64::INFINITY;
    for (e, conn) in mesh.elements.iter().enumerate() {
        let x0: [[f64; 3]; 8] = std::array::from_fn(|a| mesh.nodes[conn[a] as usize]);
        let x: [[f64; 3]; 8] = std::array::from_fn(|a| {
            let (p, d) = (x0[a], u[conn[a] as usize]);
            [p[0] + d[0], p[1] + d[1], p[2] + d[2]]
        });
        if let (Ok(g0), Ok(g), Some(&(c0, kappa))) = (
            element_geometry(&x0),
            element_geometry(&x),
            props.get(mesh.element_part[e] as usize),
        ) {
            let iso = (g0.volume / g.volume).cbrt();
            dt = dt.min(kappa * iso * initial_element_dt(&x, g.volume, c0));
        }
    }
    dt
}

/// Smallest initial `kappa L / c` over the mesh (s), without mass scaling. Inverted elements
/// are skipped here (the model build reports them).
fn natural_step(mesh: &Mesh, parts: &[Part]) -> f64 {
    // undisplaced, every element keeps its volume: the isochoric factor is exactly 1
    isochoric_step_at(mesh, parts, &vec![[0.0; 3]; mesh.nodes.len()])
}

impl Model {
    /// Build the model. `dt_factor` is the time-step safety factor (used by mass scaling).
    pub fn build(
        mesh: Mesh,
        parts: Vec<Part>,
        mass_scaling: Option<MassScaling>,
        dt_factor: f64,
    ) -> Result<Model, SolverError> {
        check_connectivity(&mesh)?;
        // The target step; a multiple of the initial step needs that step first.
        let fixed_target = match mass_scaling.map(|m| m.target) {
            None => None,
            Some(StepTarget::Step(t)) => Some(t),
            Some(StepTarget::Initial(k)) => Some(k * dt_factor * natural_step(&mesh, &parts)),
        };
        let mut builder = Builder::new(
            &mesh,
            &parts,
            dt_factor,
            fixed_target,
            mass_scaling.is_some(),
        );
        let mut groups = Vec::new();
        for (pi, part) in parts.iter().enumerate() {
            let mut elems: Vec<u32> = (0..mesh.elements.len() as u32)
                .filter(|&e| mesh.element_part[e as usize] as usize == pi)
                .collect();
            // Element order for locality: by lowest node, then by number. A raster-numbered
            // mesh (the box generator's, the phantom's voxels) keeps its order; after a
            // renumbering (`crate::renumber`) the elements follow their nodes.
            let lowest = |e: u32| *mesh.elements[e as usize].iter().min().unwrap();
            elems.sort_by_key(|&e| (lowest(e), e));
            if elems.is_empty() {
                continue;
            }
            groups.push(builder.group(pi, part, elems)?);
        }
        let Builder {
            mass,
            part_mass,
            initial_dt,
            scaled_dt,
            part_dt,
            ..
        } = builder;
        if let Some(ms) = mass_scaling {
            check_added_mass(&ms, &part_mass)?;
        }
        if let Some(n) = mass.iter().position(|&m| !(m > 0.0)) {
            return Err(SolverError::Invalid(format!(
                "node {n} belongs to no element (zero mass); remove it"
            )));
        }
        Ok(Model {
            mesh,
            parts,
            groups,
            mass,
            part_mass,
            initial_dt,
            scaled_dt,
            part_dt,
            dt_factor,
            mass_scaling: match (mass_scaling, fixed_target) {
                (Some(m), Some(t)) => Some(ResolvedMassScaling {
                    target_dt: t,
                    max_added: m.max_added,
                }),
                _ => None,
            },
        })
    }

    /// Split every group with slow elements (`slow`, per global element id) into the group of
    /// its other elements and a group of the slow ones evaluated every `k` steps
    /// ([`crate::subcycle`]). Call before the first force evaluation: the groups are built
    /// anew, with initial history. Returns, per split part, its name and how many of its
    /// elements are slow out of how many.
    pub fn split_for_subcycling(
        &mut self,
        slow: &[bool],
        slow_part: &[bool],
        k: u32,
    ) -> Result<Vec<(String, usize, usize)>, SolverError> {
        // a fresh builder: its masses and reports are discarded (the model has them)
        let target = self.mass_scaling.map(|m| m.target_dt);
        let scaling = self.mass_scaling.is_some();
        let mut builder = Builder::new(&self.mesh, &self.parts, self.dt_factor, target, scaling);
        let mut groups = Vec::with_capacity(self.groups.len() + 1);
        let mut split = Vec::new();
        // every group of a slow part reports its step over k (the slow nodes take the macro
        // step under its elements' stiffness too), and mass scaling keeps its target on the
        // same terms
        let ratio = |mut h: Group| {
            h.step_ratio = k;
            h.dt_floor *= k as f64;
            h
        };
        for g in std::mem::take(&mut self.groups) {
            let (s, f): (Vec<u32>, Vec<u32>) = g.elements.iter().partition(|&&e| slow[e as usize]);
            if s.is_empty() {
                // a slow part without slow elements still borders slow nodes
                groups.push(match slow_part[g.part] {
                    true => ratio(g),
                    false => g,
                });
                continue;
            }
            let part = &self.parts[g.part];
            split.push((part.name.clone(), s.len(), g.elements.len()));
            if !f.is_empty() {
                groups.push(ratio(builder.group(g.part, part, f)?));
            }
            let mut sg = ratio(builder.group(g.part, part, s)?);
            sg.subcycle = k;
            groups.push(sg);
        }
        self.groups = groups;
        Ok(split)
    }

    /// Total physical mass (kg).
    pub fn physical_mass(&self) -> f64 {
        self.part_mass.iter().map(|p| p.physical).sum()
    }
    /// Total added mass (kg).
    pub fn added_mass(&self) -> f64 {
        self.part_mass.iter().map(|p| p.added).sum()
    }
}

/// Every element has a part and refers to nodes of the mesh.
fn check_connectivity(mesh: &Mesh) -> Result<(), SolverError> {
    if mesh.element_part.len() != mesh.elements.len() {
        return Err(SolverError::Invalid("every element needs a part".into()));
    }
    for (e, c) in mesh.elements.iter().enumerate() {
        for &n in c {
            if n as usize >= mesh.nodes.len() {
                return Err(SolverError::Invalid(format!(
                    "element {e} refers to node {n}, but the mesh has {} nodes",
                    mesh.nodes.len()
                )));
            }
        }
    }
    Ok(())
}

/// The mass-scaling limit at build time: the added mass of the whole model may be at most
/// `max_added` times its physical mass; the error names the part with the most added mass.
fn check_added_mass(ms: &MassScaling, part_mass: &[PartMass]) -> Result<(), SolverError> {
    let phys: f64 = part_mass.iter().map(|p| p.physical).sum();
    let added: f64 = part_mass.iter().map(|p| p.added).sum();
    if added > ms.max_added * phys {
        let worst = part_mass
            .iter()
            .max_by(|a, b| a.added.total_cmp(&b.added))
            .map(|p| p.name.clone())
            .unwrap_or_default();
        return Err(SolverError::MassScalingLimit {
            added_fraction: added / phys,
            limit: ms.max_added,
            part: worst,
        });
    }
    Ok(())
}

/// What [`Model::build`] keeps while it goes through the parts: the settings every part shares,
/// and the nodal masses, the mass report and the initial steps summed so far.
struct Builder<'m> {
    mesh: &'m Mesh,
    /// Time-step safety factor.
    dt_factor: f64,
    /// Mass scaling's target step (s), if any.
    target: Option<f64>,
    /// Mass scaling is on: groups keep their density scales and lumped volumes.
    scaling: bool,
    /// Nodal mass including mass scaling (kg).
    mass: Vec<f64>,
    /// Per-part mass report.
    part_mass: Vec<PartMass>,
    /// Smallest initial step without mass scaling (s), and its element.
    initial_dt: (f64, u32),
    /// Smallest initial step with mass scaling (s).
    scaled_dt: f64,
    /// The same per part (s).
    part_dt: Vec<f64>,
}

/// The constants of one part that its elements' reference data and steps need.
struct PartConstants<'p> {
    part: &'p Part,
    /// Density (kg/m^3).
    rho: f64,
    /// Initial wave speed (m/s).
    c0: f64,
    /// The stiffness hourglass form's modulus (Pa), see [`HourglassModulus`].
    hg_modulus: f64,
    /// The viscous hourglass form's factor on the wave speed.
    hg_c_ratio: f64,
}

/// One group's reference data element by element (arrays of structs), before it is put in
/// lanes ([`ElementData::batch_into`]), and the density scale of each element.
struct ElementData {
    scale: Vec<f64>,
    grad: Vec<Nodal>,
    gamma: Vec<[[f64; 8]; 4]>,
    frames: Vec<([[f64; 3]; 3], [f64; 3])>,
    gp_grad: Vec<[Nodal; 8]>,
    gp_weight: Vec<[f64; 8]>,
}

impl<'m> Builder<'m> {
    /// A builder with nothing added yet: `target` is mass scaling's target step (s), if any;
    /// `scaling` whether mass scaling is on.
    fn new(
        mesh: &'m Mesh,
        parts: &[Part],
        dt_factor: f64,
        target: Option<f64>,
        scaling: bool,
    ) -> Builder<'m> {
        Builder {
            mesh,
            dt_factor,
            target,
            scaling,
            mass: vec![0.0; mesh.nodes.len()],
            part_mass: parts
                .iter()
                .map(|p| PartMass {
                    name: p.name.clone(),
                    ..Default::default()
                })
                .collect(),
            initial_dt: (f64::INFINITY, 0u32),
            scaled_dt: f64::INFINITY,
            part_dt: vec![f64::INFINITY; parts.len()],
        }
    }

    /// The group of part `pi`, whose elements are `elems`: reference data, history and chunk
    /// colouring. Adds the elements' masses and initial steps to the builder's totals.
    fn group(&mut self, pi: usize, part: &Part, elems: Vec<u32>) -> Result<Group, SolverError> {
        let n = elems.len();
        let law = &part.material;
        let rho = law.density();
        let (c0, kappa) = step_constants(law);
        let stride = law.history_len() * part.formulation.n_ip();
        let mut g = empty_group(pi, elems.clone(), stride);
        let mut data = ElementData {
            scale: Vec::with_capacity(n),
            grad: Vec::with_capacity(n),
            gamma: Vec::new(),
            frames: Vec::new(),
            gp_grad: Vec::new(),
            gp_weight: Vec::new(),
        };
        let lambda2mu = rho * c0 * c0;
        g.dt_kappa = kappa;
        if let Some(t) = self.target {
            g.dt_floor = t / (self.dt_factor * g.dt_kappa);
        }
        let (hg_modulus, hg_c_ratio) = hourglass_scaling(part, lambda2mu);
        if let Some(moduli) = physical_moduli(part, lambda2mu)? {
            g.hg_moduli = moduli;
        }
        let pc = PartConstants {
            part,
            rho,
            c0,
            hg_modulus,
            hg_c_ratio,
        };
        for &e in &elems {
            self.element(&mut g, &mut data, &pc, pi, e)?;
        }
        if self.scaling {
            g.density_scale = std::mem::take(&mut data.scale);
        }
        data.batch_into(&mut g);
        if stride > 0 {
            init_history(&mut g, law, stride);
        }
        g.colours = colour_chunks(&g.conn, self.mesh.nodes.len());
        g.max_node = g.conn.iter().flatten().copied().max().unwrap_or(0) as usize;
        Ok(g)
    }

    /// Add element `e` of part `pi` to its group: its geometry and reference data, its initial
    /// step and the density scale mass scaling gives it, and its lumped mass.
    fn element(
        &mut self,
        g: &mut Group,
        data: &mut ElementData,
        pc: &PartConstants,
        pi: usize,
        e: u32,
    ) -> Result<(), SolverError> {
        let conn = self.mesh.elements[e as usize];
        let x: [[f64; 3]; 8] = std::array::from_fn(|a| self.mesh.nodes[conn[a] as usize]);
        let geo = element_geometry(&x).map_err(|(corner, det)| SolverError::InvertedElement {
            element: e,
            part: pc.part.name.clone(),
            corner,
            det,
        })?;
        g.conn.push(conn);
        g.vol0.push(geo.volume);
        data.push(g, pc, e, &x, &geo)?;
        let dte = g.dt_kappa * initial_element_dt(&x, geo.volume, pc.c0);
        if dte < self.initial_dt.0 {
            self.initial_dt = (dte, e);
        }
        let mut s = 1.0;
        if let Some(target) = self.target {
            let own = self.dt_factor * dte;
            if own < target {
                s = (target / own).powi(2);
                self.part_mass[pi].scaled_elements += 1;
            }
        }
        self.scaled_dt = self.scaled_dt.min(dte * s.sqrt());
        self.part_dt[pi] = self.part_dt[pi].min(dte * s.sqrt());
        data.scale.push(s);
        if self.scaling {
            g.lumped.push(geo.lumped_volume);
        }
        let rho = pc.rho;
        let pm = &mut self.part_mass[pi];
        pm.physical += rho * geo.volume;
        pm.added += rho * geo.volume * (s - 1.0);
        pm.elements += 1;
        for (&n, &v) in conn.iter().zip(&geo.lumped_volume) {
            self.mass[n as usize] += rho * s * v;
        }
        Ok(())
    }
}

/// A group of part `part` with its elements and history buffer, the rest of its data still
/// empty.
fn empty_group(part: usize, elements: Vec<u32>, stride: usize) -> Group {
    let n = elements.len();
    Group {
        part,
        elements,
        conn: Vec::with_capacity(n),
        grad: Vec::new(),
        vol0: Vec::with_capacity(n),
        gamma: Vec::new(),
        hg_scale: Vec::new(),
        hg_frame: Vec::new(),
        hg_inv_len: Vec::new(),
        hg_moduli: [0.0; 3],
        narrow: None,
        gp_grad: Vec::new(),
        gp_weight: Vec::new(),
        history_stride: stride,
        history: vec![F64x8::splat(0.0); stride * n.div_ceil(LANES)],
        density_scale: Vec::new(),
        colours: Vec::new(),
        max_node: 0,
        hourglass: GroupHourglass::default(),
        chunks: vec![ChunkOut::default(); n.div_ceil(CHUNK)],
        eroded: Vec::new(),
        dt_kappa: 1.0,
        dt_floor: 0.0,
        lumped: Vec::new(),
        subcycle: 1,
        step_ratio: 1,
        held: ElementTotals::EMPTY,
        evaluated: false,
        dt_reference: Vec::new(),
        record_dt: false,
    }
}

/// Hourglass scaling of a part (see [`HourglassModulus`]): the stiffness form's modulus, and
/// the factor on c of the viscous form. `lambda2mu` is the law's `rho c0^2`.
fn hourglass_scaling(part: &Part, lambda2mu: f64) -> (f64, f64) {
    match part.formulation {
        Formulation::OnePoint(hg) if hg.modulus == HourglassModulus::Shear => {
            let two_mu = 2.0 * part.material.initial_shear_modulus();
            (two_mu, (two_mu / lambda2mu).sqrt())
        }
        _ => (lambda2mu, 1.0),
    }
}

/// Young's modulus, Poisson's ratio and shear modulus of a part with the physical hourglass
/// form (None for other formulations); an error unless its law's shear and bulk moduli are
/// positive.
fn physical_moduli(part: &Part, lambda2mu: f64) -> Result<Option<[f64; 3]>, SolverError> {
    if !matches!(part.formulation, Formulation::OnePoint(h) if h.form == HourglassForm::Physical) {
        return Ok(None);
    }
    let mu = part.material.initial_shear_modulus();
    let k = lambda2mu - 4.0 * mu / 3.0;
    if k.is_nan() || mu.is_nan() || k <= 0.0 || mu <= 0.0 {
        return Err(SolverError::Invalid(format!(
            "part `{}`: physical hourglass control needs a positive shear and bulk modulus (its law has G = {mu:e} Pa, K = {k:e} Pa)",
            part.name
        )));
    }
    let (e, nu) = material::law::young_poisson(k, mu);
    Ok(Some([e, nu, mu]))
}

/// Fill a group's history buffer with its law's initial history values.
fn init_history(g: &mut Group, law: &Material, stride: usize) {
    let hl = law.history_len();
    let mut h0 = vec![0.0; hl];
    material::with_law!(law, l => material::Law::init_history(l, &mut h0));
    for (k, h) in g.history.iter_mut().enumerate() {
        *h = F64x8::splat(h0[k % stride % hl]);
    }
}

impl ElementData {
    /// The reference data of element `e` (nodes `x`, geometry `geo`) that its formulation
    /// needs; the one-point element's hourglass scale goes straight to the group.
    fn push(
        &mut self,
        g: &mut Group,
        pc: &PartConstants,
        e: u32,
        x: &[[f64; 3]; 8],
        geo: &ElementGeometry,
    ) -> Result<(), SolverError> {
        match pc.part.formulation {
            Formulation::OnePoint(hg) => {
                self.grad.push(geo.mean_grad);
                self.gamma.push(hourglass_gamma(x, &geo.mean_grad));
                g.hg_scale.push(self.hourglass_scale(hg, pc, e, x, geo)?);
            }
            Formulation::Full { .. } => {
                self.grad.push(geo.mean_grad);
                self.gp_grad.push(geo.gp_grad);
                self.gp_weight.push(geo.gp_weight);
            }
        }
        Ok(())
    }

    /// The hourglass scale of a one-point element (see [`Group::hg_scale`]); the physical
    /// form also keeps the element's frame.
    fn hourglass_scale(
        &mut self,
        hg: Hourglass,
        pc: &PartConstants,
        e: u32,
        x: &[[f64; 3]; 8],
        geo: &ElementGeometry,
    ) -> Result<f64, SolverError> {
        Ok(if hg.form == HourglassForm::Physical {
            self.frames.push(physical::element_frame(x).ok_or_else(|| {
                SolverError::Invalid(format!(
                    "element {e} (part `{}`): no element frame for physical hourglass control (an edge of zero length)",
                    pc.part.name
                ))
            })?);
            hg.coefficient * geo.volume / 3.0
        } else if hg.form == HourglassForm::Stiffness {
            let mut bb = 0.0;
            for i in 0..3 {
                for a in 0..8 {
                    let b = geo.mean_grad[i][a] * geo.volume;
                    bb += b * b;
                }
            }
            hg.coefficient * pc.hg_modulus * bb / (3.0 * geo.volume) / 64.0
        } else {
            // The kernel multiplies by the current wave speed c.
            hg.coefficient * pc.rho * geo.volume.powf(2.0 / 3.0) * 0.25 * pc.hg_c_ratio
        })
    }

    /// Put the reference data in lanes, batch by batch, into the group.
    fn batch_into(&self, g: &mut Group) {
        let nodal = |e: &[&Nodal; LANES]| -> Nodal<F64x8> {
            std::array::from_fn(|i| std::array::from_fn(|a| lanes(|l| e[l][i][a])))
        };
        g.grad = batched(&self.grad, nodal);
        g.gamma = batched(&self.gamma, |e| {
            std::array::from_fn(|k| std::array::from_fn(|a| lanes(|l| e[l][k][a])))
        });
        g.hg_frame = batched(&self.frames, |e| {
            std::array::from_fn(|i| std::array::from_fn(|j| lanes(|l| e[l].0[i][j])))
        });
        g.hg_inv_len = batched(&self.frames, |e| {
            std::array::from_fn(|j| lanes(|l| e[l].1[j]))
        });
        g.gp_grad = batched(&self.gp_grad, |e| {
            std::array::from_fn(|gp| {
                std::array::from_fn(|i| std::array::from_fn(|a| lanes(|l| e[l][gp][i][a])))
            })
        });
        g.gp_weight = batched(&self.gp_weight, |e| {
            std::array::from_fn(|gp| lanes(|l| e[l][gp]))
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Connectivity of an nx x ny x nz block of hexahedra (the box generator's, elements in
    /// x-fastest order) and its node count.
    fn block(nx: u32, ny: u32, nz: u32) -> (Vec<[u32; 8]>, usize) {
        let spec = crate::generate::BoxSpec {
            divisions: [nx as usize, ny as usize, nz as usize],
            ..Default::default()
        };
        let mesh = crate::generate::box_mesh(&spec, "block").unwrap();
        (mesh.elements, mesh.nodes.len())
    }

    /// Every chunk in exactly one colour, and no two chunks of a colour sharing a node.
    fn assert_valid(conn: &[[u32; 8]], n_nodes: usize, colours: &[Vec<u32>]) {
        let n_chunks = conn.len().div_ceil(CHUNK);
        let mut seen = vec![0; n_chunks];
        for colour in colours {
            let mut owner = vec![u32::MAX; n_nodes];
            for &ci in colour {
                seen[ci as usize] += 1;
                let c = ci as usize;
                for e in &conn[c * CHUNK..((c + 1) * CHUNK).min(conn.len())] {
                    for &n in e {
                        let o = &mut owner[n as usize];
                        assert!(
                            *o == u32::MAX || *o == ci,
                            "chunks {} and {ci} share node {n}",
                            *o
                        );
                        *o = ci;
                    }
                }
            }
            assert!(
                colour.windows(2).all(|w| w[0] < w[1]),
                "chunks in ascending order"
            );
        }
        assert!(seen.iter().all(|&s| s == 1), "every chunk coloured once");
    }

    #[test]
    fn colouring_of_an_ordered_block_is_race_free_and_parallel() {
        let (conn, nn) = block(50, 50, 40);
        let colours = colour_chunks(&conn, nn);
        assert_valid(&conn, nn, &colours);
        // Slabs of 512 elements in a 50 x 50 plane: a handful of colours, each with many chunks.
        assert!(colours.len() <= 6, "{} colours", colours.len());
        assert!(colours.iter().all(|c| c.len() >= 20));
    }

    #[test]
    fn colouring_of_a_shuffled_block_is_still_race_free() {
        let (mut conn, nn) = block(20, 20, 20);
        // A fixed pseudo-random permutation of the elements (xorshift).
        let mut s = 0x9e37_79b9_7f4a_7c15u64;
        for i in (1..conn.len()).rev() {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            conn.swap(i, (s % (i as u64 + 1)) as usize);
        }
        let colours = colour_chunks(&conn, nn);
        assert_valid(&conn, nn, &colours);
    }
}
