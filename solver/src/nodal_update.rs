//! The central-difference nodal update (Belytschko, Liu, Moran, Box 6.1) and the sums the
//! energy balance needs, over one chunk of nodes:
//!
//!   f_net = f_ext - f_int - f_damp,   f_damp = alpha m v^(n-1/2)
//!   v^(n+1/2) = v^(n-1/2) + dt_avg f_net / m     (or the velocity a kinematic condition imposes)
//!   u^(n+1) = u^n + dt v^(n+1/2)
//!
//! with the works over the half steps before and after t^n (trapezoidal rule), the kinetic
//! energy at t^n, the residual norms and, for dynamic relaxation, `u.f_int` and `u.M.u`.
//!
//! Degrees of freedom are taken in lanes of eight (a chunk's displacements, velocities and
//! forces as flat arrays, `3 n + d`); each sum is kept per lane, lane `j mod 8` for degree of
//! freedom `j` of the chunk, and the lanes are added in lane order at the chunk's end. The
//! chunk size is fixed, so the sums are the same on any thread count. Every lane group runs in
//! [`F64x8`] arithmetic; in a group with a kinematic condition only the imposed velocities are
//! set lane by lane. Velocities, displacements and reactions come from the same IEEE
//! operations, in the same order, as the update one degree of freedom at a time that this
//! replaced, so for given forces the motion is bitwise that update's; the sums' last digits
//! moved (they are added in another order). The one exception is dynamic relaxation: its
//! damping coefficient (Underwood's, from `u.f_int` and `u.M.u`) and its stop test (the
//! residual) come from the sums, so a relaxation run agrees with the old update to round-off
//! only, and may stop a step earlier or later.
//!
//! A chunk of nodes without any kinematic condition (most chunks of a palpation) reads no
//! degree-of-freedom codes and writes no reactions (zero on free degrees of freedom from the
//! start). Measured against the update one degree of freedom at a time in
//! docs/performance.md ("The nodal update in lanes").

use crate::bc::{Kinematic, Prescribed};
use material::real::{F64x8, Real, LANES};

/// Nodes per chunk of the parallel update (fixed, so sums are thread-count independent).
pub(crate) const NODE_CHUNK: usize = 2048;

/// Per chunk of [`NODE_CHUNK`] nodes: whether any of its degrees of freedom (codes `dof_code`,
/// 0 free) has a kinematic condition.
pub(crate) fn constrained_chunks(dof_code: &[u32]) -> Vec<bool> {
    dof_code
        .chunks(3 * NODE_CHUNK)
        .map(|c| c.iter().any(|&k| k != 0))
        .collect()
}

/// The scalars of one nodal update: the steps around t^n and the damping.
#[derive(Clone, Copy, Debug)]
pub(crate) struct StepParams {
    /// The step dt^(n+1/2) about to be taken (s).
    pub dt: f64,
    /// The step dt^(n-1/2) taken last (s).
    pub dt_old: f64,
    /// Their mean, the step of the velocity update (s).
    pub dt_avg: f64,
    /// Mass-proportional damping coefficient (1/s).
    pub alpha: f64,
    /// Whether the damping force is applied.
    pub damping: bool,
    /// Dynamic relaxation: also sum `u.f_int` and `u.M.u`.
    pub relax: bool,
}

/// The sums of the nodal update over one chunk of nodes or all of them: the work of the
/// internal, external (loads, gravity, contact and constraint reactions) and damping forces
/// over the half steps before and after t^n, the kinetic energies, and the norms of the
/// residual and of the dynamic relaxation. As [`StepSums<f64>`] a chunk's (or the step's)
/// totals; as [`StepSums<F64x8>`] a chunk's sums lane by lane.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct StepSums<T = f64> {
    /// `f_int . dt_old/2 v^(n-1/2)`.
    pub w_int_old: T,
    /// `f_int . dt/2 v^(n+1/2)`.
    pub w_int_new: T,
    /// `(f_ext + R) . dt_old/2 v^(n-1/2)`.
    pub w_ext_old: T,
    /// `(f_ext + R) . dt/2 v^(n+1/2)`.
    pub w_ext_new: T,
    /// `f_damp . dt_old/2 v^(n-1/2)`.
    pub w_damp_old: T,
    /// `f_damp . dt/2 v^(n+1/2)`.
    pub w_damp_new: T,
    /// Kinetic energy at t^n, of `v^n = (v^(n-1/2) + v^(n+1/2)) / 2`.
    pub kinetic: T,
    /// `|f_ext - f_int - f_damp|^2` over the free degrees of freedom.
    pub residual2: T,
    /// `|f_int|^2`.
    pub f_int2: T,
    /// `u . f_int` (dynamic relaxation only).
    pub u_f_int: T,
    /// `u . M u` (dynamic relaxation only).
    pub u_m_u: T,
}

impl StepSums {
    /// Add the sums of another chunk.
    pub fn add(&mut self, o: &StepSums) {
        self.w_int_old += o.w_int_old;
        self.w_int_new += o.w_int_new;
        self.w_ext_old += o.w_ext_old;
        self.w_ext_new += o.w_ext_new;
        self.w_damp_old += o.w_damp_old;
        self.w_damp_new += o.w_damp_new;
        self.kinetic += o.kinetic;
        self.residual2 += o.residual2;
        self.f_int2 += o.f_int2;
        self.u_f_int += o.u_f_int;
        self.u_m_u += o.u_m_u;
    }
}

impl StepSums<F64x8> {
    /// All lanes zero.
    fn zero() -> Self {
        let z = F64x8::zero();
        StepSums {
            w_int_old: z,
            w_int_new: z,
            w_ext_old: z,
            w_ext_new: z,
            w_damp_old: z,
            w_damp_new: z,
            kinetic: z,
            residual2: z,
            f_int2: z,
            u_f_int: z,
            u_m_u: z,
        }
    }

    /// The lanes added in lane order.
    fn total(&self) -> StepSums {
        let sum = |x: F64x8| x.to_array().iter().fold(0.0, |s, &v| s + v);
        StepSums {
            w_int_old: sum(self.w_int_old),
            w_int_new: sum(self.w_int_new),
            w_ext_old: sum(self.w_ext_old),
            w_ext_new: sum(self.w_ext_new),
            w_damp_old: sum(self.w_damp_old),
            w_damp_new: sum(self.w_damp_new),
            kinetic: sum(self.kinetic),
            residual2: sum(self.residual2),
            f_int2: sum(self.f_int2),
            u_f_int: sum(self.u_f_int),
            u_m_u: sum(self.u_m_u),
        }
    }
}

/// What the nodal update reads, shared by its parallel chunks.
pub(crate) struct NodalUpdate<'a> {
    pub p: StepParams,
    pub mass: &'a [f64],
    pub f_int: &'a [[f64; 3]],
    pub f_ext: &'a [[f64; 3]],
    /// Per degree of freedom: 0 free, 1 fixed, k + 2 the k-th prescription.
    pub dof_code: &'a [u32],
    /// Per chunk: whether any of its degrees of freedom has a kinematic condition.
    pub constrained: &'a [bool],
    pub prescribed: &'a [Prescribed],
    /// Each prescription's target this step (see `Simulation::kinematic_targets`).
    pub targets: &'a [f64],
}

/// One lane group of degrees of freedom: `LANES` values of each nodal field.
struct Dofs {
    m: F64x8,
    fi: F64x8,
    fe: F64x8,
}

impl NodalUpdate<'_> {
    /// Update the nodes of chunk `ci` (their displacements `uc`, velocities `vc` and reactions
    /// `rc`) and return the chunk's sums.
    pub fn chunk(
        &self,
        ci: usize,
        uc: &mut [[f64; 3]],
        vc: &mut [[f64; 3]],
        rc: &mut [[f64; 3]],
    ) -> StepSums {
        match (self.p.damping, self.p.relax) {
            (false, false) => self.chunk_in::<false, false>(ci, uc, vc, rc),
            (true, false) => self.chunk_in::<true, false>(ci, uc, vc, rc),
            (false, true) => self.chunk_in::<false, true>(ci, uc, vc, rc),
            (true, true) => self.chunk_in::<true, true>(ci, uc, vc, rc),
        }
    }

    /// [`Self::chunk`] with the damping force (`DAMP`) and the relaxation sums (`RELAX`)
    /// decided at compile time. (Read at run time, with `free` and `mixed` folded into one
    /// function, the update of the 5 mm palpation took 1.89-2.16 s against 1.66-1.75 s, in
    /// alternating runs: the constrained path stays out of line in [`Self::mixed`].)
    fn chunk_in<const DAMP: bool, const RELAX: bool>(
        &self,
        ci: usize,
        uc: &mut [[f64; 3]],
        vc: &mut [[f64; 3]],
        rc: &mut [[f64; 3]],
    ) -> StepSums {
        let n0 = ci * NODE_CHUNK;
        let nn = uc.len();
        let u = uc.as_flattened_mut();
        let v = vc.as_flattened_mut();
        let r = rc.as_flattened_mut();
        let fi = self.f_int[n0..n0 + nn].as_flattened();
        let fe = self.f_ext[n0..n0 + nn].as_flattened();
        let mass = &self.mass[n0..n0 + nn];
        let codes = &self.dof_code[3 * n0..3 * (n0 + nn)];
        let constrained = self.constrained[ci];
        let mut s = StepSums::<F64x8>::zero();
        // Blocks of eight nodes: 24 degrees of freedom, three lane groups.
        const B: usize = 3 * LANES;
        let blocks = nn / LANES;
        for b in 0..blocks {
            let j = B * b..B * (b + 1);
            let block = Block {
                mass: &mass[LANES * b..LANES * (b + 1)],
                fi: &fi[j.clone()],
                fe: &fe[j.clone()],
                codes: constrained.then(|| &codes[j.clone()]),
            };
            let (u, v, r) = (&mut u[j.clone()], &mut v[j.clone()], &mut r[j]);
            self.block::<DAMP, RELAX>(&block, u, v, r, &mut s);
        }
        // The last chunk's last nodes (fewer than eight): a block padded with unit masses and
        // zero forces and motion, which add nothing to the sums.
        let rest = nn - LANES * blocks;
        if rest > 0 {
            let j0 = B * blocks;
            let k = 3 * rest;
            let pad =
                |x: &[f64], fill: f64| material::arr![B, |i| if i < k { x[j0 + i] } else { fill }];
            let (mut ub, mut vb, mut rb) = (pad(u, 0.0), pad(v, 0.0), pad(r, 0.0));
            let (fib, feb) = (pad(fi, 0.0), pad(fe, 0.0));
            let mb = material::arr![LANES, |n| if n < rest {
                mass[LANES * blocks + n]
            } else {
                1.0
            }];
            let cb = material::arr![B, |i| if constrained && i < k {
                codes[j0 + i]
            } else {
                0
            }];
            let block = Block {
                mass: &mb,
                fi: &fib,
                fe: &feb,
                codes: constrained.then_some(&cb[..]),
            };
            self.block::<DAMP, RELAX>(&block, &mut ub, &mut vb, &mut rb, &mut s);
            u[j0..].copy_from_slice(&ub[..k]);
            v[j0..].copy_from_slice(&vb[..k]);
            if constrained {
                r[j0..].copy_from_slice(&rb[..k]);
            }
        }
        s.total()
    }

    /// Eight nodes (24 degrees of freedom, three lane groups): their update and sums.
    #[inline(always)]
    fn block<const DAMP: bool, const RELAX: bool>(
        &self,
        b: &Block,
        u: &mut [f64],
        v: &mut [f64],
        r: &mut [f64],
        s: &mut StepSums<F64x8>,
    ) {
        for q in 0..3 {
            let j = LANES * q;
            let d = Dofs {
                m: F64x8::new(material::arr![LANES, |l| b.mass[(j + l) / 3]]),
                fi: F64x8::from_slice(&b.fi[j..]),
                fe: F64x8::from_slice(&b.fe[j..]),
            };
            let mut uj = F64x8::from_slice(&u[j..]);
            let mut vj = F64x8::from_slice(&v[j..]);
            let codes = b
                .codes
                .map(|c| &c[j..j + LANES])
                .filter(|c| c.iter().any(|&k| k != 0));
            match codes {
                None => self.free::<DAMP, RELAX>(&d, &mut uj, &mut vj, s),
                Some(c) => {
                    let rj = self.mixed::<DAMP, RELAX>(&d, c, &mut uj, &mut vj, s);
                    rj.write_to(&mut r[j..]);
                }
            }
            uj.write_to(&mut u[j..]);
            vj.write_to(&mut v[j..]);
        }
    }

    /// A lane group of free degrees of freedom: the velocity from the net force, the
    /// displacement, and the sums into `s`. With `DAMP` false the damping force is zero; with
    /// `RELAX` false the relaxation sums are not formed.
    #[inline(always)]
    fn free<const DAMP: bool, const RELAX: bool>(
        &self,
        d: &Dofs,
        u: &mut F64x8,
        v: &mut F64x8,
        s: &mut StepSums<F64x8>,
    ) {
        let v_old = *v;
        let (fd, fnet) = self.net_force::<DAMP>(d, v_old);
        let v_new = v_old + F64x8::splat(self.p.dt_avg) * fnet / d.m;
        s.residual2 += fnet * fnet;
        sums::<RELAX>(&self.p, d, fd, d.fe, *u, v_old, v_new, s);
        *v = v_new;
        *u += F64x8::splat(self.p.dt) * v_new;
    }

    /// A lane group with kinematic conditions (`codes`, 0 on a free lane): free lanes as in
    /// [`Self::free`], constrained lanes take the imposed velocity; returns the conditions'
    /// reactions (zero on the free lanes), which count as external force in the works.
    #[inline(never)]
    fn mixed<const DAMP: bool, const RELAX: bool>(
        &self,
        d: &Dofs,
        codes: &[u32],
        u: &mut F64x8,
        v: &mut F64x8,
        s: &mut StepSums<F64x8>,
    ) -> F64x8 {
        let p = &self.p;
        let v_old = *v;
        let (fd, fnet) = self.net_force::<DAMP>(d, v_old);
        let mut v_new = v_old + F64x8::splat(p.dt_avg) * fnet / d.m;
        let free = F64x8::new(material::arr![LANES, |l| if codes[l] == 0 {
            1.0
        } else {
            0.0
        }]);
        let is_free = free.ne(F64x8::zero());
        for (l, &c) in codes.iter().enumerate() {
            if c != 0 {
                v_new.set_lane(l, self.imposed_velocity(c, u.lane(l)));
            }
        }
        let react = d.m * (v_new - v_old) / F64x8::splat(p.dt_avg) - fnet;
        let r = F64x8::select(is_free, F64x8::zero(), react);
        let fe_r = F64x8::select(is_free, d.fe, d.fe + r);
        let res = F64x8::select(is_free, fnet * fnet, F64x8::zero());
        s.residual2 += res;
        sums::<RELAX>(p, d, fd, fe_r, *u, v_old, v_new, s);
        *v = v_new;
        *u += F64x8::splat(p.dt) * v_new;
        r
    }

    /// The damping force (zero without `DAMP`) and the net force `f_ext - f_int - f_damp`.
    #[inline(always)]
    fn net_force<const DAMP: bool>(&self, d: &Dofs, v_old: F64x8) -> (F64x8, F64x8) {
        let fd = if DAMP {
            F64x8::splat(self.p.alpha) * d.m * v_old
        } else {
            F64x8::zero()
        };
        (fd, d.fe - d.fi - fd)
    }

    /// The velocity v^(n+1/2) the kinematic condition `code` (1 fixed, k + 2 the k-th
    /// prescription) imposes on a degree of freedom at displacement `u`: zero, the prescribed
    /// velocity, or the velocity that lands on the prescribed displacement.
    #[inline]
    fn imposed_velocity(&self, code: u32, u: f64) -> f64 {
        match code {
            1 => 0.0,
            c => {
                let tgt = self.targets[(c - 2) as usize];
                match self.prescribed[(c - 2) as usize].kind {
                    Kinematic::Displacement(_) => (tgt - u) / self.p.dt,
                    _ => tgt,
                }
            }
        }
    }
}

/// Eight nodes' masses and 24 degrees of freedom's forces and codes (`None`: all free).
struct Block<'a> {
    mass: &'a [f64],
    fi: &'a [f64],
    fe: &'a [f64],
    codes: Option<&'a [u32]>,
}

/// The sums every degree of freedom adds (all but the residual): the works of the internal,
/// external (`fe_r`, with the reaction) and damping (`fd`) forces over both half steps, the
/// internal force norm, the kinetic energy at t^n and (with `RELAX`) the relaxation sums.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn sums<const RELAX: bool>(
    p: &StepParams,
    d: &Dofs,
    fd: F64x8,
    fe_r: F64x8,
    u: F64x8,
    v_old: F64x8,
    v_new: F64x8,
    s: &mut StepSums<F64x8>,
) {
    let fi = d.fi;
    s.f_int2 += fi * fi;
    if RELAX {
        s.u_f_int += u * fi;
        s.u_m_u += d.m * u * u;
    }
    let half = F64x8::splat(0.5);
    let h_old = F64x8::splat(0.5 * p.dt_old) * v_old;
    let h_new = F64x8::splat(0.5 * p.dt) * v_new;
    s.w_int_old += fi * h_old;
    s.w_int_new += fi * h_new;
    s.w_ext_old += fe_r * h_old;
    s.w_ext_new += fe_r * h_new;
    s.w_damp_old += fd * h_old;
    s.w_damp_new += fd * h_new;
    let vn = half * (v_old + v_new);
    s.kinetic += half * d.m * vn * vn;
}

#[cfg(test)]
mod tests {
    use super::*;
    use contact::Curve;

    /// A pseudo-random value in [-1, 1) (xorshift).
    fn rnd(s: &mut u64) -> f64 {
        *s ^= *s << 13;
        *s ^= *s >> 7;
        *s ^= *s << 17;
        (*s >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }

    /// The update of Belytschko et al. Box 6.1 written out for degree of freedom `d` of node
    /// `n`: the new (u, v), the reaction, and its terms of the 11 sums (in `StepSums` order).
    fn reference(
        nu: &NodalUpdate,
        n: usize,
        d: usize,
        u: &mut f64,
        v: &mut f64,
    ) -> (f64, [f64; 11]) {
        let p = &nu.p;
        let m = nu.mass[n];
        let (fi, fe) = (nu.f_int[n][d], nu.f_ext[n][d]);
        let v_old = *v;
        let fd = if p.damping { p.alpha * m * v_old } else { 0.0 };
        let fnet = fe - fi - fd;
        let code = nu.dof_code[3 * n + d];
        let (v_new, r, fe_r) = match code {
            0 => (v_old + p.dt_avg * fnet / m, 0.0, fe),
            c => {
                let v_new = if c == 1 {
                    0.0
                } else {
                    let tgt = nu.targets[(c - 2) as usize];
                    match nu.prescribed[(c - 2) as usize].kind {
                        Kinematic::Displacement(_) => (tgt - *u) / p.dt,
                        _ => tgt,
                    }
                };
                let r = m * (v_new - v_old) / p.dt_avg - fnet;
                (v_new, r, fe + r)
            }
        };
        let (h_old, h_new) = (0.5 * p.dt_old * v_old, 0.5 * p.dt * v_new);
        let vn = 0.5 * (v_old + v_new);
        let (ufi, umu) = if p.relax {
            (*u * fi, m * *u * *u)
        } else {
            (0.0, 0.0)
        };
        let terms = [
            fi * h_old,
            fi * h_new,
            fe_r * h_old,
            fe_r * h_new,
            fd * h_old,
            fd * h_new,
            0.5 * m * vn * vn,
            if code == 0 { fnet * fnet } else { 0.0 },
            fi * fi,
            ufi,
            umu,
        ];
        *v = v_new;
        *u += p.dt * v_new;
        (r, terms)
    }

    fn as_array(s: &StepSums) -> [f64; 11] {
        [
            s.w_int_old,
            s.w_int_new,
            s.w_ext_old,
            s.w_ext_new,
            s.w_damp_old,
            s.w_damp_new,
            s.kinetic,
            s.residual2,
            s.f_int2,
            s.u_f_int,
            s.u_m_u,
        ]
    }

    /// Lanes against the formulas written out per degree of freedom, on three chunks: the first
    /// with fixed, velocity- and displacement-prescribed degrees of freedom, the second free,
    /// the third 21 nodes (not a multiple of eight) with conditions in its tail; with and without
    /// damping and relaxation. The motion and the reactions bit for bit; the sums bit for bit
    /// against the same terms added per lane (`j mod 8`), lanes in order, chunks in order.
    #[test]
    fn lanes_give_the_update_written_out_per_degree_of_freedom() {
        let nn = 2 * NODE_CHUNK + 21;
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mass: Vec<f64> = (0..nn).map(|_| 1.5 + rnd(&mut seed)).collect();
        let field =
            |s: &mut u64| -> Vec<[f64; 3]> { (0..nn).map(|_| [rnd(s), rnd(s), rnd(s)]).collect() };
        let (f_int, f_ext, u0, v0) = (
            field(&mut seed),
            field(&mut seed),
            field(&mut seed),
            field(&mut seed),
        );
        let tail = 2 * NODE_CHUNK;
        let mut dof_code = vec![0u32; 3 * nn];
        for j in [3 * 100, 3 * 100 + 1, 3 * 100 + 2, 3 * (tail + 18) + 1] {
            dof_code[j] = 1;
        }
        for n in 200..208 {
            dof_code[3 * n] = 2;
        }
        for n in [301, 333, tail + 20] {
            dof_code[3 * n + 2] = 3;
        }
        let prescribed = vec![
            Prescribed {
                kind: Kinematic::Velocity(Curve::Constant { value: 0.3 }),
            },
            Prescribed {
                kind: Kinematic::Displacement(Curve::Constant { value: 0.01 }),
            },
        ];
        let targets = [0.3, 0.01];
        let constrained = constrained_chunks(&dof_code);
        assert_eq!(constrained, [true, false, true]);
        let bits =
            |x: &[[f64; 3]]| -> Vec<u64> { x.iter().flatten().map(|v| v.to_bits()).collect() };
        for (damping, relax) in [(false, false), (true, false), (false, true), (true, true)] {
            let nu = NodalUpdate {
                p: StepParams {
                    dt: 1.1e-3,
                    dt_old: 0.9e-3,
                    dt_avg: 1.0e-3,
                    alpha: 3.0,
                    damping,
                    relax,
                },
                mass: &mass,
                f_int: &f_int,
                f_ext: &f_ext,
                dof_code: &dof_code,
                constrained: &constrained,
                prescribed: &prescribed,
                targets: &targets,
            };
            let (mut ur, mut vr, mut rr) = (u0.clone(), v0.clone(), vec![[0.0; 3]; nn]);
            let mut want = [0.0; 11];
            for c0 in (0..nn).step_by(NODE_CHUNK) {
                let mut lanes = [[0.0; 11]; LANES];
                for n in c0..nn.min(c0 + NODE_CHUNK) {
                    for d in 0..3 {
                        let (r, t) = reference(&nu, n, d, &mut ur[n][d], &mut vr[n][d]);
                        rr[n][d] = r;
                        let lane = &mut lanes[(3 * (n - c0) + d) % LANES];
                        for k in 0..11 {
                            lane[k] += t[k];
                        }
                    }
                }
                for k in 0..11 {
                    want[k] += lanes.iter().fold(0.0, |s, l| s + l[k]);
                }
            }
            let (mut u, mut v, mut r) = (u0.clone(), v0.clone(), vec![[0.0; 3]; nn]);
            let mut got = StepSums::default();
            for (ci, ((uc, vc), rc)) in u
                .chunks_mut(NODE_CHUNK)
                .zip(v.chunks_mut(NODE_CHUNK))
                .zip(r.chunks_mut(NODE_CHUNK))
                .enumerate()
            {
                got.add(&nu.chunk(ci, uc, vc, rc));
            }
            let case = format!("damping {damping}, relaxation {relax}");
            assert!(
                bits(&u) == bits(&ur) && bits(&v) == bits(&vr),
                "motion differs ({case})"
            );
            assert!(bits(&r) == bits(&rr), "reactions differ ({case})");
            let got = as_array(&got);
            for k in 0..11 {
                assert_eq!(
                    got[k].to_bits(),
                    want[k].to_bits(),
                    "sum {k} ({case}): {} vs {}",
                    got[k],
                    want[k]
                );
            }
            assert!(want[3].abs() > 0.0 && want[6] > 0.0);
            assert_eq!(want[4] != 0.0, damping, "damping work ({case})");
            assert_eq!(want[10] != 0.0, relax, "u.M.u ({case})");
        }
    }
}
