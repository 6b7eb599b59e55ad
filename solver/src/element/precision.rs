//! Precision of the element kernels: `f64` (the default) or `f32` ([`Precision`]).
//!
//! LS-DYNA ships single- and double-precision executables and chooses by executable, not by
//! keyword; single precision is the usual explicit choice, double the advice for long runs
//! (many cycles, where round-off accumulates in the positions) and for implicit work (ANSYS
//! LS-DYNA training, lecture 7 "Solution and Simulation Controls", section "LS-DYNA Solver
//! Precision"). A palpation takes 15-35k cycles. palpa's `f32` kernels are the cautious variant
//! described in [`material::real_f32`]: nodal coordinates, displacements and velocities, the
//! nodal force sums, the laws and their history stay in `f64`; the element kinematics, hourglass
//! forces, nodal forces and critical step run in eight `f32` lanes, reading the reference data
//! (gradients, hourglass vectors, element frames, Gauss weights) from an `f32` copy
//! ([`NarrowRef`]), kept beside the `f64` data (so the run holds half as much again). That is
//! half the bytes of the stored `f64` data; the `f64` one-point kernels form their hourglass
//! vectors instead of reading them (`solver::forces`), so there `f32` reads 224 bytes per
//! element against `f64`'s 192.
//!
//! Before a batch is narrowed, each element's nodal coordinates, displacements and velocities are
//! taken relative to its first node (in `f64`). Every quantity the kernels form from them is
//! invariant under that shift: gradients (sum_a grad N_a = 0), hourglass modes (sum_a gamma_a =
//! 0), face areas (differences). Without it, an element carried 10 mm by the press would lose
//! `f32` digits of its 0.1 mm of relative motion to the 10 mm they share.

use super::Nodal;
use material::real::{F64x8, Real};
#[cfg(target_arch = "x86_64")]
use material::real_avx512::{Z32x8, Z64x8};
use material::real_f32::F32x8;

/// The number type of the element kernels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Precision {
    /// Double precision throughout (the default).
    #[default]
    F64,
    /// Single-precision kernels, with the laws and nodal state in double precision.
    F32,
}

impl Precision {
    /// `"f64"` or `"f32"`, as scenes and the command line spell it.
    pub fn label(&self) -> &'static str {
        match self {
            Precision::F64 => "f64",
            Precision::F32 => "f32",
        }
    }

    /// From `"f64"` (or `"double"`) or `"f32"` (or `"single"`); the error names the accepted
    /// values.
    pub fn parse(s: &str) -> Result<Precision, String> {
        match s {
            "f64" | "double" => Ok(Precision::F64),
            "f32" | "single" => Ok(Precision::F32),
            _ => Err(format!(
                "unknown precision {s:?}: expected \"f64\" (double) or \"f32\" (single)"
            )),
        }
    }
}

/// A group's reference data, borrowed, in lanes of `R` ([`F64x8`] from the group itself,
/// [`F32x8`] from its [`NarrowRef`]): per batch, the mean gradients, hourglass vectors, element
/// frames and inverse half-lengths of the physical form, Gauss-point gradients and weights (each
/// empty where the group's formulation has none).
#[derive(Clone, Copy)]
pub struct Refs<'a, R> {
    /// Mean gradients.
    pub grad: &'a [Nodal<R>],
    /// Hourglass vectors.
    pub gamma: &'a [[[R; 8]; 4]],
    /// Element frames of the physical hourglass form.
    pub hg_frame: &'a [[[R; 3]; 3]],
    /// Inverse half-lengths of the physical form.
    pub hg_inv_len: &'a [[R; 3]],
    /// Gauss-point gradients.
    pub gp_grad: &'a [[Nodal<R>; 8]],
    /// Gauss-point weights.
    pub gp_weight: &'a [[R; 8]],
}

impl<R> Refs<'_, R> {
    /// Bytes these data hold (what kernels reading all of them read over one step).
    pub fn bytes(&self) -> usize {
        std::mem::size_of_val(self.grad)
            + std::mem::size_of_val(self.gamma)
            + std::mem::size_of_val(self.hg_frame)
            + std::mem::size_of_val(self.hg_inv_len)
            + std::mem::size_of_val(self.gp_grad)
            + std::mem::size_of_val(self.gp_weight)
    }
}

impl<'a> Refs<'a, F64x8> {
    /// The same data read as [`Z64x8`] lanes, for the AVX-512 kernels (no copy: [`F64x8`] is
    /// aligned to 64 bytes, as `Z64x8` needs, and both are eight `f64`).
    #[cfg(target_arch = "x86_64")]
    pub fn as_z64x8(&self) -> Refs<'a, Z64x8> {
        // SAFETY: the same numbers in the same layout.
        unsafe { self.recast() }
    }
}

impl<'a> Refs<'a, F32x8> {
    /// The same data read as [`Z32x8`] lanes (a transparent wrapper of [`F32x8`]).
    #[cfg(target_arch = "x86_64")]
    pub fn as_z32x8(&self) -> Refs<'a, Z32x8> {
        // SAFETY: the same numbers in the same layout.
        unsafe { self.recast() }
    }
}

impl<'a, A> Refs<'a, A> {
    /// Every array read as the same arrays of `B`.
    ///
    /// # Safety
    /// As [`recast`].
    #[cfg(target_arch = "x86_64")]
    unsafe fn recast<B>(&self) -> Refs<'a, B> {
        // SAFETY: passed on to the caller.
        unsafe {
            Refs {
                grad: recast(self.grad),
                gamma: recast(self.gamma),
                hg_frame: recast(self.hg_frame),
                hg_inv_len: recast(self.hg_inv_len),
                gp_grad: recast(self.gp_grad),
                gp_weight: recast(self.gp_weight),
            }
        }
    }
}

/// A slice of arrays of [`F64x8`] as the same arrays of [`Z64x8`], or of [`F32x8`] as [`Z32x8`].
///
/// # Safety
/// `A` and `B` must hold the same numbers in the same layout, every bit pattern of `A` being a
/// valid `B`: [`Refs::as_z64x8`] and [`Refs::as_z32x8`] call it with those pairs only. Size and
/// alignment are checked at compile time.
#[cfg(target_arch = "x86_64")]
unsafe fn recast<A, B>(x: &[A]) -> &[B] {
    const { assert!(std::mem::size_of::<A>() == std::mem::size_of::<B>()) };
    const { assert!(std::mem::align_of::<A>() >= std::mem::align_of::<B>()) };
    // SAFETY: same size, no stricter alignment (checked above), same lanes (the caller).
    unsafe { std::slice::from_raw_parts(x.as_ptr() as *const B, x.len()) }
}

/// A group's reference data in `f32` lanes, built from the `f64` data the first time an `f32`
/// run evaluates the group.
#[derive(Clone, Debug, Default)]
pub struct NarrowRef {
    grad: Vec<Nodal<F32x8>>,
    gamma: Vec<[[F32x8; 8]; 4]>,
    hg_frame: Vec<[[F32x8; 3]; 3]>,
    hg_inv_len: Vec<[F32x8; 3]>,
    gp_grad: Vec<[Nodal<F32x8>; 8]>,
    gp_weight: Vec<[F32x8; 8]>,
}

/// Every lane of an array of lane vectors, rounded to `f32`.
fn narrow_all<const N: usize, const M: usize>(x: &[[F64x8; N]; M]) -> [[F32x8; N]; M] {
    x.map(|row| row.map(F32x8::narrow))
}

impl NarrowRef {
    /// The `f32` copy of a group's reference data.
    pub fn new(r: &Refs<F64x8>) -> NarrowRef {
        NarrowRef {
            grad: r.grad.iter().map(narrow_all).collect(),
            gamma: r.gamma.iter().map(narrow_all).collect(),
            hg_frame: r.hg_frame.iter().map(narrow_all).collect(),
            hg_inv_len: r.hg_inv_len.iter().map(|x| x.map(F32x8::narrow)).collect(),
            gp_grad: r
                .gp_grad
                .iter()
                .map(|g| g.map(|n| narrow_all(&n)))
                .collect(),
            gp_weight: r.gp_weight.iter().map(|x| x.map(F32x8::narrow)).collect(),
        }
    }

    /// The copy, borrowed.
    pub fn refs(&self) -> Refs<'_, F32x8> {
        Refs {
            grad: &self.grad,
            gamma: &self.gamma,
            hg_frame: &self.hg_frame,
            hg_inv_len: &self.hg_inv_len,
            gp_grad: &self.gp_grad,
            gp_weight: &self.gp_weight,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn precision_parses_its_labels_and_refuses_others() {
        for p in [Precision::F64, Precision::F32] {
            assert_eq!(Precision::parse(p.label()), Ok(p));
        }
        let e = Precision::parse("f16").unwrap_err();
        assert!(e.contains("f16") && e.contains("\"f32\""), "{e}");
    }
}
