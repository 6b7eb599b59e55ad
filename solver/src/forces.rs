//! The internal-force stage: the parallel element loop, adding element forces straight into the
//! nodal force array.
//!
//! Elements are processed in batches of [`LANES`] (eight): the nodal displacements, velocities
//! and coordinates of a batch are gathered into lane vectors (struct of arrays inside the batch),
//! and one call of the element kernel evaluates the kinematics, the law, the internal and
//! hourglass forces and the critical step of all eight ([`crate::element`], generic over
//! [`material::real::Real`]). Reference data (gradients, hourglass vectors, Gauss-point data) and
//! history are stored batch by batch in the same lane layout ([`crate::model::Group`]), so they
//! load as whole vectors. Two measured exceptions to "read what was stored": the `f64` one-point
//! kernels form their hourglass vectors from the reference coordinates they gather anyway
//! ([`KernelLanes::hourglass_vectors`], bitwise the stored ones), and the one-point kernels ask
//! the cache for the reference data and history two batches ahead ([`prefetch_batch`]). Both
//! cut the stalls of the first loads of each batch; together they raised the one-point blocks
//! of `palpa bench` 1.4-1.6x (docs/performance.md). Prefetching the fully integrated element's
//! Gauss-point data made it slower, so it reads as before.
//!
//! The batch kernel is compiled twice: for AVX-512 (chosen at run time when
//! the processor has it) and for the build's baseline (AVX2 with the project's `.cargo/config.toml`,
//! SSE2 or NEON elsewhere). The AVX-512 path runs its own lane types (`Z64x8`, `Z32x8` of
//! `material::real_avx512`: eight `f64` in one 512-bit register where `wide`'s `f64x8` is two
//! 256-bit halves on the baseline build); both paths perform the same IEEE operations in the
//! same order, so results do not depend on which runs (the `palpa` package's
//! `tests/simd_paths.rs` compares whole runs byte for byte). `PALPA_SIMD=baseline` forces the
//! baseline path.
//!
//! Assembly: the elements of a group are cut into chunks of [`CHUNK`], and the chunks are
//! coloured so that no two chunks of one colour share a node ([`crate::model::Group::colours`]).
//! The chunks of one colour run in parallel, each adding its elements' nodal forces into the
//! nodal force array as it goes (element by element, lane by lane); the colours run one after
//! the other. No two threads write the same node at once, and every node receives its
//! contributions in the same order (colour, then element order) whatever the thread count, so
//! results are bitwise identical on 1 or N threads. This replaced a per-element force buffer
//! summed by a node-to-element gather table, which moved 384 bytes per element and cycle more and
//! cost about a third of the step on the 100k-element blocks of `palpa bench` (the gather's loads
//! were cache misses 512 bytes apart). Chunk partial results (minimum step, energy rates: one
//! [`ElementTotals`] per chunk) are reduced serially in chunk order, and inside a chunk element
//! by element in element order, both by [`ElementTotals::combine`], for the same reason.
//!
//! Subcycling ([`crate::subcycle`]): a group of slow elements (`Group::subcycle` > 1) is
//! evaluated only when [`StepInput::macro_dt`] is given, with that step for its laws; in the
//! other steps it adds nothing to the nodal forces and reports the totals of its last
//! evaluation ([`Group::held`]), its law dissipation only once.

use crate::element::physical::PhysicalRef;
use crate::element::precision::{NarrowRef, Precision, Refs};
use crate::element::{fault_error, full, one_point, ElementOut, Formulation, Nodal, StepInput};
use crate::model::{ChunkOut, ElementTotals, Group, Part, CHUNK};
use material::real::{F64x8, Mask, Real, LANES};
#[cfg(target_arch = "x86_64")]
use material::real_avx512::{Z32x8, Z64x8};
use material::real_f32::F32x8;
use material::{with_law, Law};
use rayon::prelude::*;
use std::sync::OnceLock;
/// A raw pointer shared by the element loop to write disjoint ranges: history and stress per
/// element, chunk results per chunk, nodal forces per node of a colour's chunks.
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
    force: Shared<[f64; 3]>,
}

/// Run the element loop: set `force` (one entry per node) to the sum of the element forces and
/// `stress` (if requested, indexed by global element id) to the Cauchy stress; return totals or
/// the first failing element.
/// `x_ref` must be the coordinates the model was built from: the `f64` one-point kernels form
/// their hourglass vectors from it.
#[allow(clippy::too_many_arguments)]
pub fn element_loop(
    parts: &[Part],
    groups: &mut [Group],
    x_ref: &[[f64; 3]],
    u: &[[f64; 3]],
    v: &[[f64; 3]],
    input: &StepInput,
    force: &mut [[f64; 3]],
    stress: Option<&mut [[f64; 6]]>,
) -> Result<ElementTotals, (u32, String)> {
    // The kernels index these arrays by the connectivity without bounds checks: O(groups)
    // checks against what the model recorded when it was built.
    let n_nodes = x_ref.len();
    assert!(
        u.len() == n_nodes && v.len() == n_nodes && force.len() == n_nodes,
        "element_loop: u, v and force need one entry per node of x_ref"
    );
    assert!(
        groups.iter().all(|g| g.max_node < n_nodes),
        "element_loop: an element refers to a node beyond x_ref"
    );
    if let Some(s) = &stress {
        let ne = groups.iter().flat_map(|g| g.elements.iter()).max();
        assert!(
            ne.is_none_or(|&e| (e as usize) < s.len()),
            "element_loop: stress is too short"
        );
    }
    let stress_ptr = stress.map(|s| Shared(s.as_mut_ptr()));
    force.par_chunks_mut(4096).for_each(|c| c.fill([0.0; 3]));
    let force_ptr = Shared(force.as_mut_ptr());
    let mut tot = ElementTotals::EMPTY;
    for g in groups.iter_mut() {
        // A subcycled group (crate::subcycle) is evaluated at macro times only, with the macro
        // step; between them it reports the totals of its last evaluation.
        let input = &match (g.subcycle, input.macro_dt) {
            (1, _) => *input,
            // its stress is written at every evaluation when the run keeps stress
            (_, Some(big)) => StepInput {
                dt: big,
                want_stress: stress_ptr.is_some(),
                ..*input
            },
            (_, None) => {
                g.evaluated = false;
                tot.combine(&g.held);
                continue;
            }
        };
        g.evaluated = true;
        let part = &parts[g.part];
        let n = g.elements.len();
        if input.precision == Precision::F32 && g.narrow.is_none() {
            g.narrow = Some(Box::new(NarrowRef::new(&g.refs())));
        }
        let mut chunks = std::mem::take(&mut g.chunks);
        let chunk_ptr = Shared(chunks.as_mut_ptr());
        let hist = Shared(g.history.as_mut_ptr());
        let batch = Batch {
            form: part.formulation,
            group: g,
            x_ref,
            u,
            v,
            input,
            hist,
            stress: stress_ptr.filter(|_| input.want_stress),
            force: force_ptr,
        };
        with_law!(&part.material, l => {
            for colour in &g.colours {
                colour.par_iter().for_each(|&ci| {
                    let out = run_chunk(l, &batch, ci as usize);
                    // SAFETY: each chunk index appears once in the colouring.
                    unsafe { chunk_ptr.slice(ci as usize, 1)[0] = out };
                });
            }
        });
        g.chunks = chunks;
        // the run's totals chunk by chunk in chunk order (bitwise), the group's beside
        let mut group = ElementTotals::EMPTY;
        for ch in &g.chunks {
            if let Some(e) = &ch.error {
                return Err(e.clone());
            }
            // Erosion (LS-DYNA element deletion): a failed element keeps its nodal mass and
            // carries no force from the next step on. The eroded array exists only once an
            // element of the group has failed. A chunk skips eroded elements, so the elements
            // it reports failed (and counts in its totals) are newly failed.
            for &le in &ch.failed {
                if g.eroded.is_empty() {
                    g.eroded = vec![false; n];
                }
                debug_assert!(!g.eroded[le as usize]);
                g.eroded[le as usize] = true;
            }
            let c = ElementTotals {
                dt_min: ch.totals.dt_min * g.dt_kappa / g.step_ratio as f64,
                ..ch.totals
            };
            tot.combine(&c);
            group.combine(&c);
        }
        g.hourglass.stored = group.hg_stored;
        g.hourglass.power = group.hg_power;
        if g.subcycle > 1 {
            // the law dissipation covered the macro step: booked once, at this evaluation
            g.held = ElementTotals {
                law_dissipation: 0.0,
                newly_eroded: 0,
                first_eroded: None,
                ..group
            };
        }
    }
    Ok(tot)
}

/// One chunk of batches, in the run's precision.
fn run_chunk<L: Law>(l: &L, b: &Batch, ci: usize) -> ChunkOut {
    match b.input.precision {
        Precision::F64 => run_chunk_in::<L, F64x8>(l, b, ci),
        Precision::F32 => run_chunk_in::<L, F32x8>(l, b, ci),
    }
}

/// One chunk of batches with kernels over `R` (over `R::Avx512` with AVX-512), with the
/// instruction set of [`simd_level`]. The one-point and the fully integrated kernels are
/// compiled as separate functions (`FULL`): in one function, adding work to one of them
/// changed how the other was compiled. On the F-bar block (one thread) the shared function
/// ran 2.86 M element-cycles/s once the one-point kernel formed its hourglass vectors, the
/// separate one 3.01 M, the build before both 3.12-3.17 M (docs/performance.md).
fn run_chunk_in<L: Law, R: KernelLanes>(l: &L, b: &Batch, ci: usize) -> ChunkOut {
    let full = matches!(b.form, Formulation::Full { .. });
    #[cfg(target_arch = "x86_64")]
    if simd_level() == "avx512" {
        // SAFETY: the processor has the features (checked by `simd_level`).
        return unsafe {
            match full {
                true => run_chunk_avx512::<L, R::Avx512, true>(l, b, ci),
                false => run_chunk_avx512::<L, R::Avx512, false>(l, b, ci),
            }
        };
    }
    match full {
        true => run_chunk_body::<L, ScalarGather, R, true>(l, b, ci),
        false => run_chunk_body::<L, ScalarGather, R, false>(l, b, ci),
    }
}

/// [`run_chunk_body`] compiled for AVX-512.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512dq,avx512vl,avx512bw")]
unsafe fn run_chunk_avx512<L: Law, R: KernelLanes, const FULL: bool>(
    l: &L,
    b: &Batch,
    ci: usize,
) -> ChunkOut {
    run_chunk_body::<L, Avx512Gather, R, FULL>(l, b, ci)
}

/// The number types the element kernels run in ([`F64x8`], [`F32x8`], and [`Z64x8`] in place
/// of `F64x8` with AVX-512), and where each finds its reference data and history: the group's
/// own `f64` lanes (read as `Z64x8` by the AVX-512 kernels) or its [`NarrowRef`] (`f32`).
trait KernelLanes: Real {
    /// The type the AVX-512 kernels use instead (the same numbers, bitwise).
    type Avx512: KernelLanes;
    fn refs(g: &Group) -> Refs<'_, Self>;
    /// A batch's nodal field in the kernel's number type: as it is in `f64`; relative to each
    /// element's first node before rounding in `f32` (see [`crate::element::precision`]).
    fn nodal(x: &Nodal<F64x8>) -> Nodal<Self>;
    /// `f64` lanes in the law's number type.
    fn wide(x: F64x8) -> Self::Wide;
    /// A batch's stored history in the law's number type.
    fn history(h: &mut [F64x8]) -> &mut [Self::Wide];
    /// Batch `bi`'s hourglass vectors ([`crate::hex::hourglass_vectors`]) from its reference
    /// coordinates `x_ref`. In `f64` they are formed here, bitwise as the model formed them:
    /// that costs about 300 vector operations per batch and saves reading 256 bytes per element
    /// from memory (measured in docs/performance.md). In `f32` they are read.
    #[inline(always)]
    fn hourglass_vectors(refs: &Refs<Self>, bi: usize, x_ref: &Nodal<F64x8>) -> [[Self; 8]; 4] {
        if Self::READS_GAMMA {
            refs.gamma[bi]
        } else {
            crate::hex::hourglass_vectors(&Self::nodal(x_ref), &refs.grad[bi])
        }
    }
    /// Whether [`KernelLanes::hourglass_vectors`] reads the stored vectors (`f32`) rather than
    /// forming them (`f64`).
    const READS_GAMMA: bool;
    /// Per-element `f64` lanes (volume, hourglass scale, density scale) in the kernel's type.
    #[inline(always)]
    fn per_element(x: F64x8) -> Self {
        Self::narrow(Self::wide(x))
    }
}

impl KernelLanes for F64x8 {
    #[cfg(target_arch = "x86_64")]
    type Avx512 = Z64x8;
    #[cfg(not(target_arch = "x86_64"))]
    type Avx512 = F64x8;
    #[inline(always)]
    fn refs(g: &Group) -> Refs<'_, Self> {
        g.refs()
    }
    #[inline(always)]
    fn nodal(x: &Nodal<F64x8>) -> Nodal<Self> {
        *x
    }
    const READS_GAMMA: bool = false;
    #[inline(always)]
    fn wide(x: F64x8) -> F64x8 {
        x
    }
    #[inline(always)]
    fn history(h: &mut [F64x8]) -> &mut [F64x8] {
        h
    }
}

#[cfg(target_arch = "x86_64")]
impl KernelLanes for Z64x8 {
    type Avx512 = Z64x8;
    #[inline(always)]
    fn refs(g: &Group) -> Refs<'_, Self> {
        g.refs().as_z64x8()
    }
    #[inline(always)]
    fn nodal(x: &Nodal<F64x8>) -> Nodal<Self> {
        material::arr![3, |i| material::arr![8, |a| Self::wide(x[i][a])]]
    }
    const READS_GAMMA: bool = false;
    #[inline(always)]
    fn wide(x: F64x8) -> Z64x8 {
        Z64x8::from_f64x8(x)
    }
    #[inline(always)]
    fn history(h: &mut [F64x8]) -> &mut [Z64x8] {
        const { assert!(std::mem::size_of::<F64x8>() == std::mem::size_of::<Z64x8>()) };
        const { assert!(std::mem::align_of::<F64x8>() >= std::mem::align_of::<Z64x8>()) };
        // SAFETY: same size, no stricter alignment (checked above), any bits are valid lanes.
        unsafe { std::slice::from_raw_parts_mut(h.as_mut_ptr() as *mut Z64x8, h.len()) }
    }
}

impl KernelLanes for F32x8 {
    #[cfg(target_arch = "x86_64")]
    type Avx512 = Z32x8;
    #[cfg(not(target_arch = "x86_64"))]
    type Avx512 = F32x8;
    #[inline(always)]
    fn refs(g: &Group) -> Refs<'_, Self> {
        g.narrow
            .as_deref()
            .expect("element_loop builds the f32 reference data first")
            .refs()
    }
    #[inline(always)]
    fn nodal(x: &Nodal<F64x8>) -> Nodal<Self> {
        material::arr![3, |i| {
            let x0 = x[i][0];
            material::arr![8, |a| F32x8::narrow(x[i][a] - x0)]
        }]
    }
    const READS_GAMMA: bool = true;
    #[inline(always)]
    fn wide(x: F64x8) -> F64x8 {
        x
    }
    #[inline(always)]
    fn history(h: &mut [F64x8]) -> &mut [F64x8] {
        h
    }
}

#[cfg(target_arch = "x86_64")]
impl KernelLanes for Z32x8 {
    type Avx512 = Z32x8;
    #[inline(always)]
    fn refs(g: &Group) -> Refs<'_, Self> {
        F32x8::refs(g).as_z32x8()
    }
    #[inline(always)]
    fn nodal(x: &Nodal<F64x8>) -> Nodal<Self> {
        let n = F32x8::nodal(x);
        material::arr![3, |i| material::arr![8, |a| Z32x8(n[i][a])]]
    }
    const READS_GAMMA: bool = true;
    #[inline(always)]
    fn wide(x: F64x8) -> Z64x8 {
        Z64x8::from_f64x8(x)
    }
    #[inline(always)]
    fn history(h: &mut [F64x8]) -> &mut [Z64x8] {
        <Z64x8 as KernelLanes>::history(h)
    }
}

/// Lane vector of per-element values `x[le0 + lane]`, lanes past `n` repeating the last.
#[inline(always)]
fn lanes_of(x: &[f64], le0: usize) -> F64x8 {
    let n = x.len();
    F64x8::new(material::arr![LANES, |l| x[(le0 + l).min(n - 1)]])
}

#[inline(always)]
fn run_chunk_body<L: Law, G: GatherLanes, R: KernelLanes, const FULL: bool>(
    l: &L,
    b: &Batch,
    ci: usize,
) -> ChunkOut {
    let g = b.group;
    let n = g.elements.len();
    let mut acc = ChunkOut {
        totals: ElementTotals::EMPTY,
        ..Default::default()
    };
    // the group's reference data in R, looked up once per chunk
    let refs = R::refs(g);
    let first = ci * (CHUNK / LANES);
    for bi in first..g.batches().min(first + CHUNK / LANES) {
        let le0 = bi * LANES;
        let nvalid = LANES.min(n - le0);
        let conn: [[u32; 8]; LANES] = material::arr![LANES, |q| g.conn[(le0 + q).min(n - 1)]];
        let mut fe: Nodal<R> = [[R::zero(); 8]; 3];
        let s64 = if g.density_scale.is_empty() {
            F64x8::splat(1.0)
        } else {
            lanes_of(&g.density_scale, le0)
        };
        if !FULL {
            prefetch_batch(b, &refs, bi + PREFETCH_AHEAD);
        }
        let o = batch_forces::<L, G, R, FULL>(l, b, &refs, bi, &conn, s64, &mut fe);
        let add = book_lanes(l, b, le0, nvalid, &o, s64, &mut acc);
        scatter_forces(b, &conn, &add, &fe);
    }
    acc
}

/// How many batches ahead [`prefetch_batch`] asks for (one to four measured alike on the
/// `palpa bench` blocks).
const PREFETCH_AHEAD: usize = 2;

/// Ask the cache for batch `bi`'s reference data and history, when the group has that batch.
/// The kernels read each batch's data once per step from arrays of hundreds of bytes per
/// element; the hardware prefetcher did not keep up with them, and the first loads of each
/// batch stalled. Measured in docs/performance.md ("Reference data formed and fetched ahead").
#[inline(always)]
fn prefetch_batch<R: KernelLanes>(b: &Batch, refs: &Refs<R>, bi: usize) {
    let g = b.group;
    if bi >= g.batches() {
        return;
    }
    if R::READS_GAMMA {
        prefetch(refs.gamma.get(bi));
    }
    prefetch(refs.grad.get(bi));
    prefetch(refs.hg_frame.get(bi));
    prefetch(refs.hg_inv_len.get(bi));
    let stride = g.history_stride;
    // Pointer arithmetic only: other threads write other batches' history meanwhile.
    let h = b.hist.0.wrapping_add(bi * stride) as *const u8;
    prefetch_bytes(h, stride * std::mem::size_of::<F64x8>());
}

/// [`prefetch_bytes`] of one value, if there is one.
#[inline(always)]
fn prefetch<T>(x: Option<&T>) {
    if let Some(x) = x {
        prefetch_bytes(x as *const T as *const u8, std::mem::size_of::<T>());
    }
}

/// Ask the cache for the `bytes` from `p`, line by line (a hint: it never faults).
#[inline(always)]
fn prefetch_bytes(p: *const u8, bytes: usize) {
    #[cfg(target_arch = "x86_64")]
    for k in (0..bytes).step_by(64) {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        // SAFETY: a prefetch does not access memory and never faults.
        unsafe { _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(k) as *const i8) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (p, bytes);
}

/// One batch's element kernel: the nodal data gathered into lanes (in `R`, see
/// [`KernelLanes::nodal`]), the reference data and history of batch `bi`, the forces into `fe`.
#[inline(always)]
fn batch_forces<L: Law, G: GatherLanes, R: KernelLanes, const FULL: bool>(
    l: &L,
    b: &Batch,
    refs: &Refs<R>,
    bi: usize,
    conn: &[[u32; 8]; LANES],
    density_scale: F64x8,
    fe: &mut Nodal<R>,
) -> ElementOut<R> {
    let g = b.group;
    let le0 = bi * LANES;
    let stride = g.history_stride;
    let ue = G::lanes(b.u, conn);
    let ve = G::lanes(b.v, conn);
    let xr = G::lanes(b.x_ref, conn);
    let xe: Nodal<F64x8> = material::arr![3, |i| material::arr![8, |a| xr[i][a] + ue[i][a]]];
    let (ue, ve, xe) = (R::nodal(&ue), R::nodal(&ve), R::nodal(&xe));
    let s = R::per_element(density_scale);
    // SAFETY: batch bi owns history[bi*stride..(bi+1)*stride] alone.
    let h = R::history(unsafe { b.hist.slice(bi * stride, stride) });
    match b.form {
        Formulation::OnePoint(hg) if !FULL => {
            let gamma = R::hourglass_vectors(refs, bi, &xr);
            let rf = one_point::OnePointRef {
                grad: &refs.grad[bi],
                gamma: &gamma,
                vol0: R::per_element(lanes_of(&g.vol0, le0)),
                hg_scale: R::per_element(lanes_of(&g.hg_scale, le0)),
                physical: (!g.hg_frame.is_empty()).then(|| PhysicalRef {
                    frame: &refs.hg_frame[bi],
                    inv_len: &refs.hg_inv_len[bi],
                    young: g.hg_moduli[0],
                    poisson: g.hg_moduli[1],
                    shear: g.hg_moduli[2],
                }),
            };
            one_point::compute_forces(l, &rf, hg.form, &xe, &ue, &ve, s, b.input, h, fe)
        }
        Formulation::Full { fbar } if FULL => {
            let rf = full::FullRef {
                centre_grad: &refs.grad[bi],
                gp_grad: &refs.gp_grad[bi],
                gp_weight: &refs.gp_weight[bi],
                vol0: R::per_element(lanes_of(&g.vol0, le0)),
            };
            full::compute_forces(l, &rf, fbar, &xe, &ue, &ve, s, b.input, h, fe)
        }
        _ => unreachable!("run_chunk_in picks FULL from the formulation"),
    }
}

/// The batch's lanes booked into the chunk's results, element by element: the first fault, the
/// run-time mass scaling of a step below the group's floor, failed elements, the totals
/// ([`ElementTotals::combine`]) and the stress. Returns which lanes add their forces (valid,
/// not eroded, no fault).
#[inline(always)]
fn book_lanes<L: Law, R: Real>(
    l: &L,
    b: &Batch,
    le0: usize,
    nvalid: usize,
    o: &ElementOut<R>,
    density_scale: F64x8,
    acc: &mut ChunkOut,
) -> [bool; LANES] {
    let g = b.group;
    let f64s = |x: R| {
        let mut a = [0.0; LANES];
        x.widen().write_to(&mut a);
        a
    };
    let (fault_l, fault_v) = (f64s(o.fault), f64s(o.fault_value));
    let (dt_l, hs_l, hp_l) = (
        f64s(o.dt),
        f64s(o.hourglass_stored),
        f64s(o.hourglass_power),
    );
    let (bulk_l, diss_l) = (f64s(o.bulk_power), f64s(o.law_dissipation));
    let s_l = density_scale.to_array();
    let mut add = [false; LANES];
    for q in 0..nvalid {
        let le = le0 + q;
        let eroded = !g.eroded.is_empty() && g.eroded[le];
        let fault = fault_l[q];
        if eroded || fault != 0.0 {
            if !eroded && acc.error.is_none() {
                let e = fault_error(fault, fault_v[q], l.name());
                acc.error = Some((g.elements[le], e.to_string()));
            }
            if g.record_dt {
                acc.dts.push(f64::INFINITY);
            }
            continue;
        }
        add[q] = true;
        let mut dt = dt_l[q];
        if dt < g.dt_floor {
            // Run-time mass scaling: dt grows with sqrt(density scale).
            let r = g.dt_floor / dt;
            acc.rescale.push((le as u32, s_l[q] * r * r));
            dt = g.dt_floor;
        }
        if let Some(r) = g.dt_reference.get(le) {
            if r / dt > acc.rise {
                acc.rise = r / dt;
                acc.rise_elem = g.elements[le];
            }
        }
        if g.record_dt {
            acc.dts.push(dt);
        }
        let (hs, hp) = (hs_l[q], hp_l[q]);
        let failed = o.failed.lane(q);
        if failed {
            acc.failed.push(le as u32);
        }
        acc.totals.combine(&ElementTotals {
            dt_min: dt,
            dt_elem: g.elements[le],
            hg_stored: hs,
            hg_power: hp,
            hg_peak: hs + hp * b.input.dt,
            hg_peak_elem: g.elements[le],
            bulk_power: bulk_l[q],
            law_dissipation: diss_l[q],
            newly_eroded: failed as u32,
            first_eroded: failed.then_some(g.elements[le]),
        });
        if let Some(sp) = b.stress {
            // SAFETY: one element writes one entry.
            unsafe {
                sp.slice(g.elements[le] as usize, 1)[0] = material::arr![6, |c| o.cauchy[c].lane(q)]
            };
        }
    }
    add
}

/// Add the batch's forces into the nodal array, element by element, for the lanes in `add`.
#[inline(always)]
fn scatter_forces<R: Real>(
    b: &Batch,
    conn: &[[u32; 8]; LANES],
    add: &[bool; LANES],
    fe: &Nodal<R>,
) {
    let fl: [[[f64; LANES]; 8]; 3] = material::arr![3, |i| material::arr![8, |a| {
        let mut l = [0.0; LANES];
        fe[i][a].widen().write_to(&mut l);
        l
    }]];
    for q in 0..LANES {
        if !add[q] {
            continue;
        }
        for a in 0..8 {
            // SAFETY: no other chunk of this colour has this node (see `Group::colours`).
            let f = unsafe { &mut b.force.slice(conn[q][a] as usize, 1)[0] };
            f[0] += fl[0][a][q];
            f[1] += fl[1][a][q];
            f[2] += fl[2][a][q];
        }
    }
}

/// Lane vectors of a nodal field over a batch: `[component][node][lane]` of
/// `field[conn[lane][node]]`. Both implementations load the same numbers.
trait GatherLanes {
    fn lanes(field: &[[f64; 3]], conn: &[[u32; 8]; LANES]) -> Nodal<F64x8>;
}

/// Scalar loads assembled into lane vectors (any instruction set).
struct ScalarGather;

impl GatherLanes for ScalarGather {
    #[inline(always)]
    fn lanes(field: &[[f64; 3]], conn: &[[u32; 8]; LANES]) -> Nodal<F64x8> {
        material::arr![3, |i| material::arr![8, |a| F64x8::new(material::arr![
            LANES,
            |q| field[conn[q][a] as usize][i]
        ])]]
    }
}

/// AVX-512 masked loads and permutes ([`gather_avx512`]). Sound only inside
/// [`run_chunk_avx512`], which is entered only on a processor with AVX-512.
struct Avx512Gather;

impl GatherLanes for Avx512Gather {
    #[inline(always)]
    fn lanes(field: &[[f64; 3]], conn: &[[u32; 8]; LANES]) -> Nodal<F64x8> {
        #[cfg(target_arch = "x86_64")]
        {
            // SAFETY: only reached from `run_chunk_avx512`, on a processor with AVX-512.
            unsafe { gather_avx512(field, conn) }
        }
        #[cfg(not(target_arch = "x86_64"))]
        ScalarGather::lanes(field, conn)
    }
}

/// [`GatherLanes::lanes`] for AVX-512: for each element node, the eight nodes' (x, y, z) are
/// loaded as four-wide vectors (the fourth entry masked off, so the last node never reads past
/// the array) and transposed into three lane vectors by two rounds of two-source permutes.
/// Measured on the 100k-element one-point block (`palpa bench --cases nh-1pt --threads 1`): the
/// `vgatherdpd` form (one gather per component and node) spent a quarter of the step in its
/// gathers; this form issues eight loads and eleven shuffles where that one issued three
/// 8-element gathers.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl")]
#[inline]
unsafe fn gather_avx512(field: &[[f64; 3]], conn: &[[u32; 8]; LANES]) -> Nodal<F64x8> {
    use std::arch::x86_64::*;
    let n = field.len();
    let base = field.as_ptr() as *const f64;
    let ix = |v: [i64; 8]| _mm512_loadu_si512(v.as_ptr() as *const __m512i);
    let (i_xy, i_zw) = (
        ix([0, 4, 8, 12, 1, 5, 9, 13]),
        ix([2, 6, 10, 14, 3, 7, 11, 15]),
    );
    let (i_lo, i_hi) = (
        ix([0, 1, 2, 3, 8, 9, 10, 11]),
        ix([4, 5, 6, 7, 12, 13, 14, 15]),
    );
    let mut out = [[F64x8::zero(); 8]; 3];
    let lanes = |v: __m512d| F64x8::new(std::mem::transmute::<__m512d, [f64; LANES]>(v));
    for a in 0..8 {
        // Node q's (x, y, z, -) as one four-wide load; every node index is below the field's
        // length (the model checks its connectivity).
        let r = |q: usize| {
            let nd = conn[q][a] as usize;
            debug_assert!(nd < n);
            _mm256_maskz_loadu_pd(0b0111, base.add(3 * nd))
        };
        let pair = |q: usize| _mm512_insertf64x4::<1>(_mm512_castpd256_pd512(r(q)), r(q + 1));
        let (z01, z23, z45, z67) = (pair(0), pair(2), pair(4), pair(6));
        let t0 = _mm512_permutex2var_pd(z01, i_xy, z23); // x0..x3, y0..y3
        let t1 = _mm512_permutex2var_pd(z01, i_zw, z23); // z0..z3, -
        let t2 = _mm512_permutex2var_pd(z45, i_xy, z67); // x4..x7, y4..y7
        let t3 = _mm512_permutex2var_pd(z45, i_zw, z67); // z4..z7, -
        out[0][a] = lanes(_mm512_permutex2var_pd(t0, i_lo, t2));
        out[1][a] = lanes(_mm512_permutex2var_pd(t0, i_hi, t2));
        out[2][a] = lanes(_mm512_permutex2var_pd(t1, i_lo, t3));
    }
    out
}
