//! Eight `f64` lanes in one AVX-512 register: [`Z64x8`], the number type of the solver's `f64`
//! element kernels when the processor has AVX-512 (the solver's `forces::simd_level`).
//!
//! [`F64x8`] wraps the `wide` crate's `f64x8`, whose representation is fixed when `wide` is
//! compiled: two AVX2 registers on the project's x86-64-v3 baseline. The solver compiles its
//! batch kernel a second time for AVX-512 and picks it at run time, but LLVM does not fuse the
//! pairs of 256-bit operations that `wide` emits into 512-bit ones, so that kernel still ran on
//! half-width vectors. [`Z64x8`] holds an `__m512d` and calls the AVX-512 intrinsics directly.
//! Its methods are `#[inline(always)]` and are meant to be reached only from code compiled with
//! AVX-512 enabled (`#[target_feature(enable = "avx512f,...")]`): inlined there, each operator
//! becomes one 512-bit instruction. Measured on this project's 2-core AMD EPYC (Zen 5, full-width
//! AVX-512): `palpa bench`'s `f64` press case runs 1.25-1.35x faster than with [`F64x8`]
//! (docs/performance.md). Constructing or using a [`Z64x8`] on a processor without AVX-512 is
//! undefined behaviour, which is why only the solver's AVX-512 dispatch path names it.
//!
//! Every operation is the IEEE operation [`F64x8`] performs, in the same order, with the same
//! comparison predicates and the same `max`/`min` operand order (`wide`'s `max`: `self` where
//! `rhs` is NaN, else `vmaxpd(self, rhs)`). So the two types give bitwise the same results, and a run's
//! numbers do not depend on the processor it ran on; `tests` below and the `palpa` package's
//! `tests/simd_paths.rs` check it. [`Z32x8`] is the same idea for the `f32` kernels: their
//! lanes as [`F32x8`]'s, their laws in [`Z64x8`]. The transcendentals are the same generic functions as
//! [`F64x8`]'s ([`exp_lanes`], [`ln_lanes`], ...; [`LaneBits`] gives their bit operations on
//! [`ZU64`]), except `exp_m1`, which goes through [`F64x8`]'s (it calls the library per lane).

#![cfg(target_arch = "x86_64")]

use crate::real::{
    cbrt_lanes, exp_lanes, ln_1p_lanes, ln_lanes, F64x8, LaneBits, Mask, Real, LANES,
};
use crate::real_f32::{F32x8, M8f};
use std::arch::x86_64::*;
use std::ops::{
    Add, AddAssign, BitAnd, BitOr, Div, DivAssign, Mul, MulAssign, Neg, Not, Shl, Shr, Sub,
    SubAssign,
};

/// Eight `f64` lanes in one AVX-512 register.
///
/// Contract: construct and use it only on a processor with AVX-512 F, DQ, VL and BW (the
/// solver's `forces::simd_level` checks them before its AVX-512 path, the only user); elsewhere
/// its intrinsics are undefined behaviour. The constructors are safe functions so that the
/// generic law and element code can call them; the type is not meant for other callers.
#[derive(Clone, Copy)]
#[repr(transparent)]
pub struct Z64x8(pub __m512d);

/// Eight boolean lanes of [`Z64x8`]: an AVX-512 mask register, bit `i` for lane `i`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(transparent)]
pub struct ZM8(pub __mmask8);

impl std::fmt::Debug for Z64x8 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Z64x8({:?})", self.to_array())
    }
}

impl Z64x8 {
    /// From an array of lanes.
    #[inline(always)]
    pub fn new(x: [f64; LANES]) -> Z64x8 {
        // SAFETY: AVX-512 code only (module doc); the load is unaligned.
        Z64x8(unsafe { _mm512_loadu_pd(x.as_ptr()) })
    }
    /// The lanes as an array.
    #[inline(always)]
    pub fn to_array(self) -> [f64; LANES] {
        // SAFETY: `__m512d` and `[f64; 8]` have the same size and any bits are valid.
        unsafe { std::mem::transmute::<__m512d, [f64; LANES]>(self.0) }
    }
    /// The same lanes as an [`F64x8`] (a copy, no rounding).
    #[inline(always)]
    pub fn to_f64x8(self) -> F64x8 {
        F64x8::new(self.to_array())
    }
    /// From an [`F64x8`] (a copy, no rounding).
    #[inline(always)]
    pub fn from_f64x8(x: F64x8) -> Z64x8 {
        Z64x8::new(x.to_array())
    }
    #[inline(always)]
    fn cmp<const P: i32>(self, o: Z64x8) -> ZM8 {
        // SAFETY: AVX-512 code only.
        ZM8(unsafe { _mm512_cmp_pd_mask::<P>(self.0, o.0) })
    }
    /// `wide`'s `f64x8::max`: `self` where `o` is NaN, else `vmaxpd(self, o)`.
    #[inline(always)]
    fn wide_max(self, o: Z64x8) -> Z64x8 {
        // SAFETY: AVX-512 code only.
        let m = Z64x8(unsafe { _mm512_max_pd(self.0, o.0) });
        Z64x8::select(o.cmp::<_CMP_UNORD_Q>(o), self, m)
    }
    /// `wide`'s `f64x8::min`: `self` where `o` is NaN, else `vminpd(self, o)`.
    #[inline(always)]
    fn wide_min(self, o: Z64x8) -> Z64x8 {
        // SAFETY: AVX-512 code only.
        let m = Z64x8(unsafe { _mm512_min_pd(self.0, o.0) });
        Z64x8::select(o.cmp::<_CMP_UNORD_Q>(o), self, m)
    }
    /// A function of [`F64x8`] applied lane for lane.
    #[inline(always)]
    fn through(self, f: impl Fn(F64x8) -> F64x8) -> Z64x8 {
        Z64x8::from_f64x8(f(self.to_f64x8()))
    }
}

impl BitAnd for ZM8 {
    type Output = ZM8;
    #[inline(always)]
    fn bitand(self, o: ZM8) -> ZM8 {
        ZM8(self.0 & o.0)
    }
}
impl BitOr for ZM8 {
    type Output = ZM8;
    #[inline(always)]
    fn bitor(self, o: ZM8) -> ZM8 {
        ZM8(self.0 | o.0)
    }
}
impl Not for ZM8 {
    type Output = ZM8;
    #[inline(always)]
    fn not(self) -> ZM8 {
        ZM8(!self.0)
    }
}
impl Mask for ZM8 {
    #[inline(always)]
    fn splat(b: bool) -> Self {
        ZM8(if b { 0xff } else { 0 })
    }
    #[inline(always)]
    fn any(self) -> bool {
        self.0 != 0
    }
    #[inline(always)]
    fn lane(self, i: usize) -> bool {
        self.0 >> i & 1 == 1
    }
}

/// A binary operator of [`Z64x8`], with another [`Z64x8`] and with a plain `f64` (splat).
macro_rules! z_binary {
    ($tr:ident, $f:ident, $atr:ident, $af:ident, $op:tt, $intr:ident) => {
        impl $tr for Z64x8 {
            type Output = Z64x8;
            #[inline(always)]
            fn $f(self, o: Z64x8) -> Z64x8 {
                // SAFETY: AVX-512 code only (module doc).
                Z64x8(unsafe { $intr(self.0, o.0) })
            }
        }
        impl $tr<f64> for Z64x8 {
            type Output = Z64x8;
            #[inline(always)]
            fn $f(self, o: f64) -> Z64x8 {
                self $op Z64x8::splat(o)
            }
        }
        impl $atr for Z64x8 {
            #[inline(always)]
            fn $af(&mut self, o: Z64x8) {
                *self = *self $op o;
            }
        }
    };
}
z_binary!(Add, add, AddAssign, add_assign, +, _mm512_add_pd);
z_binary!(Sub, sub, SubAssign, sub_assign, -, _mm512_sub_pd);
z_binary!(Mul, mul, MulAssign, mul_assign, *, _mm512_mul_pd);
z_binary!(Div, div, DivAssign, div_assign, /, _mm512_div_pd);

impl Neg for Z64x8 {
    type Output = Z64x8;
    #[inline(always)]
    fn neg(self) -> Z64x8 {
        // As `wide`: the sign bit flipped (AVX512DQ).
        // SAFETY: AVX-512 code only.
        Z64x8(unsafe { _mm512_xor_pd(self.0, _mm512_set1_pd(-0.0)) })
    }
}

impl Real for Z64x8 {
    type Mask = ZM8;
    const LANES: usize = LANES;
    type Wide = Z64x8;
    #[inline(always)]
    fn widen(self) -> Z64x8 {
        self
    }
    #[inline(always)]
    fn narrow(w: Z64x8) -> Self {
        w
    }
    #[inline(always)]
    fn narrow_mask(m: ZM8) -> ZM8 {
        m
    }
    #[inline(always)]
    fn splat(x: f64) -> Self {
        // SAFETY: AVX-512 code only.
        Z64x8(unsafe { _mm512_set1_pd(x) })
    }
    #[inline(always)]
    fn lane(self, i: usize) -> f64 {
        self.to_array()[i]
    }
    #[inline(always)]
    fn set_lane(&mut self, i: usize, x: f64) {
        let mut a = self.to_array();
        a[i] = x;
        *self = Z64x8::new(a);
    }
    #[inline(always)]
    fn from_slice(x: &[f64]) -> Self {
        let x = &x[..LANES];
        // SAFETY: eight values in bounds (checked above); AVX-512 code only.
        Z64x8(unsafe { _mm512_loadu_pd(x.as_ptr()) })
    }
    #[inline(always)]
    fn write_to(self, out: &mut [f64]) {
        let out = &mut out[..LANES];
        // SAFETY: eight values in bounds (checked above); AVX-512 code only.
        unsafe { _mm512_storeu_pd(out.as_mut_ptr(), self.0) }
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        // SAFETY: AVX-512 code only.
        Z64x8(unsafe { _mm512_sqrt_pd(self.0) })
    }
    #[inline(always)]
    fn cbrt(self) -> Self {
        cbrt_lanes(self)
    }
    #[inline(always)]
    fn exp(self) -> Self {
        exp_lanes(self)
    }
    #[inline(always)]
    fn exp_m1(self) -> Self {
        self.through(|x| x.exp_m1())
    }
    #[inline(always)]
    fn ln(self) -> Self {
        ln_lanes(self)
    }
    #[inline(always)]
    fn ln_1p(self) -> Self {
        ln_1p_lanes(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        // SAFETY: AVX-512 code only (AVX512DQ, which the solver's dispatch checks).
        Z64x8(unsafe { _mm512_andnot_pd(_mm512_set1_pd(-0.0), self.0) })
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        // As F64x8 (and f64::max): the other operand where one is NaN.
        let m = self.wide_max(o);
        Self::select(self.ne(self), o, Self::select(o.ne(o), self, m))
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        let m = self.wide_min(o);
        Self::select(self.ne(self), o, Self::select(o.ne(o), self, m))
    }
    #[inline(always)]
    fn lt(self, o: Self) -> ZM8 {
        self.cmp::<_CMP_LT_OQ>(o)
    }
    #[inline(always)]
    fn le(self, o: Self) -> ZM8 {
        self.cmp::<_CMP_LE_OQ>(o)
    }
    #[inline(always)]
    fn gt(self, o: Self) -> ZM8 {
        self.cmp::<_CMP_GT_OQ>(o)
    }
    #[inline(always)]
    fn ge(self, o: Self) -> ZM8 {
        self.cmp::<_CMP_GE_OQ>(o)
    }
    #[inline(always)]
    fn ne(self, o: Self) -> ZM8 {
        self.cmp::<_CMP_NEQ_UQ>(o)
    }
    #[inline(always)]
    fn is_finite(self) -> ZM8 {
        self.abs().cmp::<_CMP_LT_OQ>(Z64x8::splat(f64::INFINITY))
    }
    #[inline(always)]
    fn select(m: ZM8, a: Self, b: Self) -> Self {
        // SAFETY: AVX-512 code only.
        Z64x8(unsafe { _mm512_mask_blend_pd(m.0, b.0, a.0) })
    }
}

/// Eight `u64` lanes in one AVX-512 register: the bits of [`Z64x8`] for the transcendentals.
#[derive(Clone, Copy)]
#[repr(transparent)]
pub struct ZU64(pub __m512i);

/// A binary operator of [`ZU64`].
macro_rules! zu_binary {
    ($tr:ident, $f:ident, $intr:ident) => {
        impl $tr for ZU64 {
            type Output = ZU64;
            #[inline(always)]
            fn $f(self, o: ZU64) -> ZU64 {
                // SAFETY: AVX-512 code only (module doc).
                ZU64(unsafe { $intr(self.0, o.0) })
            }
        }
    };
}
zu_binary!(Add, add, _mm512_add_epi64);
zu_binary!(Sub, sub, _mm512_sub_epi64);
zu_binary!(BitAnd, bitand, _mm512_and_si512);
zu_binary!(BitOr, bitor, _mm512_or_si512);

impl Shl<u32> for ZU64 {
    type Output = ZU64;
    #[inline(always)]
    fn shl(self, n: u32) -> ZU64 {
        // As `wide`: the count taken modulo 64. SAFETY: AVX-512 code only.
        ZU64(unsafe { _mm512_sll_epi64(self.0, _mm_cvtsi64_si128((n & 63) as i64)) })
    }
}
impl Shr<u32> for ZU64 {
    type Output = ZU64;
    #[inline(always)]
    fn shr(self, n: u32) -> ZU64 {
        // SAFETY: AVX-512 code only.
        ZU64(unsafe { _mm512_srl_epi64(self.0, _mm_cvtsi64_si128((n & 63) as i64)) })
    }
}

impl LaneBits for Z64x8 {
    type U = ZU64;
    #[inline(always)]
    fn bits(self) -> ZU64 {
        // SAFETY: AVX-512 code only.
        ZU64(unsafe { _mm512_castpd_si512(self.0) })
    }
    #[inline(always)]
    fn from_bits(b: ZU64) -> Z64x8 {
        // SAFETY: AVX-512 code only.
        Z64x8(unsafe { _mm512_castsi512_pd(b.0) })
    }
    #[inline(always)]
    fn splat_u(x: u64) -> ZU64 {
        // SAFETY: AVX-512 code only.
        ZU64(unsafe { _mm512_set1_epi64(x as i64) })
    }
    #[inline(always)]
    fn clamp_raw(self, lo: f64, hi: f64) -> Z64x8 {
        self.wide_max(Z64x8::splat(lo)).wide_min(Z64x8::splat(hi))
    }
    #[inline(always)]
    fn eq_(self, o: Z64x8) -> ZM8 {
        self.cmp::<_CMP_EQ_OQ>(o)
    }
}

/// The single-precision kernel lanes of the AVX-512 path: [`F32x8`]'s numbers and operations
/// (one 256-bit register), with [`Z64x8`] as the law's number type instead of [`F64x8`], so the
/// laws of an `f32` run also evaluate in 512-bit registers. Widening and narrowing are the
/// same exact conversion and round-to-nearest as [`F32x8`]'s, so the two give bitwise the same
/// results.
#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub struct Z32x8(pub F32x8);

/// A binary operator of [`Z32x8`]: [`F32x8`]'s.
macro_rules! z32_binary {
    ($tr:ident, $f:ident, $atr:ident, $af:ident, $op:tt) => {
        impl $tr for Z32x8 {
            type Output = Z32x8;
            #[inline(always)]
            fn $f(self, o: Z32x8) -> Z32x8 {
                Z32x8(self.0 $op o.0)
            }
        }
        impl $tr<f64> for Z32x8 {
            type Output = Z32x8;
            #[inline(always)]
            fn $f(self, o: f64) -> Z32x8 {
                Z32x8(self.0 $op o)
            }
        }
        impl $atr for Z32x8 {
            #[inline(always)]
            fn $af(&mut self, o: Z32x8) {
                *self = *self $op o;
            }
        }
    };
}
z32_binary!(Add, add, AddAssign, add_assign, +);
z32_binary!(Sub, sub, SubAssign, sub_assign, -);
z32_binary!(Mul, mul, MulAssign, mul_assign, *);
z32_binary!(Div, div, DivAssign, div_assign, /);

impl Neg for Z32x8 {
    type Output = Z32x8;
    #[inline(always)]
    fn neg(self) -> Z32x8 {
        Z32x8(-self.0)
    }
}

impl Z32x8 {
    /// A function of [`Z64x8`] applied to the lanes: widened, evaluated, narrowed.
    #[inline(always)]
    fn through(self, f: impl Fn(Z64x8) -> Z64x8) -> Z32x8 {
        Z32x8::narrow(f(self.widen()))
    }
}

impl Real for Z32x8 {
    type Mask = M8f;
    const LANES: usize = LANES;
    type Wide = Z64x8;
    #[inline(always)]
    fn widen(self) -> Z64x8 {
        // SAFETY: AVX-512 code only; `F32x8` is one 256-bit `f32x8` (exact conversion).
        Z64x8(unsafe { _mm512_cvtps_pd(std::mem::transmute::<F32x8, __m256>(self.0)) })
    }
    #[inline(always)]
    fn narrow(w: Z64x8) -> Self {
        // Round to nearest (the default rounding mode), as `F32x8::narrow`'s `as f32`.
        // SAFETY: AVX-512 code only.
        Z32x8(unsafe { std::mem::transmute::<__m256, F32x8>(_mm512_cvtpd_ps(w.0)) })
    }
    #[inline(always)]
    fn narrow_mask(m: ZM8) -> M8f {
        // SAFETY: AVX-512 code only (AVX512DQ + VL): all bits set in the lanes of set bits.
        unsafe { std::mem::transmute::<__m256i, M8f>(_mm256_movm_epi32(m.0)) }
    }
    #[inline(always)]
    fn splat(x: f64) -> Self {
        Z32x8(F32x8::splat(x))
    }
    #[inline(always)]
    fn lane(self, i: usize) -> f64 {
        self.0.lane(i)
    }
    #[inline(always)]
    fn set_lane(&mut self, i: usize, x: f64) {
        self.0.set_lane(i, x)
    }
    #[inline(always)]
    fn from_slice(x: &[f64]) -> Self {
        Z32x8(F32x8::from_slice(x))
    }
    #[inline(always)]
    fn write_to(self, out: &mut [f64]) {
        self.0.write_to(out)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Z32x8(self.0.sqrt())
    }
    #[inline(always)]
    fn cbrt(self) -> Self {
        self.through(Z64x8::cbrt)
    }
    #[inline(always)]
    fn exp(self) -> Self {
        self.through(Z64x8::exp)
    }
    #[inline(always)]
    fn exp_m1(self) -> Self {
        self.through(Z64x8::exp_m1)
    }
    #[inline(always)]
    fn ln(self) -> Self {
        self.through(Z64x8::ln)
    }
    #[inline(always)]
    fn ln_1p(self) -> Self {
        self.through(Z64x8::ln_1p)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        Z32x8(self.0.abs())
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        Z32x8(self.0.max(o.0))
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        Z32x8(self.0.min(o.0))
    }
    #[inline(always)]
    fn lt(self, o: Self) -> M8f {
        self.0.lt(o.0)
    }
    #[inline(always)]
    fn le(self, o: Self) -> M8f {
        self.0.le(o.0)
    }
    #[inline(always)]
    fn gt(self, o: Self) -> M8f {
        self.0.gt(o.0)
    }
    #[inline(always)]
    fn ge(self, o: Self) -> M8f {
        self.0.ge(o.0)
    }
    #[inline(always)]
    fn ne(self, o: Self) -> M8f {
        self.0.ne(o.0)
    }
    #[inline(always)]
    fn is_finite(self) -> M8f {
        self.0.is_finite()
    }
    #[inline(always)]
    fn select(m: M8f, a: Self, b: Self) -> Self {
        Z32x8(F32x8::select(m, a.0, b.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Numbers that exercise every branch: signed zeros, NaN, infinities, subnormals, huge and
    /// tiny values, ordinary ones.
    fn samples() -> Vec<f64> {
        let mut v = vec![
            0.0,
            -0.0,
            f64::NAN,
            f64::INFINITY,
            -f64::INFINITY,
            1e-310,
            -1e-310,
            1e300,
            -1e300,
            1.0,
            -1.0,
            0.5,
            709.0,
            -708.0,
            800.0,
        ];
        let mut s = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..400 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let m = (s >> 11) as f64 / (1u64 << 53) as f64;
            let e = ((s & 0x3f) as i32) - 32;
            let sign = if s & 0x40 != 0 { -1.0 } else { 1.0 };
            v.push(sign * m * 2f64.powi(e));
        }
        v
    }

    /// Bitwise equal lanes, NaN matching any NaN (LLVM does not keep a NaN's sign or payload:
    /// it may commute the operands of a product whose two factors are NaN).
    fn same(a: F64x8, b: Z64x8) -> bool {
        a.to_array()
            .iter()
            .zip(b.to_array())
            .all(|(x, y)| x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()))
    }

    /// Every operation of [`Z64x8`] gives bitwise what [`F64x8`] gives, on the same lanes.
    #[test]
    fn z64x8_is_bitwise_f64x8() {
        if !std::arch::is_x86_feature_detected!("avx512f")
            || !std::arch::is_x86_feature_detected!("avx512dq")
            || !std::arch::is_x86_feature_detected!("avx512vl")
            || !std::arch::is_x86_feature_detected!("avx512bw")
        {
            eprintln!("no AVX-512 here: nothing to compare");
            return;
        }
        let s = samples();
        let n = s.len() - s.len() % 8;
        for a0 in (0..n).step_by(8) {
            for b0 in [0, 8, 16, 24, 40, a0] {
                let (a, b) = (F64x8::from_slice(&s[a0..]), F64x8::from_slice(&s[b0..]));
                let (za, zb) = (Z64x8::from_slice(&s[a0..]), Z64x8::from_slice(&s[b0..]));
                assert!(same(a + b, za + zb));
                assert!(same(a - b, za - zb));
                assert!(same(a * b, za * zb));
                assert!(same(a / b, za / zb));
                assert!(same(a * 0.3, za * 0.3));
                assert!(same(-a, -za));
                assert!(same(a.max(b), za.max(zb)));
                assert!(same(a.min(b), za.min(zb)));
                assert!(same(a.abs(), za.abs()));
                assert!(same(a.abs().sqrt(), za.abs().sqrt()));
                assert!(same(a.exp(), za.exp()));
                assert!(same(a.abs().ln(), za.abs().ln()));
                assert!(same(a.ln_1p(), za.ln_1p()));
                assert!(same(a.abs().cbrt(), za.abs().cbrt()));
                for l in 0..LANES {
                    assert_eq!(a.lt(b).lane(l), za.lt(zb).lane(l));
                    assert_eq!(a.le(b).lane(l), za.le(zb).lane(l));
                    assert_eq!(a.gt(b).lane(l), za.gt(zb).lane(l));
                    assert_eq!(a.ge(b).lane(l), za.ge(zb).lane(l));
                    assert_eq!(a.ne(b).lane(l), za.ne(zb).lane(l));
                    assert_eq!(a.is_finite().lane(l), za.is_finite().lane(l));
                }
                let m = a.lt(b) | !a.is_finite();
                let zm = za.lt(zb) | !za.is_finite();
                assert!(same(F64x8::select(m, a, b), Z64x8::select(zm, za, zb)));
                assert_eq!(m.any(), zm.any());
                // the f32 lanes: conversions, masks, transcendentals through the wide type
                let (n, zn) = (F32x8::narrow(a), Z32x8::narrow(za));
                assert!(same(n.widen(), zn.widen()));
                assert!(same(n.exp().widen(), zn.exp().widen()));
                assert!(same(n.abs().ln().widen(), zn.abs().ln().widen()));
                let (nm, znm) = (F32x8::narrow_mask(m), Z32x8::narrow_mask(zm));
                for l in 0..LANES {
                    assert_eq!(nm.lane(l), znm.lane(l));
                }
            }
        }
    }
}
