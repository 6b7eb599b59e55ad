//! The penalty contact stage: deformable boundary quads against rigid indenters.
//!
//! ## Kinematics and penalty (surface-to-surface, sampled)
//! Each boundary face is a bilinear quad with nodes `x_1..x_4` (counter-clockwise seen from
//! outside) and shape functions `N_a(xi, eta)` on `[-1, 1]^2`. The face is sampled at the centres
//! of an `n x n` grid of parametric sub-cells (composite midpoint rule, weights
//! `w_s = J_0(xi_s, eta_s) (2/n)^2` with `J_0` the reference area Jacobian). `n` is chosen per face
//! so that the sample spacing is at most `sample_spacing` times the smallest indenter feature
//! size (fingertip radius), within `[samples_min, samples_max]`: a fingertip smaller than a face
//! still meets many samples, and the force varies smoothly as it slides.
//!
//! A sample at `x_s = sum_a N_a x_a` penetrates an indenter when `phi(x_s - u) < 0`; with the gap
//! `g_s = -phi > 0` and the indenter's outward normal `n_s`, the penalty potential and forces are
//!
//! ```text
//!   Pi = sum_s 1/2 eps_f g_s^2 w_s                 (stored penalty energy, J)
//!   f_a = sum_s N_a(s) eps_f g_s w_s n_s           (force on body node a, N)
//!   F_indenter = -sum_a f_a                        (force of the body on the indenter)
//! ```
//!
//! i.e. a pressure `p = eps_f g` (Pa) integrated over the face, exactly the gradient of `Pi`
//! (reference weights keep it conservative). The pressure penalty of a face is `eps_f = k_f / A_f`
//! where `k_f` is the segment stiffness (N/m) of
//! - **segment** (LS-DYNA `SOFT=0`, OpenRadioss `/INTER/TYPE7` `Istf`): `k_f = s K_f A_f^2 / V_f`,
//!   `K_f` the bulk modulus and `V_f` the volume of the element owning the face, `s` = `penalty_scale`
//!   (LS-DYNA `SLSFAC`, default 0.1) (LS-DYNA Theory Manual, *Contact-Impact Algorithm*,
//!   "penalty method", eq. for `k_i = f_si K_i A_i^2 / V_i`);
//! - **soft** (LS-DYNA `SOFT=1`, meant for soft bodies against stiff ones): `k_f = s_soft m_f /
//!   dt_0^2` with `m_f` the mean nodal mass of the face and `dt_0` the design time step
//!   (`soft_scale`, LS-DYNA `SOFSCL`, default 0.1);
//! - **max**: the larger of the two (LS-DYNA's `SOFT=1` behaviour).
//!
//! ## Stable time step
//! The contact adds to node `a` at most the stiffness `k_a = sum_f eps_f int_f N_a dA` (row sum of
//! the penalty stiffness `eps int N N^T dA`, a Gershgorin bound). The stage reports
//! `dt_c = min_a 2 sqrt(m_a / k_a)` ([`ContactStage::stable_dt_bound`]). Since the largest
//! eigenvalues add at most, `omega^2 <= omega_elem^2 + omega_c^2`, a safe step for body plus contact
//! is `dt <= 1 / sqrt(1/dt_elem^2 + 1/dt_c^2)`. When [`ContactParams::design_dt`] is given, the
//! stage also caps each face's penalty so that `k_a <= stiffness_cap * m_a (2/dt_0)^2`
//! (default cap 0.1): then a solver running at `dt <= dt_0 <= 0.9 * dt_elem` stays stable without
//! looking at contact, because `0.9^2 + 0.1 < 1`. The cap is reported
//! ([`ContactStage::capped_faces`]).
//!
//! ## Damping and friction (optional)
//! With the sample's velocity relative to the indenter `v_r = sum_a N_a v_a - u'`,
//! `v_n = v_r . n_s`, `v_t = v_r - v_n n_s`:
//! - normal damping (LS-DYNA `VDC`): `c_s = 2 zeta sqrt(eps_f w_s m_s)`, normal force
//!   `max(eps_f g_s w_s - c_s v_n, 0)` (never adhesive), `m_s = m_f w_s / A_f`;
//! - regularised Coulomb friction: `f_t = -mu f_n v_t / max(|v_t|, v_reg)`, i.e. viscous below
//!   the regularisation speed `v_reg` and Coulomb above it. For explicit stability `v_reg` is raised
//!   per sample to at least `mu f_n dt / m_s` (the viscous coefficient never exceeds `m_s / dt`).
//!
//! Both dissipate `-(f_damp + f_t) . v_r >= 0`, accumulated as [`ContactStage::dissipated_energy`].
//!
//! ## Energy balance
//! With `W_drive = -int F_indenter . du` the work the indenter drivers do on the body
//! ([`ContactStage::driver_work`], trapezoidal rule), the body's balance reads
//! `KE + IE + E_contact = W_ext + W_drive` with `E_contact = Pi + D` ([`ContactStage::energy`]).
//!
//! ## Broad phase (cost scales with the contact zone)
//! A Verlet-style candidate list per indenter: at a rebuild every face whose current bounding box
//! overlaps the indenter's bounding box inflated by `margin` is listed. The list stays valid while
//! the indenter moves less than `margin / 2` and body nodes move less than `margin / 2`; a rebuild
//! happens when the indenter has moved `margin / 2`, or after `floor(margin / (4 v_max dt))` steps
//! (at most `rebuild_interval`), `v_max` the fastest surface node at the last rebuild (a factor 2
//! of safety for acceleration). Per step only listed faces are visited; each is culled with one
//! distance evaluation at its centre (`phi(c) > max_a |x_a - c|` means no point of the face can
//! touch, `phi` being 1-Lipschitz) before its samples are evaluated. Rebuilds scan all faces
//! (`O(N_faces)`), amortised over the interval. OpenRadioss and LS-DYNA likewise re-sort their
//! buckets every few tens of cycles.
//!
//! Nothing in [`ContactStage::apply`] allocates: lists are reserved at construction, and only the
//! faces touched in the previous step are cleared in the pressure array.

use serde::Deserialize;

use crate::aabb::Aabb;
use crate::indenter::{Indenter, IndenterSpec, IndenterState};
use crate::vec3::*;
use crate::ContactError;

/// The deformable body's boundary, as faces with the data the penalty needs.
#[derive(Clone, Debug, Default)]
pub struct ContactSurface {
    /// Quad faces: 4 node ids, counter-clockwise seen from outside (outward normal by the right-hand rule).
    pub faces: Vec<[u32; 4]>,
    /// Bulk modulus of the element owning each face (Pa).
    pub face_bulk_modulus: Vec<f64>,
    /// Reference volume of the element owning each face (m^3).
    pub face_element_volume: Vec<f64>,
}

/// Where a ray meets the surface ([`ContactSurface::raycast`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayHit {
    /// Face index.
    pub face: usize,
    /// Distance along the (unit) ray (m).
    pub distance: f64,
    /// Hit point (m).
    pub point: [f64; 3],
    /// Outward unit normal of the face there.
    pub normal: [f64; 3],
}

impl ContactSurface {
    /// A flat `n x n` grid of square faces of edge `h` (m) in the plane z = 0, spanning
    /// `[0, n h]^2`, outward normal +z, every face owned by a cube of edge `h` with bulk
    /// modulus `bulk` (Pa): the surface of the contact tests, benchmarks and timing example.
    /// Returns the node positions (x fastest) and the surface.
    pub fn flat_grid(n: usize, h: f64, bulk: f64) -> (Vec<[f64; 3]>, ContactSurface) {
        let mut x = Vec::with_capacity((n + 1) * (n + 1));
        for j in 0..=n {
            for i in 0..=n {
                x.push([i as f64 * h, j as f64 * h, 0.0]);
            }
        }
        let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
        let mut faces = Vec::with_capacity(n * n);
        for j in 0..n {
            for i in 0..n {
                faces.push([id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let nf = faces.len();
        let surface = ContactSurface {
            faces,
            face_bulk_modulus: vec![bulk; nf],
            face_element_volume: vec![h * h * h; nf],
        };
        (x, surface)
    }

    /// First hit of the ray `origin + s * direction` (s >= 0) with the faces at positions `x`
    /// (each quad split into two triangles). `O(N_faces)`: for placing indenters, not per step.
    pub fn raycast(&self, x: &[[f64; 3]], origin: [f64; 3], direction: [f64; 3]) -> Option<RayHit> {
        let d = normalize(direction)?;
        let mut best: Option<RayHit> = None;
        for (fi, f) in self.faces.iter().enumerate() {
            let p = f.map(|i| x[i as usize]);
            for tri in [[0, 1, 2], [0, 2, 3]] {
                let (a, b, c) = (p[tri[0]], p[tri[1]], p[tri[2]]);
                let e1 = sub(b, a);
                let e2 = sub(c, a);
                let h = cross(d, e2);
                let det = dot(e1, h);
                if det.abs() < 1e-300 {
                    continue;
                }
                let inv = 1.0 / det;
                let sv = sub(origin, a);
                let uu = inv * dot(sv, h);
                if !(-1e-12..=1.0 + 1e-12).contains(&uu) {
                    continue;
                }
                let q = cross(sv, e1);
                let vv = inv * dot(d, q);
                if vv < -1e-12 || uu + vv > 1.0 + 1e-12 {
                    continue;
                }
                let s = inv * dot(e2, q);
                #[allow(clippy::unnecessary_map_or)] // is_none_or needs Rust 1.82
                let nearer = best.map_or(true, |b| s < b.distance);
                if s >= 0.0 && nearer {
                    // (x2 - x0) x (x3 - x1) points outward for counter-clockwise 0-1-2-3.
                    let n = normalize(cross(sub(p[2], p[0]), sub(p[3], p[1])))
                        .unwrap_or([0.0, 0.0, 1.0]);
                    best = Some(RayHit {
                        face: fi,
                        distance: s,
                        point: axpy(s, d, origin),
                        normal: n,
                    });
                }
            }
        }
        best
    }
}

/// How the penalty stiffness of a face is chosen.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum PenaltyKind {
    /// Segment based: `k = penalty_scale * K * A^2 / V` (LS-DYNA SOFT=0).
    #[default]
    Segment,
    /// Mass and time-step based: `k = soft_scale * m / dt_0^2` (LS-DYNA SOFT=1); needs `design_dt`.
    Soft,
    /// The larger of the two; needs `design_dt`.
    Max,
}

/// Contact parameters (SI). `Default` gives the documented defaults.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct ContactParams {
    /// Penalty formula. Default [`PenaltyKind::Segment`].
    pub penalty: PenaltyKind,
    /// `s` of the segment formula (LS-DYNA SLSFAC). Default 0.1.
    pub penalty_scale: f64,
    /// `s_soft` of the soft formula (LS-DYNA SOFSCL). Default 0.1.
    pub soft_scale: f64,
    /// Time step the solver plans to run at (s): used by the soft formula and the stiffness cap.
    /// Default none.
    pub design_dt: Option<f64>,
    /// Cap on the contact stiffness per node as a fraction of `m (2/design_dt)^2`; applied only
    /// with `design_dt`. Default 0.1; `None` disables.
    pub stiffness_cap: Option<f64>,
    /// Coulomb friction coefficient for indenters that set none. Default 0.
    pub friction: f64,
    /// Friction regularisation speed (m/s). Default 1 mm/s.
    pub friction_velocity: f64,
    /// Normal contact damping as a fraction of critical (LS-DYNA VDC / 100). Default 0.
    pub damping_ratio: f64,
    /// Fewest samples per face direction. Default 2.
    pub samples_min: u32,
    /// Most samples per face direction. Default 12.
    pub samples_max: u32,
    /// Target sample spacing as a fraction of the smallest indenter feature size. Default 0.125.
    pub sample_spacing: f64,
    /// Broad-phase margin (m). Default: the mean face edge length.
    pub margin: Option<f64>,
    /// Most steps between broad-phase rebuilds. Default 200.
    pub rebuild_interval: u32,
}

impl Default for ContactParams {
    fn default() -> Self {
        ContactParams {
            penalty: PenaltyKind::Segment,
            penalty_scale: 0.1,
            soft_scale: 0.1,
            design_dt: None,
            stiffness_cap: Some(0.1),
            friction: 0.0,
            friction_velocity: 1e-3,
            damping_ratio: 0.0,
            samples_min: 2,
            samples_max: 12,
            sample_spacing: 0.125,
            margin: None,
            rebuild_interval: 200,
        }
    }
}

/// Per-face constant data.
#[derive(Clone, Debug)]
struct FaceData {
    /// Reference corner positions (m).
    x0: [[f64; 3]; 4],
    /// Pressure penalty eps = k / A (N/m^3).
    eps: f64,
    /// Reference area (m^2).
    area: f64,
    /// Mean nodal mass (kg).
    mass: f64,
    /// Samples per direction.
    n: u32,
}

/// Penalty contact between rigid indenters and a deformable boundary. See the module doc.
#[derive(Debug)]
pub struct ContactStage {
    indenters: Vec<Indenter>,
    states: Vec<IndenterState>,
    faces: Vec<[u32; 4]>,
    data: Vec<FaceData>,
    params: ContactParams,
    n_nodes: usize,
    margin: f64,
    dt_bound: f64,
    capped: usize,
    // Broad phase.
    candidates: Vec<Vec<u32>>,
    u_rebuild: Vec<[f64; 3]>,
    steps_since_rebuild: u32,
    steps_allowed: u32,
    rebuilt: bool,
    rebuilds: u64,
    // Output.
    face_pressure: Vec<f64>,
    touched: Vec<u32>,
    // Energy.
    penalty_energy: f64,
    dissipated: f64,
    driver_work: f64,
    prev_force: Vec<[f64; 3]>,
    prev_offset: Vec<[f64; 3]>,
    faces_checked: u64,
    samples_checked: u64,
}

#[inline]
fn shape_fns(xi: f64, eta: f64) -> [f64; 4] {
    [
        0.25 * (1.0 - xi) * (1.0 - eta),
        0.25 * (1.0 + xi) * (1.0 - eta),
        0.25 * (1.0 + xi) * (1.0 + eta),
        0.25 * (1.0 - xi) * (1.0 + eta),
    ]
}

/// Area Jacobian `|x_xi x x_eta|` of the bilinear quad at `(xi, eta)`.
#[inline]
fn jacobian(p: &[[f64; 3]; 4], xi: f64, eta: f64) -> f64 {
    let mut a = [0.0; 3];
    let mut b = [0.0; 3];
    let dxi = [
        -0.25 * (1.0 - eta),
        0.25 * (1.0 - eta),
        0.25 * (1.0 + eta),
        -0.25 * (1.0 + eta),
    ];
    let deta = [
        -0.25 * (1.0 - xi),
        -0.25 * (1.0 + xi),
        0.25 * (1.0 + xi),
        0.25 * (1.0 - xi),
    ];
    for k in 0..4 {
        a = axpy(dxi[k], p[k], a);
        b = axpy(deta[k], p[k], b);
    }
    norm(cross(a, b))
}

const GAUSS2: [f64; 2] = [-0.577_350_269_189_625_8, 0.577_350_269_189_625_8];

impl ContactStage {
    /// Build the stage.
    ///
    /// - `indenters`: the rigid indenters (see [`IndenterSpec`], [`crate::HandSpec::to_indenter_spec`]);
    /// - `surface`: boundary faces with per-face bulk modulus (Pa) and element volume (m^3);
    /// - `reference_positions`: all node positions at `t = 0` (m), indexed by the face node ids;
    /// - `node_mass`: lumped nodal masses (kg), same indexing;
    /// - `params`: see [`ContactParams`].
    pub fn new(
        indenters: &[IndenterSpec],
        surface: ContactSurface,
        reference_positions: &[[f64; 3]],
        node_mass: &[f64],
        params: ContactParams,
    ) -> Result<Self, ContactError> {
        let inv = |m: String| Err(ContactError::Invalid(m));
        let nf = surface.faces.len();
        let n_nodes = reference_positions.len();
        if node_mass.len() != n_nodes {
            return inv(format!(
                "{} node masses for {} nodes",
                node_mass.len(),
                n_nodes
            ));
        }
        if indenters.is_empty() {
            return inv("contact stage without indenters".into());
        }
        let needs_k = params.penalty != PenaltyKind::Soft;
        if needs_k
            && (surface.face_bulk_modulus.len() != nf || surface.face_element_volume.len() != nf)
        {
            return inv("face_bulk_modulus and face_element_volume need one entry per face".into());
        }
        let needs_dt = params.penalty != PenaltyKind::Segment;
        let dt0 = params.design_dt;
        if let Some(dt) = dt0 {
            if !(dt > 0.0 && dt.is_finite()) {
                return inv(format!("design_dt must be positive, got {dt}"));
            }
        } else if needs_dt {
            return inv("the soft penalty needs design_dt".into());
        }
        if !(params.penalty_scale > 0.0
            && params.soft_scale > 0.0
            && params.friction >= 0.0
            && params.friction_velocity > 0.0
            && params.damping_ratio >= 0.0
            && params.samples_min >= 1
            && params.samples_max >= params.samples_min
            && params.samples_max <= 64
            && params.sample_spacing > 0.0
            && params.rebuild_interval >= 1)
        {
            return inv(format!("invalid contact parameters {params:?}"));
        }
        if let Some(c) = params.stiffness_cap {
            if !(c > 0.0) {
                return inv("stiffness_cap must be positive".into());
            }
        }
        let indenters = indenters
            .iter()
            .map(Indenter::from_spec)
            .collect::<Result<Vec<_>, _>>()?;
        let feature = indenters
            .iter()
            .map(|i| i.feature_size())
            .fold(f64::INFINITY, f64::min);

        let mut data = Vec::with_capacity(nf);
        let mut edge_sum = 0.0;
        for (fi, f) in surface.faces.iter().enumerate() {
            if f.iter().any(|&i| i as usize >= n_nodes) {
                return inv(format!("face {fi} refers to a missing node"));
            }
            let x0 = f.map(|i| reference_positions[i as usize]);
            let mut area = 0.0;
            for &xi in &GAUSS2 {
                for &eta in &GAUSS2 {
                    area += jacobian(&x0, xi, eta);
                }
            }
            if !(area > 0.0) {
                return inv(format!("face {fi} has zero area"));
            }
            let mass = f.iter().map(|&i| node_mass[i as usize]).sum::<f64>() / 4.0;
            if !(mass > 0.0) {
                return inv(format!("face {fi} has non-positive nodal mass"));
            }
            let mut h: f64 = 0.0;
            for k in 0..4 {
                let e = norm(sub(x0[(k + 1) % 4], x0[k]));
                h = h.max(e);
                edge_sum += e;
            }
            let k_seg = if needs_k {
                let (kb, v) = (
                    surface.face_bulk_modulus[fi],
                    surface.face_element_volume[fi],
                );
                if !(kb > 0.0 && v > 0.0) {
                    return inv(format!(
                        "face {fi}: bulk modulus and volume must be positive"
                    ));
                }
                params.penalty_scale * kb * area * area / v
            } else {
                0.0
            };
            let k_soft = match dt0 {
                Some(dt) if needs_dt => params.soft_scale * mass / (dt * dt),
                _ => 0.0,
            };
            let k = match params.penalty {
                PenaltyKind::Segment => k_seg,
                PenaltyKind::Soft => k_soft,
                PenaltyKind::Max => k_seg.max(k_soft),
            };
            let n = if feature.is_finite() {
                (h / (params.sample_spacing * feature)).ceil() as u32
            } else {
                params.samples_min
            }
            .clamp(params.samples_min, params.samples_max);
            data.push(FaceData {
                x0,
                eps: k / area,
                area,
                mass,
                n,
            });
        }
        let margin = params.margin.unwrap_or(if nf > 0 {
            edge_sum / (4 * nf) as f64
        } else {
            0.0
        });

        // Node stiffness row sums and the cap.
        let node_k = |data: &[FaceData]| {
            let mut k = vec![0.0; n_nodes];
            for (f, d) in surface.faces.iter().zip(data) {
                for &xi in &GAUSS2 {
                    for &eta in &GAUSS2 {
                        let nn = shape_fns(xi, eta);
                        let j = jacobian(&d.x0, xi, eta);
                        for a in 0..4 {
                            k[f[a] as usize] += d.eps * nn[a] * j;
                        }
                    }
                }
            }
            k
        };
        let mut capped = 0;
        if let (Some(dt), Some(cap)) = (dt0, params.stiffness_cap) {
            let k = node_k(&data);
            for (f, d) in surface.faces.iter().zip(data.iter_mut()) {
                let mut r: f64 = 1.0;
                for &a in f {
                    let a = a as usize;
                    let limit = cap * node_mass[a] * 4.0 / (dt * dt);
                    if k[a] > limit {
                        r = r.min(limit / k[a]);
                    }
                }
                if r < 1.0 {
                    d.eps *= r;
                    capped += 1;
                }
            }
        }
        let k = node_k(&data);
        let dt_bound = k
            .iter()
            .zip(node_mass)
            .filter(|(k, _)| **k > 0.0)
            .map(|(k, m)| 2.0 * (m / k).sqrt())
            .fold(f64::INFINITY, f64::min);

        let ni = indenters.len();
        let states = indenters
            .iter()
            .map(|i| IndenterState {
                name: i.name.clone(),
                offset: [0.0; 3],
                travel: 0.0,
                depth: 0.0,
                speed: 0.0,
                force: [0.0; 3],
                reaction: 0.0,
                area: 0.0,
                max_penetration: 0.0,
                penalty_energy: 0.0,
            })
            .collect();
        Ok(ContactStage {
            indenters,
            states,
            faces: surface.faces,
            data,
            params,
            n_nodes,
            margin,
            dt_bound,
            capped,
            candidates: (0..ni).map(|_| Vec::with_capacity(nf)).collect(),
            u_rebuild: vec![[0.0; 3]; ni],
            steps_since_rebuild: 0,
            steps_allowed: 0,
            rebuilt: false,
            rebuilds: 0,
            face_pressure: vec![0.0; nf],
            touched: Vec::with_capacity(nf),
            penalty_energy: 0.0,
            dissipated: 0.0,
            driver_work: 0.0,
            prev_force: vec![[0.0; 3]; ni],
            prev_offset: vec![[0.0; 3]; ni],
            faces_checked: 0,
            samples_checked: 0,
        })
    }

    /// Evaluate contact at time `t` (s) for current positions `x` (m) and velocities `v` (m/s; the
    /// latest available, e.g. the half-step velocity of the central-difference scheme), with the
    /// step `dt` (s). Adds the contact forces on the body to `force` (N); per-indenter results are
    /// then in [`ContactStage::indenters`]. Moves the indenters to their position at `t` first, and
    /// updates force-controlled indenters' speed for the next call afterwards. Allocation-free.
    pub fn apply(
        &mut self,
        t: f64,
        dt: f64,
        x: &[[f64; 3]],
        v: &[[f64; 3]],
        force: &mut [[f64; 3]],
    ) {
        assert!(
            x.len() >= self.n_nodes && v.len() >= self.n_nodes && force.len() >= self.n_nodes,
            "contact: arrays shorter than the node count"
        );
        for ind in self.indenters.iter_mut() {
            ind.state.advance(&ind.motion, t);
        }
        self.broad_phase(dt, x, v);

        for &f in &self.touched {
            self.face_pressure[f as usize] = 0.0;
        }
        self.touched.clear();
        self.penalty_energy = 0.0;

        let zeta = self.params.damping_ratio;
        let v_reg = self.params.friction_velocity;
        for j in 0..self.indenters.len() {
            let ind = &self.indenters[j];
            let u = ind.offset();
            let ud = scale(ind.direction, ind.state.v);
            let mu = ind.friction.unwrap_or(self.params.friction);
            let need_v = zeta > 0.0 || mu > 0.0;
            let mut f_ind = [0.0; 3];
            let mut area = 0.0;
            let mut max_pen: f64 = 0.0;
            let mut energy = 0.0;
            let mut diss_power = 0.0;
            for &fi in &self.candidates[j] {
                let fi = fi as usize;
                let face = self.faces[fi];
                let p = face.map(|i| x[i as usize]);
                let c = scale(add(add(p[0], p[1]), add(p[2], p[3])), 0.25);
                let mut r2: f64 = 0.0;
                for q in &p {
                    r2 = r2.max(norm2(sub(*q, c)));
                }
                self.faces_checked += 1;
                let r = r2.sqrt();
                if ind.signed_distance_within(c, u, r).0 > r {
                    continue;
                }
                let d = &self.data[fi];
                let n = d.n;
                let h = 2.0 / n as f64;
                let cell = h * h;
                let pv = if need_v {
                    face.map(|i| v[i as usize])
                } else {
                    [[0.0; 3]; 4]
                };
                let mut fa = [[0.0; 3]; 4];
                let mut fn_face = 0.0;
                for b in 0..n {
                    let eta = -1.0 + h * (b as f64 + 0.5);
                    for a in 0..n {
                        let xi = -1.0 + h * (a as f64 + 0.5);
                        let nn = shape_fns(xi, eta);
                        let mut xs = [0.0; 3];
                        for k in 0..4 {
                            xs = axpy(nn[k], p[k], xs);
                        }
                        self.samples_checked += 1;
                        let (phi, nrm) = ind.signed_distance_within(xs, u, 0.0);
                        if phi >= 0.0 {
                            continue;
                        }
                        let g = -phi;
                        let w = jacobian(&d.x0, xi, eta) * cell;
                        let f_el = d.eps * g * w;
                        energy += 0.5 * f_el * g;
                        max_pen = max_pen.max(g);
                        area += jacobian(&p, xi, eta) * cell;
                        let mut fvec;
                        let mut f_n = f_el;
                        if need_v {
                            let m_s = d.mass * w / d.area;
                            let mut vs = [0.0; 3];
                            for k in 0..4 {
                                vs = axpy(nn[k], pv[k], vs);
                            }
                            let vr = sub(vs, ud);
                            let vn = dot(vr, nrm);
                            if zeta > 0.0 {
                                let c_s = 2.0 * zeta * (d.eps * w * m_s).sqrt();
                                f_n = (f_el - c_s * vn).max(0.0);
                                diss_power -= (f_n - f_el) * vn;
                            }
                            fvec = scale(nrm, f_n);
                            if mu > 0.0 && f_n > 0.0 {
                                let vt = axpy(-vn, nrm, vr);
                                let vt_n = norm(vt);
                                let v_eff = v_reg.max(mu * f_n * dt / m_s);
                                let ft = scale(vt, -mu * f_n / vt_n.max(v_eff));
                                diss_power -= dot(ft, vt);
                                fvec = add(fvec, ft);
                            }
                        } else {
                            fvec = scale(nrm, f_n);
                        }
                        fn_face += f_n;
                        for k in 0..4 {
                            fa[k] = axpy(nn[k], fvec, fa[k]);
                        }
                    }
                }
                if fn_face > 0.0 {
                    for k in 0..4 {
                        let fk = &mut force[face[k] as usize];
                        *fk = add(*fk, fa[k]);
                        f_ind = sub(f_ind, fa[k]);
                    }
                    if self.face_pressure[fi] == 0.0 {
                        self.touched.push(fi as u32);
                    }
                    self.face_pressure[fi] += fn_face / d.area;
                }
            }
            self.penalty_energy += energy;
            self.dissipated += diss_power * dt;

            // Driver work, trapezoidal.
            let du = sub(u, self.prev_offset[j]);
            self.driver_work -= 0.5 * dot(add(self.prev_force[j], f_ind), du);
            self.prev_force[j] = f_ind;
            self.prev_offset[j] = u;

            let dir = ind.direction;
            let reaction = -dot(f_ind, dir);
            let ind = &mut self.indenters[j];
            ind.state
                .after_contact(&ind.motion, t, dt, reaction, max_pen > 0.0);
            let st = &mut self.states[j];
            st.offset = u;
            st.travel = ind.state.s;
            st.depth = ind
                .state
                .contact
                .map_or(0.0, |(s_c, _)| (ind.state.s - s_c).max(0.0));
            st.speed = ind.state.v;
            st.force = f_ind;
            st.reaction = reaction;
            st.area = area;
            st.max_penetration = max_pen;
            st.penalty_energy = energy;
        }
    }

    fn broad_phase(&mut self, dt: f64, x: &[[f64; 3]], v: &[[f64; 3]]) {
        let half = 0.5 * self.margin;
        let mut need = !self.rebuilt || self.steps_since_rebuild >= self.steps_allowed;
        for (ind, u0) in self.indenters.iter().zip(&self.u_rebuild) {
            if norm2(sub(ind.offset(), *u0)) > half * half {
                need = true;
            }
        }
        if !need {
            self.steps_since_rebuild += 1;
            return;
        }
        for c in self.candidates.iter_mut() {
            c.clear();
        }
        let mut vmax2: f64 = 0.0;
        for (fi, f) in self.faces.iter().enumerate() {
            let mut bb = Aabb::EMPTY;
            for &a in f {
                bb.include(x[a as usize]);
                vmax2 = vmax2.max(norm2(v[a as usize]));
            }
            for (j, ind) in self.indenters.iter().enumerate() {
                let u = ind.offset();
                if ind.may_touch(u, &bb, self.margin) {
                    self.candidates[j].push(fi as u32);
                }
            }
        }
        for (ind, u0) in self.indenters.iter().zip(self.u_rebuild.iter_mut()) {
            *u0 = ind.offset();
        }
        let vmax = vmax2.sqrt();
        let allowed = if vmax * dt > 0.0 {
            (self.margin / (4.0 * vmax * dt)).floor()
        } else {
            f64::INFINITY
        };
        self.steps_allowed = allowed.clamp(1.0, self.params.rebuild_interval as f64) as u32;
        self.steps_since_rebuild = 1;
        self.rebuilt = true;
        self.rebuilds += 1;
    }

    /// The surface faces (node ids): the only nodes whose positions [`ContactStage::apply`]
    /// reads.
    pub fn faces(&self) -> &[[u32; 4]] {
        &self.faces
    }

    /// Per-indenter results of the last [`ContactStage::apply`].
    pub fn indenters(&self) -> &[IndenterState] {
        &self.states
    }

    /// Contact energy `Pi + D` (J): stored penalty energy plus the energy dissipated by contact
    /// damping and friction; the term that closes the body's energy balance.
    pub fn energy(&self) -> f64 {
        self.penalty_energy + self.dissipated
    }

    /// Stored penalty energy `Pi` of the last evaluation (J).
    pub fn penalty_energy(&self) -> f64 {
        self.penalty_energy
    }

    /// Energy dissipated by contact damping and friction so far (J).
    pub fn dissipated_energy(&self) -> f64 {
        self.dissipated
    }

    /// Work done on the body by the indenter drivers so far, `-int F_indenter . du` (J).
    pub fn driver_work(&self) -> f64 {
        self.driver_work
    }

    /// Mean contact pressure per face of the last evaluation (Pa): normal force / reference area.
    pub fn face_pressure(&self) -> &[f64] {
        &self.face_pressure
    }

    /// Contact-alone critical time step `min_a 2 sqrt(m_a / k_a)` (s); combine with the element
    /// step as `1 / sqrt(1/dt_elem^2 + 1/dt_c^2)`. Infinite without penalty stiffness.
    pub fn stable_dt_bound(&self) -> f64 {
        self.dt_bound
    }

    /// Number of faces whose penalty the stiffness cap reduced.
    pub fn capped_faces(&self) -> usize {
        self.capped
    }

    /// Faces that carried a contact force in the last evaluation (indices into the surface's
    /// faces, each once): exactly the faces whose nodes received force.
    pub fn touched_faces(&self) -> &[u32] {
        &self.touched
    }

    /// Pressure penalty `eps_f = k_f / A_f` of each face (N/m^3), after the cap.
    pub fn face_penalty(&self) -> impl ExactSizeIterator<Item = f64> + '_ {
        self.data.iter().map(|d| d.eps)
    }

    /// Samples per direction chosen for each face.
    pub fn face_samples(&self) -> impl ExactSizeIterator<Item = u32> + '_ {
        self.data.iter().map(|d| d.n)
    }

    /// Broad-phase candidate faces of indenter `j` (valid since the last rebuild).
    pub fn candidates(&self, j: usize) -> &[u32] {
        &self.candidates[j]
    }

    /// Broad-phase margin (m).
    pub fn margin(&self) -> f64 {
        self.margin
    }

    /// Counters: (broad-phase rebuilds, faces visited, sample points evaluated) since construction.
    pub fn counters(&self) -> (u64, u64, u64) {
        (self.rebuilds, self.faces_checked, self.samples_checked)
    }
}
