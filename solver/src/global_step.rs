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
//! The one-point element's linear stiffness at the current state, as the element loop forms
//! it: per element `K_e = V B^T D B` with `B = F^-T b0` the reference mean gradients pushed
//! forward by the element's mean deformation gradient, `V = J V0`, and `D` isotropic; `M` the
//! lumped nodal masses after mass scaling. (The centre gradients of the current shape are not
//! the element loop's: on a crushed, hourglassed element they are far softer, and a run on
//! them went unstable: the 5 mm palpation without mass scaling at 22 ms.) `D` holds the part's initial
//! moduli times `phi = (c / c0)^2`, with `c = L sqrt(s) / dt_e` the wave speed that the element
//! loop's own step `dt_e` for that element implies (`L = V / A_max`, `s` its density scale):
//! the operator's element-by-element estimate is then exactly the element loop's, with the
//! current tangent stiffness of the law (a crushed rubber element stiffens) and the bulk
//! viscosity counted in as stiffness, which errs safe. Eroded elements are left out.
//! Constraints are left out too: they can only lower `omega_max` (Cauchy interlacing). The
//! hourglass forms add no stiffness here: the viscous form (the default) has none; the
//! stiffness form adds about `Q_hg / 8` of the P-wave stiffness (`Q_hg` = 0.1) to modes the
//! mean strain does not see, and the physical form stiffness of the order of the shear
//! modulus, both far below the dilatational modes. Fully integrated elements without F-bar
//! are refused (their volumetric locking stiffens modes the operator does not hold); F-bar
//! elements take the one-point operator, which holds their volumetric part exactly and leaves
//! out deviatoric stiffness of the order of the shear modulus: the estimate is meant for
//! nearly incompressible tissue, and for a compressible solid it gains little anyway.
//!
//! ## The iteration
//! Lanczos on `A = M^-1/2 K M^-1/2` (symmetric), without reorthogonalisation (lost orthogonality
//! only repeats converged Ritz values; the largest one stays right). It stops when the largest
//! Ritz value `theta` has `beta_k |s_k| <= TOLERANCE theta` after at least [`MIN_ITERATIONS`],
//! and the estimate is `theta` plus that bound. Some eigenvalue lies within the bound of
//! `theta`, not necessarily the largest: the start decides whether the largest is found. The
//! first estimate starts from a fixed pseudo-random vector; later ones from the last top Ritz
//! vector plus the random vector at half its length, plus the dilatation of the element whose
//! step fell most since (where a new fastest mode would be) at unit length. Every sum runs in fixed chunks in a fixed order: the same bits on any
//! thread count.
//!
//! ## The step
//! `dt = f G s(t)`, with `G = 2 / sqrt(lambda)` from the last estimate and `s(t)` the smallest
//! ratio, at most 1, of an element's step in this step's element loop to its step at the last
//! estimate (`Group::dt_reference`, compared element by element in the loop,
//! `ChunkOut::rise`). An element's stiffness over its mass goes as `1 / dt_e^2`; were every
//! element's `K_e` at most `1 / s^2` times its value at the estimate, the Rayleigh quotient
//! would bound the mesh's `lambda` by `lambda_0 / s^2` (the shapes change too, so this is the
//! scaling rather than a bound). An element crushed between two estimates, or stiffening,
//! therefore lowers the step at once.
//! The estimate is renewed every `interval` steps, and early when `s` falls below
//! `1 - RENEW_FALL` (at most every [`MIN_SPACING`] steps); the loop before an estimate records
//! every element's step (`Group::record_dt`). The step never goes below the element estimate
//! `f min_e dt_e`.
use crate::element::{max_face_area, Nodal};
use crate::model::Model;
use rayon::prelude::*;

/// Relative residual bound of the largest Ritz value that ends an estimate (the step to half
/// that).
pub const TOLERANCE: f64 = 2e-3;
/// Fewest iterations of one estimate.
pub const MIN_ITERATIONS: usize = 10;
/// Most iterations of one estimate.
pub const MAX_ITERATIONS: usize = 150;
/// A fall of some element's step, relative to the last estimate, that renews the estimate
/// before its interval is out: more than the bulk viscosity's coming and going (its linear term
/// alone takes 6 % off an element's step whenever the element is compressed), so that renewals
/// answer crushing only.
pub const RENEW_FALL: f64 = 0.3;
/// Default interval between two estimates (steps).
pub const DEFAULT_INTERVAL: u64 = 500;
/// Fewest steps between two estimates that a fall renews early. Safety does not depend on
/// renewals (`s` lowers the step at once); a renewal only gives back a step that a crushed but
/// well-surrounded element took away.
pub const MIN_SPACING: u64 = 100;
/// Bytes per node and Lanczos iteration of the kept basis (`f32` x 3).
pub const BASIS_BYTES_PER_NODE: usize = 3 * std::mem::size_of::<f32>();
/// Elements or nodes per parallel work item (a fixed size, so the sums do not depend on the
/// threads).
const CHUNK: usize = 1024;

/// One element of the operator: nodes, volume (m^3), gradients `F^-T b0` (1/m), moduli (Pa).
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
    /// Smallest and largest ratio of the mesh's critical step to the element loop's smallest
    /// element estimate at the same step (`kappa dt_e`, with the law's current wave speed,
    /// density scale and bulk viscosity).
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
    /// Step of the last estimate.
    last_step: u64,
    /// `s` of the last element loop ([`GlobalStep::fall`]).
    pub fall: f64,
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
            last_step: 0,
            fall: 1.0,
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

    /// `s(t)` of the element loop that has just run: the smallest ratio of an element's step
    /// now to its step at the last estimate, at most 1 (1 before the first estimate).
    pub fn fall(model: &Model) -> f64 {
        largest_rise(model).map_or(1.0, |(rise, _)| 1.0 / rise)
    }

    /// Whether the next element loop should record the elements' steps for an estimate at
    /// `step`, the last loop's fall being `s`: the first estimate, the interval out, or `s`
    /// below `1 - RENEW_FALL` with [`MIN_SPACING`] steps passed.
    pub fn due(&self, step: u64, s: f64) -> bool {
        self.report.estimates == 0
            || step >= self.last_step + self.interval
            || (s < 1.0 - RENEW_FALL && step >= self.last_step + MIN_SPACING)
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

    /// Estimate at displacements `u` and the model's masses, from the element loop that has just
    /// run with every group's `record_dt` set: its steps become the groups' `dt_reference`.
    pub fn estimate(&mut self, model: &mut Model, u: &[[f64; 3]], step: u64) {
        let t0 = std::time::Instant::now();
        let mut dts = vec![f64::INFINITY; model.mesh.elements.len()];
        let mut element = f64::INFINITY;
        // the element whose step fell most since the last estimate (its neighbourhood is where
        // a new fastest mode would be)
        let hot = largest_rise(model);
        for g in model.groups.iter_mut() {
            g.record_dt = false;
            g.dt_reference.clear();
            for ch in &mut g.chunks {
                g.dt_reference.append(&mut ch.dts);
            }
            assert_eq!(
                g.dt_reference.len(),
                g.elements.len(),
                "one step per element"
            );
            for (&e, &dt) in g.elements.iter().zip(&g.dt_reference) {
                dts[e as usize] = dt;
                element = element.min(g.dt_kappa * dt);
            }
        }
        let ops = operator(model, u, &dts);
        let w: Vec<f64> = model.mass.iter().map(|m| 1.0 / m.sqrt()).collect();
        let hot = hot.map(|(_, e)| &ops[e as usize]);
        let (lambda, it) = self.lanczos(&ops, &w, hot);
        // a breakdown (no stiffness at all, or a non-finite one) leaves the element estimate
        self.global = if lambda.is_finite() && lambda > 0.0 {
            2.0 / lambda.sqrt()
        } else {
            0.0
        };
        self.last_step = step;
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
    fn lanczos(&mut self, ops: &[OpElement], w: &[f64], hot: Option<&OpElement>) -> (f64, usize) {
        let n = self.vector.len();
        let mut q = std::mem::take(&mut self.vector);
        if self.report.estimates > 0 {
            // the last top Ritz vector (unit length) plus the fixed random vector at half that
            // length
            let (nq, nr) = (dot(&q, &q).sqrt(), dot(&self.random, &self.random).sqrt());
            scale(&mut q, 1.0 / nq);
            axpy(&mut q, 0.5 / nr, &self.random);
        }
        if let Some(op) = hot {
            // plus, at unit length, the dilatation of the element whose step fell most: a
            // start with only a spread-out part on its mode could stop on the old fastest one
            let mut h = vec![[0.0; 3]; n];
            for a in 0..8 {
                let m = op.conn[a] as usize;
                for i in 0..3 {
                    h[m][i] += op.grad[i][a] / w[m];
                }
            }
            let nh = dot(&h, &h).sqrt();
            if nh > 0.0 && nh.is_finite() {
                let nq = dot(&q, &q).sqrt();
                scale(&mut q, 1.0 / nq);
                axpy(&mut q, 1.0 / nh, &h);
            }
        }
        let nq = dot(&q, &q).sqrt();
        scale(&mut q, 1.0 / nq);
        // BASIS_BYTES_PER_NODE per node and iteration
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

/// The largest fall of an element's step since the last estimate in the element loop that has
/// just run, as the ratio then / now (above 1), and its element; groups and chunks in order.
fn largest_rise(model: &Model) -> Option<(f64, u32)> {
    let mut hot: Option<(f64, u32)> = None;
    for ch in model.groups.iter().flat_map(|g| g.chunks.iter()) {
        if ch.rise > 1.0 && hot.is_none_or(|(r, _)| ch.rise > r) {
            hot = Some((ch.rise, ch.rise_elem));
        }
    }
    hot
}

/// The operator's elements at displacements `u`, with `dts` each element's step from the
/// element loop of this state (global id; before `kappa`, with its density scale, current wave
/// speed and bulk viscosity; infinite for an eroded or faulted element, which adds no
/// stiffness). The gradients are the element loop's own: the reference mean gradients `b0`
/// pushed forward by the element's mean deformation gradient, `b = F^-T b0`, on the volume
/// `V = J V0` (a crushed element's centre gradients can differ from them several times over).
/// Each element's moduli are its part's initial ones times `phi = (c / c0)^2`, the wave speed
/// `c = L sqrt(s) / dt` its step implies (`L = V / A_max`, `s` its density scale), so that the
/// operator's own element-by-element estimate is the element loop's.
fn operator(model: &Model, u: &[[f64; 3]], dts: &[f64]) -> Vec<OpElement> {
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
    let mut ops = vec![
        OpElement {
            conn: [0; 8],
            volume: 0.0,
            grad: [[0.0; 8]; 3],
            lambda: 0.0,
            mu: 0.0,
        };
        mesh.elements.len()
    ];
    for g in &model.groups {
        let (c0, lambda, mu) = consts[g.part];
        let built: Vec<OpElement> = (0..g.elements.len())
            .into_par_iter()
            .with_min_len(CHUNK)
            .map(|le| {
                let e = g.elements[le] as usize;
                let conn = g.conn[le];
                let mut op = OpElement {
                    conn,
                    volume: 0.0,
                    grad: [[0.0; 8]; 3],
                    lambda: 0.0,
                    mu: 0.0,
                };
                let dt = dts[e];
                if !(dt.is_finite() && dt > 0.0) {
                    return op;
                }
                let (bi, q) = (le / material::real::LANES, le % material::real::LANES);
                let b0: Nodal = std::array::from_fn(|i| {
                    std::array::from_fn(|a| g.grad[bi][i][a].to_array()[q])
                });
                // F summed node by node from the identity (`element::deformation_gradient`
                // sums in another order; its last digits would move the estimate and the run)
                let mut f = nalgebra::Matrix3::<f64>::identity();
                let mut x: Nodal = [[0.0; 8]; 3];
                for a in 0..8 {
                    let n = conn[a] as usize;
                    for i in 0..3 {
                        x[i][a] = mesh.nodes[n][i] + u[n][i];
                        for k in 0..3 {
                            f[(i, k)] += u[n][i] * b0[k][a];
                        }
                    }
                }
                let j = f.determinant();
                let Some(finv) = f.try_inverse().filter(|_| j > 0.0) else {
                    return op;
                };
                for a in 0..8 {
                    for i in 0..3 {
                        op.grad[i][a] = (0..3).map(|k| finv[(k, i)] * b0[k][a]).sum();
                    }
                }
                let s = g.density_scale.get(le).copied().unwrap_or(1.0);
                op.volume = j * g.vol0[le];
                let initial = op.volume / max_face_area(&x) / c0 * s.sqrt();
                let phi = (initial / dt).powi(2);
                op.lambda = phi * lambda;
                op.mu = phi * mu;
                op
            })
            .collect();
        for (le, op) in built.into_iter().enumerate() {
            ops[g.elements[le] as usize] = op;
        }
    }
    ops
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
