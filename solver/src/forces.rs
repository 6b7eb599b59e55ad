//! The internal-force stage: the parallel element loop and the race-free gather.
//!
//! Each element writes its eight nodal force vectors into its own slot of an element-force
//! buffer; then every node sums its slots in a fixed order through the gather table. No two
//! threads write the same memory, and every sum is formed in the same order whatever the
//! thread count, so results are bitwise identical on 1 or N threads. Chunk partial results
//! (minimum step, energy rates) are reduced serially in chunk order for the same reason.

use crate::element::{full, one_point, ElementOut, Formulation, Nodal, StepInput};
use crate::model::{ChunkOut, Group, Model, Part, CHUNK};
use material::with_law;
use rayon::prelude::*;

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

/// Run the element loop: fill `slots` with element forces and `stress` (if requested, indexed by
/// global element id) with Cauchy stress; return totals or the first failing element.
pub fn element_loop(
    parts: &[Part],
    groups: &mut [Group],
    x_ref: &[[f64; 3]],
    u: &[[f64; 3]],
    v: &[[f64; 3]],
    input: &StepInput,
    slots: &mut [Nodal],
    stress: Option<&mut [[f64; 6]]>,
) -> Result<ElementTotals, (u32, String)> {
    let stress_ptr = stress.map(|s| Shared(s.as_mut_ptr()));
    let mut tot = ElementTotals {
        dt_min: f64::INFINITY,
        ..Default::default()
    };
    for g in groups.iter_mut() {
        let part = &parts[g.part];
        let form = part.formulation;
        let law = &part.material;
        let n = g.elements.len();
        let stride = g.history_stride;
        let hist = Shared(g.history.as_mut_ptr());
        let gslots = &mut slots[g.slot_offset..g.slot_offset + n];
        let (elements, conn, grad, vol0) = (&g.elements, &g.conn, &g.grad, &g.vol0);
        let eroded = &g.eroded;
        let dt_floor = g.dt_floor;
        let (gamma, hgk, gpg, gpw, dscale) = (
            &g.gamma,
            &g.hg_scale,
            &g.gp_grad,
            &g.gp_weight,
            &g.density_scale,
        );
        with_law!(law, l => {
            gslots.par_chunks_mut(CHUNK).zip(g.chunks.par_iter_mut()).enumerate().for_each(|(ci, (fch, out))| {
                let mut acc = ChunkOut { dt_min: f64::INFINITY, ..Default::default() };
                for (k, fe) in fch.iter_mut().enumerate() {
                    let le = ci * CHUNK + k;
                    if !eroded.is_empty() && eroded[le] {
                        *fe = [[0.0; 8]; 3];
                        continue;
                    }
                    let c = &conn[le];
                    let mut xe: Nodal = [[0.0; 8]; 3];
                    let mut ue: Nodal = [[0.0; 8]; 3];
                    let mut ve: Nodal = [[0.0; 8]; 3];
                    for a in 0..8 {
                        let nd = c[a] as usize;
                        let (un, vn, xr) = (u[nd], v[nd], x_ref[nd]);
                        for i in 0..3 {
                            ue[i][a] = un[i];
                            ve[i][a] = vn[i];
                            xe[i][a] = xr[i] + un[i];
                        }
                    }
                    let s = if dscale.is_empty() { 1.0 } else { dscale[le] };
                    // SAFETY: element le owns history[le*stride..(le+1)*stride] alone.
                    let h = unsafe { hist.slice(le * stride, stride) };
                    let r: Result<ElementOut, _> = match form {
                        Formulation::OnePoint(hg) => {
                            let rf = one_point::OnePointRef {
                                grad: &grad[le],
                                gamma: &gamma[le],
                                vol0: vol0[le],
                                hg_scale: hgk[le],
                            };
                            one_point::compute_forces(l, &rf, hg.form, &xe, &ue, &ve, s, input, h, fe)
                        }
                        Formulation::Full { fbar } => {
                            let rf = full::FullRef {
                                centre_grad: &grad[le],
                                gp_grad: &gpg[le],
                                gp_weight: &gpw[le],
                                vol0: vol0[le],
                            };
                            full::compute_forces(l, &rf, fbar, &xe, &ue, &ve, s, input, h, fe)
                        }
                    };
                    match r {
                        Ok(mut o) => {
                            if o.dt < dt_floor {
                                // Run-time mass scaling: dt grows with sqrt(density scale).
                                let r = dt_floor / o.dt;
                                acc.rescale.push((le as u32, s * r * r));
                                o.dt = dt_floor;
                            }
                            if o.dt < acc.dt_min {
                                acc.dt_min = o.dt;
                                acc.dt_elem = elements[le];
                            }
                            acc.hg_stored += o.hourglass_stored;
                            acc.hg_power += o.hourglass_power;
                            let hg = o.hourglass_stored + o.hourglass_power * input.dt;
                            if hg > acc.hg_peak {
                                acc.hg_peak = hg;
                                acc.hg_peak_elem = elements[le];
                            }
                            acc.bulk_power += o.bulk_power;
                            acc.law_dissipation += o.law_dissipation;
                            if o.failed {
                                acc.failed.push(le as u32);
                            }
                            if let Some(sp) = stress_ptr {
                                // SAFETY: one element writes one entry.
                                unsafe { sp.slice(elements[le] as usize, 1)[0] = o.cauchy };
                            }
                        }
                        Err(e) => {
                            if acc.error.is_none() {
                                acc.error = Some((elements[le], e.to_string()));
                            }
                            *fe = [[0.0; 8]; 3];
                        }
                    }
                }
                *out = acc;
            });
        });
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

/// Gather element slots into nodal forces: f[n] = sum of its slots, in table order.
pub fn gather(model: &Model, slots: &[Nodal], f: &mut [[f64; 3]]) {
    let ptr = &model.gather_ptr;
    let idx = &model.gather_idx;
    f.par_chunks_mut(4096).enumerate().for_each(|(ci, ch)| {
        for (k, fn_) in ch.iter_mut().enumerate() {
            let n = ci * 4096 + k;
            let mut s = [0.0; 3];
            for &sl in &idx[ptr[n] as usize..ptr[n + 1] as usize] {
                let (e, a) = ((sl >> 3) as usize, (sl & 7) as usize);
                let v = &slots[e];
                s[0] += v[0][a];
                s[1] += v[1][a];
                s[2] += v[2][a];
            }
            *fn_ = s;
        }
    });
}
