//! The global estimate of the stable step: the largest eigenvalue of `M^-1 K` of the whole
//! mesh by Lanczos iteration, as Abaqus/Explicit's global estimator does (Abaqus Analysis
//! User's Guide, "Explicit dynamic analysis", *Stability limit*: the element-by-element
//! estimate is conservative; the global estimate, from the current dilatational wave speeds,
//! gives the larger stable step of the mesh as a whole).
//!
//! ## Why
//! The element estimate `dt_e = kappa L_e / c_e` (`L = V / A_max`, [`crate::element`]) is about
//! the exact critical step of a regular mesh. An element much thinner than its neighbours gets a
//! short `L_e`, but its nodes also carry the neighbours' mass, so the mesh's fastest mode is
//! slower than the element alone suggests. On the paper's 3 mm phantom, whose smoothed surface
//! leaves elements of `L` = 1.6-1.8 mm among 3 mm voxels, the mesh's critical step
//! `2 / omega_max` is 1.57 times the smallest element estimate.
//!
//! ## The operator
//! The one-point element's linear stiffness at the current shape, with each part's initial
//! moduli: per element `K_e = V B^T D B` with `B` the centre gradients of the current shape, `V`
//! its exact volume, `D` isotropic with the P-wave modulus `rho c0^2` and the initial shear
//! modulus (the moduli of the element estimate); `M` the lumped nodal masses with mass scaling;
//! eroded elements left out. Constraints are left out too: they can only lower `omega_max`
//! (Cauchy interlacing), so the estimate errs safe. The hourglass forms add no stiffness here:
//! the viscous form (the default) has none; the stiffness and physical forms add stiffness of the
//! order of the shear modulus to modes the mean strain does not see, far below the dilatational
//! modes of a nearly incompressible tissue (the estimate is meant for those; for a compressible
//! solid it gains little anyway).
//!
//! ## The iteration
//! Lanczos on `A = M^-1/2 K M^-1/2` (symmetric), without reorthogonalisation (lost orthogonality
//! only repeats converged Ritz values; the largest one stays right). It stops when the largest
//! Ritz value `theta` has `beta_k |s_k| <= TOLERANCE theta` (an eigenvalue lies within that
//! bound of `theta`) after at least [`MIN_ITERATIONS`], and the estimate is `theta` plus that
//! bound. The first estimate starts from a fixed pseudo-random vector; later ones from the last
//! top Ritz vector plus half that vector again, so that a mode that has since become the
//! fastest is not missed. Every sum runs in fixed chunks in a fixed order: the same bits on any
//! thread count.
//!
//! ## The step
//! `dt = f G s(t)`, with `G = 2 / sqrt(lambda)` from the last estimate and
//! `s(t) = min(1, min_c m_c(t) / m_c^0)`: `m_c(t)` is chunk `c`'s element minimum in this step's
//! element loop (current shapes, wave speeds, density scales and bulk-viscous term `Q`), `m_c^0`
//! the same on the estimate's shape without `Q`. An element crushed between two estimates
//! therefore lowers the step at once, and the bulk viscosity lowers it as it lowers the
//! element estimate (LS-DYNA's `L / (Q + sqrt(Q^2 + c^2))`; the linear term alone gives
//! `s` = 0.94). The estimate is renewed every `interval` steps, and early when `s` has fallen
//! by `RENEW_FALL` since just after the last estimate (at most every [`MIN_SPACING`] steps): a
//! crushed element that turns out to be surrounded by heavier ones then gets its step back.
//! The step never goes below the element estimate `f min_e dt_e`.
use crate::model::Model;
use rayon::prelude::*;

/// Relative residual bound of the largest Ritz value that ends an estimate.
pub const TOLERANCE: f64 = 1e-3;
/// Fewest iterations of one estimate.
pub const MIN_ITERATIONS: usize = 10;
/// Most iterations of one estimate.
pub const MAX_ITERATIONS: usize = 150;
/// A fall of some chunk's element minimum, relative to the last estimate, that renews the
/// estimate before its interval is out.
pub const RENEW_FALL: f64 = 0.1;
/// Default interval between two estimates (steps).
pub const DEFAULT_INTERVAL: u64 = 500;
/// Fewest steps between two estimates that a fall renews early. Safety does not depend on
/// renewals (`s` lowers the step at once); a renewal only gives back a step that a crushed but
/// well-surrounded element took away.
pub const MIN_SPACING: u64 = 50;
/// Elements or nodes per parallel work item (a fixed size, so the sums do not depend on the
/// threads).
const CHUNK: usize = 1024;

/// One element of the operator: nodes, volume (m^3), centre gradients (1/m), moduli (Pa).
#[derive(Clone, Copy)]
struct OpElement {
    conn: [u32; 8],
    volume: f64,
    grad: [[f64; 8]; 3],
    lambda: f64,
    mu: f64,
}

/// What a run reports about its global estimates.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GlobalStepReport {
    /// Estimates made.
    pub estimates: u64,
    /// Lanczos iterations in all.
    pub iterations: u64,
    /// Smallest and largest ratio of the global to the element estimate (same shape, no bulk
    /// viscosity).
    pub ratio: (f64, f64),
    /// Wall time spent on the estimates (s).
    pub seconds: f64,
}

/// The estimator's state between estimates.
pub struct GlobalStep {
    /// Renew the estimate every this many steps.
    interval: u64,
    /// The last estimate's critical step `2 / sqrt(lambda)` (s).
    global: f64,
    /// Every chunk's element minimum at the last estimate, groups and chunks in order.
    chunk_dt: Vec<f64>,
    /// Step of the last estimate.
    last_step: u64,
    /// `s` just after the last estimate (the bulk viscosity of that step in it).
    fall_after: f64,
    /// What the run reports.
    pub report: GlobalStepReport,
    /// The next start vector, per node.
    vector: Vec<[f64; 3]>,
    /// A fixed pseudo-random vector (the first start, and the part mixed into later ones).
    random: Vec<[f64; 3]>,
    /// Node to (element, local node) adjacency, CSR.
    adj_start: Vec<u32>,
    adj: Vec<(u32, u8)>,
}

impl GlobalStep {
    /// An estimator for `model`, renewed every `interval` steps.
    pub fn new(model: &Model, interval: u64) -> GlobalStep {
        let n = model.mesh.nodes.len();
        let mut count = vec![0u32; n + 1];
        for conn in &model.mesh.elements {
            for &a in conn {
                count[a as usize + 1] += 1;
            }
        }
        for i in 0..n {
            count[i + 1] += count[i];
        }
        let mut fill = count.clone();
        let mut adj = vec![(0u32, 0u8); count[n] as usize];
        for (e, conn) in model.mesh.elements.iter().enumerate() {
            for (la, &a) in conn.iter().enumerate() {
                let k = &mut fill[a as usize];
                adj[*k as usize] = (e as u32, la as u8);
                *k += 1;
            }
        }
        let random: Vec<[f64; 3]> = (0..n)
            .map(|i| {
                let h = (i as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
                std::array::from_fn(|k| ((h >> (13 + 17 * k)) & 0xFFFF) as f64 / 32768.0 - 1.0)
            })
            .collect();
        GlobalStep {
            interval: interval.max(1),
            global: 0.0,
            chunk_dt: Vec::new(),
            last_step: 0,
            fall_after: 1.0,
            report: GlobalStepReport {
                ratio: (f64::INFINITY, 0.0),
                ..Default::default()
            },
            vector: random.clone(),
            random,
            adj_start: count,
            adj,
        }
    }

    /// `s(t)`: the smallest ratio of a chunk's element minimum now to the same at the last
    /// estimate (1 when none fell, or before the first estimate).
    pub fn fall(&self, model: &Model) -> f64 {
        let mut s = 1.0f64;
        for (now, then) in chunk_minima(model).zip(&self.chunk_dt) {
            if now.is_finite() && then.is_finite() && *then > 0.0 {
                s = s.min(now / then);
            }
        }
        s
    }

    /// Whether the estimate is due at `step` with the fall `s` ([`GlobalStep::fall`]): its
    /// interval is out, or `s` fell by `RENEW_FALL` since just after the last estimate and
    /// [`MIN_SPACING`] steps have passed.
    pub fn due(&self, step: u64, s: f64) -> bool {
        self.report.estimates == 0
            || step >= self.last_step + self.interval
            || (s < (1.0 - RENEW_FALL) * self.fall_after && step >= self.last_step + MIN_SPACING)
    }

    /// The last estimate's critical step of the mesh `G = 2 / sqrt(lambda)` (s; 0 before the
    /// first).
    pub fn critical_step(&self) -> f64 {
        self.global
    }

    /// The step this estimator allows before the safety factor (s): `G s`.
    pub fn step(&self, s: f64) -> f64 {
        self.global * s.min(1.0)
    }

    /// Estimate at displacements `u` and masses `mass` (the model's element loop has just run:
    /// its chunk minima are this state's).
    pub fn estimate(&mut self, model: &Model, u: &[[f64; 3]], mass: &[f64], step: u64) {
        let t0 = std::time::Instant::now();
        let (ops, elem_dt) = operator(model, u);
        let w: Vec<f64> = mass.iter().map(|m| 1.0 / m.sqrt()).collect();
        let (lambda, it) = self.lanczos(&ops, &w);
        self.global = 2.0 / lambda.sqrt();
        // each chunk's element minimum on this shape without bulk viscosity, and the model's
        // element estimate (with kappa) for the report
        self.chunk_dt.clear();
        let mut element = f64::INFINITY;
        for g in &model.groups {
            for ch in g.elements.chunks(crate::model::CHUNK) {
                let m = ch
                    .iter()
                    .map(|&e| elem_dt[e as usize])
                    .fold(f64::INFINITY, f64::min);
                self.chunk_dt.push(m);
                element = element.min(g.dt_kappa * m);
            }
        }
        self.last_step = step;
        self.fall_after = self.fall(model);
        let ratio = self.global / element;
        let r = &mut self.report;
        r.estimates += 1;
        r.iterations += it as u64;
        r.ratio = (r.ratio.0.min(ratio), r.ratio.1.max(ratio));
        r.seconds += t0.elapsed().as_secs_f64();
    }

    /// Lanczos on `A = W K W` (`W = M^-1/2`, per node `w`): the largest Ritz value plus its
    /// residual bound, and the iterations. Keeps the top Ritz vector for the next start; the
    /// basis it is formed from is kept in `f32` (a start vector needs no more digits): 12 bytes
    /// per node and iteration, 80 MB for the first estimate of the 3 mm phantom (60 iterations).
    fn lanczos(&mut self, ops: &[OpElement], w: &[f64]) -> (f64, usize) {
        let n = self.vector.len();
        let mut q = std::mem::take(&mut self.vector);
        if self.report.estimates > 0 {
            // the last top Ritz vector (unit length) plus the fixed random vector at half that
            // length
            let (nq, nr) = (dot(&q, &q).sqrt(), dot(&self.random, &self.random).sqrt());
            scale(&mut q, 1.0 / nq);
            axpy(&mut q, 0.5 / nr, &self.random);
        }
        let nq = dot(&q, &q).sqrt();
        scale(&mut q, 1.0 / nq);
        let mut basis: Vec<Vec<[f32; 3]>> = Vec::new();
        let mut prev = vec![[0.0; 3]; n];
        let (mut alpha, mut beta) = (Vec::new(), Vec::<f64>::new());
        let (mut estimate, mut top) = (0.0, Vec::new());
        for j in 0..MAX_ITERATIONS {
            let mut r = apply(ops, w, &q, &self.adj_start, &self.adj);
            let b_prev = beta.last().copied().unwrap_or(0.0);
            axpy(&mut r, -b_prev, &prev);
            let a = dot(&q, &r);
            axpy(&mut r, -a, &q);
            alpha.push(a);
            let b = dot(&r, &r).sqrt();
            let (theta, s) = top_ritz(&alpha, &beta);
            beta.push(b);
            let bound = b * s[j].abs();
            estimate = theta + bound;
            top = s;
            basis.push(q.iter().map(|x| x.map(|c| c as f32)).collect());
            let converged = j + 1 >= MIN_ITERATIONS && bound <= TOLERANCE * theta;
            if converged || !(b > 0.0) {
                break;
            }
            scale(&mut r, 1.0 / b);
            prev = std::mem::replace(&mut q, r);
        }
        let mut v = vec![[0.0; 3]; n];
        for (s, b) in top.iter().zip(&basis) {
            v.par_iter_mut()
                .with_min_len(CHUNK)
                .zip(b.par_iter())
                .for_each(|(v, b)| {
                    for k in 0..3 {
                        v[k] += s * b[k] as f64;
                    }
                });
        }
        self.vector = v;
        (estimate, alpha.len())
    }
}

/// Every chunk's element minimum (s; before each group's `dt_kappa`, which cancels in ratios),
/// groups and chunks in order.
fn chunk_minima(model: &Model) -> impl Iterator<Item = f64> + '_ {
    model
        .groups
        .iter()
        .flat_map(|g| g.chunks.iter().map(|c| c.totals.dt_min))
}

/// `y += a x`.
fn axpy(y: &mut [[f64; 3]], a: f64, x: &[[f64; 3]]) {
    y.par_iter_mut()
        .with_min_len(CHUNK)
        .zip(x.par_iter())
        .for_each(|(y, x)| *y = [y[0] + a * x[0], y[1] + a * x[1], y[2] + a * x[2]]);
}

/// `x *= a`.
fn scale(x: &mut [[f64; 3]], a: f64) {
    x.par_iter_mut()
        .with_min_len(CHUNK)
        .for_each(|x| *x = [x[0] * a, x[1] * a, x[2] * a]);
}

/// `x . y`, summed per fixed chunk and then in chunk order (the same bits on any thread count).
fn dot(x: &[[f64; 3]], y: &[[f64; 3]]) -> f64 {
    let parts: Vec<f64> = x
        .par_chunks(CHUNK)
        .zip(y.par_chunks(CHUNK))
        .map(|(a, b)| {
            a.iter()
                .zip(b)
                .map(|(a, b)| a[0] * b[0] + a[1] * b[1] + a[2] * b[2])
                .sum::<f64>()
        })
        .collect();
    parts.iter().sum()
}

/// The largest eigenvalue of the symmetric tridiagonal matrix with diagonal `a` and
/// off-diagonal `b`, and its unit eigenvector.
fn top_ritz(a: &[f64], b: &[f64]) -> (f64, Vec<f64>) {
    let k = a.len();
    let t = nalgebra::DMatrix::from_fn(k, k, |i, j| {
        if i == j {
            a[i]
        } else if i + 1 == j {
            b[i]
        } else if j + 1 == i {
            b[j]
        } else {
            0.0
        }
    });
    let e = t.symmetric_eigen();
    let (imax, theta) =
        e.eigenvalues
            .iter()
            .enumerate()
            .fold(
                (0, f64::NEG_INFINITY),
                |acc, (i, &l)| if l > acc.1 { (i, l) } else { acc },
            );
    (theta, e.eigenvectors.column(imax).iter().copied().collect())
}

/// `y = W K W x` with `W = M^-1/2` (per node `w`): the element stresses of `W x`, then per node
/// the sum over its elements, times `w`.
fn apply(
    ops: &[OpElement],
    w: &[f64],
    x: &[[f64; 3]],
    adj_start: &[u32],
    adj: &[(u32, u8)],
) -> Vec<[f64; 3]> {
    // each element's stress times its volume (symmetric, xx yy zz xy yz zx)
    let stress: Vec<[f64; 6]> = ops
        .par_iter()
        .with_min_len(CHUNK)
        .map(|op| {
            let mut h = [[0.0; 3]; 3];
            for a in 0..8 {
                let n = op.conn[a] as usize;
                let v = x[n];
                for (i, hi) in h.iter_mut().enumerate() {
                    for (j, hij) in hi.iter_mut().enumerate() {
                        *hij += w[n] * v[i] * op.grad[j][a];
                    }
                }
            }
            let (l, m, vol) = (op.lambda, op.mu, op.volume);
            let p = l * (h[0][0] + h[1][1] + h[2][2]);
            [
                vol * (p + 2.0 * m * h[0][0]),
                vol * (p + 2.0 * m * h[1][1]),
                vol * (p + 2.0 * m * h[2][2]),
                vol * m * (h[0][1] + h[1][0]),
                vol * m * (h[1][2] + h[2][1]),
                vol * m * (h[2][0] + h[0][2]),
            ]
        })
        .collect();
    let mut y = vec![[0.0; 3]; x.len()];
    y.par_iter_mut()
        .with_min_len(CHUNK)
        .enumerate()
        .for_each(|(n, f)| {
            for &(e, la) in &adj[adj_start[n] as usize..adj_start[n + 1] as usize] {
                let s = &stress[e as usize];
                let g = &ops[e as usize].grad;
                let b = [g[0][la as usize], g[1][la as usize], g[2][la as usize]];
                f[0] += s[0] * b[0] + s[3] * b[1] + s[5] * b[2];
                f[1] += s[3] * b[0] + s[1] * b[1] + s[4] * b[2];
                f[2] += s[5] * b[0] + s[4] * b[1] + s[2] * b[2];
            }
            *f = [f[0] * w[n], f[1] * w[n], f[2] * w[n]];
        });
    y
}

/// The operator's elements at displacements `u`, and each element's estimate `L / c` with
/// its density scale, before the part's `kappa` (s; infinite for an element left out). An
/// element whose centre Jacobian is not positive adds no stiffness (the element loop stops
/// such a run).
fn operator(model: &Model, u: &[[f64; 3]]) -> (Vec<OpElement>, Vec<f64>) {
    let mesh = &model.mesh;
    let consts: Vec<(f64, f64, f64)> = model
        .parts
        .iter()
        .map(|p| {
            let law = &p.material;
            let c0 = law.initial_wave_speed();
            let m = law.density() * c0 * c0;
            let mu = law.initial_shear_modulus().max(0.0);
            (c0, (m - 2.0 * mu).max(0.0), mu)
        })
        .collect();
    let none = |conn: &[u32; 8]| {
        let op = OpElement {
            conn: *conn,
            volume: 0.0,
            grad: [[0.0; 8]; 3],
            lambda: 0.0,
            mu: 0.0,
        };
        (op, f64::INFINITY)
    };
    // mass scaling's density scale and erosion, per element
    let mut scale = vec![1.0; mesh.elements.len()];
    for g in &model.groups {
        for (le, &e) in g.elements.iter().enumerate() {
            scale[e as usize] = match g.eroded.get(le) {
                Some(true) => 0.0,
                _ => g.density_scale.get(le).copied().unwrap_or(1.0),
            };
        }
    }
    let per: Vec<(OpElement, f64)> = mesh
        .elements
        .par_iter()
        .with_min_len(CHUNK)
        .zip(mesh.element_part.par_iter())
        .zip(scale.par_iter())
        .map(|((conn, &part), &scale)| {
            let (c0, lambda, mu) = consts[part as usize];
            if scale == 0.0 {
                return none(conn);
            }
            let x: [[f64; 3]; 8] = std::array::from_fn(|a| {
                let (p, d) = (mesh.nodes[conn[a] as usize], u[conn[a] as usize]);
                [p[0] + d[0], p[1] + d[1], p[2] + d[2]]
            });
            let j = crate::hex::jacobian(&x, [0.0; 3]);
            let det = j.determinant();
            let Some(jinv) = j.try_inverse().filter(|_| det > 0.0) else {
                return none(conn);
            };
            let jit = jinv.transpose();
            let d = crate::hex::dn_dxi([0.0; 3]);
            let mut grad = [[0.0; 8]; 3];
            for a in 0..8 {
                let g = jit * nalgebra::Vector3::new(d[a][0], d[a][1], d[a][2]);
                for i in 0..3 {
                    grad[i][a] = g[i];
                }
            }
            // the exact volume (det J is of degree 2 in each coordinate: 2x2x2 Gauss is exact)
            let volume: f64 = crate::hex::gauss_points()
                .iter()
                .map(|p| crate::hex::jacobian(&x, *p).determinant())
                .sum();
            let dt = crate::model::initial_element_dt(&x, volume, c0) * scale.sqrt();
            let op = OpElement {
                conn: *conn,
                volume,
                grad,
                lambda,
                mu,
            };
            (op, dt)
        })
        .collect();
    per.into_iter().unzip()
}
