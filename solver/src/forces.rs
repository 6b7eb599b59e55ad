//! The internal-force stage: the parallel element loop and the race-free gather.
//!
//! Elements are processed in batches of [`LANES`] (eight): the nodal displacements, velocities
//! and coordinates of a batch are gathered into lane vectors (struct of arrays inside the batch),
//! and one call of the element kernel evaluates the kinematics, the law, the internal and
//! hourglass forces and the critical step of all eight ([`crate::element`], generic over
//! [`material::real::Real`]). Reference data (gradients, hourglass vectors, Gauss-point data) and
//! history are stored batch by batch in the same lane layout ([`crate::model::Group`]), so they
//! load as whole vectors. The batch kernel is compiled twice: for AVX-512 (chosen at run time when
//! the processor has it) and for the build's baseline (AVX2 with the project's `.cargo/config.toml`,
//! SSE2 or NEON elsewhere); both perform the same IEEE operations in the same order, so results
//! do not depend on which runs. `PALPA_SIMD=baseline` forces the baseline path.
//!
//! Each batch writes its eight elements' nodal force vectors into its own slot of an
//! element-force buffer; then every node sums its slots in a fixed order through the gather
//! table. No two threads write the same memory, and every sum is formed in the same order
//! whatever the thread count, so results are bitwise identical on 1 or N threads. Chunk partial
//! results (minimum step, energy rates) are reduced serially in chunk order, and inside a chunk
//! element by element in element order, for the same reason.

use crate::element::{fault_error, full, one_point, ElementOut, Formulation, Nodal, StepInput};
use crate::model::{ChunkOut, Group, Model, Part, CHUNK};
use material::real::{F64x8, Mask, Real, LANES};
use material::{with_law, Law};
use rayon::prelude::*;
use std::sync::OnceLock;
/// Sum of the element loop's scalar outputs.
#[derive(Clone, Copy, Debug, Default)]
pub struct ElementTotals {
    /// Smallest critical step (s).
    pub dt_min: f64,
    /// Element with the smallest step.
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

/// A raw pointer shared by the element loop to write disjoint per-element ranges.
#[derive(Clone, Copy)]
struct Shared<T>(*mut T);
unsafe impl<T> Send for Shared<T> {}
unsafe impl<T> Sync for Shared<T> {}
impl<T> Shared<T> {
    /// # Safety
    /// The caller guarantees that no two live slices overlap.
    #[inline(always)]
    #[allow(clippy::mut_from_ref)]
    unsafe fn slice(&self, start: usize, len: usize) -> &mut [T] {
        std::slice::from_raw_parts_mut(self.0.add(start), len)
    }
}

/// Which instruction set the batch kernels run with: `"avx512"` or `"baseline"`.
pub fn simd_level() -> &'static str {
    static LEVEL: OnceLock<&'static str> = OnceLock::new();
    LEVEL.get_or_init(|| {
        let forced = std::env::var("PALPA_SIMD")
            .map(|v| v == "baseline")
            .unwrap_or(false);
        #[cfg(target_arch = "x86_64")]
        {
            if !forced
                && std::arch::is_x86_feature_detected!("avx512f")
                && std::arch::is_x86_feature_detected!("avx512dq")
                && std::arch::is_x86_feature_detected!("avx512vl")
                && std::arch::is_x86_feature_detected!("avx512bw")
            {
                return "avx512";
            }
        }
        let _ = forced;
        "baseline"
    })
}

/// Everything a chunk of batches reads: one group's data and the step's state.
struct Batch<'a> {
    form: Formulation,
    group: &'a Group,
    x_ref: &'a [[f64; 3]],
    u: &'a [[f64; 3]],
    v: &'a [[f64; 3]],
    input: &'a StepInput,
    hist: Shared<F64x8>,
    stress: Option<Shared<[f64; 6]>>,
}

/// Run the element loop: fill `slots` (one lane vector per force component and node, per batch)
/// with element forces and `stress` (if requested, indexed by global element id) with Cauchy
/// stress; return totals or the first failing element.
#[allow(clippy::too_many_arguments)]
pub fn element_loop(
    parts: &[Part],
    groups: &mut [Group],
    x_ref: &[[f64; 3]],
    u: &[[f64; 3]],
    v: &[[f64; 3]],
    input: &StepInput,
    slots: &mut [Nodal<F64x8>],
    stress: Option<&mut [[f64; 6]]>,
) -> Result<ElementTotals, (u32, String)> {
    let stress_ptr = stress.map(|s| Shared(s.as_mut_ptr()));
    let mut tot = ElementTotals {
        dt_min: f64::INFINITY,
        ..Default::default()
    };
    for g in groups.iter_mut() {
        let part = &parts[g.part];
        let n = g.elements.len();
        let first = g.slot_offset / LANES;
        let gslots = &mut slots[first..first + g.batches()];
        let mut chunks = std::mem::take(&mut g.chunks);
        let hist = Shared(g.history.as_mut_ptr());
        let batch = Batch {
            form: part.formulation,
            group: g,
            x_ref,
            u,
            v,
            input,
            hist,
            stress: stress_ptr,
        };
        with_law!(&part.material, l => {
            gslots
                .par_chunks_mut(CHUNK / LANES)
                .zip(chunks.par_iter_mut())
                .enumerate()
                .for_each(|(ci, (fch, out))| *out = run_chunk(l, &batch, ci, fch));
        });
        g.chunks = chunks;
        for ch in &g.chunks {
            if let Some(e) = &ch.error {
                return Err(e.clone());
            }
            // Erosion (LS-DYNA element deletion): a failed element keeps its nodal mass and
            // carries no force from the next step on. The eroded array exists only once an
            // element of the group has failed.
            for &le in &ch.failed {
                if g.eroded.is_empty() {
                    g.eroded = vec![false; n];
                }
                if !g.eroded[le as usize] {
                    g.eroded[le as usize] = true;
                    tot.newly_eroded += 1;
                    tot.first_eroded.get_or_insert(g.elements[le as usize]);
                }
            }
            if ch.dt_min * g.dt_kappa < tot.dt_min {
                tot.dt_min = ch.dt_min * g.dt_kappa;
                tot.dt_elem = ch.dt_elem;
            }
            tot.hg_stored += ch.hg_stored;
            tot.hg_power += ch.hg_power;
            if ch.hg_peak > tot.hg_peak {
                tot.hg_peak = ch.hg_peak;
                tot.hg_peak_elem = ch.hg_peak_elem;
            }
            tot.bulk_power += ch.bulk_power;
            tot.law_dissipation += ch.law_dissipation;
        }
    }
    Ok(tot)
}

/// One chunk of batches, with the instruction set of [`simd_level`].
fn run_chunk<L: Law>(l: &L, b: &Batch, ci: usize, fch: &mut [Nodal<F64x8>]) -> ChunkOut {
    #[cfg(target_arch = "x86_64")]
    if simd_level() == "avx512" {
        // SAFETY: the processor has the features (checked by `simd_level`).
        return unsafe { run_chunk_avx512(l, b, ci, fch) };
    }
    run_chunk_body(l, b, ci, fch)
}

/// [`run_chunk_body`] compiled for AVX-512.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512dq,avx512vl,avx512bw")]
unsafe fn run_chunk_avx512<L: Law>(
    l: &L,
    b: &Batch,
    ci: usize,
    fch: &mut [Nodal<F64x8>],
) -> ChunkOut {
    run_chunk_body(l, b, ci, fch)
}

/// Lane vector of per-element values `x[le0 + lane]`, lanes past `n` repeating the last.
#[inline(always)]
fn lanes_of(x: &[f64], le0: usize) -> F64x8 {
    let n = x.len();
    F64x8::new(material::arr![LANES, |l| x[(le0 + l).min(n - 1)]])
}

#[inline(always)]
fn run_chunk_body<L: Law>(l: &L, b: &Batch, ci: usize, fch: &mut [Nodal<F64x8>]) -> ChunkOut {
    let g = b.group;
    let n = g.elements.len();
    let stride = g.history_stride;
    let mut acc = ChunkOut {
        dt_min: f64::INFINITY,
        ..Default::default()
    };
    for (k, fe) in fch.iter_mut().enumerate() {
        let bi = ci * (CHUNK / LANES) + k;
        let le0 = bi * LANES;
        let nvalid = LANES.min(n - le0);
        let conn: [&[u32; 8]; LANES] = material::arr![LANES, |q| &g.conn[(le0 + q).min(n - 1)]];
        // Gather into plain arrays [component][node][lane], then load whole lane vectors.
        let mut xb = [[[0.0; LANES]; 8]; 3];
        let mut ub = [[[0.0; LANES]; 8]; 3];
        let mut vb = [[[0.0; LANES]; 8]; 3];
        for a in 0..8 {
            for (q, c) in conn.iter().enumerate() {
                let nd = c[a] as usize;
                let (un, vn, xr) = (b.u[nd], b.v[nd], b.x_ref[nd]);
                for i in 0..3 {
                    ub[i][a][q] = un[i];
                    vb[i][a][q] = vn[i];
                    xb[i][a][q] = xr[i] + un[i];
                }
            }
        }
        let xe: Nodal<F64x8> = material::arr![3, |i| material::arr![8, |a| F64x8::new(xb[i][a])]];
        let ue: Nodal<F64x8> = material::arr![3, |i| material::arr![8, |a| F64x8::new(ub[i][a])]];
        let ve: Nodal<F64x8> = material::arr![3, |i| material::arr![8, |a| F64x8::new(vb[i][a])]];
        let s = if g.density_scale.is_empty() {
            F64x8::splat(1.0)
        } else {
            lanes_of(&g.density_scale, le0)
        };
        // SAFETY: batch bi owns history[bi*stride..(bi+1)*stride] alone.
        let h = unsafe { b.hist.slice(bi * stride, stride) };
        let o: ElementOut<F64x8> = match b.form {
            Formulation::OnePoint(hg) => {
                let rf = one_point::OnePointRef {
                    grad: &g.grad[bi],
                    gamma: &g.gamma[bi],
                    vol0: lanes_of(&g.vol0, le0),
                    hg_scale: lanes_of(&g.hg_scale, le0),
                };
                one_point::compute_forces(l, &rf, hg.form, &xe, &ue, &ve, s, b.input, h, fe)
            }
            Formulation::Full { fbar } => {
                let rf = full::FullRef {
                    centre_grad: &g.grad[bi],
                    gp_grad: &g.gp_grad[bi],
                    gp_weight: &g.gp_weight[bi],
                    vol0: lanes_of(&g.vol0, le0),
                };
                full::compute_forces(l, &rf, fbar, &xe, &ue, &ve, s, b.input, h, fe)
            }
        };
        let (fault_l, fault_v) = (o.fault.to_array(), o.fault_value.to_array());
        let (dt_l, hs_l, hp_l) = (
            o.dt.to_array(),
            o.hourglass_stored.to_array(),
            o.hourglass_power.to_array(),
        );
        let (bulk_l, diss_l, s_l) = (
            o.bulk_power.to_array(),
            o.law_dissipation.to_array(),
            s.to_array(),
        );
        for q in 0..nvalid {
            let le = le0 + q;
            let eroded = !g.eroded.is_empty() && g.eroded[le];
            let fault = fault_l[q];
            if eroded || fault != 0.0 {
                if !eroded && acc.error.is_none() {
                    let e = fault_error(fault, fault_v[q], l.name());
                    acc.error = Some((g.elements[le], e.to_string()));
                }
                for row in fe.iter_mut() {
                    for x in row.iter_mut() {
                        x.set_lane(q, 0.0);
                    }
                }
                continue;
            }
            let mut dt = dt_l[q];
            if dt < g.dt_floor {
                // Run-time mass scaling: dt grows with sqrt(density scale).
                let r = g.dt_floor / dt;
                acc.rescale.push((le as u32, s_l[q] * r * r));
                dt = g.dt_floor;
            }
            if dt < acc.dt_min {
                acc.dt_min = dt;
                acc.dt_elem = g.elements[le];
            }
            let (hs, hp) = (hs_l[q], hp_l[q]);
            acc.hg_stored += hs;
            acc.hg_power += hp;
            let hg = hs + hp * b.input.dt;
            if hg > acc.hg_peak {
                acc.hg_peak = hg;
                acc.hg_peak_elem = g.elements[le];
            }
            acc.bulk_power += bulk_l[q];
            acc.law_dissipation += diss_l[q];
            if o.failed.lane(q) {
                acc.failed.push(le as u32);
            }
            if let Some(sp) = b.stress {
                // SAFETY: one element writes one entry.
                unsafe {
                    sp.slice(g.elements[le] as usize, 1)[0] =
                        material::arr![6, |c| o.cauchy[c].lane(q)]
                };
            }
        }
    }
    acc
}

/// Gather element slots into nodal forces: f[n] = sum of its slots, in table order.
pub fn gather(model: &Model, slots: &[Nodal<F64x8>], f: &mut [[f64; 3]]) {
    let ptr = &model.gather_ptr;
    let idx = &model.gather_idx;
    // The slots as plain numbers: batch b, component i, node a, lane q at
    // ((b * 3 + i) * 8 + a) * LANES + q (lane vectors are arrays of f64 in memory).
    // SAFETY: F64x8 is a transparent wrapper of wide's f64x8, a plain (repr(C)) block of eight
    // f64, so a slot batch is 3 * 8 * LANES contiguous f64 with no padding.
    let flat: &[f64] = unsafe {
        std::slice::from_raw_parts(slots.as_ptr() as *const f64, slots.len() * 3 * 8 * LANES)
    };
    const PER_BATCH: usize = 3 * 8 * LANES;
    f.par_chunks_mut(4096).enumerate().for_each(|(ci, ch)| {
        for (k, fn_) in ch.iter_mut().enumerate() {
            let n = ci * 4096 + k;
            let mut s = [0.0; 3];
            for &sl in &idx[ptr[n] as usize..ptr[n + 1] as usize] {
                let (e, a) = ((sl >> 3) as usize, (sl & 7) as usize);
                let base = (e / LANES) * PER_BATCH + a * LANES + e % LANES;
                s[0] += flat[base];
                s[1] += flat[base + 8 * LANES];
                s[2] += flat[base + 16 * LANES];
            }
            *fn_ = s;
        }
    });
}
