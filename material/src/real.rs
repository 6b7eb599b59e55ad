//! The number type every law and element kernel is written over: one body of code serves the
//! scalar path (`f64`, one integration point at a time: the material-point driver, tests) and the
//! batched path ([`F64x8`], [`LANES`] points at once, struct-of-arrays inside the batch: the
//! solver's element loop).
//!
//! [`F64x8`] wraps the `wide` crate's `f64x8`, whose operators are vector instructions of the
//! build's baseline (two AVX2 registers on the project's x86-64-v3, SSE2 or NEON elsewhere); the
//! solver's AVX-512 path runs [`crate::real_avx512::Z64x8`] instead, the same operations in one
//! 512-bit register (see the solver's `forces` module). This is the "code shaped so that the compiler
//! vectorises it" route: `std::simd` needs nightly, and `pulp`'s closure-generic style would
//! have to thread its `Simd` token through every law. `palpa bench` shows the result.
//!
//! Branches become masks: a comparison gives a [`Real::Mask`] and [`Real::select`] picks per
//! lane. Both sides of a select are computed, so code keeps non-finite values of the rejected
//! side out of the result by selecting, never by trapping.
//!
//! Transcendentals. For `f64`, `exp`, `ln`, `ln_1p`, `cbrt` and `exp_m1` are the standard
//! library's. For [`F64x8`], `exp` and `ln` are polynomial versions written with lane-wise
//! operations only, so that they vectorise (a branchy scalar version left each lane scalar)
//! ([`exp_lanes`], [`ln_lanes`]: the classic fdlibm reductions, Sun Microsystems 1993, with their
//! published minimax coefficients; within 1 ulp of the library on the tested range), `ln_1p` is
//! Goldberg's correction `ln(u) x / (u - 1)` with `u = 1 + x` (Goldberg 1991, "What every
//! computer scientist should know about floating-point arithmetic", thm. 4), `cbrt` is
//! `exp(ln(x)/3)` refined by one Newton step, and `exp_m1` calls the library per lane (it only
//! runs on plastic steps). So the batched path agrees with the scalar one to round-off, not
//! bitwise; each law's test holds the two within a few ulp.

use std::ops::{
    Add, AddAssign, BitAnd, BitOr, Div, DivAssign, Mul, MulAssign, Neg, Not, Shl, Shr, Sub,
    SubAssign,
};
use wide::bytemuck::cast;
use wide::{f64x8, u64x8};

/// Lanes of the batched number type.
pub const LANES: usize = 8;

/// A per-lane boolean.
pub trait Mask: Copy + BitAnd<Output = Self> + BitOr<Output = Self> + Not<Output = Self> {
    /// The same value in every lane.
    fn splat(b: bool) -> Self;
    /// True if any lane is set.
    fn any(self) -> bool;
    /// Lane `i`.
    fn lane(self, i: usize) -> bool;
}

/// A real number, or [`LANES`] of them.
pub trait Real:
    Copy
    + Send
    + Sync
    + std::fmt::Debug
    + 'static
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
    + DivAssign
    + Add<f64, Output = Self>
    + Sub<f64, Output = Self>
    + Mul<f64, Output = Self>
    + Div<f64, Output = Self>
{
    /// Per-lane boolean.
    type Mask: Mask;
    /// Number of lanes.
    const LANES: usize;
    /// The number type laws are evaluated in for a kernel over `Self`: `Self` itself, except for
    /// the single-precision lanes ([`crate::real_f32::F32x8`]), whose laws run in [`F64x8`].
    type Wide: Real;
    /// To the law's number type (exact).
    fn widen(self) -> Self::Wide;
    /// From the law's number type (rounded to nearest where `Self` is narrower).
    fn narrow(w: Self::Wide) -> Self;
    /// A mask of the law's number type as a mask of `Self`.
    fn narrow_mask(m: <Self::Wide as Real>::Mask) -> Self::Mask;
    /// The same value in every lane.
    fn splat(x: f64) -> Self;
    /// Lane `i`.
    fn lane(self, i: usize) -> f64;
    /// Set lane `i`.
    fn set_lane(&mut self, i: usize, x: f64);
    /// From the first `LANES` values of a slice.
    fn from_slice(x: &[f64]) -> Self;
    /// Write the lanes to the first `LANES` values of a slice.
    fn write_to(self, out: &mut [f64]);
    /// Square root.
    fn sqrt(self) -> Self;
    /// Cube root.
    fn cbrt(self) -> Self;
    /// e^x.
    fn exp(self) -> Self;
    /// e^x - 1.
    fn exp_m1(self) -> Self;
    /// Natural logarithm.
    fn ln(self) -> Self;
    /// ln(1 + x).
    fn ln_1p(self) -> Self;
    /// |x|.
    fn abs(self) -> Self;
    /// Larger of two (the non-NaN one if one is NaN, as `f64::max`).
    fn max(self, o: Self) -> Self;
    /// Smaller of two (as `f64::min`).
    fn min(self, o: Self) -> Self;
    /// Lane-wise `<`.
    fn lt(self, o: Self) -> Self::Mask;
    /// Lane-wise `<=`.
    fn le(self, o: Self) -> Self::Mask;
    /// Lane-wise `>`.
    fn gt(self, o: Self) -> Self::Mask;
    /// Lane-wise `>=`.
    fn ge(self, o: Self) -> Self::Mask;
    /// Lane-wise `!=`.
    fn ne(self, o: Self) -> Self::Mask;
    /// Finite (neither infinite nor NaN).
    fn is_finite(self) -> Self::Mask;
    /// `a` where `m`, else `b`.
    fn select(m: Self::Mask, a: Self, b: Self) -> Self;
    /// Zero.
    #[inline(always)]
    fn zero() -> Self {
        Self::splat(0.0)
    }
}

impl Mask for bool {
    #[inline(always)]
    fn splat(b: bool) -> Self {
        b
    }
    #[inline(always)]
    fn any(self) -> bool {
        self
    }
    #[inline(always)]
    fn lane(self, _i: usize) -> bool {
        self
    }
}

impl Real for f64 {
    type Mask = bool;
    const LANES: usize = 1;
    type Wide = f64;
    #[inline(always)]
    fn widen(self) -> f64 {
        self
    }
    #[inline(always)]
    fn narrow(w: f64) -> Self {
        w
    }
    #[inline(always)]
    fn narrow_mask(m: bool) -> bool {
        m
    }
    #[inline(always)]
    fn splat(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn lane(self, _i: usize) -> f64 {
        self
    }
    #[inline(always)]
    fn set_lane(&mut self, _i: usize, x: f64) {
        *self = x;
    }
    #[inline(always)]
    fn from_slice(x: &[f64]) -> Self {
        x[0]
    }
    #[inline(always)]
    fn write_to(self, out: &mut [f64]) {
        out[0] = self;
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn cbrt(self) -> Self {
        f64::cbrt(self)
    }
    #[inline(always)]
    fn exp(self) -> Self {
        f64::exp(self)
    }
    #[inline(always)]
    fn exp_m1(self) -> Self {
        f64::exp_m1(self)
    }
    #[inline(always)]
    fn ln(self) -> Self {
        f64::ln(self)
    }
    #[inline(always)]
    fn ln_1p(self) -> Self {
        f64::ln_1p(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f64::abs(self)
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        f64::max(self, o)
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        f64::min(self, o)
    }
    #[inline(always)]
    fn lt(self, o: Self) -> bool {
        self < o
    }
    #[inline(always)]
    fn le(self, o: Self) -> bool {
        self <= o
    }
    #[inline(always)]
    fn gt(self, o: Self) -> bool {
        self > o
    }
    #[inline(always)]
    fn ge(self, o: Self) -> bool {
        self >= o
    }
    #[inline(always)]
    fn ne(self, o: Self) -> bool {
        self != o
    }
    #[inline(always)]
    fn is_finite(self) -> bool {
        f64::is_finite(self)
    }
    #[inline(always)]
    fn select(m: bool, a: Self, b: Self) -> Self {
        if m {
            a
        } else {
            b
        }
    }
}

/// `[e(0), e(1), ..., e(N-1)]` for an expression `e` of the index, written out as a loop with no
/// closure: `arr![3, |i| x[i] * 2.0]`. Closures (and `std::array::from_fn`) called from the
/// AVX-512 kernels were left out of line by LLVM and cost a quarter of the element loop.
#[macro_export]
macro_rules! arr {
    ($n:expr, |$i:ident| $e:expr) => {{
        let mut r = {
            let $i = 0usize;
            [$e; $n]
        };
        let mut $i = 1usize;
        while $i < $n {
            r[$i] = $e;
            $i += 1;
        }
        r
    }};
}

/// Eight `f64` lanes: the `wide` crate's `f64x8` (one AVX-512 register, or two AVX2 registers
/// on the build's x86-64-v3 baseline, or four SSE2/NEON ones), which guarantees vector
/// instructions where plain `[f64; 8]` loops were vectorised only in part.
///
/// Aligned to 64 bytes (one cache line, and the alignment of an AVX-512 register), so that the
/// solver may read its stored lanes as [`crate::real_avx512::Z64x8`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct F64x8(pub f64x8);

/// Eight boolean lanes (all bits set where true), as `wide` compares give them.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(transparent)]
pub struct M8(pub f64x8);

impl F64x8 {
    /// From an array of lanes.
    #[inline(always)]
    pub fn new(x: [f64; LANES]) -> F64x8 {
        F64x8(f64x8::new(x))
    }
    /// The lanes as an array.
    #[inline(always)]
    pub fn to_array(self) -> [f64; LANES] {
        self.0.to_array()
    }
    /// The lanes, mutably.
    #[inline(always)]
    pub fn lanes_mut(&mut self) -> &mut [f64; LANES] {
        self.0.as_mut_array()
    }
}

/// The operators shared by the lane types ([`F64x8`], [`crate::real_f32::F32x8`]): `$t` wraps
/// the `wide` vector `$w` of `$s` lanes, `$m` its mask. Arithmetic with a plain `f64` rounds it
/// to `$s` first.
macro_rules! lane_operators {
    ($t:ident, $m:ident, $w:ident, $s:ident) => {
        impl BitAnd for $m {
            type Output = $m;
            #[inline(always)]
            fn bitand(self, o: $m) -> $m {
                $m(self.0 & o.0)
            }
        }
        impl BitOr for $m {
            type Output = $m;
            #[inline(always)]
            fn bitor(self, o: $m) -> $m {
                $m(self.0 | o.0)
            }
        }
        impl Not for $m {
            type Output = $m;
            #[inline(always)]
            fn not(self) -> $m {
                $m(!self.0)
            }
        }
        impl Mask for $m {
            #[inline(always)]
            fn splat(b: bool) -> Self {
                $m($w::splat(if b { $s::from_bits(!0) } else { 0.0 }))
            }
            #[inline(always)]
            fn any(self) -> bool {
                self.0.any()
            }
            #[inline(always)]
            fn lane(self, i: usize) -> bool {
                self.0.to_bitmask() >> i & 1 == 1
            }
        }
        lane_operators!(@bin $t, $w, $s, Add, add, AddAssign, add_assign, +);
        lane_operators!(@bin $t, $w, $s, Sub, sub, SubAssign, sub_assign, -);
        lane_operators!(@bin $t, $w, $s, Mul, mul, MulAssign, mul_assign, *);
        lane_operators!(@bin $t, $w, $s, Div, div, DivAssign, div_assign, /);
        impl Neg for $t {
            type Output = $t;
            #[inline(always)]
            fn neg(self) -> $t {
                $t(-self.0)
            }
        }
    };
    (@bin $t:ident, $w:ident, $s:ident, $tr:ident, $f:ident, $atr:ident, $af:ident, $op:tt) => {
        impl $tr for $t {
            type Output = $t;
            #[inline(always)]
            fn $f(self, o: $t) -> $t {
                $t(self.0 $op o.0)
            }
        }
        impl $tr<f64> for $t {
            type Output = $t;
            #[inline(always)]
            #[allow(clippy::unnecessary_cast)]
            fn $f(self, o: f64) -> $t {
                $t(self.0 $op $w::splat(o as $s))
            }
        }
        impl $atr for $t {
            #[inline(always)]
            fn $af(&mut self, o: $t) {
                *self = *self $op o;
            }
        }
    };
}
pub(crate) use lane_operators;

/// The [`Real`] methods shared by the lane types, written inside their `impl Real` blocks:
/// square root, |x|, `max`/`min` with `f64::max`'s NaN rule, comparisons and select.
macro_rules! lane_real_methods {
    ($t:ident, $m:ident, $w:ident, $s:ident) => {
        #[inline(always)]
        fn sqrt(self) -> Self {
            $t(self.0.sqrt())
        }
        #[inline(always)]
        fn abs(self) -> Self {
            $t(self.0.abs())
        }
        #[inline(always)]
        fn max(self, o: Self) -> Self {
            // As f64::max: the other operand where one is NaN.
            let m = $t(self.0.max(o.0));
            Self::select(self.ne(self), o, Self::select(o.ne(o), self, m))
        }
        #[inline(always)]
        fn min(self, o: Self) -> Self {
            let m = $t(self.0.min(o.0));
            Self::select(self.ne(self), o, Self::select(o.ne(o), self, m))
        }
        #[inline(always)]
        fn lt(self, o: Self) -> $m {
            $m(self.0.simd_lt(o.0))
        }
        #[inline(always)]
        fn le(self, o: Self) -> $m {
            $m(self.0.simd_le(o.0))
        }
        #[inline(always)]
        fn gt(self, o: Self) -> $m {
            $m(self.0.simd_gt(o.0))
        }
        #[inline(always)]
        fn ge(self, o: Self) -> $m {
            $m(self.0.simd_ge(o.0))
        }
        #[inline(always)]
        fn ne(self, o: Self) -> $m {
            $m(self.0.simd_ne(o.0))
        }
        #[inline(always)]
        fn is_finite(self) -> $m {
            $m(self.0.abs().simd_lt($w::splat($s::INFINITY)))
        }
        #[inline(always)]
        fn select(m: $m, a: Self, b: Self) -> Self {
            $t(m.0.select(a.0, b.0))
        }
    };
}
pub(crate) use lane_real_methods;

lane_operators!(F64x8, M8, f64x8, f64);

impl Real for F64x8 {
    type Mask = M8;
    const LANES: usize = LANES;
    type Wide = F64x8;
    #[inline(always)]
    fn widen(self) -> F64x8 {
        self
    }
    #[inline(always)]
    fn narrow(w: F64x8) -> Self {
        w
    }
    #[inline(always)]
    fn narrow_mask(m: M8) -> M8 {
        m
    }
    #[inline(always)]
    fn splat(x: f64) -> Self {
        F64x8(f64x8::splat(x))
    }
    #[inline(always)]
    fn lane(self, i: usize) -> f64 {
        self.0.as_array()[i]
    }
    #[inline(always)]
    fn set_lane(&mut self, i: usize, x: f64) {
        self.0.as_mut_array()[i] = x;
    }
    #[inline(always)]
    fn from_slice(x: &[f64]) -> Self {
        F64x8(f64x8::from(&x[..LANES]))
    }
    #[inline(always)]
    fn write_to(self, out: &mut [f64]) {
        out[..LANES].copy_from_slice(self.0.as_array());
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
        let mut r = self;
        for x in r.0.as_mut_array() {
            *x = x.exp_m1();
        }
        r
    }
    #[inline(always)]
    fn ln(self) -> Self {
        ln_lanes(self)
    }
    #[inline(always)]
    fn ln_1p(self) -> Self {
        ln_1p_lanes(self)
    }
    lane_real_methods!(F64x8, M8, f64x8, f64);
}

/// The bit-level view of the lane types that the vector transcendentals ([`exp_lanes`],
/// [`ln_lanes`], ...) are written over, so that [`F64x8`] and the AVX-512 lanes
/// ([`crate::real_avx512::Z64x8`]) run the same operations on their own registers.
pub trait LaneBits: Real {
    /// Eight `u64` lanes.
    type U: Copy
        + Add<Output = Self::U>
        + Sub<Output = Self::U>
        + BitAnd<Output = Self::U>
        + BitOr<Output = Self::U>
        + Shl<u32, Output = Self::U>
        + Shr<u32, Output = Self::U>;
    /// The bits of each lane.
    fn bits(self) -> Self::U;
    /// Lanes from their bits.
    fn from_bits(b: Self::U) -> Self;
    /// The same `u64` in every lane.
    fn splat_u(x: u64) -> Self::U;
    /// `wide`'s `max(lo)` then `min(hi)`: `vmaxpd`/`vminpd` with the bound kept where it is NaN.
    fn clamp_raw(self, lo: f64, hi: f64) -> Self;
    /// Lane-wise `==` (ordered).
    fn eq_(self, o: Self) -> Self::Mask;
}

impl LaneBits for F64x8 {
    type U = u64x8;
    #[inline(always)]
    fn bits(self) -> u64x8 {
        cast(self.0)
    }
    #[inline(always)]
    fn from_bits(b: u64x8) -> F64x8 {
        F64x8(cast(b))
    }
    #[inline(always)]
    fn splat_u(x: u64) -> u64x8 {
        u64x8::splat(x)
    }
    #[inline(always)]
    fn clamp_raw(self, lo: f64, hi: f64) -> F64x8 {
        F64x8(self.0.max(f64x8::splat(lo)).min(f64x8::splat(hi)))
    }
    #[inline(always)]
    fn eq_(self, o: F64x8) -> M8 {
        M8(self.0.simd_eq(o.0))
    }
}

const LN2_HI: f64 = 6.931_471_803_691_238_164_90e-01;
const LN2_LO: f64 = 1.908_214_929_270_587_700_02e-10;
/// 1.5 * 2^52: adding it rounds to an integer, held in the low bits of the result.
const SHIFT: f64 = 6_755_399_441_055_744.0;

/// `2^k` for integer-valued `kf` in [-1022, 1023] (`kf + SHIFT` holds k in its low bits).
#[inline(always)]
fn pow2<R: LaneBits>(kf: R) -> R {
    let k = (kf + SHIFT).bits() - R::splat_u(SHIFT.to_bits());
    R::from_bits((k + R::splat_u(1023)) << 52)
}

/// e^x in every lane with vector operations only: fdlibm's e_exp.c reduction `x = k ln2 + r`,
/// `|r| <= ln2/2`, and its degree-5 minimax rational form (error < 1 ulp); +inf above 709.78,
/// 0 below -708.39 (no subnormal results), NaN stays NaN.
#[inline(always)]
pub fn exp_lanes<R: LaneBits>(x: R) -> R {
    const P1: f64 = 1.666_666_666_666_660_190_37e-01;
    const P2: f64 = -2.777_777_777_701_559_338_42e-03;
    const P3: f64 = 6.613_756_321_437_934_361_17e-05;
    const P4: f64 = -1.653_390_220_546_525_153_90e-06;
    const P5: f64 = 4.138_136_797_057_238_460_39e-08;
    let xc = x.clamp_raw(-708.39, 709.78);
    let kf = (xc * std::f64::consts::LOG2_E + SHIFT) - SHIFT;
    let hi = xc - kf * LN2_HI;
    let lo = kf * LN2_LO;
    let r = hi - lo;
    let t = r * r;
    let c = r - t * ((((t * P5 + P4) * t + P3) * t + P2) * t + P1);
    let y = R::splat(1.0) - ((lo - (r * c) / (R::splat(2.0) - c)) - hi);
    // 2^k in two halves, so k up to 1024 stays representable.
    let k1 = (kf * 0.5 + SHIFT) - SHIFT;
    let v = y * pow2(k1) * pow2(kf - k1);
    let v = R::select(x.gt(R::splat(709.78)), R::splat(f64::INFINITY), v);
    let v = R::select(x.lt(R::splat(-708.39)), R::zero(), v);
    R::select(x.ne(x), x, v)
}

/// ln x in every lane with vector operations only (fdlibm's e_log.c: `x = 2^k m`,
/// `sqrt(2)/2 <= m < sqrt(2)`, `s = f/(2+f)` with `f = m - 1`, and its degree-14 minimax
/// polynomial in `s`; error < 1 ulp). Zero gives -inf, negative numbers and NaN give NaN, +inf
/// gives +inf; subnormal inputs are scaled by 2^54 first.
#[inline(always)]
pub fn ln_lanes<R: LaneBits>(x: R) -> R {
    const LG1: f64 = 6.666_666_666_666_735_130e-01;
    const LG2: f64 = 3.999_999_999_940_941_908e-01;
    const LG3: f64 = 2.857_142_874_366_239_149e-01;
    const LG4: f64 = 2.222_219_843_214_978_396e-01;
    const LG5: f64 = 1.818_357_216_161_805_012e-01;
    const LG6: f64 = 1.531_383_769_920_937_332e-01;
    const LG7: f64 = 1.479_819_860_511_658_591e-01;
    let sub = x.lt(R::splat(f64::MIN_POSITIVE));
    let xs = R::select(sub, x * 18_014_398_509_481_984.0, x); // 2^54
    let bits = xs.bits();
    // Mantissa moved into [sqrt(2)/2, sqrt(2)): add (1 - sqrt(2)/2) to the high bits as fdlibm.
    let hx = (bits >> 32) + R::splat_u(0x3ff0_0000 - 0x3fe6_a09e);
    let m = R::from_bits(
        (((hx & R::splat_u(0x000f_ffff)) + R::splat_u(0x3fe6_a09e)) << 32)
            | (bits & R::splat_u(0xffff_ffff)),
    );
    // k as f64 through the shift trick (k - 0x3ff wraps as two's complement).
    let kb = (hx >> 20) + R::splat_u(SHIFT.to_bits().wrapping_sub(0x3ff));
    let kf = R::from_bits(kb) - SHIFT;
    let kf = R::select(sub, kf - 54.0, kf);
    let f = m - 1.0;
    let hfsq = f * f * 0.5;
    let s = f / (f + 2.0);
    let z = s * s;
    let w = z * z;
    let t1 = w * ((w * LG6 + LG4) * w + LG2);
    let t2 = z * (((w * LG7 + LG5) * w + LG3) * w + LG1);
    let r = t2 + t1;
    let v = kf * LN2_HI - ((hfsq - (s * (hfsq + r) + kf * LN2_LO)) - f);
    let v = R::select(x.eq_(R::zero()), R::splat(f64::NEG_INFINITY), v);
    let v = R::select(!x.ge(R::zero()), R::splat(f64::NAN), v);
    R::select(x.eq_(R::splat(f64::INFINITY)), x, v)
}

/// ln(1 + x) in every lane: `ln(u) x / (u - 1)` with `u = 1 + x` (exact `x` where `u == 1`),
/// Goldberg's correction of the rounding in `1 + x`.
#[inline(always)]
pub fn ln_1p_lanes<R: LaneBits>(x: R) -> R {
    let u = x + 1.0;
    let d = u - 1.0;
    let l = ln_lanes(u);
    let same = d.eq_(R::zero());
    let v = l * (x / R::select(same, R::splat(1.0), d));
    let v = R::select(u.eq_(R::splat(f64::INFINITY)), l, v);
    R::select(same, x, v)
}

/// Cube root of positive lanes: `exp(ln(x)/3)` and one Newton step on `y^3 = x`.
#[inline(always)]
pub fn cbrt_lanes<R: LaneBits>(x: R) -> R {
    let y = exp_lanes(ln_lanes(x) * (1.0 / 3.0));
    y - (y - x / (y * y)) * (1.0 / 3.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn exp_poly(x: f64) -> f64 {
        exp_lanes(F64x8::splat(x)).lane(3)
    }
    fn ln_poly(x: f64) -> f64 {
        ln_lanes(F64x8::splat(x)).lane(5)
    }
    fn ln_1p_poly(x: f64) -> f64 {
        ln_1p_lanes(F64x8::splat(x)).lane(0)
    }
    fn cbrt_poly(x: f64) -> f64 {
        cbrt_lanes(F64x8::splat(x)).lane(7)
    }

    fn ulps(a: f64, b: f64) -> f64 {
        if a == b {
            return 0.0;
        }
        (a - b).abs() / (f64::EPSILON * b.abs().max(f64::MIN_POSITIVE))
    }

    fn sweep() -> Vec<f64> {
        let mut s = 0x9e37_79b9_7f4a_7c15u64;
        (0..200_000)
            .map(|_| {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                (s >> 11) as f64 / (1u64 << 53) as f64
            })
            .collect()
    }

    #[test]
    fn exp_within_one_ulp_of_the_library() {
        let mut worst: f64 = 0.0;
        for u in sweep() {
            let x = -700.0 + 1400.0 * u;
            worst = worst.max(ulps(exp_poly(x), x.exp()));
            let x = -3.0 + 6.0 * u;
            worst = worst.max(ulps(exp_poly(x), x.exp()));
        }
        assert!(worst <= 1.0, "{worst}");
        assert_eq!(exp_poly(0.0), 1.0);
        assert_eq!(exp_poly(1000.0), f64::INFINITY);
        assert_eq!(exp_poly(-1000.0), 0.0);
        assert!(exp_poly(f64::NAN).is_nan());
        assert!(ulps(exp_poly(709.7), 709.7f64.exp()) <= 1.0);
    }

    #[test]
    fn ln_within_one_ulp_of_the_library() {
        let mut worst: f64 = 0.0;
        for u in sweep() {
            for x in [u * 4.0, (u * 1400.0 - 700.0).exp(), 1.0 + (u - 0.5) * 1e-6] {
                worst = worst.max(ulps(ln_poly(x), x.ln()) * (x.ln().abs() > 1e-300) as u8 as f64);
            }
        }
        assert!(worst <= 1.0, "{worst}");
        assert_eq!(ln_poly(1.0), 0.0);
        assert_eq!(ln_poly(0.0), f64::NEG_INFINITY);
        assert!(ln_poly(-1.0).is_nan() && ln_poly(f64::NAN).is_nan());
        assert_eq!(ln_poly(f64::INFINITY), f64::INFINITY);
        assert!(ulps(ln_poly(1e-310), 1e-310f64.ln()) <= 1.0);
    }

    #[test]
    fn ln_1p_and_cbrt_within_a_few_ulp() {
        let mut worst: f64 = 0.0;
        let mut worst_c: f64 = 0.0;
        for u in sweep() {
            for x in [u * 1e-9, -u * 0.999, u * 50.0, (u - 0.5) * 1e-14] {
                worst = worst.max(ulps(ln_1p_poly(x), x.ln_1p()));
            }
            let x = (u * 40.0 - 20.0).exp();
            worst_c = worst_c.max(ulps(cbrt_poly(x), x.cbrt()));
        }
        assert!(worst <= 3.0, "ln_1p {worst}");
        assert!(worst_c <= 2.0, "cbrt {worst_c}");
        assert_eq!(ln_1p_poly(0.0), 0.0);
        assert_eq!(ln_1p_poly(-1.0), f64::NEG_INFINITY);
    }

    #[test]
    fn lanes_match_scalar_lane_by_lane() {
        let a = F64x8::new([0.5, -1.0, 2.0, 1e-3, 7.0, -0.25, 3.0, 9.0]);
        let b = F64x8::splat(2.0);
        let s = (a * b + a / b - b).max(a.min(b));
        for i in 0..LANES {
            let (x, y) = (a.lane(i), 2.0);
            assert_eq!(s.lane(i), (x * y + x / y - y).max(x.min(y)));
        }
        let m = a.gt(F64x8::zero());
        assert_eq!(F64x8::select(m, a, b).lane(1), 2.0);
        assert!(m.any() && (0..LANES).all(|i| (!m | m).lane(i)));
    }
}
